"""What an answer is and when two answers are the same, shared by the workbook self-checks and the grader:
the answer normaliser (:mod:`.normalise`), the comparers (:mod:`.compare`, with the properties of
:mod:`.properties`) and the named mistakes (:mod:`.mistakes`).

Importing this package imports nothing (import the modules you need).
"""
