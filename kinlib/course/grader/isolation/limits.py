"""Resource limits per submission: memory and processes in all (a cgroup), bytes written in all (a tmpfs).

Defaults (:class:`Limits`, ``kinlib grade --memory/--processes/--disk``): **2 GiB** of memory in all (every
process of the submission together, tmpfs pages it wrote included), **256** processes, **512 MiB** written in
all. Each submission gets an :class:`Enclosure`:

* a **cgroup** of its own, made before its kernel starts and joined by the kernel's launcher before it
  runs anything (``sh -c 'echo $$ > cgroup.procs; exec bwrap ...'``), so every process the submission starts
  is in it: cgroup v2 (``memory.max``, ``memory.swap.max``, ``pids.max``, ``cgroup.kill``) where its
  controllers are available, else cgroup v1's ``memory`` and ``pids`` hierarchies (``memory.limit_in_bytes``,
  ``memory.memsw.limit_in_bytes``, ``pids.max``); creating one needs root (or a delegated cgroup). A fork
  past the limit fails (``BlockingIOError`` in the cell); memory past it is reclaimed, then the kernel's OOM
  killer ends a process of *this* cgroup only.
* one **size-limited tmpfs** holding everything the sandbox can write: the working folder (the submission's
  copy, the kernel's connection file and sockets, the result files), the sandbox's ``/tmp`` and its
  ``/dev/shm`` (``/dev`` itself is read-only in the sandbox, :mod:`kinlib.course.grader.isolation.sandbox`). Mounting it
  needs root; without root the sandbox's ``/tmp`` and ``/dev/shm`` are tmpfs of their own sizes and the
  working folder is on the host's disk, each file limited by ``RLIMIT_FSIZE``.

Without cgroups (not root, no delegation) the kernel's rlimits are what is left: ``RLIMIT_AS`` per process
(not in all) and ``RLIMIT_NPROC``; :meth:`Enclosure.describe` says which limits are in force, and the result
of a submission that reached one says so in a row (:meth:`Enclosure.reached`).
"""

from __future__ import annotations

import atexit
import ctypes
import os
import re
import shutil
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from .reap import kill_until_gone

__all__ = ["Limits", "Enclosure", "parse_size", "cgroup_support", "kill_cgroup", "release", "launch_prelude"]

MS_NOSUID, MS_NODEV, MNT_DETACH = 2, 4, 2


def launch_prelude(mem: int, fsize: int, nofile: int, nproc: int = 0, path_first: str | None = None) -> str:
    """The first lines of ``python -c`` for a process the grader starts on student data (a kernel, a judge):
    its own rlimits (address space, file size, no core, open files, processes when ``nproc``), then ``sys.path``
    without the working directory (``path_first`` in front when given). What follows is the process's own code.

    >>> code = launch_prelude(2**30, 0, 64, path_first="/src")
    >>> "RLIMIT_AS, 1073741824" in code and "RLIMIT_NPROC" not in code and "['/src']" in code
    True
    """
    lines = [
        "import resource, sys",
        "def _lim(r, v):",
        "    try:",
        "        resource.setrlimit(r, (v, v))",
        "    except (ValueError, OSError):",
        "        pass",
        f"_lim(resource.RLIMIT_AS, {int(mem)})",
        f"_lim(resource.RLIMIT_FSIZE, {int(fsize)})",
        "_lim(resource.RLIMIT_CORE, 0)",
        f"_lim(resource.RLIMIT_NOFILE, {int(nofile)})",
    ]
    if nproc:
        lines.append(f"_lim(resource.RLIMIT_NPROC, {int(nproc)})")
    first = f"[{path_first!r}] + " if path_first else ""
    lines.append(f"sys.path[:] = {first}[p for p in sys.path if p not in ('', '.')]")
    return "\n".join(lines) + "\n"


_CG2 = Path("/sys/fs/cgroup")
_SUPPORT: dict = {}


@dataclass(frozen=True)
class Limits:
    """What one submission may use, in all.

    >>> Limits()
    Limits(memory_bytes=2147483648, processes=256, disk_bytes=536870912, shm_bytes=67108864, files=1024)
    """

    memory_bytes: int = 2 * 2**30
    processes: int = 256
    disk_bytes: int = 512 * 2**20
    shm_bytes: int = 64 * 2**20  # the sandbox's /dev/shm when it is not on the submission's tmpfs
    files: int = 1024  # open files per process of the submission (RLIMIT_NOFILE; one kernel opened 19,928)

    def words(self) -> str:
        """The limits in words.

        >>> Limits().words()
        '2 GiB of memory, 256 processes, 512 MiB written'
        """
        return f"{_size(self.memory_bytes)} of memory, {self.processes} processes, {_size(self.disk_bytes)} written"


def _size(n: int) -> str:
    for unit, k in (("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= k and n % (k // 8 or 1) == 0:
            return f"{n / k:g} {unit}"
    return f"{n} bytes"


def parse_size(text: str) -> int:
    """Bytes in ``text``: a number with an optional K, M, G (powers of 1024; ``MiB`` and ``MB`` alike).

    >>> parse_size("2G"), parse_size("512MiB"), parse_size("1048576")
    (2147483648, 536870912, 1048576)
    """
    m = re.fullmatch(r"\s*(\d+(?:\.\d+)?)\s*([kKmMgG]?)(?:i?[bB])?\s*", str(text))
    if not m:
        raise ValueError(f"not a size: {text!r} (e.g. 512M, 2G)")
    n = float(m.group(1)) * {"": 1, "k": 2**10, "m": 2**20, "g": 2**30}[m.group(2).lower()]
    if n < 1:
        raise ValueError(f"a size must be positive, got {text!r}")
    return int(n)


# ----------------------------------------------------------------------------------------- cgroups


def _own_cgroup(controller: str) -> str | None:
    """This process's cgroup path in ``controller``'s v1 hierarchy ("" for v2's), or None."""
    try:
        lines = Path("/proc/self/cgroup").read_text().splitlines()
    except OSError:
        return None
    for line in lines:
        _, names, path = line.split(":", 2)
        if (controller == "" and names == "") or controller in names.split(","):
            return path
    return None


def _write(path: Path, text: str) -> bool:
    try:
        path.write_text(text)
        return True
    except OSError:
        return False


def _v2_base() -> Path | None:
    """A cgroup v2 folder whose children can have memory and pids limits (made for this grader), or None."""
    own = _own_cgroup("")
    if own is None or not (_CG2 / "cgroup.controllers").exists():
        return None
    me = _CG2 / own.lstrip("/")
    parent = _CG2 if own == "/" else me.parent
    have = set((parent / "cgroup.subtree_control").read_text().split()) if parent.exists() else set()
    if not {"memory", "pids"} <= have and not (
        parent == _CG2 and _write(parent / "cgroup.subtree_control", "+memory +pids")
    ):
        return None
    base = parent / f"kinlib-grade-{os.getpid()}"
    try:
        base.mkdir(exist_ok=True)
    except OSError:
        return None
    if not _write(base / "cgroup.subtree_control", "+memory +pids"):
        return None
    return base


def _v1_bases() -> dict | None:
    """{"memory": folder, "pids": folder} in cgroup v1's hierarchies, made for this grader, or None."""
    out = {}
    for ctl in ("memory", "pids"):
        own = _own_cgroup(ctl)
        root = _CG2 / ctl
        if own is None or not (root / "cgroup.procs").exists():
            return None
        base = root / own.lstrip("/") / f"kinlib-grade-{os.getpid()}"
        try:
            base.mkdir(exist_ok=True)
        except OSError:
            return None
        out[ctl] = base
    return out


def _bases(pid: int) -> list[Path]:
    """The grader-made cgroup folders of process ``pid`` (see :func:`cgroup_support`), in every hierarchy."""
    name = f"kinlib-grade-{int(pid)}"
    found = []
    for ctl in ("", "memory", "pids"):
        own = _own_cgroup(ctl)
        if own is None:
            continue
        root = _CG2 if ctl == "" else _CG2 / ctl
        here = root / own.lstrip("/")
        for base in (here / name, here.parent / name):
            if base.is_dir() and base not in found:
                found.append(base)
    return found


def release(pid: int | None = None) -> list[int]:
    """Kill every process in the per-submission cgroups made by grader process ``pid`` (default: this one)
    and remove them; returns PIDs that would not die. The supervisor calls it for a worker it lost.

    >>> release(2**22 + 1)
    []
    """
    pid = os.getpid() if pid is None else int(pid)
    left = []
    for base in _bases(pid):
        subs = [c for c in base.iterdir() if c.is_dir()] if base.is_dir() else []
        for c in subs:
            left += kill_cgroup([c])
            _rmdir_cgroup(c)
        try:
            base.rmdir()
        except OSError:
            pass
    _remove_folders(pid)
    return left


def _rmdir_cgroup(folder: Path, tries: int = 50) -> None:
    """Remove an emptied cgroup folder, retrying while the kernel still counts its last processes (EBUSY)."""
    for _ in range(tries):
        try:
            folder.rmdir()
            return
        except FileNotFoundError:
            return
        except OSError:
            time.sleep(0.02)


def _remove_folders(pid: int) -> None:
    """Unmount and delete the submission folders a (dead) grader process ``pid`` left."""
    prefix = os.path.join(tempfile.gettempdir(), f"kinlib-grade-{int(pid)}-")
    try:
        mounts = [line.split()[4] for line in Path("/proc/self/mountinfo").read_text().splitlines()]
    except (OSError, IndexError):
        mounts = []
    for m in mounts:
        if m.startswith(prefix):
            _umount(m)
    for d in Path(tempfile.gettempdir()).glob(f"kinlib-grade-{int(pid)}-*"):
        shutil.rmtree(d, ignore_errors=True)


def cgroup_support() -> tuple[str, object]:
    """("v2", base folder), ("v1", {controller: base folder}) or ("", why not): where this process can make
    per-submission cgroups (checked once per process).

    >>> kind, where = cgroup_support()
    >>> kind in ("v2", "v1", "")
    True
    """
    if "res" not in _SUPPORT:
        base = _v2_base()
        if base is not None:
            _SUPPORT["res"] = ("v2", base)
            atexit.register(release)
        else:
            bases = _v1_bases()
            _SUPPORT["res"] = ("v1", bases) if bases else ("", "no writable cgroup with memory and pids controllers")
            if bases:
                atexit.register(release)
    return _SUPPORT["res"]


def _procs(folder: Path) -> list[int]:
    try:
        return [int(x) for x in (folder / "cgroup.procs").read_text().split()]
    except (OSError, ValueError):
        return []


def kill_cgroup(folders, timeout: float = 10.0) -> list[int]:
    """Kill every process in the cgroup ``folders`` (one per hierarchy) until none is left (or ``timeout``);
    returns the PIDs still there.

    >>> kill_cgroup([])
    []
    """
    folders = [Path(f) for f in folders]
    for f in folders:
        _write(f / "cgroup.kill", "1") if (f / "cgroup.kill").exists() else None
    return kill_until_gone(lambda: sorted({p for f in folders for p in _procs(f)}), timeout, pause=0.02)


def _counter(path: Path, key: str) -> int:
    try:
        for line in path.read_text().splitlines():
            k, _, v = line.partition(" ")
            if k == key:
                return int(v)
    except (OSError, ValueError):
        pass
    return 0


# ----------------------------------------------------------------------------------------- tmpfs


def _mount_tmpfs(target: str, size: int) -> bool:
    """Mount a tmpfs of ``size`` bytes on ``target`` (root only); False when it cannot."""
    if not hasattr(os, "geteuid") or os.geteuid() != 0:
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        opts = f"size={int(size)},mode=0700".encode()
        return libc.mount(b"tmpfs", target.encode(), b"tmpfs", MS_NOSUID | MS_NODEV, opts) == 0
    except (OSError, AttributeError):
        return False


def _umount(target: str) -> None:
    try:
        ctypes.CDLL(None, use_errno=True).umount2(target.encode(), MNT_DETACH)
    except (OSError, AttributeError):
        pass


# ----------------------------------------------------------------------------------------- one submission


class Enclosure:
    """One submission's folder (a size-limited tmpfs when possible) and cgroup, with its ``limits``.

    ``folder``: where the grader puts the submission's copy and the kernel's files; ``tmp_dir`` and
    ``shm_dir``: the sandbox's ``/tmp`` and ``/dev/shm`` on the same tmpfs ("" when there is none).

    >>> with Enclosure(Limits(), "doctest") as e:
    ...     os.path.isdir(e.folder), e.describe().startswith("limits:")
    (True, True)
    """

    def __init__(self, limits: Limits | None = None, tag: str = ""):
        self.limits = limits or Limits()
        self.folder = tempfile.mkdtemp(prefix=f"kinlib-grade-{os.getpid()}-")  # release(pid) finds it by name
        self.tmpfs = _mount_tmpfs(self.folder, self.limits.disk_bytes)
        self.tmp_dir = self.shm_dir = ""
        if self.tmpfs:
            self.tmp_dir, self.shm_dir = os.path.join(self.folder, ".tmp"), os.path.join(self.folder, ".shm")
            os.mkdir(self.tmp_dir, 0o700)
            os.mkdir(self.shm_dir, 0o1777)
        self.kind, self.cgroups = "", []
        kind, where = cgroup_support()
        name = f"s-{re.sub(r'[^A-Za-z0-9_.-]', '_', tag)[:40]}-{os.urandom(4).hex()}"
        try:
            if kind == "v2":
                self.cgroups = [where / name]
            elif kind == "v1":
                self.cgroups = [where["memory"] / name, where["pids"] / name]
            for c in self.cgroups:
                c.mkdir()
            self.kind = kind if self.cgroups else ""
            if self.kind and not self._apply():
                self.kind = ""
        except OSError:
            self.kind = ""
        if not self.kind:
            self._remove_cgroups()
            self.cgroups = []

    def _apply(self) -> bool:
        lim = self.limits
        if len(self.cgroups) == 1:  # v2
            c = self.cgroups[0]
            ok = _write(c / "memory.max", str(lim.memory_bytes)) and _write(c / "pids.max", str(lim.processes))
            _write(c / "memory.swap.max", "0")
            return ok
        mem, pids = self.cgroups
        ok = _write(mem / "memory.limit_in_bytes", str(lim.memory_bytes))
        if (mem / "memory.memsw.limit_in_bytes").exists():
            _write(mem / "memory.memsw.limit_in_bytes", str(lim.memory_bytes))
        return ok and _write(pids / "pids.max", str(lim.processes))

    def wrap(self, argv: list) -> list:
        """``argv`` run from a launcher that first moves itself into this submission's cgroup(s)."""
        if not self.cgroups:
            return list(argv)
        joins = " && ".join(f'echo $$ > "${k + 1}"' for k in range(len(self.cgroups)))
        n = len(self.cgroups)
        script = f'{joins} && shift {n} && exec "$@"'
        return ["/bin/sh", "-c", script, "sh", *[str(c / "cgroup.procs") for c in self.cgroups], *argv]

    def rlimits(self) -> dict:
        """The kernel's rlimits: per-process address space (a backstop; the cgroup limits the sum), file size,
        and, without a cgroup, the number of processes."""
        files = self.limits.files
        if self.cgroups:  # the cgroup stops the sum first; this only stops one runaway mapping
            return {"as": self.limits.memory_bytes + 2 * 2**30, "fsize": self.limits.disk_bytes, "nofile": files}
        # without one: per process only (an IPython kernel with NumPy and SymPy maps ~1 GiB before any answer)
        as_ = max(self.limits.memory_bytes, 3 * 2**30)
        return {"as": as_, "fsize": self.limits.disk_bytes, "nproc": self.limits.processes, "nofile": files}

    def describe(self) -> str:
        """Which limits are in force, in words."""
        lim = self.limits
        how = f"cgroup {self.kind}" if self.kind else "rlimits only: memory per process, not in all"
        disk = "one tmpfs for every writable folder" if self.tmpfs else "per file only (no tmpfs: not root)"
        return f"limits: {lim.words()} ({how}; writes: {disk})"

    def reached(self) -> list[str]:
        """The limits this submission reached, in words for its feedback (empty when none)."""
        lim, out = self.limits, []
        if self.kind == "v2":
            c = self.cgroups[0]
            oom, pmax = _counter(c / "memory.events", "oom_kill"), _counter(c / "pids.events", "max")
        elif self.kind == "v1":
            oom, pmax = _counter(self.cgroups[0] / "memory.oom_control", "oom_kill"), 0
            pmax = _counter(self.cgroups[1] / "pids.events", "max")
        else:
            oom = pmax = 0
        if oom:
            out.append(
                f"memory: the submission's processes used more than {_size(lim.memory_bytes)} in all; "
                f"{oom} process(es) killed"
            )
        if pmax:
            out.append(f"processes: more than {lim.processes} at once; {pmax} new process(es) refused")
        if self.tmpfs and self._disk_full():
            out.append(f"disk: more than {_size(lim.disk_bytes)} written in all; further writes failed (no space)")
        return out

    def _disk_full(self) -> bool:
        try:
            st = os.statvfs(self.folder)
        except OSError:
            return False
        self.peak_free = min(getattr(self, "peak_free", st.f_bavail * st.f_frsize), st.f_bavail * st.f_frsize)
        return self.peak_free < 2**20

    def check_disk(self) -> None:
        """Note how full the tmpfs is now (called after each cell, so a file written then deleted counts)."""
        if self.tmpfs:
            self._disk_full()

    def kill(self) -> list[int]:
        """Kill every process of the submission (its cgroup); returns any still alive."""
        return kill_cgroup(self.cgroups) if self.cgroups else []

    def _remove_cgroups(self) -> None:
        for c in self.cgroups:
            _rmdir_cgroup(c)

    def close(self) -> None:
        """Kill what is left, remove the cgroup, unmount and delete the folder."""
        self.kill()
        self._remove_cgroups()
        if self.tmpfs:
            _umount(self.folder)
        shutil.rmtree(self.folder, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
