"""The exact tree: a SymPy expression or matrix as a JSON tree of plain lists, and back by a whitelist.

An answer decided *exactly* in the grader (a ``property`` answer, problem 5.5; a constant exact subspace) is
carried as this tree (:func:`expr_tree`): numbers, symbols (real, or positive), π, +, ×, powers and
sin/cos/tan, nothing else. :func:`from_tree` rebuilds it from that whitelist (never ``eval``), with bounded
size, so a hostile tree cannot run code or exhaust the grader; :func:`exact_ranks` compares two constant
exact spans by exact ranks (:func:`kinlib.course.answers.subspace.compare_subspace`).
"""

from __future__ import annotations

import math

import sympy as sp

from .base import as_sympy
from .wire import safe_name

__all__ = ["expr_tree", "from_tree", "exact_ranks"]

_TREE_FUNCS = ("sin", "cos", "tan")
_TREE_MAX_NODES = 4000


def expr_tree(obj, max_nodes=_TREE_MAX_NODES):
    """A SymPy expression or matrix as a JSON tree of plain lists: a ``property`` answer (or a constant exact
    subspace) is decided exactly in the grader, which rebuilds it from a whitelist of numbers, symbols, π,
    +, ×, powers and sin/cos/tan (:func:`from_tree`). Raises ValueError for
    anything else or more than ``max_nodes`` nodes.

    >>> expr_tree(sp.Symbol("L", positive=True) * sp.cos(sp.Symbol("t")) + sp.Rational(1, 2))
    ['add', ['rat', '1', '2'], ['mul', ['sym', 'L', True], ['fn', 'cos', ['sym', 't', False]]]]
    """
    count = [0]

    def walk(e):
        count[0] += 1
        if count[0] > max_nodes:
            raise ValueError(f"more than {max_nodes} nodes")
        if isinstance(e, sp.Integer):
            return ["int", str(int(e))]
        if isinstance(e, sp.Rational):
            return ["rat", str(e.p), str(e.q)]
        if isinstance(e, sp.Float):
            return ["float", repr(float(e))]
        if e is sp.pi:
            return ["pi"]
        if isinstance(e, sp.Symbol):
            return ["sym", e.name, bool(e.is_positive)]
        if isinstance(e, sp.Add):
            return ["add", *[walk(a) for a in e.args]]
        if isinstance(e, sp.Mul):
            return ["mul", *[walk(a) for a in e.args]]
        if isinstance(e, sp.Pow):
            return ["pow", walk(e.base), walk(e.exp)]
        if isinstance(e, sp.Function) and type(e).__name__ in _TREE_FUNCS and len(e.args) == 1:
            return ["fn", type(e).__name__, walk(e.args[0])]
        raise ValueError(f"{type(e).__name__} is not supported here")

    if isinstance(obj, sp.MatrixBase):
        return ["matrix", obj.rows, obj.cols, *[walk(x) for x in obj]]
    return walk(as_sympy(obj))


def from_tree(t, syms: dict | None = None, budget: list | None = None):
    """Rebuild a student's expression from its JSON tree (:func:`expr_tree`) by a whitelist, never ``eval``:
    numbers (at most 60 digits), symbols (real, or positive as declared; named by a
    :func:`~kinlib.course.answers.wire.safe_name`), π, +, ×, powers with small exact
    exponents, sin/cos/tan. Anything else raises ValueError. ``syms`` collects the symbols made (one per name and
    assumption), ``budget`` ([nodes left]) bounds the size.

    >>> from_tree(["add", ["rat", "1", "2"], ["fn", "cos", ["sym", "theta1", False]]])
    cos(theta1) + 1/2
    >>> from_tree(["call", "__import__", "os"])
    Traceback (most recent call last):
    ...
    ValueError: 'call' is not supported here
    """
    syms = {} if syms is None else syms
    budget = [20_000] if budget is None else budget
    budget[0] -= 1
    if budget[0] < 0:
        raise ValueError("the expression is too large")
    if not isinstance(t, list) or not t or not isinstance(t[0], str):
        raise ValueError("malformed expression")
    op, args = t[0], t[1:]

    def digits(x):
        if not isinstance(x, str) or not 0 < len(x) <= 60 or not x.lstrip("-").isdigit():
            raise ValueError("malformed number")
        return int(x)

    if op == "int" and len(args) == 1:
        return sp.Integer(digits(args[0]))
    if op == "rat" and len(args) == 2:
        q = digits(args[1])
        if q == 0:
            raise ValueError("malformed number")
        return sp.Rational(digits(args[0]), q)
    if op == "float" and len(args) == 1 and isinstance(args[0], str) and len(args[0]) <= 40:
        x = float(args[0])
        if not math.isfinite(x):
            raise ValueError("not a finite number")
        return sp.Rational(x)  # its exact binary value (as kinlib.trigpoly takes floats)
    if op == "pi" and not args:
        return sp.pi
    if op == "sym" and len(args) == 2 and safe_name(args[0]) and len(args[0]) <= 40:
        key = (args[0], bool(args[1]))
        if key not in syms:
            syms[key] = sp.Symbol(args[0], positive=True) if args[1] else sp.Symbol(args[0], real=True)
        return syms[key]
    if op in ("add", "mul") and args:
        parts = [from_tree(a, syms, budget) for a in args]
        return sp.Add(*parts) if op == "add" else sp.Mul(*parts)
    if op == "pow" and len(args) == 2:
        base, exp = from_tree(args[0], syms, budget), from_tree(args[1], syms, budget)
        if not (exp.is_Rational and abs(exp.p) <= 12 and exp.q <= 2):
            raise ValueError("a power that is not a small whole number or half")
        return sp.Pow(base, exp)
    if op == "fn" and len(args) == 2 and args[0] in ("sin", "cos", "tan"):
        return getattr(sp, args[0])(from_tree(args[1], syms, budget))
    raise ValueError(f"{op!r} is not supported here")


def exact_ranks(stu_tree, ref_tree):
    """(rank A, rank B, rank [A B]) computed exactly for two constant exact matrices given as expression trees
    (:func:`expr_tree`; both sides must have one), or None (then the spans are compared numerically): when
    a tree is missing or malformed, has symbols, or SymPy cannot decide whether a pivot is zero. Equal spans ⇔
    rank A = rank B = rank [A B].

    >>> col = lambda *xs: ["matrix", len(xs), 1, *[["int", str(x)] for x in xs]]
    >>> exact_ranks(col(1, 0, 10**30), col(0, 0, 1)), exact_ranks(col(1, 0), ["sym", "x", False])
    ((1, 1, 2), None)
    """
    if not (isinstance(stu_tree, list) and isinstance(ref_tree, list)):
        return None
    mats = []
    try:
        for t in (stu_tree, ref_tree):
            if t[:1] != ["matrix"] or len(t) < 3 or not all(isinstance(x, int) and 0 < x <= 12 for x in t[1:3]):
                return None
            if len(t) != 3 + t[1] * t[2]:
                return None
            budget = [600]
            M = sp.Matrix(t[1], t[2], [from_tree(x, {}, budget) for x in t[3:]])
            if M.free_symbols:
                return None
            mats.append(M)
    except (ValueError, TypeError, RecursionError):
        return None
    A, B = mats
    if A.rows != B.rows:
        return None
    unsure = []

    def iszero(x):
        z = as_sympy(x).equals(0)
        if z is None:
            unsure.append(x)
        return bool(z)

    ranks = tuple(M.rank(iszerofunc=iszero) for M in (A, B, A.row_join(B)))
    return None if unsure else ranks
