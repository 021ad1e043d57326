"""Reference answers as data: SymPy objects read back from their ``srepr`` text by a strict parser, never ``eval``.

The grader keeps each reference answer as the ``srepr`` text the reference kernel produced
(:mod:`kinlib.course.grader.refdata`); :func:`parse_srepr` rebuilds the object from Python's syntax tree of that
text, accepting only calls of SymPy classes (subclasses of ``Basic`` or matrices), SymPy singletons
(``pi``, ``oo``, ``Reals``, ``EmptySet``, ``true``...), numbers, lists, tuples and dicts, and strings
only as dict keys, the name of a Symbol/Dummy/Function or the digits of a Float. Nothing else (names, attributes,
lambdas, strings that SymPy would ``sympify``) is accepted, so a tampered text cannot run code. Like
:mod:`kinlib.course.grader.in_kernel.probe` it is also sent to student kernels as source text (imports: ``ast``, SymPy).
"""

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
    import ast

    if not isinstance(text, str) or len(text) > max_len:
        raise ValueError("not reference data: not a string of at most 2 MB")
    names = _srepr_names()

    def bad(why):
        return ValueError(f"not reference data: {why}")

    def num(node):
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            return -num(node.operand)
        if isinstance(node, ast.Constant) and type(node.value) in (int, float, bool) and abs(node.value) < 10**100:
            return node.value
        raise bad("a keyword or number argument that is not a number")

    def key(node):  # a dict key: a string (answers keyed by name) is plain data, never given to SymPy
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            return node.value
        if node is None:
            raise bad("**mapping")
        return build(node)

    def build(node):
        if isinstance(node, ast.Name):
            if node.id not in names:
                raise bad(f"{node.id} is not a SymPy class")
            return names[node.id]
        if isinstance(node, (ast.List, ast.Tuple)):
            items = [build(e) for e in node.elts]
            return items if isinstance(node, ast.List) else tuple(items)
        if isinstance(node, ast.Dict):
            return {key(k): build(v) for k, v in zip(node.keys, node.values)}
        if isinstance(node, (ast.Constant, ast.UnaryOp)) and not isinstance(getattr(node, "value", 0), str):
            return num(node)
        if not isinstance(node, ast.Call):
            raise bad(f"{type(node).__name__} is not allowed")
        f = node.func
        if isinstance(f, ast.Call) and isinstance(f.func, ast.Name) and f.func.id == "Function":
            fn = build(f)  # an undefined function applied to arguments: Function('f')(x)
        elif isinstance(f, ast.Name) and f.id in names and isinstance(names[f.id], type):
            fn = names[f.id]
        else:
            raise bad(f"{ast.unparse(f)[:40]} is not a SymPy class")
        args = list(node.args)
        first = []
        if args and isinstance(args[0], ast.Constant) and isinstance(args[0].value, str):
            if not (isinstance(f, ast.Name) and f.id in _NAMED_BY_STRING):
                raise bad(f"a string argument to {ast.unparse(f)[:40]}")
            s = args.pop(0).value
            if f.id == "Float" and not all(c in "0123456789.eE+-" for c in s):
                raise bad("a Float that is not a number")
            first = [s]
        kw = {k.arg: num(k.value) for k in node.keywords if k.arg is not None}
        if len(kw) != len(node.keywords):
            raise bad("**keywords")
        return fn(*first, *[build(a) for a in args], **kw)

    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise bad(f"syntax error ({exc.msg})") from None
    return build(tree.body)
