"""Self-checks for student workbooks: is an answer right, without revealing it.

At build time (``kinlib handouts``) each reference answer is turned into a *fingerprint*:
the answer evaluated at fixed sample values of its symbols (the same values for a symbol of the same
name, whatever its assumptions), rounded to 8 significant digits and hashed (SHA-256). The sample values
cover the domains the grader's secret points are drawn from (:func:`kinlib.course.answers.kinds.draw_points`:
joint angles over a whole turn, one sample in each fifth, lengths in (0.5, 2), the reference's signed symbols
across 0), so the two judges agree: |det J| for det J, a signed manipulability, fail at home as in the grade
(tests/answer_table.py is the table both must agree on). The workbook holds only the fingerprint; the student's
answer is fingerprinted the same way when the self-check cell runs, so a right answer in any equivalent form
(simplified or not, exact, or decimals within the grader's tolerance: with a note) passes::

    from kinlib.course.workbook.selfcheck import check
    check("2.2", Js="matrix|6x3|3f0c1b9e5a7d2c44")

Kinds of answer (``kinds`` in the solution cell's ``kinlib`` metadata). Each kind is one module of
:mod:`kinlib.course.answers`, which the grader uses too: its normaliser, its canonical form at the public sample
points (``home_canon``), its verdict and the words for its mistakes (``home_verdict``) and its stub's words
(``stub_words``); this module only dispatches through the table of kinds (:data:`kinlib.course.answers.kinds.KINDS`)
and prints. The sample points, rounding and hashes are :mod:`kinlib.course.answers.fingerprints`.

- default / ``"expr"``: a SymPy Matrix, expression or number, compared as a function of its symbols;
- ``"choice"``: an int, string or tuple of them (joint numbers 1-based; order and repeats ignored);
- ``"set"``: a SymPy Set (or Python set/list of values, a number, a dict {symbol: Set} or a list of
  those dicts), compared through its points in [-2π, 2π] taken modulo 2π (angles), intervals by their
  end points;
- ``"subspace"``: a Matrix whose columns span a subspace, compared through its orthogonal projector;
- ``"property:<p>"``: the student's own design (5.5) judged as the grader does (:mod:`..answers.properties`).

A wrong answer is tried against the known mistakes of :mod:`kinlib.course.answers.mistakes` (transposed, wrong
sign, [v; ω] order, columns swapped, degrees, wrong shape, ...; the instructor checker uses the same):
each undone version of the student's answer is fingerprinted too, and a match names the mistake ("it is
transposed"), never the answer.

In a workbook, ``%load_ext kinlib.course.workbook.selfcheck`` adds the cell magic ``%%needs NAME...``
(:mod:`kinlib.course.workbook.needs`): the cell runs only once the names it uses from the student's answers are
filled in, and if it fails while their self-check has not passed, says "fix the answer above first".
"""

from __future__ import annotations

import json
import sys

import sympy as sp  # noqa: F401  (the examples below use it)

from ..answers import kinds
from ..answers.base import is_angle_name, is_bool, is_unanswered
from ..answers.fingerprints import (
    SAMPLE_POINTS,
    SIGNED,
    CannotCheck,
    Judge,
    Unanswered,
    WrongForm,
    digest,
    hint_hash,
    sample_value,
    shape_words,
    sym_hash,
    symbols_of,
)
from .needs import answer_status, last_results, needs

__all__ = [
    "check",
    "verdict",
    "fingerprint",
    "describe_answer",
    "emit_fingerprints",
    "Unanswered",
    "CannotCheck",
    "WrongForm",
    "KINDS",
    "FINGERPRINT_MARK",
    "SAMPLE_POINTS",
    "last_results",
    "sample_value",
    "load_ipython_extension",
]

FINGERPRINT_MARK = "KINLIB-SELFCHECK "  # starts the line emit_fingerprints prints (read by the handouts)
KINDS = kinds.NAMES  # the kind names a solution notebook may declare (the table of kinds)


def fingerprint(value, kind: str = "default", salt: str = "") -> str:
    """The spec string of ``value``: ``"<form>|<shape>|<hash>"``, and for an answer with symbols
    ``"|<symbols' hash>|<signed symbols>"`` (no information about the value itself).

    ``form`` is matrix/scalar/bool/choice/set/subspace (the kind's ``home_canon``); ``shape`` is ``"6x3"`` for a
    matrix, the ambient dimension for a subspace, ``"dict"`` for a dict of sets (``"union"`` for a list of them).
    ``salt`` (the workbooks use ``"part:name"``) makes equal answers to different questions hash differently. The
    symbols' hash lets the self-check say, as the grader does, that an answer misses a variable ("did you
    substitute L = 1?") or is a constant; the signed symbols (not lengths, not joint angles: forces, velocities)
    are sampled on both sides of 0, as the grader's points are (:func:`sample_value`).

    >>> fingerprint(sp.Matrix([[1, 2, 3]]), salt="1.1:v")[:11]
    'matrix|1x3|'
    >>> fingerprint((2, 1), "choice") == fingerprint([1, 2, 2], "choice")
    True
    >>> fingerprint(sp.Symbol("F_x", real=True) * sp.Symbol("L", positive=True), salt="7.4:tau").split("|")[4]
    'F_x'
    >>> fingerprint(...)
    Traceback (most recent call last):
        ...
    kinlib.course.answers.fingerprints.Unanswered: the value is missing or ...
    >>> fingerprint(sp.Function("f")(sp.Symbol("t")))
    Traceback (most recent call last):
        ...
    kinlib.course.answers.fingerprints.CannotCheck: it does not evaluate to a number (Cannot convert expression to float)
    >>> fingerprint([[1, 2], [3]])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    kinlib.course.answers.fingerprints.WrongForm: it should be a SymPy Matrix, expression or number, yours is a list of ...
    """
    if is_unanswered(value):
        raise Unanswered("the value is missing or ...")
    k, arg = kinds.find(kind)
    if k.home_spec is not None:
        return k.home_spec(value, arg, salt)
    syms = symbols_of(value) if k.symbols else set()
    signed = sorted(x.name for x in syms if not x.is_positive and not is_angle_name(x.name))
    token = SIGNED.set(frozenset(signed))
    try:
        form, shape, canon = k.home_canon(value)
        hints = k.home_hints(value) if k.home_hints is not None else {}
    finally:
        SIGNED.reset(token)
    spec = f"{form}|{shape}|{digest(form, canon, salt)}"
    if syms or hints:
        spec += f"|{sym_hash([x.name for x in syms], salt) if syms else ''}|{','.join(signed)}"
    if hints:
        spec += "|" + ",".join(f"{n}={hint_hash(n, c, salt)}" for n, c in sorted(hints.items()))
    return spec


def describe_answer(value, kind: str = "default") -> str:
    """A short description of the form of an answer (for the workbook's stub), e.g. 'a 6×3 Matrix': the kind's
    ``stub_words`` (a yes/no answer is "True or False" whatever its declared kind).

    >>> describe_answer(sp.zeros(6, 3)), describe_answer(3, "choice"), describe_answer({sp.Symbol("t"): {0}}, "set")
    ('a 6×3 Matrix', 'a joint number or a tuple of joint numbers (1-based)', 'a dict {symbol: SymPy Set}')
    >>> describe_answer(False, "choice"), describe_answer([{sp.Symbol("t"): {0}}], "set")
    ('True or False', 'a list of dicts {symbol: SymPy Set}, one per condition ([] for none)')
    """
    k, _ = kinds.lookup(kind)
    if k.home_spec is None and is_bool(value):
        return "True or False"
    return k.stub(value)


# ---------------------------------------------------------------------------------------------------
# The student's side.


def _parse_spec(spec: str):
    """(form, shape, digest, symbols' hash or None, signed symbols, hints) of a spec (3 fields: an answer without
    symbols, or a spec made before the symbols were recorded; 6: with the hashes of the right answer's invariants
    that name a typical mistake, ``name=hash`` separated by commas)."""
    fields = spec.split("|") if isinstance(spec, str) else []
    if len(fields) == 3:
        return (*fields, None, frozenset(), {})
    if len(fields) in (5, 6):
        form, shape, digest_, symhash, signed = fields[:5]
        hints = dict(h.partition("=")[::2] for h in fields[5].split(",") if "=" in h) if len(fields) == 6 else {}
        return form, shape, digest_, symhash or None, frozenset(x for x in signed.split(",") if x), hints
    raise ValueError(f"a self-check spec looks like 'matrix|6x3|<16 hex digits>', got {spec!r}")


def verdict(value, spec: str, salt: str = "") -> tuple[str, str]:
    """``(status, message)`` for an answer against a spec; status is correct/incorrect/unanswered/error.

    The kind that made the spec's form judges it (its ``home_verdict``): a wrong answer is tried against the
    known mistakes (:mod:`kinlib.course.answers.mistakes`: the grader's too); the message names the mistake,
    never the answer.

    >>> spec = fingerprint(sp.Rational(1, 2), salt="1.1:x")
    >>> verdict(sp.Rational(1, 2), spec, salt="1.1:x"), verdict(..., spec, salt="1.1:x")[0]
    (('correct', 'correct'), 'unanswered')
    >>> verdict(-sp.Rational(1, 2), spec, salt="1.1:x")
    ('incorrect', 'not right yet: it has the wrong sign')
    >>> verdict(0.5, spec, salt="1.1:x")[1]
    'correct; note: it contains decimals (floats): exact values (sp.Rational, sp.sqrt, sp.pi) are safer'
    >>> f = sp.Function("f")(sp.Symbol("t"))
    >>> verdict(f, fingerprint(sp.Symbol("t")))
    ('error', 'cannot check it automatically: it does not evaluate to a number (Cannot convert expression to float)')
    """
    form, shape, digest_, symhash, signed, hints = _parse_spec(spec)
    if is_unanswered(value):
        return "unanswered", "not answered yet"
    if form == "none":
        return "error", "this answer has no automatic self-check: compare it with the worked solution"
    kind = kinds.FORMS.get(form)
    if kind is None:
        raise ValueError(f"unknown answer form {form!r} in spec {spec!r}")
    token = SIGNED.set(signed)
    try:
        return kinds.KINDS[kind].home_verdict(value, Judge(form, shape, digest_, salt, symhash, hints))
    except WrongForm as e:
        return "incorrect", f"wrong form: {e}"
    except CannotCheck as e:
        return "error", f"cannot check it automatically: {e}"
    except Exception as e:  # anything the student's object throws while being evaluated
        return "error", f"could not evaluate your answer ({type(e).__name__}: {e})"
    finally:
        SIGNED.reset(token)


def check(part: str, /, _namespace: dict | None = None, **specs: str) -> None:
    """Print for each answer variable of ``part`` whether it is right; never shows the answer.

    ``specs`` maps variable names to fingerprints made at build time; the variables are looked up
    in the caller's globals (the notebook), so a missing variable reads as "not answered yet".

    >>> check("1.1", _namespace={"x": sp.Rational(1, 2)}, x=fingerprint(sp.Rational(1, 2), salt="1.1:x"))
    part 1.1 · x: ✓ correct
    >>> check("1.1", _namespace={}, J=fingerprint(sp.eye(2), salt="1.1:J"))
    part 1.1 · J: … not answered yet: replace the ... in `J = ...` above with your answer (a 2×2 matrix)
    >>> check("1.1", _namespace={"J": sp.eye(3)}, J=fingerprint(sp.eye(2), salt="1.1:J"))
    part 1.1 · J: ✗ wrong form: it should be a 2×2 matrix, yours is a 3×3 matrix (J Jᵀ is task × task, Jᵀ J joints × joints: the product in the other order?)
    """
    ns = _namespace if _namespace is not None else sys._getframe(1).f_globals
    results = {}
    for name, spec in specs.items():
        value = ns.get(name, Ellipsis)
        status, message = verdict(value, spec, salt=f"{part}:{name}")
        results[name] = status
        mark = {"correct": "✓", "incorrect": "✗", "unanswered": "…", "error": "?"}[status]
        if status == "unanswered":
            form, shape = _parse_spec(spec)[:2]
            what = (
                shape_words(shape)
                if form in ("matrix", "scalar")
                else "your robot itself, a kinlib SerialChain"
                if form == "property"
                else ("see the question" if form == "none" else "True or False" if form == "bool" else f"a {form}")
            )
            message = f"not answered yet: replace the ... in `{name} = ...` above with your answer ({what})"
        print(f"part {part} · {name}: {mark} {message}")
    last_results[part] = results


# ---------------------------------------------------------------------------------------------------
# Build side: used by kinlib.course.publish.handouts inside the kernel, right after a part's solution cells ran.


def emit_fingerprints(specs: dict, ns: dict) -> None:
    """Print one line, ``FINGERPRINT_MARK`` and the JSON {name: {"spec", "describe"} | {"error"}}, for
    the answers ``specs`` = {name: (kind, part)} found in the namespace ``ns``.

    >>> emit_fingerprints({"n": ("choice", "1.2")}, {})
    KINLIB-SELFCHECK {"n": {"error": "the solution cells did not define n"}}
    """
    out = {}
    for name, (kind, part) in specs.items():
        if name not in ns:
            out[name] = {"error": f"the solution cells did not define {name}"}
            continue
        try:
            out[name] = {
                "spec": fingerprint(ns[name], kind, salt=f"{part}:{name}"),
                "describe": describe_answer(ns[name], kind),
            }
        except Exception as e:
            out[name] = {"error": f"{type(e).__name__}: {e}"}
    print(FINGERPRINT_MARK + json.dumps(out))


# ---------------------------------------------------------------------------------------------------
# The workbook extension


def load_ipython_extension(ip) -> None:
    """``%load_ext kinlib.course.workbook.selfcheck``: registers the ``%%needs NAME...`` cell magic
    (:func:`kinlib.course.workbook.needs.needs`: skips a cell until its answers are filled in, and turns an error in
    it into "fix the answer above first" while the self-check has not passed them).

    IPython calls it with the shell; any object with ``register_magic_function`` does here:

    >>> class Shell:
    ...     def register_magic_function(self, func, magic_kind, magic_name):
    ...         print(magic_kind, magic_name)
    >>> load_ipython_extension(Shell())
    cell needs
    """

    def _needs(line: str, cell: str):
        return needs(line, cell, ip, status=answer_status)

    ip.register_magic_function(_needs, magic_kind="cell", magic_name="needs")
