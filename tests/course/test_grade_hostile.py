"""Nothing a submission sends is evaluated on the trusted side (issue 31, item 1: typed decoding, no evaluation).

An answer crosses from the kernel as a JSON tree (:mod:`kinlib.course.answers.wire`). SymPy's ``sympify`` of a
string is ``parse_expr``, i.e. ``eval``, and SymPy's constructors ``sympify`` their arguments; so a string in the
tree that reaches a SymPy constructor, or a container entry that reaches ``sympify``/``Matrix`` in a kind's
normaliser, runs the student's code in the grader. Here:

* an audit hook (``sys.addaudithook``) fails on ``exec``/``compile`` (but lambdify's own generated function,
  whose source is then checked to hold no string and to call only printed SymPy/NumPy names), ``import`` of
  anything but SymPy/NumPy/mpmath submodules, ``open``, processes, sockets, file changes, while
  :func:`kinlib.course.answers.wire.load` and the whole :func:`kinlib.course.grader.judge.judge_answer` path
  (read, describe, compare, exact check) run for every kind of answer;
* a hypothesis property drives it over the tree grammar (strings that are code, names with quotes, dunders,
  newlines, every node of ``wire.CLASSES`` and ``SINGLETONS``, Matrix, UndefinedFunction, nested containers,
  ndarray, robot) and checks the grader's state (builtins, loaded modules, kinlib's and SymPy's module globals,
  environment, cwd, signal handlers) is unchanged;
* every site that once evaluated a string is driven directly (the strings must not be *read* either: "1 + 1" is
  not 2);
* the end-to-end attack (an untouched workbook whose last cell sets every answer to code in strings) graded by
  ``kinlib grade``'s batch, sandbox on with two workers and with ``--no-sandbox``: no code runs, the attacker
  scores 0, a victim in the same batch is graded right (slow).
"""

from __future__ import annotations

import ast
import builtins
import json
import os
import signal
import sys
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kinlib.course.answers import base, expr, sets, wire
from kinlib.course.grader import judge
from kinlib.course.grader.in_kernel import export as ex
from kinlib.course.grader.refdata import Reference, reference_answers, reference_value

# ----------------------------------------------------------------------------------------- what code would do

CANARY = "_KINLIB_HOSTILE_RAN"  # a builtin the payloads set: present means code ran


def _payloads(marker: str = "") -> list[str]:
    """Strings that run code when SymPy parses them (each sets the canary builtin; with ``marker``, a file too)."""
    setc = f"__import__('builtins').__setattr__('{CANARY}', 1)"
    touch = f"__import__('pathlib').Path({marker!r}).write_text('ran')" if marker else setc
    return [
        f'exec("{setc}") or 0',
        f"{setc} or 0",
        f"({touch}, 0)[1]",
        f"Symbol('x') + ({setc} or 0)",
        f"Lambda(x, x)({setc} or 0)",
        f"[{setc}, 1][1]",
        f"x')+({setc} or 0)+Symbol('y",
        "1 + 1",  # harmless, and still never read as an expression
    ]


PAYLOADS = _payloads()
NAMES = [
    "x", "theta1", "θ2", "_x0", "L", r"\theta_{2}",  # fine
    "__class__", "__import__", "x')", 'x"', "a\nb", "a b", "lambda", "f()", "os.system", "", "x" * 80,
    f"__import__('builtins').__setattr__('{CANARY}', 1)", "{0.__class__}",
    "exec", "sin", "Symbol", "print", "open", "exit",  # identifiers: names of symbols, never of functions
]  # fmt: skip

# ----------------------------------------------------------------------------------------- the audit hook

_AUDIT = {"armed": False, "events": [], "lambdified": []}
_IMPORT_OK = ("sympy", "numpy", "mpmath")  # lazily imported submodules of the libraries the judge uses
_FORBIDDEN_PREFIXES = ("os.", "subprocess.", "socket.", "shutil.", "ctypes.", "pty.", "webbrowser.", "urllib.")
_FORBIDDEN = {"exec", "compile", "import", "open", "builtins.input", "code.__new__", "function.__new__"}


def _hook(event, args):
    if not _AUDIT["armed"]:
        return
    if event == "compile" and isinstance(args[1], str) and args[1].startswith("<lambdifygenerated-"):
        _AUDIT["lambdified"].append(args[0] if isinstance(args[0], str) else bytes(args[0]).decode())
        return
    if event == "exec" and str(getattr(args[0], "co_filename", "")).startswith("<lambdifygenerated-"):
        return
    if event == "import" and str(args[0]).split(".")[0] in _IMPORT_OK:
        return
    if event == "os.listdir" or event == "os.scandir":  # reading a folder changes nothing
        return
    if event in _FORBIDDEN or event.startswith(_FORBIDDEN_PREFIXES):
        _AUDIT["events"].append((event, repr(args)[:160]))
        _AUDIT["armed"] = False  # (no recursion while raising)
        try:
            raise RuntimeError(f"audit: {event} during judging")
        finally:
            _AUDIT["armed"] = True


sys.addaudithook(_hook)  # (cannot be removed; inert unless armed)


class _Armed:
    def __enter__(self):
        _AUDIT["events"].clear()
        _AUDIT["lambdified"].clear()
        _AUDIT["armed"] = True
        return _AUDIT

    def __exit__(self, *exc):
        _AUDIT["armed"] = False
        return False


# names a lambdified function may call: what SymPy's NumPy printer prints for the whitelisted classes
_LAMBDIFY_CALLS = {
    "select", "where", "less", "greater", "equal", "not_equal", "less_equal", "greater_equal", "logical_and",
    "logical_or", "logical_not", "amin", "amax", "fmin", "fmax", "copysign", "conjugate", "real", "imag", "angle",
    "sign", "floor", "ceil", "mod", "hypot", "arctan2", "exp", "log", "sqrt", "sin", "cos", "tan", "arcsin",
    "arccos", "arctan", "sinh", "cosh", "tanh", "arcsinh", "arccosh", "arctanh", "abs", "absolute", "power",
    "float", "complex", "int", "array", "asarray", "isnan", "isinf", "nan", "inf", "e", "pi", "euler_gamma",
    "Min", "Max", "Abs", "heaviside", "maximum", "minimum", "reduce", "divide", "multiply", "add", "subtract",
    "round", "trunc", "piecewise", "sec", "csc", "cot", "acot", "asec", "acsc", "ExprCondPair", "bool",
}  # fmt: skip


def _check_lambdified(sources):
    """lambdify's generated functions hold no string and call only printed numeric functions (never a name
    the student chose): its arguments are identifiers or lambdify's dummies."""
    for src in sources:
        tree = ast.parse(src)
        for node in ast.walk(tree):
            assert not (isinstance(node, ast.Constant) and isinstance(node.value, (str, bytes))), src
            if isinstance(node, ast.Call):
                f = node.func
                called = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", None)
                assert called in _LAMBDIFY_CALLS, (called, src)
            if isinstance(node, ast.Attribute):
                assert not node.attr.startswith("_"), src
            if isinstance(node, ast.Name):
                assert "__" not in node.id, src


# ----------------------------------------------------------------------------------------- the grader's state

_KINLIB_MODULES = ("kinlib.course.answers", "kinlib.course.grader")


def _state():
    mods = {}
    for name, m in list(sys.modules.items()):
        if name.startswith(_KINLIB_MODULES) or name in ("sympy", "numpy", "builtins", "os", "sys"):
            mods[name] = {k: id(v) for k, v in vars(m).items() if not k.startswith("__")}
    return {
        "canary": hasattr(builtins, CANARY),
        "builtins": {k: id(v) for k, v in vars(builtins).items()},
        "modules": mods,
        "loaded": {n for n in sys.modules if n.split(".")[0] not in _IMPORT_OK},
        "environ": dict(os.environ),
        "cwd": os.getcwd(),
        "sigalrm": signal.getsignal(signal.SIGALRM),
        "itimer": signal.getitimer(signal.ITIMER_REAL)[0],
        "path": list(sys.path),
        "meta_path": [id(f) for f in sys.meta_path],
    }


def _same_state(before, after):
    for key in before:
        if key == "modules":
            for name, d in before[key].items():
                assert after[key].get(name) == d, f"module {name} changed"
        else:
            assert after[key] == before[key], f"the grader's {key} changed"


# ----------------------------------------------------------------------------------------- references per kind

x, th1, th2 = sp.symbols("x theta1 theta2")
L = sp.Symbol("L", positive=True)
POINTS = [{"x": 0.7, "theta1": 0.3, "theta2": -1.1, "L": 1.3}, {"x": -0.4, "theta1": 1.2, "theta2": 2.0, "L": 0.8}]
POINTS += [{"x": 0.2, "theta1": -2.0, "theta2": 0.4, "L": 1.7}] * 3


def _robot():
    from kinlib.robots import planar_rpp

    return planar_rpp()


REFERENCES = {  # kind -> a reference answer of that kind
    "expr": sp.Matrix([[-L * sp.sin(th1), sp.cos(th1 + th2)], [L * sp.cos(th1), 1]]),
    "subspace": sp.Matrix([[1, 4], [2, 5], [3, 6]]),
    "set": {th2: sp.ImageSet(sp.Lambda(sp.Symbol("n", integer=True), sp.Symbol("n", integer=True) * sp.pi),
                             sp.Integers)},
    "choice": (1, 3),
    "property:nonsingular": _robot,
}  # fmt: skip


@pytest.fixture(scope="module")
def refs():
    out = {}
    for kind, value in REFERENCES.items():
        value = value() if callable(value) else value
        entry = reference_answers({"a": ex.exported(value)}, {"a": kind})
        assert "error" not in entry["a"], entry
        out[kind] = (entry["a"]["kind"], Reference("t", "t", "p", "0" * 64, [], entry))
    # warm up: everything the judge imports lazily is imported before any hook is armed
    for k, ref in out.values():
        for v in (REFERENCES["expr"], [1, 2], {th2: {0}}, 1, sp.FiniteSet(0), _robot(), np.array([[1.0]])):
            judge.judge_answer("a", k, json.loads(json.dumps(ex.exported(v))), ref, POINTS, 1, 10.0)
    return out


def _judge_everywhere(tree, refs):
    """wire.load and judge_answer (every kind; one, when the parser refuses the tree: then every kind stops at
    the same read) on ``tree`` under the armed hook; returns the verdicts."""
    verdicts = []
    with _Armed() as audit:
        try:
            wire.load(tree)
            kinds = list(refs.values())
        except (wire.WireError, RecursionError):
            kinds = [refs["expr"]]
        for kind, ref in kinds:
            verdicts.append(judge.judge_answer("a", kind, {"tree": tree}, ref, POINTS, 1, 10.0))
    events, lambdified = list(audit["events"]), list(audit["lambdified"])
    assert not events, (events, tree)
    _check_lambdified(lambdified)
    return verdicts


# ----------------------------------------------------------------------------------------- the tree grammar

_text = st.one_of(st.sampled_from(PAYLOADS), st.text(max_size=12))
_name = st.one_of(st.sampled_from(NAMES), st.text(max_size=8))
_assume = st.sampled_from([{}, {"real": True}, {"positive": True}, {"integer": True}, {"__class__": True}])
_small = st.integers(-50, 50)
_floats = st.floats(allow_nan=True, allow_infinity=True, width=64)

LEAVES = st.one_of(
    st.sampled_from([["none"], ["ellipsis"], ["bool", True], ["bool", False]]),
    _small.map(lambda n: ["int", str(n)]),
    _floats.map(lambda f: ["float", repr(f)]),
    st.tuples(_floats, _floats).map(lambda c: ["complex", repr(c[0]), repr(c[1])]),
    _text.map(lambda s: ["str", s]),
    _text.map(lambda s: ["other", s]),
    _small.map(lambda n: ["Integer", str(n)]),
    st.tuples(_small, _small).map(lambda pq: ["Rational", str(pq[0]), str(pq[1])]),
    st.tuples(
        st.sampled_from(["1.5", "-2e3", "inf", "nan", "1e400", "e", "", "1__0"] + PAYLOADS[:2]), st.integers(0, 120)
    ).map(lambda t: ["Float", t[0], t[1]]),  # fmt: skip
    st.tuples(_name, _assume).map(lambda t: ["Symbol", t[0], t[1]]),
    st.tuples(_name, _assume, st.integers(0, 3)).map(lambda t: ["Dummy", t[0], t[1], t[2]]),
    st.sampled_from(wire.SINGLETONS).map(lambda s: [s]),
    st.sampled_from(["__import__", "eval", "Symbol('x')", "MatrixSymbol", "Str", "Function"]).map(lambda s: [s]),
)


def _branches(kids):
    few = st.lists(kids, max_size=3)
    return st.one_of(
        st.tuples(st.sampled_from(["list", "tuple", "set", "frozenset"]), few).map(lambda t: [t[0], *t[1]]),
        st.lists(st.tuples(kids, kids), max_size=2).map(lambda kv: ["dict", *[list(p) for p in kv]]),
        few.map(lambda xs: ["ndarray", [len(xs)], *xs]),
        st.lists(kids, min_size=4, max_size=4).map(lambda xs: ["ndarray", [2, 2], *xs]),
        kids.map(lambda t: ["robot", t]),
        st.lists(kids, min_size=1, max_size=3).map(lambda xs: ["Matrix", len(xs), 1, *xs]),
        st.lists(kids, min_size=4, max_size=4).map(lambda xs: ["Matrix", 2, 2, *xs]),
        st.tuples(_name, few).map(lambda t: ["UndefinedFunction", t[0], *t[1]]),
        st.tuples(st.sampled_from(wire.CLASSES), few).map(lambda t: [t[0], *t[1]]),
    )


TREES = st.recursive(LEAVES, _branches, max_leaves=8)


@settings(
    max_examples=40,
    derandomize=True,
    database=None,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.function_scoped_fixture],
)
@given(tree=TREES)
def test_no_tree_runs_code_or_changes_the_grader(refs, tree):
    before = _state()
    _judge_everywhere(tree, refs)
    _same_state(before, _state())


# every node of the grammar, deterministically, with a string that is code as an argument
_CODE = PAYLOADS[0]
NODE_TREES = (
    [[op, ["str", _CODE]] for op in wire.CLASSES]
    + [[op, ["Symbol", "x", {}], ["str", _CODE]] for op in wire.CLASSES]
    + [[op, ["list", ["str", _CODE]], ["Integer", "1"]] for op in wire.CLASSES]
    + [[s, ["str", _CODE]] for s in wire.SINGLETONS]
    + [
        ["Matrix", 1, 1, ["str", _CODE]],
        ["Matrix", 1, 2, ["int", "1"], ["list", ["str", _CODE]]],
        ["UndefinedFunction", "f", ["str", _CODE]],
        ["UndefinedFunction", "f", ["tuple", ["str", _CODE]]],
        ["Dict", ["Tuple", ["Symbol", "x", {}], ["str", _CODE]]],
        ["Dict", ["str", _CODE]],
        ["Lambda", ["Tuple", ["Symbol", "x", {}]], ["str", _CODE]],
        ["ImageSet", ["Lambda", ["Symbol", "n", {}], ["str", _CODE]], ["Integers"]],
        ["FiniteSet", ["Tuple", ["str", _CODE], ["Integer", "0"]]],
        ["Piecewise", ["tuple", ["str", _CODE], ["BooleanTrue"]]],
        ["robot", ["Matrix", 1, 1, ["str", _CODE]]],
        ["robot", ["list", ["str", _CODE]]],
        ["robot", ["ndarray", [6, 1], *[["str", _CODE]] * 6]],
    ]
    + [["Symbol", n, {}] for n in NAMES]
    + [["UndefinedFunction", n, ["Symbol", "x", {}]] for n in NAMES]
    + [["Add", ["Symbol", n, {}], ["Integer", "1"]] for n in NAMES]
    + [["ImageSet", ["Lambda", ["Symbol", n, {}], ["Symbol", n, {}]], ["Integers"]] for n in NAMES]
)


def test_every_node_with_code_as_an_argument_runs_nothing(refs):
    before = _state()
    for tree in NODE_TREES:
        verdicts = _judge_everywhere(tree, refs)
        assert all(v.status == "fail" for v in verdicts), (tree, verdicts)  # wrong, never a grader "error"
    _same_state(before, _state())


# plain containers of strings reach every kind's normaliser: each form a kernel can send
CONTAINER_FORMS = []
for _p in (PAYLOADS[0], PAYLOADS[2], PAYLOADS[-1]):
    CONTAINER_FORMS += [
        [_p],
        (_p, 0),
        [[_p, 0], [0, 1]],
        [[_p], [0]],
        {_p},
        {"a": [_p]},
        {th2: [_p]},
        {th2: {(_p, 0)}},
        [{th2: [_p]}],
        [(_p, 0), (0, 1)],
        np.array([_p, 1], dtype=object),
        np.array([[_p, 1], [1, 0]], dtype=object),
        [np.array([_p, 1], dtype=object), sp.Matrix([1, 0])],
        [sp.Matrix([1, 0]), [_p, 1]],
        _p,
    ]


def test_strings_in_containers_are_never_parsed(refs):
    before = _state()
    for value in CONTAINER_FORMS:
        tree = json.loads(json.dumps(ex.export(value)))
        verdicts = _judge_everywhere(tree, refs)
        assert not any(v.passed for v in verdicts[:3]), (value, verdicts)  # (expr, subspace, set: never right)
        assert not any(v.status == "error" for v in verdicts), (value, verdicts)
    _same_state(before, _state())


def test_a_string_is_not_read_as_its_value():
    """Before, "1 + 1" in a list was parsed: ["1 + 1"] passed for [2] and "2" in a set for {2}."""
    for kind, ref, value in [
        ("expr", [2], ["1 + 1"]),
        ("expr", sp.Matrix([[1, 2]]), [["1", "2"]]),
        ("subspace", sp.Matrix([1, 0]), [["1", "0"]]),
        ("set", sp.FiniteSet(2), ["2"]),
        ("set", {th2: sp.FiniteSet(0)}, {th2: ["0"]}),
    ]:
        entry = reference_answers({"a": ex.exported(ref)}, {"a": kind})
        r = Reference("t", "t", "p", "0" * 64, [], entry)
        v = judge.judge_answer("a", entry["a"]["kind"], json.loads(json.dumps(ex.exported(value))), r, POINTS, 1)
        assert not v.passed, (kind, value, v)


# ----------------------------------------------------------------------------------------- each former site


@pytest.mark.parametrize("code", PAYLOADS)
def test_each_former_sympify_site_refuses_a_string(code):
    """wire.py (constructors, Function, Matrix), expr.py (rows, columns, arrays, scalars), sets.py (members,
    tuples), base.py (to_complex), the exact subset (names) and the answer key (the same wire trees): none parses."""
    before = _state()
    with _Armed() as audit:
        for tree in (
            ["sin", ["str", code]],
            ["UndefinedFunction", "f", ["str", code]],
            ["Matrix", 1, 1, ["str", code]],
        ):
            with pytest.raises(wire.WireError):
                wire.load(tree)
        for value in ([code], [[code, 1]], [sp.Matrix([1]), np.array([code], dtype=object)], np.array([code])):
            assert expr.to_sympy(value)[1] is None
            assert expr.to_sympy(value, vectors=True)[1] is None
        with pytest.raises(TypeError):
            sets.to_set([code])
        comp = sets.describe_set({th2: {(code, 0)}}, [{}])["conditions"][0][0][0]
        assert "error" in comp
        with pytest.raises(TypeError):
            base.to_complex(code)
        with pytest.raises(TypeError):
            base.as_sympy([code])
        with pytest.raises(ValueError):
            wire.exact_load(["Symbol", "__import__('os')", {}])
        for tree in (
            ["Dict", ["Tuple", ["Symbol", "x", {}], ["str", code]]],
            ["Tuple", ["str", code]],
            ["Symbol", code, {}],
        ):
            with pytest.raises(wire.WireError):  # a reference cache's tree is read by the same parser
                reference_value(Reference("n", "t", "p", "0", [], {"a": {"tree": tree}}), "a")
    assert not audit["events"], audit["events"]
    _same_state(before, _state())


def test_names_are_identifiers_and_good_answers_still_read():
    """Every name a course answer uses reads; a name that is not one token is refused, whatever node it names."""
    good = [sp.Symbol(n) for n in ("x", "theta_1", "θ2", "_x0", "L1", r"\theta_{2}", "x^T")]
    for s in good:
        assert wire.load(json.loads(json.dumps(ex.export(s)))) == s
    assert wire.load(ex.export(sp.Function("f")(th1))) == sp.Function("f")(th1)
    n = sp.Dummy("n", integer=True)
    img = sp.ImageSet(sp.Lambda(n, 2 * n * sp.pi), sp.Integers)
    assert str(wire.load(ex.export(img))) == str(img)  # (a new Dummy: equal up to the bound variable)
    for bad in NAMES[6:-6]:
        for tree in (["Symbol", bad, {}], ["UndefinedFunction", bad], ["Dummy", bad, {}, 0]):
            with pytest.raises(wire.WireError):
                wire.load(tree)
    for name in ("exec", "print", "open", "exit", "eval"):  # a symbol may be called so; a function may not
        assert wire.load(["Symbol", name, {}]) == sp.Symbol(name)
        with pytest.raises(wire.WireError):
            wire.load(["UndefinedFunction", name, ["Symbol", "x", {}]])


# ----------------------------------------------------------------------------------------- the end-to-end attack


def _attack_cell(marker: Path) -> str:
    """The last cell of an untouched workbook: every answer set to code in strings, in every form."""
    code = _payloads(str(marker))[2]
    return (
        f"_c = {code!r}\n"
        "import numpy as _np\n"
        "Js = [_c]\n"
        "detJ = _np.array([_c, 1], dtype=object)\n"
        "moves = [[_c, 0, 0], [0, 1, 0]]\n"
        "singular = {th2: [_c]}\n"
        "joint_x = (_c,)\n"
        "joint_y = _c\n"
    )


@pytest.mark.slow
@pytest.mark.parametrize("sandbox", [True, False], ids=["sandbox-jobs2", "no-sandbox"])
def test_the_end_to_end_attack_runs_nothing_in_a_batch(tmp_path, sandbox, grader_reference_cache):
    from test_grade import FIX, PARTS, WB, completed

    from kinlib.course.grader import grade

    marker = tmp_path / "trusted-side-ran-code"
    d = tmp_path / "subs"
    d.mkdir()
    wb = json.loads(WB.read_text())
    cell = {"cell_type": "code", "metadata": {}, "outputs": [], "execution_count": None}
    (d / "attacker.ipynb").write_text(
        json.dumps(dict(wb, cells=wb["cells"] + [dict(cell, source=_attack_cell(marker))]))
    )
    (d / "victim.ipynb").write_text(json.dumps(completed()))
    out = tmp_path / "out"
    summary = grade.grade_batch(
        [d], out, jobs=2, timeout=300, cell_timeout=90, notebooks=FIX / "notebooks",
        cache=grader_reference_cache, log=None, sandbox=sandbox,
    )  # fmt: skip
    assert not marker.exists(), "a string in an answer ran as code on the trusted side"
    res = {r["relpath"]: r for r in summary["results"]}
    attacker, victim = res["attacker.ipynb"], res["victim.ipynb"]
    assert not attacker.get("infrastructure") and not victim.get("infrastructure"), summary
    assert [r["part"] for r in attacker["rows"]] == PARTS
    assert sum(r["points"] for r in attacker["rows"]) == 0, [(r["part"], r["message"]) for r in attacker["rows"]]
    assert all(r["status"] == "fail" for r in attacker["rows"]), [(r["part"], r["status"]) for r in attacker["rows"]]
    assert all(r["status"] == "pass" for r in victim["rows"]), [(r["part"], r["message"]) for r in victim["rows"]]
    assert not list(out.rglob("overrides.csv"))


@pytest.mark.slow
def test_the_end_to_end_attack_runs_nothing_in_the_gradescope_bundle(tmp_path, grader_reference_cache):
    """The Gradescope bundle's own entry point (:func:`kinlib.course.lms.bundles.run_platform`, what
    ``run_autograder`` calls; in this process, not in a container: test_grade_lms runs the container): the
    attacker's results.json scores 0 of the maximum, the key is not in its output, no code ran."""
    from test_grade import FIX, WB

    from kinlib.course.lms import bundles

    marker = tmp_path / "trusted-side-ran-code"
    root = tmp_path / "autograder"
    cfg = bundles.build_bundle(root / "source", notebooks=FIX / "notebooks", cache=grader_reference_cache)
    (root / "submission").mkdir(parents=True)
    wb = json.loads(WB.read_text())
    cell = {"cell_type": "code", "metadata": {}, "outputs": [], "execution_count": None}
    nb = dict(wb, cells=wb["cells"] + [dict(cell, source=_attack_cell(marker))])
    (root / "submission" / "90_grade_fixture.ipynb").write_text(json.dumps(nb))
    out = bundles.run_platform("gradescope", root=root)
    assert not marker.exists(), "a string in an answer ran as code on the trusted side"
    results = json.loads((root / "results" / "results.json").read_text())
    top = sum(t["max_score"] for t in results["tests"])
    assert top > 0 and results["score"] == 0 == out["score"], results
    assert all(t["score"] == 0 for t in results["tests"]), results["tests"]
    key = (root / "source" / "grader-secret").read_bytes().strip().decode(errors="ignore")
    assert key not in json.dumps(results) and cfg
