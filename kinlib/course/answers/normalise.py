"""The answer normaliser: what form a student's (or the reference's) answer value has, in SymPy terms.

One implementation for both the workbook self-checks (:mod:`kinlib.course.workbook.selfcheck`) and the
instructor checker (:mod:`kinlib.course.grader.in_kernel.probe`, which runs it inside each student kernel), so an answer
form one of them accepts, the other accepts too:

* **matrices and expressions** (:func:`to_sympy`): SymPy matrices; NumPy arrays (0-d: a number, 1-D:
  a column, 2-D: the matrix); a flat list/tuple of numbers (a column); a list of vectors (column or
  row matrices, 1-D arrays: one vector per *column*, the screw-list convention); a list of lists (the
  rows); SymPy expressions, Python and NumPy numbers, anything ``sympify(strict=True)`` accepts (e.g.
  mpmath numbers). For subspaces (``vectors=True``) a list of lists or of matrices is the list of
  spanning vectors (or blocks), side by side;
* **sets of configurations** (:func:`set_conditions`, :func:`to_set`): a SymPy Set; a Python
  set/list/tuple or NumPy array of values; a single number; a dict {symbol: Set}; a list of such dicts
  (their union, as ``kinlib.singular_configurations`` returns; ``[]`` is the empty set);
* **choices** (:func:`choice_value`): an int, string or bool, or a list/tuple/set/array/Matrix/FiniteSet
  of them (ties as tuples); strings compare without case or extra spaces, integral floats as ints;
* **yes/no** (:func:`is_bool`) and **not answered** (:func:`is_unanswered`: ``...`` or ``None``);
* **a robot** for an answer judged by a property of the student's own design (:func:`property_answer`): an
  object with a 6×n ``screws`` matrix (a kinlib ``SerialChain``, found by duck typing: this module never
  imports kinlib), or its task Jacobian as a matrix.

It imports only the standard library, NumPy and SymPy (never kinlib): the checker sends its source text
into each student kernel, where it must not depend on anything the submission could have changed.
"""

import math
import numbers

import numpy as np
import sympy as sp

__all__ = [
    "is_unanswered",
    "is_bool",
    "to_sympy",
    "set_conditions",
    "to_set",
    "looks_like_set",
    "choice_value",
    "type_name",
    "expr_tree",
    "robot_screws",
    "property_answer",
]


def is_unanswered(value) -> bool:
    """True for an answer not given yet: ``...`` (the workbook's stub) or ``None``.

    >>> is_unanswered(...), is_unanswered(None), is_unanswered(0)
    (True, True, False)
    """
    return value is Ellipsis or value is None


def is_bool(value) -> bool:
    """True for a yes/no answer: Python, NumPy or SymPy True/False.

    >>> is_bool(True), is_bool(np.bool_(False)), is_bool(sp.true), is_bool(1)
    (True, True, True, False)
    """
    return isinstance(value, (bool, np.bool_)) or value is sp.true or value is sp.false


def type_name(value) -> str:
    """The type of ``value`` as students know it (``Matrix``'s module spelled out, builtins bare).

    >>> type_name(3), type_name(sp.Integer(3))
    ('int', 'sympy.core.numbers.Integer')
    """
    t = type(value)
    return f"{t.__module__}.{t.__qualname__}" if t.__module__ not in ("builtins",) else t.__qualname__


def _is_vector(x) -> bool:
    if isinstance(x, sp.MatrixBase):
        return 1 in x.shape
    if isinstance(x, np.ndarray):
        return x.ndim == 1 or (x.ndim == 2 and 1 in x.shape)
    return False


def _flat(x) -> list:
    if isinstance(x, sp.MatrixBase):
        return list(x)
    return list(np.asarray(x, dtype=object).ravel())


def _is_matrix_like(x) -> bool:
    return isinstance(x, sp.MatrixBase) or (isinstance(x, np.ndarray) and x.ndim in (1, 2))


def to_sympy(value, vectors: bool = False):
    """``(tag, obj)``: ``obj`` a SymPy Matrix or scalar expression, or None with ``tag`` saying why not.

    Tags: ``matrix``, ``scalar``; and, with ``obj`` None: ``ellipsis``, ``none``, ``bool``, ``empty``
    (an empty list), ``ragged`` (vectors of different lengths), ``array`` (more than 2 dimensions),
    ``other``. With ``vectors=True`` (subspaces) a list of lists, or of matrices, is a list of spanning
    vectors (or blocks of them) put side by side.

    >>> to_sympy([1, 2])
    ('matrix', Matrix([
    [1],
    [2]]))
    >>> to_sympy([sp.Matrix([1, 0]), np.array([0, 1]), sp.Matrix([[2, 3]])])[1].shape   # one vector per column
    (2, 3)
    >>> to_sympy([[1, 2, 3], [4, 5, 6]])[1].shape, to_sympy([[1, 2, 3], [4, 5, 6]], vectors=True)[1].shape
    ((2, 3), (3, 2))
    >>> to_sympy(np.float64(0.5)), to_sympy(...), to_sympy("J"), to_sympy([])
    (('scalar', 0.500000000000000), ('ellipsis', None), ('other', None), ('empty', None))
    """
    if value is Ellipsis:
        return "ellipsis", None
    if value is None:
        return "none", None
    if is_bool(value):
        return "bool", None
    if isinstance(value, sp.MatrixBase):
        return "matrix", sp.Matrix(value)
    if isinstance(value, np.ndarray):
        if value.ndim == 0:
            return to_sympy(value.item())
        if value.ndim == 1:
            return "matrix", sp.Matrix([sp.sympify(e) for e in value.tolist()])
        if value.ndim == 2:
            return "matrix", sp.Matrix([[sp.sympify(e) for e in row] for row in value.tolist()])
        return "array", None
    if isinstance(value, (sp.Tuple, list, tuple)):
        items = list(value)
        if not items:
            return "empty", None
        if all(_is_vector(v) for v in items) or (
            vectors
            and all(
                isinstance(v, (list, tuple, sp.Tuple)) and not any(isinstance(e, (list, tuple)) for e in v)
                for v in items
            )
        ):
            cols = [sp.Matrix([sp.sympify(e) for e in _flat(v)]) for v in items]
            if len({c.shape for c in cols}) != 1:
                return "ragged", None
            return "matrix", sp.Matrix.hstack(*cols)
        if vectors and all(_is_matrix_like(v) for v in items):
            try:
                return "matrix", sp.Matrix.hstack(
                    *[sp.Matrix(v.tolist() if isinstance(v, np.ndarray) else v) for v in items]
                )
            except Exception:  # noqa: BLE001  (blocks of different heights)
                return "ragged", None
        if all(isinstance(v, (list, tuple, sp.Tuple)) for v in items):
            try:
                return "matrix", sp.Matrix([[sp.sympify(e) for e in row] for row in items])
            except Exception:  # noqa: BLE001
                return "ragged", None
        try:
            return "matrix", sp.Matrix([sp.sympify(e) for e in items])
        except Exception:  # noqa: BLE001
            return "other", None
    if isinstance(value, sp.Expr):
        return "scalar", value
    if isinstance(value, sp.Basic):
        return "other", None
    if isinstance(value, (numbers.Number, np.number)):
        v = value.item() if isinstance(value, np.generic) else value
        return "scalar", sp.sympify(v)
    if isinstance(value, (str, bytes, dict, set, frozenset)):
        return "other", None
    try:  # mpmath numbers, objects with a _sympy_ method, ...
        v = sp.sympify(value, strict=True)
    except (sp.SympifyError, TypeError, ValueError, AttributeError):
        return "other", None
    if isinstance(v, sp.MatrixBase):
        return "matrix", sp.Matrix(v)
    return ("scalar", v) if isinstance(v, sp.Expr) else ("other", None)


def to_set(value):
    """One set of values as a SymPy Set: Sets as they are; a Python set/list/tuple or NumPy array of
    values, or a single number, as a FiniteSet. Raises TypeError for anything else.

    >>> to_set([0, sp.pi]), to_set(np.array([1.5])), to_set(sp.Interval(0, 1)), to_set(2)
    ({0, pi}, {1.5}, Interval(0, 1), {2})
    """
    if isinstance(value, sp.Set):
        return value
    if isinstance(value, np.ndarray):
        value = value.ravel().tolist()
    if isinstance(value, (set, frozenset, list, tuple)):
        return sp.FiniteSet(*[sp.sympify(v) for v in value])
    if isinstance(value, (numbers.Number, np.number, sp.Expr)) and not is_bool(value):
        return sp.FiniteSet(value.item() if isinstance(value, np.generic) else value)
    raise TypeError(f"a set should be a SymPy Set (or a dict {{symbol: Set}}), not a {type(value).__name__}")


def set_conditions(value):
    """A set-of-configurations answer as a list of conditions (their union), each a list of
    ``(key, set)``: ``key`` a joint variable (or None for a bare set of the only one), ``set`` a SymPy
    Set or a collection of values (see :func:`to_set`); None if ``value`` is not a set at all.

    A dict {symbol: Set} is one condition on each named joint; a list of such dicts is their union (an
    empty list: no configuration); a Set, a collection of values or a single number is one condition.

    >>> th = sp.Symbol("theta2")
    >>> set_conditions({th: {0}}), set_conditions([{th: {0}}, {th: {1}}]), set_conditions([])
    ([[(theta2, {0})]], [[(theta2, {0})], [(theta2, {1})]], [])
    >>> set_conditions(sp.FiniteSet(0, sp.pi)), set_conditions(sp.pi / 2), set_conditions("x")
    ([[(None, {0, pi})]], [[(None, {pi/2})]], None)
    """
    if isinstance(value, (dict, sp.Dict)):
        return [list(dict(value).items())]
    if isinstance(value, (list, tuple)) and all(isinstance(v, (dict, sp.Dict)) for v in value):
        return [list(dict(v).items()) for v in value]
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (sp.Set, set, frozenset, list, tuple)):
        return [[(None, value)]]
    if isinstance(value, (numbers.Number, np.number, sp.Expr)) and not is_bool(value):
        return [[(None, to_set(value))]]
    return None


def looks_like_set(value) -> bool:
    """Answers of the default kind that are really sets of configurations: a Set, a non-empty
    {symbol: Set} dict, or a list of those dicts (``[]`` included).

    >>> th = sp.Symbol("theta1")
    >>> looks_like_set(sp.EmptySet), looks_like_set([{th: sp.FiniteSet(0)}]), looks_like_set({"a": 1})
    (True, True, False)
    """
    if isinstance(value, sp.Set):
        return True
    if isinstance(value, (dict, sp.Dict)):
        return bool(value) and all(isinstance(k, sp.Symbol) for k in dict(value))
    if isinstance(value, (list, tuple)):
        return len(value) == 0 or all(isinstance(v, (dict, sp.Dict)) and looks_like_set(v) for v in value)
    return False


def choice_value(value):
    """A choice answer as plain JSON data: a bool, a string (lower case, single spaces), an int (integral
    numbers), a float, or a list of those for a collection (nested lists for tuples inside one, a tie);
    an item of another type becomes ``{"other": type name}``.

    >>> choice_value((3, 1.0)), choice_value(sp.FiniteSet(2)), choice_value("  Joint   Two ")
    ([3, 1], [2], 'joint two')
    >>> choice_value(np.array([[1, 2]])), choice_value([(1, 2), 3]), choice_value(sp.Symbol("x"))
    ([1, 2], [[1, 2], 3], {'other': 'sympy.core.symbol.Symbol'})
    """
    if is_bool(value):
        return bool(value)
    if isinstance(value, str):
        return " ".join(value.strip().lower().split())
    if isinstance(value, np.ndarray):
        return [choice_value(e) for e in value.ravel().tolist()]
    if isinstance(value, (sp.FiniteSet, sp.Tuple, list, tuple, set, frozenset, sp.MatrixBase)):
        items = list(value.args) if isinstance(value, (sp.FiniteSet, sp.Tuple)) else list(value)
        return [choice_value(e) for e in items]
    try:
        f = float(value)
    except Exception:  # noqa: BLE001  (whatever the object raises)
        return {"other": type_name(value)}
    if math.isfinite(f) and f == int(f):
        return int(f)
    return f


_TREE_FUNCS = ("sin", "cos", "tan")
_TREE_MAX_NODES = 4000


def expr_tree(obj, max_nodes=_TREE_MAX_NODES):
    """A SymPy expression or matrix as a JSON tree of plain lists: a ``property`` answer (or a constant exact
    subspace) is decided exactly in the grader, which rebuilds it from a whitelist of numbers, symbols, π,
    +, ×, powers and sin/cos/tan (:func:`kinlib.course.answers.properties.from_tree`). Raises ValueError for
    anything else or more than ``max_nodes`` nodes.

    >>> import sympy as sp
    >>> expr_tree(sp.Symbol("L", positive=True) * sp.cos(sp.Symbol("t")) + sp.Rational(1, 2))
    ['add', ['rat', '1', '2'], ['mul', ['sym', 'L', True], ['fn', 'cos', ['sym', 't', False]]]]
    """
    count = [0]

    def walk(e):
        count[0] += 1
        if count[0] > max_nodes:
            raise ValueError(f"more than {max_nodes} nodes")
        if isinstance(e, sp.Integer):
            return ["int", str(int(e))]
        if isinstance(e, sp.Rational):
            return ["rat", str(e.p), str(e.q)]
        if isinstance(e, sp.Float):
            return ["float", repr(float(e))]
        if e is sp.pi:
            return ["pi"]
        if isinstance(e, sp.Symbol):
            return ["sym", e.name, bool(e.is_positive)]
        if isinstance(e, sp.Add):
            return ["add", *[walk(a) for a in e.args]]
        if isinstance(e, sp.Mul):
            return ["mul", *[walk(a) for a in e.args]]
        if isinstance(e, sp.Pow):
            return ["pow", walk(e.base), walk(e.exp)]
        if isinstance(e, sp.Function) and type(e).__name__ in _TREE_FUNCS and len(e.args) == 1:
            return ["fn", type(e).__name__, walk(e.args[0])]
        raise ValueError(f"{type(e).__name__} is not supported here")

    if isinstance(obj, sp.MatrixBase):
        return ["matrix", obj.rows, obj.cols, *[walk(x) for x in obj]]
    return walk(sp.sympify(obj))


def robot_screws(value):
    """The space screw axes (a 6×n SymPy Matrix, one per column) of a robot answer, or None when ``value`` is
    not a robot: any object, not itself a matrix, number, container or SymPy object, whose ``screws``
    attribute is a 6×n matrix (a kinlib ``SerialChain``; duck typing, never an import of kinlib).

    >>> class Arm:
    ...     screws = sp.Matrix([[0, 0, 1, 0, 0, 0], [0, 0, 0, 1, 0, 0]]).T
    >>> robot_screws(Arm()).shape, robot_screws(sp.eye(6)), robot_screws([1, 2])
    ((6, 2), None, None)
    """
    if isinstance(value, (sp.Basic, sp.MatrixBase, np.ndarray, list, tuple, dict, set, str, bytes, numbers.Number)):
        return None
    try:
        screws = getattr(value, "screws", None)
    except Exception:  # noqa: BLE001  (a property that raises: not a robot)
        return None
    if screws is None:
        return None
    tag, S = to_sympy(screws)
    if tag != "matrix" or S.rows != 6 or not 1 <= S.cols <= 12:
        return None
    return S


def property_answer(value) -> dict:
    """An answer judged by a property of the student's own design (problem 5.5: "your redesign has no singular
    configuration") as plain JSON data for the judge (:mod:`kinlib.course.answers.properties`): ``{"tag": "robot",
    "tree": …}`` for a robot (its screw axes, :func:`robot_screws`), ``{"tag": "matrix"|"scalar", "tree": …}``
    for a matrix (its task Jacobian) or an expression, with the exact :func:`expr_tree`; ``tree_error`` says
    why there is none; other tags as :func:`to_sympy`.

    >>> property_answer(sp.Matrix([[1, 0], [0, 1]]))["tree"][:3]
    ['matrix', 2, 2]
    >>> property_answer(...)["tag"], property_answer("robot")["tag"]
    ('ellipsis', 'other')
    """
    S = robot_screws(value)
    if S is not None:
        tag, obj = "robot", S
    else:
        tag, obj = to_sympy(value)
    out = {"tag": tag, "type": type_name(value)}
    if obj is not None:
        try:
            out["tree"] = expr_tree(obj)
        except Exception as exc:  # noqa: BLE001  (any failure is reported, not raised)
            out["tree_error"] = str(exc)[:200]
    return out
