"""Numeric code generated from exact SymPy expressions (the fast path of :class:`SerialChain`).

The *unsimplified* product-of-exponentials expression is reduced by common-subexpression
elimination (``sympy.cse``) and printed as straight-line Python twice: once over ``math`` for a
single configuration (floats in, one NumPy array out), once over NumPy with the batch on the last
axis (arrays of N values in, an (N, rows, cols) array out). Simplified expressions would be
slower: simplification destroys the shared subexpressions.
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np
import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from ._backend import describe

__all__ = ["CompiledMatrix", "compile_matrix"]

_MATH = {name: getattr(math, name) for name in ("sin", "cos", "tan", "sqrt", "exp", "log", "atan2", "pi", "e")}
_NUMPY = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "sqrt": np.sqrt, "exp": np.exp, "log": np.log,
          "atan2": np.arctan2, "pi": math.pi, "e": math.e}


class _Printer(PythonCodePrinter):
    def __init__(self):
        super().__init__({"fully_qualified_modules": False, "standard": "python3"})


class CompiledMatrix:
    """A matrix expression in ``args`` compiled to NumPy code; call it with q of shape (n,) or (N, n)."""

    def __init__(self, expr: sp.MatrixBase, args: Sequence[sp.Symbol], name: str = "matrix"):
        expr = sp.Matrix(expr)
        self.shape = expr.shape
        self.args = tuple(args)
        self.n = len(self.args)
        self.name = name
        local = [sp.Symbol(f"_q{i}") for i in range(self.n)]
        entries = list(expr.xreplace(dict(zip(self.args, local))))
        extra = set().union(*(e.free_symbols for e in entries)) - set(local) if entries else set()
        if extra:
            raise ValueError(f"cannot generate numeric code for {name}: it still has the free symbols "
                             f"{sorted(map(str, extra))} besides the joint variables; give them values first")
        repl, reduced = sp.cse(entries, symbols=sp.numbered_symbols("_x"))
        pr = _Printer()
        body = [f"    {s} = {pr.doprint(e)}" for s, e in repl]
        unpack = f"    {', '.join(map(str, local))}{',' if self.n == 1 else ''} = q" if self.n else ""
        items = [pr.doprint(e) for e in reduced]
        r, c = self.shape
        single = ["def _single(q):", unpack, *body,
                  f"    return _fromiter(({', '.join(items)}{',' if len(items) == 1 else ''}), _float, {r * c}).reshape({r}, {c})"]
        batch = ["def _batch(q):", unpack, *body, f"    out = _empty(({r}, {c}, q.shape[1]))"]
        for k, it in enumerate(items):
            batch.append(f"    out[{k // c}, {k % c}] = {it}")
        batch.append("    return out")
        self.source = "\n".join(single) + "\n\n" + "\n".join(batch) + "\n"
        ns_single = dict(_MATH, _fromiter=np.fromiter, _float=float)
        ns_batch = dict(_NUMPY, _empty=np.empty)
        exec(compile("\n".join(single), f"<kinlib {name} single>", "exec"), ns_single)
        exec(compile("\n".join(batch), f"<kinlib {name} batch>", "exec"), ns_batch)
        self._single = ns_single["_single"]
        self._batch = ns_batch["_batch"]

    def __call__(self, q):
        """Evaluate at q: shape (n,) gives (rows, cols); shape (N, n) gives (N, rows, cols)."""
        try:
            arr = np.asarray(q, dtype=float)
        except (TypeError, ValueError):
            raise TypeError(f"q must hold {self.n} real joint values (or an (N, {self.n}) batch), "
                            f"got {describe(q)}") from None
        if arr.ndim == 1 and arr.shape[0] == self.n:
            return self._single(arr.tolist())
        if arr.ndim == 2 and arr.shape[1] == self.n:
            out = self._batch(np.ascontiguousarray(arr.T))
            return out.transpose(2, 0, 1)
        raise ValueError(f"q must have shape ({self.n},) or (N, {self.n}) for this {self.n}-joint chain, "
                         f"got {describe(q)}")


def compile_matrix(expr: sp.MatrixBase, args: Sequence[sp.Symbol], name: str = "matrix") -> CompiledMatrix:
    """Compile a SymPy matrix in the symbols ``args`` to fast NumPy code (see :class:`CompiledMatrix`)."""
    return CompiledMatrix(expr, args, name)
