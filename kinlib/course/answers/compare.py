"""Instructor side of the checker: compare the JSON a student kernel sent with the reference's.

Everything here works on plain JSON data (numbers, strings, lists) produced by
:mod:`kinlib.course.grader.in_kernel.probe`; nothing from a submission is evaluated. Each comparison returns
``(ok, message)``; messages name the mistake when it is recognizable (wrong shape, transposed,
wrong sign, columns swapped, [v; ω] instead of [ω; v], degrees instead of radians, a missing or
extra variable) without printing the reference answer or anything that gives it away (a factor, the
answer's dimension, its number of members or conditions, which joints it restricts): only what the
student can read off their own answer.

* **expr**: values at the points; **subspace**: spans, whatever the basis and its scaling (each column
  normalised, principal angles between orthonormal bases; constant exact bases by exact ranks);
* **set**: members compared modulo 2π whenever the reference is a set of angles (members that are simple
  multiples of π, or a joint angle's family), whatever the set is keyed by; FiniteSets, ImageSets, unions
  and ``solveset`` results alike; degrees named; **choice**: as sets;
* **property:<p>** (:mod:`kinlib.course.answers.properties`): open-ended answers by the property asked, decided
  exactly, never by one design's value (5.5: det(J Jᵀ) ≠ 0 for every θ).
"""

from __future__ import annotations

import math
import re
from fractions import Fraction

import numpy as np

from . import mistakes
from .properties import exact_ranks, judge

__all__ = [
    "compare",
    "compare_expr",
    "compare_subspace",
    "compare_set",
    "compare_choice",
    "compare_property",
    "COMPARE",
    "NOT_ANSWERED",
    "RTOL",
    "ATOL",
]

RTOL, ATOL = 1e-6, 1e-8

NOT_ANSWERED = {
    "missing": "is not defined after your notebook ran (never assigned, deleted, or its cell failed)",
    "ellipsis": "is still `...`: not answered yet",
    "none": "is None",
    "bool": "is True/False (an equation sp.Eq(...) or a comparison?); expected a SymPy expression or matrix",
    "empty": "is an empty list",
    "ragged": "is a list of vectors of different lengths",
    "array": "is an array with more than 2 dimensions",
    "probe-error": "could not be read",
}


def _fmt_shape(shape):
    return "a scalar" if not shape else "×".join(str(s) for s in shape)


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


def _arr(values):
    """[[ [re, im] | None per entry ] per point] -> complex array (points, entries), with NaN for None."""
    out = np.full((len(values), len(values[0]) if values else 0), np.nan + 0j, dtype=complex)
    for i, row in enumerate(values):
        for j, v in enumerate(row):
            if v is not None:
                out[i, j] = complex(float(v[0]), float(v[1]))
    return out


def _close(a, b):
    return bool(np.all(np.abs(a - b) <= ATOL + RTOL * np.maximum(np.abs(a), np.abs(b))))


def _not_answered(desc):
    tag = desc.get("tag")
    if tag in NOT_ANSWERED:
        msg = NOT_ANSWERED[tag]
        if tag == "probe-error" and desc.get("error"):
            msg += f" ({desc['error']})"
        return msg
    return None


def _symbol_notes(stu, ref):
    rs, ss = set(ref.get("symbols", [])), set(stu.get("symbols", []))
    notes = []
    missing, extra = sorted(rs - ss), sorted(ss - rs)
    if missing and not ss:
        notes.append(f"is a constant, but the answer depends on {', '.join(sorted(rs))}")
    elif missing:
        notes.append(f"does not depend on {', '.join(missing)} (a missing variable: did you substitute a number?)")
    if extra:
        known = ", ".join(sorted(rs)) or "no symbols"
        notes.append(f"uses {', '.join(extra)}, which the problem does not (the answer is in terms of {known})")
    return notes


def _entries(idx, shape):
    cols = shape[1] if len(shape) == 2 else 1
    return ", ".join(f"({i // cols + 1},{i % cols + 1})" for i in idx[:6]) + (" …" if len(idx) > 6 else "")


def compare_expr(stu: dict, ref: dict, name: str) -> tuple[bool, str]:
    """Matrices and expressions as functions of the symbols: same shape, same values at the points.

    >>> ref = {"shape": [1, 2], "symbols": [], "values": [[[1.0, 0.0], [2.0, 0.0]]]}
    >>> compare_expr(dict(ref, tag="matrix"), ref, "v")
    (True, '')
    >>> compare_expr(dict(ref, tag="matrix", shape=[2, 1]), ref, "v")
    (False, 'v is transposed: yours is 2×1, expected 1×2')
    """
    na = _not_answered(stu)
    if na:
        return False, f"{name} {na}"
    if ref.get("tag") == "dict":
        if stu.get("tag") != "dict":
            return False, f"{name} is a {stu.get('type')}; expected a dict with keys {', '.join(ref['items'])}"
        if set(stu["items"]) != set(ref["items"]):
            missing, extra = (
                sorted(set(ref["items"]) - set(stu["items"])),
                sorted(set(stu["items"]) - set(ref["items"])),
            )
            what = [f"no key {', '.join(map(repr, missing))}"] if missing else []
            what += [f"keys {', '.join(map(repr, extra))} that are not asked for"] if extra else []
            return False, f"{name} has " + " and ".join(what)
        msgs = [compare_expr(stu["items"][k], ref["items"][k], f"{name}[{k!r}]") for k in ref["items"]]
        return all(ok for ok, _ in msgs), "; ".join(m for _, m in msgs if m)
    if stu.get("tag") not in ("matrix", "scalar"):
        if str(stu.get("type", "")).endswith("Equality"):
            return False, f"{name} is an equation (sp.Eq): assign the expression or matrix itself"
        return False, f"{name} is a {stu.get('type')}; expected a SymPy expression or Matrix"
    rshape, sshape = list(ref["shape"]), list(stu["shape"])
    if rshape in ([1, 1], []) and sshape in ([1, 1], []):
        rshape = sshape
    if sshape != rshape:
        if len(sshape) == 2 and sshape[::-1] == rshape:
            return False, (
                f"{name} is transposed: yours is {_fmt_shape(sshape)}, expected "
                f"{_fmt_shape(rshape)}" + (" (one column per joint)" if rshape[0] == 6 else "")
            )
        return False, f"{name} has the wrong shape: yours is {_fmt_shape(sshape)}, expected {_fmt_shape(rshape)}"
    if stu.get("undefined"):
        return False, f"{name} contains undefined functions {', '.join(stu['undefined'])}"
    S, R = _arr(stu["values"]), _arr(ref["values"])
    if S.shape != R.shape:
        return False, f"{name} could not be compared (malformed values)"
    if np.isnan(S).any():
        return False, f"{name} could not be evaluated at some joint values (division by zero, or undefined symbols?)"
    notes = _symbol_notes(stu, ref)
    if _close(S, R):
        extra = []
        if stu.get("has_float") and not ref.get("has_float"):
            extra.append("contains decimals: use exact values (sp.pi, sp.sqrt(2), sp.Rational(1, 2))")
        return True, "; ".join(extra)
    return False, f"{name} " + "; ".join(notes + [_no_key(_diagnose(S, R, rshape, stu))])


_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_LEAKS = [
    (re.compile(rf"\s*\({_NUM}\s*times the answer\)"), ""),
    (re.compile(rf"\bis {_NUM} times the answer"), "is within 1% of the answer"),
    (re.compile(rf"\b{_NUM} times the answer"), "a constant times the answer"),
]


def _no_key(msg: str) -> str:
    """A diagnosis without numbers that give the reference away: "off by a constant factor (0.5 times the
    answer)" tells the student the answer is theirs / 0.5, so the factor is dropped.

    >>> _no_key("is off by a constant factor (0.5 times the answer)")
    'is off by a constant factor'
    >>> _no_key("is 0.997 times the answer: rounded decimals?")
    'is within 1% of the answer: rounded decimals?'
    """
    for rx, rep in _LEAKS:
        msg = rx.sub(rep, msg)
    return msg


def _diagnose(S, R, shape, stu) -> str:
    """What is wrong with values S (points × entries) against R: a named mistake of
    :mod:`kinlib.course.answers.mistakes` (the self-check's too), else which entries differ; never a value."""
    P = S.shape[0]
    r, c = (shape + [1, 1])[:2] if len(shape) == 2 else (1, 1)
    S3, R3 = S.reshape(P, r, c), R.reshape(P, r, c)
    found = mistakes.search(S3, lambda X: X.shape == R3.shape and _close(X, R3), exhaustive=True)
    if found is not None:
        return found.says
    neg = [k for k in range(S.shape[1]) if _close(S[:, k], -R[:, k]) and not _close(S[:, k], R[:, k])]
    bad = [k for k in range(S.shape[1]) if not _close(S[:, k], R[:, k])]
    if neg and len(neg) == len(bad):
        return f"has the wrong sign in entries {_entries(neg, shape)}"
    if np.all(np.abs(S) < 1e-12):
        return "is zero everywhere"
    ratio = _const_ratio(S, R)
    if ratio is not None:
        if abs(abs(ratio) - 180 / math.pi) < 1e-6 * 180 / math.pi or abs(abs(ratio) - math.pi / 180) < 1e-9:
            return "looks like it is in degrees: SymPy and NumPy angles are radians (45° = sp.pi/4)"
        if abs(ratio - 1) < 1e-2:
            return "is close to the answer but not equal: rounded decimals? Use exact values (sp.sqrt(2), sp.pi)"
        return "is off by a constant factor (a factor missing or extra, e.g. a length or ½?)"
    if stu.get("degrees"):
        return "looks like it uses degrees inside sin/cos (e.g. sin(θ + 45)): angles are radians, write sp.pi/4"
    if S.shape[1] > 1:
        return f"differs in entries {_entries(bad, shape)}"
    return "has the wrong value"


def _const_ratio(S, R):
    mask = np.abs(R) > 1e-6
    if not mask.any() or np.any(np.abs(S[~mask]) > 1e-6):
        return None
    q = S[mask] / R[mask]
    if np.allclose(q, q.flat[0], rtol=1e-6, atol=0) and abs(q.flat[0].imag) < 1e-9:
        return float(q.flat[0].real)
    return None


# ----------------------------------------------------------------------------- subspaces


SUBSPACE_TOL = 1e-7  # rank cut-off on singular values of unit columns; largest principal angle (sine)


def _orthonormal(A):
    """An orthonormal basis (columns) of the span of A's columns, whatever their scaling.

    Each column is scaled to length 1 first (a column 10¹² or 10⁻¹² times another counts the same), columns
    that are zero (or round-off beside the largest: below 10⁻¹³ of it) dropped; the rank is the number of
    singular values of the unit columns above ``SUBSPACE_TOL`` (the largest is ≥ 1).
    """
    if A.size == 0:
        return A[:, :0]
    norms = np.linalg.norm(A, axis=0)
    top = norms.max()
    if not np.isfinite(top) or top == 0:
        return A[:, :0]
    keep = norms > 1e-13 * top
    U = A[:, keep] / norms[keep]
    u, s, _ = np.linalg.svd(U, full_matrices=False)
    return u[:, : int(np.sum(s > SUBSPACE_TOL * s[0]))]


def _same_span(QA, QB):
    """Largest principal angle between two subspaces of one dimension (orthonormal bases) is ~0."""
    if QA.shape[1] != QB.shape[1]:
        return False
    if QA.shape[1] == 0:
        return True
    resid = QA - QB @ (QB.conj().T @ QA)
    return float(np.linalg.norm(resid, 2)) < 1e-6


def compare_subspace(stu: dict, ref: dict, name: str) -> tuple[bool, str]:
    """A subspace by its span, at every point: orthonormal bases of both (each column normalised first,
    so no scaling of a basis matters) of one dimension, and principal angles ~0 between them.

    >>> ref = {"shape": [2, 1], "symbols": [], "values": [[[1.0, 0.0], [0.0, 0.0]]]}
    >>> compare_subspace(dict(ref, tag="matrix", values=[[[3e12, 0.0], [0.0, 0.0]]]), ref, "s")
    (True, '')
    >>> compare_subspace(dict(ref, tag="matrix", values=[[[1e12, 0.0], [1e12, 0.0]]]), ref, "s")[0]
    False
    """
    na = _not_answered(stu)
    if na:
        return False, f"{name} {na}"
    if stu.get("tag") not in ("matrix", "scalar"):
        return False, f"{name} is a {stu.get('type')}; expected a Matrix whose columns span the subspace"
    rshape, sshape = list(ref["shape"]) or [1, 1], list(stu["shape"]) or [1, 1]
    if len(sshape) == 1:
        sshape = [sshape[0], 1]
    if len(rshape) == 1:
        rshape = [rshape[0], 1]
    S, R = _arr(stu["values"]), _arr(ref["values"])
    if S.shape[0] != R.shape[0]:
        return False, f"{name} could not be compared (malformed values)"
    if np.isnan(S).any() or not np.isfinite(S).all():
        return False, f"{name} could not be evaluated at some values of the symbols"
    if sshape[0] != rshape[0]:
        if sshape[1] == rshape[0]:
            return False, (
                f"{name} gives the vectors as rows ({_fmt_shape(sshape)}): put one vector per column ({rshape[0]} rows)"
            )
        return False, f"{name} has vectors of length {sshape[0]}; expected {rshape[0]}"
    notes = _symbol_notes(stu, ref)
    exact = exact_ranks(stu.get("tree"), ref.get("tree"))
    if exact is not None:
        ra, rb, rab = exact
        if ra != rb:
            dep = f" ({sshape[1]} columns, {ra} independent)" if sshape[1] != ra else ""
            return False, f"{name} spans a {ra}-dimensional space{dep}, not the right dimension"
        if rab != rb:
            return False, (
                f"{name} spans a space of the right dimension but not the right one (some of your directions "
                "are not in the answer's span)"
            )
        return True, "" if sshape[1] == rshape[1] else f"same span (you gave {sshape[1]} columns)"
    for p in range(S.shape[0]):
        QA = _orthonormal(S[p].reshape(sshape))
        QB = _orthonormal(R[p].reshape(rshape))
        ra = QA.shape[1]
        if ra != QB.shape[1]:
            dep = f" ({sshape[1]} columns, {ra} independent)" if sshape[1] != ra else ""
            return False, (
                f"{name} spans a {ra}-dimensional space{dep}, not the right dimension"
                + (f"; {notes[0]}" if notes else "")
            )
        if not _same_span(QA, QB):
            return False, (
                f"{name} spans a space of the right dimension but not the right one (some of your directions "
                "are not in the answer's span)" + (f"; {'; '.join(notes)}" if notes else "")
            )
    extra = "" if sshape[1] == rshape[1] else f"same span (you gave {sshape[1]} columns)"
    return True, extra


# ----------------------------------------------------------------------------- sets of configurations


def _wrap(x):
    y = math.remainder(x, 2 * math.pi)
    return math.pi if abs(y + math.pi) < 1e-9 else y


def _canon_points(pts, periodic, scale=1.0):
    out = []
    for x in pts:
        x = x * scale
        if periodic:
            x = _wrap(x)
        if not any(abs(x - y) < 1e-6 for y in out):
            out.append(x)
    return sorted(out)


def _same(a, b):
    return len(a) == len(b) and all(abs(x - y) < 1e-6 for x, y in zip(a, b))


def _canon_intervals(ivs):
    return sorted([float(a) if a is not None else -math.inf, float(b) if b is not None else math.inf] for a, b in ivs)


def _empty(c):
    return not c.get("error") and not c.get("points") and not c.get("intervals") and not c.get("tuples")


def _free(c):
    return c.get("intervals") == [[-math.inf, math.inf]] and not c.get("points")


_GREEK = {"θ": "theta", "φ": "phi", "ψ": "psi", "α": "alpha", "β": "beta", "γ": "gamma"}


def _var_name(v):
    """A joint variable's name without typesetting: θ_2, theta_{2}, \\theta_2 and theta2 are one variable.

    >>> [_var_name(v) for v in ("θ_2", "theta_{2}", r"\\theta_2", "theta2", None)]
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
            v = _var_name(c.get("var"))
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
    return bool(inner) and all(any(abs(x + 2 * math.pi - y) < 1e-6 for y in pts) for x in inner)


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
    'v: these look like degrees (90, 270): angles are radians (90° = sp.pi/2)'
    """
    na = _not_answered(stu)
    if na:
        return False, f"{name} {na}"
    if stu.get("tag") != "set":
        return False, (
            f"{name} is a {stu.get('type')}; expected a SymPy Set, a dict {{symbol: Set}} or a list of those"
        )
    if len(stu.get("conditions", [])) != len(ref.get("conditions", [])):
        return False, f"{name} could not be compared (malformed values)"
    for sp_, rp in zip(stu["conditions"], ref["conditions"]):
        ref_vars = {_var_name(c.get("var")) for cond in rp for c in cond if c.get("var") is not None}
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
    return f"these look like degrees ({shown}): angles are radians (90° = sp.pi/2)"


def _compare_component(s, r, periodic):
    if "tuples" in r or "tuples" in s:
        if "tuples" not in s or "tuples" not in r:
            return False, "expected a set of configurations (tuples)"

        def canon(ts):
            out = []
            for t in ts:
                t = [_wrap(x) if periodic else x for x in t]
                if not any(len(t) == len(u) and all(abs(a - b) < 1e-6 for a, b in zip(t, u)) for u in out):
                    out.append(t)
            return sorted(out)

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
    missing = [x for x in rp if not any(abs(x - y) < 1e-6 for y in sp_)]
    wrong = [x for x in sp_ if not any(abs(x - y) < 1e-6 for y in rp)]
    where = " (compared modulo 2π)" if periodic else ""
    if wrong:
        return False, (
            f"{', '.join(_pi_multiple(x) for x in wrong[:4])} "
            f"{'is' if len(wrong) == 1 else 'are'} not in the set{where}"
        )
    if missing:
        return False, f"some values of the set are missing{where}"
    return False, "not the right set"


# ----------------------------------------------------------------------------- answers graded by a property


def compare_property(stu: dict, ref: dict, name: str, prop: str = "nonsingular") -> tuple[bool, str]:
    """An open-ended answer graded by the property asked, never by one design's value (the reference is not
    used): :func:`kinlib.course.answers.properties.judge`. ``prop``: "nonsingular": the answer is the student's own
    redesigned robot (or its task Jacobian J), whose det(J Jᵀ) must be nonzero for every joint value, proved
    exactly (kinlib.singularities); a bare value of det(J Jᵀ) belongs to no robot and fails.

    >>> compare_property({"tag": "scalar", "tree": ["int", "1"]}, {}, "d")[0]
    False
    >>> col = lambda *xs: [["int", str(x)] for x in xs]
    >>> three_r = col(0, 0, 0, 0, 0, 0, 1, 1, 1, 0, 0, 0, 0, -1, -2, 0, 0, 0)   # joints at x = 0, 1, 2
    >>> compare_property({"tag": "robot", "tree": ["matrix", 6, 3, *three_r]}, {}, "d")[1]
    'd: det(J Jᵀ) of your robot = 0 where theta2 = 0, pi (+ 2πk): your design still has singular configurations'
    """
    na = _not_answered(stu)
    if na:
        return False, f"{name} {na}"
    return judge(prop, stu, name)


# ----------------------------------------------------------------------------- choices


def _canon_choice(x):
    if isinstance(x, list):
        if all(not isinstance(e, list) for e in x):
            return frozenset(_hashable(e) for e in x)
        return tuple(_canon_choice(e) for e in x)
    return frozenset([_hashable(x)])


def _hashable(x):
    return repr(x) if isinstance(x, dict) else x


def compare_choice(stu: dict, ref: dict, name: str) -> tuple[bool, str]:
    """Choices (joint numbers, 1-based; ties as tuples) compared as sets.

    >>> compare_choice({"tag": "choice", "value": [2, 1]}, {"value": [1, 2]}, "j")
    (True, '')
    >>> compare_choice({"tag": "choice", "value": [1]}, {"value": [1, 2]}, "j")[1]
    'j: (1) is not the right choice (a tie counts: give a tuple of every joint that qualifies)'
    """
    na = _not_answered(stu)
    if na:
        return False, f"{name} {na}"
    if stu.get("tag") != "choice":
        return False, f"{name} is a {stu.get('type')}; expected a joint number or a tuple of them"
    a, b = _canon_choice(stu["value"]), _canon_choice(ref["value"])
    if a == b:
        return True, ""
    if isinstance(a, frozenset) and isinstance(b, frozenset):
        if any(isinstance(e, int) and not isinstance(e, bool) and e == 0 for e in a):
            return False, f"{name}: joints are numbered from 1"
        mine = ", ".join(map(str, sorted(a, key=str)))
        joints = all(isinstance(e, int) and not isinstance(e, bool) for e in a)
        tie = " (a tie counts: give a tuple of every joint that qualifies)" if joints else ""
        return False, f"{name}: ({mine}) is not the right choice" + tie
    return False, f"{name}: not the right choice(s)"


COMPARE = {
    "expr": compare_expr,
    "subspace": compare_subspace,
    "set": compare_set,
    "choice": compare_choice,
    "property": compare_property,
}


def compare(kind: str, stu: dict, ref: dict, name: str) -> tuple[bool, str]:
    """``(ok, message)`` for the student's description ``stu`` of answer ``name`` against the reference's
    (other kinds compare as ``expr``); never raises.

    >>> compare("choice", {"tag": "ellipsis"}, {"value": 1}, "j")
    (False, 'j is still `...`: not answered yet')
    """
    base, _, arg = str(kind).partition(":")
    try:
        if base == "property":
            return compare_property(stu, ref, name, arg or "nonsingular")
        return COMPARE.get(base, compare_expr)(stu, ref, name)
    except Exception as exc:  # noqa: BLE001  malformed data from a kernel must not stop the batch
        return False, f"{name} could not be compared ({type(exc).__name__}: {str(exc)[:200]})"
