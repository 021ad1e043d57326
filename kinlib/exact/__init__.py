"""The exact engine: decisions that are proofs, or numbers flagged as numbers.

The field of a configuration's sines and cosines and its zero test (``field``), polynomials in sines and
cosines (``trigpoly``) and their signs (``trigsign``), how a rank is decided (``rank``), exact linear algebra
at a configuration (``linalg``: ``rank_at``, ``column_space``, ``left_null_space``, ``evaluate_at``), the
60-digit fallback (``fallback``), simplification for display (``display``) and time budgets that never touch
the process they limit (``budget``).

Builds on ``kinlib._backend`` only; ``kinlib.kinematics`` and ``kinlib.analysis`` build on it. This package
re-exports ``linalg``'s names: ``kinlib.exact`` was that module before the core was laid out by job (issue 32).

>>> from kinlib.exact import rank_at
>>> rank_at([[1, 2], [2, 4]])
1
"""

from .linalg import *  # noqa: F403  (kinlib.exact's names before the layout by job)
from .linalg import __all__  # noqa: F401
