"""``npm pack`` into a vendor folder, once: the offline copies of the JavaScript packages the handouts use
(the widget embedder, require.js, font-awesome: :mod:`kinlib.course.publish.pages`; the JupyterLite site's Pyodide:
:mod:`kinlib.course.publish.lite`; axe-core for the accessibility test)."""

from __future__ import annotations

import shutil
import subprocess
import tarfile
from pathlib import Path

__all__ = ["npm_pack"]


def npm_pack(name: str, version: str, vendor: Path) -> Path:
    """The unpacked npm package ``name@version`` under ``vendor`` (``npm pack`` from the registry once;
    the ``.tgz`` stays in ``vendor`` beside the unpacked ``package/`` folder).

    A download the first time, hence not run here (tests/course/test_handouts.py and tests/course/test_lite.py use it):

    >>> npm_pack("requirejs", "2.3.8", Path("build/vendor")).name  # doctest: +SKIP
    'package'
    """
    vendor.mkdir(parents=True, exist_ok=True)
    stem = name.lstrip("@").replace("/", "-") + "-" + version
    unpacked = vendor / stem
    if (unpacked / "package" / "package.json").exists():
        return unpacked / "package"
    tgz = vendor / f"{stem}.tgz"
    if not tgz.exists():
        if shutil.which("npm") is None:
            raise RuntimeError(
                f"npm is needed once to fetch {name}@{version} (the offline widget renderer) "
                f"into {vendor}; install node/npm or copy {tgz.name} there"
            )
        r = subprocess.run(
            ["npm", "pack", f"{name}@{version}", "--silent", "--pack-destination", str(vendor)],
            capture_output=True,
            text=True,
        )
        if r.returncode != 0 or not tgz.exists():
            raise RuntimeError(f"npm pack {name}@{version} failed (exit {r.returncode}):\n{r.stderr.strip()[-2000:]}")
    tmp = vendor / (stem + ".tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    with tarfile.open(tgz) as tf:
        tf.extractall(tmp, filter="data")
    shutil.rmtree(unpacked, ignore_errors=True)
    tmp.rename(unpacked)
    return unpacked / "package"
