"""The grader, on the trusted host (``kinlib grade``): the batch and its steps (:mod:`.grade`), partial
credit (:mod:`.credit`), the outputs (:mod:`.report`), the reference answers (:mod:`.refdata`), the key and the
secret evaluation points (:mod:`.secret`), the submission files and student ids (:mod:`.intake`), and the
supervised grading workers (:mod:`.batch`).

Code sent into the untrusted student kernel is in :mod:`.in_kernel`; the kernel and its sandbox in
:mod:`.isolation`. Importing this package imports nothing (import the modules you need).
"""
