"""Numeric code generated from exact SymPy expressions (the fast path of :class:`SerialChain`).

The *unsimplified* product-of-exponentials expression is reduced by common-subexpression
elimination (``sympy.cse``) and printed as straight-line Python twice:

* over ``math`` for a single configuration: floats in, the entries packed straight into a fresh
  NumPy array (``struct.pack_into``, no intermediate list);
* over NumPy with the batch on the last axis, in blocks of ``BLOCK`` configurations (each
  temporary is freed after its last use, so the live ones stay in cache), giving an
  (N, rows, cols) array (constant entries are written once, not per block).

Simplified expressions would be slower: simplification destroys the shared subexpressions. The
printer only rearranges what it prints (rationals as float literals, ``c - a*b`` rather than
``-a*b + c``, ``x*x`` rather than ``x**2``), so the numbers agree with the expression to rounding.
``CompiledMatrix.source`` holds the generated code.
"""
from __future__ import annotations

import math
import struct
from typing import Sequence

import numpy as np
import sympy as sp
from sympy.printing.precedence import precedence
from sympy.printing.pycode import PythonCodePrinter

from ._backend import describe

__all__ = ["CompiledMatrix", "compile_matrix"]

_MATH = {name: getattr(math, name) for name in ("sin", "cos", "tan", "sqrt", "exp", "log", "atan2", "pi", "e")}
_NUMPY = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "sqrt": np.sqrt, "exp": np.exp, "log": np.log,
          "atan2": np.arctan2, "pi": math.pi, "e": math.e}

#: configurations per block in the batched code: the live temporaries of a block stay in cache
BLOCK = 8192


class _Printer(PythonCodePrinter):
    """Python printer for generated numeric code: fewer operations, same value."""

    def __init__(self):
        super().__init__({"fully_qualified_modules": False, "standard": "python3"})

    def _print_Rational(self, expr):  # 89/1000 -> 0.089 (the same correctly rounded float)
        return repr(float(expr))

    def _print_Half(self, expr):
        return "0.5"

    def _print_Pow(self, expr, rational=False):
        b, e = expr.args
        if e.is_Integer and 2 <= int(e) <= 4:  # x*x is cheaper than x**2 for Python floats
            base = self.parenthesize(b, precedence(expr), strict=False)
            return "*".join([base] * int(e))
        return super()._print_Pow(expr, rational=rational)

    def _print_Add(self, expr, order=None):
        # print as the base class does, then put a '+' term first: 'c - a*b' saves a negation
        terms = self._as_ordered_terms(expr, order=order)
        prec = precedence(expr)
        items = []
        for term in terms:
            t = self._print(term)
            if t.startswith("-") and not term.is_Add:
                sign, t = "-", t[1:]
            else:
                sign = "+"
            if precedence(term) < prec or term.is_Add:
                t = f"({t})"
            items.append((sign, t))
        for k, (sign, _) in enumerate(items):
            if sign == "+":
                items.insert(0, items.pop(k))
                break
        first_sign, first = items[0]
        out = ("-" if first_sign == "-" else "") + first
        for sign, t in items[1:]:
            out += f" {sign} {t}"
        return out


def _constant(e: sp.Expr):
    """The float value of a constant entry, else None."""
    if e.free_symbols:
        return None
    try:
        return float(e)
    except TypeError:  # e.g. complex: let the generated code raise
        return None


class CompiledMatrix:
    """A matrix expression in ``args`` compiled to NumPy code; call it with q of shape (n,) or (N, n)."""

    def __init__(self, expr: sp.MatrixBase, args: Sequence[sp.Symbol], name: str = "matrix"):
        expr = sp.Matrix(expr)
        self.shape = expr.shape
        self.args = tuple(args)
        self.n = len(self.args)
        self.name = name
        local = [sp.Symbol(f"_q{i}") for i in range(self.n)]
        # cse first, then rename the joint symbols in the (small) reduced pieces: xreplace on the
        # unreduced tree revisits every shared subtree (seconds for a dense 6-joint arm)
        tmp = sp.numbered_symbols("_x")
        repl, reduced = sp.cse(list(expr), symbols=tmp, order="none")  # canonical ordering: same code, ~6× slower
        ren = dict(zip(self.args, local))
        repl = [(s, e.xreplace(ren)) for s, e in repl]
        reduced = [e.xreplace(ren) for e in reduced]
        # inline pure negations (_x17 = -_x16): later sums absorb the sign (c - a*b), saving a pass
        neg: dict = {}
        kept = []
        for s, e in repl:
            e = e.xreplace(neg) if neg else e
            if (-e).is_Symbol:
                neg[s] = e
            else:
                kept.append((s, e))
        repl = kept
        reduced = [e.xreplace(neg) for e in reduced] if neg else reduced
        known = set(local) | {s for s, _ in repl}
        extra = set().union(*(e.free_symbols for _, e in repl), *(e.free_symbols for e in reduced)) - known
        if extra:
            raise ValueError(f"cannot generate numeric code for {name}: it still has the free symbols "
                             f"{sorted(map(str, extra))} besides the joint variables; give them values first")
        pr = _Printer()
        r, c = self.shape
        size = r * c
        temps = [(str(s), pr.doprint(e)) for s, e in repl]
        consts = [_constant(e) for e in reduced]
        items = [repr(v) if v is not None else pr.doprint(e) for v, e in zip(consts, reduced)]
        names = ", ".join(map(str, local)) + ("," if self.n == 1 else "")

        # one configuration: math functions on floats, entries packed into a fresh array
        single = ["def _single(q):"]
        if self.n:
            single.append(f"    {names} = q")
        single += [f"    {s} = {e}" for s, e in temps]
        single += [f"    out = _empty(({r}, {c}))", f"    _pack(out, 0, {', '.join(items)})", "    return out"]

        # a batch, on the last axis, block by block; constant entries written once
        batch = ["def _batch(q):", "    N = q.shape[1]", f"    out = _empty(({r}, {c}, N))"]
        for k, v in enumerate(consts):
            if v is not None:
                batch.append(f"    out[{k // c}, {k % c}] = {v!r}")
        varying = [(k, it) for k, (it, v) in enumerate(zip(items, consts)) if v is None]
        if varying:
            batch += [f"    for _s in range(0, N, {BLOCK}):", f"        _e = _s + {BLOCK}"]
            if self.n:
                batch.append(f"        {names} = q[:, _s:_e]")
            # free each temporary after its last use, so the next one reuses its (cache-hot) memory
            stmts = [(f"{s} = {e}", repl[j][1]) for j, (s, e) in enumerate(temps)]
            stmts += [(f"out[{k // c}, {k % c}, _s:_e] = {it}", reduced[k]) for k, it in varying]
            last = {}
            for j, (_, e) in enumerate(stmts):
                for sym in e.free_symbols:
                    last[sym] = j
            dead: dict[int, list[str]] = {}
            for s, _ in repl:
                dead.setdefault(last.get(s, -1), []).append(str(s))
            for j, (line, _) in enumerate(stmts):
                batch.append(f"        {line}")
                if dead.get(j):
                    batch.append(f"        del {', '.join(dead[j])}")
        batch.append("    return out")

        self.source = "\n".join(single) + "\n\n" + "\n".join(batch) + "\n"
        ns_single = dict(_MATH, _empty=np.empty, _pack=struct.Struct(f"{size}d").pack_into)
        ns_batch = dict(_NUMPY, _empty=np.empty)
        exec(compile("\n".join(single), f"<kinlib {name} single>", "exec"), ns_single)
        exec(compile("\n".join(batch), f"<kinlib {name} batch>", "exec"), ns_batch)
        self._single = ns_single["_single"]
        self._batch = ns_batch["_batch"]

    def __call__(self, q):
        """Evaluate at q: shape (n,) gives (rows, cols); shape (N, n) gives (N, rows, cols)."""
        # fast path: a list/tuple of n numbers, or a float array of shape (n,)
        tq = type(q)
        if tq is np.ndarray:
            if q.ndim == 1 and q.shape[0] == self.n and q.dtype.kind == "f":
                return self._single(q.tolist())
        elif (tq is list or tq is tuple) and len(q) == self.n:
            try:
                return self._single(q)
            except (TypeError, ValueError, struct.error):
                pass  # not plain numbers: the checks below say what is wrong
        try:
            arr = np.asarray(q, dtype=float)
        except (TypeError, ValueError):
            raise TypeError(f"q must hold {self.n} real joint values (or an (N, {self.n}) batch), "
                            f"got {describe(q)}: {repr(q)[:80]}") from None
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
