"""What an answer is and when two answers are the same, shared by the workbook self-checks and the grader.

One module per kind of answer, each with that kind's normaliser, the wire form it accepts from a kernel, its
description at the grader's secret points, its comparison and its reference form: :mod:`.expr`, :mod:`.subspace`,
:mod:`.sets`, :mod:`.choice`, :mod:`.properties` (what they share: :mod:`.base`, the named
mistakes :mod:`.mistakes`). The table of kinds (:mod:`.kinds`) dispatches; :func:`.describe.describe` and
:func:`.compare.compare` are the grader's entry points; :mod:`.wire` is the one format in which values cross (a
kernel's answers, the grader's answer key, exact matrices) and its parser (never ``eval``).

Importing this package imports nothing (import the modules you need).
"""
