"""The instructor's grading secret: keys the reference cache and chooses each submission's evaluation points.

The secret is 32 random bytes (hex) in a file only its owner can read, outside anything a student kernel
sees: ``$XDG_CONFIG_HOME/kinlib/grader-secret`` (default ``~/.config/kinlib/grader-secret``), the file
named by ``$KINLIB_GRADER_SECRET`` (the test suite's), or a path given with ``kinlib grade --secret``. It is created on first use (mode 0600). From it:

* :func:`sign` / :func:`verify`: an HMAC-SHA256 tag over the reference cache, so a cache file edited by
  anyone without the secret is rejected (and rebuilt) instead of trusted;
* :func:`evaluation_seed`: the seed of a submission's random evaluation points, HMAC(secret, submission
  bytes), so the points cannot be computed from the file alone (a student cannot search offline for a
  wrong answer that agrees with the right one at the grader's points). The workbook self-checks use
  other, public points (:mod:`kinlib.course.workbook.selfcheck`).
"""

from __future__ import annotations

import hashlib
import hmac
import os
import stat
from pathlib import Path

__all__ = ["default_secret_path", "load_secret", "sign", "verify", "evaluation_seed"]


def default_secret_path() -> Path:
    """``$KINLIB_GRADER_SECRET`` if set, else ``$XDG_CONFIG_HOME/kinlib/grader-secret``
    (``~/.config/kinlib/grader-secret`` when unset).

    >>> default_secret_path().name in ("grader-secret", os.environ.get("KINLIB_GRADER_SECRET", "-").split("/")[-1])
    True
    """
    if os.environ.get("KINLIB_GRADER_SECRET"):
        return Path(os.environ["KINLIB_GRADER_SECRET"])
    base = os.environ.get("XDG_CONFIG_HOME") or os.path.join(os.path.expanduser("~"), ".config")
    return Path(base) / "kinlib" / "grader-secret"


def load_secret(path=None, create: bool = True) -> bytes:
    """The secret in ``path`` (default :func:`default_secret_path`), created (mode 0600) if missing.

    A file that others can read or write is refused (ValueError), as is one shorter than 16 bytes:

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     s = load_secret(Path(d) / "k")
    ...     len(s), s == load_secret(Path(d) / "k"), oct((Path(d) / "k").stat().st_mode & 0o777)
    (64, True, '0o600')
    """
    p = Path(path) if path is not None else default_secret_path()
    if not p.exists():
        if not create:
            raise FileNotFoundError(f"no grader secret at {p}")
        p.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
        # written in full under a private name, then linked into place: another grader starting at the same
        # moment either makes the link itself or reads the whole secret, never an empty file
        tmp = p.with_name(f".{p.name}.{os.getpid()}.{os.urandom(4).hex()}")
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        try:
            with os.fdopen(fd, "w") as f:
                f.write(os.urandom(32).hex() + "\n")
            os.link(tmp, p)
        except FileExistsError:  # created meanwhile by another grader: use that one
            pass
        except OSError:  # a file system without hard links: moved into place instead
            if not p.exists():
                os.rename(tmp, p)
        finally:
            tmp.unlink(missing_ok=True)
    fd = os.open(p, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    with os.fdopen(fd, "rb") as f:
        st = os.fstat(f.fileno())
        if not stat.S_ISREG(st.st_mode):
            raise ValueError(f"the grader secret {p} is not a regular file")
        if st.st_mode & 0o077:
            raise ValueError(
                f"the grader secret {p} is readable or writable by others (mode {oct(st.st_mode & 0o777)}); "
                f"run: chmod 600 {p}"
            )
        data = f.read(4096).strip()
    if len(data) < 16:
        raise ValueError(f"the grader secret {p} is too short ({len(data)} bytes; expected 64 hex digits)")
    return data


def sign(secret: bytes, purpose: str, data: bytes) -> str:
    """HMAC-SHA256 of ``data`` for ``purpose`` (a label, so one tag is never valid for another use), in hex.

    >>> sign(b"k" * 32, "cache", b"{}")[:16]
    '212b3ce380360c07'
    """
    return hmac.new(secret, purpose.encode() + b"\0" + data, hashlib.sha256).hexdigest()


def verify(secret: bytes, purpose: str, data: bytes, tag) -> bool:
    """Whether ``tag`` is :func:`sign`'s tag of ``data`` (constant-time comparison).

    >>> tag = sign(b"k" * 32, "cache", b"{}")
    >>> verify(b"k" * 32, "cache", b"{}", tag), verify(b"k" * 32, "cache", b"{ }", tag), verify(b"k" * 32, "x", b"{}", 1)
    (True, False, False)
    """
    return isinstance(tag, str) and hmac.compare_digest(sign(secret, purpose, data), tag)


def evaluation_seed(secret: bytes, submission: bytes) -> int:
    """The seed of a submission's evaluation points: HMAC(secret, bytes), 60 bits (never the file alone).

    >>> a = evaluation_seed(b"k" * 32, b"notebook")
    >>> a == evaluation_seed(b"k" * 32, b"notebook"), a == evaluation_seed(b"K" * 32, b"notebook")
    (True, False)
    """
    return int(sign(secret, "points", submission)[:15], 16)
