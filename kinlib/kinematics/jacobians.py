"""Jacobians of an open chain: space J_s, body J_b and the problem set's geometric J.

Three Jacobians, one twist convention [ω; v] (angular rows first):

* space Jacobian   V_s = J_s(θ) θ̇,  column i = Ad_{e^{[S1]θ1}⋯e^{[S_{i−1}]θ_{i−1}}} S_i;
* body Jacobian    V_b = J_b(θ) θ̇,  column i = Ad_{e^{−[B_n]θ_n}⋯e^{−[B_{i+1}]θ_{i+1}}} B_i;
* geometric Jacobian [ω_s; ṗ] = J(θ) θ̇ with J = blockdiag(R, R) J_b = [[I, 0], [−[p], I]] J_s,
  where T(θ) = [[R, p], [0, 1]]: angular velocity in the space frame, velocity of the
  end-effector origin p in the space frame.

Pinocchio and the Robotics Toolbox put the linear rows first: see :func:`linear_first`.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from .._backend import as_matrix, as_vector, describe, is_symbolic, nested_shape
from .poe import checked_screw_list, fk_space
from .rigid import check_se3, check_so3, cross, rodrigues_coefficients, skew
from .screws import exp6_unchecked

__all__ = [
    "jacobian_space",
    "jacobian_body",
    "geometric_jacobian",
    "space_to_body",
    "body_to_space",
    "body_to_geometric",
    "geometric_to_body",
    "space_to_geometric",
    "geometric_to_space",
    "linear_first",
    "angular_first",
    "position_jacobian",
]


def _ad_apply(T, S, symbolic):
    """Ad_T S = [R ω; p × (R ω) + R v] without forming the 6×6 adjoint."""
    if symbolic:
        R, p = T[:3, :3], T[:3, 3]
        w = R * S[:3, 0]
        return sp.Matrix.vstack(w, cross(p, w) + R * S[3:, 0])
    R, p = T[:3, :3], T[:3, 3]
    w = R @ S[:3]
    return np.concatenate([w, cross(p, w) + R @ S[3:]])


def jacobian_space(Slist, thetas):
    """Space Jacobian J_s(θ) (6×n, rows [ω; v]): V_s = J_s θ̇.

    Column i is Ad_{e^{[S1]θ1}⋯e^{[S_{i−1}]θ_{i−1}}} S_i; the first column is S_1.

    Numbers in (a float array 6×n and n joint values): plain float arithmetic, no SymPy (≈ 30–50 µs for 6
    joints, modern-robotics' JacobianSpace ≈ 250 µs); for many calls on one arm,
    ``SerialChain(M, S).jacobian_space(q)`` runs generated code (a few µs, batches too).

    >>> from kinlib.robots import planar_2r
    >>> r = planar_2r()
    >>> jacobian_space(r.screws, r.thetas).T   # column 1 is S1; column 2 = Ad_{e^{[S1]θ1}} S2 turns with θ1
    Matrix([
    [0, 0, 1,              0,               0, 0],
    [0, 0, 1, L1*sin(theta1), -L1*cos(theta1), 0]])
    """
    fast = _numeric_screws(Slist, thetas)
    if fast is not None:
        return _jacobian_space_floats(*fast)
    S, th, kinds, symbolic = checked_screw_list(Slist, thetas, "Slist")
    n = S.shape[1]
    T = sp.eye(4) if symbolic else np.eye(4)
    cols = []
    for i in range(n):
        Si = S[:, i]
        cols.append(Si if i == 0 else _ad_apply(T, Si, symbolic))
        E = exp6_unchecked(Si, th[i], kinds[i], symbolic)
        T = T * E if symbolic else T @ E
    return sp.Matrix.hstack(*cols) if symbolic else np.column_stack(cols)


_PLAIN = (float, int, np.float64, np.int64)


def _numeric_screws(Slist, thetas):
    """(screws as 6-lists of floats, θ as floats, kinds) for plain numeric input whose every check passes at
    once (a finite float array 6×n or sequence of n 6-vectors of numbers, n finite joint values, unit axes);
    None for anything else, which then takes the checked path (and its error messages)."""
    if is_symbolic(Slist, thetas):
        return None
    try:
        if isinstance(Slist, np.ndarray):
            if Slist.dtype.kind not in "fiu" or Slist.ndim != 2 or Slist.shape[0] != 6:
                return None
            A = Slist.astype(float).T
        elif isinstance(Slist, (list, tuple)) and Slist and all(type(c) in (list, tuple, np.ndarray) for c in Slist):
            if any(c.dtype.kind not in "fiu" for c in Slist if type(c) is np.ndarray) or any(
                type(x) not in _PLAIN for c in Slist if type(c) is not np.ndarray for x in c
            ):
                return None
            A = np.array(Slist, dtype=float)
            if A.ndim != 2 or A.shape[1] != 6:
                return None
        else:
            return None
        if isinstance(thetas, (list, tuple)) and any(type(x) not in _PLAIN for x in thetas):
            return None  # bools, strings, None ... (NumPy would make True a 1.0): the checked path names them
        th = np.asarray(thetas)
        if th.dtype.kind not in "fiu" or th.shape != (A.shape[0],):
            return None
        th = th.astype(float)
    except (TypeError, ValueError):
        return None
    if not (np.isfinite(A).all() and np.isfinite(th).all()):
        return None
    wn = np.sqrt((A[:, :3] ** 2).sum(axis=1))
    vn = np.sqrt((A[:, 3:] ** 2).sum(axis=1))
    rev = np.abs(wn - 1.0) <= 1e-6
    pri = (np.abs(A[:, :3]).max(axis=1) <= 1e-12) & (np.abs(vn - 1.0) <= 1e-6)
    if not (rev | pri).all():
        return None
    return A.tolist(), th.tolist(), ["R" if r else "P" for r in rev]


def _jacobian_space_floats(screws, th, kinds):
    """J_s by the recursion of :func:`jacobian_space` in Python floats: T = (R, p) carried joint by joint."""
    R = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    p = [0.0, 0.0, 0.0]
    cols = []
    for (w0, w1, w2, v0, v1, v2), t, kind in zip(screws, th, kinds):
        a = [r[0] * w0 + r[1] * w1 + r[2] * w2 for r in R]  # R ω
        b = [r[0] * v0 + r[1] * v1 + r[2] * v2 for r in R]  # R v
        cols.append(
            a + [p[1] * a[2] - p[2] * a[1] + b[0], p[2] * a[0] - p[0] * a[2] + b[1], p[0] * a[1] - p[1] * a[0] + b[2]]
        )
        if kind == "P":
            p = [p[k] + b[k] * t for k in range(3)]
            continue
        s, oc, ts = rodrigues_coefficients(t)
        w = (w0, w1, w2)
        # [ω] x = ω × x and [ω]² = ωωᵀ − I for a unit ω
        E = [
            [1.0 + oc * (w0 * w0 - 1.0), -s * w2 + oc * w0 * w1, s * w1 + oc * w0 * w2],
            [s * w2 + oc * w1 * w0, 1.0 + oc * (w1 * w1 - 1.0), -s * w0 + oc * w1 * w2],
            [-s * w1 + oc * w2 * w0, s * w0 + oc * w2 * w1, 1.0 + oc * (w2 * w2 - 1.0)],
        ]
        wv = w0 * v0 + w1 * v1 + w2 * v2
        wxv = (w1 * v2 - w2 * v1, w2 * v0 - w0 * v2, w0 * v1 - w1 * v0)
        e = [t * x + oc * c + ts * (wk * wv - x) for x, c, wk in zip((v0, v1, v2), wxv, w)]
        p = [p[i] + R[i][0] * e[0] + R[i][1] * e[1] + R[i][2] * e[2] for i in range(3)]
        R = [[R[i][0] * E[0][j] + R[i][1] * E[1][j] + R[i][2] * E[2][j] for j in range(3)] for i in range(3)]
    return np.array(cols).T + 0.0


def jacobian_body(Blist, thetas):
    """Body Jacobian J_b(θ) (6×n, rows [ω; v]): V_b = J_b θ̇.

    Column i is Ad_{e^{−[B_n]θ_n}⋯e^{−[B_{i+1}]θ_{i+1}}} B_i; the last column is B_n.

    >>> import sympy as sp
    >>> from kinlib.robots import planar_2r
    >>> from kinlib.rigid import adjoint, trans_inv
    >>> r, q = planar_2r(), [0, sp.pi / 2]
    >>> Jb = jacobian_body(r.body_screws, q)
    >>> Jb.T   # the last column is B2
    Matrix([
    [0, 0, 1, L1, L2, 0],
    [0, 0, 1,  0, L2, 0]])
    >>> Jb == adjoint(trans_inv(fk_space(r.M, r.screws, q))) * jacobian_space(r.screws, q)   # J_b = Ad_{T⁻¹} J_s
    True
    """
    B, th, kinds, symbolic = checked_screw_list(Blist, thetas, "Blist")
    n = B.shape[1]
    T = sp.eye(4) if symbolic else np.eye(4)
    cols = [None] * n
    for i in range(n - 1, -1, -1):
        Bi = B[:, i]
        cols[i] = Bi if i == n - 1 else _ad_apply(T, Bi, symbolic)
        E = exp6_unchecked(-Bi, th[i], kinds[i], symbolic)
        T = T * E if symbolic else T @ E
    return sp.Matrix.hstack(*cols) if symbolic else np.column_stack(cols)


def geometric_jacobian(M, Slist, thetas):
    """The problem set's geometric Jacobian J(θ) (6×n): [ω_s; ṗ] = J θ̇.

    J = blockdiag(R, R) J_b = [[I, 0], [−[p], I]] J_s with T(θ) = e^{[S1]θ1}⋯e^{[Sn]θn} M = [[R, p], [0, 1]]:
    top rows the angular velocity in {s}, bottom rows the velocity of the end-effector origin p in {s}.

    >>> import sympy as sp
    >>> from kinlib.robots import planar_2r
    >>> r = planar_2r()
    >>> J = geometric_jacobian(r.M, r.screws, [0, sp.pi / 2])
    >>> J[[3, 4], :]   # rows ṗ_x, ṗ_y at θ = (0, π/2)
    Matrix([
    [-L2, -L2],
    [ L1,   0]])
    >>> J[[3, 4], :].det()   # L1 L2 sin θ2 at θ2 = π/2
    L1*L2
    """
    T = fk_space(M, Slist, thetas)
    Js = jacobian_space(Slist, thetas)
    return space_to_geometric(Js, T)


def _transform(T, name="T"):
    return check_se3(T, name)


def space_to_body(Js, T):
    """J_b = Ad_{T⁻¹} J_s (T = T(θ), the end-effector pose).

    >>> import numpy as np
    >>> from kinlib.robots import planar_2r
    >>> r, q = planar_2r(1, 1), [0.3, 0.5]
    >>> Js, T = r.jacobian_space(q), r.fk(q)   # floats in, floats out
    >>> np.allclose(space_to_body(Js, T), r.jacobian_body(q))
    True
    """
    symbolic = is_symbolic(Js, T)
    Js, T = as_matrix(Js, "Js", (6, None), symbolic), _transform(as_matrix(T, "T", None, symbolic))
    R, p = T[:3, :3], T[:3, 3]
    if symbolic:
        Rt = R.T
        top = Rt * Js[:3, :]
        return sp.Matrix.vstack(top, Rt * (Js[3:, :] - skew(p) * Js[:3, :]))
    Rt = R.T
    return np.vstack([Rt @ Js[:3], Rt @ (Js[3:] - skew(p) @ Js[:3])])


def body_to_space(Jb, T):
    """J_s = Ad_T J_b.

    >>> import sympy as sp
    >>> from kinlib.robots import planar_2r
    >>> r, q = planar_2r(), [0, sp.pi / 2]
    >>> body_to_space(jacobian_body(r.body_screws, q), fk_space(r.M, r.screws, q)) == jacobian_space(r.screws, q)
    True
    """
    symbolic = is_symbolic(Jb, T)
    Jb, T = as_matrix(Jb, "Jb", (6, None), symbolic), _transform(as_matrix(T, "T", None, symbolic))
    R, p = T[:3, :3], T[:3, 3]
    if symbolic:
        w = R * Jb[:3, :]
        return sp.Matrix.vstack(w, skew(p) * w + R * Jb[3:, :])
    w = R @ Jb[:3]
    return np.vstack([w, skew(p) @ w + R @ Jb[3:]])


def _rotation_of(T, symbolic, name="T"):
    """R from a 4×4 transform T or a 3×3 rotation R."""
    X = as_matrix(T, name, None, symbolic)
    if X.shape == (3, 3):
        return check_so3(X, name)
    if X.shape == (4, 4):
        return check_se3(X, name)[:3, :3]
    raise ValueError(f"{name} must be a 4×4 transform T(θ) or its 3×3 rotation R, got {describe(T)}")


def body_to_geometric(Jb, T):
    """Geometric J = blockdiag(R, R) J_b, with R the rotation of T(θ) (T or R may be given).

    >>> import sympy as sp
    >>> from kinlib.robots import planar_2r
    >>> r, q = planar_2r(), [0, sp.pi / 2]
    >>> T = fk_space(r.M, r.screws, q)
    >>> J = body_to_geometric(jacobian_body(r.body_screws, q), T[:3, :3])   # R alone is enough
    >>> J == geometric_jacobian(r.M, r.screws, q), J[[3, 4], :]
    (True, Matrix([
    [-L2, -L2],
    [ L1,   0]]))
    """
    symbolic = is_symbolic(Jb, T)
    Jb = as_matrix(Jb, "Jb", (6, None), symbolic)
    R = _rotation_of(T, symbolic)
    if symbolic:
        return sp.Matrix.vstack(R * Jb[:3, :], R * Jb[3:, :])
    return np.vstack([R @ Jb[:3], R @ Jb[3:]])


def geometric_to_body(J, T):
    """J_b = blockdiag(Rᵀ, Rᵀ) J (the inverse of :func:`body_to_geometric`).

    >>> import sympy as sp
    >>> from kinlib.robots import planar_2r
    >>> r, q = planar_2r(), [0, sp.pi / 2]
    >>> T = fk_space(r.M, r.screws, q)
    >>> geometric_to_body(geometric_jacobian(r.M, r.screws, q), T) == jacobian_body(r.body_screws, q)
    True
    """
    symbolic = is_symbolic(J, T)
    J = as_matrix(J, "J", (6, None), symbolic)
    R = _rotation_of(T, symbolic)
    if symbolic:
        return sp.Matrix.vstack(R.T * J[:3, :], R.T * J[3:, :])
    return np.vstack([R.T @ J[:3], R.T @ J[3:]])


def space_to_geometric(Js, T):
    """Geometric J = [[I, 0], [−[p], I]] J_s: ṗ = v_s + ω_s × p.

    >>> import sympy as sp
    >>> from kinlib.robots import planar_2r
    >>> r, q = planar_2r(), [0, sp.pi / 2]
    >>> Js, T = jacobian_space(r.screws, q), fk_space(r.M, r.screws, q)
    >>> T[:3, 3].T, Js[[2, 3, 4], :]   # p; rows ω_z, v_x, v_y of J_s
    (Matrix([[L1, L2, 0]]), Matrix([
    [1,   1],
    [0,   0],
    [0, -L1]]))
    >>> space_to_geometric(Js, T)[[3, 4], :]   # ṗ = v_s + ω_s × p
    Matrix([
    [-L2, -L2],
    [ L1,   0]])
    """
    symbolic = is_symbolic(Js, T)
    Js, T = as_matrix(Js, "Js", (6, None), symbolic), _transform(as_matrix(T, "T", None, symbolic))
    p = T[:3, 3]
    if symbolic:
        return sp.Matrix.vstack(Js[:3, :], Js[3:, :] - skew(p) * Js[:3, :])
    return np.vstack([Js[:3], Js[3:] - skew(p) @ Js[:3]])


def geometric_to_space(J, T):
    """J_s = [[I, 0], [[p], I]] J (the inverse of :func:`space_to_geometric`).

    >>> import numpy as np
    >>> from kinlib.robots import planar_2r
    >>> r, q = planar_2r(1, 1), [0.3, 0.5]
    >>> J, T = r.jacobian_geometric(q), r.fk(q)
    >>> np.allclose(geometric_to_space(J, T), r.jacobian_space(q))
    True
    """
    symbolic = is_symbolic(J, T)
    J, T = as_matrix(J, "J", (6, None), symbolic), _transform(as_matrix(T, "T", None, symbolic))
    p = T[:3, 3]
    if symbolic:
        return sp.Matrix.vstack(J[:3, :], J[3:, :] + skew(p) * J[:3, :])
    return np.vstack([J[:3], J[3:] + skew(p) @ J[:3]])


def linear_first(J):
    """Rows [ω; v] → [v; ω] (the order of Pinocchio and the Robotics Toolbox); a twist or a 6×n Jacobian.

    >>> linear_first([1, 2, 3, 4, 5, 6]).tolist()   # V = [ω; v] → [v; ω]
    [4.0, 5.0, 6.0, 1.0, 2.0, 3.0]
    >>> from kinlib.robots import planar_2r
    >>> linear_first(planar_2r().jacobian_space())[:, 1].T
    Matrix([[L1*sin(theta1), -L1*cos(theta1), 0, 0, 0, 1]])
    """
    symbolic = is_symbolic(J)
    if isinstance(J, (str, bytes)) or J is None:
        raise TypeError(f"J must be a twist (6 entries) or a 6×n Jacobian, got {describe(J)}")
    if len(nested_shape(J, "J")) == 2:  # a ragged list is refused here, naming J
        X = as_matrix(J, "J", (6, None), symbolic)
    else:
        X = as_vector(J, "J", 6, symbolic)
        if symbolic:
            X = sp.Matrix(X)
    if symbolic:
        return sp.Matrix.vstack(X[3:, :], X[:3, :])
    return np.concatenate([X[3:], X[:3]])


def angular_first(J):
    """Rows [v; ω] → [ω; v] (from Pinocchio/Robotics Toolbox order back to the textbook's).

    >>> angular_first([4, 5, 6, 1, 2, 3]).tolist()   # [v; ω] → [ω; v]
    [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
    >>> from kinlib.robots import planar_2r
    >>> Js = planar_2r().jacobian_space()
    >>> angular_first(linear_first(Js)) == Js
    True
    """
    return linear_first(J)  # swapping the two 3-row blocks is its own inverse


def position_jacobian(p, thetas):
    """∂p/∂θ for a position map p(θ) written by hand (SymPy expressions): ṗ = (∂p/∂θ) θ̇.

    Problem 1.1's cart-pole: p = [θ1 + L cos θ2, h + L sin θ2] gives [[1, −L sin θ2], [0, L cos θ2]].

    >>> import sympy as sp
    >>> th1, th2 = sp.symbols("theta1 theta2", real=True)
    >>> L, h = sp.symbols("L h", positive=True)
    >>> position_jacobian([th1 + L * sp.cos(th2), h + L * sp.sin(th2)], [th1, th2])
    Matrix([
    [1, -L*sin(theta2)],
    [0,  L*cos(theta2)]])
    """
    if isinstance(p, sp.MatrixBase):
        exprs = list(p)
    elif isinstance(p, (list, tuple)):
        exprs = list(p)
    else:
        raise TypeError(f"p must be a sequence or column of SymPy expressions (the position map), got {describe(p)}")
    if not exprs:
        raise ValueError("p must hold at least one coordinate, got an empty sequence")
    for i, e in enumerate(exprs):
        if isinstance(e, (str, bytes, bool, np.bool_)) or not isinstance(
            e, (sp.Expr, int, float, np.integer, np.floating)
        ):
            raise TypeError(f"p[{i}] must be a SymPy expression in the joint symbols, got {describe(e)}")
    exprs = [as_vector([e], f"p[{i}]", 1, True)[0] for i, e in enumerate(exprs)]  # exact, real and finite
    if isinstance(thetas, sp.Symbol):
        thetas = [thetas]
    if not isinstance(thetas, (list, tuple, sp.MatrixBase)):
        raise TypeError(f"thetas must be a sequence of SymPy symbols (the joint variables), got {describe(thetas)}")
    ths = list(thetas)
    if not ths:
        raise ValueError("thetas must hold at least one joint symbol, got an empty sequence")
    for i, t in enumerate(ths):
        if not isinstance(t, sp.Symbol):
            raise TypeError(f"thetas[{i}] must be a SymPy Symbol (a joint variable), got {describe(t)}")
        if t.is_real is not True:
            raise ValueError(
                f"thetas[{i}] must be a real symbol (sp.Symbol({str(t)!r}, real=True)), got the symbol "
                f"{t} with no real assumption"
            )
    if len(set(ths)) != len(ths):
        raise ValueError(f"thetas must hold distinct symbols, got {', '.join(map(str, ths))}")
    return sp.Matrix(exprs).jacobian(ths)
