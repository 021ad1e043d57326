"""Where student code runs, seen from the trusted host: the Jupyter kernel of one submission and the
checker's code sent into it (:mod:`.kernel`), the bubblewrap sandbox around it (:mod:`.sandbox`), and the
submission's limits in all: its cgroup and size-limited tmpfs (:mod:`.limits`); without bubblewrap, the
unprivileged student user (:mod:`.unprivileged`); and the one way all of them end a submission's processes,
SIGKILL until none is left (:mod:`.reap`).

Importing this package imports nothing (import the modules you need).
"""
