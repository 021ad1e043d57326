"""Answers leave the kernel as data and are judged outside it (issue 22, item 1), and "the same answer" has one
definition for the workbook self-check and the grader (item 7).

* Only :mod:`kinlib.course.grader.in_kernel` (``guard``, ``export``) is shipped into a kernel; it receives no
  evaluation point, seed or reference (every message sent to the kernel is scanned for them).
* The export format is read back by a whitelist parser with caps (:mod:`kinlib.course.answers.wire`); the
  trusted side evaluates, compares and checks exactly, each answer under a time limit.
* A workbook that replaces or patches the export can only claim an answer: claiming inf everywhere gets 0.
* The self-check and the grader give the same verdict on every row of one table (right, other valid forms,
  wrong, hostile: True, inf, nan, huge).
"""

from __future__ import annotations

import ast
import json
import math
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from kinlib.course.answers import compare, wire
from kinlib.course.grader import judge
from kinlib.course.grader.in_kernel import export as ex
from kinlib.course.grader.isolation import kernel
from kinlib.course.grader.refdata import Reference, reference_answers
from kinlib.course.workbook.selfcheck import fingerprint, verdict

x, th1, th2 = sp.symbols("x theta1 theta2")
L = sp.Symbol("L", positive=True)
M = sp.Matrix([[-L * sp.sin(th1), sp.cos(th1 + th2)], [L * sp.cos(th1), 1]])
M32 = sp.Matrix([[1, 4], [2, 5], [3, 6]])
POINTS = [{"x": 0.7, "theta1": 0.3, "theta2": -1.1, "L": 1.3}, {"x": -0.4, "theta1": 1.2, "theta2": 2.0, "L": 0.8}]
POINTS += [{"x": 0.2, "theta1": -2.0, "theta2": 0.4, "L": 1.7}] * 3


# ----------------------------------------------------------------------------------------- what is shipped


def test_only_the_in_kernel_modules_are_shipped_and_they_import_nothing_of_ours():
    folder = Path(kernel.__file__).parents[1] / "in_kernel"
    assert kernel.IN_KERNEL_MODULES == ("guard", "export")
    assert sorted(p.name for p in folder.glob("*.py")) == ["__init__.py", "export.py", "guard.py"]
    code = kernel.setup_code("_kinlib_grade_0", snapshot=True)
    for name in kernel.IN_KERNEL_MODULES:
        assert repr((folder / f"{name}.py").read_text()) in code
    # no other kinlib source travels: every other module's text is absent
    for p in Path(kernel.__file__).parents[3].rglob("*.py"):
        if p.parent != folder and len(p.read_text()) > 200:
            assert repr(p.read_text())[1:200] not in code, p
    for name in kernel.IN_KERNEL_MODULES:
        tree = ast.parse((folder / f"{name}.py").read_text())
        tops = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        tops |= {n.module.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.level == 0}
        assert tops <= {"json", "copy", "numbers", "sys", "types", "numpy", "sympy", "mpmath"}, (name, tops)


# ----------------------------------------------------------------------------------------- the format and its parser

n = sp.Symbol("n", integer=True)
ROUND_TRIP = [
    M,
    M32,
    sp.Rational(1, 2) + sp.sqrt(2) * sp.I,
    sp.Float("1.25", 30),
    [{th2: sp.ImageSet(sp.Lambda(n, 2 * n * sp.pi + sp.pi / 4), sp.Integers)}, {th1: sp.Interval(0, 1)}],
    sp.FiniteSet(sp.Tuple(0, sp.pi), sp.Tuple(sp.pi, 0)),
    sp.Union(sp.Interval.Lopen(0, 1), sp.FiniteSet(3)),
    (1, 3),
    {"a": [1, 2.5, "two"], "b": None},
    True,
    sp.Eq(th1, 0),
    sp.Function("f")(th1),
    sp.S.EmptySet,
]


@pytest.mark.parametrize("value", ROUND_TRIP, ids=lambda v: type(v).__name__)
def test_an_exported_answer_reads_back_as_the_same_value(value):
    tree = json.loads(json.dumps(ex.export(value)))
    assert wire.load(tree) == value


def test_arrays_and_other_objects():
    a = np.array([[1.0, 2.0], [3.0, 4.0]])
    assert (wire.load(ex.export(a)) == a).all()
    other = wire.load(ex.export(object()))
    assert isinstance(other, wire.Other) and other.type_name == "object"


HOSTILE_TREES = [
    ["__import__", ["str", "os"]],
    ["Symbol", "x", {"__class__": True}],
    ["Pow", ["Integer", "10"], ["Integer", "100000000"]],
    ["Integer", "9" * 5000],
    ["Float", "__import__('os')", 53],
    ["Matrix", 1000, 1000],
    ["ndarray", [10**9], ["int", "1"]],
    ["list", *[["int", "1"]] * (wire.MAX_NODES + 1)],
    ["str", "x" * (wire.MAX_STR + 1)],
    ["dict", [["list"], ["int", "1"]]],
    "Symbol('x')",
    ["Interval", ["str", "1"], ["Integer", "2"]],
]


def _deep(k):
    t = ["int", "1"]
    for _ in range(k):
        t = ["list", t]
    return t


@pytest.mark.parametrize("tree", HOSTILE_TREES + [_deep(wire.MAX_DEPTH + 5)], ids=lambda t: str(t)[:30])
def test_hostile_trees_are_refused_not_built(tree):
    with pytest.raises(wire.WireError):
        wire.load(tree)


# ----------------------------------------------------------------------------------------- one verdict for both


def grader(kind, ref, value):
    """The grader's path, without a kernel: both answers exported as a kernel exports them, the reference read as
    :func:`refdata.build_reference` reads it, the student's judged by :func:`judge.judge_answer`."""
    entry = reference_answers({"a": ex.exported(ref)}, {"a": kind})
    assert "error" not in entry["a"], entry
    refobj = Reference("t", "t", "p", "0" * 64, [], entry)
    sent = json.loads(json.dumps(ex.exported(value)))
    return judge.judge_answer("a", entry["a"]["kind"], sent, refobj, POINTS, 1)


def selfcheck(kind, ref, value):
    return verdict(value, fingerprint(ref, "default" if kind == "expr" else kind, salt="9.9:a"), salt="9.9:a")


TABLE = [  # (kind, reference, answer, passes)
    # right, and right in other forms
    ("expr", M, M, True),
    ("expr", M, [M[:, 0], M[:, 1]], True),  # a list of columns
    ("expr", sp.sin(x) ** 2, 1 - sp.cos(x) ** 2, True),
    ("expr", sp.sqrt(2) / 2, math.sqrt(2) / 2, True),
    ("expr", sp.Rational(1, 2), np.float64(0.5), True),
    ("subspace", M32, [[1, 2, 3], [4, 5, 6]], True),
    ("subspace", M32, sp.Matrix([[5, 1], [7, 2], [9, 3]]), True),
    ("set", {th2: sp.FiniteSet(0, sp.pi)}, {th2: [0, sp.pi, 2 * sp.pi]}, True),
    ("set", sp.FiniteSet(sp.pi / 2), sp.pi / 2, True),
    ("choice", 1, 1, True),
    ("choice", (1, 3), [3, 1], True),
    ("choice", 2, (2.0,), True),
    ("choice", "Joint two", "joint   two", True),
    # wrong
    ("expr", M, M.T, False),
    ("expr", M, -M, False),
    ("expr", sp.Rational(1, 2), sp.Rational(1, 3), False),
    ("subspace", M32, [[1, 0, 0]], False),
    ("set", {th2: sp.FiniteSet(0, sp.pi)}, {th2: sp.FiniteSet(0)}, False),
    ("choice", (1, 3), [1], False),
    ("choice", 2, "2", False),
    # hostile
    ("choice", 1, True, False),  # True is not joint 1 (the grader passed it, the self-check did not)
    ("choice", (1, 3), (True, 3), False),
    ("choice", 1, float("inf"), False),
    ("choice", 1, float("nan"), False),
    ("expr", M, True, False),
    ("expr", sp.Rational(1, 2), float("inf"), False),
    ("expr", sp.Rational(1, 2), sp.oo, False),
    ("expr", sp.Rational(1, 2), float("nan"), False),
    ("expr", sp.Rational(1, 2), sp.nan, False),
    ("expr", sp.Rational(1, 2), sp.zoo, False),
    ("expr", M, sp.Matrix(2, 2, [sp.oo] * 4), False),
    ("expr", M, 10**300 * M, False),
    ("expr", sp.Rational(1, 2), sp.Integer(10) ** 400, False),
    ("set", sp.FiniteSet(0, sp.pi), sp.FiniteSet(0, sp.pi, sp.oo), False),
    ("subspace", M32, sp.Matrix([[sp.oo, 1], [2, 5], [3, 6]]), False),
]


@pytest.mark.parametrize("kind, ref, value, passes", TABLE, ids=lambda v: str(v)[:24])
def test_the_selfcheck_and_the_grader_give_the_same_verdict(kind, ref, value, passes):
    status, message = selfcheck(kind, ref, value)
    v = grader(kind, ref, value)
    assert (status == "correct") == passes, (status, message)
    assert v.passed == passes, v


# ----------------------------------------------------------------------------------------- non-finite and huge


def test_non_finite_values_never_compare_equal():
    ref = {"tag": "scalar", "shape": [], "symbols": [], "values": [[[0.5, 0.0]]]}
    for bad in (math.inf, -math.inf, math.nan):
        stu = dict(ref, values=[[[bad, 0.0]]])
        assert not compare.compare("expr", stu, ref, "d")[0]
        assert not compare._close(np.array([bad]), np.array([0.5]))
    assert not compare._close(np.array([math.inf]), np.array([math.inf]))  # not even inf = inf


def test_a_huge_set_is_refused_or_compared_in_bounded_time():
    huge = [float(k) for k in range(250_000)]
    sent = ex.exported(huge)  # the kernel refuses to write it: too many nodes
    assert "too_large" in sent
    entry = reference_answers({"a": ex.exported(sp.FiniteSet(0, sp.pi))}, {"a": "set"})
    v = judge.judge_answer("a", "set", sent, Reference("t", "t", "p", "0" * 64, [], entry), POINTS, 1)
    assert v.status == "fail" and "too large" in v.message
    # a patched kernel that writes it anyway: the parser refuses it
    forged = {"tree": ["list", *[["float", repr(x)] for x in huge]]}
    v = judge.judge_answer("a", "set", forged, Reference("t", "t", "p", "0" * 64, [], entry), POINTS, 1)
    assert v.status == "fail" and "too large" in v.message
    # and the comparison itself is O(n log n): 250,000 members against 250,000 finish (no O(n²) 17 minutes)
    desc = {"tag": "set", "conditions": [[[{"var": None, "points": huge, "intervals": []}]]]}
    assert compare.compare_set(desc, {"conditions": desc["conditions"]}, "S")[0]


def test_an_answer_that_takes_too_long_is_wrong_not_a_stopped_batch():
    """Judged in a judge process that is killed past the limit (tests/course/test_grade_judging.py has the
    process's own tests): a judge that never answers makes the answer wrong, and the next one is judged."""
    import sys

    from kinlib.course.grader import judging

    hang = (
        "import json, os, struct, sys\n"
        "def send(o):\n    b = json.dumps(o).encode(); os.write(1, struct.pack('>I', len(b)) + b)\n"
        "sys.stdin.buffer.read(4); send({'ready': True})\n"
        "while True:\n    pass\n"
    )
    entry = reference_answers({"a": ex.exported(x)}, {"a": "expr"})
    jp = judging.JudgeProcess(
        Reference("t", "t", "p", "0" * 64, [], entry), POINTS, 1, argv=[sys.executable, "-c", hang]
    )
    try:
        v = jp.judge("a", "expr", ex.exported(x), seconds=1.0)
    finally:
        jp.close()
    assert v.status == "fail" and "too large to grade" in v.message and jp.kills == 1


# ----------------------------------------------------------------------------------------- attacks in a kernel

PATCH_EXPORT = """
import json, sys
def _claim(ns, name, path):  # every answer: inf (|inf - r| <= inf passed before)
    with open(path, "w") as f:
        json.dump({"tree": ["float", "inf"]}, f)
for _k, _m in list(sys.modules.items()):
    if _k.startswith("_kinlib_grade_") and hasattr(_m, "export_answer"):
        _m.export_answer = _claim
"""
REPLACE_MODULE = """
import json, sys, types
def _claim(ns, name, path):  # a 6x3 matrix of inf for every answer, from a module put in the export's place
    with open(path, "w") as f:
        json.dump({"tree": ["Matrix", 6, 3, *[["Infinity"]] * 18]}, f)
def _restored(path):
    with open(path, "w") as f:
        json.dump({"restored": []}, f)
for _k in [k for k in sys.modules if k.startswith("_kinlib_grade_") and not k.endswith("_guard")]:
    sys.modules[_k] = types.SimpleNamespace(export_answer=_claim, restore_saved=_restored, stash=lambda *a: None)
"""
SEARCH = """
import gc, json, os, sys
found = []
def _look(text):
    if any(w in text for w in ("srepr", "Symbol(", "Matrix([", "points", "seed")):
        found.append(text[:200])
for _k, _m in list(sys.modules.items()):
    if _k.startswith("_kinlib_grade_"):
        for _n, _v in vars(_m).items():
            if isinstance(_v, (str, dict, list)):
                _look(repr(_v))
for _v in list(os.environ.values()):
    _look(_v)
for _root in (os.getcwd(), "/tmp", os.path.expanduser("~")):
    for _d, _, _fs in os.walk(_root):
        for _f in _fs:
            try:
                with open(os.path.join(_d, _f), errors="ignore") as _h:
                    _look(_h.read(100_000))
            except OSError:
                pass
for _o in gc.get_objects():
    if isinstance(_o, dict) and "points" in _o:
        found.append(repr(_o)[:200])
Js = detJ = moves = singular = joint_x = joint_y = None
if found:  # whatever it found, as its answers
    Js = detJ = moves = singular = joint_x = joint_y = found[0]
"""


@pytest.fixture(scope="module")
def kernel_attacks(tmp_path_factory, grader_reference_cache):
    from jupyter_client.session import Session
    from test_grade import FIX, WB, completed

    from kinlib.course.grader import grade
    from kinlib.course.grader.isolation import sandbox
    from kinlib.course.grader.secret import evaluation_seed, load_secret

    ok, why = sandbox.check()
    assert ok, f"the grader's sandbox does not work here: {why}"
    key = b"k" * 32  # the grading's secret (the evaluation points); the answer key is the run's (read, not rebuilt)
    refs = grade.load_references(FIX / "notebooks", cache=grader_reference_cache, secret=load_secret())
    d = tmp_path_factory.mktemp("kernel-attacks")
    wb = json.loads(WB.read_text())
    cell = {"cell_type": "code", "metadata": {}, "outputs": [], "execution_count": None}
    subs = {
        "honest": completed(),
        "patch_export": dict(wb, cells=wb["cells"] + [dict(cell, source=PATCH_EXPORT)]),
        "replace_module": dict(wb, cells=wb["cells"] + [dict(cell, source=REPLACE_MODULE)]),
        "right_then_patch": completed(end=[PATCH_EXPORT]),
        "search": dict(wb, cells=wb["cells"] + [dict(cell, source=SEARCH)]),
    }
    sent: dict = {}
    real_send = Session.send
    out = {}
    for name, nb in subs.items():
        path = d / f"{name}.ipynb"
        path.write_text(json.dumps(nb))
        sent[name] = []

        def spy(self, stream, msg_or_type, content=None, *a, _log=sent[name], **k):
            _log.append(json.dumps(msg_or_type if isinstance(msg_or_type, dict) else content, default=str))
            return real_send(self, stream, msg_or_type, content, *a, **k)

        Session.send = spy
        try:
            out[name] = grade.grade_submission(path, refs, 20, 180, display_name=name, secret=key)
        finally:
            Session.send = real_send
    ref = refs["90_grade_fixture"]
    symbols = {}
    for a in ref.answers.values():
        symbols.update(a.get("symbols", {}))
    secrets = {}
    for name in subs:
        seed = evaluation_seed(key, (d / f"{name}.ipynb").read_bytes())
        pts = grade.make_points(symbols, seed, grade.N_POINTS)
        secrets[name] = [str(seed)] + [repr(v)[:12] for p in pts for v in p.values()]
    return {"res": out, "sent": sent, "secrets": secrets, "ref": ref}


def _earned(res):
    return sum(r["points"] for r in res["rows"]), sum(r.get("max_points", 0) for r in res["rows"])


@pytest.mark.slow
def test_an_honest_workbook_still_gets_full_marks(kernel_attacks):
    got, top = _earned(kernel_attacks["res"]["honest"])
    assert top > 0 and got == top, kernel_attacks["res"]["honest"]["rows"]


@pytest.mark.slow
@pytest.mark.parametrize("name", ["patch_export", "replace_module", "right_then_patch", "search"])
def test_a_replaced_or_patched_export_gains_nothing(kernel_attacks, name):
    res = kernel_attacks["res"][name]
    assert not res.get("infrastructure"), res
    assert _earned(res)[0] == 0, [(r["part"], r["status"], r["message"]) for r in res["rows"]]


@pytest.mark.slow
def test_no_point_seed_or_reference_is_ever_sent_to_the_kernel(kernel_attacks):
    ref = kernel_attacks["ref"]
    keys = [json.dumps(a["tree"]) for a in ref.answers.values() if "tree" in a]
    for name, messages in kernel_attacks["sent"].items():
        text = "\n".join(messages)
        assert "export_answer" in text  # the spy saw the grader's requests
        for s in kernel_attacks["secrets"][name]:
            assert s not in text, (name, s)
        for k in keys:
            assert k not in text, (name, k[:80])
