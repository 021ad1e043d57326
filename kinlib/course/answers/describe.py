"""An answer described for the comparison, on the trusted side: its values at the grader's secret points.

The grader rebuilds each answer from the data a kernel exported (:mod:`.wire`) and describes it here, in its
own process, exactly as it describes the reference answer: shape, symbols and values at the points (``expr``,
``subspace``, ``property``), members per point (``set``), the plain value (``choice``). The comparers
(:mod:`.compare`) read these descriptions. The points, the seed and the reference never leave the grader.

Non-finite values (inf, nan) are described as ``None`` (cannot be evaluated) and are a wrong answer.
"""

import math
import random

from . import normalise as answers
from .srepr import parse_srepr

__all__ = [
    "describe",
    "describe_expr",
    "describe_set",
    "describe_choice",
    "describe_subspace",
    "describe_property",
    "normalize_reference",
    "dump_reference",
    "exact_equal",
    "DESCRIBE",
    "MAX_SET_MEMBERS",
]

MAX_SET_MEMBERS = 5000  # members of one set listed per point (more: the answer is too large to grade)


_DEGREE_CONSTANTS = {15, 30, 45, 60, 75, 90, 105, 120, 135, 150, 165, 180, 210, 225, 240, 270, 300, 315, 330, 360}
_MISSING = object()


# ----------------------------------------------------------------------------- coercion (kinlib.course.answers)


def _shape(obj):
    import sympy as sp

    return list(obj.shape) if isinstance(obj, sp.MatrixBase) else []


def _extra_value(seed, name):
    return random.Random(f"{seed}:{name}").uniform(0.5, 2.0)


def _to_complex(e):
    import sympy as sp

    e = sp.sympify(e)
    if not e.is_number:
        e = e.evalf(20)
        if not e.is_number:
            return None
    c = complex(e.evalf(20))
    if not (math.isfinite(c.real) and math.isfinite(c.imag)):
        return None
    return [c.real, c.imag]


def _subs_for(obj, point, seed):
    import sympy as sp

    subs = {}
    for s in getattr(obj, "free_symbols", set()):
        if isinstance(s, sp.Symbol):
            v = point.get(s.name)
            subs[s] = sp.Float(v if v is not None else _extra_value(seed, s.name), 20)
    return subs


def _degrees_hint(obj):
    import sympy as sp

    trig = (sp.sin, sp.cos, sp.tan, sp.cot, sp.sec, sp.csc)
    for f in obj.atoms(*trig) if hasattr(obj, "atoms") else ():
        for n in f.args[0].atoms(sp.Number):
            try:
                if abs(n) in _DEGREE_CONSTANTS:
                    return True
            except TypeError:
                pass
    return False


def _lambdified_values(obj, entries, points, seed):
    """Values at ``points`` through a NumPy lambdify (complex128), or None to fall back to evalf."""
    import numpy as np
    import sympy as sp

    if not points:
        return []
    syms = sorted((s for s in obj.free_symbols if isinstance(s, sp.Symbol)), key=lambda s: s.name)
    if any(not isinstance(s, sp.Symbol) for s in obj.free_symbols) or obj.atoms(sp.core.function.AppliedUndef):
        return None
    try:
        f = sp.lambdify(syms, entries, modules="numpy", cse=True)
        out = []
        for p in points:
            args = [np.complex128(p[s.name] if s.name in p else _extra_value(seed, s.name)) for s in syms]
            with np.errstate(all="ignore"):
                vals = [complex(v) for v in f(*args)]
            if not all(math.isfinite(v.real) and math.isfinite(v.imag) for v in vals):
                return None
            out.append([[v.real, v.imag] for v in vals])
        return out
    except Exception:  # noqa: BLE001
        return None


def describe_expr(value, points, seed=0, vectors=False):
    """Matrix/expression answer: type, shape, symbols and values at ``points`` (dicts name -> float).
    ``vectors``: a list of lists is a list of spanning vectors (subspaces; see ``answers.to_sympy``).

    >>> import sympy as sp
    >>> d = describe_expr(sp.Matrix([sp.Symbol("x"), 1]), [{"x": 2.0}])
    >>> d["tag"], d["shape"], d["symbols"], d["values"]
    ('matrix', [2, 1], ['x'], [[[2.0, 0.0], [1.0, 0.0]]])
    """
    import sympy as sp

    if isinstance(value, dict) and value and all(isinstance(k, (str, int)) for k in value):
        return {
            "tag": "dict",
            "type": "dict",
            "items": {str(k): describe_expr(v, points, seed, vectors) for k, v in value.items()},
        }
    tag, obj = answers.to_sympy(value, vectors=vectors)
    out = {"tag": tag, "type": answers.type_name(value)}
    if obj is None:
        return out
    syms = sorted({s.name for s in obj.free_symbols if isinstance(s, sp.Symbol)})
    out.update(
        shape=_shape(obj),
        symbols=syms,
        has_float=bool(obj.atoms(sp.Float)),
        degrees=_degrees_hint(obj),
        undefined=sorted({str(f.func) for f in obj.atoms(sp.core.function.AppliedUndef)}),
    )
    entries = list(obj) if isinstance(obj, sp.MatrixBase) else [obj]
    fast = _lambdified_values(obj, entries, points, seed)
    if fast is not None:
        out["values"] = fast
        return out
    values = []
    for p in points:
        subs = _subs_for(obj, p, seed)
        row = []
        for e in entries:
            try:
                row.append(_to_complex(e.xreplace(subs)))
            except Exception:
                row.append(None)
        values.append(row)
    out["values"] = values
    return out


# ----------------------------------------------------------------------------- sets of configurations


def _real(e, subs):
    c = _to_complex(e.xreplace(subs) if subs else e)
    if c is None or abs(c[1]) > 1e-9 * max(1.0, abs(c[0])):
        return None
    return c[0]


def _enum1d(S, subs, window):
    """Members of the 1-D set ``S`` in [-window, window]: (points, intervals); raises ValueError if unknown or
    if it lists more than :data:`MAX_SET_MEMBERS` members."""
    import sympy as sp

    if not isinstance(S, sp.Set):
        S = answers.to_set(S)
    if S is sp.S.EmptySet:
        return [], []
    if S in (sp.S.Reals, sp.S.UniversalSet, sp.S.Complexes) or isinstance(S, sp.sets.sets.UniversalSet):
        return [], [[-math.inf, math.inf]]
    if isinstance(S, sp.Interval):
        return [], [[_real(S.start, subs), _real(S.end, subs)]]
    if isinstance(S, sp.Union):
        pts, ivs = [], []
        for a in S.args:
            p, i = _enum1d(a, subs, window)
            pts += p
            ivs += i
            _cap(pts)
        return pts, ivs
    for kind, enum in _ENUMERATE:
        if isinstance(S, kind()):
            return _cap(enum(S, subs, window)), []
    raise ValueError(f"a {type(S).__name__} cannot be enumerated (use FiniteSet, ImageSet or Union)")


def _cap(pts):
    if len(pts) > MAX_SET_MEMBERS:
        raise ValueError(f"more than {MAX_SET_MEMBERS} members: too large to grade")
    return pts


def _finite(S, subs, window):
    import sympy as sp

    _cap(S.args)
    pts = []
    for e in S.args:
        x = _real(sp.sympify(e), subs)
        if x is None:
            raise ValueError(f"member {e} is not a real number")
        pts.append(x)
    return pts


def _image(S, subs, window):
    """The members of an image set over the integers {f(n)} in the window (those nearest 0 if none is)."""
    import sympy as sp

    lam = S.lamda
    base = S.base_sets[0] if hasattr(S, "base_sets") else S.base_set
    if len(lam.variables) != 1 or base not in (sp.S.Integers, sp.S.Naturals, sp.S.Naturals0):
        raise ValueError("only image sets over the integers can be compared")
    v = lam.variables[0]
    f = lam.expr.xreplace(subs) if subs else lam.expr
    f0, f1 = _real(f.xreplace({v: 0}), {}), _real(f.xreplace({v: 1}), {})
    step = abs(f1 - f0) if f0 is not None and f1 is not None else 0.0
    K = min(2000, int(2 * window / step) + 3) if step > 1e-9 else 50
    # centred on the member nearest 0 (a family 2πn + 1000π, or one in degrees, has members in the window)
    c = 0 if step <= 1e-9 or base is not sp.S.Integers else int(max(-1e6, min(1e6, round(-f0 / (f1 - f0)))))
    lo = 0 if base is sp.S.Naturals0 else (1 if base is sp.S.Naturals else c - K)
    pts, near = [], []
    for n in range(lo, c + K + 1):
        x = _real(f.xreplace({v: n}), {})
        if x is not None and abs(x) <= window:
            pts.append(x)
        elif x is not None and abs(n - c) <= 3:
            near.append(x)
    return pts or near


def _intersection(S, subs, window):
    """The members of an intersection of enumerable sets, filtered by the intervals in it."""
    import sympy as sp

    filters = [a for a in S.args if isinstance(a, sp.Interval) or a is sp.S.Reals]
    enumerable = [a for a in S.args if not (isinstance(a, sp.Interval) or a is sp.S.Reals)]
    if not enumerable:
        raise ValueError("an intersection of intervals cannot be compared")
    pts, ivs = _enum1d(enumerable[0], subs, window)
    if ivs:
        raise ValueError("cannot compare an intersection with a continuous set")
    for other in enumerable[1:]:
        p2, i2 = _enum1d(other, subs, window)
        pts = [x for x in pts if any(abs(x - y) < 1e-7 for y in p2) or any(a <= x <= b for a, b in i2)]
    for fset in filters:
        if fset is sp.S.Reals:
            continue
        a, b = _real(fset.start, subs), _real(fset.end, subs)
        pts = [
            x
            for x in pts
            if (a < x < b)
            or (not fset.left_open and abs(x - a) < 1e-12)
            or (not fset.right_open and abs(x - b) < 1e-12)
        ]
    return pts


def _set_class(name):
    def get():
        import sympy as sp

        return getattr(sp, name)

    return get


_ENUMERATE = (  # (the SymPy class, lazily, its members' enumeration)
    (_set_class("FiniteSet"), _finite),
    (_set_class("ImageSet"), _image),
    (_set_class("Intersection"), _intersection),
)


def _component(key, S, p, seed, window):
    import sympy as sp

    name = key.name if isinstance(key, sp.Symbol) else (str(key) if key is not None else None)
    subs = _subs_for(S, p, seed) if isinstance(S, sp.Basic) else {}
    comp = {"var": name}
    try:
        if (
            isinstance(S, sp.FiniteSet)
            and any(isinstance(a, (sp.Tuple, sp.MatrixBase)) for a in S.args)
            or isinstance(S, (list, tuple, set, frozenset))
            and S
            and all(isinstance(a, (tuple, list, sp.Tuple)) for a in S)
        ):
            tuples = []
            if len(S.args if isinstance(S, sp.FiniteSet) else S) > MAX_SET_MEMBERS:
                raise ValueError(f"more than {MAX_SET_MEMBERS} members: too large to grade")
            for a in S.args if isinstance(S, sp.FiniteSet) else S:
                t = []
                for e in a:
                    x = _real(sp.sympify(e), subs)
                    if x is None:
                        raise ValueError(f"member {a} is not real")
                    t.append(x)
                tuples.append(t)
            comp["tuples"] = tuples
        else:
            pts, ivs = _enum1d(S, subs, window)
            comp["points"] = pts
            comp["intervals"] = ivs
    except Exception as exc:  # noqa: BLE001  (any failure is reported, not raised)
        comp["error"] = f"{type(exc).__name__}: {exc}"[:300]
    return comp


def describe_set(value, points, seed=0, window=4 * math.pi):
    """Set-of-configurations answer (forms: ``answers.set_conditions``): per point, a list of conditions,
    each a list of components {"var": name or None, "points"/"intervals" (members in [-window, window])
    or "tuples"}.

    >>> import sympy as sp
    >>> describe_set({sp.Symbol("theta1"): sp.FiniteSet(0, sp.pi)}, [{}])["conditions"]
    [[[{'var': 'theta1', 'points': [0.0, 3.141592653589793], 'intervals': []}]]]
    """
    if value is Ellipsis:
        return {"tag": "ellipsis", "type": "ellipsis"}
    if value is None:
        return {"tag": "none", "type": "NoneType"}
    conds = answers.set_conditions(value)
    if conds is None:
        return {"tag": "other", "type": answers.type_name(value)}
    per_point = []
    for p in points:
        per_point.append([[_component(k, S, p, seed, window) for k, S in cond] for cond in conds])
    return {"tag": "set", "type": answers.type_name(value), "conditions": per_point}


# ----------------------------------------------------------------------------- choices


def describe_choice(value, points=(), seed=0):
    """Choice answer: its value as ``answers.choice_value`` gives it (``points`` and ``seed`` unused:
    the signature of every describe function).

    >>> describe_choice((2, 1))
    {'tag': 'choice', 'type': 'tuple', 'value': [2, 1]}
    """
    if value is Ellipsis:
        return {"tag": "ellipsis", "type": "ellipsis"}
    if value is None:
        return {"tag": "none", "type": "NoneType"}
    return {"tag": "choice", "type": answers.type_name(value), "value": answers.choice_value(value)}


def describe_subspace(value, points, seed=0):
    """Subspace answer: a matrix whose columns span it (a list of lists: the spanning vectors); a constant
    exact matrix also as its ``answers.expr_tree`` (``tree``), so the grader can compare spans exactly.

    >>> d = describe_subspace([[1, 0], [0, 1]], [{}])
    >>> d["shape"], d["tree"][:3]
    ([2, 2], ['matrix', 2, 2])
    """
    out = describe_expr(value, points, seed, vectors=True)
    if out.get("tag") == "matrix" and not out.get("symbols") and not out.get("has_float"):
        try:
            out["tree"] = answers.expr_tree(answers.to_sympy(value, vectors=True)[1], max_nodes=600)
        except Exception:  # noqa: BLE001  (compared numerically then)
            pass
    return out


def describe_property(value, points, seed=0):
    """An answer graded by a property (``kind`` "property:<name>"): a robot as its screw axes' exact tree
    (``answers.property_answer``), anything else described as an expression plus its exact expression tree
    (``answers.expr_tree``), for the grader's proof.

    >>> import sympy as sp
    >>> describe_property(sp.Rational(1, 2), [{}])["tree"]
    ['rat', '1', '2']
    """
    prop = answers.property_answer(value)  # a robot (its screw axes), a matrix or an expression, as a tree
    if prop["tag"] == "robot":
        return prop
    out = describe_expr(value, points, seed)
    out.update({k: v for k, v in prop.items() if k in ("tree", "tree_error")})
    return out


DESCRIBE = {
    "expr": describe_expr,
    "subspace": describe_subspace,
    "set": describe_set,
    "choice": describe_choice,
    "property": describe_property,
}


def describe(kind, value, points, seed=0):
    """The answer ``value`` of kind ``kind`` described for the comparison (other kinds: as ``expr``).

    >>> describe("choice", 3, [])["value"]
    3
    """
    return DESCRIBE.get(str(kind).split(":")[0], describe_expr)(value, points, seed)


# ----------------------------------------------------------------------------- reference dump


def _as_set(v):
    import sympy as sp

    try:
        return v if isinstance(v, sp.Set) else answers.to_set(v)
    except TypeError:
        return v  # left for describe_set to report


def normalize_reference(kind, value):
    """The reference value as something ``srepr`` round-trips (instructor side only).

    >>> normalize_reference("set", [0, 1]), normalize_reference("expr", [1, 2]).shape
    ({0, 1}, (2, 1))
    >>> from kinlib.robots import planar_rpp
    >>> normalize_reference("property:nonsingular", planar_rpp()).shape   # a robot: its screw axes
    (6, 3)
    """
    import sympy as sp

    if kind == "expr" and isinstance(value, dict) and value and all(isinstance(k, (str, int)) for k in value):
        return {str(k): normalize_reference(kind, v) for k, v in value.items()}
    if kind in ("expr", "subspace"):
        tag, obj = answers.to_sympy(value, vectors=kind == "subspace")
        if obj is None:
            raise TypeError(f"reference answer of kind {kind!r} is {tag} ({answers.type_name(value)})")
        return obj
    if str(kind).startswith("property"):  # judged by the property alone; the reference is kept as data only
        screws = answers.robot_screws(value)  # a robot (the printed design): its screw axes
        if screws is not None:
            return screws
        obj = answers.to_sympy(value)[1]
        return obj if obj is not None else sp.Integer(0)
    if kind == "set":
        conds = answers.set_conditions(value)
        if conds is None or isinstance(value, sp.Set):
            return value
        sets = [{k: _as_set(v) for k, v in cond} for cond in conds]
        if isinstance(value, (list, tuple)) and all(isinstance(v, (dict, sp.Dict)) for v in value):
            return sets
        if isinstance(value, (dict, sp.Dict)):
            return sets[0]
        return sets[0][None]
    return value


def dump_reference(ns, kinds):
    """{name: {"kind", "srepr", "symbols": {name: {"positive": bool}}} | {"kind", "choice"} | {"error"}}
    for the reference answers ``kinds`` = {name: kind} found in ``ns``.

    >>> dump_reference({"n": 2, "ok": True}, {"n": "choice", "ok": "expr", "x": "expr"})["ok"]
    {'choice': {'tag': 'choice', 'type': 'bool', 'value': True}, 'kind': 'choice'}
    """
    import sympy as sp

    out = {}
    for name, kind in kinds.items():
        if name not in ns:
            out[name] = {"error": f"{name} is not defined after the solution notebook ran"}
            continue
        try:
            if kind == "expr" and answers.looks_like_set(ns[name]):
                kind = "set"
            if kind == "expr" and (answers.is_bool(ns[name]) or isinstance(ns[name], str)):
                kind = "choice"
            if kind == "choice":
                out[name] = {"choice": describe_choice(ns[name]), "kind": kind}
                continue
            obj = normalize_reference(kind, ns[name])
            text = sp.srepr(obj)
            syms = set()
            stack = [obj]
            while stack:
                o = stack.pop()
                if isinstance(o, dict):
                    stack += list(o.values())
                elif isinstance(o, (list, tuple)):
                    stack += list(o)
                else:
                    syms |= set(getattr(o, "free_symbols", set()) or set())
            out[name] = {
                "kind": kind,
                "srepr": text,
                "symbols": {s.name: {"positive": bool(s.is_positive)} for s in syms if isinstance(s, sp.Symbol)},
            }
        except Exception as exc:  # noqa: BLE001
            out[name] = {"error": f"{type(exc).__name__}: {exc}"[:500]}
    return out


# ----------------------------------------------------------------------------- exact equivalence (student kernel)


def exact_equal(value, ref, budget=5.0):
    """'equal' when value - reference simplifies to exactly zero, else 'not proved' (advisory only).

    >>> import sympy as sp
    >>> x = sp.Symbol("x")
    >>> exact_equal(sp.sin(x)**2 + sp.cos(x)**2, "Integer(1)"), exact_equal(x, "Integer(1)")
    ('equal', 'not proved')
    """
    import time

    import sympy as sp

    t0 = time.monotonic()
    tag, obj = answers.to_sympy(value)
    if obj is None:
        return "not sympy"
    ref = parse_srepr(ref) if isinstance(ref, str) else ref
    ref_syms = {s.name: s for s in ref.free_symbols if isinstance(s, sp.Symbol)}
    obj = obj.xreplace(
        {s: ref_syms[s.name] for s in obj.free_symbols if isinstance(s, sp.Symbol) and s.name in ref_syms}
    )
    a = list(obj) if isinstance(obj, sp.MatrixBase) else [obj]
    b = list(ref) if isinstance(ref, sp.MatrixBase) else [ref]
    if len(a) != len(b):
        return "not proved"
    for x, y in zip(a, b):
        d = sp.sympify(x - y)
        if d == 0:
            continue
        d = sp.expand(sp.expand_trig(d))
        if d == 0:
            continue
        if time.monotonic() - t0 < budget and sp.count_ops(d) < 400 and sp.simplify(d) == 0:
            continue
        return "not proved"
    return "equal"
