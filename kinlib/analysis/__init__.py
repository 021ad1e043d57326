"""What a Jacobian says about a robot: task rows (``taskspace``), singular configurations in closed form
and by numerical search (``singularities``), manipulability and the one "near a singularity" rule
(``manipulability``), velocity kinematics and statics (``velocity``).

Builds on ``kinlib.kinematics`` and the exact engine (``kinlib.exact``); the pictures (``kinlib.plotting``,
``kinlib.widgets``) and the course (``kinlib.course``) build on it.
"""
