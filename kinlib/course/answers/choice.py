"""The ``choice`` kind: joint numbers (1-based; ties as tuples), strings or yes/no, compared as sets.

* **normalise** (:func:`choice_value`): an int, string or bool, or a list/tuple/set/array/Matrix/FiniteSet of them
  (ties as tuples), as plain JSON data; strings compare without case or extra spaces, integral floats as ints.
  :func:`choice_key` is the one definition of "the same choice" for the workbook self-check (which hashes it)
  and the grader (which compares it): ``True`` is not joint 1, non-finite numbers equal nothing.
* **wire form**: ``int``, ``float``, ``bool``, ``str``, containers of those, ``Matrix``, ``FiniteSet``, ``Tuple``.
* **describe** (:func:`describe_choice`): the value itself (no points).
* **compare** (:func:`compare_choice`): by :func:`choice_key`; messages name the student's own items only.
* **reference**: the value as given (kept as its description).
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from . import fingerprints as fp
from . import mistakes
from .base import is_bool, not_answered, type_name

__all__ = [
    "choice_value",
    "choice_key",
    "describe_choice",
    "compare_choice",
    "reference_choice",
    "home_canon",
    "home_verdict",
    "stub_words",
]


def choice_value(value):
    """A choice answer as plain JSON data: a bool, a string (lower case, single spaces), an int (integral
    numbers), a float, or a list of those for a collection (nested lists for tuples inside one, a tie);
    an item of another type becomes ``{"other": type name}``.

    >>> choice_value((3, 1.0)), choice_value(sp.FiniteSet(2)), choice_value("  Joint   Two ")
    ([3, 1], [2], 'joint two')
    >>> choice_value(np.array([[1, 2]])), choice_value([(1, 2), 3]), choice_value(sp.Symbol("x"))
    ([1, 2], [[1, 2], 3], {'other': 'sympy.core.symbol.Symbol'})
    """
    if is_bool(value):
        return bool(value)
    if isinstance(value, str):
        return " ".join(value.strip().lower().split())
    if isinstance(value, np.ndarray):
        return [choice_value(e) for e in value.ravel().tolist()]
    if isinstance(value, (sp.FiniteSet, sp.Tuple, list, tuple, set, frozenset, sp.MatrixBase)):
        items = list(value.args) if isinstance(value, (sp.FiniteSet, sp.Tuple)) else list(value)
        return [choice_value(e) for e in items]
    try:
        f = float(value)
    except Exception:  # noqa: BLE001  (whatever the object raises)
        return {"other": type_name(value)}
    if math.isfinite(f) and f == int(f):
        return int(f)
    return f


def choice_key(cv):
    """The one definition of "the same choice" (the self-check hashes it, the grader compares it): a choice value
    (:func:`choice_value`'s output) as sorted tagged strings, ties nested. A bool is never a joint number
    (``True`` is not joint 1); floats to 8 significant digits, non-finite ones never equal a number. Raises
    TypeError for an item that is not a number or a string.

    >>> choice_key([2, 1, 2]) == choice_key([1, 2]), choice_key(True) == choice_key(1), choice_key([[1, 2], 3])
    (True, False, ['T', [['i:1', 'i:2'], ['i:3']]])
    """
    if isinstance(cv, list):
        if all(not isinstance(e, list) for e in cv):
            return sorted({_choice_item(e) for e in cv})
        return ["T", [choice_key(e) for e in cv]]
    return [_choice_item(cv)]


def _choice_item(x) -> str:
    if isinstance(x, bool):
        return f"b:{x}"
    if isinstance(x, str):
        return "s:" + x
    if isinstance(x, int):
        return f"i:{x}"
    if isinstance(x, float):
        if not math.isfinite(x):
            return "n:nan"
        return "n:" + ("0" if abs(x) < 1e-10 else f"{x:.7e}")
    name = x.get("other", "object") if isinstance(x, dict) else type(x).__name__
    raise TypeError(f"choices are numbers or strings, yours holds a {str(name).rsplit('.', 1)[-1]}")


def describe_choice(value, points=(), seed=0):
    """Choice answer: its value as :func:`choice_value` gives it (``points`` and ``seed`` unused:
    the signature of every describe function).

    >>> describe_choice((2, 1))
    {'tag': 'choice', 'type': 'tuple', 'value': [2, 1]}
    """
    if value is Ellipsis:
        return {"tag": "ellipsis", "type": "ellipsis"}
    if value is None:
        return {"tag": "none", "type": "NoneType"}
    return {"tag": "choice", "type": type_name(value), "value": choice_value(value)}


def _choice_items(v) -> list:
    """The items of a choice value (a list of non-lists, or one item), for the messages."""
    return (
        v if isinstance(v, list) and all(not isinstance(e, list) for e in v) else [v] if not isinstance(v, list) else []
    )


def compare_choice(stu: dict, ref: dict, name: str) -> tuple[bool, str]:
    """Choices (joint numbers, 1-based; ties as tuples) compared as sets, by :func:`choice_key`
    (the self-check's definition too: ``True`` is not joint 1).

    >>> compare_choice({"tag": "choice", "value": [2, 1]}, {"value": [1, 2]}, "j")
    (True, '')
    >>> compare_choice({"tag": "choice", "value": [1]}, {"value": [1, 2]}, "j")[1]
    'j: (1) is not the right choice (a tie counts: give a tuple of every joint that qualifies)'
    >>> compare_choice({"tag": "choice", "value": True}, {"value": 1}, "j")[0]
    False
    """
    na = not_answered(stu)
    if na:
        return False, f"{name} {na}"
    if stu.get("tag") != "choice":
        return False, f"{name} is a {stu.get('type')}; expected a joint number or a tuple of them"
    try:
        a = choice_key(stu["value"])
    except TypeError as exc:
        return False, f"{name}: {exc}"
    if a == choice_key(ref["value"]):
        return True, ""
    sv = stu["value"]
    if (
        isinstance(ref["value"], bool)
        and type(sv) is int
        and sv in (0, 1)
        and choice_key(bool(sv)) == choice_key(ref["value"])
    ):
        return True, ""  # 0 / 1 for a yes/no answer: False / True (Python's own reading; the self-check's too)
    items = _choice_items(stu["value"])
    rv = ref["value"]
    if items and (not isinstance(rv, list) or all(not isinstance(e, list) for e in rv)):
        joints = bool(items) and all(isinstance(e, int) and not isinstance(e, bool) for e in items)
        if joints and any(e == 0 for e in items):
            return False, f"{name}: joints are numbered from 1"
        if items:
            mine = ", ".join(map(str, sorted(set(items), key=str)))
            tie = " (a tie counts: give a tuple of every joint that qualifies)" if joints else ""
            return False, f"{name}: ({mine}) is not the right choice" + tie
    return False, f"{name}: not the right choice(s)"


def reference_choice(value):
    """The reference value of a ``choice`` answer: the value itself (the grader keeps its description).

    >>> reference_choice((1, 3))
    (1, 3)
    """
    return value


# ----------------------------------------------------------------------------------------- the self-check
# The workbook's side of the kind (kinlib.course.workbook.selfcheck): choice_key hashed (home_canon), and the
# verdict against the spec (home_verdict), reading 0 / 1 for a yes/no answer and naming mistakes.CHOICE_MISTAKES.

HOME_DIFFERS = "that is not the right choice"


def _home_key(x):
    try:
        return choice_key(x)
    except TypeError as e:
        raise fp.WrongForm(str(e)) from None


def home_canon(value) -> tuple:
    """``("choice", "", choice_key)`` of a ``choice`` answer (:func:`choice_key`: the grader's definition too).

    >>> home_canon((3, 1))
    ('choice', '', ['i:1', 'i:3'])
    """
    return "choice", "", _home_key(choice_value(value))


def home_verdict(value, judge: fp.Judge) -> tuple[str, str]:
    """The self-check's ``(status, message)`` on a ``choice`` answer against the spec in ``judge``.

    >>> j = fp.Judge("choice", "", fp.digest("choice", home_canon((1, 3))[2]))
    >>> home_verdict([3, 1], j), home_verdict((0, 2), j)[1]
    (('correct', 'correct'), 'not right yet: that counts joints from 0: joints are numbered from 1 (the first joint is 1)')
    """
    right = judge.right
    _, _, canon = home_canon(value)
    if right(canon):
        return "correct", "correct"
    cv = choice_value(value)
    if isinstance(cv, int) and not isinstance(cv, bool) and cv in (0, 1) and right(_home_key(bool(cv))):
        return "correct", "correct"  # 0 / 1 for a yes/no answer: False / True (as the grader reads it)
    for m in mistakes.CHOICE_MISTAKES:
        try:
            if right(_home_key(next(m.candidates(cv))[1])):
                return "incorrect", f"not right yet: that {m.message()}"
        except fp.WrongForm:
            continue
    return "incorrect", f"not right yet: {HOME_DIFFERS}"


def stub_words(value) -> str:
    """What a ``choice`` answer is, for the workbook's stub.

    >>> stub_words(3), stub_words(False), stub_words("joint two")
    ('a joint number or a tuple of joint numbers (1-based)', 'True or False', 'a string')
    """
    if is_bool(value):  # a True/False answer is no joint number
        return "True or False"
    return "a joint number or a tuple of joint numbers (1-based)" if not isinstance(value, str) else "a string"
