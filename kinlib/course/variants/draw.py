"""A student's variant: drawn from HMAC(course secret, student id, notebook), reproducible and unguessable.

The digest (256 bits) is read as one integer and spent digit by digit in the mixed radix of the choices (the
parameters in the order the spec writes them, then their elements), so every variant of the spec can be drawn and
each is equally likely up to 2^-200. A draw the proof rejects is redrawn with ``attempt`` 1, 2, …: the same
student always gets the same sequence, so the grader finds the variant the build proved.

>>> from kinlib.course.variants.spec import Spec
>>> spec = Spec.from_metadata({"params": {"q": {"type": "angle", "choices": [["1/4", "-1/4", "3/4"], ["0", "1/2"]]}},
...                            "original": {"q": ["1/4", "0"]}})
>>> a = draw(b"s" * 32, "ada", "05_planar", spec)
>>> a == draw(b"s" * 32, "ada", "05_planar", spec), spec.param("q").domain(a["q"])
(True, True)
>>> len(variant_key(a))
12
"""

from __future__ import annotations

import hashlib
import hmac

from .spec import Spec, canonical

__all__ = ["draw", "variant_key", "PURPOSE"]

PURPOSE = b"kinlib-variant"


def draw(secret: bytes, student_id: str, notebook_id: str, spec: Spec, attempt: int = 0) -> dict:
    """The values of ``student_id``'s variant of ``notebook_id`` (its ``attempt``-th draw).

    >>> spec = Spec.from_metadata({"params": {"L": {"type": "number", "choices": [str(k) for k in range(1, 9)]}},
    ...                            "original": {"L": "1"}})
    >>> sorted({draw(b"k" * 32, f"s{i}", "02", spec)["L"] for i in range(60)}) == [str(k) for k in range(1, 9)]
    True
    >>> draw(b"short", "ada", "02", spec)
    Traceback (most recent call last):
        ...
    ValueError: secret: expected the course secret (at least 16 bytes)
    """
    if not isinstance(secret, bytes) or len(secret) < 16:
        raise ValueError("secret: expected the course secret (at least 16 bytes)")
    for name, v in (("student_id", student_id), ("notebook_id", notebook_id)):
        if not isinstance(v, str) or not v or "\0" in v:
            raise ValueError(f"{name}: expected a non-empty string without NUL")
    if not isinstance(attempt, int) or attempt < 0:
        raise ValueError("attempt: expected an integer >= 0")
    msg = b"\0".join([PURPOSE, notebook_id.encode(), student_id.encode(), str(attempt).encode()])
    n = int.from_bytes(hmac.new(secret, msg, hashlib.sha256).digest(), "big")
    values: dict = {}
    for p in spec.params:
        got = []
        for choices in p.choices:
            n, k = divmod(n, len(choices))
            got.append(choices[k])
        values[p.name] = got if p.vector else got[0]
    return values


def variant_key(values) -> str:
    """A variant's name in files and the key: 12 hex digits of the SHA-256 of its canonical JSON.

    >>> variant_key({"L": "1"}) == variant_key({"L": "1"}) != variant_key({"L": "2"})
    True
    """
    return hashlib.sha256(canonical(values).encode()).hexdigest()[:12]
