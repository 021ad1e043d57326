"""Where student code runs, seen from the trusted host: the Jupyter kernel of one submission and the
checker's code sent into it (:mod:`.kernel`), and the bubblewrap sandbox around it (:mod:`.sandbox`).

Importing this package imports nothing (import the modules you need).
"""
