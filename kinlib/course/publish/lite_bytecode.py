"""The site's Python wheels with their bytecode: ``import sympy`` in the browser without compiling sympy first.

Pyodide's package files (and the PyPI wheels) hold Python sources only, so every kernel start in the browser
compiles each module it imports (sympy, mpmath, IPython, matplotlib's and numpy's Python parts, kinlib) to
bytecode in WebAssembly: measured in Node on Pyodide 0.27.7, ``import sympy`` costs 4.0 s of CPU from sources and
1.3 s with its bytecode. :func:`compile_wheels` adds to each wheel the ``__pycache__/*.cpython-312.pyc`` files,
compiled by the site's own Pyodide (the same CPython 3.12.7, run in Node: no host Python of the right version is
needed) as *unchecked-hash* pycs (PEP 552: used as they are, whatever the files' times after unpacking). The
sources stay (tracebacks show their lines); ``tests/`` folders are not compiled. Each wheel keeps its file name;
its ``RECORD`` lists the added files; the site's ``pyodide-lock.json`` carries the new sha256
(:func:`kinlib.course.publish.lite.build_lite`). The source of a pinned wheel is verified before it is compiled,
and compiled wheels are cached by the source's sha256 (``$KINLIB_CACHE/lite/pyc-0.27.7/``: the build's own output,
trusted as ``build/`` is; delete the folder to compile again). Without ``node`` the wheels go in as they are
(slower first imports, nothing else changes), and the build says so.
"""

from __future__ import annotations

import base64
import hashlib
import shutil
import subprocess
import tempfile
import zipfile
from pathlib import Path

__all__ = ["compile_wheels", "record_line"]

#: compiled by Pyodide in Node: every wheel folder under the mount, its tests left out, unchecked-hash pycs
_NODE_SCRIPT = r"""
const path = require('path');
const [indexURL, root] = process.argv.slice(2);
const {loadPyodide} = require(path.join(indexURL, 'pyodide.js'));
(async () => {
  const py = await loadPyodide({indexURL: indexURL + '/', stdout: s => console.log(s), stderr: s => console.error(s)});
  py.FS.mkdir('/w');
  py.FS.mount(py.FS.filesystems.NODEFS, {root: path.resolve(root)}, '/w');
  py.runPython(`
import compileall, py_compile, re, sys
ok = compileall.compile_dir('/w', quiet=1, rx=re.compile(r'/tests?/'), workers=1,
                            invalidation_mode=py_compile.PycInvalidationMode.UNCHECKED_HASH)
print('compiled', sys.version.split()[0], ok)
if not ok:
    sys.exit(1)
`);
})().catch(e => { console.error(String(e)); process.exit(1); });
"""


def record_line(name: str, data: bytes) -> str:
    """The wheel ``RECORD`` line of a file ``name`` holding ``data`` (PEP 376/427: urlsafe base64 sha256).

    >>> record_line("a/__pycache__/b.cpython-312.pyc", b"abc")
    'a/__pycache__/b.cpython-312.pyc,sha256=ungWv48Bz-pBQUDeXa4iI7ADYaOWF3qctBD_YfIAFa0,3'
    """
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _repack(wheel: Path, tree: Path, dest: Path) -> None:
    """``wheel`` written again to ``dest`` with the ``.pyc`` files found in ``tree`` (its unpacked copy) added
    beside its members and listed in its RECORD."""
    with zipfile.ZipFile(wheel) as z:
        infos = z.infolist()
        names = {i.filename for i in infos}
        record = next((i.filename for i in infos if i.filename.endswith(".dist-info/RECORD")), None)
        added = sorted(
            p.relative_to(tree).as_posix() for p in tree.rglob("*.pyc") if p.relative_to(tree).as_posix() not in names
        )
        with zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as out:
            for info in infos:
                data = z.read(info)
                if info.filename == record:
                    lines = data.decode().rstrip("\n").split("\n")
                    lines[-1:-1] = [record_line(n, (tree / n).read_bytes()) for n in added] if lines else []
                    data = ("\n".join(lines) + "\n").encode()
                out.writestr(info, data, compress_type=zipfile.ZIP_DEFLATED)
            for name in added:
                info = zipfile.ZipInfo(name, date_time=infos[0].date_time if infos else (1980, 1, 1, 0, 0, 0))
                info.external_attr = 0o644 << 16
                out.writestr(info, (tree / name).read_bytes(), compress_type=zipfile.ZIP_DEFLATED)


def compile_wheels(wheels, pyodide: Path, cache: Path | None = None, log=print) -> dict:
    """Compile the wheels ``wheels`` (paths; each already verified) with the Pyodide of the npm package folder
    ``pyodide`` (in Node); return {wheel path: compiled wheel path (same file name, in ``cache`` when given
    (``cache/<sha256 of the source>/``), else beside a temporary folder the caller must not outlive)}. A wheel
    already in ``cache`` is not compiled again. Without ``node``, or if Pyodide fails, returns {} and logs why
    (the caller ships the wheels as they are).

    Needs Node and the Pyodide npm package, hence not run here (tests/course/test_lite.py checks the built
    site's wheels):

    >>> compile_wheels([], Path("pyodide"))
    {}
    >>> compile_wheels([Path("sympy.whl")], Path("pyodide"))  # doctest: +SKIP
    {PosixPath('sympy.whl'): PosixPath('.../sympy.whl')}
    """
    wheels = [Path(w) for w in wheels]
    if not wheels:
        return {}
    node = shutil.which("node")
    if node is None:
        log("  lite: no node: the wheels go in without bytecode (the browser compiles on first import)")
        return {}
    cache = Path(cache) if cache is not None else Path(tempfile.mkdtemp(prefix="kinlib-pyc-"))
    done, todo = {}, []
    for w in wheels:
        target = cache / _sha256(w) / w.name
        if target.is_file():
            done[w] = target
        else:
            todo.append((w, target))
    if not todo:
        return done
    with tempfile.TemporaryDirectory(prefix="kinlib-pyc-") as tmp:
        root = Path(tmp) / "trees"
        for k, (w, _target) in enumerate(todo):
            with zipfile.ZipFile(w) as z:
                z.extractall(root / str(k))
        script = Path(tmp) / "compile.js"
        script.write_text(_NODE_SCRIPT)
        r = subprocess.run([node, str(script), str(Path(pyodide).resolve()), str(root)], capture_output=True, text=True)
        if r.returncode != 0 or "compiled" not in r.stdout:
            log(f"  lite: compiling the wheels in Pyodide failed (exit {r.returncode}); they go in without bytecode:")
            log("    " + (r.stdout + r.stderr).strip()[-600:])
            return {}
        for k, (w, target) in enumerate(todo):
            target.parent.mkdir(parents=True, exist_ok=True)
            part = target.with_name(target.name + ".part")
            _repack(w, root / str(k), part)
            part.replace(target)
            done[w] = target
    log(f"  lite: bytecode for {len(todo)} wheel(s) compiled in Pyodide ({len(done) - len(todo)} cached)")
    return done
