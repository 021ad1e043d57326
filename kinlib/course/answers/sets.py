"""The ``set`` kind: a set of configurations, judged by its members (angles modulo 2π).

* **normalise** (:func:`set_conditions`, :func:`to_set`): a SymPy Set; a Python set/list/tuple or NumPy array of
  values; a single number; a dict {symbol: Set} (one condition on each named joint); a list of such dicts (their
  union, as ``kinlib.singular_configurations`` returns; ``[]`` is the empty set). :func:`looks_like_set` finds
  default-kind answers that are sets.
* **wire form**: SymPy sets (``FiniteSet``, ``Interval``, ``ImageSet``, ``Union``, ``Intersection``, ...),
  ``dict``, ``list``, ``set``, ``tuple``, numbers.
* **describe** (:func:`describe_set`, at the secret points): per point, each condition's members in a window
  (at most :data:`MAX_SET_MEMBERS`), intervals by their ends, configurations as tuples.
* **compare** (:func:`compare_set`): the same conditions, each with the same members, modulo 2π whenever the
  reference is a set of angles (members that are simple multiples of π, or a joint angle's family), whatever
  the set is keyed by; degrees named. O(n log n).
* **reference** (:func:`reference_set`).
"""

from __future__ import annotations

import bisect
import json
import math
import numbers
from fractions import Fraction

import numpy as np
import sympy as sp

from . import fingerprints as fp
from .base import as_sympy, is_bool, not_answered, subs_for, to_complex, type_name
from .mistakes import SET_MISTAKES, SET_VARIABLE

__all__ = [
    "to_set",
    "set_conditions",
    "looks_like_set",
    "describe_set",
    "compare_set",
    "reference_set",
    "var_name",
    "MAX_SET_MEMBERS",
    "JOINT_NAMES",
    "home_canon",
    "home_verdict",
    "stub_words",
]

MAX_SET_MEMBERS = 5000  # members of one set listed per point (more: the answer is too large to grade)


def to_set(value):
    """One set of values as a SymPy Set: Sets as they are; a Python set/list/tuple or NumPy array of
    values, or a single number, as a FiniteSet. Raises TypeError for anything else.

    >>> to_set([0, sp.pi]), to_set(np.array([1.5])), to_set(sp.Interval(0, 1)), to_set(2)
    ({0, pi}, {1.5}, Interval(0, 1), {2})
    """
    if isinstance(value, sp.Set):
        return value
    if isinstance(value, np.ndarray):
        value = value.ravel().tolist()
    if isinstance(value, (set, frozenset, list, tuple)):
        return sp.FiniteSet(*[as_sympy(v) for v in value])  # never parsed: a string member raises TypeError
    if isinstance(value, (numbers.Number, np.number, sp.Expr)) and not is_bool(value):
        return sp.FiniteSet(as_sympy(value))
    raise TypeError(f"a set should be a SymPy Set (or a dict {{symbol: Set}}), not a {type(value).__name__}")


def set_conditions(value):
    """A set-of-configurations answer as a list of conditions (their union), each a list of
    ``(key, set)``: ``key`` a joint variable (or None for a bare set of the only one), ``set`` a SymPy
    Set or a collection of values (see :func:`to_set`); None if ``value`` is not a set at all.

    A dict {symbol: Set} is one condition on each named joint; a list of such dicts is their union (an
    empty list: no configuration); a Set, a collection of values or a single number is one condition.

    >>> th = sp.Symbol("theta2")
    >>> set_conditions({th: {0}}), set_conditions([{th: {0}}, {th: {1}}]), set_conditions([])
    ([[(theta2, {0})]], [[(theta2, {0})], [(theta2, {1})]], [])
    >>> set_conditions(sp.FiniteSet(0, sp.pi)), set_conditions(sp.pi / 2), set_conditions("x")
    ([[(None, {0, pi})]], [[(None, {pi/2})]], None)
    """
    if isinstance(value, (dict, sp.Dict)):
        return [list(dict(value).items())]
    if isinstance(value, (list, tuple)) and all(isinstance(v, (dict, sp.Dict)) for v in value):
        return [list(dict(v).items()) for v in value]
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (sp.Set, set, frozenset, list, tuple)):
        return [[(None, value)]]
    if isinstance(value, (numbers.Number, np.number, sp.Expr)) and not is_bool(value):
        return [[(None, to_set(value))]]
    return None


def looks_like_set(value) -> bool:
    """Answers of the default kind that are really sets of configurations: a Set, a non-empty
    {symbol: Set} dict, or a list of those dicts (``[]`` included).

    >>> th = sp.Symbol("theta1")
    >>> looks_like_set(sp.EmptySet), looks_like_set([{th: sp.FiniteSet(0)}]), looks_like_set({"a": 1})
    (True, True, False)
    """
    if isinstance(value, sp.Set):
        return True
    if isinstance(value, (dict, sp.Dict)):
        return bool(value) and all(isinstance(k, sp.Symbol) for k in dict(value))
    if isinstance(value, (list, tuple)):
        return len(value) == 0 or all(isinstance(v, (dict, sp.Dict)) and looks_like_set(v) for v in value)
    return False


def _real(e, subs):
    c = to_complex(e.xreplace(subs) if subs else e)
    if c is None or abs(c[1]) > 1e-9 * max(1.0, abs(c[0])):
        return None
    return c[0]


def _enum1d(S, subs, window):
    """Members of the 1-D set ``S`` in [-window, window]: (points, intervals); raises ValueError if unknown or
    if it lists more than :data:`MAX_SET_MEMBERS` members."""
    if not isinstance(S, sp.Set):
        S = to_set(S)
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
        if isinstance(S, kind):
            return _cap(enum(S, subs, window)), []
    raise ValueError(f"a {type(S).__name__} cannot be enumerated (use FiniteSet, ImageSet or Union)")


def _cap(pts):
    if len(pts) > MAX_SET_MEMBERS:
        raise ValueError(f"more than {MAX_SET_MEMBERS} members: too large to grade")
    return pts


def _finite(S, subs, window):
    _cap(S.args)
    pts = []
    for e in S.args:
        x = _real(as_sympy(e), subs)
        if x is None:
            raise ValueError(f"member {e} is not a real number")
        pts.append(x)
    return pts


def _image(S, subs, window):
    """The members of an image set over the integers {f(n)} in the window (those nearest 0 if none is)."""
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


_ENUMERATE = (  # (the SymPy class, its members' enumeration)
    (sp.FiniteSet, _finite),
    (sp.ImageSet, _image),
    (sp.Intersection, _intersection),
)


def _component(key, S, p, seed, window):
    name = key.name if isinstance(key, sp.Symbol) else (str(key) if key is not None else None)
    subs = subs_for(S, p, seed) if isinstance(S, sp.Basic) else {}
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
                    x = _real(as_sympy(e), subs)
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
    """Set-of-configurations answer (forms: :func:`set_conditions`): per point, a list of conditions,
    each a list of components {"var": name or None, "points"/"intervals" (members in [-window, window])
    or "tuples"}.

    >>> describe_set({sp.Symbol("theta1"): sp.FiniteSet(0, sp.pi)}, [{}])["conditions"]
    [[[{'var': 'theta1', 'points': [0.0, 3.141592653589793], 'intervals': []}]]]
    """
    if value is Ellipsis:
        return {"tag": "ellipsis", "type": "ellipsis"}
    if value is None:
        return {"tag": "none", "type": "NoneType"}
    conds = set_conditions(value)
    if conds is None:
        return {"tag": "other", "type": type_name(value)}
    per_point = []
    for p in points:
        per_point.append([[_component(k, S, p, seed, window) for k, S in cond] for cond in conds])
    return {"tag": "set", "type": type_name(value), "conditions": per_point}


def _as_set(v):
    try:
        return v if isinstance(v, sp.Set) else to_set(v)
    except TypeError:
        return v  # left for describe_set to report


def reference_set(value):
    """The reference value of a ``set`` answer as something the wire format round-trips: a Set, a dict {symbol: Set} or
    a list of those, as it was given.

    >>> reference_set([0, 1]), reference_set({sp.Symbol("t"): [0]})
    ({0, 1}, {t: {0}})
    """
    conds = set_conditions(value)
    if conds is None or isinstance(value, sp.Set):
        return value
    sets = [{k: _as_set(v) for k, v in cond} for cond in conds]
    if isinstance(value, (list, tuple)) and all(isinstance(v, (dict, sp.Dict)) for v in value):
        return sets
    if isinstance(value, (dict, sp.Dict)):
        return sets[0]
    return sets[0][None]


def _pi_multiple(x: float) -> str:
    """3π/4-style text when x is a simple multiple of π, else the decimal."""
    if not math.isfinite(x):
        return str(x)
    fr = Fraction(x / math.pi).limit_denominator(24)
    if abs(float(fr) * math.pi - x) < 1e-7:
        if fr == 0:
            return "0"
        num, den = fr.numerator, fr.denominator
        s = ("-" if num < 0 else "") + ("" if abs(num) == 1 else str(abs(num))) + "π"
        return s + ("" if den == 1 else f"/{den}")
    return f"{x:.4g}"


def _wrap(x):
    y = math.remainder(x, 2 * math.pi)
    return math.pi if abs(y + math.pi) < 1e-9 else y


def _canon_points(pts, periodic, scale=1.0):
    """The members sorted, taken modulo 2π when ``periodic``, those within 1e-6 of the previous one dropped
    (O(n log n): a set of 250,000 members is compared in a second, not in minutes).

    >>> _canon_points([2 * math.pi, 0.0, 1e-9, 1.0], periodic=True)
    [0.0, 1.0]
    """
    xs = sorted(_wrap(x * scale) if periodic else x * scale for x in pts)
    out = []
    for x in xs:
        if not math.isfinite(x):
            raise ValueError("a member that is not a finite number")
        if not out or x - out[-1] >= 1e-6:
            out.append(x)
    return out


def _near(x, sorted_pts) -> bool:
    """Whether x is within 1e-6 of a member of ``sorted_pts`` (bisection)."""
    i = bisect.bisect_left(sorted_pts, x - 1e-6)
    return i < len(sorted_pts) and abs(sorted_pts[i] - x) < 1e-6 + 1e-12


def _same(a, b):
    return len(a) == len(b) and all(abs(x - y) < 1e-6 for x, y in zip(a, b))


def _canon_intervals(ivs):
    return sorted([float(a) if a is not None else -math.inf, float(b) if b is not None else math.inf] for a, b in ivs)


def _empty(c):
    return not c.get("error") and not c.get("points") and not c.get("intervals") and not c.get("tuples")


def _free(c):
    return c.get("intervals") == [[-math.inf, math.inf]] and not c.get("points")


_GREEK = {"θ": "theta", "φ": "phi", "ψ": "psi", "α": "alpha", "β": "beta", "γ": "gamma"}


def var_name(v):
    """A joint variable's name without typesetting: θ_2, theta_{2}, \\theta_2 and theta2 are one variable.

    >>> [var_name(v) for v in ("θ_2", "theta_{2}", r"\\theta_2", "theta2", None)]
    ['theta2', 'theta2', 'theta2', 'theta2', None]
    """
    if v is None:
        return None
    v = str(v)
    for g, name in _GREEK.items():
        v = v.replace(g, name)
    return "".join(ch for ch in v if ch not in "\\_{} ") or str(v)


def _conds(desc_point, ref_vars):
    """Conditions as {var: component}; unsatisfiable ones (an empty component) dropped, "any value" ones
    ignored, and a bare set (var None) taken as the set of the only reference variable; when the reference
    is itself a bare set, a one-variable condition of the student's is taken as that set (whatever its key)."""
    out = []
    for cond in desc_point:
        d = {}
        dead = False
        live = [c for c in cond if not _free(c)]
        for c in cond:
            v = var_name(c.get("var"))
            if v is None and len(ref_vars) == 1:
                v = next(iter(ref_vars))
            elif not ref_vars and len(live) == 1:
                v = None
            if _empty(c):
                dead = True
            if _free(c):
                continue
            d[v] = c
        if not dead:
            out.append(d)
    return out


_ANGLE_NAMES = ("theta", "phi", "psi", "alpha", "beta", "gamma", "q", "th", "angle")


def _pi_rational(x: float) -> bool:
    fr = Fraction(x / math.pi).limit_denominator(24)
    return abs(float(fr) * math.pi - x) < 1e-9 * max(1.0, abs(x))


def _periodic_points(pts) -> bool:
    """The points are a 2π-periodic family (as enumerated in a window): x + 2π is a member for each x that
    has room for it."""
    top = max(pts, default=0.0)
    inner = [x for x in pts if x + 2 * math.pi <= top + 1e-9]
    ordered = sorted(pts)
    return bool(inner) and all(_near(x + 2 * math.pi, ordered) for x in inner)


def _is_angle(var, r) -> bool:
    """Whether the reference component ``r`` (of variable ``var``) is a set of angles, compared modulo 2π:
    its members are all simple multiples of π (whatever the key), or it is keyed by an angle's name (θ…, φ…,
    q…) and is itself a 2π-periodic family. Continuous ranges, keys like d3/x and other isolated values
    (a prismatic θ3 = −L) compare as numbers."""
    if "tuples" in r:
        flat = [x for t in r["tuples"] for x in t]
        return str(var or "").startswith(_ANGLE_NAMES) or bool(flat) and all(_pi_rational(x) for x in flat)
    if r.get("intervals"):
        return False
    pts = r.get("points", [])
    name = str(var or "")
    if name[:1] in ("d", "x", "y", "z") and not name.startswith(_ANGLE_NAMES):
        return False
    if pts and all(_pi_rational(x) for x in pts):
        return True
    return name.startswith(_ANGLE_NAMES) and _periodic_points(pts)


def _cond_match(s, r, periodic):
    if set(s) != set(r):
        return False, None
    for v in r:
        ok, msg = _compare_component(s[v], r[v], periodic and _is_angle(v, r[v]))
        if not ok:
            return False, (f"({v}): {msg}" if v is not None else msg)
    return True, ""


def compare_set(stu: dict, ref: dict, name: str, periodic: bool = True) -> tuple[bool, str]:
    """Sets of configurations as sets: the same conditions, each with the same members (angles modulo 2π,
    whatever the set is keyed by: a member of the reference that is a simple multiple of π, or a key named
    like an angle, makes it a set of angles).

    >>> ref = {"conditions": [[[{"var": "theta1", "points": [0.0], "intervals": []}]]]}
    >>> stu = {"tag": "set", "conditions": [[[{"var": None, "points": [6.283185307179586], "intervals": []}]]]}
    >>> compare_set(stu, ref, "S")
    (True, '')
    >>> bare = {"conditions": [[[{"var": None, "points": [-1.5707963267948966, 1.5707963267948966]}]]]}
    >>> compare_set({"tag": "set", "conditions": [[[{"var": None, "points": [90.0, 270.0]}]]]}, bare, "v")[1]
    'v: these look like degrees (90, 270): angles are radians (multiply degrees by sp.pi/180)'
    """
    na = not_answered(stu)
    if na:
        return False, f"{name} {na}"
    if stu.get("tag") != "set":
        return False, (
            f"{name} is a {stu.get('type')}; expected a SymPy Set, a dict {{symbol: Set}} or a list of those"
        )
    if len(stu.get("conditions", [])) != len(ref.get("conditions", [])):
        return False, f"{name} could not be compared (malformed values)"
    for sp_, rp in zip(stu["conditions"], ref["conditions"]):
        ref_vars = {var_name(c.get("var")) for cond in rp for c in cond if c.get("var") is not None}
        rc, sc = _conds(rp, ref_vars), _conds(sp_, ref_vars)
        errs = [f"{v or 'your set'}: {c['error']}" for d in sc for v, c in d.items() if c.get("error")]
        if errs:
            return False, f"{name} could not be compared: " + "; ".join(errs)
        if rc and not sc:
            return False, f"{name} is empty: not the right set"
        if not rc and sc:
            return False, f"{name} is not the right set"
        if len(rc) == 1 and len(sc) == 1:
            r, s = rc[0], sc[0]
            if set(s) != set(r):
                if len(s) == len(r) == 1 and _cond_match({next(iter(r)): next(iter(s.values()))}, r, periodic)[0]:
                    return False, f"{name} {SET_VARIABLE.says}"  # the right set on the wrong variable
                mine = ", ".join(sorted(map(str, (v for v in s if v is not None)))) or "one unnamed variable"
                return False, (
                    f"{name} constrains {mine}: not the right joint variables (which joints does the "
                    "condition restrict, and which are free?)"
                )
            ok, msg = _cond_match(s, r, periodic)
            if not ok:
                return False, f"{name}{'' if msg.startswith('(') else ':'} {msg}"
            continue
        unmatched = list(sc)
        for r in rc:
            hit = next((s for s in unmatched if _cond_match(s, r, periodic)[0]), None)
            if hit is None:
                return False, f"{name}: {len(sc)} condition(s) given, and not all of them are right"
            unmatched.remove(hit)
        if unmatched:
            return False, f"{name}: {len(sc)} condition(s) given, and not all of them are right"
    return True, ""


_DEGREE_VALUES = {15 * k for k in range(1, 25)}


def _looks_like_degrees(pts) -> list:
    """The student's values as degrees in [0, 360) when they all are whole multiples of 15 (not 0), else []."""
    out = []
    for x in pts:
        if not math.isfinite(x) or abs(x - round(x)) > 1e-9 or round(x) == 0:
            return []
        d = round(x) % 360
        if d not in _DEGREE_VALUES and d != 0:
            return []
        if d not in out:
            out.append(d)
    return sorted(out)


def _degrees_msg(pts) -> str:
    degs = _looks_like_degrees(pts)
    shown = ", ".join(str(d) for d in degs[:4]) + (" …" if len(degs) > 4 else "")
    return f"these look like degrees ({shown}): angles are radians (multiply degrees by sp.pi/180)"


def _compare_component(s, r, periodic):
    if "tuples" in r or "tuples" in s:
        if "tuples" not in s or "tuples" not in r:
            return False, "expected a set of configurations (tuples)"

        def canon(ts):  # sorted, near-duplicates (next to each other once sorted) dropped: O(n log n)
            out = []
            for t in sorted([_wrap(x) if periodic else x for x in t] for t in ts):
                if not out or len(t) != len(out[-1]) or not all(abs(a - b) < 1e-6 for a, b in zip(t, out[-1])):
                    out.append(t)
            return out

        a, b = canon(s["tuples"]), canon(r["tuples"])
        if len(a) == len(b) and all(len(x) == len(y) and _same(x, y) for x, y in zip(a, b)):
            return True, ""
        return False, f"{len(a)} configuration(s) given: not the right ones"
    si, ri = _canon_intervals(s.get("intervals", [])), _canon_intervals(r.get("intervals", []))
    if len(si) != len(ri) or any(not _same(x, y) for x, y in zip(si, ri)):
        if ri and not si:
            return False, "yours lists isolated values; a continuous range of values is expected"
        if si and not ri:
            return False, "yours is a continuous range; isolated values are expected"
        return False, "not the right range of values"
    sp_, rp = _canon_points(s.get("points", []), periodic), _canon_points(r.get("points", []), periodic)
    if _same(sp_, rp):
        return True, ""
    raw = s.get("points", [])
    if periodic and (_same(_canon_points(raw, True, math.pi / 180), rp) or _looks_like_degrees(raw)):
        return False, _degrees_msg(raw)
    missing = [x for x in rp if not _near(x, sp_)]
    wrong = [x for x in sp_ if not _near(x, rp)]
    where = " (compared modulo 2π)" if periodic else ""
    if wrong:
        return False, (
            f"{', '.join(_pi_multiple(x) for x in wrong[:4])} "
            f"{'is' if len(wrong) == 1 else 'are'} not in the set{where}"
        )
    if missing:
        return False, f"some values of the set are missing{where}"
    return False, "not the right set"


# ----------------------------------------------------------------------------------------- the self-check
# The workbook's side of the kind (kinlib.course.workbook.selfcheck): a set's points in [-2π, 2π] modulo 2π at
# the public sample points (home_canon), and the verdict against the spec (home_verdict), naming the mistakes of
# mistakes.SET_MISTAKES and the wrong variable as the grader does.


def _angle_point(p, k):
    """A point of a set, modulo 2π, as a stable string (tuples component-wise)."""
    if isinstance(p, (sp.Tuple, tuple)):
        return "(" + ",".join(_angle_point(q, k) for q in p) + ")"
    p = sp.sympify(p)  # a member of a SymPy set, in the student's own kernel
    pt = fp.sample_point(p, k)
    if pt:
        p = p.subs(pt)
    if p.is_number and p.is_real is not False:
        p = sp.Mod(p, 2 * sp.pi)
        s = fp.fmt(p.evalf(30))
        return "0" if s == fp.fmt(2 * math.pi) else s
    return fp.fmt(p.evalf(30))


def _canon_one_set(s, k, fmap=None):
    try:
        s = to_set(s)
    except TypeError as e:
        raise fp.WrongForm(str(e).replace("a set should be", "it should be")) from None
    if fmap is not None:  # a mistake undone (mistakes.SET_MISTAKES)
        s = fmap(s)
    pt = fp.sample_point(s, k)
    if pt:
        s = s.subs(pt)
    if not isinstance(s, sp.FiniteSet):
        window = sp.Interval(-2 * sp.pi, 2 * sp.pi)
        s = sp.Intersection(s, window)
        if isinstance(s, sp.Intersection) or isinstance(s, sp.ConditionSet):
            raise fp.CannotCheck("SymPy cannot list this set's points in [-2π, 2π]")
    parts = s.args if isinstance(s, sp.Union) else (s,)
    out = set()
    for part in parts:
        if isinstance(part, sp.FiniteSet):
            out.update(_angle_point(p, k) for p in part)
        elif isinstance(part, sp.Interval):
            out.add(
                f"I{'(' if part.left_open else '['}{fp.fmt(part.start.evalf(30))},"
                f"{fp.fmt(part.end.evalf(30))}{')' if part.right_open else ']'}"
            )
        elif part is sp.S.EmptySet:
            pass
        else:
            raise fp.CannotCheck(f"SymPy cannot list the points of {type(part).__name__} in [-2π, 2π]")
    return sorted(out)


def _canon_condition(cond: list, fmap=None, keys: dict | None = None) -> list:
    """A condition {variable: Set} canonical per sample point; keys by their untypeset name (θ_2 is theta2, as
    the grader reads them, :func:`var_name`), ``keys`` renaming some."""
    keys = keys or {}
    return [
        [keys.get(var_name(key), var_name(key))] + [_canon_one_set(s, k, fmap) for k in range(fp.SAMPLE_POINTS)]
        for key, s in sorted(cond, key=lambda kv: keys.get(var_name(kv[0]), var_name(kv[0])))
    ]


_EMPTY = [[] for _ in range(fp.SAMPLE_POINTS)]


def home_canon(value, fmap=None, keys=None) -> tuple:
    """``("set", shape, canonical points)`` of a ``set`` answer at the public sample points: a dict {symbol: Set}
    is shape "dict", a list of several such dicts (a union) "union", the rest ""; a set with no member (an empty
    Set, ``[]``, a condition that no value meets) is the empty bare set, whatever its form: an empty answer is
    judged by being empty, never told "it should be a dict".

    >>> home_canon({sp.Symbol("theta2"): {0}})[:2], home_canon([])
    (('set', 'dict'), ('set', '', [[], [], [], [], []]))
    """
    conds = set_conditions(value)
    if conds is None:
        raise fp.WrongForm(f"it should be a SymPy Set (or a dict {{symbol: Set}}), yours is a {type(value).__name__}")
    if len(conds) == 1 and conds[0] and conds[0][0][0] is None:
        return "set", "", [_canon_one_set(conds[0][0][1], k, fmap) for k in range(fp.SAMPLE_POINTS)]
    canon = [_canon_condition(c, fmap, keys) for c in conds]
    live = [c for c in canon if not any(all(not pts for pts in entry[1:]) for entry in c)]
    if not live:
        return "set", "", _EMPTY
    if len(conds) == 1:
        return "set", "dict", canon[0]
    return "set", "union", sorted(canon, key=json.dumps)


# the joint variables a one-variable condition may be re-keyed to (a bare set for a dict, the right set on the
# wrong variable): the names the course uses
JOINT_NAMES = tuple(f"{p}{i}" for p in ("theta", "q") for i in range(1, 8))
HOME_DIFFERS = "it holds different points"


def home_verdict(value, judge: fp.Judge) -> tuple[str, str]:
    """The self-check's ``(status, message)`` on a ``set`` answer against the spec in ``judge``: a bare set for a
    one-variable dict and back are read as the grader reads them; the right set on another joint variable, and
    degrees, are named (:data:`~.mistakes.SET_VARIABLE`, :data:`~.mistakes.SET_MISTAKES`).

    >>> t2 = sp.Symbol("theta2")
    >>> j = fp.Judge("set", "dict", fp.digest("set", home_canon({t2: {0}})[2]))
    >>> home_verdict({t2: {0}}, j)[0], home_verdict({sp.Symbol("theta1"): {0}}, j)[1][:40]
    ('correct', 'not right yet: it holds the right values')
    """
    shape, right, named = judge.shape, judge.right, judge.named
    _, mine_shape, canon = home_canon(value)
    if right(canon):
        return "correct", "correct"
    conds = set_conditions(value)
    one_var = conds is not None and len(conds) == 1 and len(conds[0]) == 1
    if mine_shape == "dict" and shape == "" and one_var:  # {θ2: S} for a bare S: the grader reads it as S
        if right([_canon_one_set(conds[0][0][1], k) for k in range(fp.SAMPLE_POINTS)]):
            return "correct", "correct"
    if mine_shape == "" and shape == "dict" and canon is not _EMPTY:  # a bare S for {θk: S}: the grader too
        bare = [[(sp.Symbol(v), conds[0][0][1])] for v in JOINT_NAMES]
        if any(right(_canon_condition(c)) for c in bare):
            return "correct", "correct"
    if mine_shape == "dict" and one_var:  # the right set on the wrong variable (mistakes.SET_VARIABLE)
        mine = var_name(conds[0][0][0])
        for v in JOINT_NAMES:
            if v != mine and right(_canon_condition(conds[0], keys={mine: v})):
                return named(SET_VARIABLE.says)
    if canon is not _EMPTY and mine_shape != shape and (mine_shape, shape) not in (("dict", ""), ("", "dict")):
        want = {"dict": "a dict {symbol: Set}", "union": "a list of dicts {symbol: Set}"}.get(shape, "a single Set")
        raise fp.WrongForm(f"it should be {want}")
    for m in SET_MISTAKES:
        try:
            if right(home_canon(value, lambda s, m=m: next(m.candidates(s))[1])[2]):
                return named(m.message())
        except Exception:  # noqa: BLE001  SymPy may not map this set: not that mistake
            continue
    return "incorrect", f"not right yet: {HOME_DIFFERS}"


def stub_words(value) -> str:
    """What a ``set`` answer is, for the workbook's stub.

    >>> stub_words({sp.Symbol("t"): {0}}), stub_words(sp.EmptySet)
    ('a dict {symbol: SymPy Set}', 'a SymPy Set')
    """
    if isinstance(value, dict):
        return "a dict {symbol: SymPy Set}"
    if isinstance(value, (list, tuple)) and all(isinstance(v, dict) for v in value):
        return "a list of dicts {symbol: SymPy Set}, one per condition ([] for none)"
    return "a SymPy Set"
