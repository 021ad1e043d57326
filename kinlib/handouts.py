"""``make handouts``: HTML handouts, student workbooks and an index, from the executed notebooks.

    python -m kinlib.handouts notebooks --out build/handouts [--jobs 2] [--timeout 120] [--no-verify]

For every ``notebooks/NN_*.ipynb`` (executed with nbclient, then exported with nbconvert) it writes

- ``solutions/NN_*.html``: the whole notebook with its outputs;
- ``problems/NN_*.html``: questions, narrative, set-up and figures; left out: ``solution`` and
  ``check`` cells, the untagged markdown inside a worked solution (between a ``question`` and the last
  ``solution``/``check`` cell answering it), cells that read answer variables (and their markdown
  caption just above), any output that repeats an answer cell's output; no prompt numbers; the saved
  widget state pruned to the widgets still shown;
- ``workbooks/NN_*.ipynb``: the student notebook: each ``solution`` code cell becomes a stub
  (``Js = ...  # TODO: ...``, keeping its ``kinlib`` metadata), each solution markdown cell a prompt,
  each ``check`` cell a self-check (:mod:`kinlib.selfcheck`) that compares a fingerprint of the
  student's answer with the reference's made here (a part without a check cell gets one after its
  last solution cell); worked-solution markdown left out as above; cells that use answer variables
  run only once those are filled in (``%%needs``); outputs cleared. Unless ``--no-verify``, each
  workbook is then run top to bottom (the stubs must not crash it);
- ``index.html`` linking everything, and ``assets/``: MathJax 2 (copied from the installed
  ``jupyter-server-mathjax``), require.js and the ``@jupyter-widgets/html-manager`` embed bundle
  (``npm pack`` from the npm registry into ``build/vendor`` once, then reused), so every page
  renders offline.

Progress goes to stdout; a failing cell stops the job with the notebook and the cell named (exit 1).
"""
from __future__ import annotations

import argparse
import ast
import asyncio
import copy
import html
import json
import re
import shutil
import subprocess
import sys
import tarfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import nbformat

__all__ = ["build", "build_assets", "execute_notebook", "make_problems", "make_workbook",
           "answer_groups", "run_workbook", "NotebookFailed", "main"]

HTML_MANAGER = ("@jupyter-widgets/html-manager", "1.0.15")   # the embedder for ipywidgets 8.1 (controls 5)
REQUIREJS = ("requirejs", "2.3.8")
FONT_AWESOME = ("font-awesome", "4.7.0")    # the play buttons of matplotlib's to_jshtml() animations
_FA_CDN = re.compile(r"https?://(?:maxcdn|stackpath)\.bootstrapcdn\.com/font-awesome/[0-9.]+/css/font-awesome(?:\.min)?\.css")
_FA_LOCAL = "../assets/font-awesome/css/font-awesome.min.css"
_REQUIRE_TAG = '<script src="../assets/require.js"></script>'
# The widget bundle finds its icon fonts relative to its AMD module ids: point those at assets/widgets/.
_WIDGET_PATHS = """<script>
window.__jupyter_widgets_assets_path__ = "../assets/widgets/";
if (window.requirejs) {
  requirejs.config({paths: {
    "@jupyter-widgets/html-manager/dist": "../assets/widgets",
    "@jupyter-widgets/base": "../assets/widgets/base", "@jupyter-widgets/controls": "../assets/widgets/controls",
    "@jupyter-widgets/output": "../assets/widgets/output", "@jupyter-widgets/html-manager": "../assets/widgets/hm"}});
}
</script>"""
MATHJAX_CONFIG = "TeX-AMS-MML_HTMLorMML-full,Safe,kinlib"
ANSWER_TAGS = {"solution", "check"}
_SELFCHECK_MARK = "KINLIB-SELFCHECK "

_MATHJAX_LOCAL_CONFIG = """\
/* kinlib: MathJax 2 from jupyter-server-mathjax ships only the STIX-Web fonts: use them, no image fonts. */
/* No URL that is not there: MathJax_Blank (a font-loading probe) and the TeX web fonts of the hidden
   (assistive) MathML point at local() names instead of about:blank and the missing TeX otf files. */
(function () {
  var none = "local('kinlib-no-such-font')", mml = {};
  for (var i = 1; i <= 6; i++) { mml["@font-face /*" + i + "*/"] = {src: none}; }
  MathJax.Hub.Config({
    "HTML-CSS": {availableFonts: [], preferredFont: null, webFont: "STIX-Web", imageFont: null,
                 styles: {"@font-face": {"font-family": "MathJax_Blank", src: none}}},
    NativeMML: {styles: mml},
    SVG: {font: "STIX-Web"},
    MathMenu: {showLocale: false}
  });
})();
MathJax.Ajax.loadComplete("[MathJax]/config/kinlib.js");
"""


class NotebookFailed(RuntimeError):
    """A notebook failed to execute: names the notebook and the cell."""

    def __init__(self, path, index, cell, error):
        self.path, self.index, self.cell, self.error = Path(path), index, cell, error
        tags = ", ".join(cell.metadata.get("tags", [])) or "none"
        part = cell.metadata.get("kinlib", {}).get("part")
        src = "\n".join("    | " + line for line in cell.source.splitlines()[:6])
        ename = getattr(error, "ename", type(error).__name__)
        evalue = getattr(error, "evalue", str(error))
        super().__init__(
            f"{self.path.name}: cell {index} failed (code cell, tags: {tags}"
            + (f", part {part}" if part else "") + f"):\n{src}\n  {ename}: {evalue}")


# ---------------------------------------------------------------------------------------------------
# Offline assets

def _npm_pack(name: str, version: str, vendor: Path) -> Path:
    """The unpacked npm package ``name@version`` under ``vendor`` (``npm pack`` from the registry once)."""
    vendor.mkdir(parents=True, exist_ok=True)
    stem = name.lstrip("@").replace("/", "-") + "-" + version
    unpacked = vendor / stem
    if (unpacked / "package" / "package.json").exists():
        return unpacked / "package"
    tgz = vendor / f"{stem}.tgz"
    if not tgz.exists():
        if shutil.which("npm") is None:
            raise RuntimeError(f"npm is needed once to fetch {name}@{version} (the offline widget renderer) "
                               f"into {vendor}; install node/npm or copy {tgz.name} there")
        r = subprocess.run(["npm", "pack", f"{name}@{version}", "--silent", "--pack-destination", str(vendor)],
                           capture_output=True, text=True)
        if r.returncode != 0 or not tgz.exists():
            raise RuntimeError(f"npm pack {name}@{version} failed (exit {r.returncode}):\n{r.stderr.strip()[-2000:]}")
    tmp = vendor / (stem + ".tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    with tarfile.open(tgz) as tf:
        tf.extractall(tmp, filter="data")
    shutil.rmtree(unpacked, ignore_errors=True)
    tmp.rename(unpacked)
    return unpacked / "package"


def build_assets(assets: Path, vendor: Path) -> dict:
    """Copy MathJax, require.js and the widget embedder into ``assets``; return their relative URLs."""
    import jupyter_server_mathjax
    assets.mkdir(parents=True, exist_ok=True)
    mj_src = Path(jupyter_server_mathjax.__file__).parent / "static"
    mj = assets / "mathjax"
    if not (mj / "MathJax.js").exists():
        shutil.copytree(mj_src, mj, dirs_exist_ok=True)
    (mj / "config" / "kinlib.js").write_text(_MATHJAX_LOCAL_CONFIG)

    hm = _npm_pack(*HTML_MANAGER, vendor)
    wdst = assets / "widgets"
    wdst.mkdir(exist_ok=True)
    for f in (hm / "dist").iterdir():
        if f.name == "embed-amd.js" or f.suffix in (".woff", ".woff2", ".ttf", ".eot", ".svg"):
            shutil.copy2(f, wdst / f.name)
    rq = _npm_pack(*REQUIREJS, vendor)
    shutil.copy2(rq / "require.js", assets / "require.js")
    fa = _npm_pack(*FONT_AWESOME, vendor)
    for sub in ("css", "fonts"):
        shutil.copytree(fa / sub, assets / "font-awesome" / sub, dirs_exist_ok=True)
    return {"mathjax_url": f"../assets/mathjax/MathJax.js?config={MATHJAX_CONFIG}",
            "require_js_url": "../assets/require.js",
            "widget_renderer_url": "../assets/widgets/embed-amd.js"}


# ---------------------------------------------------------------------------------------------------
# The notebook's graded parts

def _tags(cell) -> list:
    return list(cell.metadata.get("tags", []))


def _kinlib_meta(cell) -> dict:
    return dict(cell.metadata.get("kinlib", {}))


@dataclass
class Group:
    """The answers checked together: solution cells up to a check cell (or the next question)."""
    answers: list = field(default_factory=list)   # (part, name, kind, cell index)
    check_cell: int | None = None                   # index of the check cell, if any
    last_solution: int = -1


def answer_groups(nb) -> list[Group]:
    """Group the answer variables of ``solution`` code cells by the ``check`` cell that follows them."""
    groups, pending = [], Group()

    def close(check=None):
        nonlocal pending
        if pending.answers or check is not None:
            pending.check_cell = check
            groups.append(pending)
        pending = Group()

    for i, cell in enumerate(nb.cells):
        tags = _tags(cell)
        if "solution" in tags and "check" in tags:
            raise ValueError(f"cell {i} is tagged both 'solution' and 'check'")
        if "question" in tags:
            close()
        if "solution" in tags and cell.cell_type == "code":
            meta = _kinlib_meta(cell)
            kinds = meta.get("kinds", {})
            for name in meta.get("answers", []):
                pending.answers = [a for a in pending.answers if a[1] != name]
                pending.answers.append((str(meta.get("part", "")), name, kinds.get(name, "default"), i))
            pending.last_solution = i
        if "check" in tags:
            close(check=i)
    close()
    return groups


# ---------------------------------------------------------------------------------------------------
# Execution

def _capture_code(answers: dict) -> str:
    return f"__import__('kinlib.selfcheck').selfcheck._emit({answers!r}, globals())"


async def _execute(nb, path: Path, timeout: int, capture_after: dict) -> dict:
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError, CellTimeoutError, DeadKernelError

    client = NotebookClient(nb, timeout=timeout, kernel_name="python3", record_timing=False,
                            resources={"metadata": {"path": str(path.parent)}})
    fingerprints: dict = {}
    count = 0
    async with client.async_setup_kernel(stderr=subprocess.DEVNULL):  # quiet: ipykernel's TCP warning
        msg_id = client.kc.kernel_info()
        info = await client.async_wait_for_reply(msg_id)
        if info is not None and "language_info" in info["content"]:
            nb.metadata["language_info"] = info["content"]["language_info"]
        for i, cell in enumerate(nb.cells):
            if cell.cell_type == "code" and cell.source.strip():
                count += 1
            try:
                await client.async_execute_cell(cell, i, execution_count=count)
            except (CellExecutionError, CellTimeoutError, DeadKernelError) as e:
                raise NotebookFailed(path, i, cell, e) from None
            if i in capture_after:
                probe = nbformat.v4.new_code_cell(_capture_code(capture_after[i]))
                try:
                    await client.async_execute_cell(probe, i, store_history=False)
                except CellExecutionError as e:
                    raise NotebookFailed(path, i, cell, e) from None
                finally:
                    nb.cells[i] = cell          # execute_cell stores the probe at index i: put the cell back
                text = "".join(o.get("text", "") for o in probe.outputs if o.get("output_type") == "stream")
                for line in text.splitlines():
                    if line.startswith(_SELFCHECK_MARK):
                        for name, fp in json.loads(line[len(_SELFCHECK_MARK):]).items():
                            if "error" in fp:         # the workbook says: no automatic self-check
                                fp = {"spec": "none||", "describe": "", "warning":
                                      f"cell {i}: answer {name!r} has no self-check ({fp['error']})"}
                            fingerprints[(i, name)] = fp
        client.set_widgets_metadata()
    return fingerprints


def execute_notebook(path: Path, timeout: int = 120):
    """Execute ``path``; return (executed notebook, groups, {(cell index, name): fingerprint})."""
    nb = nbformat.read(path, as_version=4)
    groups = answer_groups(nb)
    capture_after: dict = {}
    for g in groups:
        for part, name, kind, idx in g.answers:
            capture_after.setdefault(idx, {})[name] = (kind, part)
    fps = _run_async(lambda: _execute(nb, Path(path), timeout, capture_after))
    return nb, groups, fps


def _run_async(make_coro):
    """asyncio.run, in a worker thread when this thread already runs an event loop (e.g. under playwright)."""
    try:
        asyncio.get_running_loop()
    except RuntimeError:
        return asyncio.run(make_coro())
    with ThreadPoolExecutor(max_workers=1) as pool:
        return pool.submit(lambda: asyncio.run(make_coro())).result()


# ---------------------------------------------------------------------------------------------------
# Problems: the executed notebook without answers

def _output_texts(output) -> list[str]:
    texts = []
    if output.get("output_type") == "stream":
        texts.append(output.get("text", ""))
    for mime in ("text/plain", "text/latex", "text/markdown", "text/html"):
        v = output.get("data", {}).get(mime)
        if v:
            texts.append(v if isinstance(v, str) else "".join(v))
    return texts


def _leak_signatures(cells) -> tuple[set, set]:
    """Texts (lines of ≥ 12 characters, whole LaTeX outputs) and images shown by answer cells."""
    texts, images = set(), set()
    for c in cells:
        for o in c.get("outputs", []):
            for t in _output_texts(o):
                pieces = [t.strip()]
                if o.get("output_type") == "stream":          # printed lines count one by one
                    pieces += [ln.strip() for ln in t.splitlines()]
                for piece in pieces:
                    if (len(piece) >= 12 and sum(ch.isalnum() for ch in piece) >= 4
                            and not piece.startswith("<Figure size")):
                        texts.add(piece)
            for mime in ("image/png", "image/jpeg"):
                if mime in o.get("data", {}):
                    images.add(o["data"][mime])
    return texts, images


def _leaks(output, texts, images) -> bool:
    data = output.get("data", {})
    if any(data.get(m) in images for m in ("image/png", "image/jpeg") if m in data):
        return True
    for t in _output_texts(output):
        if any(s in t for s in texts):
            return True
    return False


def _widget_ids(obj, found: set):
    if isinstance(obj, str):
        if obj.startswith("IPY_MODEL_"):
            found.add(obj[len("IPY_MODEL_"):])
    elif isinstance(obj, dict):
        for v in obj.values():
            _widget_ids(v, found)
    elif isinstance(obj, list):
        for v in obj:
            _widget_ids(v, found)


def prune_widget_state(nb) -> None:
    """Keep only the saved widget models that the notebook's remaining outputs show (and what they use)."""
    key = "application/vnd.jupyter.widget-state+json"
    state = nb.metadata.get("widgets", {}).get(key, {}).get("state")
    if state is None:
        return
    todo = set()
    for c in nb.cells:
        for o in c.get("outputs", []):
            view = o.get("data", {}).get("application/vnd.jupyter.widget-view+json")
            if view:
                todo.add(view["model_id"])
    keep = set()
    while todo:
        mid = todo.pop()
        if mid in keep or mid not in state:
            continue
        keep.add(mid)
        found: set = set()
        _widget_ids(state[mid], found)
        todo |= found - keep
    if keep:
        nb.metadata["widgets"][key]["state"] = {k: v for k, v in state.items() if k in keep}
    else:
        del nb.metadata["widgets"]


def make_problems(executed) -> tuple:
    """The problem version of an executed notebook, and a list of notes on what was dropped."""
    nb = copy.deepcopy(executed)
    answer_cells = [c for c in nb.cells if ANSWER_TAGS & set(_tags(c))]
    texts, images = _leak_signatures(answer_cells)
    dependents = answer_dependents(nb)
    narrative = worked_narrative(nb)
    notes, cells = [], []
    if narrative:
        notes.append(f"problems and workbook: left out {len(narrative)} untagged markdown cell(s) inside worked "
                     f"solutions (cells {', '.join(map(str, sorted(narrative)))})")
    dropped = [i for i in dependents if not ANSWER_TAGS & set(_tags(nb.cells[i]))]
    if dropped:
        notes.append(f"problems: left out {len(dropped)} cell(s) computed from answers "
                     f"(cells {', '.join(map(str, sorted(dropped)))})")
    captions = {i - 1 for i in dependents if i > 0 and nb.cells[i - 1].cell_type == "markdown"
                and not _tags(nb.cells[i - 1]) and not nb.cells[i - 1].source.lstrip().startswith("#")}
    for i, c in enumerate(nb.cells):
        if ANSWER_TAGS & set(_tags(c)) or i in narrative or i in dependents or i in captions:
            continue       # answers, worked-solution steps, what is computed from answers and its caption
        if c.cell_type == "code":
            kept = [o for o in c.outputs if not _leaks(o, texts, images)]
            if len(kept) != len(c.outputs):
                notes.append(f"problems: cell {i}: dropped {len(c.outputs) - len(kept)} output(s) that repeat "
                             "an answer")
            for o in kept:
                if "execution_count" in o:
                    o["execution_count"] = None
            c.outputs = kept
            c.execution_count = None
        cells.append(c)
    nb.cells = cells
    prune_widget_state(nb)
    return nb, notes


# ---------------------------------------------------------------------------------------------------
# Workbooks

def _python_source(src: str) -> str:
    """Cell source as plain Python (IPython magics and shell escapes transformed)."""
    from IPython.core.inputtransformer2 import TransformerManager
    return TransformerManager().transform_cell(src)


class _Names(ast.NodeVisitor):
    """Names a cell reads before binding them (free names), and names it binds, in evaluation order."""

    def __init__(self):
        self.free, self.bound = set(), set()

    def visit_Name(self, node):
        if isinstance(node.ctx, ast.Load):
            if node.id not in self.bound:
                self.free.add(node.id)
        else:
            self.bound.add(node.id)

    def visit_Assign(self, node):
        self.visit(node.value)
        for t in node.targets:
            self.visit(t)

    def visit_AnnAssign(self, node):
        if node.value is not None:
            self.visit(node.value)
        self.visit(node.target)

    def visit_AugAssign(self, node):
        self.visit(node.value)
        if isinstance(node.target, ast.Name):
            if node.target.id not in self.bound:
                self.free.add(node.target.id)
            self.bound.add(node.target.id)
        else:
            self.visit(node.target)

    def visit_NamedExpr(self, node):
        self.visit(node.value)
        self.visit(node.target)

    def visit_For(self, node):
        self.visit(node.iter)
        self.visit(node.target)
        for n in node.body + node.orelse:
            self.visit(n)

    def _comprehension(self, node, elts):
        outer = set(self.bound)
        for g in node.generators:
            self.visit(g.iter)
            self.visit(g.target)
            for cond in g.ifs:
                self.visit(cond)
        for e in elts:
            self.visit(e)
        self.bound = outer                  # comprehension variables do not leak

    def visit_ListComp(self, node):
        self._comprehension(node, [node.elt])

    visit_SetComp = visit_GeneratorExp = visit_ListComp

    def visit_DictComp(self, node):
        self._comprehension(node, [node.key, node.value])

    def _function(self, node, body):
        for d in getattr(node, "decorator_list", []):
            self.visit(d)
        for d in node.args.defaults + [d for d in node.args.kw_defaults if d is not None]:
            self.visit(d)
        if not isinstance(node, ast.Lambda):
            self.bound.add(node.name)
        outer = set(self.bound)
        a = node.args
        self.bound |= {x.arg for x in a.posonlyargs + a.args + a.kwonlyargs}
        self.bound |= {x.arg for x in (a.vararg, a.kwarg) if x is not None}
        for n in body:
            self.visit(n)
        self.bound = outer | ({node.name} if not isinstance(node, ast.Lambda) else set())

    def visit_FunctionDef(self, node):
        self._function(node, node.body)

    visit_AsyncFunctionDef = visit_FunctionDef

    def visit_Lambda(self, node):
        self._function(node, [node.body])

    def visit_ClassDef(self, node):
        for n in node.bases + node.decorator_list:
            self.visit(n)
        self.bound.add(node.name)

    def visit_Import(self, node):
        for a in node.names:
            self.bound.add((a.asname or a.name).split(".")[0])

    visit_ImportFrom = visit_Import


def _names(src: str) -> tuple[set, set]:
    """(names read before being bound, names bound) by a code cell; empty sets if it does not parse."""
    try:
        tree = ast.parse(_python_source(src))
    except SyntaxError:
        return set(), set()
    v = _Names()
    for stmt in tree.body:
        v.visit(stmt)
    return v.free, v.bound


def worked_narrative(nb) -> set:
    """Untagged markdown cells inside a worked solution: after a ``question`` cell and before the last
    ``solution``/``check`` cell answering it (its steps and explanations). Problems and workbooks drop them."""
    out: set = set()
    cells = nb.cells
    questions = [i for i, c in enumerate(cells) if "question" in _tags(c)]
    for k, q in enumerate(questions):
        stop = questions[k + 1] if k + 1 < len(questions) else len(cells)
        answers = [i for i in range(q + 1, stop) if ANSWER_TAGS & set(_tags(cells[i]))]
        if answers:
            out |= {i for i in range(q + 1, answers[-1])
                    if cells[i].cell_type == "markdown" and not _tags(cells[i])}
    return out


def answer_dependents(nb) -> dict:
    """{cell index: names it reads that come from solution cells} for the other code cells.

    Names bound by ``solution`` cells, and by cells that use them, exist only once the student has
    answered; a cell that reads one of them (before any non-answer cell bound it) depends on answers.
    """
    answer_names: set = set()
    defined: set = set()
    needs: dict = {}
    for i, cell in enumerate(nb.cells):
        if cell.cell_type != "code":
            continue
        loads, binds = _names(cell.source)
        tags = set(_tags(cell))
        if "solution" in tags:
            answer_names |= binds
            continue
        if "check" in tags:
            continue
        used = sorted((loads & answer_names) - defined)
        if used:
            needs[i] = used
            answer_names |= binds
        else:
            defined |= binds - answer_names
    return needs


def _stub(cell, describe: dict) -> str:
    meta = _kinlib_meta(cell)
    part = meta.get("part", "")
    answers = meta.get("answers", [])
    words = meta.get("describe", {})
    lines = [f"# Part {part}: your answer. Replace each ... below; the self-check further down says "
             "whether it is right." if answers else f"# Part {part}: your work here."]
    for name in answers:
        what = ", ".join(x for x in (words.get(name), describe.get(name)) if x)
        lines.append(f"{name} = ...  # TODO: {what or 'your answer'} (part {part})")
    return "\n".join(lines) + "\n"


def _selfcheck_source(answers: list, fps: dict) -> str:
    by_part: dict = {}
    for part, name, kind, idx in answers:
        by_part.setdefault(part, []).append(f'{name}="{fps[(idx, name)]["spec"]}"')
    lines = ["# Self-check: says whether your answers are right, without showing them.",
             "from kinlib.selfcheck import check", ""]
    lines += [f'check("{part}", {", ".join(args)})' for part, args in by_part.items()]
    return "\n".join(lines) + "\n"


def make_workbook(source_nb, groups: list, fps: dict):
    """The student workbook made from the (unexecuted) notebook, its groups and the fingerprints."""
    nb = copy.deepcopy(source_nb)
    nb.metadata.pop("widgets", None)
    describe = {(idx, name): fp.get("describe", "") for (idx, name), fp in fps.items()}
    check_group = {g.check_cell: g for g in groups if g.check_cell is not None}
    after = {g.last_solution: g for g in groups if g.check_cell is None and g.answers}

    needs = answer_dependents(nb)
    narrative = worked_narrative(nb)

    cells = []
    part = ""
    for i, cell in enumerate(nb.cells):
        tags = set(_tags(cell))
        meta = _kinlib_meta(cell)
        part = str(meta.get("part", part))
        if cell.cell_type == "code":
            cell.outputs, cell.execution_count = [], None
        if "solution" in tags:
            if cell.cell_type == "code":
                d = {name: describe.get((i, name), "") for name in meta.get("answers", [])}
                cell.source = _stub(cell, d)
            else:
                cell.source = f"**Your answer (part {part}):** *write it here.*"
                cell.pop("attachments", None)
            cells.append(cell)
        elif "check" in tags:
            g = check_group.get(i)
            if g is not None and g.answers:
                cells.append(_selfcheck_cell(g, fps, cell))
        elif i in narrative:
            pass
        else:
            if i in needs:
                cell.source = f"%%needs {' '.join(needs[i])}\n" + cell.source
            cells.append(cell)
        if i in after:
            cells.append(_selfcheck_cell(after[i], fps, None))
    if needs:
        setup = nbformat.v4.new_code_cell(
            "%load_ext kinlib.selfcheck\n# (cells marked %%needs run once the answers they use are filled in)")
        setup.metadata["tags"] = ["workbook-setup"]
        first_code = next((k for k, c in enumerate(cells) if c.cell_type == "code"), len(cells))
        cells.insert(first_code, setup)
    nb.cells = cells
    nbformat.validator.normalize(nb)
    return nb


def _selfcheck_cell(group: Group, fps: dict, original):
    cell = nbformat.v4.new_code_cell(_selfcheck_source(group.answers, fps))
    if original is not None and "kinlib" in original.metadata:
        cell.metadata["kinlib"] = copy.deepcopy(original.metadata["kinlib"])
    cell.metadata["tags"] = ["selfcheck"]
    return cell


def run_workbook(path: Path, timeout: int = 120):
    """Run a workbook top to bottom (it must not raise); return the executed notebook."""
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError
    nb = nbformat.read(path, as_version=4)
    client = NotebookClient(nb, timeout=timeout, kernel_name="python3", record_timing=False,
                            resources={"metadata": {"path": str(Path(path).parent)}})
    try:
        _run_async(lambda: client.async_execute(stderr=subprocess.DEVNULL))
    except CellExecutionError as e:
        idx = next((k for k, c in enumerate(nb.cells) if any(o.get("output_type") == "error"
                                                              for o in c.get("outputs", []))), -1)
        raise NotebookFailed(path, idx, nb.cells[idx] if idx >= 0 else nbformat.v4.new_code_cell(""), e) from None
    return nb


# ---------------------------------------------------------------------------------------------------
# HTML and index

def export_html(nb, dest: Path, urls: dict, *, title: str, problems: bool) -> None:
    from nbconvert import HTMLExporter
    nb = copy.deepcopy(nb)
    for c in nb.cells:                      # matplotlib's to_jshtml() links font-awesome on a CDN
        for o in c.get("outputs", []):
            h = o.get("data", {}).get("text/html")
            if h:
                h = _FA_CDN.sub(_FA_LOCAL, h if isinstance(h, str) else "".join(h))
                if "_anim_img" in h and _FA_LOCAL not in h:      # an animation whose CDN link was dropped
                    h = f'<link rel="stylesheet" href="{_FA_LOCAL}">\n' + h
                o["data"]["text/html"] = h
    exporter = HTMLExporter(template_name="lab", embed_images=True, exclude_input_prompt=problems,
                            exclude_output_prompt=problems, **urls)
    body, _ = exporter.from_notebook_node(nb, resources={"metadata": {"name": title}})
    if _REQUIRE_TAG not in body:
        raise RuntimeError(f"nbconvert's lab template changed: no {_REQUIRE_TAG} in {dest.name}")
    body = body.replace(_REQUIRE_TAG, _REQUIRE_TAG + "\n" + _WIDGET_PATHS, 1)
    dest.parent.mkdir(parents=True, exist_ok=True)
    dest.write_text(body, encoding="utf-8")


_INDEX = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>kinlib handouts</title>
<style>
body {{ font-family: system-ui, sans-serif; max-width: 60rem; margin: 2rem auto; padding: 0 1rem; color: #222; }}
table {{ border-collapse: collapse; width: 100%; }} th, td {{ text-align: left; padding: .5rem; border-bottom: 1px solid #ddd; }}
td.sections {{ color: #666; font-size: .9em; }} a {{ margin-right: .8rem; }}
</style></head><body>
<h1>kinlib: Jacobians, singularities and manipulability</h1>
<p>Problems (no answers), solutions (worked, with outputs) and workbooks (Jupyter notebooks to fill in, with self-checks)
for each notebook. Everything here works offline.</p>
<table><thead><tr><th>#</th><th>Notebook</th><th>Sections</th><th>Handouts</th></tr></thead><tbody>
{rows}
</tbody></table>
<p><small>Built by <code>make handouts</code> ({when}).</small></p>
</body></html>
"""


def write_index(out: Path, entries: list) -> None:
    rows = []
    for e in entries:
        stem = e["stem"]
        rows.append(
            f'<tr><td>{html.escape(stem[:2])}</td><td>{html.escape(e["title"])}</td>'
            f'<td class="sections">{html.escape(", ".join(e["sections"]))}</td>'
            f'<td><a href="problems/{stem}.html">problems</a><a href="solutions/{stem}.html">solutions</a>'
            f'<a href="workbooks/{stem}.ipynb" download>workbook (.ipynb)</a></td></tr>')
    (out / "index.html").write_text(_INDEX.format(rows="\n".join(rows), when=time.strftime("%Y-%m-%d")),
                                    encoding="utf-8")


# ---------------------------------------------------------------------------------------------------
# The job

def _title(nb, stem: str) -> str:
    return nb.metadata.get("kinlib", {}).get("title") or stem.replace("_", " ")


def build_one(path: Path, out: Path, urls: dict, timeout: int, verify: bool, log=print) -> dict:
    """Execute one notebook and write its three handouts; return its index entry."""
    t0 = time.perf_counter()
    stem = path.stem
    source = nbformat.read(path, as_version=4)
    executed, groups, fps = execute_notebook(path, timeout)
    t_exec = time.perf_counter() - t0
    title = _title(executed, stem)
    export_html(executed, out / "solutions" / f"{stem}.html", urls, title=f"{title} (solutions)", problems=False)
    problems, notes = make_problems(executed)
    export_html(problems, out / "problems" / f"{stem}.html", urls, title=f"{title} (problems)", problems=True)
    wb = make_workbook(source, groups, fps)
    wpath = out / "workbooks" / f"{stem}.ipynb"
    wpath.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(wb, wpath)
    extra = ""
    if verify:
        t1 = time.perf_counter()
        run_workbook(wpath, timeout)
        extra = f", workbook runs ({time.perf_counter() - t1:.1f} s)"
    notes = notes + [fp["warning"] for fp in fps.values() if "warning" in fp]
    for n in notes:
        log(f"    {stem}: {n}")
    n_answers = sum(len(g.answers) for g in groups)
    log(f"  {stem}: done in {time.perf_counter() - t0:.1f} s (executed in {t_exec:.1f} s, "
        f"{n_answers} self-checked answers{extra})")
    return {"stem": stem, "title": title,
            "sections": [str(s) for s in executed.metadata.get("kinlib", {}).get("sections", [])],
            "executed": executed, "problems": problems, "workbook": wb, "notes": notes}


def build(notebooks: Path, out: Path, *, vendor: Path | None = None, jobs: int = 1, timeout: int = 120,
          verify: bool = True, only: list | None = None, log=print) -> list:
    """The whole job; raises NotebookFailed naming the notebook and cell when one fails."""
    t0 = time.perf_counter()
    notebooks, out = Path(notebooks), Path(out)
    paths = sorted(p for p in notebooks.glob("[0-9][0-9]_*.ipynb"))
    if only:
        paths = [p for p in paths if any(p.stem.startswith(o) for o in only)]
    if not paths:
        raise FileNotFoundError(f"no notebooks named NN_*.ipynb in {notebooks}")
    vendor = Path(vendor) if vendor else out.parent / "vendor"
    log(f"kinlib.handouts: {len(paths)} notebook(s) from {notebooks} -> {out}")
    urls = build_assets(out / "assets", vendor)
    log(f"  assets: MathJax (jupyter-server-mathjax), require.js {REQUIREJS[1]}, "
        f"{HTML_MANAGER[0]} {HTML_MANAGER[1]} ({time.perf_counter() - t0:.1f} s)")
    entries: dict = {}
    if jobs <= 1:
        for k, p in enumerate(paths, 1):
            log(f"[{k}/{len(paths)}] {p.name} ...")
            entries[p] = build_one(p, out, urls, timeout, verify, log)
    else:
        with ThreadPoolExecutor(max_workers=jobs) as pool:
            futures = {p: pool.submit(build_one, p, out, urls, timeout, verify, log) for p in paths}
            log(f"  running {len(paths)} notebooks, {jobs} at a time")
            try:
                for p, f in futures.items():
                    entries[p] = f.result()
            except BaseException:
                for f in futures.values():
                    f.cancel()
                raise
    write_index(out, [entries[p] for p in paths])
    log(f"kinlib.handouts: wrote {out / 'index.html'} and {3 * len(paths)} handouts "
        f"in {time.perf_counter() - t0:.1f} s")
    return [entries[p] for p in paths]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m kinlib.handouts", description=__doc__.split("\n\n")[0])
    ap.add_argument("notebooks", type=Path, help="folder with the NN_*.ipynb notebooks")
    ap.add_argument("--out", type=Path, default=Path("build/handouts"))
    ap.add_argument("--vendor", type=Path, default=None,
                    help="cache of npm packages (default: OUT/../vendor)")
    ap.add_argument("--jobs", type=int, default=2, help="notebooks executed at once (default 2)")
    ap.add_argument("--timeout", type=int, default=120, help="seconds allowed per cell (default 120)")
    ap.add_argument("--no-verify", dest="verify", action="store_false",
                    help="do not run the workbooks after writing them")
    ap.add_argument("--only", nargs="*", help="only notebooks whose name starts with these (e.g. 05)")
    args = ap.parse_args(argv)
    try:
        build(args.notebooks, args.out, vendor=args.vendor, jobs=args.jobs, timeout=args.timeout,
              verify=args.verify, only=args.only, log=lambda s: print(s, flush=True))
    except NotebookFailed as e:
        print(f"kinlib.handouts: FAILED: {e}", file=sys.stderr)
        return 1
    except (RuntimeError, FileNotFoundError, ValueError) as e:
        print(f"kinlib.handouts: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
