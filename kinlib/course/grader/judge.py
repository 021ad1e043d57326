"""Judging one answer on the trusted side: the data a kernel exported, read, evaluated at the secret points,
compared with the reference, and checked exactly — all in the grader's process, within caps and a time limit.

The kernel only *claims* an answer (:mod:`kinlib.course.grader.in_kernel.export`); :func:`judge_answer`
decides whether it is the answer, in named steps:

1. **read**: the exported tree rebuilt by the whitelist parser :func:`kinlib.course.answers.wire.load`
   (size, depth and digit caps; a tree over a cap is a wrong answer that says so);
2. **describe**: the value at the secret points (:mod:`kinlib.course.answers.describe`), the reference's too
   (:func:`kinlib.course.grader.refdata.reference_description`);
3. **compare**: :func:`kinlib.course.answers.compare.compare` (non-finite values are wrong everywhere);
4. **exact**: for a passing expression, whether SymPy proves it equal to the reference (advisory: it never
   turns a numeric failure into a pass).

The grader runs it in a judge process of the submission's own (:mod:`kinlib.course.grader.judging`), which is
killed when an answer takes longer than :data:`JUDGE_SECONDS` (the answer is then wrong, "too large to grade");
nothing here raises into SymPy (an exception from a timer was swallowed by ``except Exception`` in SymPy and in
describe, and the answer ran on).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from ..answers import compare, describe, kinds, wire
from ..answers.expr import exact_equal, to_sympy

__all__ = ["Verdict", "judge_answer", "exact_check", "JUDGE_SECONDS", "EXACT_SECONDS", "n_points"]

JUDGE_SECONDS = 30.0  # the most one answer may take to read, evaluate and compare in the grader
EXACT_SECONDS = 5.0  # of which the advisory exact check may take (SymPy simplify)
N_POINTS = max(k.points for k in kinds.KINDS.values())  # secret points made per submission (each kind uses its own)


@dataclass
class Verdict:
    """The grader's decision on one answer (one entry of ``Row.answers``; read by :mod:`.credit` and the reports).

    >>> Verdict("J", "fail", "J is transposed: yours is 3×6, expected 6×3").passed
    False
    """

    answer: str  # the answer's variable name
    status: str  # pass | fail | error (error: the kernel could not report it; never the answer's own fault)
    message: str = ""  # what is wrong (or a note on a pass); never shows the reference
    exact: str = ""  # the advisory exact check: equal | not proved | timed out | "" (not run)
    seconds: float = 0.0  # time spent judging it in the grader

    @property
    def passed(self) -> bool:
        return self.status == "pass"

    def as_dict(self) -> dict:
        """The entry of ``Row.answers`` (keys: answer, status, message)."""
        return {"answer": self.answer, "status": self.status, "message": self.message}


def n_points(kind: str) -> int:
    """How many secret points an answer of ``kind`` is evaluated at (the table of kinds says).

    >>> n_points("expr"), n_points("set"), n_points("choice")
    (5, 2, 0)
    """
    return kinds.lookup(kind)[0].points


def _read(exported, name):
    """(value, None) from the kernel's export, or (None, description of why it is not an answer)."""
    if not isinstance(exported, dict):
        return None, {"tag": "probe-error", "error": "malformed result"}
    if exported.get("missing"):
        return None, {"tag": "missing"}
    if "too_large" in exported:
        return None, {"tag": "too-large", "error": str(exported["too_large"])[:200]}
    if "tree" not in exported:
        return None, {"tag": "probe-error", "error": str(exported.get("error", "no answer"))[:300]}
    try:
        return wire.load(exported["tree"]), None
    except WireError as exc:
        big = str(exc).startswith(
            ("more than", "nested more", "numbers with more", "a power too large", "a number too large")
        )
        return None, {"tag": "too-large" if big else "unreadable", "error": str(exc)[:200]}
    except RecursionError:
        return None, {"tag": "too-large", "error": "nested too deeply"}


WireError = wire.WireError


def judge_answer(name, kind, exported, ref, points, seed, seconds=JUDGE_SECONDS, exact=True, keep_value=False):
    """The verdict on answer ``name`` (of ``kind``) that a kernel exported (``{"tree"|"missing"|...}``),
    against the reference ``ref`` (:class:`kinlib.course.grader.refdata.Reference`), at ``points``.

    No time limit here: ``seconds`` is the one the caller enforces by ending the process
    (:class:`kinlib.course.grader.judging.JudgeProcess`). ``exact=False`` leaves the advisory exact check to a
    separate request (``verdict.exact`` is then "?" when it applies); ``keep_value``: returns (verdict, value).

    >>> from kinlib.course.grader.refdata import Reference
    >>> ref = Reference("n", "t", "p", "0" * 64, [], {"x2": {"kind": "expr", "tree": ["Pow", ["Symbol", "x", {}], ["Integer", "2"]],
    ...                                                      "symbols": {"x": {}}}})
    >>> pts = [{"x": 0.3}, {"x": -1.1}]
    >>> x2 = ["Pow", ["Symbol", "x", {}], ["Integer", "2"]]
    >>> judge_answer("x2", "expr", {"tree": x2}, ref, pts, 0).status
    'pass'
    >>> judge_answer("x2", "expr", {"tree": ["Infinity"]}, ref, pts, 0).message
    'x2 could not be evaluated at some joint values (division by zero, or undefined symbols?)'
    """
    from .refdata import reference_description, reference_value

    t0 = time.monotonic()
    pts = points[: n_points(kind)]
    value, whose = None, "your answer"
    try:
        value, stu = _read(exported, name)
        if stu is None:
            stu = describe.describe(kind, value, pts, seed)
        whose = "the reference"
        rd = reference_description(ref, name, kind, pts, seed)
        whose = "the comparison"
        ok, msg = compare.compare(kind, stu, rd, name)
        verdict = Verdict(name, "pass" if ok else "fail", msg if (ok and msg) or not ok else "")
        if ok and kind == "expr" and stu.get("tag") in ("matrix", "scalar") and "tree" in ref.answers[name]:
            verdict.exact = exact_check(value, reference_value(ref, name), EXACT_SECONDS) if exact else "?"
    except (MemoryError, RecursionError) as exc:
        verdict = Verdict(name, "fail", f"{name} is too large to grade ({type(exc).__name__})")
    except Exception as exc:  # noqa: BLE001  a grader bug on one answer must not stop the submission
        why = f"{name}: {whose} could not be evaluated by the grader ({type(exc).__name__}: {exc})"
        verdict = Verdict(name, "error", why[:300])
    verdict.seconds = round(time.monotonic() - t0, 3)
    return (verdict, value) if keep_value else verdict


def exact_check(value, ref_value, seconds) -> str:
    """'equal' | 'not proved' | 'not sympy' (advisory; ``seconds``: SymPy's simplify is not tried after it). Not
    tried on powers of sums with large exponents (expanding (a + b + c)**90 would take the grader's memory
    before its time limit). Its hard time limit is the judge process's (:mod:`.judging`): killed past it.

    >>> import sympy as sp
    >>> exact_check(sp.sin(sp.Symbol("x"))**2 + sp.cos(sp.Symbol("x"))**2, sp.Integer(1), 5)
    'equal'
    """
    import sympy as sp

    obj = to_sympy(value)[1]
    if obj is None:
        return "not sympy"
    if any(p.base.is_Add and p.exp.is_Number and abs(p.exp) > 12 for p in obj.atoms(sp.Pow)):
        return "not proved"
    try:
        return exact_equal(value, ref_value, budget=seconds / 2)
    except Exception:  # noqa: BLE001
        return "not proved"
