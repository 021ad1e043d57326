"""Instructor side of the checker: compare the JSON a student kernel sent with the reference's.

Everything here works on plain JSON data (numbers, strings, lists) produced by
:mod:`kinlib.course.probe`; nothing from a submission is evaluated. Each comparison returns
``(ok, message)``; messages name the mistake when it is recognizable (wrong shape, transposed,
wrong sign, columns swapped, [v; ω] instead of [ω; v], degrees instead of radians, a missing or
extra variable) without printing the reference answer.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

__all__ = [
    "compare",
    "compare_expr",
    "compare_subspace",
    "compare_set",
    "compare_choice",
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
            return False, f"{name} has keys {sorted(stu['items'])}; expected {sorted(ref['items'])}"
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
    return False, f"{name} " + "; ".join(notes + [_diagnose(S, R, rshape, stu)])


def _diagnose(S, R, shape, stu) -> str:
    P = S.shape[0]
    r, c = (shape + [1, 1])[:2] if len(shape) == 2 else (1, 1)
    S3, R3 = S.reshape(P, r, c), R.reshape(P, r, c)
    if _close(S, -R):
        return "has the wrong sign (every entry is negated)"
    if r == c and r > 1 and _close(S3, np.swapaxes(R3, 1, 2)):
        return "is transposed"
    if r == 6 and _close(S3, np.concatenate([R3[:, 3:], R3[:, :3]], axis=1)):
        return (
            "has the rows in [v; ω] order: the textbook stacks angular first, [ω; v] "
            "(rows 1–3 angular, rows 4–6 linear)"
        )
    if c > 1:
        perm = _match(S3, R3, axis=2)
        if perm is not None and perm != list(range(c)):
            moved = [f"your column {i + 1} is column {j + 1}" for i, j in enumerate(perm) if i != j]
            return "has its columns swapped: " + ", ".join(moved) + " (column i belongs to joint i)"
    if r > 1:
        perm = _match(S3, R3, axis=1)
        if perm is not None and perm != list(range(r)):
            moved = [f"your row {i + 1} is row {j + 1}" for i, j in enumerate(perm) if i != j]
            return "has its rows swapped: " + ", ".join(moved)
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
            return (
                f"is {ratio:.6g} times the answer: rounded decimals? Use exact values "
                "(sp.sqrt(2), sp.pi, sp.Rational(1, 3))"
            )
        return f"is off by a constant factor ({ratio:.6g} times the answer)"
    if stu.get("degrees"):
        return "looks like it uses degrees inside sin/cos (e.g. sin(θ + 45)): angles are radians, write sp.pi/4"
    if S.shape[1] > 1:
        return f"differs in entries {_entries(bad, shape)}"
    return "has the wrong value"


def _match(S3, R3, axis):
    """Permutation p with S[..., i] == R[..., p[i]] along ``axis`` (columns 2, rows 1), or None."""
    n = S3.shape[axis]
    take = (lambda A, i: A[:, :, i]) if axis == 2 else (lambda A, i: A[:, i, :])
    perm = []
    used = set()
    for i in range(n):
        cands = [j for j in range(n) if j not in used and _close(take(S3, i), take(R3, j))]
        if not cands:
            return None
        j = i if i in cands else cands[0]
        used.add(j)
        perm.append(j)
    return perm


def _const_ratio(S, R):
    mask = np.abs(R) > 1e-6
    if not mask.any() or np.any(np.abs(S[~mask]) > 1e-6):
        return None
    q = S[mask] / R[mask]
    if np.allclose(q, q.flat[0], rtol=1e-6, atol=0) and abs(q.flat[0].imag) < 1e-9:
        return float(q.flat[0].real)
    return None


# ----------------------------------------------------------------------------- subspaces


def _rank(A, tol=1e-7):
    if A.size == 0:
        return 0
    s = np.linalg.svd(A, compute_uv=False)
    return int(np.sum(s > tol * max(1.0, s.max() if s.size else 0)))


def compare_subspace(stu: dict, ref: dict, name: str) -> tuple[bool, str]:
    """A subspace by its span: rank [A B] = rank A = rank B at every point.

    >>> ref = {"shape": [2, 1], "symbols": [], "values": [[[1.0, 0.0], [0.0, 0.0]]]}
    >>> compare_subspace(dict(ref, tag="matrix", values=[[[3.0, 0.0], [0.0, 0.0]]]), ref, "s")
    (True, '')
    """
    na = _not_answered(stu)
    if na:
        return False, f"{name} {na}"
    if stu.get("tag") not in ("matrix", "scalar"):
        return False, f"{name} is a {stu.get('type')}; expected a Matrix whose columns span the subspace"
    rshape, sshape = list(ref["shape"]) or [1, 1], list(stu["shape"]) or [1, 1]
    S, R = _arr(stu["values"]), _arr(ref["values"])
    if np.isnan(S).any():
        return False, f"{name} could not be evaluated at some values of the symbols"
    if sshape[0] != rshape[0]:
        if sshape[1] == rshape[0]:
            return False, (
                f"{name} gives the vectors as rows ({_fmt_shape(sshape)}): put one vector per column ({rshape[0]} rows)"
            )
        return False, f"{name} has vectors of length {sshape[0]}; expected {rshape[0]}"
    notes = _symbol_notes(stu, ref)
    for p in range(S.shape[0]):
        A = S[p].reshape(sshape)
        B = R[p].reshape(rshape)
        ra, rb, rab = _rank(A), _rank(B), _rank(np.hstack([A, B]))
        if ra != rb:
            what = "too small" if ra < rb else "too large"
            dep = f" ({sshape[1]} columns, {ra} independent)" if sshape[1] != ra else ""
            return False, (
                f"{name} spans a {ra}-dimensional space{dep}; the answer is {rb}-dimensional "
                f"({what})" + (f"; {notes[0]}" if notes else "")
            )
        if rab != rb:
            return False, (
                f"{name} spans a {ra}-dimensional space of the right dimension but not the "
                "right one (some of your directions are not in the answer's span)"
                + (f"; {'; '.join(notes)}" if notes else "")
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


def _conds(desc_point, ref_vars):
    """Conditions as {var: component}; unsatisfiable ones (an empty component) dropped, "any value" ones
    ignored, and a bare set (var None) taken as the set of the only reference variable."""
    out = []
    for cond in desc_point:
        d = {}
        dead = False
        for c in cond:
            v = c.get("var")
            if v is None and len(ref_vars) == 1:
                v = next(iter(ref_vars))
            if _empty(c):
                dead = True
            if _free(c):
                continue
            d[v] = c
        if not dead:
            out.append(d)
    return out


def _cond_match(s, r, periodic):
    if set(s) != set(r):
        return False, None
    for v in r:
        ok, msg = _compare_component(s[v], r[v], periodic and str(v).startswith("theta"))
        if not ok:
            return False, f"({v}): {msg}"
    return True, ""


def compare_set(stu: dict, ref: dict, name: str, periodic: bool = True) -> tuple[bool, str]:
    """Sets of configurations as sets: the same conditions, each with the same members (angles modulo 2π).

    >>> ref = {"conditions": [[[{"var": "theta1", "points": [0.0], "intervals": []}]]]}
    >>> stu = {"tag": "set", "conditions": [[[{"var": None, "points": [6.283185307179586], "intervals": []}]]]}
    >>> compare_set(stu, ref, "S")
    (True, '')
    """
    na = _not_answered(stu)
    if na:
        return False, f"{name} {na}"
    if stu.get("tag") != "set":
        return False, (
            f"{name} is a {stu.get('type')}; expected a SymPy Set, a dict {{symbol: Set}} or a list of those"
        )
    for sp_, rp in zip(stu["conditions"], ref["conditions"]):
        ref_vars = {c.get("var") for cond in rp for c in cond if c.get("var") is not None}
        rc, sc = _conds(rp, ref_vars), _conds(sp_, ref_vars)
        errs = [f"{v or 'your set'}: {c['error']}" for d in sc for v, c in d.items() if c.get("error")]
        if errs:
            return False, f"{name} could not be compared: " + "; ".join(errs)
        if not rc and sc:
            return False, f"{name} is not empty, but there are no such configurations"
        if rc and not sc:
            return False, f"{name} is empty, but such configurations exist"
        if len(rc) == 1 and len(sc) == 1:
            r, s = rc[0], sc[0]
            if set(s) != set(r):
                missing, extra = sorted(set(r) - set(s), key=str), sorted(set(s) - set(r), key=str)
                parts = []
                if missing:
                    parts.append(f"says nothing about {', '.join(map(str, missing))}")
                if extra:
                    parts.append(f"constrains {', '.join(map(str, extra))}, which the answer leaves free")
                return False, f"{name} " + " and ".join(parts)
            ok, msg = _cond_match(s, r, periodic)
            if not ok:
                return False, f"{name} {msg}"
            continue
        unmatched = list(sc)
        for r in rc:
            hit = next((s for s in unmatched if _cond_match(s, r, periodic)[0]), None)
            if hit is None:
                return False, (
                    f"{name}: {len(sc)} condition(s) given, {len(rc)} expected, and not all of them "
                    f"match (conditions on {', '.join(sorted(map(str, r)))})"
                )
            unmatched.remove(hit)
        if unmatched:
            return False, f"{name} has {len(unmatched)} condition(s) more than the answer"
    return True, ""


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
        return False, f"{len(a)} configuration(s) given, {len(b)} expected, or different ones"
    si, ri = _canon_intervals(s.get("intervals", [])), _canon_intervals(r.get("intervals", []))
    if len(si) != len(ri) or any(not _same(x, y) for x, y in zip(si, ri)):
        if ri and not si:
            return False, "the answer is a continuous range of values; yours lists isolated values"
        if si and not ri:
            return False, "the answer is isolated values; yours is a continuous range"
        return False, "a different range of values"
    sp_, rp = _canon_points(s.get("points", []), periodic), _canon_points(r.get("points", []), periodic)
    if _same(sp_, rp):
        return True, ""
    if periodic and _same(_canon_points(s.get("points", []), True, math.pi / 180), rp):
        return False, "these look like degrees: angles are radians (45° = sp.pi/4)"
    missing = [x for x in rp if not any(abs(x - y) < 1e-6 for y in sp_)]
    wrong = [x for x in sp_ if not any(abs(x - y) < 1e-6 for y in rp)]
    where = " (compared modulo 2π)" if periodic else ""
    if wrong:
        return False, (
            f"{', '.join(_pi_multiple(x) for x in wrong[:4])} "
            f"{'is' if len(wrong) == 1 else 'are'} not in the set{where}"
        )
    return False, f"{len(missing)} value(s) of the set are missing{where}"


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
    'j: partly right, but more than one choice is correct (a tie counts: give a tuple)'
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
        if a < b:
            return False, f"{name}: partly right, but more than one choice is correct (a tie counts: give a tuple)"
        if a > b:
            return False, f"{name}: you chose {sorted(a, key=str)}, more than the correct choice(s)"
        if any(isinstance(e, int) and e == 0 for e in a):
            return False, f"{name}: joints are numbered from 1"
        return False, f"{name}: {sorted(a, key=str)} is not the right choice"
    return False, f"{name}: not the right choice(s)"


COMPARE = {"expr": compare_expr, "subspace": compare_subspace, "set": compare_set, "choice": compare_choice}


def compare(kind: str, stu: dict, ref: dict, name: str) -> tuple[bool, str]:
    """``(ok, message)`` for the student's description ``stu`` of answer ``name`` against the reference's
    (other kinds compare as ``expr``); never raises.

    >>> compare("choice", {"tag": "ellipsis"}, {"value": 1}, "j")
    (False, 'j is still `...`: not answered yet')
    """
    try:
        return COMPARE.get(kind, compare_expr)(stu, ref, name)
    except Exception as exc:  # noqa: BLE001  malformed data from a kernel must not stop the batch
        return False, f"{name} could not be compared ({type(exc).__name__}: {str(exc)[:200]})"
