"""The format in which an answer leaves a kernel, and its parser on the trusted side (never ``eval``).

A kernel (:mod:`kinlib.course.grader.in_kernel.export`, the only grader code shipped into it) writes each
answer as a JSON tree of plain lists; :func:`load` rebuilds the value in the grader from a whitelist, with
caps on size, depth, digits and powers, so a hostile tree cannot run code, nor make the grader build an
object that takes minutes or gigabytes. A tree over a cap raises :class:`WireError` (the answer is then
wrong, with a message that says why).

Nodes (``T`` a tree):

====================================  =================================================================
``["none"]``, ``["ellipsis"]``          None, ``...``
``["bool", b]``                         a bool (also NumPy's)
``["int", "digits"]``                   an int (also NumPy's); ``["float", repr]``, ``["complex", re, im]``
``["str", s]``                          a string (at most :data:`MAX_STR` characters): plain data, never
                                        an expression (no SymPy node takes one, see below)
``["list"|"tuple"|"set"|"frozenset",    Python containers; ``["dict", [T, T], ...]`` a dict
T, ...]``
``["ndarray", [shape], T, ...]``        a NumPy array (entries flattened, row-major)
``["robot", T]``                        a robot (an object with ``screws``, e.g. a kinlib ``SerialChain``):
                                        only its screw axes cross, as the 6×n matrix T (answers judged by a
                                        property of the student's own design, problem 5.5)
``["other", "module.Type"]``            an object of another type (only its type name crosses)
``["Integer", "digits"]``,              SymPy numbers (a Float by its decimal digits and precision in bits)
``["Rational", p, q]``,
``["Float", "digits", prec]``
``["Symbol", name, {a: b}]``            a symbol with its assumptions (known assumption names only; the
                                        name a :func:`safe_name`)
``["Dummy", name, {a: b}, index]``      a dummy symbol: one per (name, index) within the answer
``["UndefinedFunction", name, T...]``   ``Function(name)(T, ...)`` (the name a :func:`safe_name`, not a builtin's)
``["Matrix", rows, cols, T, ...]``      a SymPy matrix (entries row-major)
``["<SymPy class>", T, ...]``           one of :data:`CLASSES` applied to its arguments, or one of
                                        :data:`SINGLETONS` (``["Pi"]``, ``["Reals"]``, ``["BooleanTrue"]``)
====================================  =================================================================

**One format.** The same trees carry a student's answer out of a kernel (:func:`dump` is the kernel's own
encoder, :func:`kinlib.course.grader.in_kernel.export.export`), the reference answers in the grader's signed
cache (:func:`kinlib.course.answers.describe.dump_reference`) and, restricted to the subset a proof reads
(numbers, symbols, π, +, ×, small powers, sin/cos/tan: :func:`exact_dump`, :func:`exact_load`), the exact
matrices of ``property`` and ``subspace`` answers; every one is read back by :func:`load`.

**Typed, never evaluated.** SymPy's constructors ``sympify`` their arguments, and ``sympify`` of a string is
``parse_expr``, i.e. ``eval``. So a SymPy node (``Matrix``, ``UndefinedFunction`` and every one of
:data:`CLASSES`) is built only from arguments that are already SymPy objects made by this parser (numbers,
symbols, singletons, other SymPy nodes; a matrix inside a set as an immutable matrix): a string, a Python number,
list, dict or any other plain value as an argument is refused (the kernel's exporter never writes one there).
Names (of symbols, dummies and undefined functions) are :func:`safe_name` s, so whatever later prints,
lambdifies or reports them sees an identifier, never code, a quote or a newline. Plain strings stay plain
``str`` values in plain containers; the kinds' normalisers convert container entries with
:func:`kinlib.course.answers.base.as_sympy` (``strict``: a string raises, it is never parsed).

>>> load(["Matrix", 1, 2, ["Symbol", "L", {"positive": True}], ["Rational", "1", "2"]])
Matrix([[L, 1/2]])
>>> load(["other", "os.system"])
<other: os.system>
>>> load(["sin", ["str", "__import__('os').system('id')"]])
Traceback (most recent call last):
...
kinlib.course.answers.wire.WireError: sin takes SymPy values, not a str
>>> load(["Pow", ["Integer", "10"], ["Integer", "100000000"]])
Traceback (most recent call last):
...
kinlib.course.answers.wire.WireError: a power too large to compute (exponent 100000000)
"""

from __future__ import annotations

import builtins
import json
import keyword
import re
import unicodedata

__all__ = [
    "load",
    "dump",
    "exact_dump",
    "exact_load",
    "safe_name",
    "WireError",
    "Other",
    "Robot",
    "MAX_NODES",
    "MAX_DEPTH",
    "MAX_DIGITS",
    "MAX_NAME",
    "CLASSES",
    "SINGLETONS",
]

MAX_NODES = 100_000  # nodes in one answer (a 250,000-point set is refused, not compared for minutes)
MAX_DEPTH = 200  # nesting depth
MAX_DIGITS = 20_000  # digits of all integers of one answer together (and of one number: 1000)
MAX_NUMBER_DIGITS = 1000
MAX_POWER = 1000  # |exponent| of a power of an exact number (of anything else: 100)
MAX_STR = 10_000
MAX_ENTRIES = 40_000  # entries of one matrix or array
MAX_PREC = 4000  # bits of a Float
MAX_NAME = 64  # characters of a symbol's or function's name

CLASSES = (
    # arithmetic and elementary functions
    "Add Mul Pow sin cos tan cot sec csc asin acos atan acot atan2 sinh cosh tanh asinh acosh atanh "
    "exp log Abs sign re im conjugate arg floor ceiling Min Max Piecewise ExprCondPair Mod "
    # relations and logic (an equation given as an answer must be readable to be named)
    "Equality Unequality StrictLessThan LessThan StrictGreaterThan GreaterThan And Or Not "
    # sets of configurations and containers
    "FiniteSet Interval Union Intersection Complement ImageSet Lambda ProductSet ConditionSet Range "
    "Contains Tuple Dict"
).split()
SINGLETONS = (
    "Pi Exp1 ImaginaryUnit Infinity NegativeInfinity ComplexInfinity NaN EulerGamma GoldenRatio Catalan "
    "Reals Integers Naturals Naturals0 Complexes Rationals EmptySet UniversalSet BooleanTrue BooleanFalse "
    "Zero One NegativeOne Half"
).split()
_SINGLETON_ATTR = {"BooleanTrue": "true", "BooleanFalse": "false"}


class WireError(ValueError):
    """The tree is not an answer in this format, or is over a cap (the message says which).

    >>> str(WireError("nested more than 200 levels deep"))
    'nested more than 200 levels deep'
    """


_NAME = re.compile(r"\\?[^\W\d][\w\\{}^]*")  # (\)letter-or-_ then word characters, LaTeX's \ { } ^


def safe_name(name) -> bool:
    r"""Whether ``name`` may name a symbol or an undefined function in an answer: at most :data:`MAX_NAME`
    characters; a letter or ``_`` (optionally after one ``\``), then letters, digits, ``_`` and LaTeX's
    ``\ { } ^`` (``theta_1``, ``θ2``, ``\theta_{2}``, ``x^T``); no ``__`` (no dunder), no keyword, no quote,
    space, newline, dot or bracket, and unchanged by Unicode NFKC (what Python does to identifiers), so it
    prints as one token that is never code.

    >>> [safe_name(n) for n in ("theta1", "θ_2", r"\theta_{2}", "_x0", "L")]
    [True, True, True, True, True]
    >>> [safe_name(n) for n in ("__class__", "x'", "a b", "x\n", "lambda", "os.system", "f()", "", "ｅｘｅｃ")]
    [False, False, False, False, False, False, False, False, False]
    """
    return (
        isinstance(name, str)
        and 0 < len(name) <= MAX_NAME
        and _NAME.fullmatch(name) is not None
        and "__" not in name
        and not keyword.iskeyword(name)
        and unicodedata.normalize("NFKC", name) == name
    )


class Robot:
    """A robot answer as it crossed the boundary: its screw axes (``screws``, what the property judges read).

    >>> load(["robot", ["Matrix", 6, 1, *[["Integer", d] for d in "001000"]]]).screws.T
    Matrix([[0, 0, 1, 0, 0, 0]])
    """

    __slots__ = ("screws",)

    def __init__(self, screws):
        self.screws = screws

    def __repr__(self):
        return f"<robot: {getattr(self.screws, 'shape', '?')} screws>"


class Other:
    """An answer object of a type the format does not carry: only its type name crossed the boundary.

    >>> Other("pandas.DataFrame")
    <other: pandas.DataFrame>
    """

    __slots__ = ("type_name",)

    def __init__(self, type_name: str):
        self.type_name = str(type_name)[:200]

    def __repr__(self):
        return f"<other: {self.type_name}>"


def load(tree, max_nodes: int = MAX_NODES, max_depth: int = MAX_DEPTH):
    """The answer value that ``tree`` describes (see the module's table), or :class:`WireError`.

    >>> load(["list", ["Symbol", "theta1", {"real": True}], ["float", "0.5"], ["str", "joint 2"]])
    [theta1, 0.5, 'joint 2']
    >>> load(["Symbol", "x", {"__class__": True}])
    Traceback (most recent call last):
    ...
    kinlib.course.answers.wire.WireError: unknown assumptions
    """
    import sympy as sp

    left = {"nodes": max_nodes, "digits": MAX_DIGITS * max(1, max_nodes // MAX_NODES)}
    classes = {name: getattr(sp, name, None) or _sympy_class(name) for name in CLASSES}
    dummies: dict = {}  # (name, assumptions, index) -> the one Dummy of that answer

    def bad(why):
        return WireError(why)

    def text(x, cap=MAX_STR):
        if not isinstance(x, str) or len(x) > cap:
            raise bad("malformed text")
        return x

    def integer(x):
        s = text(x, MAX_NUMBER_DIGITS + 1)
        if not s.lstrip("-").isdigit():
            raise bad("malformed integer")
        left["digits"] -= len(s)
        if left["digits"] < 0:
            raise bad(f"numbers with more than {MAX_DIGITS} digits in all")
        return int(s)

    def small(x, cap):
        if not isinstance(x, int) or isinstance(x, bool) or not 0 <= x <= cap:
            raise bad("malformed size")
        return x

    def build(t, depth):
        left["nodes"] -= 1
        if left["nodes"] < 0:
            raise bad(f"more than {max_nodes} parts")
        if depth > max_depth:
            raise bad(f"nested more than {max_depth} levels deep")
        if not isinstance(t, list) or not t or not isinstance(t[0], str):
            raise bad("malformed answer data")
        op, args = t[0], t[1:]
        fn = _PLAIN.get(op)
        if fn is not None:
            return fn(args, lambda x: build(x, depth + 1), text, integer, small)
        return _sympy(op, args, lambda x: build(x, depth + 1), text, integer, small, classes, dummies)

    return build(tree, 0)


def _sympy_class(name):
    import sympy as sp

    return {"Equality": sp.Eq, "Unequality": sp.Ne, "ExprCondPair": sp.functions.elementary.piecewise.ExprCondPair}.get(
        name
    ) or getattr(sp.sets.sets, name, None)


# ----------------------------------------------------------------------------- plain Python and NumPy values


def _container(kind):
    def make(args, build, *_):
        items = [build(a) for a in args]
        if kind == "list":
            return items
        if kind == "tuple":
            return tuple(items)
        try:
            return set(items) if kind == "set" else frozenset(items)
        except TypeError:
            raise WireError("a set of unhashable items") from None

    return make


def _dict(args, build, *_):
    out = {}
    for kv in args:
        if not isinstance(kv, list) or len(kv) != 2:
            raise WireError("malformed dict")
        k = build(kv[0])
        try:
            out[k] = build(kv[1])
        except TypeError:
            raise WireError("a dict with an unhashable key") from None
    return out


def _number(kind):
    def make(args, build, text, integer, small):
        if kind == "int" and len(args) == 1:
            return integer(args[0])
        if kind == "float" and len(args) == 1:
            return _float(text(args[0], 40))
        if kind == "complex" and len(args) == 2:
            return complex(_float(text(args[0], 40)), _float(text(args[1], 40)))
        raise WireError("malformed number")

    return make


def _float(s):
    try:
        return float(s)
    except ValueError:
        raise WireError("malformed number") from None


def _ndarray(args, build, text, integer, small):
    import math

    import numpy as np

    if not args or not isinstance(args[0], list) or len(args[0]) > 8:
        raise WireError("malformed array")
    shape = [small(n, MAX_ENTRIES) for n in args[0]]
    if math.prod(shape) != len(args) - 1 or len(args) - 1 > MAX_ENTRIES:
        raise WireError("malformed array (shape and entries disagree, or too many entries)")
    out = np.empty(len(args) - 1, dtype=object)
    for i, a in enumerate(args[1:]):
        out[i] = build(a)
    try:  # numbers as NumPy numbers (as the student's array held them), anything else as objects
        typed = np.array(out.tolist())
        if typed.dtype.kind in "biufc":
            out = typed
    except (ValueError, TypeError):
        pass
    return out.reshape(shape)


_PLAIN = {
    "none": lambda args, *_: None if not args else _malformed(),
    "ellipsis": lambda args, *_: ... if not args else _malformed(),
    "bool": lambda args, *_: args[0] if len(args) == 1 and isinstance(args[0], bool) else _malformed(),
    "str": lambda args, build, text, *_: text(args[0]) if len(args) == 1 else _malformed(),
    "other": lambda args, build, text, *_: Other(text(args[0], 200)) if len(args) == 1 else _malformed(),
    "robot": lambda args, build, *_: Robot(build(args[0])) if len(args) == 1 else _malformed(),
    "int": _number("int"),
    "float": _number("float"),
    "complex": _number("complex"),
    "list": _container("list"),
    "tuple": _container("tuple"),
    "set": _container("set"),
    "frozenset": _container("frozenset"),
    "dict": _dict,
    "ndarray": _ndarray,
}


def _malformed():
    raise WireError("malformed answer data")


# ----------------------------------------------------------------------------- SymPy objects


_ASSUMPTIONS: set = set()


def _assumptions(d):
    if not _ASSUMPTIONS:
        from sympy.core.assumptions import _assume_defined

        _ASSUMPTIONS.update(_assume_defined)
    if not isinstance(d, dict) or len(d) > 40:
        raise WireError("malformed assumptions")
    if not all(k in _ASSUMPTIONS and isinstance(v, bool) for k, v in d.items()):
        raise WireError("unknown assumptions")
    return d


def _name(x, function=False):
    if not safe_name(x):
        raise WireError("a name that is not an identifier (letters, digits and _ only)")
    if function and x in _BUILTIN_NAMES:  # (printed as a call, "exit(x)" would be Python's)
        raise WireError(f"a function named like Python's own {x}()")
    return x


_BUILTIN_NAMES = frozenset(dir(builtins))


def _basic_args(op, items):
    """The arguments of a SymPy node: every one a SymPy object already (a matrix as an immutable one), never a
    string or other plain value that SymPy's constructor would ``sympify`` (parse, i.e. evaluate)."""
    import sympy as sp

    out = []
    for a in items:
        if isinstance(a, sp.MatrixBase):
            a = a.as_immutable()
        if not isinstance(a, sp.Basic):
            raise WireError(f"{op[:40]} takes SymPy values, not a {type(a).__name__}")
        out.append(a)
    return out


def _sympy(op, args, build, text, integer, small, classes, dummies):
    import sympy as sp

    if op == "Integer" and len(args) == 1:
        return sp.Integer(integer(args[0]))
    if op == "Rational" and len(args) == 2:
        p, q = integer(args[0]), integer(args[1])
        if q == 0:
            raise WireError("a fraction with denominator 0")
        return sp.Rational(p, q)
    if op == "Float" and len(args) == 2:
        return _sympy_float(args, text, small)
    if op == "Symbol" and len(args) == 2:
        return sp.Symbol(_name(args[0]), **_assumptions(args[1]))
    if op == "Dummy" and len(args) == 3:
        key = (_name(args[0]), json.dumps(_assumptions(args[1]), sort_keys=True), small(args[2], 2**31))
        if key not in dummies:
            dummies[key] = sp.Dummy(key[0], **args[1])
        return dummies[key]
    if op == "UndefinedFunction" and args:
        name = _name(args[0], function=True)
        fargs = _basic_args(op, [build(a) for a in args[1:]])
        try:
            return sp.Function(name)(*fargs)
        except (TypeError, ValueError):
            raise WireError("UndefinedFunction could not be rebuilt") from None
    if op == "Matrix" and len(args) >= 2:
        return _sympy_matrix(args, build, small)
    if op in SINGLETONS and not args:
        return getattr(sp.S, _SINGLETON_ATTR.get(op, op))
    cls = classes.get(op)
    if cls is None:
        raise WireError(f"{op[:40]} is not an answer the grader reads")
    items = _basic_args(op, [build(a) for a in args])
    if op == "Pow" and len(items) == 2:
        _check_power(*items)
    if op == "Dict":
        if not all(isinstance(kv, sp.Tuple) and len(kv) == 2 for kv in items):
            raise WireError("malformed Dict")
        return sp.Dict(*items)
    try:
        made = cls(*items)
    except (TypeError, ValueError, AttributeError, NotImplementedError, IndexError, KeyError, ArithmeticError) as exc:
        raise WireError(f"{op} could not be rebuilt ({type(exc).__name__})") from None
    return _check_number(made) if isinstance(made, sp.Number) else made


def _sympy_float(args, text, small):
    """A Float from its digits (mpmath's number syntax, checked character by character; never eval) and precision."""
    import sympy as sp

    digits = text(args[0], 1300)
    if not digits or not all(c in "0123456789.eE+-infa" for c in digits):
        raise WireError("malformed Float")
    try:  # mpmath's number syntax (never eval); malformed digits are a ValueError
        made = sp.Float(digits, precision=small(args[1], MAX_PREC) or 53)
    except (ValueError, TypeError):
        raise WireError("malformed Float") from None
    return _check_number(made)


def _sympy_matrix(args, build, small):
    """A Matrix from its shape and at most MAX_ENTRIES entries, each a SymPy value."""
    import sympy as sp

    r, c = small(args[0], MAX_ENTRIES), small(args[1], MAX_ENTRIES)
    if r * c != len(args) - 2 or r * c > MAX_ENTRIES:
        raise WireError("malformed matrix (shape and entries disagree, or too many entries)")
    entries = [build(a) for a in args[2:]]
    if not all(isinstance(e, sp.Basic) for e in entries):
        raise WireError("a Matrix's entries are SymPy values")
    return sp.Matrix(r, c, entries)


def _check_number(x):
    """Refuse a number whose magnitude is beyond 2**±MAX_PREC (about 10**±1200): a Float('1e1000000') inside
    sin needs π to millions of bits (SymPy's argument reduction: minutes holding the GIL), and SymPy folds
    products and powers of numbers as it builds them, so each number made is checked.

    >>> _check_number(__import__("sympy").Float("1e300")) > 0
    True
    """
    import sympy as sp

    if isinstance(x, sp.Float):
        sign, man, exp, bc = x._mpf_
        if man and abs(exp + bc) > MAX_PREC:
            raise WireError(f"a number too large to compute with (about 2**{exp + bc})")
    elif isinstance(x, sp.Rational) and max(x.p.bit_length(), x.q.bit_length()) > 4 * MAX_PREC:
        raise WireError("a number too large to compute with (more than 16000 bits)")
    return x


def _check_power(base, exp):
    """Refuse a power of exact numbers SymPy would compute into a huge number (10**(10**8))."""
    import sympy as sp

    if isinstance(exp, sp.Rational) and isinstance(base, sp.Number) and abs(exp.p) > MAX_POWER:
        raise WireError(f"a power too large to compute (exponent {exp.p})")
    if isinstance(exp, sp.Rational) and abs(exp.p) > MAX_POWER // 10:
        raise WireError(f"a power too large to compute (exponent {exp.p})")


# ----------------------------------------------------------------------------- encoding, and the exact subset


def dump(value, max_nodes: int = MAX_NODES):
    """``value`` as a tree of this format: the kernel's own encoder
    (:func:`kinlib.course.grader.in_kernel.export.export`), so what the grader keeps (its reference answers) is
    written exactly as a student's answer is; raises ValueError past ``max_nodes``.

    >>> import sympy as sp
    >>> dump(sp.pi / 2)
    ['Mul', ['Rational', '1', '2'], ['Pi']]
    >>> n = sp.Dummy("n")
    >>> load(dump(sp.ImageSet(sp.Lambda(n, sp.pi * n), sp.Integers))).base_set
    Integers
    """
    from ..grader.in_kernel.export import export

    return export(value, max_nodes=max_nodes)


_EXACT_FUNCS = ("sin", "cos", "tan")


def _exact_node(e) -> None:
    """Refuse (ValueError) a node outside the exact subset: numbers, symbols, π, +, ×, powers with a small
    whole or half exponent, sin/cos/tan of one argument."""
    import sympy as sp

    if (
        isinstance(e, (sp.Rational, sp.Float))
        or e is sp.pi
        or (isinstance(e, sp.Symbol) and not isinstance(e, sp.Dummy))
    ):
        return
    if isinstance(e, (sp.Add, sp.Mul)):
        return
    if isinstance(e, sp.Pow):
        x = sp.Rational(e.exp) if isinstance(e.exp, sp.Float) and e.exp.is_finite else e.exp  # its exact value
        if x.is_Rational and abs(x.p) <= 12 and x.q <= 2:
            return
        raise ValueError("a power that is not a small whole number or half")
    if type(e).__name__ in _EXACT_FUNCS and len(e.args) == 1:
        return
    raise ValueError(f"{type(e).__name__} is not supported here")


def _exact_walk(obj, max_nodes: int) -> None:
    import sympy as sp

    stack = list(obj) if isinstance(obj, sp.MatrixBase) else [obj]
    seen = 0
    while stack:
        e = stack.pop()
        seen += 1
        if seen > max_nodes:
            raise ValueError(f"more than {max_nodes} nodes")
        if not isinstance(e, sp.Basic):
            raise ValueError(f"{type(e).__name__} is not supported here")
        _exact_node(e)
        stack += e.args if isinstance(e, (sp.Add, sp.Mul, sp.Pow, sp.Function)) else []


def exact_dump(obj, max_nodes: int = 4000):
    """A SymPy expression or matrix in the exact subset of the format (what a proof reads: numbers, symbols, π,
    +, ×, small powers, sin/cos/tan), as its tree; ValueError for anything else or more than ``max_nodes`` nodes.

    >>> import sympy as sp
    >>> exact_dump(sp.Matrix([[sp.Symbol("L", positive=True), sp.pi]]))
    ['Matrix', 1, 2, ['Symbol', 'L', {'positive': True}], ['Pi']]
    >>> exact_dump(sp.exp(sp.Symbol("t")))
    Traceback (most recent call last):
    ...
    ValueError: exp is not supported here
    """
    _exact_walk(obj, max_nodes)
    return dump(obj, max_nodes=max_nodes)


def exact_load(tree, max_nodes: int = 20_000):
    """The value of an exact-subset tree (:func:`exact_dump`) read by :func:`load`, checked to be in the subset
    (ValueError otherwise), with each symbol real (positive when it says so) and each Float its exact binary
    value, as a proof takes them.

    >>> exact_load(["Add", ["Rational", "1", "2"], ["cos", ["Symbol", "theta1", {}]]])
    cos(theta1) + 1/2
    >>> exact_load(["exp", ["Symbol", "t", {}]])
    Traceback (most recent call last):
    ...
    ValueError: exp is not supported here
    """
    import sympy as sp

    obj = load(tree, max_nodes=max_nodes)
    if not isinstance(obj, (sp.Basic, sp.MatrixBase)):
        raise ValueError(f"{type(obj).__name__} is not supported here")
    _exact_walk(obj, max_nodes)
    syms = {
        s: sp.Symbol(s.name, positive=True) if s.is_positive else sp.Symbol(s.name, real=True) for s in obj.free_symbols
    }
    syms.update({f: sp.Rational(f) for f in obj.atoms(sp.Float)})
    return obj.xreplace(syms)
