"""Bad input: a ValueError or TypeError whose message names the argument, what was expected and what was given."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import kinlib
from kinlib import robots
from kinlib.manipulability import manipulability

Z = [0, 0, 1, 0, 0, 0]
S2 = np.array([Z, [0, 0, 1, 0, -1, 0]], dtype=float).T  # 6×2, two revolute joints
BAD_R = np.diag([2.0, 1.0, 1.0, 1.0])  # not a rotation
BAD_ROW = np.eye(4)
BAD_ROW[3] = [1, 0, 0, 1]
x = sp.Symbol("x", real=True)

PLANAR = robots.planar_offset_3r()
PLANAR1 = robots.planar_offset_3r(1)
PLANAR1.fk(np.zeros(3))  # code generated: the fast path is what is checked below

CASES = [
    # --- wrong shapes ---------------------------------------------------------------------
    (
        "exp6 S of length 5",
        lambda: kinlib.exp6([0, 0, 1, 0, 0], 1.0),
        ValueError,
        r"S must be a vector of length 6, got a list of shape \(5,\)",
    ),
    (
        "skew of a 2-vector",
        lambda: kinlib.skew([1, 2]),
        ValueError,
        r"w must be a vector of length 3, got a list of shape \(2,\)",
    ),
    (
        "Slist 5×2",
        lambda: kinlib.jacobian_space(np.zeros((5, 2)), [1, 2]),
        ValueError,
        r"Slist must be a 6×n matrix .* got an array of shape \(5, 2\)",
    ),
    (
        "Blist with a 5-vector",
        lambda: kinlib.jacobian_body([Z, [0, 0, 1, 0, 0]], [1, 2]),
        ValueError,
        r"Blist\[1\] must be a vector of length 6, got a list of shape \(5,\)",
    ),
    (
        "M 3×3 in fk_space",
        lambda: kinlib.fk_space(np.eye(3), S2, [1, 2]),
        ValueError,
        r"M must be a 4×4 homogeneous transform in SE\(3\), got an array of shape \(3, 3\)",
    ),
    (
        "M 3×3 in fk_body",
        lambda: kinlib.fk_body(np.eye(3), S2, [1, 2]),
        ValueError,
        r"M must be a 4×4 .* shape \(3, 3\)",
    ),
    (
        "Js 5 rows",
        lambda: kinlib.space_to_body(np.zeros((5, 2)), np.eye(4)),
        ValueError,
        r"Js must be a matrix of shape \(6, n\), got an array of shape \(5, 2\)",
    ),
    (
        "Jb 3 rows",
        lambda: kinlib.body_to_geometric(np.zeros((3, 2)), np.eye(4)),
        ValueError,
        r"Jb must be a matrix of shape \(6, n\), got an array of shape \(3, 2\)",
    ),
    (
        "T 5×5 in body_to_geometric",
        lambda: kinlib.body_to_geometric(np.zeros((6, 2)), np.eye(5)),
        ValueError,
        r"T must be a 4×4 transform .* or its 3×3 rotation R, got an array of shape \(5, 5\)",
    ),
    (
        "linear_first of 5 rows",
        lambda: kinlib.linear_first(np.zeros((5, 2))),
        ValueError,
        r"J must be a matrix of shape \(6, n\), got an array of shape \(5, 2\)",
    ),
    (
        "rp_to_trans p of length 2",
        lambda: kinlib.rp_to_trans(np.eye(3), [1, 2]),
        ValueError,
        r"p must be a vector of length 3, got a list of shape \(2,\)",
    ),
    (
        "Slist a number",
        lambda: kinlib.jacobian_space(3.0, [1]),
        TypeError,
        r"Slist must be a 6×n matrix .* got float 3.0",
    ),
    ("M None", lambda: kinlib.fk_space(None, S2, [1, 2]), TypeError, r"M must be a matrix .* got NoneType None"),
    # --- a revolute ω (or a prismatic v) that is not a unit vector ---------------------------
    (
        "screw_revolute ω = (1, 1, 0)",
        lambda: kinlib.screw_revolute([1, 1, 0], [0, 0, 0]),
        ValueError,
        r"omega must be a unit vector \(\|ω\| = 1\), got \[1\.0, 1\.0, 0\.0\] with \|ω\| = 1\.41421",
    ),
    (
        "screw_revolute symbolic ω",
        lambda: kinlib.screw_revolute(sp.Matrix([1, 1, 0]), [0, 0, x]),
        ValueError,
        r"omega must be a unit vector \(\|ω\| = 1\), got \[1, 1, 0\] with \|ω\|² = 2",
    ),
    (
        "exp6 ω = (0, 0, 2)",
        lambda: kinlib.exp6([0, 0, 2, 0, 0, 0], 1.0),
        ValueError,
        r"angular part ω of S must be a unit vector .* got \[0\.0, 0\.0, 2\.0\] with \|ω\| = 2",
    ),
    ("exp3 ω = (0, 0, 2)", lambda: kinlib.exp3([0, 0, 2], 1.0), ValueError, r"omega must be a unit vector .*\|ω\| = 2"),
    (
        "jacobian_space, column 2 not a unit ω",
        lambda: kinlib.jacobian_space([Z, [0, 0.5, 0, 0, 0, 0]], [1, 2]),
        ValueError,
        r"angular part ω of Slist column 2 must be a unit vector .* got \[0\.0, 0\.5, 0\.0\]",
    ),
    (
        "prismatic v = (0, 0, 2)",
        lambda: kinlib.exp6([0, 0, 0, 0, 0, 2], 1.0),
        ValueError,
        r"linear part v of S \(a prismatic axis, ω = 0\) must be a unit vector .* got \[0\.0, 0\.0, 2\.0\]",
    ),
    (
        "screw_prismatic v = 0",
        lambda: kinlib.screw_prismatic([0, 0, 0]),
        ValueError,
        r"v must be a unit vector .*\|ω\| = 0",
    ),
    (
        "SerialChain non-unit axis",
        lambda: kinlib.SerialChain(np.eye(4), [[0, 0, 3, 0, 0, 0]]),
        ValueError,
        r"angular part ω of screws column 1 must be a unit vector .* \|ω\|² = 9",
    ),
    # --- thetas of the wrong length, strings ---------------------------------------------------
    (
        "thetas too short",
        lambda: kinlib.jacobian_space(S2, [1.0]),
        ValueError,
        r"thetas must be a vector of length 2, got a list of shape \(1,\)",
    ),
    (
        "thetas too long",
        lambda: kinlib.fk_space(np.eye(4), S2, [1, 2, 3]),
        ValueError,
        r"thetas must be a vector of length 2, got a list of shape \(3,\)",
    ),
    (
        "thetas too long (symbolic)",
        lambda: kinlib.jacobian_body(S2, [x, x, x]),
        ValueError,
        r"thetas must be a vector of length 2, got a list of shape \(3,\)",
    ),
    (
        "thetas strings",
        lambda: kinlib.jacobian_space(S2, ["a", "b"]),
        TypeError,
        r"thetas must hold numbers or SymPy expressions, got the string 'a'",
    ),
    (
        "thetas a string",
        lambda: kinlib.fk_space(np.eye(4), S2, "ab"),
        TypeError,
        r"thetas must be a vector of length 2, got the string 'ab'",
    ),
    (
        "thetas bools",
        lambda: kinlib.jacobian_space(S2, [True, False]),
        TypeError,
        r"thetas must hold .* got the bool True",
    ),
    (
        "theta a string",
        lambda: kinlib.exp6(Z, "1.0"),
        TypeError,
        r"theta must be a number or a SymPy expression, got the string '1.0'",
    ),
    (
        "theta None",
        lambda: kinlib.exp6(Z, None),
        TypeError,
        r"theta must be a number or a SymPy expression, got NoneType",
    ),
    # --- not in SE(3) / SO(3) ------------------------------------------------------------------
    (
        "trans_inv of a non-rotation",
        lambda: kinlib.trans_inv(BAD_R),
        ValueError,
        r"rotation part of T must be a rotation matrix in SO\(3\) \(RᵀR = I, det R = 1\), got an array of shape \(3, 3\)",
    ),
    (
        "trans_inv, last row",
        lambda: kinlib.trans_inv(BAD_ROW),
        ValueError,
        r"T must be a homogeneous transform in SE\(3\) with last row \[0, 0, 0, 1\], got last row \[1\.0, 0\.0, 0\.0, 1\.0\]",
    ),
    (
        "fk_space M not in SE(3)",
        lambda: kinlib.fk_space(BAD_R, S2, [1, 2]),
        ValueError,
        r"rotation part of M must be a rotation matrix in SO\(3\)",
    ),
    (
        "space_to_body T not in SE(3)",
        lambda: kinlib.space_to_body(np.zeros((6, 2)), BAD_R),
        ValueError,
        r"rotation part of T must be a rotation matrix in SO\(3\)",
    ),
    ("reflection", lambda: kinlib.adjoint(np.diag([1.0, 1.0, -1.0, 1.0])), ValueError, r"det R = -1"),
    (
        "symbolic non-rotation",
        lambda: kinlib.trans_inv(sp.diag(x, 1, 1, 1)),
        ValueError,
        r"rotation part of T must be a rotation matrix in SO\(3\)",
    ),
    (
        "SerialChain M not in SE(3)",
        lambda: kinlib.SerialChain(BAD_R, [Z]),
        ValueError,
        r"rotation part of M must be a rotation matrix in SO\(3\)",
    ),
    (
        "unskew of a symmetric matrix",
        lambda: kinlib.unskew(np.eye(3)),
        ValueError,
        r"W must be skew-symmetric \(W = -Wᵀ\), got",
    ),
    # --- an adjoint of a 3×3 -------------------------------------------------------------------
    (
        "adjoint of a 3×3",
        lambda: kinlib.adjoint(np.eye(3)),
        ValueError,
        r"T must be a 4×4 homogeneous transform in SE\(3\), got an array of shape \(3, 3\)",
    ),
    (
        "adjoint of a symbolic 3×3",
        lambda: kinlib.adjoint(sp.eye(3)),
        ValueError,
        r"T must be a 4×4 homogeneous transform in SE\(3\), got a SymPy Matrix of shape \(3, 3\)",
    ),
    ("adjoint of a string", lambda: kinlib.adjoint("T"), TypeError, r"T must be a matrix .* got the string 'T'"),
    # --- position_jacobian -----------------------------------------------------------------------
    (
        "position_jacobian p a string",
        lambda: kinlib.position_jacobian("x**2", [x]),
        TypeError,
        r"p must be a sequence or column of SymPy expressions .* got the string 'x\*\*2'",
    ),
    (
        "position_jacobian numeric thetas",
        lambda: kinlib.position_jacobian([x], [1.0]),
        TypeError,
        r"thetas\[0\] must be a SymPy Symbol \(a joint variable\), got float 1.0",
    ),
    # --- SerialChain -----------------------------------------------------------------------------
    (
        "chain with free parameters, numeric q",
        lambda: PLANAR.jacobian_space([0.1, 0.2, 0.3]),
        ValueError,
        r"planar_offset_3r has symbolic parameters L: give them numbers first, e\.g\. chain\.subs\(L=1\)",
    ),
    (
        "chain q of length 2",
        lambda: PLANAR1.jacobian_space([0.1, 0.2]),
        ValueError,
        r"q must have shape \(3,\) or \(N, 3\) for this 3-joint chain, got a list of shape \(2,\)",
    ),
    (
        "chain batch of width 2",
        lambda: PLANAR1.fk(np.zeros((4, 2))),
        ValueError,
        r"q must have shape \(3,\) or \(N, 3\) .* got an array of shape \(4, 2\)",
    ),
    (
        "chain 3-D batch",
        lambda: PLANAR1.jacobian_geometric(np.zeros((2, 3, 1))),
        ValueError,
        r"q must have shape \(3,\) or \(N, 3\) .* got an array of shape \(2, 3, 1\)",
    ),
    (
        "chain q strings",
        lambda: PLANAR1.jacobian_body(["a", "b", "c"]),
        TypeError,
        r"q must hold 3 real joint values \(or an \(N, 3\) batch\), got a list of shape \(3,\)",
    ),
    (
        "chain symbolic q of length 2",
        lambda: PLANAR.fk([sp.pi, 0]),
        ValueError,
        r"q must hold 3 joint values for planar_offset_3r, got a list of shape \(2,\)",
    ),
    (
        "chain symbolic q with a string",
        lambda: PLANAR.fk([sp.pi, 0, "t"]),
        TypeError,
        r"q must hold numbers or SymPy expressions, got the string 't'",
    ),
    (
        "chain screws 5×1",
        lambda: kinlib.SerialChain(np.eye(4), np.zeros((5, 1))),
        ValueError,
        r"screws must be a 6×n matrix .* got an array of shape \(5, 1\)",
    ),
    (
        "chain thetas count",
        lambda: kinlib.SerialChain(np.eye(4), [Z], thetas=sp.symbols("a b")),
        ValueError,
        r"thetas must be 1 SymPy symbols \(one per screw axis\), got a list",
    ),
    # --- issue 11: values that used to pass silently or crash inside NumPy/SymPy ---------------------
    (
        "complex joint value (numeric)",
        lambda: PLANAR1.fk([0.1 + 1j, 0, 0]),
        TypeError,
        r"q must hold 3 real joint values .* got a list of shape \(3,\) whose entry \[0\] is complex",
    ),
    ("sp.I as a joint value", lambda: PLANAR.fk([sp.I, 0, 0]), ValueError, r"q must be real and finite, got I"),
    (
        "numeric string as a joint value",
        lambda: PLANAR1.fk(["1.5", 0, 0]),
        TypeError,
        r"q must hold 3 real joint values .* whose entry \[0\] is the string '1\.5'",
    ),
    (
        "bool as a joint value",
        lambda: PLANAR1.jacobian_space([True, 0, 0]),
        TypeError,
        r"q must hold 3 real joint values .* whose entry \[0\] is bool True",
    ),
    (
        "NaN joint value, fast path",
        lambda: PLANAR1.fk(np.array([np.nan, 0.0, 0.0])),
        ValueError,
        r"q must hold 3 finite real joint values, got an array of shape \(3,\) .* whose entry \[0\] is nan",
    ),
    (
        "inf joint value (was 'math domain error')",
        lambda: PLANAR1.fk([np.inf, 0.0, 0.0]),
        ValueError,
        r"q must hold 3 finite real joint values, got a list of shape \(3,\) whose entry \[0\] is inf",
    ),
    (
        "NaN in a batch",
        lambda: PLANAR1.jacobian_body(np.array([[0, 0, 0], [0, np.nan, 0]], dtype=float)),
        ValueError,
        r"q must hold 3 finite real joint values, got an array of shape \(2, 3\) .* whose entry \[1, 1\]",
    ),
    (
        "NaN screw in SerialChain",
        lambda: kinlib.SerialChain(np.eye(4), [[0, 0, 1, 0, np.nan, 0]]),
        ValueError,
        r"screws\[0\] must be a finite real number, got nan",
    ),
    (
        "inf in M",
        lambda: kinlib.SerialChain(np.diag([1, 1, 1, np.inf]), [Z]),
        ValueError,
        r"M must be a finite real number, got inf",
    ),
    (
        "sp.oo in a screw",
        lambda: kinlib.SerialChain(np.eye(4), [sp.Matrix([0, 0, 1, sp.oo, 0, 0])]),
        ValueError,
        r"screws\[0\] must be real and finite, got oo",
    ),
    (
        "non-real joint symbol",
        lambda: kinlib.SerialChain(np.eye(4), [Z], thetas=[sp.Symbol("q1")]),
        ValueError,
        r"thetas\[0\] must be a real symbol \(sp\.Symbol\('q1', real=True\)\).* got the symbol q1",
    ),
    (
        "non-real parameter in M",
        lambda: kinlib.SerialChain(
            sp.Matrix(4, 4, lambda i, j: sp.Symbol("a") if (i, j) == (0, 3) else int(i == j)), [Z]
        ),
        ValueError,
        r"M must be real: the symbol a is not declared real \(use sp\.Symbol\('a', real=True\) or positive=True\), got a",
    ),
    (
        "complex thetas",
        lambda: kinlib.jacobian_space(S2, [1 + 2j, 0]),
        TypeError,
        r"thetas must hold real numbers, got the complex number \(1\+2j\)",
    ),
    (
        "sp.I in thetas",
        lambda: kinlib.jacobian_space(S2, [sp.I, 0]),
        ValueError,
        r"thetas must be real and finite, got I",
    ),
    ("theta oo", lambda: kinlib.exp6(Z, sp.oo), ValueError, r"theta must be real and finite, got oo"),
    (
        "theta nan",
        lambda: kinlib.exp3([0, 0, 1], float("nan")),
        ValueError,
        r"theta must be a finite real number, got nan",
    ),
    (
        "theta a NumPy bool",
        lambda: kinlib.exp6(Z, np.True_),
        TypeError,
        r"theta must be a number or a SymPy expression, got bool",
    ),
    (
        "manipulability of 1j·I",
        lambda: manipulability(1j * np.eye(2)),
        TypeError,
        r"J must hold real numbers, got complex numbers \(an array of shape \(2, 2\) and dtype complex128\)",
    ),
    (
        "robot length a numeric string",
        lambda: robots.planar_3r(1, "1.5", 1),
        TypeError,
        r"L2 must be a real number or a SymPy expression, got the string '1\.5'",
    ),
    (
        "subs a complex value",
        lambda: PLANAR.subs(L=1j),
        TypeError,
        r"L must be a real number, got the complex number 1j",
    ),
    ("subs an unknown parameter", lambda: PLANAR.subs(H=1), ValueError, r"planar_offset_3r has no parameter 'H'"),
    (
        "float axis unit only to 3e-9",
        lambda: kinlib.SerialChain(np.eye(4), [[0.70710678, 0.70710678, 0, 0, 0, 0]]),
        ValueError,
        r"angular part ω of screws column 1 must be a unit vector .* got \[35355339/50000000, .*sp\.sqrt\(2\)/2",
    ),
]


@pytest.mark.parametrize("call, exc, pattern", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_input_message(call, exc, pattern):
    with pytest.raises(exc, match=pattern):
        call()


def test_every_message_has_a_got():
    """Each message says what was given (a 'got …' clause)."""
    for label, call, exc, _ in CASES:
        with pytest.raises(exc) as info:
            call()
        msg = str(info.value)
        assert "got" in msg or "give them numbers" in msg or "no parameter" in msg, f"{label}: {msg}"


def test_exact_unit_axes_with_pi_and_constant_condition_numbers():
    """issue 32: an exact unit axis with π in it (1/(1 + π²) is not algebraic) is checked, not a SymPy-internal
    CoercionFailed; a constant exact 3×3 J with sines of numbers gets κ (60-digit, flagged) or ∞ exactly, never the
    advice to give what it already is."""
    import warnings

    from kinlib import condition_number, exp3, screw_revolute
    from kinlib.fallback import NumericFallbackWarning

    n = sp.sqrt(sp.pi**2 + 1)
    axis = [sp.pi / n, 1 / n, 0]
    R = exp3(axis, sp.Rational(1, 2))
    assert sp.simplify(R.T * R - sp.eye(3)) == sp.zeros(3) and sp.simplify(R.det()) == 1
    assert screw_revolute(axis, [1, sp.pi, 0])[:3, 0] == sp.Matrix(axis)
    with pytest.raises(ValueError, match="unit vector"):
        exp3([sp.pi / n, 2 / n, 0], 1)
    r = robots.planar_3r(1, 1, 1)
    q = [sp.Integer(1), sp.Integer(2), sp.Rational(1, 3)]
    J = r.jacobian_geometric(q)[[3, 4, 2], :]  # ṗx, ṗy, ωz: square
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        k = condition_number(J)
    assert any(w.category is NumericFallbackWarning for w in caught)
    assert abs(float(k) - np.linalg.cond(np.array(J.evalf(30), dtype=float))) < 1e-9
    stretched = r.jacobian_geometric([sp.Integer(1), sp.Integer(0), sp.Integer(0)])[[3, 4, 2], :]
    assert condition_number(stretched) == sp.oo  # decided exactly: det(J Jᵀ) = 0
