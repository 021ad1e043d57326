"""Compiled C for the single-configuration call of generated code (issue 25: real arms within 2× Pinocchio).

The Python code of :class:`kinlib.codegen.CompiledMatrix` pays fixed costs before any arithmetic (the call,
12–14 ``math.sin``/``math.cos``, packing the result: ≈ 1.6 µs for a 7-joint arm). Here the *same* cse'd
temporaries and entries are printed as C by SymPy's C99 printer with the Python printer's rules
(:class:`ArithmeticRules`: floats as the same literals, ``c - a*b``, ``(x*x)``), so every operation is the
one the Python code does, in the same order, in IEEE double arithmetic (``-ffp-contract=off``: no fused
multiply-add): the results equal the Python path's, to the bit where libm's sin and cos are Python's.
The C is a tiny CPython extension (the plain C API and the buffer protocol: no NumPy headers) whose
``single(q)`` reads a joint vector (a float64 ndarray of shape (n,), or a list/tuple of n floats or ints),
writes into a fresh ``numpy.empty`` array and returns it, or returns None for anything else (a batch, SymPy
values, nan, a bool, a wrong length): the caller's checked Python path then answers or names the argument.

**When it compiles.** Never on a first call: a matrix's first 1000 single calls (:data:`HOT_CALLS`) run the
Python code; the 1000th hands the C to a background thread (one for the process), which compiles it with the
system C compiler (≈ 0.2–0.5 s of CPU in ``cc``, off the calling thread) and swaps it in when it is loaded.
A module compiled before, by this or any other process, is loaded at once (≈ 1 ms). ``compile_native()``
of :class:`~kinlib.codegen.CompiledMatrix` (e.g. ``chain.numeric_code("jg").compile_native()``) compiles
now and waits. **Cache**: ``$KINLIB_CACHE/compiled`` (default ``~/.cache/kinlib/compiled``), one file per
SHA-256 of the C source + the compiler's identity + the Python ABI; written under a temporary name and
moved into place with ``os.replace``, so processes compiling the same key at once are safe.

**The cache is untrusted input.** A module is written with the SHA-256 of its bytes beside it
(``<module>.so.sha256``) and loaded only if the file's bytes have that hash: a truncated or altered file (a
``.so`` cut short makes ``dlopen`` kill the process with SIGBUS) is removed and compiled again, never loaded.
Both files must be regular files this user owns that nobody else can write, in a cache folder (and its parent)
that this user owns and that is not group- or world-writable; otherwise nothing is compiled or loaded and
``native_status`` says why. The compiler (and its ``--version`` probe) runs in a session of its own with a
time limit (:data:`COMPILE_SECONDS`, :data:`PROBE_SECONDS`); past it the whole process group is killed.
**No compiler, no Python headers, Pyodide, Windows, or** ``KINLIB_COMPILE=0``: the Python code, with the
reason in ``native_status``.
"""

from __future__ import annotations

import contextlib
import hashlib
import math
import os
import sys
import threading
import time
from pathlib import Path

import numpy as np
import sympy as sp  # noqa: F401  (the examples use it)
from sympy.printing.c import C99CodePrinter
from sympy.printing.precedence import precedence

__all__ = ["ArithmeticRules", "COMPILE_SECONDS", "HOT_CALLS", "NativeSingle", "PROBE_SECONDS", "c_source", "toolchain"]

#: single calls of a matrix's Python code before its C is compiled in the background
HOT_CALLS = 1000

#: seconds one compile may take (a 7-joint arm: ≈ 0.5 s of CPU) before the compiler's process group is killed
COMPILE_SECONDS = 60.0

#: seconds the compiler's ``--version`` probe may take, likewise
PROBE_SECONDS = 10.0

#: changes whenever the generated C or the way it is compiled changes (part of the cache key)
_GENERATOR = "kinlib-native-1"


class ArithmeticRules:
    """Printing rules shared by the generated Python and C (mixed into SymPy's printers): rationals as float
    literals (the same correctly rounded double), ``x**2..4`` as products, a ``+`` term first in a sum
    (``c - a*b`` saves a negation). Both printers print the same operations in the same order.

    >>> class P(ArithmeticRules, C99CodePrinter): pass
    >>> x, y = sp.symbols("x y")
    >>> P().doprint(-x**2 * y / 8 + 1)
    '1 - 0.125*(x*x)*y'
    """

    def _print_Rational(self, expr):  # 89/1000 -> 0.089 (the same correctly rounded float)
        return repr(float(expr))

    def _print_Half(self, expr):
        return "0.5"

    def _print_Pow(self, expr, rational=False):
        b, e = expr.args
        if e.is_Integer and 2 <= int(e) <= 4:  # x*x is cheaper than x**2 (Python) or pow(x, 2) (C)
            base = self.parenthesize(b, precedence(expr), strict=False)
            return "(" + "*".join([base] * int(e)) + ")"  # parenthesized: a/x**2 is a/(x*x)
        return super()._print_Pow(expr, rational=rational)

    def _print_Add(self, expr, order=None):
        # print as SymPy does, then put a '+' term first: 'c - a*b' saves a negation
        terms = self._as_ordered_terms(expr, order=order)
        prec = precedence(expr)
        items = []
        for term in terms:
            t = self._print(term)
            if t.startswith("-") and not term.is_Add:
                sign, t = "-", t[1:]
            else:
                sign = "+"
            if precedence(term) < prec or term.is_Add:
                t = f"({t})"
            items.append((sign, t))
        for k, (sign, _) in enumerate(items):
            if sign == "+":
                items.insert(0, items.pop(k))
                break
        first_sign, first = items[0]
        out = ("-" if first_sign == "-" else "") + first
        for sign, t in items[1:]:
            out += f" {sign} {t}"
        return out


class _CPrinter(ArithmeticRules, C99CodePrinter):
    def _print_Integer(self, expr):  # as Python prints it (an int literal converts to the same double); a
        v = int(expr)  # large one (a float's integer value) as that float, never a C integer constant too large
        return str(v) if abs(v) < 2**31 else repr(float(v))

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Pow(self, expr, rational=False):
        b, e = expr.args
        if e.is_Integer and int(e) == -1:  # Python prints 1/x
            return "1.0/" + self.parenthesize(b, precedence(expr), strict=False)
        return super()._print_Pow(expr, rational=rational)


_TEMPLATE = r"""/* generated by kinlib.native (@GENERATOR@) for @NAME@: do not edit */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <string.h>

#define NQ @N@
#define NOUT @SIZE@
static PyObject *empty_fn, *shape, *ndarray_type;

static void kernel(const double *q, double *out) {
@BODY@
}

/* 1: q read into v; 0: not a plain finite joint vector (the caller's checked path decides); -1: error */
static int read_q(PyObject *arg, double *v) {
    if (PyList_CheckExact(arg) || PyTuple_CheckExact(arg)) {
        if (PySequence_Fast_GET_SIZE(arg) != NQ) return 0;
        PyObject **items = PySequence_Fast_ITEMS(arg);
        for (Py_ssize_t i = 0; i < NQ; i++) {
            PyObject *x = items[i];
            if (PyFloat_Check(x)) v[i] = PyFloat_AS_DOUBLE(x);
            else if (PyLong_CheckExact(x)) {
                v[i] = PyLong_AsDouble(x);
                if (v[i] == -1.0 && PyErr_Occurred()) { PyErr_Clear(); return 0; }
            } else return 0;
            if (!isfinite(v[i])) return 0;
        }
        return 1;
    }
    if ((PyObject *)Py_TYPE(arg) != ndarray_type) return 0;
    Py_buffer b;
    if (PyObject_GetBuffer(arg, &b, PyBUF_RECORDS_RO) < 0) { PyErr_Clear(); return 0; }
    int ok = b.ndim == 1 && b.shape[0] == NQ && b.itemsize == 8 && b.format && strcmp(b.format, "d") == 0;
    for (Py_ssize_t i = 0; ok && i < NQ; i++) {
        memcpy(v + i, (const char *)b.buf + i * b.strides[0], sizeof(double));
        ok = isfinite(v[i]);
    }
    PyBuffer_Release(&b);
    return ok;
}

static PyObject *single(PyObject *self, PyObject *arg) {
    double q[NQ > 0 ? NQ : 1];
    int r = read_q(arg, q);
    if (r <= 0) { if (r < 0) return NULL; Py_RETURN_NONE; }
    if (!empty_fn) { PyErr_SetString(PyExc_RuntimeError, "setup() not called"); return NULL; }
    PyObject *out = PyObject_CallOneArg(empty_fn, shape);
    if (!out) return NULL;
    Py_buffer b;
    if (PyObject_GetBuffer(out, &b, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS) < 0) { Py_DECREF(out); return NULL; }
    if (b.len != NOUT * (Py_ssize_t)sizeof(double)) {
        PyBuffer_Release(&b); Py_DECREF(out);
        PyErr_SetString(PyExc_RuntimeError, "output array of the wrong size"); return NULL;
    }
    kernel(q, (double *)b.buf);
    PyBuffer_Release(&b);
    return out;
}

static PyObject *setup(PyObject *self, PyObject *args) {
    PyObject *e, *s, *t;
    if (!PyArg_ParseTuple(args, "OOO", &e, &s, &t)) return NULL;
    Py_XINCREF(e); Py_XINCREF(s); Py_XINCREF(t);
    Py_XSETREF(empty_fn, e); Py_XSETREF(shape, s); Py_XSETREF(ndarray_type, t);
    Py_RETURN_NONE;
}

static PyMethodDef methods[] = {
    {"single", single, METH_O, "single(q): the matrix at one configuration, or None if q is not a plain joint vector"},
    {"setup", setup, METH_VARARGS, "setup(numpy.empty, shape, numpy.ndarray)"},
    {NULL, NULL, 0, NULL}};
static struct PyModuleDef moddef = {PyModuleDef_HEAD_INIT, "@MODULE@", NULL, -1, methods};
PyMODINIT_FUNC PyInit_@MODULE@(void) { return PyModule_Create(&moddef); }
"""


def c_source(repl, reduced, n: int, shape: tuple[int, int], name: str = "matrix") -> str:
    """The C extension's source for cse pieces (as :meth:`kinlib.codegen.CompiledMatrix.from_pieces` takes
    them: ``repl`` (temporary, expression) in the joint symbols ``_q0 … _q{n−1}``, ``reduced`` the entries
    row-major); the module name is left as ``@MODULE@`` (filled in from the cache key). ValueError for what C
    cannot print.

    >>> x0, q0 = sp.symbols("_x0 _q0")
    >>> src = c_source([(x0, sp.sin(q0))], [x0, x0**2 / 2], 1, (1, 2))
    >>> print(src[src.index("static void"):src.index("/* 1:")].strip())
    static void kernel(const double *q, double *out) {
        const double _q0 = q[0];
        const double _x0 = sin(_q0);
        out[0] = _x0;
        out[1] = (0.5)*(_x0*_x0);
    }
    """
    pr = _CPrinter()
    body = [f"    const double _q{i} = q[{i}];" for i in range(n)]
    body += [f"    const double {s} = {pr.doprint(e)};" for s, e in repl]
    for k, e in enumerate(reduced):
        v = None
        if not e.free_symbols:
            try:
                v = float(e)
            except TypeError:
                v = math.nan
            if not math.isfinite(v):
                raise ValueError(f"{name}: entry {k} is {e}, not a finite real number")
        body.append(f"    out[{k}] = {repr(v) if v is not None else pr.doprint(e)};")
    if pr._not_supported:
        raise ValueError(f"{name}: C cannot print {sorted(map(str, pr._not_supported))}")
    return (
        _TEMPLATE.replace("@BODY@", "\n".join(body))
        .replace("@N@", str(n))
        .replace("@SIZE@", str(shape[0] * shape[1]))
        .replace("@NAME@", name.replace("*/", ""))
        .replace("@GENERATOR@", _GENERATOR)
    )


# --- the toolchain, the cache, loading ---------------------------------------------------------------
_lock = threading.RLock()  # the in-process tables
_compile_lock = threading.Lock()  # one compile at a time in this process (the tables stay readable meanwhile)
_toolchain_cache: dict = {}
_loaded: dict[str, object] = {}  # key -> the module's single(q), once per process


def toolchain() -> tuple[list[str] | None, str]:
    """(the compiler command to build an extension with, its identity for the cache key), or (None, why not):
    ``KINLIB_COMPILE=0``, Pyodide, Windows, no C compiler (``$CC``, Python's own, ``cc``, ``gcc``, ``clang``)
    or no ``Python.h``.

    >>> argv, about = toolchain()
    >>> argv is None or argv[0].endswith(("cc", "gcc", "clang")) or "CC" in os.environ
    True
    """
    if os.environ.get("KINLIB_COMPILE", "1").strip().lower() in ("0", "no", "false", "off"):
        return None, "KINLIB_COMPILE=0"
    if sys.platform in ("emscripten", "wasi"):
        return None, "no C compiler in the browser (Pyodide)"
    if os.name == "nt":
        return None, "compiled code is built on Linux and macOS only"
    env_cc = os.environ.get("CC", "")
    with _lock:
        if env_cc in _toolchain_cache:
            return _toolchain_cache[env_cc]
    import shlex
    import shutil
    import sysconfig

    inc = sysconfig.get_paths().get("include", "")
    result: tuple = (None, f"no Python.h in {inc or 'this Python'} (the Python headers, e.g. Debian's python3-dev)")
    if inc and Path(inc, "Python.h").is_file():
        result = (None, "no C compiler (cc, gcc or clang) on PATH")
        for cand in (env_cc, sysconfig.get_config_var("CC") or "", "cc", "gcc", "clang"):
            argv = shlex.split(cand)
            if argv and shutil.which(argv[0]):
                try:
                    rc, version = _run([*argv, "--version"], PROBE_SECONDS)
                except (OSError, TimeoutError) as e:
                    result = (None, f"the C compiler {argv[0]} did not answer --version ({e})")
                    continue
                if rc == 0:
                    link = ["-bundle", "-undefined", "dynamic_lookup"] if sys.platform == "darwin" else ["-shared"]
                    flags = ["-O2", "-fPIC", "-ffp-contract=off", "-fno-fast-math", "-w", *link, "-I", inc]
                    about = "|".join(
                        [
                            shutil.which(argv[0]),
                            version.strip(),
                            *flags,
                            sysconfig.get_config_var("EXT_SUFFIX") or "",
                            sys.version,
                        ]
                    )
                    result = ([*argv, *flags], about)
                    break
    with _lock:
        _toolchain_cache[env_cc] = result
    return result


def _cache_dir() -> Path:
    root = os.environ.get("KINLIB_CACHE")
    return (Path(root) if root else Path.home() / ".cache" / "kinlib") / "compiled"


def _run(argv: list[str], seconds: float) -> tuple[int, str]:
    """Run ``argv`` in a session of its own (its own process group) with output to a file; (exit code, output).
    Past ``seconds`` the whole process group is killed (the compiler's children too) and TimeoutError is raised.
    Output goes to a file, not a pipe: a child that outlives the kill cannot keep this call waiting for EOF.

    >>> _run([sys.executable, "-c", "print(6 * 7)"], 60)
    (0, '42\\n')
    """
    import signal
    import subprocess
    import tempfile

    with tempfile.TemporaryFile() as out:
        p = subprocess.Popen(
            argv, stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT, start_new_session=True
        )
        try:
            rc = p.wait(timeout=seconds)
        except subprocess.TimeoutExpired:
            with contextlib.suppress(OSError):
                os.killpg(p.pid, signal.SIGKILL)
            p.wait()
            raise TimeoutError(
                f"{Path(argv[0]).name} did not finish in {seconds:g} s; its processes were ended"
            ) from None
        finally:
            with contextlib.suppress(OSError):  # whatever it left running in its group
                os.killpg(p.pid, signal.SIGKILL)
        out.seek(0)
        return rc, out.read().decode("utf-8", "replace")


def _private(path: Path) -> str | None:
    """Why ``path`` (a cache folder) must not be used, or None: it must be a folder (not a link) this user owns
    that neither the group nor others can write."""
    try:
        st = path.lstat()
    except OSError as e:
        return f"the cache folder {path} cannot be read ({e.strerror})"
    import stat

    getuid = getattr(os, "getuid", None)
    if not stat.S_ISDIR(st.st_mode):
        return f"the cache folder {path} is not a folder"
    if getuid is not None and st.st_uid != getuid():
        return f"the cache folder {path} belongs to another user"
    if st.st_mode & 0o022:
        return (
            f"the cache folder {path} can be written by others (mode {stat.S_IMODE(st.st_mode):o}): nothing is compiled"
        )
    return None


def _ready_dir(folder: Path) -> None:
    """Create the cache folder (mode 700) if needed; raise ValueError if it, or its parent, is not private."""
    try:
        folder.mkdir(parents=True, exist_ok=True, mode=0o700)
    except OSError as e:
        raise ValueError(f"the cache folder {folder} cannot be created ({e.strerror})") from None
    for p in (folder, folder.parent):
        why = _private(p)
        if why:
            raise ValueError(why)


def _safe(path: Path) -> bool:
    """Loadable: a regular file (not a link) this user owns that nobody else can write (a cache dir others can write to
    must not let them run code in this process)."""
    try:
        st = path.lstat()
    except OSError:
        return False
    import stat

    getuid = getattr(os, "getuid", None)
    return stat.S_ISREG(st.st_mode) and (getuid is None or st.st_uid == getuid()) and not st.st_mode & 0o022


def _digest_path(path: Path) -> Path:
    return path.with_name(path.name + ".sha256")


def _verified(path: Path) -> bool:
    """The module at ``path`` and its recorded SHA-256 are both safe files and agree (the whole file is read: a
    truncated or altered module is never handed to ``dlopen``)."""
    digest = _digest_path(path)
    if not (_safe(path) and _safe(digest)):
        return False
    try:
        want = digest.read_text(encoding="ascii").strip()
        got = hashlib.sha256(path.read_bytes()).hexdigest()
    except (OSError, UnicodeDecodeError):
        return False
    return len(want) == 64 and want == got


def _discard(path: Path) -> None:
    """Remove a damaged module and its digest (another process may be replacing them: errors are ignored)."""
    for p in (path, _digest_path(path)):
        with contextlib.suppress(OSError):
            p.unlink()


def _load(path: Path, module: str, shape) -> object:
    import importlib.machinery
    import importlib.util

    loader = importlib.machinery.ExtensionFileLoader(module, str(path))
    spec = importlib.util.spec_from_file_location(module, str(path), loader=loader)
    mod = importlib.util.module_from_spec(spec)
    loader.exec_module(mod)
    mod.setup(np.empty, tuple(shape), np.ndarray)
    return mod.single


def _compile(argv: list[str], source: str, path: Path) -> None:
    """Compile ``source`` to ``path``: in a temporary folder beside it, then ``os.replace`` (atomic: a process that
    compiles the same key at once replaces the file with identical bytes; one that loaded it keeps its copy). The
    module's SHA-256 goes beside it (``.sha256``, moved into place after the module): :func:`_verified` loads
    nothing else. The compiler runs for at most :data:`COMPILE_SECONDS` (TimeoutError after that)."""
    import shutil
    import tempfile

    _ready_dir(path.parent)
    now = time.time()
    for old in path.parent.glob(".build-*"):  # left by a process that ended while compiling (a daemon thread)
        with contextlib.suppress(OSError):
            if now - old.stat().st_mtime > 3600:
                shutil.rmtree(old, ignore_errors=True)
    tmp = Path(tempfile.mkdtemp(prefix=".build-", dir=path.parent))
    try:
        (tmp / "m.c").write_text(source, encoding="utf-8")
        rc, out = _run([*argv, str(tmp / "m.c"), "-o", str(tmp / path.name), "-lm"], COMPILE_SECONDS)
        if rc != 0:
            raise OSError(f"the C compiler failed: {out.strip()[-300:]}")
        built = tmp / path.name
        os.chmod(built, 0o755)
        digest = tmp / (path.name + ".sha256")
        digest.write_text(hashlib.sha256(built.read_bytes()).hexdigest() + "\n", encoding="ascii")
        os.chmod(digest, 0o644)
        os.replace(built, path)
        os.replace(digest, _digest_path(path))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


class NativeSingle:
    """The compiled C of one matrix's single-configuration code: ``fn`` (``single(q)``, or None), ``status``
    (what runs, and why). :meth:`build` finds it in this process, then on disk, else compiles it (now, or in
    the background thread); ``on_ready(fn)`` is called once it is loaded.

    >>> x0, q0 = sp.symbols("_x0 _q0")
    >>> ns = NativeSingle([(x0, sp.cos(q0))], [x0], 1, (1, 1), "cos")
    >>> ok = ns.build(wait=True)   # False without a C compiler (the reason in ns.status)
    >>> ok == (ns.fn is not None) == ns.status.startswith("C")
    True
    >>> not ok or (float(ns.fn([0.5])[0, 0]) == math.cos(0.5) and ns.fn([float("nan")]) is None)
    True
    """

    def __init__(self, repl, reduced, n: int, shape: tuple[int, int], name: str = "matrix", key_text: str = ""):
        self._pieces = (list(repl), list(reduced), n, tuple(shape), name)
        self._key_text = key_text  # the Python code of the same pieces, if known: the key without printing C
        self.shape = tuple(shape)
        self.fn = None
        self.status = "Python (not compiled yet)"
        self._module = None

    def _prepare(self):
        """(compiler argv, module name, file path), or raise ValueError with the reason. The key hashes the Python
        code printed from the same pieces (the C is printed from them by fixed rules: printing it costs as much,
        so a cache hit skips it) or else the C source, with the generator's version and the toolchain's identity."""
        argv, about = toolchain()
        if argv is None:
            raise ValueError(about)
        _ready_dir(_cache_dir())
        if self._module is None:
            text = self._key_text or c_source(*self._pieces)
            self._module = "_kinlib_" + hashlib.sha256("\0".join([_GENERATOR, text, about]).encode()).hexdigest()[:32]
        return argv, self._module, _cache_dir() / (self._module + _ext_suffix())

    def source(self) -> str:
        """The C source of the extension module (its name filled in when a toolchain is found)."""
        src = c_source(*self._pieces)
        return src.replace("@MODULE@", self._module) if self._module else src

    def build(self, wait: bool = True, on_ready=None) -> bool:
        """Load or compile; True once ``fn`` is the compiled code (with ``wait=False``, False while the background
        thread compiles: ``on_ready`` is called then)."""
        if self.fn is not None:
            return True
        try:
            argv, module, path = self._prepare()
        except ValueError as e:
            self.status = f"Python: {e}"
            return False
        rebuilt = ""
        with _lock:
            fn = _loaded.get(module)
            if fn is None and _verified(path):
                try:
                    fn = _loaded[module] = _load(path, module, self.shape)
                    self.status = f"C (loaded from {path})"
                except (ImportError, OSError) as e:
                    self.status = f"Python: {path} could not be loaded ({e})"
            elif fn is None and (path.exists() or _digest_path(path).exists()):
                rebuilt = "; the cached copy failed its check and was rebuilt"
                if _safe(path) or not path.exists():  # ours but damaged: rebuild (another user's file: never touch)
                    _discard(path)
        if fn is not None:
            return self._ready(fn, on_ready)
        if not wait:
            self.status = "Python (the C is compiling in the background)"
            _worker().submit(self, on_ready)
            return False
        try:
            with _compile_lock:
                fn = _loaded.get(module)
                if fn is None:
                    _compile(argv, self.source(), path)
                    with _lock:
                        fn = _loaded[module] = _load(path, module, self.shape)
                    self.status = f"C (compiled into {path}{rebuilt})"
        except (OSError, ImportError, ValueError, TimeoutError) as e:
            self.status = f"Python: {e}"
            return False
        except Exception as e:  # e.g. subprocess.TimeoutExpired: never break the caller's numbers
            self.status = f"Python: {type(e).__name__}: {e}"
            return False
        return self._ready(fn, on_ready)

    def counting(self, raw, owner, start):
        """``raw`` (the Python single call) wrapped to count: the :data:`HOT_CALLS`-th call puts ``raw`` itself back
        as ``owner._single`` and calls ``start()`` (which compiles in the background).

        >>> calls = []
        >>> class Owner: pass
        >>> o = Owner(); o._single = NativeSingle([], [], 0, (0, 0)).counting(abs, o, lambda: calls.append(1))
        >>> [o._single(-2) for _ in range(HOT_CALLS)][-1], calls, o._single is abs
        (2, [1], True)
        """
        left = [HOT_CALLS]

        def single(q):
            left[0] -= 1
            if left[0] == 0:
                owner._single = raw
                start()
            return raw(q)

        return single

    def _ready(self, fn, on_ready) -> bool:
        self.fn = fn
        if not self.status.startswith("C"):
            self.status = "C (compiled earlier in this process)"
        if on_ready is not None:
            on_ready(fn)
        return True


def _ext_suffix() -> str:
    import sysconfig

    return sysconfig.get_config_var("EXT_SUFFIX") or ".so"


class _Worker:
    """One daemon thread per process that compiles what :meth:`NativeSingle.build` hands it (``cc`` runs in a
    subprocess: the calling thread keeps computing with the Python code meanwhile)."""

    def __init__(self):
        import queue

        self.pid = os.getpid()
        self.jobs = queue.SimpleQueue()
        threading.Thread(target=self._run, name="kinlib-native", daemon=True).start()

    def submit(self, ns: NativeSingle, on_ready) -> None:
        self.jobs.put((ns, on_ready))

    def _run(self):
        while True:
            ns, on_ready = self.jobs.get()
            ns.build(wait=True, on_ready=on_ready)


_the_worker: _Worker | None = None


def _worker() -> _Worker:
    global _the_worker
    with _lock:
        if _the_worker is None or _the_worker.pid != os.getpid():  # a forked child has no thread: start its own
            _the_worker = _Worker()
        return _the_worker
