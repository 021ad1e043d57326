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


_NOT_RESTORED = {"input", "raw_input", "get_ipython", "display", "help", "exit", "quit"}


def _fn(v):
    """Functions, classes and descriptors are restored; data (counters, caches, flags) is left alone."""
    return callable(v) or isinstance(v, (staticmethod, classmethod, property))


def _display_only(k):
    """Rich-display hooks (``init_printing`` sets them): they do not change any value."""
    return str(k).startswith("_repr_")


def restore(snap):
    """Undo replaced functions/classes in the snapshotted namespaces; returns the names put back."""
    import types
    fixed = []
    for name, m in snap["sysmods"].items():
        if sys.modules.get(name) is not m:
            sys.modules[name] = m
            fixed.append(f"sys.modules[{name!r}]")
    for name, (m, saved) in snap["mods"].items():
        cur = m.__dict__
        for k in list(cur):
            if k not in saved and _fn(cur[k]) and not isinstance(cur[k], types.ModuleType) \
                    and not k.startswith("__") and k not in _NOT_RESTORED:
                del cur[k]
                fixed.append(f"{name}.{k} (added)")
        for k, v in saved.items():
            if cur.get(k, _MISSING) is not v and _fn(v) and not k.startswith("__") and k not in _NOT_RESTORED:
                cur[k] = v
                fixed.append(f"{name}.{k}")
    for cls, saved in snap["classes"].values():
        where = f"{cls.__module__}.{cls.__qualname__}"
        for k in list(cls.__dict__):
            if k not in saved and _fn(cls.__dict__[k]) and not _display_only(k):
                try:
                    delattr(cls, k)
                    fixed.append(f"{where}.{k} (added)")
                except (AttributeError, TypeError):
                    pass
        for k, v in saved.items():
            if cls.__dict__.get(k, _MISSING) is not v and _fn(v) and not _display_only(k):
                try:
                    setattr(cls, k, v)
                    fixed.append(f"{where}.{k}")
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
    if isinstance(value, (bool, np.bool_)) or value is sp.true or value is sp.false:
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


def describe_expr(value, points, seed=0):
    """Matrix/expression answer: type, shape, symbols and values at ``points`` (dicts name -> float)."""
    import sympy as sp
    if isinstance(value, dict) and value and all(isinstance(k, (str, int)) for k in value):
        return {"tag": "dict", "type": "dict",
                "items": {str(k): describe_expr(v, points, seed) for k, v in value.items()}}
    tag, obj = to_sympy(value)
    out = {"tag": tag, "type": _type_name(value)}
    if obj is None:
        return out
    syms = sorted({s.name for s in obj.free_symbols if isinstance(s, sp.Symbol)})
    out.update(shape=_shape(obj), symbols=syms, has_float=bool(obj.atoms(sp.Float)),
               degrees=_degrees_hint(obj),
               undefined=sorted({str(f.func) for f in obj.atoms(sp.core.function.AppliedUndef)}))
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


def _conditions(value):
    """A set-of-configurations answer as a list of conditions, each a list of (key, 1-D set or tuples).

    A SymPy Set or a Python set/list of values is one condition on one (unnamed) joint; a dict
    {symbol: Set} is one condition on each named joint; a list of such dicts (as
    ``kinlib.singularities.singular_configurations`` returns) is a union of conditions; an empty list or
    ``EmptySet`` is the empty set.
    """
    import numpy as np
    import sympy as sp
    if isinstance(value, (dict, sp.Dict)):
        return [list(dict(value).items())]
    if isinstance(value, (list, tuple)) and all(isinstance(v, (dict, sp.Dict)) for v in value):
        return [list(dict(v).items()) for v in value]
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (sp.Set, set, frozenset, list, tuple)):
        return [[(None, value)]]
    return None


def _component(key, S, p, seed, window):
    import sympy as sp
    name = key.name if isinstance(key, sp.Symbol) else (str(key) if key is not None else None)
    subs = _subs_for(S, p, seed) if isinstance(S, sp.Basic) else {}
    comp = {"var": name}
    try:
        if isinstance(S, sp.FiniteSet) and any(isinstance(a, (sp.Tuple, sp.MatrixBase)) for a in S.args) \
                or isinstance(S, (list, tuple, set, frozenset)) and S and \
                all(isinstance(a, (tuple, list, sp.Tuple)) for a in S):
            tuples = []
            for a in (S.args if isinstance(S, sp.FiniteSet) else S):
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
    """Set-of-configurations answer: per point, a list of conditions, each a list of components
    {"var": name or None, "points"/"intervals" (members in [-window, window]) or "tuples"}."""
    if value is Ellipsis:
        return {"tag": "ellipsis", "type": "ellipsis"}
    if value is None:
        return {"tag": "none", "type": "NoneType"}
    conds = _conditions(value)
    if conds is None:
        return {"tag": "other", "type": _type_name(value)}
    per_point = []
    for p in points:
        per_point.append([[_component(k, S, p, seed, window) for k, S in cond] for cond in conds])
    return {"tag": "set", "type": _type_name(value), "conditions": per_point}


def looks_like_set(value):
    """Answers of the default kind that are really sets of configurations (Sets, {symbol: Set}, lists of those)."""
    import sympy as sp
    if isinstance(value, sp.Set):
        return True
    if isinstance(value, (dict, sp.Dict)):
        return bool(value) and all(isinstance(k, sp.Symbol) for k in dict(value))
    if isinstance(value, (list, tuple)):
        return len(value) == 0 or all(isinstance(v, (dict, sp.Dict)) and looks_like_set(v) for v in value)
    return False


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
    if kind == "expr" and isinstance(value, dict) and value and all(isinstance(k, (str, int)) for k in value):
        return {str(k): normalize_reference(kind, v) for k, v in value.items()}
    if kind in ("expr", "subspace"):
        tag, obj = to_sympy(value)
        if obj is None:
            raise TypeError(f"reference answer of kind {kind!r} is {tag} ({_type_name(value)})")
        return obj
    if kind == "set":
        if isinstance(value, (list, tuple)) and all(isinstance(v, dict) for v in value):
            return [normalize_reference(kind, v) for v in value]
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
            if kind == "expr" and looks_like_set(ns[name]):
                kind = "set"
            if kind == "expr" and (isinstance(ns[name], (bool, str)) or ns[name] is sp.true or ns[name] is sp.false
                                   or type(ns[name]).__name__ == "bool_"):
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
            out[name] = {"kind": kind, "srepr": text, "symbols": {s.name: {"positive": bool(s.is_positive)}
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
    names = restore(SNAP) if SNAP is not None else []
    with open(path, "w") as f:
        json.dump({"restored": names[:50]}, f)


def probe_reference(ns, answers, path):
    values = {}
    for name in answers:
        v = _value(ns, name)
        if v is not _MISSING:
            values[name] = v
    with open(path, "w") as f:
        json.dump(dump_reference(values, answers), f)

