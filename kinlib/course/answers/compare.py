"""Grader side: compare the description of a student's answer with the reference's, by the answer's kind.

:func:`compare` looks the kind up in the table of kinds (:data:`kinlib.course.answers.kinds.KINDS`) and applies
that kind's comparer (:func:`~.expr.compare_expr`, :func:`~.subspace.compare_subspace`, :func:`~.sets.compare_set`,
:func:`~.choice.compare_choice`, :func:`~.properties.compare_property`; :data:`COMPARE` names them). The
descriptions are plain data (numbers, strings, lists) made in the grader's process by
:func:`kinlib.course.answers.describe.describe` from the answer a kernel exported as data; non-finite values are
never equal to anything (:func:`~.base.close`). Each comparison returns ``(ok, message)``; messages name the
mistake when it is recognizable (wrong shape, transposed, wrong sign, columns swapped, [v; ω] instead of [ω; v],
degrees instead of radians, a missing or extra variable) without printing the reference answer or anything that
gives it away: only what the student can read off their own answer.
"""

from __future__ import annotations

from . import kinds
from .base import ATOL, NOT_ANSWERED, RTOL, close
from .choice import compare_choice
from .expr import compare_expr
from .properties import compare_property
from .sets import compare_set
from .subspace import compare_subspace

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

_close = close  # the one numeric equality (kinlib.course.answers.base.close), by its former name here

COMPARE = {name: k.compare for name, k in kinds.KINDS.items()}


def compare(kind: str, stu: dict, ref: dict, name: str) -> tuple[bool, str]:
    """``(ok, message)`` for the student's description ``stu`` of answer ``name`` against the reference's
    (other kinds compare as ``expr``); never raises.

    >>> compare("choice", {"tag": "ellipsis"}, {"value": 1}, "j")
    (False, 'j is still `...`: not answered yet')
    >>> compare("property:nonsingular", {"tag": "scalar", "tree": ["int", "1"]}, {}, "d")[0]
    False
    """
    k, arg = kinds.lookup(kind)
    try:
        return k.compare(stu, ref, name, arg) if arg else k.compare(stu, ref, name)
    except Exception as exc:  # noqa: BLE001  malformed data from a kernel must not stop the batch
        return False, f"{name} could not be compared ({type(exc).__name__}: {str(exc)[:200]})"
