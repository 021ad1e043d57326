"""Kinematics, as the textbook writes it (Modern Robotics ch. 3-5): rigid motions (``rigid``), screws and
twists (``screws``), the product of exponentials (``poe``), the space, body and geometric Jacobians
(``jacobians``), serial chains (``chains``) and the course's robots, URDF joints included (``robots``).

Builds on the exact engine (``kinlib.exact``) and the generated code (``kinlib.fast``); ``kinlib.analysis``
builds on it.
"""
