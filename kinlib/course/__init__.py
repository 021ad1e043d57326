"""kinlib.course: the course tooling around the notebooks (not needed to use the kinematics library).

Laid out by where its code runs:

- :mod:`~kinlib.course.publish` (the instructor's machine, ``kinlib handouts``): problem and solution pages,
  student workbooks with self-checks, PDFs and the in-browser (JupyterLite) site;
- :mod:`~kinlib.course.workbook` (the student's own notebook): the self-checks and the ``%%needs`` magic;
- :mod:`~kinlib.course.answers` (both of the above and the grader): what an answer is (the normaliser), the
  named mistakes, and when two answers are the same;
- :mod:`~kinlib.course.grader` (the trusted host, ``kinlib grade``): grading, credit, reports, reference data
  and the key, with :mod:`~kinlib.course.grader.in_kernel` (the code sent as text into the untrusted student
  kernel) and :mod:`~kinlib.course.grader.isolation` (the kernel and its sandbox);
- :mod:`~kinlib.course.lms` (inside Gradescope/PrairieLearn, and the Canvas file): the LMS bundles;
- here: the notebook schema (:mod:`~kinlib.course.schema`: tags, metadata, points; used by all) and the
  ``kinlib`` command (:mod:`~kinlib.course.cli`; also ``python -m kinlib.course``).

The core package never imports this one; importing it imports nothing (import the modules you need).
"""
