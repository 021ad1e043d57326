"""One isolated IPython kernel per submission, driven through jupyter_client, with time and size limits.

The kernel is a fresh ``python -P -B -c ... ipykernel`` process (no working directory on sys.path) in its
own session (process group), with the scratch directory as its working directory, a unix-socket (ipc) connection, no history database,
``MPLBACKEND=Agg`` and resource limits (address space, file size, no core dumps). With a
:class:`kinlib.course.grader.isolation.sandbox.Sandbox` it runs under bubblewrap (own PID/network/user namespaces, read-only
system, only its own folder writable); stopping it kills its whole PID namespace, daemons included.
Start-up and liveness are judged by the process itself (``poll()``), never by heartbeats: a start is
retried up to :data:`START_ATTEMPTS` times with a generous time limit, and a kernel that still cannot
start raises :class:`KernelStartError` (an infrastructure failure, not the submission's fault). Each cell runs with
a per-cell time limit; past it the kernel gets SIGINT, and if it does not come back within a grace
period the whole process group is killed. Outputs are never stored: only their size is counted (so a
submission printing megabytes costs nothing but the time it spends printing), and errors are kept as
(ename, evalue, cell index), truncated.

:class:`NotebookRun` runs a whole notebook's code cells in such kernels (restarting past a cell that
kills one), with the only code the grader ships into a kernel (:data:`SHIPPED`: the modules of
:mod:`kinlib.course.grader.in_kernel`, sent as source text) loaded in a private module first.
"""

from __future__ import annotations

import dataclasses
import json
import os
import queue
import shutil
import signal
import stat
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import zmq
from jupyter_client import BlockingKernelClient
from jupyter_client.connect import write_connection_file

from ...schema import cell_source, is_plain_selfcheck
from .limits import launch_prelude
from .reap import kill_group
from .sandbox import font_cache

__all__ = [
    "CellResult",
    "Kernel",
    "NotebookRun",
    "IN_KERNEL_MODULES",
    "SHIPPED",
    "setup_code",
    "MAX_RESTARTS",
    "MAX_RESULT_BYTES",
    "START_ATTEMPTS",
    "KernelStartError",
]

# The only code the grader ships into a kernel (student's or reference's), as source text: see
# kinlib.course.grader.in_kernel. No evaluation point, seed or reference is ever sent after it.
IN_KERNEL_DIR = Path(__file__).parents[1] / "in_kernel"
IN_KERNEL_MODULES = ("guard", "export")
SHIPPED = {name: (IN_KERNEL_DIR / f"{name}.py").read_text() for name in IN_KERNEL_MODULES}
MAX_RESTARTS = 2  # kernel restarts per notebook (past cells that kill it)
MAX_RESULT_BYTES = 5 * 2**20  # the largest JSON result read back from the kernel
RESERVED_BYTES = 2**20  # disk reserved per result file before any cell runs (NotebookRun.reserve)
START_ATTEMPTS = 3  # tries to start a kernel before it is an infrastructure failure
MAX_FILES = 1024  # open files per kernel process (RLIMIT_NOFILE) without an enclosure's limits
# What the grader reads from a kernel is bounded whatever the kernel sends (an IOPub flood: print or display of
# hundreds of MB): ZeroMQ refuses a message over MAX_MESSAGE_BYTES before the grader holds it (it drops the
# connection, which ZeroMQ makes again; the drop is counted and flagged on the cell), and queues at most
# MAX_QUEUED messages per channel, so a client holds at most about MAX_QUEUED x MAX_MESSAGE_BYTES per channel.
MAX_MESSAGE_BYTES = 16 * 2**20
MAX_QUEUED = 8


class KernelStartError(RuntimeError):
    """The kernel (or the checker's probe in it) could not be started: an infrastructure failure.

    >>> str(KernelStartError("no answer in 120 s"))
    'no answer in 120 s'
    """


_KERNEL_MAIN = "from ipykernel import kernelapp as app\napp.launch_new_instance()\n"  # after limits.launch_prelude


def _cpu_seconds(pid) -> float:
    """utime + stime + cutime + cstime of process ``pid`` in seconds (0 if it cannot be read)."""
    try:
        with open(f"/proc/{int(pid)}/stat") as f:
            fields = f.read().rsplit(")", 1)[-1].split()
        return sum(int(x) for x in fields[11:15]) / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, TypeError, IndexError):
        return 0.0


@dataclass
class CellResult:
    """What happened when one cell ran: status ok | error | timeout | died | skipped.

    >>> CellResult(0, "ok")
    CellResult(index=0, status='ok', ename='', evalue='', seconds=0.0, output_bytes=0, note='', dropped=0)
    >>> CellResult(4, "timeout", note="stopped after the 60 s limit for one cell").summary()
    'stopped after the 60 s limit for one cell'
    """

    index: int
    status: str
    ename: str = ""
    evalue: str = ""
    seconds: float = 0.0
    output_bytes: int = 0
    note: str = ""
    dropped: int = 0  # output messages refused as over the size cap (ZeroMQ dropped the connection)

    def summary(self) -> str:
        """One line for a person: "ran", "raised E: v", or the note.

        >>> CellResult(3, "error", ename="NameError", evalue="name 'J' is not defined").summary()
        "raised NameError: name 'J' is not defined"
        """
        if self.status == "ok":
            return "ran"
        if self.status == "error":
            return f"raised {self.ename}: {self.evalue}".strip()
        return self.note or self.status


@dataclass
class Kernel:
    """A kernel process plus a blocking client; ``run(code)`` executes with limits.

    Until :meth:`start` there is no process, and ``run`` says so instead of raising:

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     k = Kernel(cwd=d, conn_dir=d)
    ...     k.alive(), k.run("1 + 1", timeout=5).summary()
    (False, 'the kernel was not running')

    ``start`` launches an IPython kernel (seconds; tests/course/test_grade.py exercises it), hence not run here:

    >>> k = Kernel(cwd=".", conn_dir="/tmp")  # doctest: +SKIP
    >>> k.start()  # doctest: +SKIP
    >>> k.run("x = 1 / 0", timeout=10, index=0).summary()  # doctest: +SKIP
    'raised ZeroDivisionError: division by zero'
    >>> k.kill()  # doctest: +SKIP
    """

    cwd: str
    conn_dir: str
    mem_bytes: int = 3 * 2**30
    fsize_bytes: int = 200 * 2**20
    startup_timeout: float = 120.0
    grace: float = 3.0
    sandbox: object | None = None  # a kinlib.course.grader.isolation.sandbox.Sandbox, or None (a plain subprocess)
    enclosure: object | None = None  # a kinlib.course.grader.isolation.limits.Enclosure: cgroup and tmpfs
    user: object | None = None  # without a sandbox: a kinlib.course.grader.isolation.unprivileged.StudentUser to run as
    proc: subprocess.Popen | None = None
    kc: BlockingKernelClient | None = None
    dead_reason: str = ""
    info: dict | None = None  # bwrap's --info-fd (child-pid, pid-namespace) when sandboxed
    record: list | None = None  # sandbox.sandbox_record: [pid namespace, init PID, its start time]
    start_failures: int = 0
    cpu_seconds: float = 0.0  # CPU time the kernel process (and what it waited for) used, read when it is killed
    monitor: object | None = None  # ZeroMQ events of the IOPub socket (a connection dropped: a message over the cap)

    def start(self) -> None:
        """Launch the kernel and wait until it answers, retrying (:data:`START_ATTEMPTS` tries); raise
        :class:`KernelStartError` if it never does."""
        errors = []
        for _ in range(START_ATTEMPTS):
            try:
                self._launch()
                self._wait_ready(time.monotonic() + self.startup_timeout)
                return
            except KernelStartError as exc:
                errors.append(str(exc))
                self.start_failures += 1
                self.kill()
        raise KernelStartError(f"the kernel did not start ({START_ATTEMPTS} tries: {'; '.join(errors)})"[:600])

    def _kernel_argv(self, connection_file: str) -> list:
        """The kernel's command line: Python running the launcher that sets the rlimits, then the kernel."""
        mem, fsize, nproc, nofile = int(self.mem_bytes), int(self.fsize_bytes), 0, MAX_FILES
        if self.enclosure is not None:
            rl = self.enclosure.rlimits()
            mem, fsize, nproc = int(rl["as"]), int(rl["fsize"]), int(rl.get("nproc", 0))
            nofile = int(rl.get("nofile", MAX_FILES))
        code = launch_prelude(mem, fsize, nofile, nproc) + _KERNEL_MAIN
        argv = [sys.executable, "-P", "-B", "-c", code, "-f", connection_file, "--HistoryManager.enabled=False"]
        return argv + ["--IPKernelApp.log_level=ERROR", "--Application.log_level=ERROR"]

    def _isolate(self, argv: list) -> tuple:
        """(argv, env, fds to pass, the sandbox's info pipe or None): the kernel in the sandbox, as the student's
        user, or (``--no-sandbox`` as the grader's user) with the grader's environment."""
        extra = {"MPLBACKEND": "Agg", "PYDEVD_DISABLE_FILE_VALIDATION": "1"}
        if self.sandbox is not None:
            rfd, wfd = os.pipe()
            env = self.sandbox.environment(extra)
            sb = self.sandbox
            if self.enclosure is not None and self.enclosure.tmp_dir:
                sb = dataclasses.replace(sb, tmp_dir=self.enclosure.tmp_dir, shm_dir=self.enclosure.shm_dir)
            try:
                argv = sb.command(argv, cwd=self.cwd, rw=[self.conn_dir, self.cwd], env=env, info_fd=wfd)
            except Exception:
                os.close(rfd)
                os.close(wfd)
                raise
            return argv, env, (wfd,), rfd
        if self.user is not None:  # the student's own user: its scratch folder (and nothing of root's) is its own
            home = os.path.join(self.conn_dir, "home")
            os.makedirs(os.path.join(home, ".matplotlib"), exist_ok=True)
            fonts = font_cache()  # matplotlib's font list: not rebuilt by every kernel (sandbox.font_cache)
            if fonts:
                shutil.copyfile(fonts, os.path.join(home, ".matplotlib", os.path.basename(fonts)))
            self.user.give(self.conn_dir)
            return argv, self.user.environment(home, extra), (), None
        env = {k: v for k, v in os.environ.items() if not k.startswith(("JPY_SESSION", "JUPYTER_TOKEN"))}
        env.update(extra, JPY_PARENT_PID=str(os.getpid()))
        # a compiled-code cache of this kernel's own (kinlib.native): one student's compiled module in the shared
        # cache was loaded by the next student's kernel
        env["KINLIB_CACHE"] = os.path.join(self.conn_dir, f"kinlib-cache-{os.getpid()}-{os.urandom(4).hex()}")
        return argv, env, (), None

    def _launch(self) -> None:
        Kernel._counter = getattr(Kernel, "_counter", 0) + 1
        base = os.path.join(self.conn_dir, f"k{os.getpid()}-{Kernel._counter}")
        fn, _ = write_connection_file(fname=base + ".json", transport="ipc", ip=base)
        argv, env, fds, rfd = self._isolate(self._kernel_argv(fn))
        as_user = self.user.popen_kwargs() if self.user is not None and self.sandbox is None else {}
        if self.enclosure is not None:
            if as_user:  # the launcher joins the cgroup as the student's user: it may write cgroup.procs, nothing else
                for cg in getattr(self.enclosure, "cgroups", ()):
                    os.chown(cg / "cgroup.procs", self.user.uid, self.user.gid)
            argv = self.enclosure.wrap(argv)  # every process the kernel starts is in the submission's cgroup
        try:
            self.proc = subprocess.Popen(
                argv,
                cwd=self.cwd,
                env=env,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                start_new_session=True,
                pass_fds=fds,
                **as_user,
            )
        except OSError as exc:
            raise KernelStartError(f"cannot run {argv[0]}: {exc}") from None
        finally:
            for fd in fds:
                os.close(fd)
        if rfd is not None:
            from .sandbox import read_info, sandbox_record

            self.info = read_info(rfd, self.proc, self.startup_timeout)
            self.record = sandbox_record(self.info)
            if self.record is None:
                raise KernelStartError(f"the sandbox did not start (bwrap exit status {self.proc.poll()})")
        self.kc = BlockingKernelClient(connection_file=fn, context=capped_context())
        self.kc.load_connection_file()
        self.kc.start_channels(hb=False)
        self.monitor = self.kc.iopub_channel.socket.get_monitor_socket(_DROPPED_EVENTS)

    def _wait_ready(self, deadline: float) -> None:
        """kernel_info until it is answered and IOPub delivers; alive means ``proc.poll()`` is None."""
        kc = self.kc
        while True:
            if self.proc.poll() is not None:
                raise KernelStartError(f"the kernel process exited (status {self.proc.returncode}) before answering")
            if time.monotonic() > deadline:
                raise KernelStartError(f"no answer in {self.startup_timeout:g} s")
            kc.kernel_info()
            t_end = min(time.monotonic() + 5.0, deadline)
            while time.monotonic() < t_end and self.proc.poll() is None:
                try:
                    msg = kc.get_shell_msg(timeout=0.5)
                except queue.Empty:
                    continue
                if msg.get("msg_type") != "kernel_info_reply":
                    continue
                try:  # the reply came; IOPub must be connected too (it publishes the busy/idle status)
                    kc.get_iopub_msg(timeout=2.0)
                except queue.Empty:
                    break  # ask again
                while True:
                    try:
                        kc.get_iopub_msg(timeout=0.2)
                    except queue.Empty:
                        return

    def alive(self) -> bool:
        """Whether the kernel process is running."""
        return self.proc is not None and self.proc.poll() is None

    def kill(self) -> None:
        """Stop the client and kill the kernel's whole process group (sandboxed: its whole PID namespace,
        waiting until no process of it is left)."""
        if self.kc is not None:
            try:
                if self.monitor is not None:
                    self.kc.iopub_channel.socket.disable_monitor()
                    self.monitor.close(0)
                self.kc.stop_channels()
                self.kc.context.destroy(linger=0)
            except Exception:  # noqa: BLE001
                pass
            self.kc, self.monitor = None, None
        if self.proc is not None:
            if self.proc.poll() is None:
                self.cpu_seconds += _cpu_seconds(self._kernel_pid())
            if self.record is not None:
                # the sandbox's init first: the kernel kills its whole namespace, init reaps it, and bwrap,
                # seeing its child gone, exits (so CPU time is accounted up the chain to the grader)
                from .sandbox import reap_namespaces

                reap_namespaces([self.record])
                try:
                    self.proc.wait(timeout=2)
                except subprocess.TimeoutExpired:
                    pass
            kill_group(self.proc, timeout=5)
        if self.user is not None and self.sandbox is None:
            self.user.end_all()  # every process of the student's user, daemons in new sessions included

    def _kernel_pid(self):
        """The kernel's PID as the grader sees it: the sandbox's init's child, or the process itself."""
        child = (self.info or {}).get("child-pid")
        if not child:
            return self.proc.pid
        try:
            with open(f"/proc/{int(child)}/task/{int(child)}/children") as f:
                kids = f.read().split()
            return int(kids[0]) if kids else None
        except (OSError, ValueError):
            return None

    def _interrupt(self) -> None:
        pid = self._kernel_pid()
        try:
            if pid:
                os.kill(pid, signal.SIGINT)
            elif self.kc is not None:  # ask the kernel to interrupt itself
                self.kc.control_channel.send(self.kc.session.msg("interrupt_request", content={}))
        except (ProcessLookupError, PermissionError):
            pass

    def _take_output(self, msg_id: str, res: CellResult, wait: float) -> bool:
        """Read one output message of cell ``msg_id`` into ``res`` (its size, an error); True when it says idle."""
        msg = _message_of(self.kc.get_iopub_msg, msg_id, wait)
        if msg is None:
            return False
        mt, c = msg.get("msg_type"), msg.get("content")
        if not isinstance(c, dict):
            return False
        if mt == "status" and c.get("execution_state") == "idle":
            return True
        if mt == "stream":
            res.output_bytes += len(str(c.get("text", "")))
        elif mt in ("display_data", "execute_result", "update_display_data"):
            data = c.get("data")
            res.output_bytes += sum(len(str(v)) for v in data.values()) if isinstance(data, dict) else 0
        elif mt == "error" and res.status == "ok":
            _record_error(res, c)
        return False

    def _take_reply(self, msg_id: str, res: CellResult, wait: float) -> bool:
        """Read the execute reply of cell ``msg_id`` into ``res`` if it came; True when it did."""
        reply = _message_of(self.kc.get_shell_msg, msg_id, wait)
        if reply is None:
            return False
        c = reply.get("content")
        if not isinstance(c, dict):
            c = {"status": "error", "ename": "ProtocolError", "evalue": "the kernel's reply was malformed"}
        if c.get("status") == "error" and res.status == "ok":
            _record_error(res, c)
        elif c.get("status") == "aborted" and res.status == "ok":
            res.status, res.note = "error", "aborted"
        return True

    def run(self, code: str, timeout: float, index: int = -1, silent: bool = False) -> CellResult:
        """Execute ``code``; never raises for anything the code does."""
        t0 = time.monotonic()
        res = CellResult(index, "ok")
        if not self.alive() or self.kc is None:
            res.status, res.note = "died", "the kernel was not running"
            return res
        msg_id = self.kc.execute(code, silent=silent, store_history=not silent, allow_stdin=False, stop_on_error=False)
        deadline = t0 + timeout
        interrupted_at = None
        idle = replied = False
        replied_at = None
        while not (idle and replied):
            now = time.monotonic()
            if replied_at is not None and now > replied_at + 2.0:
                break  # the reply is in; an idle status lost in an output flood must not hang us
            if interrupted_at is None and now > deadline:
                self._interrupt()
                interrupted_at = now
                res.status, res.note = "timeout", f"stopped after the {timeout:g} s limit for one cell"
            if interrupted_at is not None and now > interrupted_at + self.grace:
                self.kill()
                self.dead_reason = f"killed after ignoring the {timeout:g} s limit for one cell"
                res.status, res.note = "timeout", self.dead_reason
                break
            if not self.alive():
                # the process is gone: drain nothing more, report
                self.dead_reason = "the kernel died (the code exited Python or crashed)"
                res.status, res.note = "died", self.dead_reason
                break
            if not idle:
                idle = self._take_output(msg_id, res, 0.1 if replied else 0.05)
                self._reconnect_if_dropped(res)
            if not replied and self._take_reply(msg_id, res, 0.1 if idle else 0):
                replied, replied_at = True, time.monotonic()
        if res.status == "timeout" and interrupted_at is not None and self.alive():
            res.ename = "TimeoutError"
        self._reconnect_if_dropped(res)
        if res.dropped and not res.note:
            res.note = f"output over {MAX_MESSAGE_BYTES // 2**20} MB in one message was not read (dropped)"
        res.seconds = time.monotonic() - t0
        return res

    def _reconnect_if_dropped(self, res) -> None:
        """When ZeroMQ dropped the IOPub connection (a message over :data:`MAX_MESSAGE_BYTES`), count it on
        ``res`` and connect a fresh IOPub socket (the dropped one is not made again)."""
        n = 0
        while self.monitor is not None and self.monitor.poll(0):
            try:
                self.monitor.recv_multipart(zmq.NOBLOCK)
            except zmq.ZMQError:
                break
            n += 1
        if not n or self.kc is None:
            return
        res.dropped += n
        channel = self.kc.iopub_channel
        old = channel.socket
        old.disable_monitor()
        self.monitor.close(0)
        channel.socket = self.kc.connect_iopub()
        self.monitor = channel.socket.get_monitor_socket(_DROPPED_EVENTS)
        old.close(0)


def capped_context():
    """A ZeroMQ context whose sockets refuse a message over :data:`MAX_MESSAGE_BYTES` and queue at most
    :data:`MAX_QUEUED` messages (the grader's kernel clients; defaults of every socket made from it).

    >>> ctx = capped_context()
    >>> ctx.socket(zmq.SUB).getsockopt(zmq.MAXMSGSIZE) == MAX_MESSAGE_BYTES
    True
    >>> ctx.term()
    """
    ctx = zmq.Context()
    ctx.setsockopt(zmq.MAXMSGSIZE, MAX_MESSAGE_BYTES)
    ctx.setsockopt(zmq.RCVHWM, MAX_QUEUED)
    ctx.setsockopt(zmq.LINGER, 0)
    return ctx


_DROPPED_EVENTS = zmq.EVENT_DISCONNECTED


def _message_of(get, msg_id: str, wait: float):
    """The next message ``get`` (a kernel client's iopub or shell reader) gives within ``wait`` seconds if it
    belongs to the execution ``msg_id``, else None. The kernel holds the connection key, so a student's code can
    send any signed message: one of the wrong shape (``parent_header = [1]``) is skipped, never an error here.

    >>> _message_of(lambda timeout: {"parent_header": [1], "content": {}}, "m1", 0.1) is None
    True
    >>> _message_of(lambda timeout: {"parent_header": {"msg_id": "m1"}, "content": {}}, "m1", 0.1)["content"]
    {}
    """
    try:
        msg = get(timeout=wait)
    except queue.Empty:
        return None
    except (ValueError, TypeError, KeyError, AttributeError, UnicodeError):  # undecodable: not ours
        return None
    if not isinstance(msg, dict):
        return None
    parent = msg.get("parent_header")
    return msg if isinstance(parent, dict) and parent.get("msg_id") == msg_id else None


def _record_error(res, content: dict) -> None:
    """The error a cell raised (its name and value, cut short) into its result."""
    res.status, res.ename, res.evalue = (
        "error",
        str(content.get("ename", ""))[:200],
        str(content.get("evalue", ""))[:500],
    )


def setup_code(nonce: str, snapshot: bool) -> str:
    """The code run in a fresh kernel before any cell: :data:`SHIPPED` (``guard``, then ``export`` with ``guard``
    bound) as private modules, ``export`` registered as ``sys.modules[nonce]``; with ``snapshot``, SymPy's, NumPy's,
    mpmath's and the builtins' namespaces saved (``guard.snapshot``) for ``restore_saved``.

    >>> code = setup_code("_kinlib_grade_0", snapshot=False)
    >>> all(repr(src) in code for src in SHIPPED.values())
    True
    """
    return (
        "def __kg_setup():\n"
        "    import sys, types\n"
        f"    g = types.ModuleType({nonce + '_guard'!r})\n"
        f"    exec(compile({SHIPPED['guard']!r}, '<kinlib-grade-guard>', 'exec'), g.__dict__)\n"
        f"    m = types.ModuleType({nonce!r})\n"
        "    m.guard = g\n"
        f"    exec(compile({SHIPPED['export']!r}, '<kinlib-grade-export>', 'exec'), m.__dict__)\n"
        f"    sys.modules[{nonce!r}] = m\n"
        f"    m.SNAP = g.snapshot() if {bool(snapshot)!r} else None\n"
        "__kg_setup(); del __kg_setup\n"
    )


class NotebookRun:
    """A submission (or reference) notebook executed cell by cell in a fresh kernel, with restarts.

    Nothing starts until :meth:`execute`; before it, :meth:`call` answers without a kernel:

    >>> NotebookRun([], cwd=".", tmp=".", cell_timeout=5, total_timeout=30).call("restore_saved(PATH)", 5)
    (None, 'the kernel was not running')

    ``execute`` starts a kernel (and a fresh one past a cell that kills it; seconds, exercised by
    tests/course/test_grade.py), hence not run here:

    >>> cells = [{"cell_type": "code", "source": "J = 2 * 3"},
    ...          {"cell_type": "code", "source": "import os; os._exit(1)"}]
    >>> run = NotebookRun(cells, cwd=".", tmp="/tmp", cell_timeout=10, total_timeout=60).execute()  # doctest: +SKIP
    >>> [run.results[i].status for i in range(2)], run.restarts  # doctest: +SKIP
    (['ok', 'died'], 1)
    >>> run.call("export_answer(globals(), 'J', PATH)", 10)  # doctest: +SKIP
    ({'tree': ['int', '6']}, '')
    >>> run.close()  # doctest: +SKIP
    """

    def __init__(
        self,
        cells: list,
        cwd: str,
        tmp: str,
        cell_timeout: float,
        total_timeout: float,
        stash_after: dict | None = None,
        snapshot: bool = True,
        sandbox=None,
        enclosure=None,
        user=None,
    ):
        self.cells = cells
        self.enclosure = enclosure  # kinlib.course.grader.isolation.limits.Enclosure: the submission's limits, or None
        self.user = user  # kinlib.course.grader.isolation.unprivileged.StudentUser (no sandbox), or None
        self.cwd, self.tmp = cwd, tmp
        self.cell_timeout, self.total = cell_timeout, total_timeout
        self.stash_after = stash_after or {}
        self.snapshot = snapshot
        self.sandbox = sandbox
        self.namespaces: list = []  # sandbox records of every sandboxed kernel this run started
        self.start_failures = 0
        self.cpu_seconds = 0.0  # of every kernel this run started (read as each is stopped)
        self.nonce = "_kinlib_grade_" + os.urandom(8).hex()
        self.reserved: list = []  # result files allocated before any cell ran (reserve), used by call in order
        self.kernel = None
        self.results: dict = {}
        self.restarts = 0
        self.t0 = time.monotonic()

    def _start(self):
        self.kernel = Kernel(
            cwd=self.cwd, conn_dir=self.tmp, sandbox=self.sandbox, enclosure=self.enclosure, user=self.user
        )
        try:
            self.kernel.start()
        finally:
            self.start_failures += self.kernel.start_failures
            if self.kernel.record is not None:
                self.namespaces.append(self.kernel.record)
        code = setup_code(self.nonce, self.snapshot)
        r = self.kernel.run(code, timeout=180, silent=True)
        if r.status != "ok":
            raise KernelStartError(f"could not start the checker's probe in the kernel: {r.summary()}")

    def _m(self) -> str:
        return f"__import__('sys').modules[{self.nonce!r}]"

    def execute(self):
        """Run all cells; returns self (results: index -> CellResult)."""
        skip: set = set()
        while True:
            self._start()
            died_at = None
            for i, cell in enumerate(self.cells):
                if i in skip:
                    continue
                left = self.total - (time.monotonic() - self.t0)
                if left <= 0:
                    self.results[i] = CellResult(i, "skipped", note="not run: the total time limit was reached")
                    continue
                src = cell_source(cell)
                if not src.strip() or is_plain_selfcheck(cell):
                    self.results[i] = CellResult(
                        i, "ok", note="self-check not run by the checker" if src.strip() else ""
                    )
                else:
                    r = self.kernel.run(src, timeout=min(self.cell_timeout, left), index=i)
                    self.results[i] = r
                    if self.enclosure is not None:
                        self.enclosure.check_disk()  # a file written, then deleted, still reached the limit
                    if r.status in ("died", "timeout") and not self.kernel.alive():
                        died_at = i
                        break
                if i in self.stash_after and self.kernel.alive():
                    self.kernel.run(f"{self._m()}.stash(globals(), {self.stash_after[i]!r})", timeout=10, silent=True)
            if died_at is None:
                return self
            skip.add(died_at)
            self.kernel.kill()
            self.cpu_seconds += self.kernel.cpu_seconds
            if self.restarts >= MAX_RESTARTS or self.total - (time.monotonic() - self.t0) <= 1:
                for j in range(died_at + 1, len(self.cells)):
                    self.results.setdefault(j, CellResult(j, "skipped", note="not run: the kernel had died"))
                self.kernel = None
                return self
            self.restarts += 1
            # rerun from the top in a fresh kernel without the cell(s) that killed it
            for j in list(self.results):
                if j not in skip:
                    del self.results[j]

    def reserve(self, n: int) -> None:
        """Allocate ``n`` result files of :data:`RESERVED_BYTES` in ``tmp`` now, before any cell runs: a
        submission that fills its disk (``tmp`` may be on its own tmpfs, or one it shares) cannot take the space
        its answers are written to (the kernel writes them in place, :func:`~..in_kernel.export.export_answer`).
        Raises OSError (ENOSPC: the disk was full before the submission ran) when it cannot.

        >>> import tempfile
        >>> run = NotebookRun([], cwd=".", tmp=tempfile.mkdtemp(), cell_timeout=5, total_timeout=30)
        >>> run.reserve(2); [os.path.getsize(p) for p in run.reserved]
        [1048576, 1048576]
        """
        for _ in range(n):
            path = os.path.join(self.tmp, "r-" + os.urandom(8).hex() + ".json")
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600)
            try:
                os.posix_fallocate(fd, 0, RESERVED_BYTES)
                os.fchmod(fd, 0o666)  # the kernel (maybe the student's user) writes it in place
            finally:
                os.close(fd)
            self.reserved.append(path)

    def call(self, expr: str, timeout: float) -> tuple[dict | None, str]:
        """Run ``export.<expr with PATH>`` in the kernel (:mod:`kinlib.course.grader.in_kernel.export`); return
        (JSON result, error text). ``expr`` names only answers: never a point, seed or reference. PATH is the
        next file :meth:`reserve` allocated (else a new one), removed once read."""
        if self.kernel is None or not self.kernel.alive():
            return None, "the kernel was not running"
        path = self.reserved.pop(0) if self.reserved else os.path.join(self.tmp, "r-" + os.urandom(8).hex() + ".json")
        try:
            return self._call(expr, path, timeout)
        finally:
            try:
                os.unlink(path)
            except OSError:
                pass

    def _call(self, expr: str, path: str, timeout: float) -> tuple[dict | None, str]:
        r = self.kernel.run(f"{self._m()}.{expr.replace('PATH', repr(path))}", timeout=timeout, silent=True)
        if r.status != "ok":
            return None, r.summary()
        try:  # the kernel can write in this folder: never follow a link it planted, read regular files only
            fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
            with os.fdopen(fd, "rb") as f:
                if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
                    return None, "no readable result (not a regular file)"
                data = f.read(MAX_RESULT_BYTES + 1)
            if len(data) > MAX_RESULT_BYTES:
                return None, "the answer is too large to read"
            return json.loads(data), ""
        except (OSError, ValueError) as exc:
            return None, f"no readable result ({type(exc).__name__})"

    def close(self):
        """Kill the kernel, if one is running."""
        if self.kernel is not None:
            self.kernel.kill()
            self.cpu_seconds += self.kernel.cpu_seconds
            self.kernel = None
