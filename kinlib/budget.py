"""Time budgets for exact computations: every exact call answers, falls back or refuses within a stated time.

An exact computation (a rank proof, a closed-form eigen-decomposition, a determinant of symbolic minors) can
grow far beyond what its input suggests. Each public function of the exact engine takes ``time_budget``
(seconds) and runs its exact part inside :func:`within`; when the budget runs out the function returns its
documented fallback (a 60-digit numeric answer flagged as such) or raises :class:`ExactTimeoutError`, a
``ValueError`` that says what would work.

What is counted: **seconds of computation**, the CPU time of the thread doing the work (``time.thread_time``),
so a budget gives the same answer on an idle laptop and on a loaded CI machine (where the wall time is longer by
the load factor); on an idle machine it is the wall time. Where a thread's CPU clock cannot be read from another
thread (macOS, Windows), the watchdog counts wall time instead.

How the budget is enforced (both mechanisms, whichever stops the work first):

* **a watchdog thread** (one per process, started on first use) raises an exception *into the working thread*
  when its deadline passes (CPython's ``PyThreadState_SetAsyncExc``). This works in any thread (the main thread
  of a script, a Jupyter kernel's executing thread, a grader's worker thread), needs no signal handler (unlike
  ``SIGALRM``, main thread only), and stops pure-Python work inside SymPy too. The exception derives from
  ``BaseException``, so library code that catches ``Exception`` cannot swallow it, and it is raised again every
  50 ms until the budgeted block has ended. One C call (a huge integer product) finishes before it lands.
  It is never fired into the budget's own entry and exit, and never cancelled (on CPython 3.11 a cancelled
  interrupt left a profiled or traced thread spinning for ever), so budgets hold under cProfile, coverage and
  debuggers too, and the watchdog's lock cannot be left held.
  Where threads are not available (Pyodide, i.e. JupyterLite in the browser) only the next mechanism applies.
* **cooperative checks**: kinlib's own loops call :func:`check`, which raises the same exception when the
  deadline has passed.

After an interrupted computation SymPy's caches are cleared (an interrupted assumption query could otherwise
stay "unknown" on a cached expression; kinlib never decides a zero from assumptions, so answers are unaffected).

>>> import time
>>> try:
...     with within(0.05, "a slow loop"):
...         while True:
...             check()
... except OutOfTime as err:
...     print(err.what, err.seconds)
a slow loop 0.05
"""

from __future__ import annotations

import ctypes
import sys
import threading
import time
from typing import Any

__all__ = ["within", "check", "remaining", "clock", "OutOfTime", "ExactTimeoutError", "budget_seconds", "THREADED"]

#: True where the watchdog thread can interrupt SymPy itself (CPython with threads); False in Pyodide
THREADED = sys.implementation.name == "cpython" and sys.platform not in ("emscripten", "wasi")
_REARM = 0.05  # seconds between repeated interrupts if the first one was swallowed


class OutOfTime(Exception):
    """A budgeted block ran out of time (raised by :func:`within` when the block ends; ``what``, ``seconds``).

    >>> str(OutOfTime("rank_at", 60.0))
    'rank_at: out of time after 60.0 s'
    """

    def __init__(self, what: str, seconds: float):
        super().__init__(f"{what}: out of time after {seconds} s")
        self.what, self.seconds = what, seconds


class ExactTimeoutError(ValueError):
    """An exact computation did not finish within its ``time_budget`` and has no numeric fallback here (the
    message says what would work: numbers for the parameters, a configuration, a larger budget).

    >>> issubclass(ExactTimeoutError, ValueError)   # a refusal: callers that catch ValueError see it
    True
    """


class _Expired(BaseException):
    """Raised inside the budgeted block (a BaseException: ``except Exception`` in library code lets it pass)."""


def clock() -> float:
    """This thread's CPU time in seconds: the clock budgets count (kinlib's cooperative deadlines use it too).

    >>> t0 = clock(); _ = sum(range(10**5)); clock() >= t0
    True
    """
    try:
        return time.thread_time()
    except (AttributeError, OSError):  # pragma: no cover - platforms without a thread clock
        return time.monotonic()


def _thread_clock(tid: int):
    """A function reading thread ``tid``'s CPU time from any thread, or None where that is not possible."""
    try:
        cid = time.pthread_getcpuclockid(tid)
        time.clock_gettime(cid)
    except (AttributeError, OSError, ValueError, OverflowError):
        return None
    return lambda: time.clock_gettime(cid)


_local = threading.local()
# The watchdog's state. Both locks are C locks (not threading.Condition, whose Python-level __enter__ can take an
# interrupt between acquiring its lock and the with-statement's protection, leaving the lock held for ever: the
# watchdog then waits for it, and no budget in the process is enforced any more).
_lock = threading.Lock()  # guards _armed; the watchdog fires only while holding it
_wake = threading.Lock()  # held while nobody needs the watchdog; released to wake it early
_wake.acquire()
_armed: dict = {}  # token -> [deadline on the thread's clock, thread id, exception class, that clock, times fired,
#                             the frame that entered the block]
_watchdog: threading.Thread | None = None


def _stack() -> list:
    if not hasattr(_local, "stack"):
        _local.stack = []
    return _local.stack


def _async_raise(tid: int, exc) -> None:
    # Never called with NULL to cancel: on CPython 3.11 that leaves the interpreter's "async exception" flag set
    # with no exception behind it, and under a profiler or tracer (cProfile, coverage, a debugger) the next call
    # of a Python function then spins at its first instruction for ever. An interrupt fired but not yet seen is
    # taken at a safe place instead (within._drain).
    ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(tid), ctypes.py_object(exc))


def _wake_watchdog() -> None:
    try:
        _wake.release()
    except RuntimeError:  # already awake
        pass


def _in_bookkeeping(tid: int, base) -> bool:
    """True while thread ``tid`` enters or leaves a budgeted block (an interrupt there would leave the block
    armed or on the stack) or imports a module (SymPy imports lazily; an interrupt inside importlib's own
    bookkeeping left other threads a half-initialised module): the watchdog fires a moment later. Only the
    frames above ``base`` (the frame whose ``with`` entered the block) count: a block entered while a module
    is being imported (work at a module's top level) is still stopped."""
    frame = sys._current_frames().get(tid)
    while frame is not None and frame is not base:
        if frame.f_code in _BOOKKEEPING or frame.f_globals.get("__name__") in _IMPORTLIB:
            return True
        frame = frame.f_back
    return False


def _watch() -> None:
    while True:
        wait = None
        with _lock:
            for token, entry in list(_armed.items()):
                try:
                    left = entry[0] - entry[3]()
                except OSError:  # the thread is gone
                    del _armed[token]
                    continue
                if left <= 0:
                    if _in_bookkeeping(entry[1], entry[5]):
                        left = 0.001
                    else:
                        _async_raise(entry[1], entry[2])
                        entry[4] += 1
                        entry[0], left = entry[3]() + _REARM, _REARM
                # CPU time runs no faster than wall time: waiting `left` wall seconds never overshoots
                wait = left if wait is None else min(wait, left)
        _wake.acquire(True, -1 if wait is None else max(0.001, wait))


def _start_watchdog() -> bool:
    global _watchdog
    if not THREADED:
        return False
    if _watchdog is None or not _watchdog.is_alive():
        try:
            _watchdog = threading.Thread(target=_watch, name="kinlib-budget-watchdog", daemon=True)
            _watchdog.start()
        except RuntimeError:  # no threads here after all
            _watchdog = None
            return False
    return True


def _tick() -> None:
    """A Python call: an interrupt set for this thread and not yet seen is raised at its start."""


class within:
    """``with within(seconds, what):`` run the block with a deadline; :class:`OutOfTime` when it runs out.

    Nested budgets each keep their own deadline (an outer one that expires ends the inner block too). ``seconds``
    None means no limit (the block runs to its end).

    >>> with within(None, "no limit"):
    ...     remaining()
    inf

    A budget of 0 s runs nothing (the caller's fallback answers at once, whatever the machine's speed):

    >>> try:
    ...     with within(0, "no time"):
    ...         print("never printed")
    ... except OutOfTime as err:
    ...     print(err)
    no time: out of time after 0 s
    """

    def __init__(self, seconds: float | None, what: str):
        self.seconds, self.what = seconds, what

    def __enter__(self):
        if self.seconds is not None and float(self.seconds) <= 0:
            # no time at all: nothing runs (deterministic: a fast block must not win a race with the watchdog)
            raise OutOfTime(self.what, self.seconds)
        self.exc = type("_Expired", (_Expired,), {})  # a class of its own: nested budgets tell theirs apart
        self.deadline = float("inf") if self.seconds is None else clock() + float(self.seconds)
        self.token, self.tid = object(), threading.get_ident()
        _stack().append(self)
        if self.seconds is not None and _start_watchdog():
            read = _thread_clock(self.tid)
            deadline = self.deadline
            if read is None:  # no cross-thread CPU clock here: the watchdog counts wall time
                read, deadline = time.monotonic, time.monotonic() + float(self.seconds)
            with _lock:
                _armed[self.token] = [deadline, self.tid, self.exc, read, 0, sys._getframe(1)]
            _wake_watchdog()
        return self

    def _drain(self, fired: bool) -> _Expired | None:
        """Take an interrupt fired into this thread but not seen yet (it is raised at the next Python call)."""
        seen = None
        for _ in range(3 if fired else 0):
            try:
                _tick()
            except _Expired as err:
                seen = err
        return seen

    def __exit__(self, et, ev, tb):
        late = None  # an interrupt that landed during this bookkeeping (the watchdog avoids it; a guard)
        entry = None
        while True:
            try:
                with _lock:
                    entry = _armed.pop(self.token, entry)
                late = self._drain(entry is not None and entry[4] > 0) or late
                stack = _stack()
                if self in stack:
                    stack.remove(self)
                break
            except _Expired as err:
                late = err
        if (et is not None and issubclass(et, self.exc)) or isinstance(late, self.exc):
            from sympy.core.cache import clear_cache

            clear_cache()
            raise OutOfTime(self.what, self.seconds) from None
        if late is not None:  # an outer block's interrupt: it ends that block too
            raise late
        return False


_IMPORTLIB = frozenset(
    ("_frozen_importlib", "_frozen_importlib_external", "importlib._bootstrap", "importlib._bootstrap_external")
)
_BOOKKEEPING = frozenset(f.__code__ for f in (within.__enter__, within.__exit__, within._drain, _tick))


def check() -> None:
    """Raise the current thread's budget expiry if a deadline has passed (kinlib's loops call this).

    >>> check()   # no budget in force: nothing happens
    """
    stack = getattr(_local, "stack", None)
    if stack:
        now = clock()
        for b in stack:  # the outermost expired budget wins (it ends every block inside it)
            if now > b.deadline:
                raise b.exc


def remaining() -> float:
    """Seconds left in the innermost budget of this thread (inf without one).

    >>> with within(30, "a rank proof"):
    ...     0 < remaining() <= 30
    True
    """
    stack = getattr(_local, "stack", None)
    if not stack:
        return float("inf")
    return max(0.0, min(b.deadline for b in stack) - clock())


def budget_seconds(time_budget: Any, name: str = "time_budget") -> float | None:
    """``time_budget`` checked: a number of seconds ≥ 0, or None (no limit).

    >>> budget_seconds(5), budget_seconds(None), budget_seconds(float("inf"))
    (5.0, None, None)
    >>> budget_seconds(-1)
    Traceback (most recent call last):
        ...
    ValueError: time_budget must be a number of seconds ≥ 0 (or None: no limit), got int -1
    """
    if time_budget is None:
        return None
    if isinstance(time_budget, bool) or not isinstance(time_budget, (int, float)) or not time_budget >= 0:
        from ._backend import describe

        raise ValueError(f"{name} must be a number of seconds ≥ 0 (or None: no limit), got {describe(time_budget)}")
    if time_budget == float("inf"):
        return None
    return float(time_budget)
