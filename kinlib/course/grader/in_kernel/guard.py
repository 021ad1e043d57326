"""Kernel side of the instructor checker: the namespaces a submission could tamper with, saved and put back.

:func:`snapshot` runs in each student kernel before the first student cell; :func:`restore` runs after the
last one, before the answers are read, and undoes replaced or added functions and classes in SymPy's,
NumPy's, mpmath's and the builtins' namespaces (and SymPy's class attributes), so
``sympy.simplify = lambda e: 0`` and the like do not change the answer the kernel exports (the grader
evaluates it in its own process anyway). Like :mod:`.export` it is sent to the kernel as source text and imports
only the standard library (and SymPy and NumPy, to snapshot them).
"""

import sys

__all__ = ["snapshot", "restore"]

_MISSING = object()


def snapshot():
    """Copies of the namespaces a submission could tamper with (taken before any student cell runs).

    >>> sorted(snapshot())
    ['classes', 'mods', 'sysmods']
    """
    import numpy  # noqa: F401  (imported so that its modules are in the snapshot)
    import sympy  # noqa: F401

    mods, classes, sysmods = {}, {}, {}
    for name, m in list(sys.modules.items()):
        top = name.split(".")[0]
        if m is None or not (top in ("sympy", "numpy", "mpmath") or name in ("builtins", "math", "cmath", "json")):
            continue
        d = getattr(m, "__dict__", None)
        if not isinstance(d, dict):
            continue
        sysmods[name] = m
        mods[name] = (m, dict(d))
        if top in ("sympy", "mpmath"):
            for v in list(d.values()):
                if (
                    isinstance(v, type)
                    and id(v) not in classes
                    and str(getattr(v, "__module__", "") or "").startswith(top)
                ):
                    classes[id(v)] = (v, dict(v.__dict__))
    return {"mods": mods, "classes": classes, "sysmods": sysmods}


_NOT_RESTORED = {"input", "raw_input", "get_ipython", "display", "help", "exit", "quit"}


def _fn(v):
    """Functions, classes and descriptors are restored; data (counters, caches, flags) is left alone."""
    return callable(v) or isinstance(v, (staticmethod, classmethod, property))


def _display_only(k):
    """Rich-display hooks (``init_printing`` sets them): they do not change any value."""
    return str(k).startswith("_repr_")


def _library_made(v, top: str) -> bool:
    """True when ``v`` was made by the library itself (``top``: 'sympy', 'mpmath', 'numpy', …): SymPy's polys
    domains build ``mpmath`` contexts, which re-wrap ``MPContext``'s class functions on every construction. Such
    a change is undone like any other but is not reported as the notebook's doing."""
    mod = str(getattr(v, "__module__", None) or getattr(getattr(v, "__func__", None), "__module__", "") or "")
    return mod == top or mod.startswith(top + ".")


def restore(snap):
    """Undo replaced functions/classes in the snapshotted namespaces; returns the names put back that the
    notebook replaced (a change the library made itself, see :func:`_library_made`, is undone silently).

    >>> import math
    >>> snap, real = snapshot(), math.sqrt
    >>> math.sqrt = lambda x: 0.0
    >>> restore(snap), math.sqrt is real
    (['math.sqrt'], True)
    """
    fixed = []
    for name, m in snap["sysmods"].items():
        if sys.modules.get(name) is not m:
            sys.modules[name] = m
            fixed.append(f"sys.modules[{name!r}]")
    for name, (m, saved) in snap["mods"].items():
        _restore_module(name, m.__dict__, saved, fixed)
    for cls, saved in snap["classes"].values():
        _restore_class(cls, saved, fixed)
    try:
        from sympy.core.cache import clear_cache

        clear_cache()
    except Exception:
        pass
    return fixed


def _top_of(module_name: str) -> str:
    return str(module_name).split(".")[0]


def _restore_module(name: str, cur: dict, saved: dict, fixed: list) -> None:
    """Put back the module ``name``'s functions/classes as snapshotted (``cur``: its __dict__), dropping added ones."""
    import types

    for k in list(cur):
        if (
            k not in saved
            and _fn(cur[k])
            and not isinstance(cur[k], types.ModuleType)
            and not k.startswith("__")
            and k not in _NOT_RESTORED
        ):
            if not _library_made(cur[k], _top_of(name)):
                fixed.append(f"{name}.{k} (added)")
            del cur[k]
    for k, v in saved.items():
        new = cur.get(k, _MISSING)
        if new is not v and _fn(v) and not k.startswith("__") and k not in _NOT_RESTORED:
            if not _library_made(new, _top_of(name)):
                fixed.append(f"{name}.{k}")
            cur[k] = v


def _restore_class(cls, saved: dict, fixed: list) -> None:
    """Put back the class's methods as snapshotted, dropping added ones (display hooks aside)."""
    where = f"{cls.__module__}.{cls.__qualname__}"
    top = _top_of(cls.__module__)
    for k in list(cls.__dict__):
        if k not in saved and _fn(cls.__dict__[k]) and not _display_only(k):
            try:
                new = cls.__dict__[k]
                delattr(cls, k)
                if not _library_made(new, top):
                    fixed.append(f"{where}.{k} (added)")
            except (AttributeError, TypeError):
                pass
    for k, v in saved.items():
        new = cls.__dict__.get(k, _MISSING)
        if new is not v and _fn(v) and not _display_only(k):
            try:
                setattr(cls, k, v)
                if not _library_made(new, top):
                    fixed.append(f"{where}.{k}")
            except (AttributeError, TypeError):
                pass
