"""Ending a submission's processes for good: SIGKILL until none is left, written once for every way the grader
finds them — a sandbox's PID namespace (:func:`.sandbox.reap_namespaces`), a submission's cgroup
(:func:`.limits.kill_cgroup`), the unprivileged student user (:meth:`.unprivileged.StudentUser.end_all`) — and
a process group (a kernel's launcher, a grading worker: :func:`kill_group`).

A process may fork while it is being killed, so one round of SIGKILLs is not enough: :func:`kill_until_gone`
looks again, kills again, and returns only when the search finds nothing (or the time is up: the PIDs still
there are returned, and the caller refuses to write results).
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from collections.abc import Callable

__all__ = ["sigkill", "kill_until_gone", "kill_group"]


def sigkill(pid: int) -> None:
    """SIGKILL ``pid``; a process already gone (or not ours to signal) is not an error.

    >>> sigkill(2**22 + 1)   # no such process
    """
    try:
        os.kill(pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def kill_until_gone(
    find: Callable[[], list], timeout: float, pause: float = 0.05, each_round: Callable | None = None
) -> list[int]:
    """SIGKILL every PID ``find()`` returns, then look again, until it returns none (returns ``[]``) or
    ``timeout`` seconds have passed (returns the PIDs still there). ``each_round`` runs before each round of
    SIGKILLs (e.g. a ``kill(-1)`` sent as the student's user, which reaches processes forked meanwhile).

    >>> kill_until_gone(lambda: [], timeout=1.0)
    []
    >>> kill_until_gone(lambda: [2**22 + 1], timeout=0.05, pause=0.01)   # one that never goes away
    [4194305]
    """
    deadline = time.monotonic() + timeout
    while True:
        left = find()
        if not left or time.monotonic() > deadline:
            return list(left)
        if each_round is not None:
            each_round()
        for pid in left:
            sigkill(pid)
        time.sleep(pause)


def kill_group(proc: subprocess.Popen, timeout: float = 5.0) -> None:
    """SIGKILL the process group led by ``proc`` (started with ``start_new_session``) and wait up to ``timeout``
    seconds for ``proc`` to be reaped.

    >>> import sys
    >>> p = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"], start_new_session=True)
    >>> kill_group(p); p.returncode == -signal.SIGKILL
    True
    """
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    try:
        proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        pass
