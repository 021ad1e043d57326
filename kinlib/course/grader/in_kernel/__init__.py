"""The code the grader sends as source text into the untrusted student kernel (see
:mod:`kinlib.course.grader.isolation.kernel`): :mod:`.probe` (answers to JSON), :mod:`.guard` (namespaces saved
and put back) and :mod:`.srepr` (the strict ``srepr`` parser, also used on the host for reference data).
The answer normaliser :mod:`kinlib.course.answers.normalise` is sent with them. These modules import only the
standard library, SymPy and NumPy; this package's ``__init__`` is never sent.

Importing this package imports nothing (import the modules you need).
"""
