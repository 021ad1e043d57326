"""kinlib: product-of-exponentials kinematics and Jacobians for teaching, exact (SymPy) and fast (NumPy).

Twists and screw axes are [ω; v] (angular first), as in Lynch & Park, *Modern Robotics*.
A SymPy argument gives an exact SymPy Matrix; plain numbers give NumPy float arrays.

Jacobians: ``jacobian_space`` (V_s = J_s θ̇), ``jacobian_body`` (V_b = J_b θ̇) and
``geometric_jacobian`` ([ω_s; ṗ] = J θ̇, J = blockdiag(R, R) J_b), the problem set's "geometric Jacobian".
Plotting and widgets live in ``kinlib.plotting`` and ``kinlib.widgets`` (imported on demand).
"""
from .rigid import adjoint, check_se3, check_so3, exp3, rp_to_trans, skew, trans_inv, trans_to_rp, unskew
from .screws import bracket, exp6, screw_axis, screw_prismatic, screw_revolute, unbracket
from .jacobians import (
    angular_first, body_to_geometric, body_to_space, geometric_jacobian, geometric_to_body,
    geometric_to_space, jacobian_body, jacobian_space, linear_first, position_jacobian,
    space_to_body, space_to_geometric,
)
from .chains import SerialChain, fk_body, fk_space
from .singularities import (
    IncompleteResultWarning, SingularSet, column_space, evaluate_at, left_null_space, rank_at,
    singular_configurations, task_rows,
)
from .exact import ConditionalResultWarning, NumericFallbackWarning, Rank
from .singular_search import SingularPoints, find_singularities
from .rigid import log3
from .screws import log6
from .velocity import (
    PinvReport, SingularityWarning, damped_least_squares, force_ellipsoid, inverse_velocity, joint_torques,
    pseudoinverse,
)
from .manipulability import (
    condition_number, isotropy, manipulability, twist_speed_form, velocity_ellipsoid,
)
from .display import is_identically_zero, simplify_for_display
from . import robots

__version__ = "0.1.0"

__all__ = [
    "skew", "unskew", "exp3", "rp_to_trans", "trans_to_rp", "trans_inv", "adjoint", "check_so3", "check_se3",
    "screw_revolute", "screw_prismatic", "screw_axis", "bracket", "unbracket", "exp6",
    "fk_space", "fk_body", "SerialChain",
    "jacobian_space", "jacobian_body", "geometric_jacobian", "space_to_body", "body_to_space",
    "body_to_geometric", "geometric_to_body", "space_to_geometric", "geometric_to_space",
    "linear_first", "angular_first", "position_jacobian", "robots",
    "task_rows", "singular_configurations", "SingularSet", "IncompleteResultWarning", "find_singularities",
    "SingularPoints", "rank_at", "column_space", "left_null_space", "evaluate_at", "Rank", "NumericFallbackWarning",
    "ConditionalResultWarning", "log3", "log6", "pseudoinverse", "inverse_velocity", "damped_least_squares",
    "joint_torques", "force_ellipsoid", "PinvReport", "SingularityWarning",
    "manipulability", "condition_number", "isotropy", "velocity_ellipsoid", "twist_speed_form",
    "simplify_for_display", "is_identically_zero",
]
