"""Numeric code generated from exact SymPy expressions (the fast path of :class:`SerialChain`).

The *unsimplified* product-of-exponentials expression is reduced by common-subexpression
elimination (``sympy.cse``) and printed as straight-line Python twice:

* over ``math`` for a single configuration: floats in, the entries packed straight into a fresh
  NumPy array (``struct.pack_into``, no intermediate list);
* over NumPy with the batch on the last axis, in blocks of ``BLOCK`` configurations, as ufunc
  calls with ``out=`` (``_mul(a, b, out=_t3)``): every value lands in a row of one scratch array
  allocated per call, or straight in its slot of the result, so a block allocates nothing; a
  row is reused once its temporary is dead, each entry is written as soon as its temporaries
  exist, and sums share their common factors (``a*(b + c)``). The result is an (N, rows, cols)
  view (constant entries are written once, not per block). sin a and cos a come together from
  t = tan(a/2) (sin a = 2t/(1 + t²), cos a = 2/(1 + t²) − 1; equal to rounding, ≤ 2 ulp of 1):
  for a 6-joint arm np.sin and np.cos were over half of the time. One transcendental call instead
  of two, and NumPy's float64 tan runs on SIMD lanes where it can (AVX-512: ≈ 1.4 ns a value)
  while its sin and cos are scalar (≈ 8 ns each): sin and cos of an angle 18 ns → 3 ns on the
  machine of ``make bench``, 16 ns → 9 ns there with AVX-512 switched off (``NPY_DISABLE_CPU_FEATURES``).

:class:`~kinlib.chains.SerialChain` records its matrices on a :class:`kinlib.tape.Tape` (the recursions of
``SerialChain._numeric_form``: points carried joint by joint rather than whole 4×4 products, the
chain's constants as floats) and hands the recorded expressions to cse: the same matrices to
rounding, with few operations left after cse, in a fraction of a second whatever the size of the
chain's exact numbers (building the exact SymPy expression of a dense 7-joint arm took seconds).
Simplified expressions would be slower: simplification destroys the shared subexpressions. The printer only rearranges what it prints (rationals as
float literals, ``c - a*b`` rather than ``-a*b + c``, ``(x*x)`` rather than ``x**2``), so the
numbers agree with the expression to rounding.
``CompiledMatrix.source`` holds the generated code; :meth:`CompiledMatrix.javascript` prints the same
temporaries and entries as a JavaScript function (SymPy's JavaScript printer), for the explorers that compute
in the browser (:mod:`kinlib.widgets`); :meth:`CompiledMatrix.compile_native` the same as C (:mod:`kinlib.native`: the
single call compiled after 1000 calls, in the background, with the same floats).
"""

from __future__ import annotations

import math
import re
import struct
from collections.abc import Sequence

import numpy as np
import sympy as sp
from sympy.printing.jscode import JavascriptCodePrinter
from sympy.printing.precedence import precedence
from sympy.printing.pycode import PythonCodePrinter

from .._backend import describe
from . import native
from .native import ArithmeticRules

__all__ = ["CompiledMatrix", "javascript_function"]

_MATH = {name: getattr(math, name) for name in ("sin", "cos", "tan", "sqrt", "exp", "log", "atan2", "pi", "e")}
_NUMPY = {
    "sin": np.sin,
    "cos": np.cos,
    "tan": np.tan,
    "sqrt": np.sqrt,
    "exp": np.exp,
    "log": np.log,
    "atan2": np.arctan2,
    "pi": math.pi,
    "e": math.e,
}

#: configurations per block in the batched code: the live temporaries of a block stay in cache
BLOCK = 8192


class _Printer(ArithmeticRules, PythonCodePrinter):
    """Python printer for generated numeric code: fewer operations, same value (the rules the C printer of
    :mod:`kinlib.native` shares)."""

    def __init__(self):
        super().__init__({"fully_qualified_modules": False, "standard": "python3"})


class _JSPrinter(JavascriptCodePrinter):
    """JavaScript printer for generated numeric code: rationals as float literals (the same correctly rounded
    double as in the Python code), small integer powers as products."""

    def _print_Rational(self, expr):
        return repr(float(expr))

    def _print_Half(self, expr):
        return "0.5"

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Pow(self, expr):
        b, e = expr.args
        if e.is_Integer and 2 <= int(e) <= 4:
            base = self.parenthesize(b, precedence(expr), strict=False)
            return "(" + "*".join([base] * int(e)) + ")"
        if e.is_Integer and int(e) == -1:
            return "(1/" + self.parenthesize(b, precedence(expr), strict=False) + ")"
        return super()._print_Pow(expr)


_JS_NAME = re.compile(r"^[A-Za-z_$][A-Za-z0-9_$]*$")


def javascript_function(repl, reduced, n: int, name: str) -> str:
    """``function name(q) {…}``: JavaScript for cse pieces (``repl`` a list of (temporary, expression),
    ``reduced`` the entries, both in the joint symbols ``_q0 … _q{n−1}``) returning the entries as an Array.

    >>> x0, q0 = sp.symbols("_x0 _q0")
    >>> print(javascript_function([(x0, sp.sin(q0))], [x0, x0**2 / 2], 1, "f"))
    function f(q) {
      const _q0 = q[0];
      const _x0 = Math.sin(_q0);
      return [_x0, (0.5)*(_x0*_x0)];
    }
    """
    if not isinstance(name, str) or not _JS_NAME.match(name):
        raise ValueError(f"name must be a JavaScript identifier, got {describe(name)}")
    pr = _JSPrinter()
    lines = [f"function {name}(q) {{"]
    if n:
        lines.append("  const " + ", ".join(f"_q{i} = q[{i}]" for i in range(n)) + ";")
    lines += [f"  const {s} = {pr.doprint(e)};" for s, e in repl]
    items = [repr(v) if (v := _constant(e)) is not None else pr.doprint(e) for e in reduced]
    lines += ["  return [" + ", ".join(items) + "];", "}"]
    return "\n".join(lines)


def _constant(e: sp.Expr):
    """The float value of a constant entry, else None."""
    if e.free_symbols:
        return None
    try:
        return float(e)
    except TypeError:  # e.g. complex: let the generated code raise
        return None


_UFUNCS = {"_mul": np.multiply, "_add": np.add, "_sub": np.subtract, "_neg": np.negative, "_div": np.divide}
_UFUNC_OF = {sp.sin: "sin", sp.cos: "cos", sp.tan: "tan", sp.exp: "exp", sp.log: "log"}


def _factors(term) -> list:
    """What a product term is a multiple of: its plain symbols and its rational coefficient's size."""
    c = term.as_coeff_Mul()[0]
    fs = [f for f in sp.Mul.make_args(term) if f.is_Symbol]
    return fs + [abs(c)] if c.is_Rational and abs(c) != 1 else fs


def _collect(e):
    """Factor the most shared symbol out of each sum, recursively: a*b + a*c - d -> a*(b + c) - d.

    Fewer multiplications for the batched code; the value is the same to rounding."""
    if e.is_Atom:
        return e
    args = [_collect(a) for a in e.args]
    if not e.is_Add:
        return e.func(*args, evaluate=False) if e.is_Mul else e.func(*args)
    return _collect_sum(args)


def _collect_sum(terms: list):
    count: dict = {}
    for t in terms:
        for f in set(_factors(t)):
            count[f] = count.get(f, 0) + 1
    best = max(count, key=lambda f: (count[f], str(f)), default=None)
    if best is None or count[best] < 2:
        return sp.Add(*terms, evaluate=False) if len(terms) > 1 else terms[0]
    inner, rest = [], []
    for t in terms:
        if best in _factors(t):
            inner.append(t / best if best.is_Number else sp.Mul(*[f for f in sp.Mul.make_args(t) if f != best]))
        else:
            rest.append(t)
    shared = sp.Mul(best, _collect_sum(inner), evaluate=False)
    return sp.Add(shared, _collect_sum(rest), evaluate=False) if rest else shared


def _half_angle(repl, reduced):
    """Name every sin(a) and cos(a) for the batched code: (repl, reduced, trig) with the symbols
    ``_sinK``/``_cosK`` in place of them and a definition of each just before its first use
    (``trig`` maps each symbol to (a, sin symbol, cos symbol); the emitter computes the pair at once)."""
    calls = set()
    for e in [e for _, e in repl] + list(reduced):
        calls |= e.atoms(sp.sin, sp.cos)
    if not calls:
        return repl, reduced, {}
    args = sorted({f.args[0] for f in calls}, key=sp.default_sort_key)
    named = {e: s for s, e in repl if e in calls}  # a temporary that is just sin(a) keeps its name
    sub, trig = {}, {}
    for k, a in enumerate(args):
        pair = [
            named.get(sp.sin(a), sp.Symbol(f"_sin{k}")) if sp.sin(a) in calls else None,
            named.get(sp.cos(a), sp.Symbol(f"_cos{k}")) if sp.cos(a) in calls else None,
        ]
        for f, sym in zip((sp.sin, sp.cos), pair):
            if sym is not None:
                sub[f(a)] = sym
                trig[sym] = (a, *pair)
    out, done = [], set()

    def define(syms):
        for sym in sorted(syms & trig.keys() - done, key=str):
            a = trig[sym][0]
            out.append((sym, sp.sin(a) if sym == trig[sym][1] else sp.cos(a)))
            done.add(sym)

    for s, e in repl:
        if s in trig:
            define({s})
            continue
        e = e.xreplace(sub)
        define(e.free_symbols)
        out.append((s, e))
    reduced = [e.xreplace(sub) for e in reduced]
    define(set(trig))  # used by the outputs only
    return out, reduced, trig


class _BatchEmitter:
    """Straight-line ufunc calls with ``out=``: every value of a block lands in a preallocated scratch
    row ``_tK`` (or straight in its ``out`` slot), so a block allocates nothing.

    A cse temporary holds its row from its definition to its last use; the pieces of one statement
    hold theirs for the statement. Signs are folded into the sums (``a - b`` rather than ``a + (-b)``).
    """

    def __init__(self, printer, trig=None):
        self.pr = printer
        self.trig = trig or {}  # symbol standing for sin(a) or cos(a) -> (a, its sin symbol, its cos symbol)
        self.nbuf = 0
        self.free: list[int] = []
        self.name: dict = {}  # cse symbol or joint symbol -> the name holding it
        self.lines: list[str] = []
        self._buf_of: dict = {}
        self.negated: set = set()  # temporaries whose row holds minus their value

    def _alloc(self) -> str:
        k = self.free.pop() if self.free else self.nbuf
        self.nbuf = max(self.nbuf, k + 1)
        return f"_t{k}"

    def _release(self, buf: str):
        self.free.append(int(buf[2:]))

    def _add_constant(self, src: str, neg: bool, k: float, dest: str) -> None:
        """dest = (−src if neg else src) + k, for a nonzero constant k."""
        if neg:
            self.lines.append(f"_sub({self._num(k)}, {src}, out={dest})")
        elif k > 0:
            self.lines.append(f"_add({src}, {self._num(k)}, out={dest})")
        else:
            self.lines.append(f"_sub({src}, {self._num(-k)}, out={dest})")

    def _num(self, v) -> str:
        return repr(float(v))

    def _emit_trig(self, s) -> None:
        """sin a and cos a together from one t = tan(a/2): r = 2/(1 + t²), sin a = t·r, cos a = r − 1
        (one tan and six cheap passes instead of np.sin and np.cos: see the module docstring)."""
        a, sin_s, cos_s = self.trig[s]
        h, r = self._alloc(), self._alloc()
        self._emit(a * sp.Rational(1, 2), h)
        self.lines += [
            f"tan({h}, out={h})",
            f"_mul({h}, {h}, out={r})",
            f"_add({r}, 1.0, out={r})",
            f"_div(2.0, {r}, out={r})",
        ]
        for sym, row, line in ((sin_s, h, f"_mul({h}, {r}, out={h})"), (cos_s, r, f"_sub({r}, 1.0, out={r})")):
            if sym is None:
                self._release(row)
            else:
                self.lines.append(f"{sym} = {line}")
                self.name[sym], self._buf_of[sym] = str(sym), row

    def _operand(self, e, scratch: list):
        """(text, negated): a name or a number as it is, anything else computed into a scratch row."""
        if e in self.name:
            return self.name[e], e in self.negated
        if e.is_Number:
            return self._num(e), False
        if e.is_Mul and e.args[0] == -1 and len(e.args) == 2 and e.args[1] in self.name:
            return self.name[e.args[1]], e.args[1] not in self.negated  # -x: the name, negated
        buf = self._alloc()
        scratch.append(buf)
        return buf, self._emit(e, buf, allow_neg=True)

    def _emit(self, e, dest: str, allow_neg: bool = False) -> bool:
        """Emit code leaving e in dest (or -e, returning True, when allow_neg); returns whether negated."""
        scratch: list[str] = []
        if e.is_Mul:
            neg = self._emit_mul(e, dest, allow_neg, scratch)
        elif e.is_Add:
            neg = self._emit_add(e, dest, allow_neg, scratch)
        elif isinstance(e, sp.Function) and e.func in _UFUNC_OF and len(e.args) == 1:
            neg = self._emit_ufunc(e, dest, scratch)
        elif e in self.name:
            neg = self._emit_name(e, dest, allow_neg)
        else:  # anything else: the NumPy expression as printed, assigned into dest
            neg = self._emit_printed(e, dest)
        for b in scratch:
            self._release(b)
        if neg and not allow_neg:
            self.lines.append(f"_neg({dest}, out={dest})")
            neg = False
        return neg

    @staticmethod
    def _mul_factors(e):
        """(coefficient, factors, divisors) of a product: small integer powers written out as repeated factors,
        x**-1 as a divisor."""
        coeff, factors = e.as_coeff_mul()
        flat, divs = [], []
        for f in factors:
            if f.is_Pow and f.exp.is_Integer and 2 <= int(f.exp) <= 4:
                flat += [f.base] * int(f.exp)
            elif f.is_Pow and f.exp.is_Integer and int(f.exp) == -1:
                divs.append(f.base)
            else:
                flat.append(f)
        return coeff, flat, divs

    def _emit_mul(self, e, dest: str, allow_neg: bool, scratch: list) -> bool:
        """dest = a product: its factors multiplied in order, then the coefficient, then the divisors."""
        coeff, flat, divs = self._mul_factors(e)
        neg = bool(coeff < 0)
        c = abs(coeff)
        if not flat:
            flat, c = [sp.Float(float(c))], sp.S.One
        ops = []
        for f in flat:
            txt, fneg = (self._num(f), False) if f.is_Number else self._operand(f, scratch)
            ops.append(txt)
            neg ^= fneg
        if len(ops) == 1:
            c, neg = self._mul_single(ops[0], c, neg, bool(divs), dest, allow_neg)
        else:
            self.lines.append(f"_mul({ops[0]}, {ops[1]}, out={dest})")
            for o in ops[2:]:
                self.lines.append(f"_mul({dest}, {o}, out={dest})")
        if c != 1:
            if neg and not allow_neg:
                c, neg = -c, False
            self.lines.append(f"_mul({dest}, {self._num(c)}, out={dest})")
        for d in divs:
            txt, dneg = self._operand(d, scratch)
            self.lines.append(f"_div({dest}, {txt}, out={dest})")
            neg ^= dneg
        return neg

    def _mul_single(self, op: str, c, neg: bool, divs: bool, dest: str, allow_neg: bool):
        """dest = one factor (times c when c ≠ 1, folding a sign into c): the (c, neg) still to apply."""
        if c != 1:
            if neg and not allow_neg:
                c, neg = -c, False
            self.lines.append(f"_mul({op}, {self._num(c)}, out={dest})")
            return sp.S.One, neg
        if divs:
            self.lines.append(f"_div({op}, 1.0, out={dest})")
        elif neg and not allow_neg:
            self.lines.append(f"_neg({op}, out={dest})")
            neg = False
        else:
            self.lines.append(f"{dest}[...] = {op}")
        return c, neg

    def _emit_add(self, e, dest: str, allow_neg: bool, scratch: list) -> bool:
        """dest = a sum: a computed positive term straight into dest, the names and scratch rows added to it
        with the signs folded into _add/_sub, the constant last."""
        const = sp.S.Zero
        terms = []
        for t in e.args:
            if t.is_Number:
                const += t
            else:
                terms.append(t)
        # a computed positive term goes straight into dest; the rest are names or scratch rows
        first = next((t for t in terms if t not in self.name and not t.could_extract_minus_sign()), None)
        acc_neg = None  # None: dest not started
        if first is not None:
            acc_neg = self._emit(first, dest, allow_neg=True)
            terms.remove(first)
        pending = None  # a first term not yet combined: (text, negated)
        for t in terms:
            if t in self.name:
                txt, tneg = self.name[t], t in self.negated
            else:
                txt, tneg = self._operand(t, scratch)
            if acc_neg is None and pending is None:
                pending = (txt, tneg)
            elif pending is not None:
                acc_neg, pending = self._add_pair(pending, txt, tneg, dest), None
            else:
                acc_neg = self._add_to(dest, acc_neg, txt, tneg)
        if pending is not None:  # a single term (and maybe a constant)
            acc_neg, const = self._add_single(pending, const, dest, allow_neg)
        if const != 0:  # when acc_neg, dest holds −(sum): the value is k − dest
            self._add_constant(dest, acc_neg, float(const), dest)
            acc_neg = False
        return bool(acc_neg)

    def _add_pair(self, first: tuple, txt: str, tneg: bool, dest: str) -> bool:
        """dest = the first two terms (each a name or row, maybe holding minus its value): whether dest is negated."""
        a, aneg = first
        if aneg == tneg:
            self.lines.append(f"_add({a}, {txt}, out={dest})")
            return aneg
        if tneg:
            self.lines.append(f"_sub({a}, {txt}, out={dest})")
        else:
            self.lines.append(f"_sub({txt}, {a}, out={dest})")
        return False

    def _add_to(self, dest: str, acc_neg: bool, txt: str, tneg: bool) -> bool:
        """dest += one more term (dest and the term each maybe negated): whether dest is negated."""
        if acc_neg == tneg:
            self.lines.append(f"_add({dest}, {txt}, out={dest})")
        elif not acc_neg:
            self.lines.append(f"_sub({dest}, {txt}, out={dest})")
        else:
            self.lines.append(f"_sub({txt}, {dest}, out={dest})")
            acc_neg = False
        return acc_neg

    def _add_single(self, term: tuple, const, dest: str, allow_neg: bool):
        """dest = a sum's only term (plus its constant when there is one): (negated, the constant still to add)."""
        a, acc_neg = term
        if const != 0:
            self._add_constant(a, acc_neg, float(const), dest)
            return False, sp.S.Zero
        if acc_neg and not allow_neg:
            self.lines.append(f"_neg({a}, out={dest})")
            acc_neg = False
        else:
            self.lines.append(f"{dest}[...] = {a}")
        return acc_neg, const

    def _emit_ufunc(self, e, dest: str, scratch: list) -> bool:
        """dest = f(argument) for a function NumPy has as a ufunc (sin, cos, sqrt, …)."""
        arg, aneg = self._operand(e.args[0], scratch)
        if aneg:  # rare: fix the sign of the argument first
            self.lines.append(f"_neg({arg}, out={dest})")
            arg = dest
        self.lines.append(f"{_UFUNC_OF[e.func]}({arg}, out={dest})")
        return False

    def _emit_name(self, e, dest: str, allow_neg: bool) -> bool:
        """dest = a temporary or joint that already has a name."""
        if e in self.negated and not allow_neg:
            self.lines.append(f"_neg({self.name[e]}, out={dest})")
            return False
        self.lines.append(f"{dest}[...] = {self.name[e]}")
        return e in self.negated

    def _emit_printed(self, e, dest: str) -> bool:
        """dest = the NumPy expression as SymPy's printer writes it, the named symbols by their names."""
        names = {s: (-1 if s in self.negated else 1) * sp.Symbol(n) for s, n in self.name.items() if s.is_Symbol}
        self.lines.append(f"{dest}[...] = {self.pr.doprint(e.xreplace(names))}")
        return False

    def emit_block(self, repl, outputs) -> list[str]:
        """Lines computing the cse temporaries ``repl`` and writing each (slot, expr) of ``outputs``."""
        stmts, last = self._schedule(repl, outputs)
        for sym in set().union(*(e.free_symbols for _, e, _ in stmts)):
            if str(sym).startswith("_q"):
                self.name[sym] = str(sym)
        for j, (s, e, slot) in enumerate(stmts):
            if s in self.trig:  # with its partner (sin a with cos a), at the first use of either
                if s not in self.name:
                    self._emit_trig(s)
                self._release_dead(e, j, last)
                continue
            e = _collect(e)
            if s is None:
                self._emit_output(e, slot)
            elif last.get(s, -1) < 0:
                continue  # unused temporary
            else:
                buf = self._emit_temporary(s, e)
            self._release_dead(e, j, last)
            if s is not None:
                self._buf_of[s] = buf
        return self.lines

    @staticmethod
    def _schedule(repl, outputs):
        """The statements in order, (temporary or None, expr, output slot or None), each output right after the
        last temporary it needs (temporaries die early, fewer rows live); and each symbol's last statement."""
        where = {s: j for j, (s, _) in enumerate(repl)}
        after: dict[int, list] = {}
        for slot, e in outputs:
            after.setdefault(max((where[x] for x in e.free_symbols if x in where), default=-1), []).append((slot, e))
        stmts = [(None, e, slot) for slot, e in after.get(-1, [])]
        for j, (s, e) in enumerate(repl):
            stmts += [(s, e, None)] + [(None, oe, slot) for slot, oe in after.get(j, [])]
        last = {}
        for j, (_, e, _) in enumerate(stmts):
            for sym in e.free_symbols:
                last[sym] = j
        return stmts, last

    def _emit_temporary(self, s, e) -> str:
        """Compute the temporary s = e into a fresh row, named s where the row is first written: the row."""
        start = len(self.lines)
        buf = self._alloc()
        if self._emit(e, buf, allow_neg=True):  # the row holds -s: users fold the sign in
            self.negated.add(s)
        self.name[s] = str(s)
        # bind the name where the row is first written; later calls use the name
        pat = re.compile(rf"\b{buf}\b")
        k = next((i for i in range(start, len(self.lines)) if pat.search(self.lines[i])), None)
        if k is not None and self.lines[k].endswith(f"out={buf})") and pat.subn("", self.lines[k])[1] == 1:
            self.lines[k] = f"{s} = {self.lines[k]}"
            self.lines[k + 1 :] = [pat.sub(str(s), ln) for ln in self.lines[k + 1 :]]
        else:
            self.lines[start:] = [pat.sub(str(s), ln) for ln in self.lines[start:]]
            self.lines.insert(start, f"{s} = {buf}")
        return buf

    def _emit_output(self, e, slot: str) -> None:
        """Write e into the output view ``slot``."""
        if e.is_Symbol and e in self.name and e in self.negated:
            self.lines.append(f"_neg({self.name[e]}, out={slot})")
        elif e.is_Symbol and e in self.name:
            self.lines.append(f"{slot} = {self.name[e]}")
        else:
            n0 = len(self.lines)
            self._emit(e, "_o")
            if len(self.lines) - n0 == 1:
                self.lines[-1] = re.sub(r"\b_o\b", slot, self.lines[-1])
            else:
                self.lines.insert(n0, f"_o = {slot}")

    def _release_dead(self, e, j: int, last: dict) -> None:
        """Free the rows of the temporaries in e whose last use is statement j."""
        for sym in e.free_symbols:
            if last.get(sym) == j and sym in self.name and not str(sym).startswith("_q"):
                self._release(self._buf_of[sym])


class CompiledMatrix:
    """A matrix expression in ``args`` compiled to NumPy code; call it with q of shape (n,) or (N, n).

    The code for one configuration is generated at once; the batched code on the first batched
    call (or when ``source`` is read). :meth:`from_pieces` starts from common subexpressions that
    are already known (e.g. from a :class:`kinlib.tape.Tape`).

    >>> import sympy as sp
    >>> x, y = sp.symbols("x y", real=True)
    >>> c = CompiledMatrix(sp.Matrix([[sp.cos(x), x * y]]), [x, y])
    >>> c([0.5, 2.0]).round(6).tolist()   # one configuration: a (1, 2) array
    [[0.877583, 1.0]]
    >>> c(np.array([[0.5, 2.0], [0.0, 3.0], [1.0, 1.0]])).shape   # a batch of three
    (3, 1, 2)
    """

    def __init__(self, expr: sp.MatrixBase, args: Sequence[sp.Symbol], name: str = "matrix"):
        expr = sp.Matrix(expr)
        args = tuple(args)
        local = [sp.Symbol(f"_q{i}") for i in range(len(args))]
        # cse first, then rename the joint symbols in the (small) reduced pieces: xreplace on the
        # unreduced tree revisits every shared subtree (seconds for a dense 6-joint arm)
        tmp = sp.numbered_symbols("_x")
        repl, reduced = sp.cse(list(expr), symbols=tmp, order="none")  # canonical ordering: same code, ~6× slower
        ren = dict(zip(args, local))
        repl = [(s, e.xreplace(ren)) for s, e in repl]
        reduced = [e.xreplace(ren) for e in reduced]
        self._setup(repl, reduced, args, expr.shape, name)

    @classmethod
    def from_pieces(
        cls, repl, reduced, args: Sequence[sp.Symbol], shape: tuple[int, int], name: str = "matrix"
    ) -> CompiledMatrix:
        """Compile from cse-style pieces: ``repl`` a list of (temporary symbol ``_xK``, expression), each
        using only earlier temporaries and the joint symbols ``_q0 … _q{n−1}`` (for ``args``), and
        ``reduced`` the rows·cols entries (row-major) in those symbols.

        >>> x0, q0 = sp.symbols("_x0 _q0")
        >>> c = CompiledMatrix.from_pieces([(x0, sp.sin(q0))], [x0, 2 * x0], [sp.Symbol("t")], (1, 2))
        >>> c([0.5]).round(6).tolist()
        [[0.479426, 0.958851]]
        """
        self = cls.__new__(cls)
        self._setup(list(repl), list(reduced), tuple(args), tuple(shape), name)
        return self

    def _setup(self, repl, reduced, args, shape, name):
        self.shape = shape
        self.args = args
        self.n = len(args)
        self.name = name
        local = [sp.Symbol(f"_q{i}") for i in range(self.n)]
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
            raise ValueError(
                f"cannot generate numeric code for {name}: it still has the free symbols "
                f"{sorted(map(str, extra))} besides the joint variables; give them values first"
            )
        self._repl, self._reduced = repl, reduced
        pr = _Printer()
        r, c = self.shape
        size = r * c
        temps = [(str(s), pr.doprint(e)) for s, e in repl]
        self._consts = consts = [_constant(e) for e in reduced]
        items = [repr(v) if v is not None else pr.doprint(e) for v, e in zip(consts, reduced)]
        self._names = names = ", ".join(map(str, local)) + ("," if self.n == 1 else "")

        # one configuration: math functions on floats, entries packed into a fresh array
        single = ["def _single(q):"]
        if self.n:
            single.append(f"    {names} = q")
        single += [f"    {s} = {e}" for s, e in temps]
        single += [f"    out = _empty(({r}, {c}))", f"    _pack(out, 0, {', '.join(items)})", "    return out"]
        self._single_source = "\n".join(single)
        self._batch_source = None
        ns_single = dict(_MATH, _empty=np.empty, _pack=struct.Struct(f"{size}d").pack_into)
        exec(compile(self._single_source, f"<kinlib {name} single>", "exec"), ns_single)
        # the compiled C of the same pieces (kinlib.native): after HOT_CALLS single calls, or compile_native()
        self._native = native.NativeSingle(repl, reduced, self.n, self.shape, name, self._single_source)
        self._fast = None  # its single(q) once loaded: a plain joint vector in, the array out (else None)
        self._single = self._native.counting(ns_single["_single"], self, lambda: self.compile_native(wait=False))

    def compile_native(self, wait: bool = True) -> bool:
        """Use compiled C for the single-configuration call from now on (see :mod:`kinlib.native`): loaded from
        the cache, or compiled now (``wait=True``, ≈ 0.2–0.5 s) or in a background thread (``wait=False``);
        True once it is in use. Without a C compiler (or with ``KINLIB_COMPILE=0``, in Pyodide) it returns False
        and the Python code stays, with the reason in :attr:`native_status`. The numbers are the same.

        >>> x = sp.Symbol("x", real=True)
        >>> c = CompiledMatrix(sp.Matrix([[sp.sin(x), x / 3]]), [x])
        >>> before = c([0.5])   # the Python code
        >>> c.compile_native() == c.native_status.startswith("C")
        True
        >>> c([0.5]).tolist() == before.tolist()   # the same floats, bit for bit
        True
        """

        def ready(fn):
            self._fast = fn

        return self._native.build(wait, ready)

    @property
    def native_status(self) -> str:
        """What the single-configuration call runs: ``C (...)`` or ``Python: <why>`` (see :meth:`compile_native`).

        >>> CompiledMatrix(sp.Matrix([[1]]), []).native_status
        'Python (not compiled yet)'
        """
        return self._native.status

    def _batch(self, q):
        """The batched code (generated on its first call): (N, n) in, (rows, cols, N) out."""
        if self._batch_source is None:
            self._make_batch()
        return self._batch_fn(q)

    def _make_batch(self) -> None:
        # a batch q of shape (N, n), computed on the last axis of out, block by block; constant
        # entries written once; each joint's block is read in place (a strided column of q)
        repl, reduced, consts, names = self._repl, self._reduced, self._consts, self._names
        r, c = self.shape
        batch = ["def _batch(q):", "    N = q.shape[0]", f"    out = _empty(({r}, {c}, N))"]
        for k, v in enumerate(consts):
            if v is not None:
                batch.append(f"    out[{k // c}, {k % c}] = {v!r}")
        varying = [k for k, v in enumerate(consts) if v is None]
        if varying:
            brepl, bred, trig = _half_angle(repl, reduced)
            em = _BatchEmitter(_Printer(), trig)
            body = em.emit_block(brepl, [(f"out[{k // c}, {k % c}, _s:_e]", bred[k]) for k in varying])
            batch += [
                f"    _B = min(N, {BLOCK})",
                f"    _buf = _empty(({max(em.nbuf, 1)}, _B))  # scratch rows, reused block after block",
            ]
            batch += [f"    for _s in range(0, N, {BLOCK}):", f"        _e = min(_s + {BLOCK}, N)"]
            if em.nbuf:
                batch.append(f"        {', '.join(f'_t{i}' for i in range(em.nbuf))}, = _buf[:, :_e - _s]")
            if self.n:
                batch.append(f"        {names} = q[_s:_e].T")
            batch += [f"        {line}" for line in body]
        batch.append("    return out")
        source = "\n".join(batch)
        ns_batch = dict(_NUMPY, _empty=np.empty, **_UFUNCS)
        exec(compile(source, f"<kinlib {self.name} batch>", "exec"), ns_batch)
        self._batch_fn = ns_batch["_batch"]
        self._batch_source = source

    def javascript(self, name: str = "matrix") -> str:
        """The same straight-line code as a JavaScript ``function name(q)`` returning the rows·cols entries
        (row-major) as an Array: the temporaries and entries this matrix was compiled from, printed by SymPy's
        JavaScript printer (see :func:`javascript_function`).

        >>> x = sp.Symbol("x", real=True)
        >>> print(CompiledMatrix(sp.Matrix([[sp.cos(x), 1]]), [x]).javascript("f"))
        function f(q) {
          const _q0 = q[0];
          return [Math.cos(_q0), 1.0];
        }
        """
        return javascript_function(self._repl, self._reduced, self.n, name)

    @property
    def source(self) -> str:
        """The generated code: ``_single`` (one configuration) and ``_batch`` (N configurations)."""
        if self._batch_source is None:
            self._make_batch()
        return self._single_source + "\n\n" + self._batch_source + "\n"

    def __call__(self, q):
        """Evaluate at q: shape (n,) gives (rows, cols); shape (N, n) gives (N, rows, cols)."""
        if self._fast is not None and (out := self._fast(q)) is not None:
            return out  # compiled C: a plain finite joint vector (anything else: None, and the checks below)
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
            raise TypeError(
                f"q must hold {self.n} real joint values (or an (N, {self.n}) batch), got {describe(q)}: {repr(q)[:80]}"
            ) from None
        if arr.ndim == 1 and arr.shape[0] == self.n:
            return self._single(arr.tolist())
        if arr.ndim == 2 and arr.shape[1] == self.n:
            out = self._batch(arr)
            return out.transpose(2, 0, 1)
        raise ValueError(
            f"q must have shape ({self.n},) or (N, {self.n}) for this {self.n}-joint chain, got {describe(q)}"
        )
