"""The grader, on the trusted host (``kinlib grade``): the submission files and student ids (:mod:`.intake`), the
batch (:mod:`.grade`) and its supervised workers (:mod:`.batch`), one submission's named steps (:mod:`.steps`), the
judging of each answer outside the kernel (:mod:`.judge`: read, evaluated at the secret points, compared, checked
exactly), partial credit (:mod:`.credit`), the outputs (:mod:`.report`), the reference answers (:mod:`.refdata`),
the key and the secret evaluation points (:mod:`.secret`).

The only code sent into the untrusted student kernel is in :mod:`.in_kernel`; the kernel and its sandbox in
:mod:`.isolation`. Importing this package imports nothing (import the modules you need).
"""
