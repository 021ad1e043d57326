"""The only code the grader ships into a kernel, as source text (see
:data:`kinlib.course.grader.isolation.kernel.SHIPPED`): :mod:`.export` (each answer written out as data, never
judged in the kernel) and :mod:`.guard` (namespaces saved and put back). They import only the standard library,
SymPy, NumPy and mpmath; this package's ``__init__`` is never sent. No evaluation point, seed or reference
answer is ever sent to a kernel: all of that stays in the grader (:mod:`kinlib.course.grader.judge`).

Importing this package imports nothing (import the modules you need).
"""
