"""Every robot of the problem set as a :class:`~kinlib.chains.SerialChain`.

Link lengths are arguments: numbers or SymPy symbols, defaulting to positive SymPy symbols of the
same names (so ``planar_offset_3r()`` is the problem set's robot in L, and
``planar_offset_3r(1)`` a numeric one for the fast path). Python floats are turned into exact
rationals (0.425 → 17/40), so symbolic work stays exact.
"""

from __future__ import annotations

import sympy as sp

from .._backend import describe, exact_number
from .chains import SerialChain

__all__ = [
    "cart_pole",
    "planar_offset_3r",
    "spatial_rppr",
    "planar_2r",
    "planar_3r",
    "planar_rpp",
    "ur5",
    "puma560",
    "stanford",
    "length",
    "from_urdf_joints",
]


def length(value, name: str):
    """A link length: a positive symbol named ``name`` when ``value`` is None, else ``value`` made exact.

    Numbers become the exact decimal typed (``kinlib._backend.exact_number``: 0.425 → 17/40, 2.0 → 2);
    SymPy expressions must be real and finite (symbols declared real or positive). Strings, bools,
    complex numbers, NaN and inf are refused.

    >>> length(0.425, "L1"), length(None, "L").is_positive
    (17/40, True)
    """
    if not isinstance(name, str):
        raise TypeError(f"name must be a string, got {describe(name)}")
    if value is None:
        return sp.Symbol(name, positive=True)
    return exact_number(value, name)


def _T(p, R=None):
    R = sp.eye(3) if R is None else sp.Matrix(R)
    return sp.Matrix.vstack(sp.Matrix.hstack(R, sp.Matrix(p)), sp.Matrix([[0, 0, 0, 1]]))


def _cols(*vs):
    return sp.Matrix.hstack(*[sp.Matrix(v) for v in vs])


def cart_pole(L=None, h=None) -> SerialChain:
    """Problem 1.1: a cart sliding along x_s (θ1) carrying a pole of length L hinged at height h (θ2 from x_s).

    End effector: the tip of the pole, p = (θ1 + L cos θ2, h + L sin θ2, 0).

    >>> import sympy as sp
    >>> r = cart_pole()
    >>> r.joint_types, r.params
    ('PR', (L, h))
    >>> r.fk([0, sp.pi / 2])[:3, 3].T   # the pole straight up: p = (θ1 + L cos θ2, h + L sin θ2, 0)
    Matrix([[0, L + h, 0]])
    """
    L, h = length(L, "L"), length(h, "h")
    S = _cols([0, 0, 0, 1, 0, 0], [0, 0, 1, h, 0, 0])
    return SerialChain(
        _T([L, h, 0]),
        S,
        name="cart_pole",
        joint_points=_cols([0, 0, 0], [0, h, 0]),
        description="cart (prismatic along x_s) + pole (revolute about z_s at height h)",
    )


def planar_offset_3r(L=None) -> SerialChain:
    """Sections 2 and 5: three revolute joints about z_s at (0, 0), (L, 0), (2L, L); tool frame at (3L, L).

    >>> import sympy as sp
    >>> r = planar_offset_3r()
    >>> r.M[:3, 3].T, r.screws[:, 2].T
    (Matrix([[3*L, L, 0]]), Matrix([[0, 0, 1, L, -2*L, 0]]))
    >>> r.jacobian_space([0, sp.pi / 2, 0])[[2, 3, 4], :]   # rows ω_z, v_x, v_y
    Matrix([
    [1,  1, 1],
    [0,  0, L],
    [0, -L, 0]])
    """
    L = length(L, "L")
    S = _cols([0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L, 0], [0, 0, 1, L, -2 * L, 0])
    return SerialChain(
        _T([3 * L, L, 0]),
        S,
        name="planar_offset_3r",
        joint_points=_cols([0, 0, 0], [L, 0, 0], [2 * L, L, 0]),
        description="planar RRR with joints at (0,0), (L,0), (2L,L) and the tool at (3L,L)",
    )


def spatial_rppr(L1=None, L2=None) -> SerialChain:
    """Sections 3 and 6: R about z_s, P along z_s, P along x, R about x through (0, 0, L1 + L2); tool at (L2, 0, L1 + L2).

    >>> import sympy as sp
    >>> r = spatial_rppr()
    >>> r.joint_types, r.params
    ('RPPR', (L1, L2))
    >>> r.fk([sp.pi / 2, 1, 0, 0])[:3, 3].T   # turn a quarter about z_s, rise by 1
    Matrix([[0, L2, L1 + L2 + 1]])
    """
    L1, L2 = length(L1, "L1"), length(L2, "L2")
    H = L1 + L2
    S = _cols([0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0, 1], [0, 0, 0, 1, 0, 0], [1, 0, 0, 0, H, 0])
    return SerialChain(
        _T([L2, 0, H]),
        S,
        name="spatial_rppr",
        joint_points=_cols([0, 0, 0], [0, 0, L1], [0, 0, H], [L2, 0, H]),
        description="spatial RPPR: base rotation, vertical slide, horizontal slide, wrist roll",
    )


def planar_2r(L1=None, L2=None) -> SerialChain:
    """The textbook two-link arm: planar RR with links L1, L2 along x_s at home; tool at (L1 + L2, 0).

    Its position Jacobian (rows ṗ_x, ṗ_y) is singular exactly where the arm is stretched out or folded
    (θ2 = 0 or π).

    >>> r = planar_2r(1, 1)
    >>> r.fk([0, 0])[:3, 3].tolist()
    [2.0, 0.0, 0.0]
    """
    L1, L2 = length(L1, "L1"), length(L2, "L2")
    S = _cols([0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L1, 0])
    return SerialChain(
        _T([L1 + L2, 0, 0]),
        S,
        name="planar_2r",
        joint_points=_cols([0, 0, 0], [L1, 0, 0]),
        description="planar RR, links L1, L2",
    )


def planar_3r(L1=None, L2=None, L3=None) -> SerialChain:
    """Section 4: planar RRR with links L1, L2, L3 along x_s at home; tool at (L1 + L2 + L3, 0).

    >>> import sympy as sp
    >>> planar_3r().jacobian_geometric([sp.pi / 2, 0, 0])[[3, 4], :]   # rows ṗ_x, ṗ_y; the arm points along y_s
    Matrix([
    [-L1 - L2 - L3, -L2 - L3, -L3],
    [            0,        0,   0]])
    >>> planar_3r(1, 1, 1).fk([0, sp.pi / 2, 0])[:2, 3].T
    Matrix([[1, 2]])
    """
    L1, L2, L3 = length(L1, "L1"), length(L2, "L2"), length(L3, "L3")
    S = _cols([0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L1, 0], [0, 0, 1, 0, -(L1 + L2), 0])
    return SerialChain(
        _T([L1 + L2 + L3, 0, 0]),
        S,
        name="planar_3r",
        joint_points=_cols([0, 0, 0], [L1, 0, 0], [L1 + L2, 0, 0]),
        description="planar RRR, links L1, L2, L3",
    )


def planar_rpp(L=None) -> SerialChain:
    """Problem 5.5's redesign: R about z_s, then P along x_s and P along y_s (as seen at home); tool offset L along x.

    >>> import sympy as sp
    >>> planar_rpp().fk([sp.pi / 2, 1, 2])[:2, 3].T   # slides (1 + L, 2) turned a quarter about z_s
    Matrix([[-2, L + 1]])
    """
    L = length(L, "L")
    S = _cols([0, 0, 1, 0, 0, 0], [0, 0, 0, 1, 0, 0], [0, 0, 0, 0, 1, 0])
    return SerialChain(
        _T([L, 0, 0]),
        S,
        name="planar_rpp",
        joint_points=_cols([0, 0, 0], [0, 0, 0], [0, 0, 0]),
        description="planar RPP: a base rotation followed by x and y slides",
    )


_UR5 = {"W1": "0.109", "W2": "0.082", "L1": "0.425", "L2": "0.392", "H1": "0.089", "H2": "0.095"}


def ur5(W1=None, W2=None, L1=None, L2=None, H1=None, H2=None) -> SerialChain:
    """The UR5 of Modern Robotics Example 4.5 (6R); defaults are the book's lengths in metres, as exact rationals.

    Pass SymPy symbols (e.g. ``ur5(*sp.symbols('W1 W2 L1 L2 H1 H2', positive=True))``) for the symbolic arm.

    >>> import sympy as sp
    >>> ur5().fk([0, -sp.pi / 2, 0, 0, sp.pi / 2, 0])   # Example 4.5's configuration and T(θ)
    Matrix([
    [0, -1, 0,   19/200],
    [1,  0, 0, 109/1000],
    [0,  0, 1,  247/250],
    [0,  0, 0,        1]])
    """
    given = dict(W1=W1, W2=W2, L1=L1, L2=L2, H1=H1, H2=H2)
    v = {k: (sp.Rational(_UR5[k]) if x is None else length(x, k)) for k, x in given.items()}
    W1, W2, L1, L2, H1, H2 = (v[k] for k in ("W1", "W2", "L1", "L2", "H1", "H2"))
    M = _T([L1 + L2, W1 + W2, H1 - H2], [[-1, 0, 0], [0, 0, 1], [0, 1, 0]])
    S = _cols(
        [0, 0, 1, 0, 0, 0],
        [0, 1, 0, -H1, 0, 0],
        [0, 1, 0, -H1, 0, L1],
        [0, 1, 0, -H1, 0, L1 + L2],
        [0, 0, -1, -W1, L1 + L2, 0],
        [0, 1, 0, H2 - H1, 0, L1 + L2],
    )
    pts = _cols([0, 0, 0], [0, 0, H1], [L1, 0, H1], [L1 + L2, 0, H1], [L1 + L2, W1, H1], [L1 + L2, W1, H1 - H2])
    return SerialChain(M, S, name="ur5", joint_points=pts, description="UR5 (Modern Robotics Example 4.5)")


#: Corke's Puma 560 (Robotics Toolbox, ``mdl_puma560``; Corke and Armstrong-Hélouvry, "A search for consensus
#: among model parameters reported for the PUMA 560 robot", ICRA 1994), standard DH, metres
_PUMA560 = {"a2": "0.4318", "d3": "0.15005", "a3": "0.0203", "d4": "0.4318"}


def puma560(a2=None, d3=None, a3=None, d4=None) -> SerialChain:
    """A PUMA 560 (6R, spherical wrist) from Corke's standard DH table; defaults are its lengths in metres, exact.

    DH rows (d, a, α): (0, 0, π/2), (0, a2, 0), (d3, a3, −π/2), (d4, 0, π/2), (0, 0, −π/2), (0, 0, 0): upper arm
    a2, shoulder offset d3, elbow offset a3, forearm d4 (a2 = d4 = 0.4318 m: upper arm and forearm are equally
    long). At θ = 0 the upper arm lies along x_s, the forearm points up, the tool is at the wrist centre
    (a2 + a3, −d3, d4). The space screw axes come from the DH frames at θ = 0 (joint i turns about z_{i−1}).
    Shoulder singularity: a2 cos θ2 + a3 cos(θ2 + θ3) − d4 sin(θ2 + θ3) = 0 (the wrist centre over the line
    of joint 1's axis in the arm's plane; on that axis when d3 = 0); elbow: a3 sin θ3 + d4 cos θ3 = 0 (the
    wrist centre on the line of the upper arm: the arm stretched out or folded back); wrist: sin θ5 = 0 (the
    factors of det J of the geometric Jacobian, :func:`~kinlib.singularities.singular_configurations`). Pass symbols (``puma560(L, 0, 0, L)``) for a symbolic arm.

    >>> import sympy as sp
    >>> r = puma560()
    >>> r.M[:3, 3].T   # the wrist centre at θ = 0
    Matrix([[4521/10000, -3001/20000, 2159/5000]])
    >>> L = sp.Symbol("L", positive=True)
    >>> r = puma560(L, 0, 0, L)   # equal upper arm and forearm, no offsets
    >>> r.fk([0, sp.pi / 4, sp.pi / 2, 0, 0, 0])[:3, 3].T   # forearm folded back: the wrist centre at the shoulder
    Matrix([[0, 0, 0]])
    """
    given = dict(a2=a2, d3=d3, a3=a3, d4=d4)
    v = {k: (sp.Rational(_PUMA560[k]) if x is None else length(x, k)) for k, x in given.items()}
    a2, d3, a3, d4 = (v[k] for k in ("a2", "d3", "a3", "d4"))
    half = sp.pi / 2
    dh = [(0, 0, half), (0, a2, 0), (d3, a3, -half), (d4, 0, half), (0, 0, -half), (0, 0, 0)]
    T, cols, pts = sp.eye(4), [], []
    for d, a, alpha in dh:  # joint i: about z_{i-1} through o_{i-1}; then A_i(0) = Tz(d) Tx(a) Rx(α)
        z, o = T[:3, 2], T[:3, 3]
        cols.append(list(z) + list(-z.cross(o)))
        pts.append(o)
        ca, sa = sp.cos(alpha), sp.sin(alpha)
        T = T * _T([a, 0, d], [[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    return SerialChain(
        T,
        _cols(*cols),
        name="puma560",
        joint_points=sp.Matrix.hstack(*pts),
        description="PUMA 560 (Corke's standard DH parameters)",
    )


def stanford(H=None, D=None) -> SerialChain:
    """A Stanford-type arm (RRPRRR): a base joint about z_s, a shoulder about x at height ``H``, a slide along
    y_s, and a wrist of three axes (y, x, y) through the shoulder point (0, 0, H), the slide retracted at θ = 0;
    the tool at (0, D, H). Defaults H = 1, D = 1/2, exact: the arm of kinlib's exact-rank tests and benchmark.

    At θ5 = 0 (and π) the axes of joints 4 and 6 line up, and J_s's columns 4 and 6 are equal: a wrist
    singularity.

    >>> import sympy as sp
    >>> r = stanford()
    >>> r.joint_types
    'RRPRRR'
    >>> J = r.jacobian_space([1, 2, sp.Rational(1, 3), 4, 0, 6])   # θ5 = 0
    >>> sp.simplify(J[:, 3] - J[:, 5]).is_zero_matrix
    True
    """
    H = sp.Integer(1) if H is None else length(H, "H")
    D = sp.Rational(1, 2) if D is None else length(D, "D")
    S = _cols(
        [0, 0, 1, 0, 0, 0],
        [1, 0, 0, 0, H, 0],
        [0, 0, 0, 0, 1, 0],
        [0, 1, 0, -H, 0, 0],
        [1, 0, 0, 0, H, 0],
        [0, 1, 0, -H, 0, 0],
    )
    return SerialChain(_T([0, D, H]), S, name="stanford", description="Stanford-type RRPRRR arm")


# --- issue 11, item 6: a student's own arm from URDF joint placements --------------------------------
_URDF_KINDS = {"revolute": "R", "continuous": "R", "prismatic": "P", "fixed": None}
#: largest difference between a typed rpy angle and the angle of its exact rational rotation (radians)
URDF_ANGLE_TOL = sp.Rational(1, 10**18)


def _rational_cos_sin(a: sp.Rational) -> tuple[sp.Rational, sp.Rational]:
    """(cos â, sin â) = ((1 − t²)/(1 + t²), 2t/(1 + t²)) for the rational t of smallest denominator
    (a continued-fraction convergent of tan(a/2), computed with 50 digits) with |â − a| ≤ URDF_ANGLE_TOL
    (modulo 2π): an exact rational point on the unit circle at the typed angle, to 1e-18 rad."""
    from ..exact.field import mp_context

    mpmath = mp_context()  # this thread's own mpmath context: never the global precision

    if a == 0:
        return sp.Integer(1), sp.Integer(0)
    with mpmath.workdps(50):
        am = mpmath.mpf(a.p) / a.q
        x, tol = mpmath.tan(am / 2), mpmath.mpf(URDF_ANGLE_TOL.p) / URDF_ANGLE_TOL.q
        h0, h1, k0, k1 = 0, 1, 1, 0
        for _ in range(200):
            ai = int(mpmath.floor(x))
            h0, h1, k0, k1 = h1, ai * h1 + h0, k1, ai * k1 + k0
            d = 2 * mpmath.atan(mpmath.mpf(h1) / k1) - am
            if abs(d - 2 * mpmath.pi * mpmath.nint(d / (2 * mpmath.pi))) <= tol or x == ai:
                break
            x = 1 / (x - ai)
    t = sp.Rational(h1, k1)
    return (1 - t**2) / (1 + t**2), 2 * t / (1 + t**2)


def _urdf_rotation(rpy, where: str) -> sp.Matrix:
    """R = Rz(yaw) Ry(pitch) Rx(roll), URDF's fixed-axis roll-pitch-yaw, exact (see :func:`from_urdf_joints`)."""
    cs = []
    for v in _urdf_triple(rpy, f"{where} rpy"):
        if v.is_Rational:
            cs.append(_rational_cos_sin(v))
        else:  # a SymPy expression (sp.pi/2, a symbol): exactly its cosine and sine
            cs.append((sp.cos(v), sp.sin(v)))
    (cr, sr), (cp, sp_), (cy, sy) = cs
    Rx = sp.Matrix([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = sp.Matrix([[cp, 0, sp_], [0, 1, 0], [-sp_, 0, cp]])
    Rz = sp.Matrix([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return Rz * Ry * Rx


def _urdf_triple(v, what: str) -> list:
    if isinstance(v, (str, bytes)) or not hasattr(v, "__len__") or len(v) != 3:
        raise ValueError(f"{what} must be 3 numbers, got {describe(v)}")
    return [exact_number(x, f"{what}[{i}]") for i, x in enumerate(v)]


def from_urdf_joints(joints, tool=None, *, name: str = "urdf_chain", description: str = "") -> SerialChain:
    """A :class:`~kinlib.chains.SerialChain` from URDF joint placements, base link to tool.

    ``joints``: a sequence of ``(type, xyz, rpy, axis)`` as in URDF ``<joint>`` elements, in order from
    the base: ``type`` 'revolute' (or 'continuous'), 'prismatic' or 'fixed'; ``xyz``, ``rpy`` the
    ``<origin>`` of the child link frame in the parent's (metres, radians; rpy = roll, pitch, yaw
    about the fixed x, y, z axes); ``axis`` the joint axis in the child frame (ignored for 'fixed';
    any nonzero vector, normalized exactly). ``tool``: ``(xyz, rpy)`` of the end-effector frame in
    the last link's frame (like a final fixed joint), or None.

    With the home placements T_k = T_{k−1} [[R(rpy_k), xyz_k], [0, 1]] (T_0 = I; joint values 0), a
    revolute joint k has the space screw axis S_k = [ω_k; −ω_k × p_k] with ω_k = R_k â_k and p_k the
    origin of T_k, a prismatic one S_k = [0; R_k â_k]; M = T_last · tool (Lynch & Park §4.1.1). The
    joint points (for drawing, ``chain.skeleton``) are the joint frames' origins p_k.

    Exact numbers: xyz and axis entries are the decimals typed (0.0388353 → 388353/10⁷, via
    ``kinlib._backend.exact_number``). The sine and cosine of a typed rpy angle a are irrational, so a is
    represented by an exact *rational* rotation: cos â = (1 − t²)/(1 + t²), sin â = 2t/(1 + t²) with t
    the first continued-fraction convergent of tan(a/2) with |â − a| ≤ 1e-18 rad (``URDF_ANGLE_TOL``),
    far below a float's resolution. So every rotation is exactly orthogonal, every ω exactly a unit
    vector, the whole chain rational (no sin(314159/100000) inside every entry, which would make
    the symbolic work heavy), and its numbers equal the URDF's to rounding. The numbers are long
    (1.5708 is not π/2: nothing is guessed); for exact right angles give SymPy angles (``sp.pi/2``),
    whose cosine and sine are used as they are; SymPy symbols in xyz make a symbolic chain. The chain keeps the
    placements (``SerialChain(placements=...)``): its generated numeric code multiplies the URDF's constant
    placements, folded into floats, and rotations about the axes as typed, like Pinocchio.

    >>> arm = from_urdf_joints([("revolute", (0, 0, 0.1), (0, 0, 0), (0, 0, 1)),
    ...                         ("revolute", (0, 0, 0.2), (sp.pi / 2, 0, 0), (0, 0, 1))],
    ...                        tool=((0, 0, 0.3), (0, 0, 0)), name="two_link")
    >>> arm.screws.T
    Matrix([
    [0,  0, 1,    0, 0, 0],
    [0, -1, 0, 3/10, 0, 0]])
    >>> arm.M
    Matrix([
    [1, 0,  0,     0],
    [0, 0, -1, -3/10],
    [0, 1,  0,  3/10],
    [0, 0,  0,     1]])
    """
    if isinstance(joints, (str, bytes)) or not isinstance(joints, (list, tuple)):
        raise TypeError(f"joints must be a list of (type, xyz, rpy, axis) tuples, got {describe(joints)}")
    R, p = sp.eye(3), sp.zeros(3, 1)
    screws, points = [], []
    C, axes, rel = [], [], sp.eye(4)  # the placements (SerialChain's ``placements``): C_i, â_i
    if tool is not None and (not isinstance(tool, (list, tuple)) or len(tool) != 2):
        raise ValueError(f"tool must be (xyz, rpy) or None, got {describe(tool)}")
    steps = list(enumerate(joints)) + ([(len(joints), ("fixed", tool[0], tool[1], None))] if tool is not None else [])
    for k, joint in steps:
        where = "tool" if k == len(joints) else f"joints[{k}]"
        if not isinstance(joint, (list, tuple)) or len(joint) != 4:
            raise ValueError(f"{where} must be (type, xyz, rpy, axis), got {describe(joint)}")
        kind, xyz, rpy, axis = joint
        if kind not in _URDF_KINDS:
            raise ValueError(f"{where} type must be one of {sorted(_URDF_KINDS)}, got {kind!r}")
        step_p = sp.Matrix(_urdf_triple(xyz, f"{where} xyz"))
        step_R = _urdf_rotation(rpy, where)
        p = p + R * step_p
        R = R * step_R
        rel = rel * sp.Matrix.vstack(sp.Matrix.hstack(step_R, step_p), sp.Matrix([[0, 0, 0, 1]]))
        if _URDF_KINDS[kind] is None:
            continue
        a = sp.Matrix(_urdf_triple(axis, f"{where} axis"))
        n2 = (a.T * a)[0]
        if n2 == 0:
            raise ValueError(f"{where} axis must be a nonzero vector, got {list(a)}")
        a = a if n2 == 1 else a / sp.sqrt(n2)
        w = R * a
        C.append(rel)
        axes.append(a)
        rel = sp.eye(4)
        screws.append(list(w) + list(-w.cross(p)) if _URDF_KINDS[kind] == "R" else [0, 0, 0] + list(w))
        points.append(p)
    if not screws:
        raise ValueError(f"joints must hold at least one revolute or prismatic joint, got {describe(joints)}")
    M = sp.Matrix.vstack(sp.Matrix.hstack(R, p), sp.Matrix([[0, 0, 0, 1]]))
    return SerialChain(
        M,
        sp.Matrix(screws).T,
        name=name,
        joint_points=sp.Matrix.hstack(*points),
        description=description or f"{len(screws)}-joint arm from URDF joint placements",
        placements=(C + [rel], axes),
    )


__all__ += ["from_urdf_joints"]
