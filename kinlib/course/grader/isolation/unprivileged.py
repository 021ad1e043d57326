"""Without bubblewrap: the student's kernel runs as an unprivileged user of its own.

Docker's default seccomp profile blocks the namespaces bubblewrap needs (containers/bubblewrap #505), so in a
Gradescope or PrairieLearn container the grader cannot count on :mod:`.sandbox`. The usual fallback (it is what
PrairieLearn's own Python grader does) is a second user: the grader runs as root and keeps the key, the
references and the results in folders only root can read (the bundle's set-up script and
:func:`kinlib.course.lms.bundles.run_platform` see to that); each kernel is started as :class:`StudentUser`
(``setgroups([])``, ``setgid``, ``setuid``, a clean environment) in a scratch folder given to that user; and
:meth:`StudentUser.end_all` kills **every** process of that user (daemons included: they cannot hide from a
``kill(-1)`` sent as the user itself) and checks that none is left, after each kernel and before any result is
written.

The user is created by the bundle's ``setup.sh`` (:data:`DEFAULT_NAME`); nothing here creates users.

>>> StudentUser.lookup("no-such-user-kinlib") is None
True
"""

from __future__ import annotations

import os
import pwd
import subprocess
import sys
from dataclasses import dataclass

from .reap import kill_until_gone

__all__ = ["DEFAULT_NAME", "StudentUser", "UnprivilegedUnavailable"]

DEFAULT_NAME = "kinlib-student"  # the user the bundles' setup.sh creates (useradd --system)


class UnprivilegedUnavailable(RuntimeError):
    """The grader cannot run the student's code as another user here (not root, or no such user).

    >>> str(UnprivilegedUnavailable("no user kinlib-student"))
    'no user kinlib-student'
    """


@dataclass(frozen=True)
class StudentUser:
    """An unprivileged account (uid and gid, never 0) the student's kernels run as.

    >>> u = StudentUser("ann", 1234, 1234)
    >>> u.popen_kwargs()
    {'user': 1234, 'group': 1234, 'extra_groups': []}
    >>> StudentUser("root", 0, 0)
    Traceback (most recent call last):
    ...
    ValueError: uid and gid of the student's user must not be 0 (root), got 0 and 0
    """

    name: str
    uid: int
    gid: int

    def __post_init__(self):
        if self.uid == 0 or self.gid == 0:
            raise ValueError(f"uid and gid of the student's user must not be 0 (root), got {self.uid} and {self.gid}")

    @classmethod
    def lookup(cls, name: str = DEFAULT_NAME) -> StudentUser | None:
        """The account ``name`` from the password database, or None if there is none (or it is root)."""
        try:
            pw = pwd.getpwnam(name)
        except KeyError:
            return None
        if pw.pw_uid == 0 or pw.pw_gid == 0:
            return None
        return cls(name, pw.pw_uid, pw.pw_gid)

    @classmethod
    def require(cls, name: str = DEFAULT_NAME) -> StudentUser:
        """:meth:`lookup`, or :class:`UnprivilegedUnavailable` saying why the grader cannot switch users."""
        if os.geteuid() != 0:
            raise UnprivilegedUnavailable(
                f"without the sandbox the student's code must run as the user {name}, which needs the grader "
                "to run as root (Gradescope's run_autograder and PrairieLearn's entrypoint do)"
            )
        user = cls.lookup(name)
        if user is None:
            raise UnprivilegedUnavailable(f"no unprivileged user {name!r}: the bundle's setup.sh creates it")
        return user

    def popen_kwargs(self) -> dict:
        """``subprocess.Popen`` arguments that start a process as this user, with no supplementary groups."""
        return {"user": self.uid, "group": self.gid, "extra_groups": []}

    def give(self, *paths) -> None:
        """Make ``paths`` (folders: with everything in them; links never followed) this user's, mode 0700."""
        for top in paths:
            top = os.fspath(top)
            if os.path.isdir(top) and not os.path.islink(top):
                for d, dirs, files in os.walk(top):
                    for n in dirs + files:
                        os.lchown(os.path.join(d, n), self.uid, self.gid)
            os.lchown(top, self.uid, self.gid)
            if not os.path.islink(top):
                os.chmod(top, 0o700 if os.path.isdir(top) else 0o600)

    def environment(self, home: str, extra: dict) -> dict:
        """The kernel's whole environment: PATH, locale, a HOME in its scratch folder, plus ``extra``."""
        env = {
            "PATH": os.pathsep.join([os.path.dirname(sys.executable), "/usr/local/bin", "/usr/bin", "/bin"]),
            "HOME": home,
            "IPYTHONDIR": os.path.join(home, ".ipython"),
            "MPLCONFIGDIR": os.path.join(home, ".matplotlib"),
            "LANG": "C.UTF-8",
            "USER": self.name,
            "LOGNAME": self.name,
        }
        env.update(extra)
        return env

    def processes(self) -> list[int]:
        """PIDs of the live (not zombie) processes owned by this user."""
        found = []
        for d in os.listdir("/proc"):
            if not d.isdigit():
                continue
            try:
                if os.stat(f"/proc/{d}").st_uid != self.uid:
                    continue
                with open(f"/proc/{d}/stat") as f:
                    state = f.read().rsplit(")", 1)[-1].split()[0]
            except (OSError, IndexError):
                continue
            if state not in ("Z", "X"):
                found.append(int(d))
        return found

    def _kill_as_user(self) -> None:
        """``kill(-1, SIGKILL)`` sent by a process of this user: every process it may signal, i.e. all of its own."""
        code = "import os, signal\nos.kill(-1, signal.SIGKILL)"
        try:
            subprocess.run(
                [sys.executable, "-I", "-S", "-c", code],
                env={"PATH": "/usr/bin:/bin"},
                cwd="/",
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                timeout=30,
                **self.popen_kwargs(),
            )
        except (OSError, subprocess.SubprocessError):
            pass

    def end_all(self, timeout: float = 15.0) -> list[int]:
        """Kill every process of this user and wait until none is left (or ``timeout``); returns the PIDs still
        alive (empty when all are gone). Root's SIGKILLs by PID alone could race a process that forks; the
        user's own ``kill(-1)`` reaches every process of the user at once."""
        return kill_until_gone(self.processes, timeout, each_round=self._kill_as_user)
