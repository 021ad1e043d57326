"""Fuzz of the public API with bad input (issue 11, item 4).

For every public function: valid arguments, and a hypothesis strategy that corrupts exactly ONE argument
(one entry of it at a random position, or the whole argument) with a bad value: complex numbers, ``sp.I``,
strings (also numeric ones such as "1.5"), booleans, None, NaN/±inf (also ``sp.nan``, ``sp.oo``, ``sp.zoo``),
a symbol that is not declared real, or a wrong shape/length. The call must raise ValueError or TypeError
(nothing else: no LinAlgError, no "math domain error", no NameError from generated code) whose message names
the argument; it must never return (no NaN, no value derived from the real part of a complex number).

Every valid call is also made once, so a corruption that is refused is refused for being bad, not because
the base call was already broken.
"""

from __future__ import annotations

import copy
import importlib
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import kinlib
from kinlib import robots

# --- bad values ----------------------------------------------------------------------------------------
X_PLAIN = sp.Symbol("x")  # not declared real
Z_COMPLEX = sp.Symbol("z", complex=True)  # declared complex
BAD_PY = [
    1 + 2j,
    np.complex128(0.5j),
    2j,
    "1.5",
    "a",
    "",
    True,
    False,
    np.True_,
    None,
    math.nan,
    math.inf,
    -math.inf,
    np.float64("nan"),
    np.float32("inf"),
]
BAD_SYM = [sp.I, 1 + 2 * sp.I, sp.nan, sp.oo, -sp.oo, sp.zoo, X_PLAIN, Z_COMPLEX, sp.sqrt(-2), sp.sin(X_PLAIN)]
BAD_SCALARS = BAD_PY + BAD_SYM
BAD_WHOLE = [None, "abc", "1.5", True, 1j, sp.I, math.nan, 3.5, sp.Symbol("t", real=True)]  # for matrices/vectors
# issue 25: 0-d arrays (a number or a name wrapped by NumPy) and ragged lists, for every container argument
BAD_WHOLE += [np.array(3.5), np.array(2), np.array("vx"), [[1.0, 2.0], [3.0]], [[0.5], 0.5]]

t1, t2, t3 = sp.symbols("theta1:4", real=True)
L = sp.Symbol("L", positive=True)


@dataclass
class Arg:
    """One argument: its name (as the messages say it), a valid value, wrong shapes, whole-value replacements."""

    name: str
    value: Any
    shapes: list = field(default_factory=list)  # values of the wrong shape/length
    whole: list | None = None  # whole-argument bad values (default BAD_WHOLE)
    entries: bool = True  # corrupt single entries (containers, scalars)
    msg: str | None = None  # the name the message must contain (default: name)
    ok: tuple = ()  # bad scalars that are valid here (None as a default ...)

    def __post_init__(self):
        if self.whole is None:  # whole-value replacements: scalars get them as entries
            self.whole = (
                []
                if not isinstance(self.value, (list, tuple, np.ndarray, sp.MatrixBase, dict))
                else [w for w in BAD_WHOLE if not any(w is o for o in self.ok)]
            )


@dataclass
class Case:
    label: str
    fn: Callable | tuple  # a callable, or (module, name) looked up at test time
    args: list
    kw: tuple = ()  # names of the args passed by keyword (in order of args)


def _resolve(fn):
    if callable(fn):
        return fn
    mod, name = fn
    for m in (mod, "kinlib", "kinlib.rigid", "kinlib.screws", "kinlib.velocity", "kinlib.exact"):
        try:
            f = getattr(importlib.import_module(m), name, None)
        except ImportError:
            f = None
        if f is not None:
            return f
    pytest.skip(f"{mod}.{name} does not exist (yet)")


def _call(case: Case, values: list):
    f = _resolve(case.fn)
    pos = [v for a, v in zip(case.args, values) if a.name not in case.kw]
    kws = {a.name: v for a, v in zip(case.args, values) if a.name in case.kw}
    return f(*pos, **kws)


# --- corruption -------------------------------------------------------------------------------------------
def _leaves(v, path=()):
    """Paths to the scalar entries of a (nested) list/tuple, NumPy array or SymPy Matrix."""
    if isinstance(v, sp.MatrixBase):
        return [path + ((i, j),) for i in range(v.rows) for j in range(v.cols)]
    if isinstance(v, np.ndarray):
        return [path + (idx,) for idx in np.ndindex(v.shape)]
    if isinstance(v, (list, tuple)):
        out = []
        for i, e in enumerate(v):
            out += _leaves(e, path + (i,))
        return out
    return [path]


def _set(v, path, bad):
    """A copy of v with the entry at ``path`` replaced by ``bad`` (the container type kept where it can hold it)."""
    if not path:
        return bad
    head, rest = path[0], path[1:]
    if isinstance(v, sp.MatrixBase):
        rows = [[v[i, j] for j in range(v.cols)] for i in range(v.rows)]
        rows[head[0]][head[1]] = bad
        if isinstance(bad, sp.Expr):
            return sp.Matrix(rows)
        return rows  # a nested list holding the bad entry as it is (str, None, ...)
    if isinstance(v, np.ndarray):
        if isinstance(bad, (float, np.floating)) and v.dtype.kind == "f":
            out = v.copy()
        elif isinstance(bad, (complex, np.complexfloating)) and v.dtype.kind in "fc":
            out = v.astype(complex)
        else:
            out = v.astype(object)
        out[head] = bad
        return out
    out = list(v)
    out[head] = _set(out[head], rest, bad)
    return type(v)(out) if isinstance(v, tuple) else out


@st.composite
def corrupted(draw, case: Case):
    """(index of the corrupted argument, the argument values with one of them bad, a description)."""
    k = draw(st.integers(0, len(case.args) - 1))
    a = case.args[k]
    values = [copy.copy(x.value) for x in case.args]
    modes = (["entry"] if a.entries else []) + (["whole"] if a.whole else []) + (["shape"] if a.shapes else [])
    mode = draw(st.sampled_from(modes))
    if mode == "entry":
        paths = _leaves(a.value)
        path = draw(st.sampled_from(paths))
        bad = draw(st.sampled_from([b for b in BAD_SCALARS if not any(b is o for o in a.ok)]))
        values[k] = _set(a.value, path, bad)
        what = f"{a.name}{list(path) if path else ''} = {bad!r}"
    elif mode == "whole":
        bad = draw(st.sampled_from(a.whole))
        values[k] = bad
        what = f"{a.name} = {bad!r}"
    else:
        bad = draw(st.sampled_from(a.shapes))
        values[k] = bad
        what = f"{a.name} of the wrong shape: {bad!r}"[:200]
    return k, values, what


# --- valid arguments ----------------------------------------------------------------------------------------
Z = [0, 0, 1, 0, 0, 0]
S2 = np.array([Z, [0, 0, 1, 0, -1, 0]], dtype=float).T  # planar 2R, unit links
S2_SYM = sp.Matrix(S2.astype(int))
M2 = np.eye(4)
M2[0, 3] = 2.0
M2_SYM = sp.Matrix(M2.astype(int))
T_NUM = kinlib.fk_space(M2, S2, [0.3, -0.4])
T_SYM = sp.Matrix([[0, -1, 0, 1], [1, 0, 0, 1], [0, 0, 1, 0], [0, 0, 0, 1]])
J_NUM = kinlib.jacobian_space(S2, [0.3, -0.4])
J_SYM = sp.Matrix(S2_SYM)
J_TRIG = sp.Matrix(
    [[-sp.sin(t1) - sp.sin(t1 + t2), -sp.sin(t1 + t2)], [sp.cos(t1) + sp.cos(t1 + t2), sp.cos(t1 + t2)]]
)  # planar 2R, rows ṗx, ṗy
J2 = np.array([[1.0, 0.5], [0.2, 2.0]])
J2_SYM = sp.Matrix([[1, sp.Rational(1, 2)], [sp.Rational(1, 5), 2]])

MAT6 = [np.zeros((5, 2)), np.zeros((6,)), np.zeros((2, 6, 2)), [[0, 0]] * 7]
MAT44 = [np.eye(3), np.eye(5), np.zeros(4), [[1, 0, 0, 0]] * 3]
VEC3 = [[0, 0], [0, 0, 1, 0], np.zeros((3, 2)), []]
VEC6 = [[0, 0, 1, 0, 0], Z + [0], np.zeros((6, 2)), []]
SCREWS = [np.zeros((5, 2)), [Z, [0, 0, 1, 0, -1]], [Z[:5]], [], np.zeros((6, 2, 1))]
TH2 = [[0.1], [0.1, 0.2, 0.3], [[0.1, 0.2]] * 2, []]  # [2] is a valid batch for rates, twists, wrenches
TH2_SYM = [[t1], [t1, t2, t3], []]
JMAT = [np.zeros((2, 2, 2, 2)), np.zeros(3), [[1.0, 2.0], [3.0]], []]

CHAIN = kinlib.SerialChain(M2, S2, name="planar_2r")
CHAIN.jacobian_space(np.array([0.1, 0.2]))  # code generated: the fast path is fuzzed too
for _m in ("fk", "jacobian_body", "jacobian_geometric", "skeleton"):
    getattr(CHAIN, _m)(np.array([0.1, 0.2]))
PCHAIN = robots.planar_offset_3r()
Q2 = [[0.1], [0.1, 0.2, 0.3], np.zeros((2, 3)), np.zeros((2, 2, 2)), []]

R_ROT = T_NUM[:3, :3]
# Symbols not declared real are refused everywhere (issue 25: one check, kinlib._backend.check_real_finite, for
# every public function): joint symbols and values, parameters of screws and M, and generic matrices too (a
# twist, a pose T, a Jacobian J, display input).
GENERIC_OK = ()
DISPLAY_OK = ()


def A(name, value, shapes=(), **kw):
    return Arg(name, value, list(shapes), **kw)


CASES = [
    # --- rigid ---------------------------------------------------------------------------------------------
    Case("skew", kinlib.skew, [A("w", [0.1, 0.2, 0.3], VEC3, ok=GENERIC_OK)]),
    Case("skew (sym)", kinlib.skew, [A("w", sp.Matrix([t1, 0, 1]), VEC3, ok=GENERIC_OK)]),
    Case(
        "unskew", kinlib.unskew, [A("W", kinlib.skew([0.1, 0.2, 0.3]), [np.zeros((2, 2)), np.zeros(3)], ok=GENERIC_OK)]
    ),
    Case("exp3", kinlib.exp3, [A("omega", [0, 0, 1.0], VEC3, ok=GENERIC_OK), A("theta", 0.3)]),
    Case("exp3 (sym)", kinlib.exp3, [A("omega", sp.Matrix([0, 0, 1]), VEC3, ok=GENERIC_OK), A("theta", t1)]),
    Case(
        "rp_to_trans",
        kinlib.rp_to_trans,
        [A("R", np.eye(3), [np.eye(4), np.zeros(3)], ok=GENERIC_OK), A("p", [1.0, 2, 3], VEC3, ok=GENERIC_OK)],
    ),
    Case("trans_to_rp", kinlib.trans_to_rp, [A("T", T_NUM, MAT44, ok=GENERIC_OK)]),
    Case("trans_inv", kinlib.trans_inv, [A("T", T_NUM, MAT44, ok=GENERIC_OK)]),
    Case("trans_inv (sym)", kinlib.trans_inv, [A("T", T_SYM, MAT44, ok=GENERIC_OK)]),
    Case("adjoint", kinlib.adjoint, [A("T", T_NUM, MAT44, ok=GENERIC_OK)]),
    Case("adjoint (sym)", kinlib.adjoint, [A("T", T_SYM, MAT44, ok=GENERIC_OK)]),
    Case("check_so3", kinlib.check_so3, [A("R", R_ROT, [np.eye(4), np.eye(2)], ok=GENERIC_OK)]),
    Case("check_se3", kinlib.check_se3, [A("T", T_NUM, MAT44, ok=GENERIC_OK)]),
    # --- screws --------------------------------------------------------------------------------------------
    Case("screw_revolute", kinlib.screw_revolute, [A("omega", [0, 0, 1.0], VEC3), A("q", [1.0, 0, 0], VEC3)]),
    Case(
        "screw_revolute (sym)",
        kinlib.screw_revolute,
        [A("omega", sp.Matrix([0, 0, 1]), VEC3), A("q", sp.Matrix([L, 0, 0]), VEC3)],
    ),
    Case("screw_prismatic", kinlib.screw_prismatic, [A("v", [1.0, 0, 0], VEC3)]),
    Case("screw_axis", kinlib.screw_axis, [A("q", [0, 1.0, 0], VEC3), A("s", [0, 0, 1.0], VEC3), A("h", 0.5)]),
    Case("bracket", kinlib.bracket, [A("V", [0.1, 0.2, 0.3, 1, 2, 3], VEC6, ok=GENERIC_OK)]),
    Case("unbracket", kinlib.unbracket, [A("X", kinlib.bracket([0.1, 0.2, 0.3, 1, 2, 3]), MAT44, ok=GENERIC_OK)]),
    Case("exp6", kinlib.exp6, [A("S", Z, VEC6), A("theta", 0.7)]),
    Case("exp6 (sym)", kinlib.exp6, [A("S", sp.Matrix(Z), VEC6), A("theta", t1)]),
    Case("log3", ("kinlib.rigid", "log3"), [A("R", R_ROT, [np.eye(4), np.zeros(3)])]),
    Case("log6", ("kinlib.screws", "log6"), [A("T", T_NUM, MAT44)]),
    # --- jacobians -------------------------------------------------------------------------------------------
    Case("jacobian_space", kinlib.jacobian_space, [A("Slist", S2, SCREWS), A("thetas", [0.3, -0.4], TH2)]),
    Case("jacobian_space (sym)", kinlib.jacobian_space, [A("Slist", S2_SYM, SCREWS), A("thetas", [t1, t2], TH2_SYM)]),
    Case("jacobian_body", kinlib.jacobian_body, [A("Blist", S2, SCREWS), A("thetas", [0.3, -0.4], TH2)]),
    Case(
        "geometric_jacobian",
        kinlib.geometric_jacobian,
        [A("M", M2, MAT44), A("Slist", S2, SCREWS), A("thetas", [0.3, -0.4], TH2)],
    ),
    Case(
        "space_to_body",
        kinlib.space_to_body,
        [A("Js", J_NUM, MAT6, ok=GENERIC_OK), A("T", T_NUM, MAT44, ok=GENERIC_OK)],
    ),
    Case(
        "space_to_body (sym)",
        kinlib.space_to_body,
        [A("Js", J_SYM, MAT6, ok=GENERIC_OK), A("T", T_SYM, MAT44, ok=GENERIC_OK)],
    ),
    Case(
        "body_to_space",
        kinlib.body_to_space,
        [A("Jb", J_NUM, MAT6, ok=GENERIC_OK), A("T", T_NUM, MAT44, ok=GENERIC_OK)],
    ),
    Case(
        "body_to_geometric",
        kinlib.body_to_geometric,
        [A("Jb", J_NUM, MAT6, ok=GENERIC_OK), A("T", T_NUM, MAT44[1:], ok=GENERIC_OK)],
    ),
    Case(
        "geometric_to_body",
        kinlib.geometric_to_body,
        [A("J", J_NUM, MAT6, ok=GENERIC_OK), A("T", T_NUM, MAT44[1:], ok=GENERIC_OK)],
    ),
    Case(
        "space_to_geometric",
        kinlib.space_to_geometric,
        [A("Js", J_NUM, MAT6, ok=GENERIC_OK), A("T", T_NUM, MAT44, ok=GENERIC_OK)],
    ),
    Case(
        "geometric_to_space",
        kinlib.geometric_to_space,
        [A("J", J_NUM, MAT6, ok=GENERIC_OK), A("T", T_NUM, MAT44, ok=GENERIC_OK)],
    ),
    Case("linear_first", kinlib.linear_first, [A("J", J_NUM, MAT6[:1] + MAT6[2:], ok=GENERIC_OK)]),
    Case("angular_first", kinlib.angular_first, [A("J", J_NUM, MAT6[:1] + MAT6[2:], ok=GENERIC_OK)]),
    Case(
        "position_jacobian",
        kinlib.position_jacobian,
        [
            A("p", [t1 + L * sp.cos(t2), L * sp.sin(t2)], [[], "p"], ok=GENERIC_OK),
            A("thetas", [t1, t2], [[], [t1, t1]], whole=[None, "ab", 3, True, [X_PLAIN, t2], [1.0, 2.0]]),
        ],
    ),
    # --- chains ----------------------------------------------------------------------------------------------
    Case("fk_space", kinlib.fk_space, [A("M", M2, MAT44), A("Slist", S2, SCREWS), A("thetas", [0.3, -0.4], TH2)]),
    Case(
        "fk_space (sym)",
        kinlib.fk_space,
        [A("M", M2_SYM, MAT44), A("Slist", S2_SYM, SCREWS), A("thetas", [t1, t2], TH2_SYM)],
    ),
    Case("fk_body", kinlib.fk_body, [A("M", M2, MAT44), A("Blist", S2, SCREWS), A("thetas", [0.3, -0.4], TH2)]),
    Case(
        "SerialChain",
        kinlib.SerialChain,
        [
            A("M", M2, MAT44),
            A("screws", [Z, [0, 0, 1, 0, -1, 0]], SCREWS),
            A(
                "thetas",
                (t1, t2),
                [(t1,), (t1, t2, t3), (t1, t1)],
                whole=[X_PLAIN, "ab", 3, True, [1.0, 2.0], [X_PLAIN, t2], [t1, Z_COMPLEX]],
                entries=False,
            ),
            A(
                "joint_points",
                [[0, 0, 0], [1.0, 0, 0]],
                [[[0, 0], [1, 0]], np.zeros((3, 3)), [[0, 0, 0]]],
                whole=["abc", True, 1j, math.nan, 3.5],
            ),
            A("name", "arm", whole=[None, 3, True, ["a"]], entries=False),
        ],
        kw=("thetas", "joint_points", "name"),
    ),
    Case("SerialChain (sym)", kinlib.SerialChain, [A("M", M2_SYM, MAT44), A("screws", S2_SYM, SCREWS)]),
    Case("SerialChain.subs", lambda L: PCHAIN.subs(L=L), [A("L", 0.5, whole=[], msg="L")]),
    *[
        Case(
            f"SerialChain.{m}",
            (lambda m: lambda q: getattr(CHAIN, m)(q))(m),  # noqa: B023 (bound by the outer lambda)
            [A("q", np.array([0.3, -0.4]), Q2, ok=(None,))],
        )
        for m in ("fk", "jacobian_space", "jacobian_body", "jacobian_geometric", "skeleton")
    ],
    Case("SerialChain.fk (list)", lambda q: CHAIN.fk(q), [A("q", [0.3, -0.4], Q2, ok=(None,))]),
    Case(
        "SerialChain.jacobian_space (batch)",
        lambda q: CHAIN.jacobian_space(q),
        [A("q", np.array([[0.3, -0.4], [1.0, 2.0], [0.0, 0.5]]), [np.zeros((3, 3))], ok=(None,))],
    ),
    Case(
        "SerialChain.jacobian_body (sym q)", lambda q: CHAIN.jacobian_body(q), [A("q", [sp.pi / 4, t2], Q2, ok=(None,))]
    ),
    Case(
        "SerialChain.fk (sym chain)",
        lambda q: PCHAIN.fk(q),
        [A("q", [sp.pi, 0, sp.Rational(1, 2)], Q2[:1], ok=(None,))],
    ),
    # --- robots ----------------------------------------------------------------------------------------------
    Case(
        "robots.length",
        robots.length,
        [A("L", 0.5, whole=[], ok=(None,)), A("name", "L", whole=[None, 3, True], entries=False)],
    ),
    Case("robots.cart_pole", robots.cart_pole, [A("L", 1.0, whole=[], ok=(None,)), A("h", 0.5, whole=[], ok=(None,))]),
    Case("robots.planar_offset_3r", robots.planar_offset_3r, [A("L", 2, whole=[], ok=(None,))]),
    Case(
        "robots.spatial_rppr",
        robots.spatial_rppr,
        [A("L1", 1, whole=[], ok=(None,)), A("L2", 0.25, whole=[], ok=(None,))],
    ),
    Case(
        "robots.planar_3r",
        robots.planar_3r,
        [A("L1", 1, whole=[], ok=(None,)), A("L2", 1, whole=[], ok=(None,)), A("L3", L, whole=[], ok=(None,))],
    ),
    Case("robots.planar_rpp", robots.planar_rpp, [A("L", 0.1, whole=[], ok=(None,))]),
    Case(
        "robots.ur5",
        robots.ur5,
        [A("W1", 0.109, whole=[], ok=(None,)), A("L2", L, whole=[], ok=(None,))],
        kw=("W1", "L2"),
    ),
    # --- display ---------------------------------------------------------------------------------------------
    Case(
        "simplify_for_display",
        kinlib.simplify_for_display,
        [
            A(
                "M",
                sp.Matrix([[sp.sin(t1) ** 2 + sp.cos(t1) ** 2, 0.5]]),
                whole=[None, "abc", True, 1j, sp.I, math.nan],
                ok=DISPLAY_OK,
            )
        ],
    ),
    Case(
        "is_identically_zero",
        kinlib.is_identically_zero,
        [
            A(
                "M",
                sp.Matrix([[sp.sin(t1) ** 2 + sp.cos(t1) ** 2 - 1, 0]]),
                whole=[None, "abc", True, 1j, sp.I, math.nan],
                ok=DISPLAY_OK,
            )
        ],
    ),
    # --- singularities (owned by items 1–2) ------------------------------------------------------------------
    Case(
        "task_rows",
        ("kinlib.singularities", "task_rows"),
        [
            A("J", J_NUM, [np.zeros((2, 2, 2)), np.zeros(6)], ok=GENERIC_OK),
            A("rows", ["vx", "vy"], [[], ["vx", "qq"], [7]], whole=[None, "abc", True, 1j, 3.5]),
        ],
    ),
    Case(
        "singular_configurations",
        ("kinlib.singularities", "singular_configurations"),
        [
            A("J", J_TRIG, JMAT[:2]),
            A(
                "thetas",
                [t1, t2],
                [[t1], [t1, t2, t3], [t1, t1]],
                entries=False,
                whole=[None, "ab", 3, [X_PLAIN, t2], [t1, Z_COMPLEX], [1.0, 2.0]],
            ),
        ],
    ),
    Case("rank_at (numeric)", ("kinlib.singularities", "rank_at"), [A("J", J2, JMAT)]),
    Case(
        "rank_at",
        ("kinlib.singularities", "rank_at"),
        [A("J", J_TRIG, JMAT), A("subs", {t1: 1, t2: 0}, whole=["abc", True, 1j, 3.5, [1.0]], entries=False)],
    ),
    Case(
        "rank_at (values)",
        lambda q: _resolve(("kinlib.singularities", "rank_at"))(J_TRIG, {t1: q[0], t2: q[1]}),
        [A("subs", [sp.Rational(1, 2), 0], whole=[])],
    ),
    Case(
        "column_space",
        ("kinlib.singularities", "column_space"),
        [A("J", J_TRIG, JMAT), A("subs", {t1: 1, t2: 0}, whole=["abc", True, 1j, 3.5], entries=False)],
    ),
    Case(
        "left_null_space",
        ("kinlib.singularities", "left_null_space"),
        [A("J", J_TRIG, JMAT), A("subs", {t1: 1, t2: 0}, whole=["abc", True, 1j, 3.5], entries=False)],
    ),
    Case(
        "left_null_space (values)",
        lambda q: _resolve(("kinlib.singularities", "left_null_space"))(J_TRIG, {t1: q[0], t2: q[1]}),
        [A("subs", [3, 0], whole=[])],
    ),
    Case(
        "evaluate_at",
        ("kinlib.singularities", "evaluate_at"),
        [A("J", J_TRIG, JMAT), A("subs", {t1: 1, t2: 0}, whole=["abc", True, 1j, 3.5], entries=False)],
    ),
    # --- manipulability --------------------------------------------------------------------------------------
    Case("manipulability", kinlib.manipulability.manipulability, [A("J", J2, JMAT, ok=GENERIC_OK)]),
    Case("manipulability (sym)", kinlib.manipulability.manipulability, [A("J", J2_SYM, JMAT, ok=GENERIC_OK)]),
    Case("singular_values", ("kinlib.manipulability", "singular_values"), [A("J", J2, JMAT, ok=GENERIC_OK)]),
    Case("velocity_ellipsoid", kinlib.velocity_ellipsoid, [A("J", J2, JMAT, ok=GENERIC_OK)]),
    Case("twist_speed_form", kinlib.twist_speed_form, [A("J", J2, JMAT, ok=GENERIC_OK)]),
    Case(
        "twist_speed",
        ("kinlib.manipulability", "twist_speed"),
        [A("J", J2, JMAT, ok=GENERIC_OK), A("qdot", [1.0, 2.0], TH2[:2] + TH2[3:], ok=GENERIC_OK)],
    ),
    Case(
        "strongest_joints",
        ("kinlib.manipulability", "strongest_joints"),
        [A("row", [1.0, -3.0, 2.0], [[], np.zeros((2, 2, 2))])],
    ),
    Case("condition_number", kinlib.condition_number, [A("J", J2, JMAT, ok=GENERIC_OK)]),
    Case("condition_number (sym)", kinlib.condition_number, [A("J", J2_SYM, JMAT, ok=GENERIC_OK)]),
    Case("isotropy", kinlib.isotropy, [A("J", J2, JMAT, ok=GENERIC_OK)]),
    Case("isotropy (sym)", kinlib.isotropy, [A("J", J2_SYM, JMAT, ok=GENERIC_OK)]),
    # --- velocity kinematics (item 7) ------------------------------------------------------------------------
    Case("pseudoinverse", ("kinlib.velocity", "pseudoinverse"), [A("J", J2, JMAT)]),
    Case("pseudoinverse (sym)", ("kinlib.velocity", "pseudoinverse"), [A("J", J2_SYM, JMAT)]),
    Case(
        "inverse_velocity",
        ("kinlib.velocity", "inverse_velocity"),
        [A("J", J2, JMAT), A("V", [1.0, 2.0], TH2[:2] + TH2[3:])],
    ),
    Case(
        "damped_least_squares",
        ("kinlib.velocity", "damped_least_squares"),
        [A("J", J2, JMAT), A("V", [1.0, 2.0], TH2[:2] + TH2[3:]), A("damping", 0.1)],
    ),
    Case(
        "joint_torques", ("kinlib.velocity", "joint_torques"), [A("J", J2, JMAT), A("F", [1.0, 2.0], TH2[:2] + TH2[3:])]
    ),
    Case("force_ellipsoid", ("kinlib.velocity", "force_ellipsoid"), [A("J", J2, JMAT)]),
]


PARAMS = [pytest.param(c, id=c.label) for c in CASES]


@pytest.mark.parametrize("case", [pytest.param(c, id=c.label) for c in CASES])
def test_valid_call_works(case):
    """The base call of each case is valid (so the corruptions below are what is refused)."""
    _call(case, [a.value for a in case.args])


def _named(msg: str, name: str) -> bool:
    return re.search(rf"(?<![A-Za-z0-9_]){re.escape(name)}(?![A-Za-z0-9_])", msg) is not None


@pytest.mark.parametrize("case", PARAMS)
@settings(
    deadline=None,
    derandomize=True,
    max_examples=25,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
)
@given(data=st.data())
def test_bad_input_is_refused(case, data):
    k, values, what = data.draw(corrupted(case), label="corruption")
    name = case.args[k].msg or case.args[k].name
    try:
        out = _call(case, values)
    except (ValueError, TypeError) as err:
        msg = str(err)
        assert _named(msg, name), f"{case.label} with {what}: the message does not name {name!r}: {msg}"
        assert "got" in msg or "no parameter" in msg, (
            f"{case.label} with {what}: the message says not what was given: {msg}"
        )
        return
    # any other exception propagates (and fails the test): LinAlgError, ZeroDivisionError, NameError, ...
    pytest.fail(f"{case.label} with {what} returned {str(out)[:200]} instead of raising")


# issue 25: every case, every argument, deterministically: a symbol not declared real in its first entry, and
# each 0-d array and ragged list in place of a container argument
_SWEEP = [np.array(3.5), np.array(2), np.array("vx"), [[1.0, 2.0], [3.0]], [[0.5], 0.5]]


def _refused_naming(case, values, k, what):
    name = case.args[k].msg or case.args[k].name
    try:
        out = _call(case, values)
    except (ValueError, TypeError) as err:
        assert _named(str(err), name), f"{case.label} with {what}: the message does not name {name!r}: {err}"
        return
    pytest.fail(f"{case.label} with {what} returned {str(out)[:200]} instead of raising")


@pytest.mark.parametrize("case", PARAMS)
def test_non_real_symbols_zero_d_arrays_and_ragged_lists_are_refused(case):
    for k, a in enumerate(case.args):
        base = [copy.copy(x.value) for x in case.args]
        if a.entries and not any(X_PLAIN is o for o in a.ok):
            for bad in (X_PLAIN, sp.sin(X_PLAIN) + 1):
                values = list(base)
                values[k] = _set(a.value, _leaves(a.value)[0], bad)
                _refused_naming(case, values, k, f"{a.name}'s first entry = {bad}")
        if isinstance(a.value, (list, tuple, np.ndarray, sp.MatrixBase)) and a.whole:
            for bad in _SWEEP:
                values = list(base)
                values[k] = bad
                _refused_naming(case, values, k, f"{a.name} = {bad!r}")


def _exact_anywhere(v) -> bool:
    if isinstance(v, (sp.Basic, sp.MatrixBase)):
        return True
    if isinstance(v, (list, tuple)):
        return any(_exact_anywhere(e) for e in v)
    if isinstance(v, np.ndarray) and v.dtype == object:
        return any(_exact_anywhere(e) for e in v.reshape(-1))
    return isinstance(v, kinlib.SerialChain)


@pytest.mark.parametrize("case", PARAMS)
def test_integers_beyond_float_range_are_refused_by_the_float_backend(case):
    """issue 32: an int such as 10**400 in any numeric argument slot (each entry in turn) raises a ValueError or
    TypeError naming the argument, never a bare OverflowError. Only calls whose arguments are all numbers (the
    float backend): with SymPy arguments an int of any size is an exact number."""
    if any(_exact_anywhere(a.value) for a in case.args):
        pytest.skip("an exact call: 10**400 is a valid exact number there")
    for k, a in enumerate(case.args):
        if not a.entries or isinstance(a.value, (str, dict)) or a.value is None:
            continue
        for path in _leaves(a.value):
            if not isinstance(_get(a.value, path), (int, float, np.integer, np.floating)) or isinstance(
                _get(a.value, path), bool
            ):
                continue
            values = [copy.copy(x.value) for x in case.args]
            values[k] = _set(a.value, path, 10**400)
            name = a.msg or a.name
            try:
                out = _call(case, values)
            except (ValueError, TypeError) as err:
                assert _named(str(err), name), f"{case.label}: the message does not name {name!r}: {err}"
                continue
            # a chain is built from exact numbers, an exact value (subs of a configuration, a length) is exact:
            # 10**400 is fine there; a float answer must refuse
            assert isinstance(out, (kinlib.SerialChain, sp.Basic, sp.MatrixBase)), (
                f"{case.label} with {a.name}{list(path)} = 10**400: {out}"
            )
            if (
                isinstance(out, kinlib.SerialChain) and out.n and not out.params
            ):  # and its float code then refuses what it cannot represent
                with pytest.raises((ValueError, TypeError, OverflowError)) as caught:
                    out.jacobian_geometric(np.zeros(out.n))
                assert caught.type is not OverflowError, caught.value


def _get(v, path):
    for head in path:
        v = v[head]
    return v


# ==========================================================================================================
# Item 3: numbers typed by the student become exact when the chain is built
# ==========================================================================================================
def _no_floats(M):
    return not any(isinstance(a, sp.Float) for a in sp.Matrix(M).atoms(sp.Float))


def test_chain_from_lists_equals_chain_from_sympy():
    """Lists, NumPy floats, sp.Float and sp.Matrix of the same numbers give the same exact chain."""
    Ml = np.eye(4)
    Ml[0, 3] = 2.0
    screws = [[0.0, 0.0, 1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0, -1.0, 0.0]]
    by_lists = kinlib.SerialChain(Ml.tolist(), screws)
    by_numpy = kinlib.SerialChain(Ml, np.array(screws).T)
    by_screw_fns = kinlib.SerialChain(
        Ml,
        [
            kinlib.screw_revolute([0, 0, 1.0], [0, 0, 0]),
            kinlib.screw_revolute(np.array([0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]),
        ],
    )
    by_floats = kinlib.SerialChain(sp.Matrix(Ml).applyfunc(sp.Float), sp.Matrix(screws).T.applyfunc(sp.Float))
    exact = kinlib.SerialChain(
        sp.Matrix([[1, 0, 0, 2], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]),
        sp.Matrix([[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -1, 0]]).T,
    )
    for c in (by_lists, by_numpy, by_screw_fns, by_floats):
        assert c.screws == exact.screws and c.M == exact.M and c.joint_points == exact.joint_points
        assert c.params == () and c.joint_types == "RR"
        assert all(isinstance(e, sp.Integer) for e in list(c.screws) + list(c.M))
        J = c.jacobian_geometric()
        assert _no_floats(J) and J == exact.jacobian_geometric()
    # the ṗ rows of the 2R arm: ∂p/∂θ of p = (cos θ1 + cos(θ1 + θ2), sin θ1 + sin(θ1 + θ2)), written by hand
    a, b = exact.thetas
    Jp = kinlib.task_rows(by_numpy.jacobian_geometric(), ["vx", "vy"])
    want = sp.Matrix([[-sp.sin(a) - sp.sin(a + b), -sp.sin(a + b)], [sp.cos(a) + sp.cos(a + b), sp.cos(a + b)]])
    assert kinlib.is_identically_zero(Jp - want) and _no_floats(Jp)


def test_typed_decimals_are_exact():
    """0.1 → 1/10, 0.425 → 17/40, 2.0 → 2: the decimal typed, never the float's binary expansion."""
    M = np.eye(4)
    M[:3, 3] = [0.1, 0.425, 2.0]
    c = kinlib.SerialChain(M, [[0, 0, 1, 0, -0.1, 0], [0, 0, 0, 0.6, 0.8, 0]])
    assert list(c.M[:3, 3]) == [sp.Rational(1, 10), sp.Rational(17, 40), 2]
    assert list(c.screws[:, 0]) == [0, 0, 1, 0, sp.Rational(-1, 10), 0]
    assert list(c.screws[:, 1]) == [0, 0, 0, sp.Rational(3, 5), sp.Rational(4, 5), 0] and c.joint_types == "RP"
    # sp.Float inside expressions too: 0.5·L → L/2
    c2 = kinlib.SerialChain(
        sp.Matrix([[1, 0, 0, sp.Float(0.5) * L], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]),
        [sp.Matrix([0, 0, 1, 0, -sp.Float(0.25) * L, 0])],
    )
    assert c2.M[0, 3] == L / 2 and c2.screws[4, 0] == -L / 4 and c2.params == (L,)
    # subs and robots.length: the typed decimal as well (was nsimplify)
    p = robots.planar_offset_3r()
    assert p.subs(L=0.1).M[:3, 3] == sp.Matrix([sp.Rational(3, 10), sp.Rational(1, 10), 0])
    assert p.subs({L: 0.1}).M == p.subs(L=sp.Rational(1, 10)).M
    assert robots.length(0.425, "L1") == sp.Rational(17, 40) and robots.length(1 / 3, "L") == sp.Rational(
        "0.3333333333333333"
    )
    assert robots.ur5(L1=0.425).M == robots.ur5().M
    # symbolic joint values: a float among them is the decimal typed
    assert c.fk([sp.pi, 0.5]) == c.fk([sp.pi, sp.Rational(1, 2)])


def test_numbers_in_numbers_out():
    """Screw functions with plain numbers keep returning NumPy arrays; SerialChain is where they become exact."""
    S = kinlib.screw_revolute([0, 0, 1.0], [0.1, 0, 0])
    assert isinstance(S, np.ndarray) and S.dtype == float
    assert isinstance(kinlib.screw_prismatic([0, 0.6, 0.8]), np.ndarray)
    assert isinstance(kinlib.screw_axis([0, 0.1, 0], [0, 0, 1.0], 0.5), np.ndarray)
    assert isinstance(kinlib.exp6(S, 0.3), np.ndarray)
    c = kinlib.SerialChain(np.eye(4), [S])
    assert c.screws[4, 0] == sp.Rational(-1, 10)


def test_float_axes_unit_only_to_rounding():
    """Axes typed (or computed) as floats that are unit only to rounding: accepted when | |ω|² − 1 | ≤ 1e-9,
    kept exactly as typed (never rounded to a 'nice' value); refused beyond, with a hint to type sp.sqrt(2)/2."""
    import modern_robotics as mr

    h = 0.7071067811865476
    c = kinlib.SerialChain(np.eye(4), [[h, h, 0, 0, 0, 0], [0, 0, 1, 0, -1.0, 0]])
    assert c.screws[0, 0] == sp.Rational("0.7071067811865476") and not c.screws[0, 0].has(sp.sqrt)
    n2 = c.screws[0, 0] ** 2 + c.screws[1, 0] ** 2
    assert n2 != 1 and abs(n2 - 1) < sp.Rational(1, 10**15)
    # an axis computed by rotating: R_x(0.3) ẑ
    w = np.array([[1, 0, 0], [0, np.cos(0.3), -np.sin(0.3)], [0, np.sin(0.3), np.cos(0.3)]]) @ [0, 0, 1.0]
    c2 = kinlib.SerialChain(np.eye(4), [kinlib.screw_revolute(w, [0.2, 0, 0])])
    assert c2.joint_types == "R" and _no_floats(c2.screws)
    q = np.array([0.7])
    np.testing.assert_allclose(c2.fk(q), mr.FKinSpace(np.eye(4), np.array(c2.screws, dtype=float), q), atol=1e-12)
    # the exact result is the exact product of exponentials of the typed numbers: compare at 50 digits
    T = c2.fk([sp.Rational(7, 10)]).evalf(50)
    np.testing.assert_allclose(np.array(T, dtype=float), c2.fk(q), atol=1e-14)
    for bad in ([0.70710678, 0.70710678, 0], [0.7071, 0.7071, 0]):  # |ω|² − 1 = −3e-9, −2e-5
        with pytest.raises(
            ValueError, match=r"angular part ω of screws column 1 must be a unit vector.*sp\.sqrt\(2\)/2"
        ):
            kinlib.SerialChain(np.eye(4), [bad + [0, 0, 0]])
    # the rule is about the numbers, not the container: the same rationals typed in an sp.Matrix behave the same
    same = sp.Matrix([sp.Rational("0.7071067811865476")] * 2 + [0] * 4)
    assert kinlib.SerialChain(np.eye(4), [same]).screws[:, 0] == c.screws[:, 0]
    with pytest.raises(ValueError, match="must be a unit vector"):
        kinlib.SerialChain(np.eye(4), [sp.Matrix([1, sp.Rational(1, 10**4), 0, 0, 0, 0])])  # |ω|² − 1 = 1e-8
    # an irrational axis must be exactly unit (no tolerance)
    with pytest.raises(ValueError, match="must be a unit vector"):
        kinlib.SerialChain(np.eye(4), [sp.Matrix([sp.sqrt(2) / 2, sp.sqrt(2) / 2 + sp.Rational(1, 10**3), 0, 0, 0, 0])])


def test_numeric_fast_path_refuses_nan_and_keeps_batches():
    """NaN/inf joint values are refused on the fast path (float array, code generated), singly and in batches."""
    c = robots.planar_offset_3r(1)
    ok = c.jacobian_space(np.array([0.1, 0.2, 0.3]))
    for bad in (
        np.array([0.1, np.nan, 0.3]),
        np.array([np.inf, 0, 0]),
        np.array([[0.1, 0.2, 0.3], [0, -np.inf, 0]]),
        [0.1, float("nan"), 0.3],
        (0.0, 0.0, float("-inf")),
    ):
        with pytest.raises(ValueError, match=r"q must hold 3 finite real joint values, got .* whose entry \[.*\] is"):
            c.jacobian_space(bad)
    # finite values whose float sum overflows still work (they take the checked path)
    big = np.array([1e308, 1e308, -1e308])
    assert np.isfinite(c.fk(big)).all()
    np.testing.assert_allclose(c.jacobian_space([0.1, 0.2, 0.3]), ok)
    np.testing.assert_allclose(c.jacobian_space([[0.1, 0.2, 0.3]] * 2)[1], ok)


_MIXED_SCRIPT = r"""
import json, sympy as sp
from kinlib import velocity_ellipsoid
from kinlib.velocity import force_ellipsoid
t = sp.Symbol("theta1", real=True)
J = [[1.0, 0.5], [0.0, t]]
out = {}
for f in (velocity_ellipsoid, force_ellipsoid):
    try:
        lengths, axes = f(J)
        out[f.__name__] = ["answered", len(lengths), str(axes.shape)]
    except (ValueError, TypeError) as err:
        out[f.__name__] = ["refused", type(err).__name__, str(err)]
print(json.dumps(out))
"""


@pytest.mark.slow
def test_ellipsoids_of_a_mixed_float_symbolic_J_answer_or_refuse_within_a_limit():
    """A float J with one symbolic entry: each ellipsoid answers (2 lengths, 2×2 axes) or refuses clearly
    (ValueError/TypeError naming J), in a subprocess with a generous limit that only guards against a hang."""
    import json
    import subprocess
    import sys

    p = subprocess.run([sys.executable, "-c", _MIXED_SCRIPT], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    for name, res in json.loads(p.stdout).items():
        if res[0] == "answered":
            assert res[1:] == [2, "(2, 2)"], (name, res)
        else:
            assert _named(res[2], "J"), (name, res)
