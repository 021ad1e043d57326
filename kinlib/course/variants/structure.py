"""The proof that a variant is as well-posed as the original: its answers have the original's structure.

A variant is kept only if, answer by answer, the exact reference answers computed for it (by the notebook's own
code, in the replay kernel) have the same *structure* as the original's:

- the same kind, shape and type (a 6×3 matrix stays a 6×3 matrix, a dict keeps its keys);
- matrices and expressions in symbols keep their zero pattern and their free symbols (an entry that becomes
  identically 0, or a symbol that drops out, changes what the student is asked to find); a matrix of numbers keeps
  its shape (an entry that is 0 is still a number: a joint that does not help);
- integers and booleans are equal (a rank, "removes every singularity");
- a set of configurations keeps its number of singular families, per variable;
- a subspace keeps its dimension, and (one of numbers) the zero pattern of its reduced basis: one that lines up
  with the axes where the original's does not is another form;
- a choice keeps its form: one winner stays one winner, a tie stays a tie of as many joints.

Zero is decided exactly: SymPy's own ``is_zero``, then simplification, then (for a constant) its minimal
polynomial; an entry none of them decides makes the variant *undecided*, which rejects it (never a guess from a
float).

>>> import sympy as sp
>>> from kinlib.course.answers import wire
>>> def ans(value, kind="expr"):
...     return {"kind": kind, "tree": wire.dump(value), "symbols": {}}
>>> orig = signature({"rank": ans(sp.Integer(2)), "j": {"kind": "choice", "choice": {"type": "tuple", "value": [1, 2]}}})
>>> same = signature({"rank": ans(sp.Integer(2)), "j": {"kind": "choice", "choice": {"type": "tuple", "value": [2, 3]}}})
>>> other = signature({"rank": ans(sp.Integer(3)), "j": {"kind": "choice", "choice": {"type": "int", "value": 2}}})
>>> differences(orig, same)
[]
>>> differences(orig, other)
['j: a tie of 2 in the original, one winner here', 'rank: 2 in the original, 3 here']
"""

from __future__ import annotations

import sympy as sp

from ..answers import wire

__all__ = ["signature", "differences", "shape"]

UNDECIDED = ("undecided",)


def _is_zero(e) -> bool | None:
    """Exactly zero? A constant: SymPy's ``is_zero``, else its minimal polynomial; an expression in symbols:
    zero when it simplifies to 0 (the same test on the original and the variant)."""
    if e.free_symbols:
        return e == 0 or sp.simplify(e) == 0
    z = e.is_zero
    if z is None:
        try:
            x = sp.Dummy("x")
            z = sp.minimal_polynomial(e, x) == x
        except (NotImplementedError, ValueError, TypeError, sp.PolynomialError):
            return None
    return bool(z)


def _set_shape(s):
    if isinstance(s, sp.Union):
        return ("union", tuple(sorted(_set_shape(a) for a in s.args)))
    if isinstance(s, sp.FiniteSet):
        return ("finite", len(s))
    if isinstance(s, sp.ImageSet):
        return ("family",)
    return (type(s).__name__,)


def _subspace_shape(m):
    """A subspace's dimension and, for one of numbers, the zero pattern of its reduced basis (the rows of rref
    of the spanning columns): a subspace that happens to line up with an axis (the x-y plane instead of a tilted
    one) is a special case the student would be asked about, and it reads like a worked example."""
    if m.free_symbols:
        return ("subspace", m.rank())
    basis = [r for r in (m.T.rref()[0].tolist()) if any(x != 0 for x in r)]
    pattern = tuple(tuple(_is_zero(sp.sympify(x)) for x in r) for r in basis)
    return ("subspace", len(basis), pattern)


def shape(obj, kind: str = "expr", top: bool = True):
    """The structure of one loaded answer value (what :func:`differences` compares). An integer or a boolean
    that *is* the answer (a rank) is kept as its value; inside a matrix or a dict a number is only zero or not.

    >>> th = sp.Symbol("theta2", real=True)
    >>> shape(sp.Matrix([[0, sp.sin(th)], [sp.sqrt(2) - 2 * sp.cos(sp.pi / 4), 1]]))
    ('matrix', (2, 2), (('number',), ('expr', ('theta2',)), ('number',), ('number',)))
    >>> shape(sp.Matrix([[sp.sin(th) ** 2 + sp.cos(th) ** 2 - 1, sp.sin(th)]]))
    ('matrix', (1, 2), (('zero',), ('expr', ('theta2',))))
    >>> shape(sp.Integer(2)), shape(sp.Matrix([[1, 0], [0, 1], [0, 0]]), "subspace")
    (('int', 2), ('subspace', 2, ((False, True, True), (True, False, True))))
    """
    if kind == "subspace" and isinstance(obj, sp.MatrixBase):
        return _subspace_shape(obj)
    if isinstance(obj, dict):
        keys = [str(k) for k in obj]
        return ("dict", tuple(sorted(zip(keys, (shape(v, kind, False) for v in obj.values())))))
    if isinstance(obj, (list, tuple, sp.Tuple)):
        return ("seq", tuple(shape(v, kind, False) for v in obj))
    if isinstance(obj, sp.MatrixBase):
        return ("matrix", obj.shape, tuple(shape(v, kind, False) for v in obj))
    if isinstance(obj, (bool, sp.logic.boolalg.BooleanAtom)):
        return ("bool", bool(obj))
    if isinstance(obj, sp.Set):
        return _set_shape(obj)
    if top and isinstance(obj, (int, sp.Integer)):
        return ("int", int(obj))
    if isinstance(obj, (int, sp.Expr)):
        obj = sp.sympify(obj)
        if not obj.free_symbols and not top:
            return ("number",)  # a number in a row of numbers: 0 is one of them (a joint that does not help)
        z = _is_zero(obj)
        if z is None:
            return UNDECIDED
        if z:
            return ("zero",)
        syms = tuple(sorted(x.name for x in obj.free_symbols))
        return ("expr", syms) if syms else ("number",)
    return (type(obj).__name__,)


def _choice_shape(c: dict):
    t, v = c.get("type"), c.get("value")
    if t == "bool":
        return ("bool", v)
    if t == "int":
        return ("winner",)
    if t in ("tuple", "list") and isinstance(v, list):
        return ("tie", len(v))
    return ("choice", t, repr(v))


def signature(answers: dict, like: dict | None = None, like_signature: dict | None = None) -> dict:
    """{name: structure} of a notebook's reference answers (``Reference.answers``: wire trees or choices). An
    answer identical to its counterpart in ``like`` (the original's answers, whose signature is
    ``like_signature``) has that structure without being looked at again.

    >>> signature({"n": {"kind": "expr", "tree": ["Integer", "3"]}, "bad": {"error": "J is not defined"}})
    {'bad': ('error', 'J is not defined'), 'n': ('expr', ('int', 3))}
    """
    out = {}
    for name, a in sorted(answers.items()):
        if like is not None and like_signature is not None and name in like_signature and like.get(name) == a:
            out[name] = like_signature[name]
        elif not isinstance(a, dict) or "error" in a:
            out[name] = ("error", str((a or {}).get("error", ""))[:200] if isinstance(a, dict) else "")
        elif "choice" in a:
            out[name] = ("choice", _choice_shape(a["choice"]))
        else:
            try:
                value = wire.load(a["tree"], max_nodes=10 * wire.MAX_NODES)
            except (wire.WireError, RecursionError) as exc:
                out[name] = ("error", str(exc)[:200])
                continue
            out[name] = (a.get("kind", "expr"), shape(value, a.get("kind", "expr")))
    return out


def _contains(s, target) -> bool:
    return s == target or (isinstance(s, tuple) and any(_contains(x, target) for x in s))


def _say(s) -> str:
    if s[0] == "choice":
        c = s[1]
        return {"winner": "one winner", "tie": f"a tie of {c[1]}" if len(c) > 1 else "a tie"}.get(c[0], str(c[-1]))
    if s[0] == "error":
        return f"an error ({s[1]})" if s[1] else "an error"
    inner = s[1]
    if inner[0] in ("int", "bool"):
        return str(inner[1])
    if inner[0] == "subspace":
        return f"a subspace of dimension {inner[1]}" + (", along the axes" if _axis_aligned(inner) else "")
    if _contains(inner, UNDECIDED):
        return "an entry whose zero could not be decided exactly"
    if inner[0] == "dict" and s[0] == "set":
        fams = sum(_count(v, ("family",)) for _k, v in inner[1])
        return f"{fams} singular famil{'y' if fams == 1 else 'ies'} in {', '.join(k for k, _ in inner[1])}"
    if inner[0] == "matrix":
        zeros = _count(inner, ("zero",))
        return f"a {inner[1][0]}×{inner[1][1]} matrix with {zeros} zero entr{'y' if zeros == 1 else 'ies'}"
    return "another form"


def _axis_aligned(inner) -> bool:
    return len(inner) > 2 and all(sum(not z for z in row) == 1 for row in inner[2])


def _count(s, target) -> int:
    if s == target:
        return 1
    return sum(_count(x, target) for x in s) if isinstance(s, tuple) else 0


def differences(original: dict, variant: dict) -> list[str]:
    """One reason per answer whose structure differs (empty: the variant is well-posed as the original).

    >>> differences({"s": ("set", ("dict", (("theta2", ("family",)),)))},
    ...             {"s": ("set", ("dict", (("theta2", ("union", (("family",), ("family",)))),)))})
    ['s: 1 singular family in theta2 in the original, 2 singular families in theta2 here']
    """
    out = []
    for name in sorted(original):
        a, b = original[name], variant.get(name, ("error", "missing"))
        if b == a and not _contains(b, UNDECIDED):
            continue
        said_a, said_b = _say(a), _say(b)
        if said_a == said_b:
            said_a, said_b = "one form", "another"
        out.append(f"{name}: {said_a} in the original, {said_b} here")
    return out
