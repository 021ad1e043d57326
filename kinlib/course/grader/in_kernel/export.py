"""Kernel side of the grader: each answer leaves the kernel as *data*, never judged here.

The grader (:mod:`kinlib.course.grader.isolation.kernel`) sends this file's source text, with
:mod:`.guard`, into every kernel it starts (the student's and the reference's) and calls, after the last
cell, :func:`restore_saved` and then :func:`export_answer` once per answer. An answer is written to a
JSON file as a tree in the format of :mod:`kinlib.course.answers.wire` (SymPy expressions, matrices,
sets, NumPy arrays, lists, dicts, numbers, strings), which the grader reads back with a whitelist
parser (never ``eval``) and judges in its own process: evaluation at the secret points, comparison with the
reference and the exact check all happen there. This module never receives points, seeds or reference
data; a submission that replaces or patches it can only claim an answer, which scores only if it *is*
the answer.

It imports only the standard library (and SymPy, NumPy and mpmath, to recognise their objects).
"""

import json

__all__ = ["export", "exported", "stash", "export_answer", "restore_saved", "TooLarge", "MAX_NODES", "MAX_DEPTH"]

MAX_NODES = 100_000  # nodes of one answer's tree (the grader refuses more: a wrong/ungradable answer)
MAX_DEPTH = 200  # nesting depth of one answer's tree

_MISSING = object()


class TooLarge(ValueError):
    """The answer has more than MAX_NODES nodes or is nested deeper than MAX_DEPTH.

    >>> exported(list(range(10)), max_nodes=5)
    {'too_large': 'more than 5 nodes'}
    """


def _digits(n):
    try:
        return str(int(n))
    except ValueError:  # more digits than Python converts (4300)
        raise TooLarge("a number with thousands of digits") from None


def _float(x):
    return ["float", repr(float(x))]


def _complex(x):
    x = complex(x)
    return ["complex", repr(x.real), repr(x.imag)]


def _basic(e, walk):
    """A SymPy object: [class name, *args] (numbers, symbols and matrices in their own forms)."""
    import sympy as sp
    from mpmath import libmp

    if isinstance(e, sp.Integer):
        return ["Integer", _digits(e)]
    if isinstance(e, sp.Rational):
        return ["Rational", _digits(e.p), _digits(e.q)]
    if isinstance(e, sp.Float):
        return ["Float", libmp.to_str(e._mpf_, libmp.repr_dps(e._prec)), int(e._prec)]
    if isinstance(e, sp.Symbol) and not isinstance(e, sp.Wild):
        given = getattr(e, "_assumptions_orig", None) or e.assumptions0  # (SymPy < 1.12 has only the latter)
        assumptions = {k: v for k, v in given.items() if isinstance(v, bool)}
        if isinstance(e, sp.Dummy):  # one Dummy, however often it appears (an ImageSet's bound variable)
            return ["Dummy", e.name, assumptions, int(e.dummy_index) % 2**31]
        return ["Symbol", e.name, assumptions]
    if isinstance(e, sp.core.function.AppliedUndef):
        return ["UndefinedFunction", type(e).__name__, *[walk(a) for a in e.args]]
    if isinstance(e, sp.MatrixBase):
        return ["Matrix", int(e.rows), int(e.cols), *[walk(x) for x in e]]
    return [type(e).__name__, *[walk(a) for a in e.args]]


def export(value, max_nodes=MAX_NODES, max_depth=MAX_DEPTH):
    """``value`` as a JSON-able tree (format: :mod:`kinlib.course.answers.wire`); raises TooLarge.

    >>> import sympy as sp
    >>> export(sp.Matrix([[sp.Symbol("L", positive=True), sp.Rational(1, 2)]]))
    ['Matrix', 1, 2, ['Symbol', 'L', {'positive': True}], ['Rational', '1', '2']]
    >>> export([1, (2.5, "a"), {True: None, 3: ...}])
    ['list', ['int', '1'], ['tuple', ['float', '2.5'], ['str', 'a']], ['dict', [['bool', True], ['none']], [['int', '3'], ['ellipsis']]]]
    """
    import numbers

    import numpy as np
    import sympy as sp

    count = [0]

    def walk(v, depth=0):
        count[0] += 1
        if count[0] > max_nodes or depth > max_depth:
            raise TooLarge(
                f"more than {max_nodes} nodes" if count[0] > max_nodes else f"nested deeper than {max_depth}"
            )

        def sub(x):
            return walk(x, depth + 1)

        if v is None:
            return ["none"]
        if v is Ellipsis:
            return ["ellipsis"]
        if isinstance(v, (bool, np.bool_)):
            return ["bool", bool(v)]
        if isinstance(v, (int, np.integer)):
            return ["int", _digits(v)]
        if isinstance(v, (float, np.floating)):
            return _float(v)
        if isinstance(v, (complex, np.complexfloating)):
            return _complex(v)
        if isinstance(v, str):
            return ["str", v[:10_000]]
        if isinstance(v, (sp.Basic, sp.MatrixBase)):
            return _basic(v, sub)
        if isinstance(v, np.ndarray):
            return ["ndarray", list(v.shape), *[sub(x) for x in v.ravel().tolist()]]
        if isinstance(v, (list, tuple, set, frozenset)):
            kinds = ((list, "list"), (tuple, "tuple"), (frozenset, "frozenset"), (set, "set"))
            return [next(n for t, n in kinds if isinstance(v, t)), *[sub(x) for x in v]]
        if isinstance(v, dict):
            return ["dict", *[[sub(k), sub(x)] for k, x in v.items()]]
        if isinstance(v, numbers.Number) or hasattr(v, "_sympy_") or type(v).__module__.startswith("mpmath"):
            try:  # mpmath numbers, fractions, objects that say what they are in SymPy terms
                return sub(sp.sympify(v, strict=True))
            except Exception:  # noqa: BLE001
                pass
        screws = getattr(v, "screws", None)  # a robot (kinlib SerialChain or alike): its screw axes cross
        if isinstance(screws, (sp.MatrixBase, np.ndarray)):
            return ["robot", sub(screws)]
        t = type(v)
        return ["other", t.__qualname__ if t.__module__ == "builtins" else f"{t.__module__}.{t.__qualname__}"]

    return walk(value)


# ----------------------------------------------------------------------------- entry points called by the grader

STASH = {}
SNAP = None


def stash(ns, names):
    """Keep the values of ``names`` as they are when their part ends (read by :func:`export_answer`).

    A shallow copy, so later cells that change or rebind the name do not change the answer:

    >>> ns = {"J": [1, 2]}
    >>> stash(ns, ["J", "K"])
    >>> ns["J"].append(3); ns["J"] = 0
    >>> STASH.pop("J")
    [1, 2]
    """
    import copy

    for n in names:
        if n in ns:
            try:
                STASH[n] = copy.copy(ns[n])
            except Exception:  # noqa: BLE001
                STASH[n] = ns[n]


def _value(ns, name):
    """The answer as it was when its part ended; the final value if it was not there yet (or ``...``)."""
    v = STASH.get(name, _MISSING)
    if v is _MISSING or v is Ellipsis:
        final = ns.get(name, _MISSING)
        if final is not _MISSING and final is not Ellipsis:
            return final
    return v if v is not _MISSING else ns.get(name, _MISSING)


def exported(value, max_nodes=MAX_NODES):
    """What :func:`export_answer` writes for ``value``: ``{"tree": ...}``, ``{"too_large": why}`` or ``{"error": why}``.

    >>> exported(list(range(MAX_NODES)))
    {'too_large': 'more than 100000 nodes'}
    """
    try:
        return {"tree": export(value, max_nodes)}
    except TooLarge as exc:
        return {"too_large": str(exc)}
    except Exception as exc:  # noqa: BLE001  (whatever the object raises)
        return {"error": f"{type(exc).__name__}: {exc}"[:300]}


def export_answer(ns, name, path):
    """Write ``{"tree": export(answer)}`` (or ``{"missing": true}``, ``{"error": ...}``) as JSON to ``path``.

    >>> import pathlib, tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = pathlib.Path(d, "r.json")
    ...     export_answer({"n": 2}, "n", path)
    ...     print(path.read_text())
    ...     export_answer({}, "J", path)
    ...     print(path.read_text())
    {"tree": ["int", "2"]}
    {"missing": true}
    """
    value = _value(ns, name)
    res = {"missing": True} if value is _MISSING else exported(value)
    _write(path, json.dumps(res))


def _write(path, text):
    """Write ``text`` to ``path``: in place when the grader allocated the file beforehand (its blocks are kept,
    so a full disk cannot stop the answer being written), then cut to its length; else a new file.

    >>> import pathlib, tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = pathlib.Path(d, "r.json")
    ...     _ = path.write_bytes(b" " * 100)
    ...     _write(path, "{}")
    ...     path.read_text()
    '{}'
    """
    try:
        f = open(path, "r+")  # noqa: SIM115
    except FileNotFoundError:
        f = open(path, "w")  # noqa: SIM115
    with f:
        f.write(text)
        f.truncate()


def restore_saved(path):
    """Put back what the snapshot taken before the first cell saved (:func:`guard.restore`); write which names
    the notebook had replaced. Without a snapshot (the reference kernel) nothing is restored:

    >>> import pathlib, tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = pathlib.Path(d, "r.json")
    ...     restore_saved(path)
    ...     print(path.read_text())
    {"restored": []}
    """
    names = guard.restore(SNAP) if SNAP is not None else []  # noqa: F821  (bound by the grader in a kernel)
    _write(path, json.dumps({"restored": names[:50]}))


if "guard" not in globals():  # imported as a package module (tests, the host); in a kernel the grader binds it
    from . import guard  # noqa: E402
