"""The explorer: a slider per joint, the arm drawn and every number recomputed **in the browser**, from
JavaScript that kinlib generates from the chain's own expressions.

How it is built (one implementation, every place a notebook is shown):

* kinlib prints, with SymPy's JavaScript printer, the same common-subexpression-eliminated, unsimplified
  expressions its NumPy code is generated from (:meth:`kinlib.chains.SerialChain.numeric_code`,
  :meth:`kinlib.codegen.CompiledMatrix.javascript`): ``skel(q)`` (base, joint points, tool) and ``jg(q)``, the
  **geometric Jacobian** J = blockdiag(R, R) J_b, rows [ω_s; ṗ]. From them the front end
  (``core.js`` and ``explorer.js`` beside this file, :mod:`kinlib.widgets.frontend`) computes σ's (Jacobi eigenvalues of J_r J_rᵀ), det J, the manipulability,
  the ṗ ellipse with the task's orientation rows held and with every joint free, and the direction the tool
  cannot move; the closed-form singular set (:func:`kinlib.singularities.singular_configurations`) is sent as
  families (θ_i = offset + k·period, or listed values) and as generated JavaScript for conditions in several
  joints; each slider's track marks where, the other joints as they are, the arm is singular.
* The output is the Jupyter display protocol's ``application/javascript`` (the front end and the generated
  functions, self-contained), beside a static ``image/png`` (drawn once by :mod:`kinlib.plotting`) and a
  ``text/plain`` line. Why this and not anywidget or an ipywidgets model: JupyterLab and JupyterLite render
  ``application/javascript`` with their built-in renderer (no extension to install or ship in the site);
  nbconvert's pages put it in a ``<script>`` (the static problem/solution pages need no widget embedder, and
  the PDF printer's Chromium draws it); a trusted notebook opened without running re-runs it from the saved
  output (the output *is* the saved state: nothing to synchronise). anywidget would need its JupyterLab
  extension in the lab and in the JupyterLite site (plus two more wheels in the Pyodide kernel), and on
  static pages a loader of our own, since standard widget embedding does not know anywidget modules
  (anywidget #339): three code paths for one picture. A slider move makes no round trip in any case. An
  untrusted notebook (opened without ``make lab``) cannot run scripts: JupyterLab then shows the static PNG.
* The status: ``"singular"`` exactly where a closed-form condition holds (families to the rounding of the
  slider values, 10⁻⁹ relative; a several-joint condition where |f| ≤ 10⁻⁹ · its largest value over the
  ranges); ``"near"`` by the course's one unit-aware rule (:data:`kinlib.manipulability.NEAR_SINGULAR`,
  :func:`~kinlib.manipulability.singularity_state`): the manipulability w = √det(J Jᵀ) of the task rows below
  ``NEAR_SINGULAR`` times w_max, the largest w of the same arm and rows over the slider ranges
  (:func:`~kinlib.manipulability.peak_manipulability`), with the same threshold and w_max sent to the browser;
  ``"regular"`` otherwise. Where no closed form is found within the time budget (the UR5's full 6-row task),
  "singular" means a singular value at most ``SINGULAR_RTOL`` · σ_max, as in ``singularity_state``.

Accessible: native range inputs (arrow keys, Home/End, Page Up/Down) with ``aria-valuetext`` in radians and
degrees and a description of the singular marks; orbit buttons and arrow keys on the focused 3-D drawing;
a ``role=status`` (``aria-live``) sentence after every move (state, singular values, the blocked direction);
colours that differ in lightness and line style. HTML hooks for tests: ``.kinlib-status[data-state]``,
``.kinlib-det``, ``.kinlib-held``, ``.kinlib-live``, ``.kinlib-mark[data-value]``, ``.kinlib-arm`` (the links' path), ``.kinlib-joint`` and
``.kinlib-tool`` (their world coordinates in ``data-x/y/z``); the explorer's root element carries
``.kinlib`` (the state, ``set(q)``).

>>> from kinlib.robots import planar_2r
>>> ex = explorer(planar_2r(1, 1), q=[0.3, 0.0])
>>> ex.state, ex.update([0.3, 1.0]).state
('singular', 'regular')
"""

from __future__ import annotations

import base64
import copy
import io
import math
from pathlib import Path

import numpy as np
import sympy as sp

from .._backend import describe
from ..analysis.manipulability import (
    NEAR_SINGULAR,
    SINGULAR_RTOL,
    peak_manipulability,
    singular_values,
    singularity_state,
)
from ..analysis.singularities import singular_configurations
from ..analysis.taskspace import default_task_rows, is_planar, task_row_indices, task_rows
from ..fast.codegen import CompiledMatrix
from ..plotting.common import as_configuration, checked_numeric, default_ranges, reach
from .frontend import script, square_view

__all__ = ["explorer", "Explorer", "classify_families", "without_answers", "FRONT_END"]

#: the explorer's part of the front end (beside it: core.js, the part every picture shares)
FRONT_END = Path(__file__).with_name("explorer.js")
_ROUNDING = 1e-9  # a slider value "is" a family member within this (relative): the rounding of lo + k·step


def _families(cond, thetas) -> list[dict] | None:
    """A dict condition {θ_i: Set} as a list of {i: family} (a Union of sets gives several), or None when a
    set is not a periodic family or a finite set of numbers."""

    def one(S):
        if isinstance(S, sp.Union):
            out = []
            for a in S.args:
                got = one(a)
                if got is None:
                    return None
                out += got
            return out
        if isinstance(S, sp.FiniteSet) and all(v.is_real and v.is_number for v in S):
            return [{"values": [float(v) for v in S]}]
        if isinstance(S, sp.ImageSet) and S.base_sets == (sp.S.Integers,) and len(S.lamda.variables) == 1:
            k, e = S.lamda.variables[0], S.lamda.expr
            period, offset = sp.diff(e, k), e.subs(k, 0)
            if period.is_number and offset.is_number and sp.expand(e - period * k - offset) == 0 and period != 0:
                return [{"offset": float(offset), "period": abs(float(period))}]
        return None

    choices = []
    for sym, S in cond.items():
        if sym not in thetas:
            return None
        fams = one(S)
        if fams is None:
            return None
        choices.append([(thetas.index(sym), f) for f in fams])
    out = [{}]
    for ch in choices:
        out = [{**d, i: f} for d in out for (i, f) in ch]
    return out


def classify_families(value: float, family: dict) -> bool:
    """Whether the joint value lies on a family {offset + k·period} or in its listed values, to the rounding
    of the slider (10⁻⁹ relative): the browser's test, written once more here for the kernel-side state.

    >>> classify_families(-math.pi / 4, {"offset": -math.pi / 4, "period": math.pi}), classify_families(0.1, {"values": [0.2]})
    (True, False)
    """
    eps = _ROUNDING * max(1.0, abs(value))
    if "values" in family:
        return any(abs(value - x) <= eps for x in family["values"])
    k = round((value - family["offset"]) / family["period"])
    return abs(value - (family["offset"] + k * family["period"])) <= eps


class Explorer:
    """One explorer (see the module text): ``chain`` (numeric), ``rows`` (task rows), ``hold`` (the task's
    orientation rows held for the main ṗ ellipse), ``ranges``, ``q``/``qdot``, ``conditions`` (the
    closed-form singular set as sent to the browser), ``complete`` (whether it is the whole singular set),
    ``spec`` (everything the front end gets), ``javascript`` (the output), ``info``/``state`` at ``q``
    (computed in Python by the same rules, for scripts and tests), ``update(q, qdot)``.

    >>> from kinlib.robots import planar_offset_3r
    >>> ex = Explorer(planar_offset_3r(1), q=[0.3, 0.7, 0.2])
    >>> ex.rows, ex.state, ex.hold
    ((2, 3, 4), 'regular', (2,))
    """

    # fmt: off
    def __init__(self, chain, *, q=None, qdot=None, params=None, ranges=None, step=None, rows=None,
                 ellipse_rows=None, tol=1e-6, show_ellipse=True, show_velocity=True, rate_sliders=True,
                 velocity_scale=0.5, title=None, show_maximum=True, size=420, singular_budget=None, **legacy):
        # fmt: on
        unknown = set(legacy) - {"continuous_update", "near", "figsize", "dpi", "image_format"}
        if unknown:
            raise TypeError(f"explorer() got unexpected keyword arguments {sorted(unknown)}")
        chain = checked_numeric(chain, params)
        self.chain, n = chain, chain.n
        self.rows = task_row_indices(rows, default=default_task_rows(chain))
        self.tol = float(tol)
        self.planar = is_planar(chain)
        self.ranges = default_ranges(chain, ranges)
        q0 = as_configuration(chain, q)
        for i, (lo, hi) in enumerate(self.ranges):
            q0[i] = min(max(q0[i], lo), hi)
        self.q = q0
        self.qdot = as_configuration(chain, qdot, "qdot") if qdot is not None else np.ones(n)
        self.ellipse_rows = (
            task_row_indices(ellipse_rows) if ellipse_rows is not None else ((3, 4) if self.planar else (3, 4, 5))
        )
        self.hold = tuple(k for k in self.rows if k < 3) if set(self.ellipse_rows) <= set(self.rows) else ()
        if not isinstance(size, int) or isinstance(size, bool) or not 200 <= size <= 2000:
            raise ValueError(f"size must be an int number of pixels in [200, 2000], got {describe(size)}")
        self.reach = reach(chain)
        ticks = []
        for i, (lo, hi) in enumerate(self.ranges):
            st = step if step is not None else (math.pi / 180 if chain.joint_types[i] == "R" else (hi - lo) / 200)
            ticks.append(max(1, round((hi - lo) / float(st))))
        self.ticks = ticks
        # the closed form: up to four joints by default (well under a second for the course's arms); beyond,
        # seconds (the UR5) and what a time budget returns would depend on the machine's load: not attempted
        budget = singular_budget if singular_budget is not None else (5.0 if n <= 4 else 0.0)
        self.conditions, self.complete, exprs = self._singular_set(float(budget)) if budget > 0 else ([], False, [])
        sample = self._sample()
        self.w_max = self._w_max(sample)
        self._exprs = [CompiledMatrix(sp.Matrix([e]), chain.thetas) for e in exprs]
        for c in self.conditions:  # |f| ≤ 10⁻⁹ · (its largest value over the ranges) counts as f = 0
            if "expr" in c:
                c["scale"] = float(np.max(np.abs(self._exprs[c["expr"]](sample)))) or 1.0
        funcs = [
            chain.numeric_code("skeleton").javascript("skel"),
            chain.numeric_code("jg").javascript("jg"),
        ]
        for k, e in enumerate(exprs):
            funcs.append(CompiledMatrix(sp.Matrix([e]), chain.thetas).javascript(f"c{k}"))
        self.spec = {
            "title": str(title or chain.name), "n": n, "types": chain.joint_types,
            "labels": [f"θ{i + 1}" for i in range(n)], "ranges": [list(r) for r in self.ranges], "ticks": ticks,
            "q0": self.q.tolist(), "qd0": self.qdot.tolist(), "planar": self.planar, "rows": list(self.rows),
            "ellRows": list(self.ellipse_rows), "hold": list(self.hold), "tol": self.tol,
            "near": {"ratio": NEAR_SINGULAR, "rtol": SINGULAR_RTOL},
            "conditions": self.conditions, "complete": self.complete, "velScale": float(velocity_scale),
            "showEllipse": bool(show_ellipse), "showVelocity": bool(show_velocity),
            "rateSliders": bool(rate_sliders and show_velocity), "showMaximum": bool(show_maximum),
            "wMax": self.w_max, "reach": self.reach, "view": self._view(sample, float(velocity_scale)), "size": size,
        }  # fmt: skip
        self._funcs = funcs
        self.update()

    # -- what the browser gets ------------------------------------------------------------------------
    def _singular_set(self, budget: float):
        """(conditions for the browser, complete?, expressions of the several-joint conditions)."""
        import warnings

        chain = self.chain
        th = list(chain.thetas)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # an incomplete answer is reported in ``complete``
            try:
                found = singular_configurations(task_rows(chain.jacobian_geometric(), self.rows), th, time_budget=budget)
            except (ValueError, TypeError, NotImplementedError):
                return [], False, []
        conds, exprs, complete = [], [], bool(found.complete)
        for c in found:
            if isinstance(c, dict):
                fams = _families(c, th)
                if fams is None:
                    complete = False
                    continue
                conds += [{"families": {str(i): f for i, f in d.items()}} for d in fams]
            elif isinstance(c, sp.Expr) and c.free_symbols and c.free_symbols <= set(th):
                joints = sorted(th.index(s) for s in c.free_symbols)
                conds.append({"expr": len(exprs), "joints": joints, "scale": 1.0})
                exprs.append(c)
            else:  # an expression in the lengths only: every configuration or none; the near rule speaks
                complete = False
        return conds, complete, exprs

    def _sample(self, N: int = 2000) -> np.ndarray:
        rng = np.random.default_rng(0)
        lo = np.array([r[0] for r in self.ranges])
        hi = np.array([r[1] for r in self.ranges])
        return np.vstack([lo + (hi - lo) * rng.random((N, self.chain.n)), self.q])

    def _w_max(self, Q) -> float:
        """w_max of the near rule over the slider ranges (and the sample ``Q`` the view is drawn from)."""
        return peak_manipulability(self.chain, self.rows, self.ranges, extra=Q)

    def _view(self, Q, vscale: float) -> dict:
        """The drawing's extent: every skeleton point over the sample, and the tool ± the largest ellipse."""
        sk = self.chain.skeleton(Q)  # (N, 3, n+2)
        J = self.chain.jacobian_geometric(Q)[:, list(self.ellipse_rows), :]
        smax = float(np.max(np.linalg.svd(J, compute_uv=False)[:, 0])) * vscale
        pts = np.concatenate([sk.transpose(1, 0, 2).reshape(3, -1), np.zeros((3, 1))], axis=1)
        return square_view(pts, self.planar, smax)  # room for the largest ellipse at any point

    #: the picture's part of the front end (:data:`kinlib.widgets.frontend.ENTRIES`)
    entry = "explorer"
    #: False in the students' version (:meth:`without_answers`): nothing that answers a graded part is shown or sent
    answers = True

    def without_answers(self):
        """The students' version of this picture (a new object; this one is unchanged): the same arm, sliders,
        velocity ellipses and ṗ arrow, and nothing that answers a graded part, neither shown nor in the data sent
        to the browser (a student can read the script): no singular marks on the tracks and no closed-form
        singular set (its families and generated conditions), no status banner or live sentence of "singular"
        or "near", no det J, manipulability, σ or rank readout, no largest manipulability (w_max), no direction
        the tool cannot move. ``kinlib handouts`` shows it on the problem pages and in the workbooks for a cell
        whose metadata says ``"kinlib": {"reveals": [...]}`` (``notebooks/README.md``).

        >>> from kinlib.robots import planar_2r
        >>> ex = explorer(planar_2r(1, 1), q=[0.3, 0.0]).without_answers()
        >>> ex.spec["conditions"], ex.spec["wMax"], ex.spec["answers"], "singular" in ex._repr_mimebundle_()["text/plain"]
        ([], 0.0, False, False)
        """
        other = copy.copy(self)
        other.answers = False
        other.spec = self._students_spec()
        other._funcs = list(self._funcs[:2])  # skel and jg: no generated singular condition
        other._exprs = []
        other.conditions, other.complete = [], False
        return other

    def _students_spec(self) -> dict:
        spec = dict(self.spec)
        spec.update(answers=False, conditions=[], complete=False, showMaximum=False, wMax=0.0)
        return spec

    @property
    def javascript(self) -> str:
        """The output: the front end, the generated functions and the spec, self-contained."""
        return script(self.entry, self._funcs, self.spec, len(self._exprs))

    # -- the same rules in Python (scripts, tests, the text/plain line) ------------------------------
    def update(self, q=None, qdot=None):
        """Set q (and/or qdot) for the kernel-side state (``info``, ``state``); the browser's sliders are the
        student's. Returns self."""
        if q is not None:
            self.q = as_configuration(self.chain, q)
        if qdot is not None:
            self.qdot = as_configuration(self.chain, qdot, "qdot")
        J = task_rows(self.chain.jacobian_geometric(self.q), self.rows)
        s = singular_values(J)
        singular = any(self._holds(c) for c in self.conditions)
        rule = singularity_state(J, self.w_max)  # the one rule: rank test, then w < NEAR_SINGULAR · w_max
        smax = float(s[0]) if s.size else 0.0
        self.info = {
            "rank": int(np.sum(s > self.tol * smax)) if smax > 0 else 0,
            "full_rank": min(J.shape),
            "det": float(np.linalg.det(J)) if J.shape[0] == J.shape[1] else None,
            "manipulability": float(np.prod(s)),
            "sigma": s,
            "ratio": float(s[-1] / smax) if smax > 0 else 0.0,
            "w_ratio": float(np.prod(s)) / self.w_max,
            "state": "singular" if singular else _without_exact_rank_test(rule, self.complete),
        }
        return self

    def _holds(self, cond) -> bool:
        """Does the closed-form singular condition ``cond`` hold at ``q`` (to the rounding of the sliders)?"""
        if "families" in cond:
            return all(classify_families(float(self.q[int(i)]), f) for i, f in cond["families"].items())
        f = float(self._exprs[cond["expr"]](self.q)[0, 0])
        return abs(f) <= _ROUNDING * cond["scale"]

    @property
    def state(self) -> str:
        """'singular', 'near' or 'regular' at ``q``."""
        return self.info["state"]

    def _static_png(self) -> bytes:
        """The picture at ``q`` drawn once by :mod:`kinlib.plotting` (for viewers that run no script)."""
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        from ..plotting import draw_chain, draw_velocity, draw_velocity_ellipses

        fig = Figure(figsize=(5.2, 5.0), dpi=80)
        FigureCanvasAgg(fig)
        ax = fig.add_subplot(projection=None if self.planar else "3d")
        draw_chain(self.chain, self.q, ax, ranges=self.ranges, title=self.spec["title"])
        vs = self.spec["velScale"]
        if self.spec["showEllipse"]:
            draw_velocity_ellipses(ax, self.chain, self.q, task=self.rows, rows=self.ellipse_rows, scale=vs)
        if self.spec["showVelocity"]:
            draw_velocity(ax, self.chain, self.q, self.qdot, scale=vs)
        fig.tight_layout()
        buf = io.BytesIO()
        fig.savefig(buf, format="png")
        return buf.getvalue()

    def _repr_mimebundle_(self, **kwargs):
        q = ", ".join(f"{x:.3f}" for x in self.q)
        state = f": {self.state} configuration" if self.answers else ""
        text = f"explorer of {self.chain.name} at θ = ({q}){state} (run the cell for sliders)"
        return {
            "application/javascript": self.javascript,
            "image/png": base64.b64encode(self._static_png()).decode("ascii"),
            "text/plain": text,
        }


def explorer(chain, **kwargs) -> Explorer:
    """An :class:`Explorer` for ``chain``: display it as the last expression of a cell.

    Keywords: ``q``/``qdot`` (initial joint values/rates; rates default to 1), ``rows`` (task rows for det J,
    manipulability and the status; default (ω_z, ṗ_x, ṗ_y) planar, all six otherwise), ``ranges`` (slider
    ranges, list or {joint number: (lo, hi)}; default ±π and ±half the reach for prismatic joints),
    ``show_ellipse``, ``show_velocity``, ``rate_sliders``, ``ellipse_rows``, ``velocity_scale`` (display factor
    of the ṗ arrow and the ellipses, 0.5), ``tol`` (rank threshold of the readout), ``show_maximum`` (False: the
    text never states the largest manipulability, e.g. in a problem that asks for it), ``params`` ({"L": 1} for
    a symbolic chain), ``step`` (slider step; π/180 for angles so that multiples of 1° such as −π/4 are
    reachable), ``title``, ``size`` (the drawing in pixels), ``singular_budget`` (seconds for the closed-form
    singular set). The keywords of the matplotlib explorer (``continuous_update``, ``near``, ``figsize``,
    ``dpi``, ``image_format``) are accepted and ignored: the near rule is the one of
    :func:`kinlib.manipulability.near_singular`.

    >>> from kinlib.robots import planar_2r
    >>> ex = explorer(planar_2r(1, 1), q=[0.5, 0.0])   # stretched out: (ṗ_x, ṗ_y) lose rank
    >>> ex.rows, ex.state, ex.info["rank"]
    ((3, 4), 'singular', 1)
    """
    return Explorer(chain, **kwargs)


def without_answers(picture):
    """The students' version of an explorer, animation or configuration picker (``picture.without_answers()``):
    the same picture without whatever answers a graded part (see :meth:`Explorer.without_answers`). Display it
    as the last expression of a cell; ``kinlib handouts`` uses it for the cells whose metadata says
    ``"kinlib": {"reveals": [...]}``. Anything else is refused:

    >>> without_answers(42)
    Traceback (most recent call last):
        ...
    TypeError: without_answers() takes an explorer, an animation or a configuration picker (kinlib.widgets), got int 42
    """
    method = getattr(type(picture), "without_answers", None)
    if method is None or not callable(method):
        raise TypeError(
            "without_answers() takes an explorer, an animation or a configuration picker (kinlib.widgets), "
            f"got {describe(picture)}"
        )
    return picture.without_answers()


def _without_exact_rank_test(state: str, complete: bool) -> str:
    """Where the closed-form singular set is complete, "singular" is decided by it alone (the rank test of
    :func:`~kinlib.manipulability.singularity_state` then only says "near"); elsewhere the rank test stands."""
    return "near" if complete and state == "singular" else state
