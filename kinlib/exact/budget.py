"""Time budgets for exact computations: every exact call answers, falls back or refuses within a stated time,
and a time limit never touches the process it limits.

An exact computation (a rank proof, a closed-form eigen-decomposition, a determinant of symbolic minors) can
grow far beyond what its input suggests. Each public function of the exact engine takes ``time_budget``
(seconds) and runs its exact part with :func:`run`; when the budget runs out, :class:`OutOfTime` reaches the
function, which returns its documented fallback (a 60-digit numeric answer flagged as such) or raises
:class:`ExactTimeoutError`, a ``ValueError`` that says what would work.

**The design.** Work that may not finish runs where it can be ended: :func:`run` forks the calling process
(``os.fork``) and the child does the work, its result sent back pickled through a pipe. The child arms the
kernel's CPU timer (``setitimer(ITIMER_PROF)``), whose expiry ends it (SIGPROF's default action, taken by the
kernel: no Python code runs, none can be interrupted half-way); the parent waits, then returns the result or
raises :class:`OutOfTime`. Nothing is ever thrown into a thread: the thread that asked waits in ``select`` and
is never interrupted. A child that makes no CPU progress for ``STALL`` seconds (a lock held by another thread
of the parent at the moment of the fork, e.g. a module half imported) is ended too (its process group), and so
is the child of a caller that is itself interrupted (Ctrl-C, a Jupyter interrupt). Warnings the work issues are
recorded in the child and issued again in the caller; an exception is sent back (with the child's traceback as
a note); :func:`report` sends partial results (the conditions found so far) as they are found, so a function
whose budget runs out can still say what it found. kinlib's own loops also call :func:`check` (cooperative
checks) inside :class:`within`: the only kind where there are no processes (Pyodide, i.e. JupyterLite in the
browser, and Windows, which has no ``fork``; :data:`ISOLATED` is False there), and a way for kinlib's loops to
stop cleanly with their partial answer before the timer ends the child.

**Why it cannot leak.** The caller's interpreter never executes a line of the interrupted work: every change a
computation makes to process-wide state (mpmath's global precision, SymPy's ``evaluate`` flag and caches, a
lock, a half-imported module) is made in the child's copy of memory and vanishes with it. The caller only
unpickles a finished result, or learns that there is none. The kernel ends the child between two machine
instructions; there is no "between a state change and the ``try`` that undoes it", because nothing is undone:
the whole process goes. Precision set by kinlib itself (the 60-digit fallbacks, which run in the caller) uses a
private mpmath context per thread (:func:`kinlib.exactfield.mp_context`), never ``mpmath.mp``, so two threads
never share one (tests/core/test_budget.py reads kinlib's code for any other use). What is left is SymPy's own:
some SymPy evaluations set ``mpmath.mp``'s precision for a moment (``evalf(2)`` in its assumptions); in budgeted
work that happens in the child, in the caller's short steps (display, the fallback's input) as SymPy does it.

**Why fork.** It copies the caller as it is: SymPy's warm caches, the function to run (closures included: no
pickling of the work), monkeypatches in tests. Measured (CPU of caller and child, medians of 9, a loaded
2-core machine): a budgeted call costs 10–17 ms more than the same call in the caller (fork, copy-on-write page
faults, exit): evaluate_at, rank_at, column_space, pseudoinverse of a 2×2 or 3×2 J 6–19 ms → 19–37 ms, a UR5
rank_at or a closed-form ellipsoid 166–173 ms → 175–184 ms (+6 %); an empty function ~6 ms.
``time_budget=None`` (no limit) runs in the caller, without a process. pebble (``concurrent.process``) was
measured too: +20–25 ms wall per call over a plain fork (a thread and a ``multiprocessing.Process`` per call),
and its time limits are wall-clock while a budget here counts CPU time, so it is not used (no new dependency).
``forkserver`` would lose the caches and need every argument pickled. Jupyter kernels have threads (heartbeat,
IOPub); the child uses none of them (it never prints; its warnings travel back), and a child stuck on a lock
another thread held at the fork is ended as stalled. (Python ≥ 3.12 warns at such a fork: pyproject.toml's
test configuration ignores that warning.)

What is counted: **seconds of computation**, CPU time (the child's, set by the kernel timer; a thread's own
``time.thread_time`` for cooperative checks), so a budget gives the same answer on an idle laptop and on a
loaded CI machine (where the wall time is longer by the load factor).

>>> try:
...     with within(0.05, "a slow loop"):
...         while True:
...             check()
... except OutOfTime as err:
...     print(err.what, err.seconds)
a slow loop 0.05
>>> run(5, "a sum", sum, range(10))
45
"""

from __future__ import annotations

import numbers
import os
import pickle
import struct
import sys
import threading
import time
import traceback
import warnings
from collections.abc import Callable
from typing import Any

try:  # (Pyodide, i.e. JupyterLite in the browser, has no processes: only cooperative checks are used there)
    import select
    import signal
except ImportError:  # pragma: no cover - platforms without them
    select = signal = None

__all__ = [
    "run",
    "report",
    "within",
    "check",
    "remaining",
    "clock",
    "OutOfTime",
    "ExactTimeoutError",
    "budget_seconds",
    "ISOLATED",
    "STALL",
]

#: True where :func:`run` does the work in a child process ended when its budget runs out (POSIX: fork and CPU
#: timers); False in Pyodide (JupyterLite: no processes) and on Windows: cooperative checks only
ISOLATED = (
    hasattr(os, "fork")
    and hasattr(signal, "setitimer")
    and hasattr(select, "select")
    and sys.platform not in ("emscripten", "wasi")
)
THREADED = ISOLATED  # the former name
#: wall seconds without CPU progress after which a child is taken as stuck and ended (a lock left held at fork)
STALL = 30.0
_HEADER = struct.Struct("<Q")


class OutOfTime(Exception):
    """A budgeted computation ran out of time (``what``, ``seconds``).

    >>> str(OutOfTime("rank_at", 60.0))
    'rank_at: out of time after 60.0 s'
    """

    def __init__(self, what: str, seconds: float | None):
        super().__init__(f"{what}: out of time after {seconds} s")
        self.what, self.seconds = what, seconds

    def __reduce__(self):
        return (type(self), (self.what, self.seconds))


class ExactTimeoutError(ValueError):
    """An exact computation did not finish within its ``time_budget`` and has no numeric fallback here (the
    message says what would work: numbers for the parameters, a configuration, a larger budget).

    >>> issubclass(ExactTimeoutError, ValueError)   # a refusal: callers that catch ValueError see it
    True
    """


class _Expired(BaseException):
    """Raised by :func:`check` inside a :class:`within` block (a BaseException: ``except Exception`` in library
    code lets it pass); the block turns it into :class:`OutOfTime`."""

    def __init__(self, block):
        super().__init__(block.what)
        self.block = block


def clock() -> float:
    """This thread's CPU time in seconds: the clock cooperative deadlines count.

    >>> t0 = clock(); _ = sum(range(10**5)); clock() >= t0
    True
    """
    try:
        return time.thread_time()
    except (AttributeError, OSError):  # pragma: no cover - platforms without a thread clock
        return time.monotonic()


_local = threading.local()
_child: dict = {}  # in a budget's child process: {"fd": the pipe to the parent, "depth": its progress depth}


def _stack() -> list:
    if not hasattr(_local, "stack"):
        _local.stack = []
    return _local.stack


def _progress() -> list:
    if not hasattr(_local, "progress"):
        _local.progress = []
    return _local.progress


class within:
    """``with within(seconds, what):`` a cooperative deadline: :func:`check` raises in the block once ``seconds``
    of this thread's CPU time have passed, and the block ends with :class:`OutOfTime`. It stops kinlib's own
    loops only (SymPy's work runs on: use :func:`run` for work that may not finish). ``seconds`` None: no limit.

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
            raise OutOfTime(self.what, self.seconds)
        self.deadline = float("inf") if self.seconds is None else clock() + float(self.seconds)
        _stack().append(self)
        return self

    def __exit__(self, et, ev, tb):
        stack = _stack()
        if self in stack:
            stack.remove(self)
        if isinstance(ev, _Expired) and ev.block is self:
            raise OutOfTime(self.what, self.seconds) from None
        return False


def check() -> None:
    """Raise the current thread's budget expiry if a deadline has passed (kinlib's loops call this).

    >>> check()   # no budget in force: nothing happens
    """
    stack = getattr(_local, "stack", None)
    if stack:
        now = clock()
        for b in stack:  # the outermost expired budget wins (it ends every block inside it)
            if now > b.deadline:
                raise _Expired(b)


def remaining() -> float:
    """Seconds left in the innermost budget of this thread (inf without one). In a budget's child, also at most what
    its CPU timer has left: the timer counts the CPU its own budgeted children used, the thread clock does not (a
    run started after another inside a budget gets only what is left; issue 32: sequential nested runs could use up
    to twice the outer budget).

    >>> with within(30, "a rank proof"):
    ...     0 < remaining() <= 30
    True
    """
    stack = getattr(_local, "stack", None)
    left = max(0.0, min(b.deadline for b in stack) - clock()) if stack else float("inf")
    if _child:  # a budget's child: its timer also counts the CPU its own budgeted children used (_charge)
        left = min(left, signal.getitimer(signal.ITIMER_PROF)[0])
    return left


def report(item: Any) -> None:
    """Hand a partial result to the caller of the innermost :func:`run` (its ``progress`` callback), at once:
    when the budget then runs out, the caller still has it. Called in the work; nothing happens outside a run.

    >>> found = []
    >>> run(5, "collect", lambda: [report(i) for i in range(3)] and None, progress=found.append)
    >>> found
    [0, 1, 2]
    """
    stack = _progress()
    callback = stack[-1] if stack else None
    if callback is not None:
        callback(item)
    if _child and len(stack) == _child["depth"]:
        _send(_child["fd"], ("progress", item))


def run(seconds: float | None, what: str, fn: Callable, *args, progress: Callable | None = None, **kwargs):
    """``fn(*args, **kwargs)`` with at most ``seconds`` of CPU time, in a child process ended when they run out
    (:data:`ISOLATED`; elsewhere in this thread with cooperative checks): its result, or :class:`OutOfTime`.

    Exceptions raised by ``fn`` are raised here; warnings it issues are issued here again (attributed to the
    first caller outside kinlib); items it passes to :func:`report` reach ``progress`` here as they are found.
    ``seconds`` None: no limit, and no process (nothing needs ending); 0: nothing runs.

    >>> import sympy as sp
    >>> run(30, "a factorisation", sp.factor, sp.Symbol("x") ** 2 - 1)
    (x - 1)*(x + 1)
    >>> try:
    ...     run(0.2, "a loop that never ends", sum, iter(int, 1))   # 0 + 0 + … for ever (in C)
    ... except OutOfTime as err:
    ...     print(err)
    a loop that never ends: out of time after 0.2 s
    """
    outer = remaining()  # a run inside a budgeted block gets at most what that block has left
    clamped = seconds is not None and outer < float(seconds)
    if seconds is not None:
        seconds = min(float(seconds), outer)
    try:
        if seconds is not None and seconds <= 0:
            raise OutOfTime(what, seconds)
        if seconds is not None and ISOLATED:
            try:
                return _forked(seconds, what, fn, args, kwargs, progress)
            except _NoFork:
                pass
        return _inline(seconds, what, fn, args, kwargs, progress)
    except OutOfTime:
        if clamped:  # the time that ran out was the enclosing block's: it ends that block
            _outer_expired()
        raise


def _outer_expired() -> None:
    if _child:  # this process is a budget's child and its budget is spent: end it as its timer would
        os.kill(os.getpid(), signal.SIGPROF)
    stack = _stack()
    if stack:
        raise _Expired(min(stack, key=lambda b: b.deadline))


def _inline(seconds, what, fn, args, kwargs, progress):
    stack = _progress()
    stack.append(progress)
    try:
        with within(seconds, what):
            return fn(*args, **kwargs)
    finally:
        stack.pop()


class _NoFork(Exception):
    pass


def _send(fd: int, obj) -> None:
    try:
        data = pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception as err:  # noqa: BLE001 - an unpicklable result or item
        data = pickle.dumps(("err", RuntimeError(f"kinlib.budget: the result could not be sent back: {err!r}"), []))
    view = memoryview(_HEADER.pack(len(data)) + data)
    while view:
        view = view[os.write(fd, view) :]


def _portable(exc: BaseException) -> BaseException:
    """exc, or an exception of its nearest built-in class with its message, that survives pickling; with the
    child's traceback as a note."""
    note = "in kinlib.budget's child process:\n" + "".join(traceback.format_exception(exc)).rstrip()
    try:
        exc.add_note(note)
        back = pickle.loads(pickle.dumps(exc))
        if type(back) is type(exc):
            return exc
    except Exception:  # noqa: BLE001 - not picklable, or not rebuilt from its pickle
        pass
    base = next(c for c in type(exc).__mro__ if c.__module__ == "builtins")
    try:
        new = base(f"{type(exc).__name__}: {exc}")
    except Exception:  # noqa: BLE001
        new = RuntimeError(f"{type(exc).__name__}: {exc}")
    new.add_note(note)
    return new


def _child_main(r: int, w: int, seconds: float, what: str, fn, args, kwargs, progress) -> None:
    os.close(r)
    try:
        os.setpgid(0, 0)  # a group of its own: ended with whatever it started
    except OSError:
        pass
    signal.signal(signal.SIGPROF, signal.SIG_DFL)  # the timer's expiry ends the process (the kernel acts)
    signal.setitimer(signal.ITIMER_PROF, max(seconds, 0.001))  # (0 would disarm it)
    _local.stack = []  # the caller's cooperative deadlines count the caller's clock: the timer holds them here
    _local.progress = []
    _child.clear()
    _child.update(fd=w, depth=1)
    with warnings.catch_warnings(record=True) as caught:
        try:
            out = ("ok", _inline(seconds, what, fn, args, kwargs, progress))
        except BaseException as exc:  # noqa: BLE001 - sent to the caller, which raises it
            out = ("err", _portable(exc))
    sent = []
    for w_ in caught:
        item = (w_.message, w_.category)
        try:
            pickle.loads(pickle.dumps(item))
        except Exception:  # noqa: BLE001
            item = (str(w_.message), UserWarning)
        sent.append(item)
    _send(w, (*out, sent))


def _proc_cpu(pid: int) -> float | None:
    """The CPU seconds process ``pid`` has used (Linux /proc), or None where that cannot be read."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            fields = f.read().rsplit(b")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return None


def _end(pid: int) -> None:
    for kill, target in ((os.killpg, pid), (os.kill, pid)):
        try:
            kill(target, signal.SIGKILL)
        except OSError:
            pass


def _forked(seconds: float, what: str, fn, args, kwargs, progress):
    r, w = os.pipe()
    pid = _fork_child(r, w, seconds, what, fn, args, kwargs, progress)
    os.close(w)
    try:
        os.setpgid(pid, pid)  # (also done by the child: whichever runs first)
    except OSError:
        pass
    pidfd = _open_pidfd(pid)
    try:
        os.set_blocking(r, False)
        frames, status, usage, stalled = _watch(pid, r, pidfd, seconds)
    except BaseException:  # the caller was interrupted (KeyboardInterrupt ...): the work goes with it
        _end(pid)
        try:
            os.waitpid(pid, 0)
        except ChildProcessError:
            pass
        raise
    finally:
        os.close(r)
        if pidfd is not None:
            os.close(pidfd)
    _charge(usage.ru_utime + usage.ru_stime)
    return _outcome(frames, status, stalled, what, seconds, progress)


def _fork_child(r: int, w: int, seconds: float, what: str, fn, args, kwargs, progress) -> int:
    """Fork a child that does the work and writes its frames to w: the child's pid (in the parent only)."""
    try:
        pid = os.fork()
    except OSError:  # no process to be had (a process limit): cooperative checks only, as in Pyodide
        os.close(r)
        os.close(w)
        raise _NoFork from None
    if pid == 0:  # the child: never returns into the caller's code
        status = 0
        try:
            _child_main(r, w, seconds, what, fn, args, kwargs, progress)
        except BaseException:  # noqa: BLE001
            status = 70
        finally:
            os._exit(status)
    return pid


def _open_pidfd(pid: int) -> int | None:
    """A file descriptor that becomes readable when the child ends (Linux ≥ 5.3), or None."""
    if hasattr(os, "pidfd_open"):
        try:
            return os.pidfd_open(pid)
        except OSError:
            return None
    return None


def _watch(pid: int, r: int, pidfd: int | None, seconds: float):
    """Read the child's frames until it answers or ends, ending it when it is stuck:
    (frames, wait status, resource usage, whether it was ended as stuck)."""
    buf, frames = bytearray(), []
    stuck = _StuckWatch(pid, seconds)
    while True:
        ready, _, _ = select.select([r] if pidfd is None else [r, pidfd], [], [], 0.5 if pidfd is not None else 0.02)
        if r in ready:
            _drain(r, buf, frames)
            if frames and frames[-1][0] in ("ok", "err"):
                _, status, usage = os.wait4(pid, 0)
                return frames, status, usage, False
        if pidfd is None or pidfd in ready:  # (without a pidfd: asked at every turn, 20 ms apart at most)
            done, status, usage = os.wait4(pid, os.WNOHANG)
            if done:
                _drain(r, buf, frames)
                return frames, status, usage, False
        if stuck():
            _end(pid)
            _, status, usage = os.wait4(pid, 0)
            _drain(r, buf, frames)
            return frames, status, usage, True


class _StuckWatch:
    """Called once a turn: whether the child has made no CPU progress for STALL seconds (without /proc: a
    generous wall-clock ceiling, 20 × its budget + STALL)."""

    def __init__(self, pid: int, seconds: float):
        self.pid, self.seconds = pid, seconds
        self.started = self.last_change = time.monotonic()
        self.last_cpu = None

    def __call__(self) -> bool:
        cpu = _proc_cpu(self.pid)
        now = time.monotonic()
        if cpu is None:  # no /proc here: a generous wall-clock ceiling instead
            return now - self.started > 20 * self.seconds + STALL
        if cpu != self.last_cpu:
            self.last_cpu, self.last_change = cpu, now
        return now - self.last_change > STALL


def _outcome(frames: list, status: int, stalled: bool, what: str, seconds: float, progress):
    """The child's answer (its progress reports passed on first), its exception, OutOfTime, or a RuntimeError
    saying how it ended without an answer."""
    for frame in frames:
        if frame[0] == "progress" and progress is not None:
            progress(frame[1])
    if frames and frames[-1][0] in ("ok", "err"):
        kind, value, caught = frames[-1]
        _reissue(caught)
        if kind == "err":
            raise value
        return value
    if stalled or (os.WIFSIGNALED(status) and os.WTERMSIG(status) in (signal.SIGPROF, signal.SIGXCPU, signal.SIGKILL)):
        raise OutOfTime(what, seconds)
    code = os.WTERMSIG(status) if os.WIFSIGNALED(status) else os.WEXITSTATUS(status)
    raise RuntimeError(
        f"{what}: the process doing the work ended without an answer "
        f"({'signal' if os.WIFSIGNALED(status) else 'exit status'} {code})"
    )


def _drain(r: int, buf: bytearray, frames: list) -> None:
    """Read what the pipe holds (non-blocking) and move complete frames from buf to frames."""
    while True:
        try:
            chunk = os.read(r, 1 << 16)
        except BlockingIOError:
            break
        if not chunk:
            break
        buf += chunk
    while len(buf) >= _HEADER.size:
        (n,) = _HEADER.unpack_from(buf)
        if len(buf) < _HEADER.size + n:
            break
        data = bytes(buf[_HEADER.size : _HEADER.size + n])
        del buf[: _HEADER.size + n]
        try:
            frames.append(pickle.loads(data))
        except Exception as err:  # noqa: BLE001 - e.g. a class the caller cannot import
            frames.append(("err", RuntimeError(f"kinlib.budget: the result could not be read back: {err!r}"), []))


def _charge(used: float) -> None:
    """In a budget's child: the CPU time a grandchild used counts against this child's own timer too."""
    if not _child:
        return
    left, _ = signal.getitimer(signal.ITIMER_PROF)
    if left - used <= 0.001:
        os.kill(os.getpid(), signal.SIGPROF)
    signal.setitimer(signal.ITIMER_PROF, left - used)


def _reissue(caught: list) -> None:
    """Issue the child's warnings here, attributed to the first frame outside kinlib (the user's call)."""
    if not caught:
        return
    level, frame = 1, sys._getframe(0)
    while frame is not None and frame.f_globals.get("__name__", "").split(".")[0] == "kinlib":
        frame, level = frame.f_back, level + 1
    for message, category in caught:
        warnings.warn(message, category, stacklevel=level)


def budget_seconds(time_budget: Any, name: str = "time_budget") -> float | None:
    """``time_budget`` checked: a real number of seconds ≥ 0, or None (no limit).

    >>> budget_seconds(5), budget_seconds(None), budget_seconds(float("inf"))
    (5.0, None, None)
    >>> budget_seconds(-1)
    Traceback (most recent call last):
        ...
    ValueError: time_budget must be a number of seconds ≥ 0 (or None: no limit), got int -1
    """
    if time_budget is None:
        return None
    ok = isinstance(time_budget, numbers.Real) and not isinstance(time_budget, bool)
    try:
        value = float(time_budget) if ok else None
    except OverflowError:  # an integer beyond float range: no limit in practice
        value = float("inf")
    except (TypeError, ValueError):
        value = None
    if value is None or not value >= 0:
        from .._backend import describe

        raise ValueError(f"{name} must be a number of seconds ≥ 0 (or None: no limit), got {describe(time_budget)}")
    return None if value == float("inf") else value
