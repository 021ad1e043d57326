"""What a Jacobian says about a robot: task rows (``taskspace``), singular configurations in closed form
(``singularities``) and by numerical search (``singular_search``), manipulability and the one "near a
singularity" rule (``manipulability``, ``nearsingular``), velocity kinematics and statics (``velocity``).

Builds on ``kinlib.kinematics`` and the exact engine (``kinlib.exact``); the pictures (``kinlib.plotting``,
``kinlib.widgets``) and the course (``kinlib.course``) build on it.
"""
