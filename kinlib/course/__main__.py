"""``python -m kinlib.course``: the ``kinlib`` command (:mod:`kinlib.course.cli`)."""

import sys

from .cli import main

sys.exit(main())
