"""``kinlib execute``: run the course notebooks top to bottom and save them in place, with their widget state.

    kinlib execute notebooks                       # every NN_*.ipynb in the folder (what `make notebooks` runs)
    kinlib execute notebooks/05_singularities_planar.ipynb [--timeout 600]

Each notebook runs in a fresh kernel (nbclient, working directory = the notebook's folder) and is written
back only if every cell ran; a failing notebook is left as it was and named with its cell.

What is saved, so that a notebook opened without running shows pictures:

* the outputs of every cell, including each widget's static ``image/png`` fallback (the display bundle of
  :class:`kinlib.widgets.Explorer`), and
* the **widget state** (``metadata.widgets``, nbclient ``store_widget_state=True``): every model the
  outputs refer to, with the explorer's last picture, which JupyterLab restores when it opens the notebook.

Deterministic, so re-executing an unchanged notebook gives an unchanged file: no timing metadata
(``record_timing=False``), consecutive stream outputs merged (``coalesce_streams``: how stdout is chunked
depends on timing), ``PYTHONHASHSEED=0`` in the kernel (set order in printed outputs), and the
random ids are renamed by their order of appearance: widget model ids (uuid4 from ipywidgets) become
``sha1(notebook stem, k)`` in the state, in every ``IPY_MODEL_`` reference and in the outputs, and the
element ids of matplotlib ``to_jshtml`` players (``_anim_img<uuid>``) become ``sha1(stem, cell id, k)``.

>>> from kinlib.course.publish.execute import stable_id
>>> stable_id("05_singularities_planar", 0) == stable_id("05_singularities_planar", 0)
True
>>> len(stable_id("x", 1))
32
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import time
from collections.abc import Callable, Iterable
from pathlib import Path

__all__ = [
    "execute_notebook",
    "execute_all",
    "notebook_client",
    "sliced_get_msg",
    "find_notebooks",
    "stabilize_ids",
    "stable_id",
    "ExecutionFailed",
]

WIDGET_STATE = "application/vnd.jupyter.widget-state+json"
WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
_MODEL_REF = re.compile(r"IPY_MODEL_([0-9a-f]{32})")
_ANIM_ID = re.compile(r"_anim_img([0-9a-f]{32})")


class ExecutionFailed(RuntimeError):
    """A notebook did not run to the end (the message names the notebook and the cell).

    >>> str(ExecutionFailed("05_x.ipynb: ZeroDivisionError: division by zero"))
    '05_x.ipynb: ZeroDivisionError: division by zero'
    """


def stable_id(*parts) -> str:
    """A 32-hex-digit id from ``parts`` (the form of a uuid4 hex, as ipywidgets' model ids have).

    >>> stable_id("a", 1) != stable_id("a", 2)
    True
    """
    return hashlib.sha1("\x1f".join(map(str, parts)).encode()).hexdigest()[:32]


def find_notebooks(paths: Iterable) -> list[Path]:
    """The notebooks named by ``paths``: files as given, folders → their ``NN_*.ipynb`` (sorted).

    >>> find_notebooks([])
    []
    """
    found = []
    for p in map(Path, paths):
        if p.is_dir():
            found += sorted(p.glob("[0-9][0-9]_*.ipynb"))
        elif p.suffix == ".ipynb" and p.is_file():
            found.append(p)
        else:
            raise FileNotFoundError(f"{p}: not a notebook (.ipynb) or a folder of notebooks")
    return found


def stabilize_ids(nb, stem: str) -> dict:
    """Rename the random ids in an executed notebook (an ``nbformat`` node, changed in place) so that the
    same execution gives the same file: widget model ids, and ``to_jshtml`` element ids. Returns the map
    {old model id: new model id}.

    >>> import nbformat
    >>> nb = nbformat.v4.new_notebook()
    >>> a, b = "a" * 32, "b" * 32
    >>> nb.metadata["widgets"] = {WIDGET_STATE: {"state": {a: {"state": {"children": [f"IPY_MODEL_{b}"]}},
    ...                                                    b: {"state": {}}}}}
    >>> cell = nbformat.v4.new_code_cell("w")
    >>> cell.outputs = [nbformat.v4.new_output("execute_result", {WIDGET_VIEW: {"model_id": a}})]
    >>> nb.cells = [cell]
    >>> m = stabilize_ids(nb, "demo")
    >>> cell.outputs[0]["data"][WIDGET_VIEW]["model_id"] == m[a] == stable_id("demo", "model", 0)
    True
    >>> nb.metadata["widgets"][WIDGET_STATE]["state"][m[a]]["state"]["children"] == [f"IPY_MODEL_{m[b]}"]
    True
    """
    mapping: dict[str, str] = {}

    def new(old: str) -> str:
        if old not in mapping:
            mapping[old] = stable_id(stem, "model", len(mapping))
        return mapping[old]

    # the order of appearance: outputs first (notebook order), then the models they contain, then the rest
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            view = out.get("data", {}).get(WIDGET_VIEW)
            if isinstance(view, dict) and view.get("model_id"):
                new(view["model_id"])
    widgets = nb.metadata.get("widgets", {}).get(WIDGET_STATE)
    if widgets and isinstance(widgets.get("state"), dict):
        state = widgets["state"]
        pending = list(mapping)
        seen = set()
        while pending:  # breadth-first through the IPY_MODEL_ references
            mid = pending.pop(0)
            if mid in seen or mid not in state:
                continue
            seen.add(mid)
            for ref in _MODEL_REF.findall(json.dumps(state[mid], sort_keys=True)):
                new(ref)
                pending.append(ref)
        for mid in state:  # models no output refers to
            new(mid)
        text = json.dumps(state, sort_keys=True)
        text = _MODEL_REF.sub(lambda m: "IPY_MODEL_" + mapping.get(m.group(1), m.group(1)), text)
        state = json.loads(text)
        widgets["state"] = {mapping.get(k, k): v for k, v in state.items()}
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            data = out.get("data", {})
            view = data.get(WIDGET_VIEW)
            if isinstance(view, dict) and view.get("model_id") in mapping:
                view["model_id"] = mapping[view["model_id"]]
            html = data.get("text/html")
            if html is None:
                continue
            text = "".join(html) if isinstance(html, list) else html
            for k, old in enumerate(dict.fromkeys(_ANIM_ID.findall(text))):
                text = text.replace(old, stable_id(stem, cell.get("id", ""), "anim", k))
            data["text/html"] = text
    return mapping


#: seconds a kernel channel is polled at a time (see :func:`sliced_get_msg`)
POLL_SLICE = 0.5


def sliced_get_msg(get_msg, step: float = POLL_SLICE):
    """``get_msg(timeout)`` of a jupyter_client asyncio channel, waiting in slices of ``step`` seconds.

    Measured here (pyzmq 27.3, jupyter_client 8.10, nbclient 0.11): now and then (about one kernel in twenty,
    idle or loaded) a kernel's reply sits in its zmq.asyncio socket while the poll waiting for it is never woken
    (zmq.asyncio's edge-triggered file descriptor; pyzmq#2173 reports the same); the poll returns it only when
    its timeout ends, and nbclient waits for a cell's reply with the whole cell timeout (120 s) as one poll, so
    the notebook stalled 120 s and then carried on, outputs complete. A fresh poll looks at the socket first,
    so waiting in short slices takes a missed wake-up after ``step`` seconds at most; the total timeout and
    every message are as before (a slice that ends empty consumes nothing).

    >>> import asyncio
    >>> from queue import Empty
    >>> calls = []
    >>> async def stalled(timeout=None):          # a reply that only a fresh poll sees
    ...     calls.append(timeout)
    ...     if len(calls) < 3:
    ...         raise Empty
    ...     return {"msg_type": "execute_reply"}
    >>> asyncio.run(sliced_get_msg(stalled, 0.01)(timeout=120))["msg_type"], calls
    ('execute_reply', [0.01, 0.01, 0.01])
    >>> async def silent(timeout=None):
    ...     await asyncio.sleep(timeout)
    ...     raise Empty
    >>> try:
    ...     asyncio.run(sliced_get_msg(silent, 0.01)(timeout=0.03))
    ... except Empty:
    ...     print("Empty after the whole timeout, as before")
    Empty after the whole timeout, as before
    """
    from queue import Empty

    async def get(timeout=None):
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            left = None if deadline is None else max(0.0, deadline - time.monotonic())
            try:
                return await get_msg(timeout=step if left is None else min(step, left))
            except Empty:
                if left is not None and left <= step:
                    raise

    return get


_CLIENT_CLASS: list = []


def notebook_client(nb, **kwargs):
    """An nbclient ``NotebookClient`` for ``nb`` (keyword arguments as nbclient's) whose kernel channels wait for
    messages in short slices (:func:`sliced_get_msg`): every notebook kinlib runs goes through it.

    >>> import nbformat
    >>> client = notebook_client(nbformat.v4.new_notebook(), timeout=60, kernel_name="python3")
    >>> type(client).__mro__[1].__name__, client.timeout
    ('NotebookClient', 60)
    """
    if not _CLIENT_CLASS:
        from nbclient import NotebookClient

        class _SlicedClient(NotebookClient):
            async def async_start_new_kernel_client(self):
                kc = await super().async_start_new_kernel_client()
                for channel in (kc.shell_channel, kc.iopub_channel):
                    channel.get_msg = sliced_get_msg(channel.get_msg)
                return kc

        _CLIENT_CLASS.append(_SlicedClient)
    return _CLIENT_CLASS[0](nb, **kwargs)


def execute_notebook(path, *, timeout: float = 600, kernel_name: str | None = None) -> float:
    """Execute the notebook at ``path`` in a fresh kernel and write it back in place (outputs, widget state,
    stable ids). Returns the seconds taken. Raises :class:`ExecutionFailed` (the file is left unchanged)
    if a cell raises or times out.

    >>> import nbformat, pathlib, tempfile
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "01_demo.ipynb"
    >>> nbformat.write(nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("6 * 7")]), p)
    >>> seconds = execute_notebook(p, timeout=120)
    >>> nbformat.read(p, as_version=4).cells[0].outputs[0]["data"]["text/plain"]
    '42'
    """
    import nbformat
    from nbclient.exceptions import CellExecutionError, CellTimeoutError, DeadKernelError

    path = Path(path)
    nb = nbformat.read(path, as_version=4)
    name = kernel_name or nb.metadata.get("kernelspec", {}).get("name") or "python3"
    nb.metadata.pop("widgets", None)  # only the state of this run
    client = notebook_client(
        nb,
        timeout=timeout,
        kernel_name=name,
        resources={"metadata": {"path": str(path.parent.resolve())}},
        store_widget_state=True,
        record_timing=False,
        coalesce_streams=True,  # stdout arrives in chunks that depend on timing: one stream output per cell
    )
    old_seed = os.environ.get("PYTHONHASHSEED")
    os.environ["PYTHONHASHSEED"] = "0"  # inherited by the kernel: set printing order does not vary
    t0 = time.perf_counter()
    try:
        client.execute()
    except (CellExecutionError, CellTimeoutError, DeadKernelError) as exc:
        lines = [ln for ln in str(exc).strip().splitlines() if ln.strip()]
        raise ExecutionFailed(f"{path.name}: " + " | ".join(lines[-3:])[:600]) from None
    finally:
        if old_seed is None:
            os.environ.pop("PYTHONHASHSEED", None)
        else:
            os.environ["PYTHONHASHSEED"] = old_seed
    seconds = time.perf_counter() - t0
    for cell in nb.cells:
        cell.metadata.pop("execution", None)
    stabilize_ids(nb, path.stem)
    text = nbformat.writes(nb)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text if text.endswith("\n") else text + "\n", encoding="utf-8")
    os.replace(tmp, path)  # atomic: a reader never sees half a notebook
    return seconds


def execute_all(paths, *, timeout: float = 600, log: Callable[[str], None] = print) -> list[str]:
    """Execute every notebook named by ``paths`` (files or folders) in place, one after the other.
    Returns the failures (one line each); the notebooks that ran are written even if another failed.

    >>> execute_all([])   # nothing to run, nothing failed
    []
    """
    failures = []
    for nb in find_notebooks(paths):
        try:
            dt = execute_notebook(nb, timeout=timeout)
            log(f"executed {nb} in {dt:.1f} s")
        except ExecutionFailed as exc:
            failures.append(str(exc))
            log(f"FAILED {exc}")
    return failures
