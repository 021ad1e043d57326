"""Judging a submission's answers in a process of its own, which is ended when an answer takes too long.

Reading, evaluating and comparing an answer (:func:`kinlib.course.grader.judge.judge_answer`) works on data a
student controls, with SymPy and mpmath, whose big-number code can run for minutes holding the GIL. So it never
runs in the grading worker (which runs the kernel, sends heartbeats and reads the results) nor in the supervisor:

* **A process per submission** (:class:`JudgeProcess`): a fresh ``python -P -B`` started (by the worker) before
  the submission's kernel runs, so that importing SymPy overlaps the kernel's work. It gets, over a pipe, as JSON,
  only what judging needs: the notebook's reference answers (:class:`kinlib.course.grader.refdata.Reference`),
  the submission's evaluation points and their seed. Never the grader secret: it cannot sign a reference cache
  or compute another submission's points. With per-student variants (issue 33) it also gets, for each answer that
  varies, the other variants' reference answers (``others``): a wrong answer is then judged against them too
  (:data:`OTHER_SECONDS` in all), and one that is right for another variant says :data:`OTHER_VARIANT` (never
  which variant, nor its numbers).
* **Ended, not interrupted.** Each answer has :data:`~kinlib.course.grader.judge.JUDGE_SECONDS` (the advisory
  exact check :data:`~kinlib.course.grader.judge.EXACT_SECONDS`, asked separately); past it the process is killed
  (SIGKILL to its process group) and the answer is wrong ("too large to grade"); the next answer gets a fresh
  process. No exception is raised into SymPy (a ``SIGALRM`` exception was swallowed by SymPy's and the grader's
  own ``except Exception``: 40 ImageSets ran 47 s against 3 s), and nothing it did can change the next verdict.
* **Bounded.** ``RLIMIT_AS`` (:data:`MEMORY_BYTES`), ``RLIMIT_NOFILE`` (:data:`MAX_FILES`), no core dumps, no
  file written (``RLIMIT_FSIZE`` 0); with bubblewrap it runs in the sandbox (:mod:`.isolation.sandbox`: no
  network, read-only system, only a private ``/tmp``; the notebooks, cache, secret and output folder invisible),
  without it, as the student's unprivileged user when the grader has one (the LMS bundles), else as a plain
  child process (``--no-sandbox`` says the grader is not isolated anyway).
* **Replies are data.** The parent reads a length-prefixed JSON reply of bounded size and keeps only a status
  from a fixed list, a message (cut short) and a known word from the exact check: a judge process that went
  wrong can at worst misjudge its own submission's answer.
"""

from __future__ import annotations

import json
import os
import select
import struct
import subprocess
import sys
import time
from dataclasses import asdict, is_dataclass
from pathlib import Path

from .isolation.limits import launch_prelude
from .isolation.reap import kill_group
from .judge import EXACT_SECONDS, JUDGE_SECONDS, Verdict

__all__ = [
    "JudgeProcess",
    "MEMORY_BYTES",
    "MAX_FILES",
    "START_SECONDS",
    "judge_command",
    "OTHER_VARIANT",
    "OTHER_SECONDS",
]

#: the feedback on a wrong answer that is another variant's right answer (issue 33's wording, exactly)
OTHER_VARIANT = "this looks like another variant's answer"
OTHER_SECONDS = 30.0  # for judging one wrong answer against every other variant's reference answer

MEMORY_BYTES = 3 * 2**30  # address space of a judge process (SymPy + NumPy map ~0.5 GiB before any answer)
MAX_FILES = 64  # open files of a judge process
START_SECONDS = 180.0  # for a judge process to import SymPy and say it is ready (a loaded machine is slow)
MAX_REPLY = 2**20  # bytes of one reply
_STATUSES = ("pass", "fail", "error")
_EXACT_WORDS = ("", "equal", "not proved", "timed out", "not sympy")

_MAIN = "from kinlib.course.grader.judging import _child\nsys.exit(_child())\n"


def judge_command(memory: int = MEMORY_BYTES, nofile: int = MAX_FILES, main: str = _MAIN) -> list:
    """The judge process's command line (before the sandbox wraps it): Python setting its limits, then ``main``
    (:func:`_child`; tests put a probe there).

    >>> argv = judge_command()
    >>> argv[1:4], "RLIMIT_NOFILE, 64" in argv[4]
    (['-P', '-B', '-c'], True)
    """
    import kinlib

    top = str(Path(kinlib.__file__).resolve().parent.parent)
    code = launch_prelude(memory, 0, nofile, path_first=top) + main
    return [sys.executable, "-P", "-B", "-c", code]


# ----------------------------------------------------------------------------------------- framing


def _send(fd: int, obj) -> None:
    data = json.dumps(obj, separators=(",", ":"), allow_nan=False).encode()
    data = struct.pack(">I", len(data)) + data
    while data:
        n = os.write(fd, data)
        data = data[n:]


def _recv_blocking(fd: int, cap: int):
    """One message from ``fd`` (blocking), or None at end of file."""
    head = _read_exact(fd, 4)
    if head is None:
        return None
    (n,) = struct.unpack(">I", head)
    if n > cap:
        return None
    body = _read_exact(fd, n)
    return None if body is None else json.loads(body)


def _read_exact(fd: int, n: int):
    buf = b""
    while len(buf) < n:
        chunk = os.read(fd, n - len(buf))
        if not chunk:
            return None
        buf += chunk
    return buf


# ----------------------------------------------------------------------------------------- the child


def _child() -> int:
    """The judge process: read the init (reference, points, seed) on stdin, then answer requests on stdout."""
    inp, out = 0, os.dup(1)
    os.dup2(os.open(os.devnull, os.O_WRONLY), 1)  # nothing else SymPy prints reaches the protocol
    init = _recv_blocking(inp, 2**31 - 1)
    if not isinstance(init, dict):
        return 2
    from ..answers import describe  # noqa: F401  imported now: the parent's time limits count judging only
    from .judge import exact_check, judge_answer
    from .refdata import Reference, reference_value

    ref = Reference(**init["ref"])
    points, seed = init["points"], init["seed"]
    others = init.get("others") or {}
    values: dict = {}
    last: dict = {}
    _send(out, {"ready": True})
    while True:
        msg = _recv_blocking(inp, 2**31 - 1)
        if not isinstance(msg, dict):
            return 0
        if msg.get("op") == "judge":
            v, value = judge_answer(
                msg["name"], msg["kind"], msg["exported"], ref, points, seed, exact=False, keep_value=True
            )
            values = {msg["name"]: value}  # only the last answer's: kept for its exact check
            last = {"name": msg["name"], "kind": msg["kind"], "exported": msg["exported"]}
            _send(out, {"status": v.status, "message": v.message, "exact": v.exact, "wants_exact": v.exact == "?"})
        elif msg.get("op") == "other":
            _send(out, {"other": _matches_other(last, msg.get("name"), others, ref, points, seed)})
        elif msg.get("op") == "exact":
            word = exact_check(values.get(msg["name"]), reference_value(ref, msg["name"]), float(msg["seconds"]))
            _send(out, {"exact": word})
        else:
            return 0


def _matches_other(last: dict, name, others: dict, ref, points, seed) -> bool:
    """Whether the last answer judged (``name``) is right for one of the other variants' reference answers."""
    from dataclasses import replace

    from .judge import judge_answer

    if last.get("name") != name:
        return False
    for alt in others.get(name) or []:
        other = replace(ref, answers={**ref.answers, name: alt})
        v = judge_answer(name, last["kind"], last["exported"], other, points, seed, exact=False)
        if v.status == "pass":
            return True
    return False


# ----------------------------------------------------------------------------------------- the parent


class JudgeProcess:
    """The judge of one submission's answers (``ref``: its notebook's Reference, ``points``/``seed``: its secret
    evaluation points), in a process that is killed, and replaced, when an answer takes too long.

    ``sandbox``: a :class:`~.isolation.sandbox.Sandbox` to run it in (None: none); ``user``: a
    :class:`~.isolation.unprivileged.StudentUser` to run it as (without a sandbox); ``argv``: the command
    (tests); ``others``: {answer: [the other variants' reference answers that differ from this student's]}
    (per-student variants). Nothing starts until :meth:`start` (or the first :meth:`judge`):

    >>> from kinlib.course.grader.refdata import Reference
    >>> jp = JudgeProcess(Reference("n", "t", "p", "0" * 64, [], {}), [], 0)
    >>> jp.proc is None, jp.kills
    (True, 0)
    """

    def __init__(self, ref, points, seed, sandbox=None, user=None, argv=None, memory=MEMORY_BYTES, others=None):
        self.init = {"ref": asdict(ref) if is_dataclass(ref) else dict(ref), "points": points, "seed": int(seed)}
        self.others = {k: v for k, v in (others or {}).items() if v}
        if self.others:
            self.init["others"] = self.others
        self.sandbox, self.user, self.argv, self.memory = sandbox, user, argv, memory
        self.proc: subprocess.Popen | None = None
        self.ready = False
        self.kills = 0  # processes killed for going past a time limit
        self.starts = 0
        self.buf = b""

    # -- process

    def start(self) -> None:
        """Start a judge process (it imports SymPy while the caller does something else)."""
        if self.proc is not None:
            return
        argv = list(self.argv or judge_command(self.memory))
        kw: dict = {}
        if self.sandbox is not None:
            env = self.sandbox.environment({})
            argv = self.sandbox.command(argv, cwd="/tmp", rw=[], env=env)
        elif self.user is not None:
            env = self.user.environment("/nonexistent", {})
            kw = self.user.popen_kwargs()
        else:
            env = {k: v for k, v in os.environ.items() if k in ("PATH", "LANG", "LC_ALL", "SYSTEMROOT")}
        self.proc = subprocess.Popen(
            argv,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            cwd="/",
            env=env,
            start_new_session=True,
            **kw,
        )
        self.starts += 1
        self.ready, self.buf = False, b""
        try:
            _send(self.proc.stdin.fileno(), self.init)
        except OSError:
            pass  # it died already: seen when its reply does not come

    def kill(self) -> None:
        """End the judge process (and everything in its process group)."""
        if self.proc is None:
            return
        for f in (self.proc.stdin, self.proc.stdout):
            try:
                f.close()
            except OSError:
                pass
        kill_group(self.proc, timeout=10)  # in the sandbox: bwrap, whose namespace dies with it (--die-with-parent)
        self.proc = None
        self.ready = False

    close = kill

    def _reply(self, deadline: float):
        """The next reply, or None when the process died, sent garbage or the deadline passed."""
        fd = self.proc.stdout.fileno()
        while True:
            if len(self.buf) >= 4:
                (n,) = struct.unpack(">I", self.buf[:4])
                if n > MAX_REPLY:
                    return None
                if len(self.buf) >= 4 + n:
                    body, self.buf = self.buf[4 : 4 + n], self.buf[4 + n :]
                    try:
                        return json.loads(body)
                    except ValueError:
                        return None
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            r, _, _ = select.select([fd], [], [], min(left, 1.0))
            if r:
                chunk = os.read(fd, 65536)
                if not chunk:
                    return None
                self.buf += chunk

    def _ask(self, msg: dict, seconds: float):
        """Send ``msg`` to a ready judge process; its reply within ``seconds`` (after it is ready), or None (the
        process is then killed). Raises RuntimeError when no judge process can start."""
        for _ in range(2):
            self.start()
            if not self.ready:
                got = self._reply(time.monotonic() + START_SECONDS)
                if not (isinstance(got, dict) and got.get("ready") is True):
                    self.kill()
                    continue
                self.ready = True
            try:
                _send(self.proc.stdin.fileno(), msg)
            except OSError:
                self.kill()
                continue
            got = self._reply(time.monotonic() + seconds)
            if got is None:
                self.kills += 1
                self.kill()
            return got
        raise RuntimeError(f"no judge process could start ({self.starts} tries)")

    # -- requests

    def judge(self, name, kind, exported, seconds: float = JUDGE_SECONDS, exact: bool = True) -> Verdict:
        """The :class:`~.judge.Verdict` on answer ``name``: judged in the judge process within ``seconds`` (else
        killed there and wrong here), then, if it passed, the advisory exact check within
        :data:`~.judge.EXACT_SECONDS`."""
        t0 = time.monotonic()
        try:
            got = self._ask({"op": "judge", "name": name, "kind": kind, "exported": exported}, seconds + 1.0)
        except (RuntimeError, OSError) as exc:
            return Verdict(name, "error", f"{name} was not graded: infrastructure: {exc}", seconds=0.0)
        except ValueError:  # exported data that is not JSON (NaN): not an answer
            return Verdict(name, "fail", f"{name} could not be read (not data)")
        if got is None:
            v = Verdict(name, "fail", f"{name} is too large to grade (it took over {seconds:g} s to evaluate)")
        elif not isinstance(got, dict) or got.get("status") not in _STATUSES:
            v = Verdict(name, "error", f"{name}: the grader's judge process gave no verdict")
        else:
            v = Verdict(name, got["status"], str(got.get("message", ""))[:1000])
            if got.get("wants_exact") is True and exact:
                v.exact = self._exact(name, min(EXACT_SECONDS, seconds / 3))
            elif v.status == "fail" and name in self.others and self._other(name):
                v = Verdict(name, "fail", f"{name}: {OTHER_VARIANT}")
        v.seconds = round(time.monotonic() - t0, 3)
        return v

    def _other(self, name) -> bool:
        """Whether the answer just judged wrong is right for another variant (False when that takes too long)."""
        try:
            got = self._ask({"op": "other", "name": name}, OTHER_SECONDS + 1.0)
        except (RuntimeError, OSError):
            return False
        return isinstance(got, dict) and got.get("other") is True

    def _exact(self, name, seconds) -> str:
        try:
            got = self._ask({"op": "exact", "name": name, "seconds": seconds}, seconds + 1.0)
        except (RuntimeError, OSError):
            return "not proved"
        if got is None:
            return "timed out"
        word = got.get("exact") if isinstance(got, dict) else None
        return word if word in _EXACT_WORDS else "not proved"

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.kill()
