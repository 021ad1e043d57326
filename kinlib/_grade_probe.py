"""Kernel side of the instructor checker: turn answer values into plain JSON numbers and strings.

This module runs in two places with the same code:

* inside each **student kernel**: :mod:`kinlib.grade` sends this file's *source text* and executes it
  in a private module (registered in ``sys.modules`` under a random name), so nothing the student
  did to ``kinlib`` reaches it; :func:`snapshot` runs before the first student cell and
  :func:`restore` puts SymPy's, NumPy's, mpmath's and the builtins' namespaces (and SymPy's class
  attributes) back before the answers are read, so ``sympy.simplify = lambda e: 0`` and the like do
  not change what the checker measures;
* in the **instructor's worker process**, on the reference answers only (instructor data, parsed
  from the ``srepr`` strings the reference kernel produced), so both sides are described by one
  code path.

It imports only the standard library, SymPy and NumPy, and never imports kinlib.
"""
import cmath
import json
import math
import random
import sys

PROBE_VERSION = "1"
MAX_SREPR = 200_000
_DEGREE_CONSTANTS = {15, 30, 45, 60, 75, 90, 105, 120, 135, 150, 165, 180, 210, 225, 240, 270, 300, 315, 330, 360}
_MISSING = object()


# ----------------------------------------------------------------------------- namespace snapshot

def snapshot():
    """Copies of the namespaces a submission could tamper with (taken before any student cell runs)."""
    import numpy  # noqa: F401  (imported so that its modules are in the snapshot)
    import sympy  # noqa: F401
    mods, classes, sysmods = {}, {}, {}
    for name, m in list(sys.modules.items()):
        top = name.split(".")[0]
        if m is None or not (top in ("sympy", "numpy", "mpmath") or name in ("builtins", "math", "cmath", "json")):
            continue
        d = getattr(m, "__dict__", None)
        if not isinstance(d, dict):
            continue
        sysmods[name] = m
        mods[name] = (m, dict(d))
        if top in ("sympy", "mpmath"):
            for v in list(d.values()):
                if isinstance(v, type) and id(v) not in classes and \
                        str(getattr(v, "__module__", "") or "").startswith(top):
                    classes[id(v)] = (v, dict(v.__dict__))
    return {"mods": mods, "classes": classes, "sysmods": sysmods}


def restore(snap):
    """Undo changes to the snapshotted namespaces; returns how many attributes were put back."""
    import types
    fixed = 0
    for name, m in snap["sysmods"].items():
        if sys.modules.get(name) is not m:
            sys.modules[name] = m
            fixed += 1
    for m, saved in snap["mods"].values():
        cur = m.__dict__
        for k in list(cur):
            if k not in saved and not isinstance(cur[k], types.ModuleType):
                del cur[k]
                fixed += 1
        for k, v in saved.items():
            if cur.get(k, _MISSING) is not v:
                cur[k] = v
                fixed += 1
    for cls, saved in snap["classes"].values():
        for k in list(cls.__dict__):
            if k not in saved:
                try:
                    delattr(cls, k)
                    fixed += 1
                except (AttributeError, TypeError):
                    pass
        for k, v in saved.items():
            if cls.__dict__.get(k, _MISSING) is not v:
                try:
                    setattr(cls, k, v)
                    fixed += 1
                except (AttributeError, TypeError):
                    pass
    try:
        from sympy.core.cache import clear_cache
        clear_cache()
    except Exception:
        pass
    return fixed


# ----------------------------------------------------------------------------- coercion

def _is_vector(x):
    import numpy as np
    import sympy as sp
    if isinstance(x, sp.MatrixBase):
        return 1 in x.shape
    if isinstance(x, np.ndarray):
        return x.ndim == 1 or (x.ndim == 2 and 1 in x.shape)
    return False


def _flat(x):
    import numpy as np
    import sympy as sp
    if isinstance(x, sp.MatrixBase):
        return list(x)
    return list(np.asarray(x, dtype=object).ravel())


def to_sympy(value):
    """``(tag, obj)``: ``obj`` a SymPy Matrix or scalar expression, or None with ``tag`` saying why.

    Conventions: a 1-D array or flat list is a column; a list of vectors is a matrix with one vector
    per column (the screw-list convention); a list of lists is a matrix given by rows.
    """
    import numbers

    import numpy as np
    import sympy as sp
    if value is Ellipsis:
        return "ellipsis", None
    if value is None:
        return "none", None
    if isinstance(value, (bool, np.bool_)):
        return "bool", None
    if isinstance(value, sp.MatrixBase):
        return "matrix", sp.Matrix(value)
    if isinstance(value, np.ndarray):
        if value.ndim == 0:
            return to_sympy(value.item())
        if value.ndim == 1:
            return "matrix", sp.Matrix([sp.sympify(e) for e in value.tolist()])
        if value.ndim == 2:
            return "matrix", sp.Matrix([[sp.sympify(e) for e in row] for row in value.tolist()])
        return "array", None
    if isinstance(value, (sp.Tuple, list, tuple)):
        items = list(value)
        if not items:
            return "empty", None
        if all(_is_vector(v) for v in items):
            cols = [sp.Matrix(_flat(v)) for v in items]
            if len({c.shape for c in cols}) != 1:
                return "ragged", None
            return "matrix", sp.Matrix.hstack(*cols)
        if all(isinstance(v, (list, tuple, sp.Tuple)) for v in items):
            try:
                return "matrix", sp.Matrix([[sp.sympify(e) for e in row] for row in items])
            except Exception:
                return "ragged", None
        try:
            return "matrix", sp.Matrix([sp.sympify(e) for e in items])
        except Exception:
            return "other", None
    if isinstance(value, sp.Expr):
        return "scalar", value
    if isinstance(value, sp.Basic):
        return "other", None
    if isinstance(value, (numbers.Number, np.number)):
        v = value.item() if isinstance(value, np.generic) else value
        return "scalar", sp.sympify(v)
    return "other", None


def _type_name(value):
    t = type(value)
    return f"{t.__module__}.{t.__qualname__}" if t.__module__ not in ("builtins",) else t.__qualname__


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


def describe_expr(value, points, seed=0):
    """Matrix/expression answer: type, shape, symbols and values at ``points`` (dicts name -> float)."""
    import sympy as sp
    tag, obj = to_sympy(value)
    out = {"tag": tag, "type": _type_name(value)}
    if obj is None:
        return out
    syms = sorted({s.name for s in obj.free_symbols if isinstance(s, sp.Symbol)})
    out.update(shape=_shape(obj), symbols=syms, has_float=bool(obj.atoms(sp.Float)),
               degrees=_degrees_hint(obj),
               undefined=sorted({str(f.func) for f in obj.atoms(sp.core.function.AppliedUndef)}))
    entries = list(obj) if isinstance(obj, sp.MatrixBase) else [obj]
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
    """Members of the 1-D set ``S`` in [-window, window]: (points, intervals); raises ValueError if unknown."""
    import sympy as sp
    if isinstance(S, (set, frozenset, list, tuple)):
        S = sp.FiniteSet(*[sp.sympify(v) for v in S])
    if S is sp.S.EmptySet:
        return [], []
    if S in (sp.S.Reals, sp.S.UniversalSet) or isinstance(S, sp.sets.sets.UniversalSet):
        return [], [[-math.inf, math.inf]]
    if S is sp.S.Complexes:
        return [], [[-math.inf, math.inf]]
    if isinstance(S, sp.FiniteSet):
        pts = []
        for e in S.args:
            x = _real(sp.sympify(e), subs)
            if x is None:
                raise ValueError(f"member {e} is not a real number")
            pts.append(x)
        return pts, []
    if isinstance(S, sp.Interval):
        return [], [[_real(S.start, subs), _real(S.end, subs)]]
    if isinstance(S, sp.Union):
        pts, ivs = [], []
        for a in S.args:
            p, i = _enum1d(a, subs, window)
            pts += p
            ivs += i
        return pts, ivs
    if isinstance(S, sp.ImageSet):
        lam = S.lamda
        base = S.base_sets[0] if hasattr(S, "base_sets") else S.base_set
        if len(lam.variables) != 1 or base not in (sp.S.Integers, sp.S.Naturals, sp.S.Naturals0):
            raise ValueError("only image sets over the integers can be compared")
        v = lam.variables[0]
        f = lam.expr.xreplace(subs) if subs else lam.expr
        f0, f1 = _real(f.xreplace({v: 0}), {}), _real(f.xreplace({v: 1}), {})
        step = abs(f1 - f0) if f0 is not None and f1 is not None else 0.0
        K = min(2000, int(2 * window / step) + 3) if step > 1e-9 else 50
        lo = 0 if base is sp.S.Naturals0 else (1 if base is sp.S.Naturals else -K)
        pts = []
        for n in range(lo, K + 1):
            x = _real(f.xreplace({v: n}), {})
            if x is not None and abs(x) <= window:
                pts.append(x)
        return pts, []
    if isinstance(S, sp.Intersection):
        enumerable = []
        filters = []
        for a in S.args:
            if isinstance(a, sp.Interval) or a in (sp.S.Reals,):
                filters.append(a)
            else:
                enumerable.append(a)
        if not enumerable:
            raise ValueError("an intersection of intervals cannot be compared")
        pts, ivs = _enum1d(enumerable[0], subs, window)
        if ivs:
            raise ValueError("cannot compare an intersection with a continuous set")
        for other in enumerable[1:]:
            p2, i2 = _enum1d(other, subs, window)
            pts = [x for x in pts if any(abs(x - y) < 1e-7 for y in p2)
                   or any(a <= x <= b for a, b in i2)]
        for fset in filters:
            if fset is sp.S.Reals:
                continue
            a, b = _real(fset.start, subs), _real(fset.end, subs)
            pts = [x for x in pts if (a < x < b) or (not fset.left_open and abs(x - a) < 1e-12)
                   or (not fset.right_open and abs(x - b) < 1e-12)]
        return pts, []
    raise ValueError(f"a {type(S).__name__} cannot be enumerated (use FiniteSet, ImageSet or Union)")


def describe_set(value, points, seed=0, window=4 * math.pi):
    """Set-of-configurations answer: {var name or None: {points, intervals}} at the first point(s)."""
    import numpy as np
    import sympy as sp
    out = {"tag": "set", "type": _type_name(value)}
    if value is Ellipsis:
        return {"tag": "ellipsis", "type": "ellipsis"}
    if value is None:
        return {"tag": "none", "type": "NoneType"}
    if isinstance(value, (dict, sp.Dict)):
        items = list(dict(value).items())
    elif isinstance(value, (sp.Set, set, frozenset, list, tuple, np.ndarray)):
        items = [(None, value)]
    else:
        out["tag"] = "other"
        return out
    per_point = []
    for p in points:
        comps = []
        for k, S in items:
            name = k.name if isinstance(k, sp.Symbol) else (str(k) if k is not None else None)
            S_ = S
            if isinstance(S_, np.ndarray):
                S_ = S_.tolist()
            subs = _subs_for(S_, p, seed) if isinstance(S_, sp.Basic) else {}
            comp = {"var": name}
            try:
                if isinstance(S_, sp.FiniteSet) and any(isinstance(a, (sp.Tuple, sp.MatrixBase)) for a in S_.args) \
                        or isinstance(S_, (list, tuple, set, frozenset)) and S_ and \
                        all(isinstance(a, (tuple, list, sp.Tuple)) for a in S_):
                    tuples = []
                    for a in (S_.args if isinstance(S_, sp.FiniteSet) else S_):
                        t = []
                        for e in a:
                            x = _real(sp.sympify(e), subs)
                            if x is None:
                                raise ValueError(f"member {a} is not real")
                            t.append(x)
                        tuples.append(t)
                    comp["tuples"] = tuples
                else:
                    pts, ivs = _enum1d(S_, subs, window)
                    comp["points"] = pts
                    comp["intervals"] = ivs
            except Exception as exc:  # noqa: BLE001  (any failure is reported, not raised)
                comp["error"] = f"{type(exc).__name__}: {exc}"[:300]
            comps.append(comp)
        per_point.append(comps)
    out["points"] = per_point
    return out


# ----------------------------------------------------------------------------- choices

def _choice(x):
    import numpy as np
    import sympy as sp
    if isinstance(x, (bool, np.bool_)) or x is sp.true or x is sp.false:
        return bool(x)
    if isinstance(x, str):
        return x.strip().lower()
    if isinstance(x, (sp.FiniteSet, sp.Tuple, list, tuple, set, frozenset, np.ndarray)):
        items = list(x.args) if isinstance(x, (sp.FiniteSet, sp.Tuple)) else list(x)
        return [_choice(e) for e in items]
    if isinstance(x, sp.MatrixBase):
        return [_choice(e) for e in x]
    try:
        f = float(x)
    except Exception:
        return {"other": _type_name(x)}
    if f == int(f):
        return int(f)
    return f


def describe_choice(value, points=(), seed=0):
    if value is Ellipsis:
        return {"tag": "ellipsis", "type": "ellipsis"}
    if value is None:
        return {"tag": "none", "type": "NoneType"}
    return {"tag": "choice", "type": _type_name(value), "value": _choice(value)}


DESCRIBE = {"expr": describe_expr, "subspace": describe_expr, "set": describe_set, "choice": describe_choice}


def describe(kind, value, points, seed=0):
    return DESCRIBE.get(kind, describe_expr)(value, points, seed)


# ----------------------------------------------------------------------------- reference dump

def normalize_reference(kind, value):
    """The reference value as something ``srepr`` round-trips (instructor side only)."""
    import numpy as np
    import sympy as sp
    if kind in ("expr", "subspace"):
        tag, obj = to_sympy(value)
        if obj is None:
            raise TypeError(f"reference answer of kind {kind!r} is {tag} ({_type_name(value)})")
        return obj
    if kind == "set":
        if isinstance(value, dict):
            return {k: (sp.FiniteSet(*v) if isinstance(v, (set, frozenset, list, tuple)) else v)
                    for k, v in value.items()}
        if isinstance(value, (set, frozenset, list, tuple, np.ndarray)):
            return sp.FiniteSet(*[sp.sympify(v) for v in np.asarray(value, dtype=object).ravel()])
        return value
    return value


def dump_reference(ns, answers):
    """{name: {"srepr": ..., "symbols": {name: {"positive": bool}}} or {"error": ...}} for the reference."""
    import sympy as sp
    out = {}
    for name, kind in answers.items():
        if name not in ns:
            out[name] = {"error": f"{name} is not defined after the solution notebook ran"}
            continue
        try:
            if kind == "choice":
                out[name] = {"choice": describe_choice(ns[name])}
                continue
            obj = normalize_reference(kind, ns[name])
            text = sp.srepr(obj)
            syms = set()
            for s in getattr(obj, "free_symbols", set()) or set():
                syms.add(s)
            if isinstance(obj, dict):
                for k, v in obj.items():
                    syms |= getattr(v, "free_symbols", set())
            out[name] = {"srepr": text, "symbols": {s.name: {"positive": bool(s.is_positive)}
                                                     for s in syms if isinstance(s, sp.Symbol)}}
        except Exception as exc:  # noqa: BLE001
            out[name] = {"error": f"{type(exc).__name__}: {exc}"[:500]}
    return out


def parse_srepr(text):
    """Evaluate a *reference* srepr string (instructor data; never call this on student text)."""
    import sympy as sp
    ns = {}
    exec("from sympy import *", ns)  # noqa: S102  (trusted instructor data)
    ns.update({"Integer": sp.Integer, "Rational": sp.Rational, "Float": sp.Float, "Symbol": sp.Symbol,
               "Dummy": sp.Dummy, "ImmutableDenseMatrix": sp.ImmutableDenseMatrix,
               "MutableDenseMatrix": sp.MutableDenseMatrix})
    return eval(text, ns)  # noqa: S307  (trusted instructor data)


# ----------------------------------------------------------------------------- exact equivalence (student kernel)

def exact_equal(value, ref_text, budget=5.0):
    """'equal' when value - reference simplifies to exactly zero, else 'not proved' (advisory only)."""
    import time

    import sympy as sp
    t0 = time.monotonic()
    tag, obj = to_sympy(value)
    if obj is None:
        return "not sympy"
    ref = parse_srepr(ref_text)
    ref_syms = {s.name: s for s in ref.free_symbols if isinstance(s, sp.Symbol)}
    obj = obj.xreplace({s: ref_syms[s.name] for s in obj.free_symbols
                        if isinstance(s, sp.Symbol) and s.name in ref_syms})
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


# ----------------------------------------------------------------------------- entry points used in a kernel

STASH = {}


def stash(ns, names):
    """Keep the values of ``names`` as they are right after their solution cell ran."""
    import copy
    for n in names:
        if n in ns:
            try:
                STASH[n] = copy.copy(ns[n])
            except Exception:  # noqa: BLE001
                STASH[n] = ns[n]


def _value(ns, name):
    """The answer as it was when its part ended; the final value if it was not there yet (or ``...``)."""
    v = STASH.get(name, _MISSING)
    if v is _MISSING or v is Ellipsis:
        final = ns.get(name, _MISSING)
        if final is not _MISSING and final is not Ellipsis:
            return final
    return v if v is not _MISSING else ns.get(name, _MISSING)


def probe_answer(ns, name, kind, points, seed, path):
    """Describe the answer ``name`` and write the JSON to ``path`` (once per answer, in the kernel)."""
    value = _value(ns, name)
    if value is _MISSING:
        res = {"tag": "missing"}
    else:
        try:
            res = describe(kind, value, points, seed)
        except Exception as exc:  # noqa: BLE001
            res = {"tag": "probe-error", "error": f"{type(exc).__name__}: {exc}"[:500]}
    with open(path, "w") as f:
        json.dump(res, f)


def probe_exact(ns, name, ref_text, path):
    value = _value(ns, name)
    try:
        res = {"exact": exact_equal(value, ref_text)} if value is not _MISSING else {"exact": "missing"}
    except Exception as exc:  # noqa: BLE001
        res = {"exact": "error", "error": f"{type(exc).__name__}: {exc}"[:300]}
    with open(path, "w") as f:
        json.dump(res, f)


SNAP = None


def restore_saved(path):
    """Restore the snapshot taken before the first student cell; write how many attributes changed."""
    n = restore(SNAP) if SNAP is not None else 0
    with open(path, "w") as f:
        json.dump({"restored": n}, f)


def probe_reference(ns, answers, path):
    values = {}
    for name in answers:
        v = _value(ns, name)
        if v is not _MISSING:
            values[name] = v
    with open(path, "w") as f:
        json.dump(dump_reference(values, answers), f)


_ = cmath  # kept importable for evaluations that return complex numbers
