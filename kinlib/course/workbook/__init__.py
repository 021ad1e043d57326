"""What runs in the student's own notebook: the workbook self-checks (:mod:`.selfcheck`, loaded by
``%load_ext kinlib.course.workbook.selfcheck``) and the ``%%needs NAME...`` cell magic (:mod:`.needs`).

Importing this package imports nothing (import the modules you need).
"""
