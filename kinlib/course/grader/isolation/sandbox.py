"""The sandbox a student kernel runs in: bubblewrap (``bwrap``) namespaces around the kernel process.

Each student kernel is started as ``bwrap <options> python -P -B -c <launcher> ...`` with

* ``--unshare-all`` (user, PID, network, IPC, UTS, cgroup namespaces): **no network** (only a loopback
  device of its own), its **own PID namespace** (it sees only its own processes and cannot find the
  grader through ``/proc``), ``--die-with-parent`` and ``--new-session``; when the kernel is stopped the
  namespace's init is killed and with it **every process the submission started** (daemons included);
  ``--cap-drop ALL``;
* a filesystem of **read-only** binds of only what the kernel needs: the system (``/usr``, ``/lib*``,
  ``/bin``, ``/sbin``, a few files of ``/etc``), the Python installation and the virtual environment,
  and the ``kinlib`` package folder (not the repository around it: no ``notebooks/``, ``build/``, tests,
  reference cache, grader secret, output folder or the instructor's home);
* a **private writable scratch**: a fresh tmpfs on ``/tmp`` (HOME, IPython's and matplotlib's folders
  are in it), a small ``/dev/shm`` (``/dev`` itself read-only) and, read-write, the one folder of this
  submission (the submission copy as the working directory, the kernel's connection file, its unix sockets
  and the result files the grader reads). With ``tmp_dir``/``shm_dir`` (:class:`kinlib.course.grader.isolation.limits.Enclosure`)
  ``/tmp`` and ``/dev/shm`` are folders of the submission's one size-limited tmpfs, so that everything it
  writes counts against one limit.

The kernel talks to the grader over ZMQ's ``ipc`` transport: unix sockets in that bound folder, which a
network namespace does not cut (loopback TCP would be). Measured in this project's container (Debian 12,
bubblewrap 0.8.0, as root): all namespaces, including an unprivileged user namespace, can be created; see
:func:`check` (it runs ``bwrap ... true`` once and caches the answer).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from .reap import kill_until_gone, sigkill

__all__ = [
    "Sandbox",
    "SandboxUnavailable",
    "check",
    "system_binds",
    "read_info",
    "sandbox_record",
    "reap_namespaces",
    "namespace_processes",
    "font_cache",
]

_ETC = (
    "passwd",
    "group",
    "nsswitch.conf",
    "ld.so.cache",
    "ld.so.conf",
    "ld.so.conf.d",
    "localtime",
    "fonts",
    "mime.types",
    "alternatives",
)
_CHECKED: dict = {}
_FONTS: dict = {}


class SandboxUnavailable(RuntimeError):
    """bubblewrap is missing or cannot create its namespaces here (the message says which and what to do).

    >>> str(SandboxUnavailable("bubblewrap (bwrap) is not installed"))
    'bubblewrap (bwrap) is not installed'
    """


def _real(p) -> str:
    return os.path.realpath(str(p))


def _under(p: str, roots) -> bool:
    return any(p == r or p.startswith(r.rstrip("/") + "/") for r in roots)


def system_binds() -> list[str]:
    """bwrap options for the read-only system: ``/usr`` and friends (``--symlink`` where the host has a
    symlink, as merged-/usr Debian does), a few ``/etc`` files, the Python installation and environment.

    >>> "/usr" in system_binds()
    True
    """
    import kinlib

    opts: list[str] = []
    for d in ("/usr", "/bin", "/sbin", "/lib", "/lib32", "/lib64", "/libx32"):
        if os.path.islink(d):
            opts += ["--symlink", os.readlink(d), d]
        elif os.path.isdir(d):
            opts += ["--ro-bind", d, d]
    for f in _ETC:
        if os.path.exists(f"/etc/{f}"):
            opts += ["--ro-bind", f"/etc/{f}", f"/etc/{f}"]
    done = ["/usr"]
    # the environment as the kernel will see it: its prefixes, then where its python really lives
    pkg = _real(Path(kinlib.__file__).parent)
    paths = [sys.prefix, sys.exec_prefix, sys.base_prefix, sys.base_exec_prefix]
    paths += [str(Path(_real(sys.executable)).parent.parent), pkg]
    for p in paths:
        for q in dict.fromkeys((os.path.abspath(p), _real(p))):
            if os.path.isdir(q) and not _under(q, done):
                opts += ["--ro-bind", q, q]
                done.append(q)
    return opts


@dataclass
class Sandbox:
    """How to wrap a kernel command in bubblewrap; ``hidden`` are folders that must stay invisible (the
    notebooks, cache, output folder, secret): building the command fails if a bind would expose one.

    >>> sb = Sandbox(hidden=["/nonexistent/notebooks"])
    >>> argv = sb.command(["python", "-c", "pass"], cwd="/tmp/kg/work", rw=["/tmp/kg"], env={"A": "1"})
    >>> argv[0].endswith("bwrap"), "--unshare-all" in argv, argv[-3:]
    (True, True, ['python', '-c', 'pass'])
    """

    hidden: list = field(default_factory=list)
    tmpfs_bytes: int = 512 * 2**20  # the private /tmp, when ``tmp_dir`` is not given
    shm_bytes: int = 64 * 2**20  # the private /dev/shm, when ``shm_dir`` is not given
    tmp_dir: str = ""  # a host folder to be the sandbox's /tmp (on the submission's size-limited tmpfs)
    shm_dir: str = ""  # a host folder to be the sandbox's /dev/shm (idem)

    def command(self, argv: list, cwd: str, rw: list, env: dict, info_fd: int | None = None) -> list:
        """The bwrap command line running ``argv`` in ``cwd`` with only ``rw`` writable and env exactly ``env``."""
        binds = system_binds()
        exposed = [binds[i + 1] for i, b in enumerate(binds) if b == "--ro-bind"] + list(rw)
        for h in (_real(h) for h in self.hidden if h):
            for b in exposed:
                if _under(h, [_real(b)]):
                    raise SandboxUnavailable(f"the sandbox would expose {h} (inside {b}); move it elsewhere")
        cmd = [shutil.which("bwrap") or "bwrap", "--unshare-all", "--die-with-parent", "--new-session"]
        cmd += ["--cap-drop", "ALL", "--proc", "/proc", "--dev", "/dev"]
        # a small /dev/shm of its own, then /dev read-only (bwrap's /dev is otherwise a writable tmpfs as large
        # as the host's memory allows)
        if self.shm_dir:
            cmd += ["--bind", _real(self.shm_dir), "/dev/shm"]
        else:
            cmd += ["--size", str(int(self.shm_bytes)), "--tmpfs", "/dev/shm"]
        cmd += ["--remount-ro", "/dev"]
        # the private /tmp first: binds after it land on top of it (an environment or checkout that lives under
        # the host's /tmp, e.g. a fresh clone in mktemp -d, stays visible instead of being covered by the tmpfs)
        if self.tmp_dir:
            cmd += ["--bind", _real(self.tmp_dir), "/tmp", "--dir", "/tmp/home"]
        else:
            cmd += ["--size", str(int(self.tmpfs_bytes)), "--tmpfs", "/tmp", "--dir", "/tmp/home"]
        fonts = font_cache()
        if fonts:  # matplotlib's font list, read-only, in the kernel's own (writable) matplotlib folder
            cmd += ["--dir", "/tmp/home/.matplotlib", "--ro-bind", fonts, "/tmp/home/.matplotlib/" + Path(fonts).name]
        cmd += binds
        for d in rw:
            cmd += ["--bind", _real(d), _real(d)]
        cmd += ["--remount-ro", "/", "--chdir", _real(cwd), "--clearenv"]  # bwrap's own root: read-only too
        for k, v in env.items():
            cmd += ["--setenv", k, str(v)]
        if info_fd is not None:
            cmd += ["--info-fd", str(info_fd)]
        return cmd + list(argv)

    def environment(self, extra: dict) -> dict:
        """The kernel's whole environment: nothing of the grader's but PATH and locale, plus ``extra``.

        >>> sorted(Sandbox().environment({"MPLBACKEND": "Agg"}))[:3]
        ['HOME', 'IPYTHONDIR', 'LANG']
        """
        env = {
            "PATH": os.pathsep.join([str(Path(sys.executable).parent), "/usr/local/bin", "/usr/bin", "/bin"]),
            "HOME": "/tmp/home",
            "IPYTHONDIR": "/tmp/home/.ipython",
            "MPLCONFIGDIR": "/tmp/home/.matplotlib",
            "LANG": "C.UTF-8",
            "TMPDIR": "/tmp",
        }
        env.update(extra)
        return env


def font_cache() -> str | None:
    """matplotlib's font list (``fontlist-v*.json``) for this Python, built once per grader process in a folder of
    the grader's own (removed at exit), or None when it cannot be built (each kernel then builds its own, as before).

    Every kernel starts with a fresh, empty matplotlib folder, and matplotlib scans the system's fonts to rebuild
    this list on its first import: about 0.4 s of CPU per kernel (measured: importing matplotlib.pyplot 0.9 s
    with an empty folder, 0.5 s with the list). The list holds font names and paths of the system and of
    matplotlib (the same paths inside the sandbox), nothing of the grader's or of another submission; the sandbox
    binds it read-only (:meth:`Sandbox.command`), the unprivileged kernel gets a copy
    (:meth:`kinlib.course.grader.isolation.kernel.Kernel`).

    >>> path = font_cache()
    >>> path is None or os.path.basename(path).startswith("fontlist-")
    True
    """
    if "path" not in _FONTS:
        _FONTS["path"] = None
        import atexit
        import tempfile

        folder = tempfile.mkdtemp(prefix="kinlib-fonts-")
        atexit.register(shutil.rmtree, folder, True)
        try:
            subprocess.run(
                [sys.executable, "-I", "-c", "import matplotlib.font_manager"],
                env={"MPLCONFIGDIR": folder, "PATH": os.environ.get("PATH", "/usr/bin:/bin"), "LANG": "C.UTF-8"},
                capture_output=True,
                timeout=120,
                check=True,
            )
            found = sorted(Path(folder).glob("fontlist-v*.json"))
        except (OSError, subprocess.SubprocessError):
            found = []
        if found:
            os.chmod(folder, 0o755)  # readable by the student's user (the list is the system's fonts: no secret)
            os.chmod(found[0], 0o644)
            _FONTS["path"] = str(found[0])
    return _FONTS["path"]


def check() -> tuple[bool, str]:
    """(True, facts) when bubblewrap runs a command with every namespace here; (False, why) otherwise.

    Cached per process (it runs ``bwrap`` once, a few milliseconds):

    >>> ok, why = check()
    >>> isinstance(ok, bool) and isinstance(why, str)
    True
    """
    if "ok" in _CHECKED:
        return _CHECKED["ok"]
    exe = shutil.which("bwrap")
    if exe is None:
        res = (False, "bubblewrap (bwrap) is not installed: apt-get install bubblewrap (make grade does it)")
    else:
        try:
            p = subprocess.run(
                [exe, "--unshare-all", "--die-with-parent", "--cap-drop", "ALL", "--proc", "/proc", "--dev", "/dev"]
                + ["--tmpfs", "/tmp"]
                + system_binds()
                + ["--", _real(sys.executable), "-I", "-c", "import sys; print(sys.version)"],
                capture_output=True,
                text=True,
                timeout=60,
            )
            res = (
                (True, f"bwrap runs Python with all namespaces ({p.stdout.strip().split()[0]})")
                if p.returncode == 0
                else (False, f"bwrap cannot create its namespaces here: {p.stderr.strip()[:300]}")
            )
        except (OSError, subprocess.TimeoutExpired) as exc:
            res = (False, f"bwrap could not run: {exc}")
    _CHECKED["ok"] = res
    return res


def read_info(fd: int, proc: subprocess.Popen, timeout: float) -> dict:
    """bwrap's ``--info-fd`` JSON (child-pid, pid-namespace, ...), read as soon as it is written; {} if bwrap
    exits or ``timeout`` passes first. Closes ``fd``.

    >>> r, w = os.pipe()
    >>> _ = os.write(w, b'{"child-pid": 7, "pid-namespace": 4026531836}'); os.close(w)
    >>> read_info(r, subprocess.Popen(["true"]), timeout=5)
    {'child-pid': 7, 'pid-namespace': 4026531836}
    """
    import select

    buf = b""
    deadline = time.monotonic() + timeout
    try:
        while time.monotonic() < deadline:
            r, _, _ = select.select([fd], [], [], 0.2)
            if r:
                chunk = os.read(fd, 65536)
                if not chunk:
                    break
                buf += chunk
                try:
                    return json.loads(buf)
                except ValueError:
                    continue
            elif proc.poll() is not None:
                break
    finally:
        os.close(fd)
    return {}


def _stat(pid: int):
    """(state, start time) of process ``pid``, or None when there is no such process."""
    try:
        with open(f"/proc/{int(pid)}/stat") as f:
            fields = f.read().rsplit(")", 1)[-1].split()
        return fields[0], int(fields[19])
    except (OSError, ValueError, IndexError):
        return None


def sandbox_record(info: dict) -> list | None:
    """[pid namespace, PID of its init (as the grader sees it), the init's start time] from bwrap's info,
    or None: what identifies one sandbox's processes even after PIDs and namespace numbers are reused.

    >>> sandbox_record({}) is None
    True
    """
    pid, ns = info.get("child-pid"), info.get("pid-namespace")
    st = _stat(pid) if pid else None
    return [int(ns), int(pid), st[1]] if ns and st else None


def namespace_processes(records) -> list[int]:
    """PIDs (as the grader sees them) of the live processes of the sandboxes ``records`` (:func:`sandbox_record`).

    A sandbox whose init has exited has no process left (the kernel kills every process of a PID namespace
    before its init finishes exiting), so only sandboxes whose init is alive are looked into:

    >>> namespace_processes([])
    []
    """
    want = set()
    for ns, pid, start in records:
        st = _stat(pid)
        if st is not None and st[1] == start and st[0] != "Z":
            want.add(f"pid:[{int(ns)}]")
    found = []
    for d in os.listdir("/proc") if want else ():
        if d.isdigit():
            try:
                if os.readlink(f"/proc/{d}/ns/pid") in want and (_stat(d) or ("Z",))[0] != "Z":
                    found.append(int(d))
            except OSError:
                pass
    return found


def reap_namespaces(records, timeout: float = 10.0) -> list[int]:
    """Kill every process of the sandboxes ``records`` (their inits first: that kills the whole namespace) and
    wait until none is left (or ``timeout``); returns the PIDs still alive (empty when all are gone).

    >>> reap_namespaces([])
    []
    """
    for _, pid, start in records:
        st = _stat(pid)
        if st is not None and st[1] == start:
            sigkill(pid)
    return kill_until_gone(lambda: namespace_processes(records), timeout)
