"""One isolated IPython kernel per submission, driven through jupyter_client, with time and size limits.

The kernel is a fresh ``python -c ... ipykernel`` process in its own session (process group), with the
scratch directory as its working directory, a unix-socket (ipc) connection, no history database,
``MPLBACKEND=Agg`` and resource limits (address space, file size, no core dumps). Each cell runs with
a per-cell time limit; past it the kernel gets SIGINT, and if it does not come back within a grace
period the whole process group is killed. Outputs are never stored: only their size is counted (so a
submission printing megabytes costs nothing but the time it spends printing), and errors are kept as
(ename, evalue, cell index), truncated.
"""
from __future__ import annotations

import os
import queue
import signal
import subprocess
import sys
import time
from dataclasses import dataclass

from jupyter_client import BlockingKernelClient
from jupyter_client.connect import write_connection_file

_LAUNCH = (
    "import resource, sys\n"
    "def _lim(r, v):\n"
    "    try:\n"
    "        resource.setrlimit(r, (v, v))\n"
    "    except (ValueError, OSError):\n"
    "        pass\n"
    "_lim(resource.RLIMIT_AS, {mem})\n"
    "_lim(resource.RLIMIT_FSIZE, {fsize})\n"
    "_lim(resource.RLIMIT_CORE, 0)\n"
    "sys.path[:] = [p for p in sys.path if p not in ('', '.')]\n"
    "from ipykernel import kernelapp as app\n"
    "app.launch_new_instance()\n"
)


@dataclass
class CellResult:
    """What happened when one cell ran: status ok | error | timeout | died | skipped."""
    index: int
    status: str
    ename: str = ""
    evalue: str = ""
    seconds: float = 0.0
    output_bytes: int = 0
    note: str = ""

    def summary(self) -> str:
        if self.status == "ok":
            return "ran"
        if self.status == "error":
            return f"raised {self.ename}: {self.evalue}".strip()
        return self.note or self.status


@dataclass
class Kernel:
    """A kernel process plus a blocking client; ``run(code)`` executes with limits."""
    cwd: str
    conn_dir: str
    mem_bytes: int = 3 * 2**30
    fsize_bytes: int = 200 * 2**20
    startup_timeout: float = 60.0
    grace: float = 3.0
    proc: subprocess.Popen | None = None
    kc: BlockingKernelClient | None = None
    dead_reason: str = ""

    def start(self) -> None:
        Kernel._counter = getattr(Kernel, "_counter", 0) + 1
        base = os.path.join(self.conn_dir, f"k{os.getpid()}-{Kernel._counter}")
        fn, _ = write_connection_file(fname=base + ".json", transport="ipc", ip=base)
        env = {k: v for k, v in os.environ.items() if not k.startswith(("JPY_SESSION", "JUPYTER_TOKEN"))}
        env.update(MPLBACKEND="Agg", JPY_PARENT_PID=str(os.getpid()), PYTHONDONTWRITEBYTECODE="1",
                   PYDEVD_DISABLE_FILE_VALIDATION="1")
        code = _LAUNCH.format(mem=int(self.mem_bytes), fsize=int(self.fsize_bytes))
        self.proc = subprocess.Popen(
            [sys.executable, "-c", code, "-f", fn, "--HistoryManager.enabled=False",
             "--IPKernelApp.log_level=ERROR", "--Application.log_level=ERROR"],
            cwd=self.cwd, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL, start_new_session=True)
        self.kc = BlockingKernelClient(connection_file=fn)
        self.kc.load_connection_file()
        self.kc.start_channels()
        try:
            self.kc.wait_for_ready(timeout=self.startup_timeout)
        except RuntimeError as exc:
            self.kill()
            raise RuntimeError(f"the kernel did not start: {exc}") from None

    def alive(self) -> bool:
        return self.proc is not None and self.proc.poll() is None

    def kill(self) -> None:
        if self.kc is not None:
            try:
                self.kc.stop_channels()
            except Exception:  # noqa: BLE001
                pass
            self.kc = None
        if self.proc is not None:
            try:
                os.killpg(self.proc.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                pass

    def _interrupt(self) -> None:
        try:
            os.kill(self.proc.pid, signal.SIGINT)
        except ProcessLookupError:
            pass

    def run(self, code: str, timeout: float, index: int = -1, silent: bool = False) -> CellResult:
        """Execute ``code``; never raises for anything the code does."""
        t0 = time.monotonic()
        res = CellResult(index, "ok")
        if not self.alive() or self.kc is None:
            res.status, res.note = "died", "the kernel was not running"
            return res
        msg_id = self.kc.execute(code, silent=silent, store_history=not silent, allow_stdin=False,
                                 stop_on_error=False)
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
            msg = None
            if not idle:
                try:
                    msg = self.kc.get_iopub_msg(timeout=0.1 if replied else 0.05)
                except queue.Empty:
                    msg = None
            if msg is not None and msg.get("parent_header", {}).get("msg_id") == msg_id:
                mt, c = msg["msg_type"], msg["content"]
                if mt == "status" and c.get("execution_state") == "idle":
                    idle = True
                elif mt == "stream":
                    res.output_bytes += len(c.get("text", ""))
                elif mt in ("display_data", "execute_result", "update_display_data"):
                    res.output_bytes += sum(len(str(v)) for v in c.get("data", {}).values())
                elif mt == "error" and res.status == "ok":
                    res.status, res.ename, res.evalue = "error", str(c.get("ename", ""))[:200], \
                        str(c.get("evalue", ""))[:500]
            if not replied:
                try:
                    reply = self.kc.get_shell_msg(timeout=0.1 if idle else 0)
                except queue.Empty:
                    reply = None
                if reply is not None and reply.get("parent_header", {}).get("msg_id") == msg_id:
                    replied, replied_at = True, time.monotonic()
                    c = reply["content"]
                    if c.get("status") == "error" and res.status == "ok":
                        res.status, res.ename, res.evalue = "error", str(c.get("ename", ""))[:200], \
                            str(c.get("evalue", ""))[:500]
                    elif c.get("status") == "aborted" and res.status == "ok":
                        res.status, res.note = "error", "aborted"
        if res.status == "timeout" and interrupted_at is not None and self.alive():
            res.ename = "TimeoutError"
        res.seconds = time.monotonic() - t0
        return res
