"""Straight-line code recorded from arithmetic: the front end of the generated code of a chain.

A :class:`Tape` records what a formula does with the joint values θ_i, sin θ_i, cos θ_i and float
constants (:class:`TapeValue` supports ``+ - *``), folding constants (0·x, 1·x, like terms) and
recording each distinct product and sum once. ``Tape.compile`` turns the recorded entries into a
:class:`~kinlib.codegen.CompiledMatrix`. :class:`~kinlib.chains.SerialChain` runs its kinematic
recursions on a tape to generate its numeric code (issue 11, item 6: a dense 7-joint arm from URDF
placements went from seconds to a fraction of a second, the UR5's code is unchanged).
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from .._backend import describe
from .codegen import CompiledMatrix

__all__ = ["Tape", "TapeValue"]


class TapeValue:
    """A value recorded on a :class:`Tape`: ``const + Σ coef·node`` with float constants; nodes are joint
    values, their sines and cosines, products of two values, and sums multiplied by something.

    Arithmetic (``+ - *`` with numbers or other values of the same tape) folds constants as it goes:
    ``0·x`` is the number 0.0, ``1·x`` is x, like terms are merged; a result with no terms is a plain
    float. Equal products and sums are one node (recorded once), so shared work is found as it is
    built (``Tape.compile`` may still hand the result to ``sympy.cse`` for the last sub-products).

    >>> tp = Tape(1)
    >>> x = tp.q(0)
    >>> 0 * x, x - x, (2 * x + 3 * x).terms == (5 * x).terms
    (0.0, 0.0, True)
    """

    __slots__ = ("tape", "const", "terms")

    def __init__(self, tape: Tape, const: float, terms: dict):
        self.tape, self.const, self.terms = tape, const, terms

    def __add__(self, other):
        if type(other) is TapeValue:
            terms = dict(self.terms)
            for k, c in other.terms.items():
                v = terms.get(k, 0.0) + c
                if v == 0.0:
                    del terms[k]
                else:
                    terms[k] = v
            const = self.const + other.const
            return TapeValue(self.tape, const, terms) if terms else const
        other = float(other)
        return TapeValue(self.tape, self.const + other, self.terms) if other else self

    __radd__ = __add__

    def __neg__(self):
        return TapeValue(self.tape, -self.const, {k: -c for k, c in self.terms.items()})

    def __sub__(self, other):
        return self + (-other)

    def __rsub__(self, other):
        return (-self) + other

    def __mul__(self, other):
        if type(other) is not TapeValue:
            other = float(other)
            if other == 0.0:
                return 0.0
            if other == 1.0:
                return self
            return TapeValue(self.tape, self.const * other, {k: c * other for k, c in self.terms.items()})
        ca, na = self._factor()
        cb, nb = other._factor()
        node = self.tape._node(("mul", na, nb) if na <= nb else ("mul", nb, na))
        return TapeValue(self.tape, 0.0, {node: ca * cb})

    __rmul__ = __mul__

    def _factor(self) -> tuple[float, int]:
        """(c, node) with self = c·node: a single term as it is, anything else a sum node."""
        if not self.const and len(self.terms) == 1:
            ((k, c),) = self.terms.items()
            return c, k
        return 1.0, self.tape._node(("sum", self.const, tuple(sorted(self.terms.items()))))


class Tape:
    """Straight-line code recorded from arithmetic on numbers and the joint values of an n-joint chain.

    ``q(i)``, ``sin(i)``, ``cos(i)`` are the joint value θ_i and its sine and cosine as
    :class:`TapeValue` s; any formula evaluated on them (with float constants) is recorded, each
    distinct product and sum once, for a few microseconds per operation whatever the size of the
    exact numbers the constants came from. :meth:`compile` turns entries (values or numbers) into a
    :class:`~kinlib.codegen.CompiledMatrix` (recorded → ``sympy.cse`` → code for one configuration;
    the batched code on its first call).

    Formulas: whatever is recorded, e.g. T(θ) = e^{[S1]θ1} ⋯ e^{[Sn]θn} M as SerialChain records it.

    >>> tp = Tape(2)
    >>> s, c = tp.sin(0), tp.cos(0)
    >>> x = 0.5 * c + 2.0
    >>> f = tp.compile([[x * s, x * x - 1.0 * s * 0 + tp.q(1)]], sp.symbols("a b"))
    >>> f([0.0, 1.0]).tolist()
    [[0.0, 7.25]]
    """

    def __init__(self, n: int):
        self.n = n
        self.nodes: list[tuple] = []
        self._index: dict = {}

    def _node(self, key: tuple) -> int:
        k = self._index.get(key)
        if k is None:
            k = self._index[key] = len(self.nodes)
            self.nodes.append(key)
        return k

    def _leaf(self, kind: str, i: int) -> TapeValue:
        if not 0 <= i < self.n:
            raise ValueError(f"joint index must be in 0…{self.n - 1}, got {i!r}")
        return TapeValue(self, 0.0, {self._node((kind, i)): 1.0})

    def q(self, i: int) -> TapeValue:
        """θ_i (0-based)."""
        return self._leaf("q", i)

    def sin(self, i: int) -> TapeValue:
        """sin θ_i."""
        return self._leaf("sin", i)

    def cos(self, i: int) -> TapeValue:
        """cos θ_i."""
        return self._leaf("cos", i)

    def operation_count(self, entries) -> int:
        """Multiplications and additions left in the entries (each shared node counted once)."""
        used, ops = self._used(entries), 0
        for k in used:
            key = self.nodes[k]
            if key[0] == "mul":
                ops += 1
            elif key[0] == "sum":
                ops += len(key[2]) - 1 + (key[1] != 0) + sum(c not in (1.0, -1.0) for _, c in key[2])
        for e in self._flat(entries):
            if type(e) is TapeValue:
                ops += len(e.terms) - 1 + (e.const != 0) + sum(c not in (1.0, -1.0) for c in e.terms.values())
        return ops

    @staticmethod
    def _flat(entries) -> list:
        return [e for row in entries for e in row]

    def _used(self, entries) -> dict:
        """node -> number of uses, for the nodes the entries depend on."""
        uses: dict[int, int] = {}
        stack = [k for e in self._flat(entries) if type(e) is TapeValue for k in e.terms]
        while stack:
            k = stack.pop()
            uses[k] = uses.get(k, 0) + 1
            if uses[k] == 1:
                key = self.nodes[k]
                if key[0] == "mul":
                    stack += [key[1], key[2]]
                elif key[0] == "sum":
                    stack += [j for j, _ in key[2]]
        return uses

    def compile(self, entries, args: Sequence[sp.Symbol], name: str = "matrix", cse: bool = True) -> CompiledMatrix:
        """The :class:`CompiledMatrix` of a rectangular list of rows of entries (values or numbers).

        ``cse=True``: the recorded nodes are written out as one SymPy expression per entry (shared
        subtrees are shared objects, so this costs one step per node) and ``sympy.cse`` picks the
        temporaries: it also finds common sub-products and sub-sums the recording order hid, for the
        fewest operations (the UR5's T, J_s, J_b, J: 120, 152, 143, 135 Python operations). ``cse=False``:
        every node used twice or more is a temporary as recorded (faster to make, ≈ 10% more operations).
        Constants are exact SymPy numbers equal to the floats (printed back as the same floats).
        """
        entries = [list(row) for row in entries]
        shape = (len(entries), len(entries[0]) if entries else 0)
        if any(len(row) != shape[1] for row in entries) or len(args) != self.n:
            raise ValueError(
                f"entries must be a rectangular list of rows and args {self.n} symbols, "
                f"got {describe(entries)} and {describe(list(args))}"
            )
        uses = self._used(entries)
        qs = [sp.Symbol(f"_q{i}") for i in range(self.n)]
        expr: dict[int, sp.Expr] = {}
        repl = []
        num = {}

        def c(v: float):  # the float as an exact SymPy number (printed back as the same float)
            r = num.get(v)
            if r is None:
                r = num[v] = sp.Integer(int(v)) if v.is_integer() else sp.Rational(v)
            return r

        def value(e):
            if type(e) is not TapeValue:
                return c(float(e))
            return sp.Add(
                *([c(e.const)] if e.const else []),
                *[c(co) * expr[k] if co != 1.0 else expr[k] for k, co in e.terms.items()],
            )

        for k in sorted(uses):
            key = self.nodes[k]
            if key[0] == "q":
                expr[k] = qs[key[1]]
                continue
            if key[0] == "sin":
                e = sp.sin(qs[key[1]])
            elif key[0] == "cos":
                e = sp.cos(qs[key[1]])
            elif key[0] == "mul":
                e = expr[key[1]] * expr[key[2]]
            else:
                e = value(TapeValue(self, key[1], dict(key[2])))
            if not cse and (uses[k] > 1 or key[0] in ("sin", "cos")):
                s = sp.Symbol(f"_x{len(repl)}")
                repl.append((s, e))
                e = s
            expr[k] = e
        reduced = [value(e) for e in self._flat(entries)]
        if cse:
            repl, reduced = sp.cse(reduced, symbols=sp.numbered_symbols("_x"), order="none")
        return CompiledMatrix.from_pieces(repl, reduced, args, shape, name)
