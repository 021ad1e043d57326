"""Fast numbers from exact expressions: a recording of the chain's recursions (``tape``), straight-line
NumPy and JavaScript generated from them (``codegen``) and the same code compiled to C (``native``).

Imports only ``kinlib._backend``; ``kinlib.kinematics`` (``SerialChain``) and ``kinlib.widgets`` use it.
"""
