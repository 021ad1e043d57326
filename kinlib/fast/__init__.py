"""Fast numbers from exact expressions: a recording of the chain's recursions (``tape``), straight-line
NumPy and JavaScript generated from them (``codegen``) and the same code compiled to C (``native``).

Builds on ``kinlib._backend`` only; ``kinlib.kinematics`` (``SerialChain``) and ``kinlib.widgets`` use it.
"""
