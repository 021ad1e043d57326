"""What runs on a learning-management system: the Gradescope and PrairieLearn autograder bundles (built on
the host, run inside the platform with ``python -m kinlib.course.lms.bundles run ...``) and the Canvas
gradebook file (:mod:`.bundles`).

Importing this package imports nothing (import the modules you need).
"""
