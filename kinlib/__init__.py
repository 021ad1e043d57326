"""kinlib: product-of-exponentials kinematics and Jacobians for teaching, exact (SymPy) and fast (NumPy).

Twists and screw axes are [ω; v] (angular first), as in Lynch & Park, *Modern Robotics*.
A SymPy argument gives an exact SymPy Matrix; plain numbers give NumPy float arrays.

Jacobians: ``jacobian_space`` (V_s = J_s θ̇), ``jacobian_body`` (V_b = J_b θ̇) and
``geometric_jacobian`` ([ω_s; ṗ] = J θ̇, J = blockdiag(R, R) J_b), the problem set's "geometric Jacobian".
Yoshikawa's measure is ``kinlib.manipulability.manipulability`` (``kinlib.manipulability`` is the module of
all the measures). Plotting and widgets live in ``kinlib.plotting`` and ``kinlib.widgets``, the course tooling
(handouts, self-checks, grading) in ``kinlib.course``; ``import kinlib`` loads none of them.

>>> import kinlib
>>> J = kinlib.robots.planar_2r(1, 1).jacobian_geometric([0, 0])   # [ω_s; ṗ], 6×2
>>> J[4].tolist()                                                      # ṗ_y = 2 θ̇1 + θ̇2
[2.0, 1.0]
"""

import importlib
import sys

from .analysis import manipulability, taskspace
from .analysis.manipulability import condition_number, isotropy, twist_speed_form, velocity_ellipsoid
from .analysis.singularities import (
    IncompleteResultWarning,
    SingularPoints,
    SingularSet,
    column_space,
    evaluate_at,
    find_singularities,
    left_null_space,
    rank_at,
    singular_configurations,
    task_rows,
)
from .analysis.velocity import (
    PinvReport,
    SingularityWarning,
    damped_least_squares,
    force_ellipsoid,
    inverse_velocity,
    joint_torques,
    pseudoinverse,
)
from .exact.display import is_identically_zero, simplify_for_display
from .exact.linalg import ConditionalResultWarning, NumericFallbackWarning, Rank
from .kinematics import robots
from .kinematics.chains import SerialChain, fk_body, fk_space
from .kinematics.jacobians import (
    angular_first,
    body_to_geometric,
    body_to_space,
    geometric_jacobian,
    geometric_to_body,
    geometric_to_space,
    jacobian_body,
    jacobian_space,
    linear_first,
    position_jacobian,
    space_to_body,
    space_to_geometric,
)
from .kinematics.rigid import (
    adjoint,
    check_se3,
    check_so3,
    exp3,
    log3,
    rp_to_trans,
    skew,
    trans_inv,
    trans_to_rp,
    unskew,
)
from .kinematics.screws import bracket, exp6, log6, screw_axis, screw_prismatic, screw_revolute, unbracket

#: Where each module of the flat layout (before issue 32 laid the core out by job) lives now. The old paths
#: stay importable and are the same module objects (``kinlib.poe is kinlib.kinematics.poe``), so
#: ``import kinlib.poe``, ``from kinlib.native import ...`` and monkeypatching through either name work.
#: ``kinlib.exact`` is now the engine's package; it re-exports what the module ``kinlib.exact`` exported.
MOVED = {
    "rigid": "kinematics.rigid",
    "screws": "kinematics.screws",
    "poe": "kinematics.poe",
    "jacobians": "kinematics.jacobians",
    "chains": "kinematics.chains",
    "robots": "kinematics.robots",
    "taskspace": "analysis.taskspace",
    "singularities": "analysis.singularities",
    "singular_search": "analysis.singularities",
    "nearsingular": "analysis.manipulability",
    "manipulability": "analysis.manipulability",
    "velocity": "analysis.velocity",
    "exact_rank": "exact.rank",
    "exactfield": "exact.field",
    "trigpoly": "exact.trigpoly",
    "trigsign": "exact.trigsign",
    "fallback": "exact.fallback",
    "display": "exact.display",
    "budget": "exact.budget",
    "tape": "fast.tape",
    "codegen": "fast.codegen",
    "native": "fast.native",
}


def _alias_old_paths() -> None:
    for old, new in MOVED.items():
        module = importlib.import_module(f"{__name__}.{new}")
        sys.modules.setdefault(f"{__name__}.{old}", module)
        globals().setdefault(old, module)


_alias_old_paths()

__version__ = "0.1.0"

# grouped as in the textbook
# fmt: off
__all__ = [
    # rigid motions, screws and the product of exponentials (Modern Robotics, chapters 3-4)
    "skew", "unskew", "exp3", "log3", "rp_to_trans", "trans_to_rp", "trans_inv", "adjoint", "check_so3", "check_se3",
    "screw_revolute", "screw_prismatic", "screw_axis", "bracket", "unbracket", "exp6", "log6",
    "fk_space", "fk_body", "SerialChain", "robots",
    # Jacobians (chapter 5): space, body and the problem set's geometric J = blockdiag(R, R) J_b
    "jacobian_space", "jacobian_body", "geometric_jacobian", "space_to_body", "body_to_space", "body_to_geometric",
    "geometric_to_body", "space_to_geometric", "geometric_to_space", "linear_first", "angular_first",
    "position_jacobian",
    # task spaces, singularities, exact answers at a configuration
    "taskspace", "task_rows", "singular_configurations", "SingularSet", "IncompleteResultWarning",
    "find_singularities", "SingularPoints", "rank_at", "column_space", "left_null_space", "evaluate_at", "Rank",
    "NumericFallbackWarning", "ConditionalResultWarning",
    # manipulability and velocity kinematics, statics
    "manipulability", "condition_number", "isotropy", "velocity_ellipsoid", "twist_speed_form",
    "pseudoinverse", "inverse_velocity", "damped_least_squares", "joint_torques", "force_ellipsoid", "PinvReport",
    "SingularityWarning",
    # exact display
    "simplify_for_display", "is_identically_zero",
]
# fmt: on
