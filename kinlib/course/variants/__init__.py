"""Per-student variants of the problem set (issue 33): the instructor's machine and the grader.

Each student's problem set has its own numbers, checked by the exact engine, graded against its own key:

- :mod:`~kinlib.course.variants.spec`: a variant is data. The instructor's notebook declares which numbers vary
  and over what (``metadata.kinlib.variants``); the variant cell and the markdown that shows the numbers are
  written from the values (nothing is evaluated);
- :mod:`~kinlib.course.variants.draw`: a student's variant is drawn from HMAC(course secret, student id, notebook),
  so it is reproducible and cannot be guessed from the workbook;
- :mod:`~kinlib.course.variants.replay`: the notebook run once, then the cells that depend on the numbers re-run
  per variant in the same kernel (answers, self-check fingerprints, figures);
- :mod:`~kinlib.course.variants.structure`: a variant is kept only if its answers have the original's structure
  (singular families, ranks, zero patterns, a unique winner or a tie), proved on the exact answers;
- :mod:`~kinlib.course.variants.key`: the roster, the draws and redraws, and the signed key the grader reads.
"""
