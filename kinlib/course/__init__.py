"""kinlib.course: the course tooling around the notebooks (not needed to use the kinematics library).

- ``kinlib handouts``: problem and solution pages, student workbooks with self-checks, an index
  (:mod:`~kinlib.course.handouts`, :mod:`~kinlib.course.pages`, :mod:`~kinlib.course.analysis`);
- the workbook self-checks (:mod:`~kinlib.course.selfcheck`, with :mod:`~kinlib.course.needs` for the cells
  drawn from answers);
- ``kinlib grade``: the instructor checker (:mod:`~kinlib.course.grade`, with :mod:`~kinlib.course.kernel`,
  :mod:`~kinlib.course.probe`, :mod:`~kinlib.course.compare`, :mod:`~kinlib.course.report`);
- shared by both: the named mistakes (:mod:`~kinlib.course.mistakes`), the notebook schema (:mod:`~kinlib.course.schema`: tags, metadata, points) and the answer
  normaliser (:mod:`~kinlib.course.answers`);
- the ``kinlib`` command (:mod:`~kinlib.course.cli`; also ``python -m kinlib.course``).

The core package never imports this one; importing it imports nothing (import the modules you need).
"""
