"""The grader's own worker pool: a class is never stopped by one dead or stuck worker.

:func:`run` grades a list of tasks in ``jobs`` worker processes that it starts and watches itself (no
``ProcessPoolExecutor``: a worker killed mid-batch made it raise ``BrokenProcessPool`` and lose the whole
class, and a worker that died while starting could leave it waiting forever, CPython gh-94777/gh-125451).

* Each worker is a fresh ``python -m <this module> --worker FD`` (it imports nothing of the command that
  started it, so a console script without a ``__main__`` guard cannot fork-bomb or kill it), talking to the
  supervisor over a private socket pair: pickled ``init``/``task`` messages in, ``ready``/``beat``/``result``
  out. The grader secret travels over that socket, never in the environment or the command line.
* A worker **dead** (killed, out of memory, crashed) is noticed at once (its socket closes, its process
  exits); a worker **stuck** (stopped, deadlocked: no heartbeat for ``beat_limit`` seconds, or past the task's
  time limit) is killed. Its submission is **retried once** on a fresh worker; a second failure makes it an
  infrastructure row ("not graded: infrastructure: ...", never 0 points silently). Whatever the dead worker
  started is ended: its submission's cgroup (:mod:`kinlib.course.grader.isolation.limits`) is killed, and orphans that the
  supervisor adopts as a child subreaper are killed by process group.
* A worker that cannot start (exits, or sends nothing within ``start_timeout``) is counted; after
  :data:`MAX_START_FAILURES` failed starts with no worker running, the rest of the batch becomes
  infrastructure rows at once: the batch never waits for a worker that will never come.
* A **watchdog** on the whole batch (``batch_timeout``) ends every worker and reports every submission not
  yet graded as infrastructure, so the caller always gets one result per task and writes its outputs.
"""

from __future__ import annotations

import ctypes
import importlib
import os
import pickle
import signal
import socket
import subprocess
import sys
import threading
import time
from collections import deque
from dataclasses import dataclass, field
from multiprocessing.connection import Connection, wait
from pathlib import Path

from .isolation.reap import kill_group

__all__ = ["run", "Supervisor", "MAX_START_FAILURES", "BEAT_SECONDS"]

MAX_START_FAILURES = 3  # failed worker starts (with none running) before the rest of the batch is given up
BEAT_SECONDS = 1.0  # a worker's heartbeat period
MAX_ATTEMPTS = 2  # a submission whose worker dies is tried this many times in all


@dataclass
class _Worker:
    proc: subprocess.Popen
    conn: Connection
    started: float
    ready: bool = False
    task: int | None = None  # index of the task it is grading
    task_started: float = 0.0
    last_beat: float = field(default_factory=time.monotonic)


def _set_subreaper(on: bool = True) -> bool:
    """Make this process adopt (or stop adopting) orphans of its descendants (Linux PR_SET_CHILD_SUBREAPER)."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(36, int(on), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _children() -> list[int]:
    """PIDs of this process's direct children (from /proc)."""
    me, kids = os.getpid(), []
    try:
        names = os.listdir("/proc")
    except OSError:
        return kids
    for d in names:
        if d.isdigit():
            try:
                with open(f"/proc/{d}/stat") as f:
                    if int(f.read().rsplit(")", 1)[1].split()[1]) == me:
                        kids.append(int(d))
            except (OSError, ValueError, IndexError):
                pass
    return kids


class Supervisor:
    """Runs ``tasks`` (keyword arguments for the worker's ``handler``) in supervised worker processes.

    ``init``: what every worker receives once (pickled over its socket), with ``handler``: "module:function", the
    function that, given ``init``, returns the function applied to each task in the worker; ``fail(task, why)``: the result of a
    task that could not be graded (an infrastructure row); ``on_event(kind, pid, task_index)``: called for
    "start" (a worker took a task), "result", "died", "stuck", "retry", "gave-up"; ``on_result(i, result)``: each
    result as it comes (infrastructure ones included); ``cleanup(pid)``: ends whatever a lost worker ``pid``
    left running (its submissions' cgroups). ``worker_cmd`` replaces the worker command (tests).

    Nothing starts until :meth:`run`:

    >>> s = Supervisor(2, {"handler": "kinlib.course.grader.grade:worker_handler"}, lambda task, why: why, 600)
    >>> s.jobs, s.workers
    (2, [])
    """

    def __init__(
        self,
        jobs: int,
        init: dict,
        fail,
        task_timeout: float,
        batch_timeout: float | None = None,
        beat_limit: float = 30.0,
        start_timeout: float = 180.0,
        on_event=None,
        on_result=None,
        cleanup=None,
        worker_cmd=None,
    ):
        self.jobs, self.init, self.fail = max(1, int(jobs)), init, fail
        self.task_timeout, self.batch_timeout = task_timeout, batch_timeout
        self.beat_limit, self.start_timeout = beat_limit, start_timeout
        self.on_event = on_event or (lambda *a: None)
        self.on_result = on_result or (lambda i, res: None)
        self.cleanup = cleanup or (lambda pid: None)
        self.worker_cmd = worker_cmd
        self.workers: list[_Worker] = []
        self.start_failures = 0
        self.log: list[str] = []

    # ------------------------------------------------------------------------------------- workers

    def _spawn(self) -> _Worker | None:
        parent, child = socket.socketpair()
        import kinlib

        env = dict(os.environ)
        top = str(Path(kinlib.__file__).resolve().parent.parent)
        env["PYTHONPATH"] = os.pathsep.join([top] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
        cmd = self.worker_cmd or [sys.executable, "-P", "-m", __name__, "--worker"]
        try:
            proc = subprocess.Popen(
                [*cmd, str(child.fileno())],
                pass_fds=(child.fileno(),),
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,  # the grader's own output stays clean; errors go to stderr
                env=env,
                start_new_session=True,
            )
        except (OSError, ValueError) as exc:
            parent.close()
            self.start_failures += 1
            self.log.append(f"cannot start a grading worker: {exc}")
            return None
        finally:
            child.close()
        conn = Connection(parent.detach())
        w = _Worker(proc, conn, time.monotonic())
        try:
            conn.send(("init", self.init))
        except OSError:
            pass  # it died already: seen as a failed start below
        self.workers.append(w)
        return w

    def _kill(self, w: _Worker) -> None:
        kill_group(w.proc, timeout=10)
        w.conn.close()
        if w in self.workers:
            self.workers.remove(w)

    def _reap_orphans(self) -> None:
        """Kill (by process group) every child of ours that is not a worker: orphans of a dead worker."""
        mine = {w.proc.pid for w in self.workers}
        for pid in _children():
            if pid in mine:
                continue
            try:
                with open(f"/proc/{pid}/stat") as f:
                    if f.read().rsplit(")", 1)[1].split()[0] == "Z":
                        os.waitpid(pid, os.WNOHANG)
                        continue
                os.killpg(os.getpgid(pid), signal.SIGKILL)
            except (OSError, ValueError, IndexError):
                pass
            try:
                os.waitpid(pid, 0)
            except ChildProcessError:
                pass

    # ------------------------------------------------------------------------------------- the batch

    def run(self, tasks: list) -> list:
        """One result per task, in order (graded, or the ``fail`` result of an infrastructure failure)."""
        t0 = time.monotonic()
        self.tasks, self.results = tasks, [None] * len(tasks)
        self.attempts, self.queue = [0] * len(tasks), deque(range(len(tasks)))
        self.subreaper = _set_subreaper()
        try:
            while self.queue or any(w.task is not None for w in self.workers):
                if self.batch_timeout is not None and time.monotonic() - t0 > self.batch_timeout:
                    self._give_up_all(
                        f"the batch's time limit ({self.batch_timeout:g} s) was reached before it was graded"
                    )
                    break
                busy = sum(w.task is not None for w in self.workers)
                if (
                    len(self.workers) < min(self.jobs, len(self.queue) + busy)
                    and self.start_failures < MAX_START_FAILURES
                ):
                    self._spawn()
                if self.queue and self.start_failures >= MAX_START_FAILURES and not self.workers:
                    self._give_up_all(f"no grading worker could start ({'; '.join(self.log[-MAX_START_FAILURES:])})")
                    break
                self._assign()
                self._receive()
                self._check()
        finally:
            self._stop_all()
        return self.results

    def _give_up_all(self, why: str) -> None:
        """End every worker; every task not graded yet gets its ``fail`` result."""
        for w in list(self.workers):
            if w.task is not None:
                self.queue.append(w.task)
            self._kill(w)
            self.cleanup(w.proc.pid)
        for i in self.queue:
            self._set(self.results, i, self.fail(self.tasks[i], why[:600]))
        self.queue.clear()

    def _assign(self) -> None:
        for w in self.workers:
            if w.ready and w.task is None and self.queue:
                i = self.queue.popleft()
                try:
                    w.conn.send(("task", i, self.tasks[i]))
                except OSError:
                    self.queue.appendleft(i)  # it died: seen by _check
                    continue
                self.attempts[i] += 1
                w.task, w.task_started, w.last_beat = i, time.monotonic(), time.monotonic()
                self.on_event("start", w.proc.pid, i)

    def _receive(self) -> None:
        conns = [w.conn for w in self.workers]
        for conn in wait(conns, timeout=0.5) if conns else time.sleep(0.2) or []:
            w = next((x for x in self.workers if x.conn is conn), None)
            if w is None:
                continue
            try:
                while conn.poll():
                    self._message(w, conn.recv(), self.results, self.tasks)
            except (EOFError, OSError, pickle.UnpicklingError):
                try:  # its socket closed: it is exiting (or is made to)
                    code = w.proc.wait(timeout=2)
                except subprocess.TimeoutExpired:
                    code = None
                self.on_event("died", w.proc.pid, w.task)
                self._lost(w, f"died (exit status {code if code is not None else 'unknown'})")

    def _check(self) -> None:
        """Workers dead, never started, without heartbeat, or past the time limit of their task: lost."""
        now = time.monotonic()
        for w in list(self.workers):
            code = w.proc.poll()
            if code is not None:
                self.on_event("died", w.proc.pid, w.task)
                self._lost(w, f"died (exit status {code})")
            elif not w.ready and now - w.started > self.start_timeout:
                self._lost(w, f"sent nothing in {self.start_timeout:g} s")
            elif w.task is not None and now - w.last_beat > self.beat_limit:
                self.on_event("stuck", w.proc.pid, w.task)
                self._lost(w, f"stopped answering (no heartbeat for {self.beat_limit:g} s)")
            elif w.task is not None and now - w.task_started > self.task_timeout:
                self.on_event("stuck", w.proc.pid, w.task)
                self._lost(w, f"went past the {self.task_timeout:g} s limit for one submission")

    def _lost(self, w: _Worker, why: str) -> None:
        """A worker is gone (killed here if it was not): what it started is ended, its task retried once."""
        i = w.task
        self._kill(w)
        self.cleanup(w.proc.pid)
        if self.subreaper:
            self._reap_orphans()
        if i is None:
            if not w.ready:
                self.start_failures += 1
                self.log.append(f"a grading worker did not start ({why})")
        elif self.attempts[i] < MAX_ATTEMPTS:
            self.on_event("retry", w.proc.pid, i)
            self.queue.appendleft(i)
        else:
            self.on_event("gave-up", w.proc.pid, i)
            why = f"the grading worker {why} twice while grading it; run it again"
            self._set(self.results, i, self.fail(self.tasks[i], why))

    def _stop_all(self) -> None:
        for w in list(self.workers):
            try:
                w.conn.send(("stop",))
            except OSError:
                pass
        deadline = time.monotonic() + 5
        for w in list(self.workers):
            try:
                w.proc.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                pass
            self._kill(w)
        if self.subreaper:
            self._reap_orphans()
            _set_subreaper(False)

    def _set(self, results, i, res) -> None:
        results[i] = res
        self.on_result(i, res)

    def _message(self, w: _Worker, msg, results, tasks) -> None:
        kind = msg[0] if isinstance(msg, tuple) and msg else None
        w.last_beat = time.monotonic()
        if kind == "ready":
            w.ready = True
            self.start_failures = 0
        elif kind in ("result", "error") and w.task is not None and msg[1] == w.task:
            i, w.task = w.task, None
            res = msg[2] if kind == "result" else self.fail(tasks[i], f"internal error in the grader: {msg[2]}")
            self._set(results, i, res)
            self.on_event("result", w.proc.pid, i)


def run(tasks: list, jobs: int, init: dict, fail, task_timeout: float, **kw) -> list:
    """Grade ``tasks`` with a :class:`Supervisor` (see there); one result per task, in order.

    A worker that cannot start never blocks the batch: every task gets its ``fail`` result.

    >>> run([{"n": 1}], 1, {}, lambda task, why: why[:29], 60, worker_cmd=[sys.executable, "-c", "exit(3)"])
    ['no grading worker could start']
    """
    return Supervisor(jobs, init, fail, task_timeout, **kw).run(tasks)


# ----------------------------------------------------------------------------------------- the worker


def _worker(fd: int) -> int:
    conn = Connection(fd)
    lock = threading.Lock()
    stop = threading.Event()

    def send(msg):
        with lock:
            conn.send(msg)

    def beat():
        while not stop.wait(BEAT_SECONDS):
            try:
                send(("beat",))
            except OSError:
                return

    msg = conn.recv()
    if not (isinstance(msg, tuple) and msg and msg[0] == "init"):
        return 2
    init = dict(msg[1])
    module, _, name = str(init.pop("handler", "")).partition(":")
    handle = getattr(importlib.import_module(module), name)(init)  # e.g. kinlib.course.grader.grade:worker_handler
    threading.Thread(target=beat, daemon=True).start()
    send(("ready",))
    try:
        while True:
            try:
                msg = conn.recv()
            except EOFError:
                return 0
            if msg[0] == "stop":
                return 0
            if msg[0] == "task":
                try:
                    res = handle(msg[2])
                except Exception as exc:  # noqa: BLE001  a grader bug: this submission's row says so
                    send(("error", msg[1], f"{type(exc).__name__}: {exc}"[:500]))
                    continue
                send(("result", msg[1], res))
    finally:
        stop.set()


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--worker":
        sys.exit(_worker(int(sys.argv[2])))
    print("usage: python -m kinlib.course.grader.batch --worker FD (started by the grader)", file=sys.stderr)
    sys.exit(2)
