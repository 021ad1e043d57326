"""Reference answers as data: SymPy objects read back from their ``srepr`` text by a strict parser, never ``eval``.

The grader keeps each reference answer (in its signed cache) as ``srepr`` text
(:mod:`kinlib.course.grader.refdata`); :func:`parse_srepr` rebuilds the object from Python's syntax tree of that
text, accepting only calls of SymPy classes (subclasses of ``Basic`` or matrices), SymPy singletons
(``pi``, ``oo``, ``Reals``, ``EmptySet``, ``true``...), numbers, lists, tuples and dicts, and strings
only as dict keys, the name of a Symbol/Dummy/Function or the digits of a Float. Nothing else (names, attributes,
lambdas, strings that SymPy would ``sympify``) is accepted, so a tampered text cannot run code. It runs on the
trusted side only; answers from a kernel are read by :mod:`kinlib.course.answers.wire`.
"""

import ast

from .wire import safe_name

__all__ = ["parse_srepr"]

_SREPR_NAMES = {}


def _srepr_names():
    """SymPy's classes (Basic and matrix subclasses) and singletons, by name: all a srepr string may call."""
    if not _SREPR_NAMES:
        import sympy as sp

        for k in dir(sp):
            v = getattr(sp, k)
            if (isinstance(v, type) and issubclass(v, (sp.Basic, sp.MatrixBase))) or isinstance(v, sp.Basic):
                _SREPR_NAMES[k] = v
        _SREPR_NAMES.update(true=sp.true, false=sp.false)
    return _SREPR_NAMES


_NAMED_BY_STRING = {"Symbol", "Dummy", "Function", "Wild", "Float"}


def _bad(why):
    return ValueError(f"not reference data: {why}")


def _num(node):
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        return -_num(node.operand)
    if isinstance(node, ast.Constant) and type(node.value) in (int, float, bool) and abs(node.value) < 10**100:
        return node.value
    raise _bad("a keyword or number argument that is not a number")


def _key(node, names):
    """A dict key: a string (answers keyed by name) is plain data, never given to SymPy."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if node is None:
        raise _bad("**mapping")
    return _build(node, names)


def _build(node, names):
    if isinstance(node, ast.Name):
        if node.id not in names:
            raise _bad(f"{node.id} is not a SymPy class")
        return names[node.id]
    if isinstance(node, (ast.List, ast.Tuple)):
        items = [_build(e, names) for e in node.elts]
        return items if isinstance(node, ast.List) else tuple(items)
    if isinstance(node, ast.Dict):
        return {_key(k, names): _build(v, names) for k, v in zip(node.keys, node.values)}
    if isinstance(node, (ast.Constant, ast.UnaryOp)) and not isinstance(getattr(node, "value", 0), str):
        return _num(node)
    if not isinstance(node, ast.Call):
        raise _bad(f"{type(node).__name__} is not allowed")
    return _call(node, names)


def _call(node, names):
    """A call of a SymPy class (or of an undefined function: ``Function('f')(x)``) on data arguments."""
    f = node.func
    if isinstance(f, ast.Call) and isinstance(f.func, ast.Name) and f.func.id == "Function":
        fn = _build(f, names)
    elif isinstance(f, ast.Name) and f.id in names and isinstance(names[f.id], type):
        fn = names[f.id]
    else:
        raise _bad(f"{ast.unparse(f)[:40]} is not a SymPy class")
    args = list(node.args)
    first = []
    if args and isinstance(args[0], ast.Constant) and isinstance(args[0].value, str):
        if not (isinstance(f, ast.Name) and f.id in _NAMED_BY_STRING):
            raise _bad(f"a string argument to {ast.unparse(f)[:40]}")
        s = args.pop(0).value
        if f.id == "Float" and not all(c in "0123456789.eE+-" for c in s):
            raise _bad("a Float that is not a number")
        first = [s]
    if first and f.id != "Float" and not safe_name(first[0]):
        raise _bad(f"a name that is not an identifier ({first[0][:40]!r})")
    kw = {k.arg: _num(k.value) for k in node.keywords if k.arg is not None}
    if len(kw) != len(node.keywords):
        raise _bad("**keywords")
    built = [_build(a, names) for a in args]
    if any(_has_string(b) for b in built):  # a string SymPy would sympify (parse): only names take one
        raise _bad(f"a string inside the arguments of {ast.unparse(f)[:40]}")
    return fn(*first, *built, **kw)


def _has_string(value) -> bool:
    """Whether a built argument holds a plain string anywhere (a dict key too)."""
    stack = [value]
    while stack:
        v = stack.pop()
        if isinstance(v, (str, bytes)):
            return True
        if isinstance(v, dict):
            stack += [*v.keys(), *v.values()]
        elif isinstance(v, (list, tuple)):
            stack += list(v)
    return False


def parse_srepr(text, max_len=2_000_000):
    """A SymPy object from its ``srepr`` text, parsed as data (never ``eval``): only SymPy class calls,
    singletons, numbers, lists, tuples and dicts are accepted; anything else raises ValueError.

    >>> parse_srepr("Mul(Integer(2), Symbol('x'))")
    2*x
    >>> parse_srepr("__import__('os')")
    Traceback (most recent call last):
    ...
    ValueError: not reference data: __import__ is not a SymPy class
    """
    if not isinstance(text, str) or len(text) > max_len:
        raise _bad("not a string of at most 2 MB")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise _bad(f"syntax error ({exc.msg})") from None
    return _build(tree.body, _srepr_names())
