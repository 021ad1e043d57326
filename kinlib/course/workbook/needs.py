"""The workbook's ``%%needs NAME...`` cell magic (loaded by ``%load_ext kinlib.course.workbook.selfcheck``).

``kinlib handouts`` starts every workbook cell that reads the student's answers (the pictures drawn from
them: :func:`kinlib.course.publish.analysis.answer_dependents`) with ``%%needs`` and the answer names. Such a cell

- is skipped, with a note, while an answer it uses is still ``...``;
- runs as usual when the self-check said every answer it uses is right (an error there is a real error,
  shown with its traceback);
- otherwise runs with a friendly error: if it fails, the student reads one line naming the answer(s) to
  fix first instead of a traceback from deep inside the plotting code; the traceback stays one click
  away (a collapsed "full error" in JupyterLab) and ``%tb`` prints it.

Cells without ``%%needs`` (not depending on answers) are never touched: their errors show as usual.
"""

from __future__ import annotations

import html
import sys
import traceback

from ..answers.base import is_unanswered

__all__ = ["needs", "friendly_error", "answer_status", "last_results"]

last_results: dict = {}  # {part: {answer name: status}} of the self-checks run in this kernel (selfcheck.check)


def answer_status(name: str) -> str | None:
    """What the last self-check said of answer ``name`` (correct/incorrect/...), None if none ran.

    >>> last_results["9.9"] = {"zz": "incorrect"}
    >>> answer_status("zz"), answer_status("no_such_answer"), last_results.pop("9.9") and None
    ('incorrect', None, None)
    """
    found = [r[name] for r in last_results.values() if name in r]
    return found[-1] if found else None


def friendly_error(suspects: list, etype, value, tb) -> dict:
    """The display bundle shown when a cell using the answers ``suspects`` raised: a one-line message
    naming them (text), and in HTML the same line with the full traceback collapsed under it.

    >>> try:
    ...     [1, 2][5]
    ... except IndexError as e:
    ...     bundle = friendly_error(["can_move"], type(e), e, e.__traceback__)
    >>> print(bundle["text/plain"])
    ⚠ This cell uses your answer `can_move` and stopped with an error (IndexError). Fix `can_move` above first: its self-check says what is wrong. (Full error: run %tb)
    >>> "<details>" in bundle["text/html"] and "list index out of range" in bundle["text/html"]
    True
    """
    names = ", ".join(f"`{n}`" for n in suspects)
    plural = "s" if len(suspects) > 1 else ""
    line = (
        f"⚠ This cell uses your answer{plural} {names} and stopped with an error ({etype.__name__}). "
        f"Fix {names} above first: {'their self-checks say' if plural else 'its self-check says'} what is wrong."
    )
    full = "".join(traceback.format_exception(etype, value, tb))
    return {
        "text/plain": line + " (Full error: run %tb)",
        "text/html": (
            f'<div class="kinlib-needs-error" style="color:#8a4b00">{html.escape(line)}</div>'
            f"<details><summary>full error</summary><pre>{html.escape(full)}</pre></details>"
        ),
    }


def _handler(suspects):
    def handle(shell, etype, value, tb, tb_offset=None):
        from IPython.display import display

        sys.last_type, sys.last_value, sys.last_traceback = etype, value, tb  # for %tb
        if hasattr(sys, "last_exc"):  # Python ≥ 3.12
            sys.last_exc = value
        display(friendly_error(suspects, etype, value, tb), raw=True)
        return []

    return handle


def needs(line: str, cell: str, shell=None, status=answer_status):
    """The ``%%needs NAME...`` cell magic: run ``cell`` once the answers ``NAME...`` are filled in.

    ``shell`` is the IPython shell (the running one when None); ``status(name)`` is what the last
    self-check said of an answer ("correct", ...; None if none ran).
    Outside IPython any object with ``user_ns`` and ``run_cell`` does:

    >>> class Shell:
    ...     user_ns = {"J": ...}
    ...     def run_cell(self, cell):
    ...         print("ran", cell)
    >>> needs("J", "draw(J)", Shell())
    (skipped: this cell uses J from your answers above; fill it in, then run this cell again)
    >>> Shell.user_ns["J"] = 1
    >>> needs("J  # comment", "draw(J)", Shell(), status=lambda name: "correct")
    ran draw(J)
    """
    if shell is None:
        from IPython import get_ipython

        shell = get_ipython()
    names = line.split("#", 1)[0].split()
    missing = [n for n in names if is_unanswered(shell.user_ns.get(n))]
    if missing:
        print(
            f"(skipped: this cell uses {', '.join(missing)} from your answers above; "
            f"fill {'them' if len(missing) > 1 else 'it'} in, then run this cell again)"
        )
        return None
    suspects = [n for n in names if status(n) != "correct"]
    if not suspects:  # the self-checks say these answers are right: an error here is a real one
        shell.run_cell(cell)
        return None
    saved = shell.custom_exceptions, shell.CustomTB
    shell.set_custom_exc((Exception,), _handler(suspects))
    try:
        shell.run_cell(cell)
    finally:
        shell.custom_exceptions, shell.CustomTB = saved
    return None
