"""The JupyterLite site's browser console (marked ``browser``, ``slow``): a new browser profile opens workbook 05 and
runs it to its first picture, with every request that is not to the loopback server blocked, and the console holds
no warning or error but the ones in :data:`ALLOWED` (each upstream's, named with its upstream issue and why it
cannot be fixed here).

What was fixed at the source (issue 30: 11 console warnings in a new browser):

- 9 "Unsatisfied version 4.4.5 from _JUPYTERLAB.CORE_OUTPUT of shared singleton module @jupyterlab/... (required
  ^4.6.2)" (and one "No satisfying version (^4.6.2) of shared module @jupyterlab/outputarea"): the site's ipywidgets
  front end was jupyterlab_widgets 3.0.17, whose remoteEntry is built against JupyterLab 4.6.2, in a site whose
  JupyterLab is 4.4.5 (jupyterlite-core 0.6.4). The site now ships jupyterlab_widgets 3.0.15, built against 4.4.1
  (kinlib.course.publish.lite.SOURCES_TABLE); 3.0.16 asks ^4.4.6, still above the site's.
- the 2 "Menu entry for command ... is duplicated." are the notebook app's own (:data:`ALLOWED`).

The browser check itself runs in tests/course/test_lite.py's
``test_workbook_05_first_picture_shows_no_stderr_in_a_new_browser`` (the same new profile, workbook 05 run whole:
one browser session, not two); this module holds the allow-list, its rules and :func:`console_problems`.
"""

from __future__ import annotations

import re

from kinlib.course.publish import lite

#: console messages that are upstream's and cannot be fixed in this project: (pattern, upstream issue, why)
ALLOWED = [
    (
        r"^Menu entry for command '(filemenu:close-and-cleanup|application:close)' is duplicated\.$",
        "https://github.com/jupyter/notebook/issues/7358",
        "Notebook 7's application-extension menus.json re-lists these two File-menu entries of JupyterLab's own "
        "schemas on purpose (to order the menu as the classic notebook did); JupyterLab's reconcileMenus warns on "
        "every such cross-plugin override. Open upstream; the maintainers place the fix in JupyterLab, and dropping "
        "the notebook app's menus plugin here would change the students' File menu.",
    ),
]

#: console message types that fail the test (Chromium's "warning"; "error"; page errors are collected too)
FAILING = ("warning", "error", "assert")


def allowed(text: str):
    """The upstream issue that allows the console message ``text``, or None.

    >>> allowed("Menu entry for command 'application:close' is duplicated.")
    'https://github.com/jupyter/notebook/issues/7358'
    >>> allowed("Unsatisfied version 4.4.5 from _JUPYTERLAB.CORE_OUTPUT of shared singleton module @jupyterlab/x") is None
    True
    """
    for pattern, issue, _why in ALLOWED:
        if re.search(pattern, text):
            return issue
    return None


def test_allow_list_entries_name_an_upstream_issue_and_a_reason():
    for pattern, issue, why in ALLOWED:
        re.compile(pattern)
        assert re.fullmatch(r"https://github\.com/[\w.-]+/[\w.-]+/issues/\d+", issue), issue
        assert len(why) > 80, f"say why {pattern!r} cannot be fixed here"


def test_the_site_ships_the_widgets_front_end_built_for_its_jupyterlab():
    """jupyterlab_widgets 3.0.15: its remoteEntry asks JupyterLab ^4.4.1 (the site's core is 4.4.5); 3.0.17, the
    .venv's (for JupyterLab 4.6 in `make lab`), asks ^4.6.2."""
    assert lite.WIDGETS_EXTENSION.name == "jupyterlab_widgets" and lite.WIDGETS_EXTENSION.version == "3.0.15"


def console_problems(seen: list) -> list:
    """The console messages of ``seen`` ((type, text, url) as test_lite.open_workbook collects them) that fail:
    a warning, error or page error outside :data:`ALLOWED`, one line each.

    >>> console_problems([("warning", "Menu entry for command 'application:close' is duplicated.", ""),
    ...                   ("log", "hello", ""), ("warning", "Unsatisfied version 4.4.5 of x", "a/remoteEntry.js")])
    ['[warning] Unsatisfied version 4.4.5 of x (remoteEntry.js)']
    """
    return [
        f"[{t}] {text[:300]} ({url.rsplit('/', 1)[-1]})"
        for t, text, url in seen
        if t in FAILING + ("pageerror",) and allowed(text) is None
    ]
