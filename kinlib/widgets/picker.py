"""The configuration picker (problem 4.1): named configurations chosen with buttons; the drawing shows the arm
with each joint's velocity arrow at the tool (column i of J_ṗ of the **geometric Jacobian**
J = blockdiag(R, R) J_b, rows [ω_s; ṗ], i.e. ṗ for θ̇_i = 1) beside a bar chart of the chosen row's joint
contributions J[row, i] (one scale for every configuration, so bars compare across them) and a table naming the
joint with the largest |J[row, i]|. Drawn in the browser by the explorer's front end
(:mod:`kinlib.widgets.frontend`, ``picker.js``) from the same generated ``skel(q)`` and ``jg(q)``: a button press
makes no round trip, and the picker works on the static pages and in JupyterLite as the explorer does. The
buttons are native buttons (Tab, Enter/Space; the arrow keys move between them), ``aria-pressed`` on the one
shown; an ``aria-live`` sentence says the configuration's contributions. The output carries a static
``image/png`` (the first configuration, drawn once by :mod:`kinlib.plotting`). HTML hooks: ``.kinlib-picker``
(its root; ``root.kinlib.select(name)``), ``button.kinlib-config[data-name]``, ``.kinlib-jvel[data-joint]`` (each
arrow, its world vector in ``data-x/y/z``), ``.kinlib-bar[data-value]``, ``.kinlib-best``, ``.kinlib-live``.

>>> import math
>>> from kinlib.robots import planar_3r
>>> cp = config_picker(planar_3r(1, 1, 1), {"c": [math.pi / 2, -math.pi / 8, -math.pi / 2]}, rows="vy")
>>> cp.best, cp.spec["configs"][0]["row"]
((1, 2), 4)
"""

from __future__ import annotations

import base64
import html
import io
from collections.abc import Mapping

import numpy as np

from .._backend import describe
from ..analysis.manipulability import NEAR_SINGULAR, SINGULAR_RTOL, strongest_joints
from ..analysis.taskspace import ROW_LABELS, ROW_TEX, is_planar, task_row_indices
from ..plotting.common import JOINT_COLORS, as_configuration, checked_numeric, reach, theta_tex
from .frontend import script, square_view

__all__ = ["config_picker", "ConfigPicker"]


class ConfigPicker:
    """Named configurations (problem 4.1), shown one at a time (see the module text).

    ``rows``: one row for all configurations ('vx', 'vy', …) or a dict {name: row}. ``scale``: display factor
    of the joint-velocity arrows. State (the kernel's copy of what the browser shows): ``name``,
    ``contributions`` (the n values J[row, i] of the current configuration), ``best`` (1-based joints with the
    largest |contribution|, from :func:`kinlib.manipulability.strongest_joints`; ties within 10⁻⁹ relative),
    ``table`` (HTML), ``select(name)``; ``spec``/``javascript`` (what the browser gets).

    >>> from kinlib.robots import planar_3r
    >>> import math
    >>> cp = ConfigPicker(planar_3r(1, 1, 1), {"home": [0, 0, 0], "c": [math.pi / 2, -math.pi / 8, -math.pi / 2]},
    ...                   rows="vy")
    >>> cp.best, cp.select("c").best   # problem 4.1 (c): joints 1 and 2 tie
    ((1,), (1, 2))
    """

    entry = "picker"
    #: False in the students' version (:meth:`without_answers`)
    answers = True

    def without_answers(self):
        """The students' version (a new object): the buttons, the arm and each joint's velocity arrow, without the
        bar chart, the table of contributions and the sentence naming the largest (what problem 4.1 asks); see
        :meth:`kinlib.widgets.Explorer.without_answers`.

        >>> from kinlib.robots import planar_3r
        >>> cp = config_picker(planar_3r(1, 1, 1), {"a": [0.1, 0.2, 0.3]}).without_answers()
        >>> cp.spec["answers"], "largest" in cp._repr_mimebundle_()["text/plain"]
        (False, False)
        """
        import copy

        other = copy.copy(self)
        other.answers = False
        other.spec = {**self.spec, "answers": False}
        return other

    def __init__(self, chain, configs: Mapping, *, rows="vx", params=None, scale=1.0, title=None, size=420, **legacy):
        unknown = set(legacy) - {"figsize", "dpi"}  # the matplotlib picker's keywords: accepted, no meaning here
        if unknown:
            raise TypeError(f"config_picker() got unexpected keyword arguments {sorted(unknown)}")
        chain = checked_numeric(chain, params)
        self.chain = chain
        if not isinstance(configs, Mapping) or not configs:
            raise TypeError(f"configs must be a non-empty dict {{name: q}}, got {describe(configs)}")
        self.configs = {str(k): as_configuration(chain, v, f"configs[{k!r}]") for k, v in configs.items()}
        if isinstance(rows, Mapping):
            missing = set(self.configs) - set(map(str, rows))
            if missing:
                raise ValueError(f"rows must give a row for every configuration; missing {sorted(missing)}")
            self.rows = {str(k): self._one_row(v) for k, v in rows.items()}
        else:
            r = self._one_row(rows)
            self.rows = dict.fromkeys(self.configs, r)
        if not isinstance(scale, (int, float)) or isinstance(scale, bool) or not 0 < scale < 1e6:
            raise ValueError(f"scale must be a positive number, got {describe(scale)}")
        if not isinstance(size, int) or isinstance(size, bool) or not 200 <= size <= 2000:
            raise ValueError(f"size must be an int number of pixels in [200, 2000], got {describe(size)}")
        self.scale, self.planar = float(scale), is_planar(chain)
        d = 2 if self.planar else 3
        # the view: every configuration's skeleton and its joint-velocity arrow tips
        pts = []
        for qq in self.configs.values():
            sk = chain.skeleton(qq)
            pts += [sk, sk[:, -1:] + self.scale * chain.jacobian_geometric(qq)[3:, :]]
        vals = [chain.jacobian_geometric(qq)[self.rows[k]] for k, qq in self.configs.items()]
        from matplotlib.colors import to_hex

        self.spec = {
            "title": str(title or chain.name), "n": chain.n, "types": chain.joint_types, "planar": self.planar,
            "configs": [{"name": k, "q": q.tolist(), "row": self.rows[k]} for k, q in self.configs.items()],
            "rowNames": list(ROW_LABELS), "scale": self.scale, "size": size, "reach": reach(chain),
            "view": square_view(np.hstack(pts), self.planar), "top": max(float(np.max(np.abs(v))) for v in vals) or 1.0,
            "colors": [to_hex(JOINT_COLORS[i % 10]) for i in range(chain.n)],
            # what the shared drawing needs (no ellipse, no ṗ arrow, no singular set: the arm and its joints)
            "rows": list(range(3, 3 + d)), "ellRows": list(range(3, 3 + d)), "hold": [], "tol": 1e-6,
            "near": {"ratio": NEAR_SINGULAR, "rtol": SINGULAR_RTOL}, "conditions": [], "complete": False,
            "wMax": 1.0, "velScale": self.scale, "showEllipse": False, "showVelocity": False,
        }  # fmt: skip
        self._funcs = [chain.numeric_code("skeleton").javascript("skel"), chain.numeric_code("jg").javascript("jg")]
        self.select(next(iter(self.configs)))

    @staticmethod
    def _one_row(r) -> int:
        idx = task_row_indices(r)
        if len(idx) != 1:
            raise ValueError(f"rows must name one row per configuration (e.g. 'vx'), got {describe(r)}")
        return idx[0]

    def select(self, name: str):
        """Make ``name`` the configuration shown (here, and first when the output is drawn). Returns self."""
        if name not in self.configs:
            raise ValueError(f"unknown configuration {name!r}; choose from {list(self.configs)}")
        q, row = self.configs[name], self.rows[name]
        self.name = name
        self.contributions = c = self.chain.jacobian_geometric(q)[row]
        best = strongest_joints(c)
        self.best = best if isinstance(best, tuple) else (best,)
        lab = html.escape(ROW_LABELS[row])
        cells = "".join(f"<td>{'<b>' if i + 1 in self.best else ''}{v:+.4f}{'</b>' if i + 1 in self.best else ''}</td>"
                        for i, v in enumerate(c))  # fmt: skip
        heads = "".join(f"<th>θ̇{i + 1}</th>" for i in range(len(c)))
        who = (
            f"joint {self.best[0]}"
            if len(self.best) == 1
            else "a tie between joints " + " and ".join(map(str, self.best))
        )
        self.table = (
            f"<div>θ = ({', '.join(f'{x:.4f}' for x in q)})</div><table><tr><th></th>{heads}</tr>"
            f"<tr><th>{lab} per unit rate</th>{cells}</tr></table>"
            f"<div class='kinlib-best'>largest |{lab}|: {who}</div>"
        )
        self.spec["start"] = list(self.configs).index(name)
        return self

    @property
    def javascript(self) -> str:
        """The output: the front end, the generated functions and the spec, self-contained."""
        return script(self.entry, self._funcs, self.spec)

    def _static_png(self) -> bytes:
        """The configuration shown, drawn once with matplotlib (for viewers that run no script)."""
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        from ..plotting import draw_chain, draw_joint_velocities

        q, row, v = self.configs[self.name], self.rows[self.name], self.spec["view"]
        fig = Figure(figsize=(9.5, 4.3) if self.answers else (4.8, 4.3), dpi=60)
        FigureCanvasAgg(fig)
        ax = fig.add_subplot(1, 2 if self.answers else 1, 1, projection=None if self.planar else "3d")
        lim = [[v["x0"], v["x1"]], [v["y0"], v["y1"]]] if self.planar else [[c - v["r"], c + v["r"]] for c in v["c"]]
        draw_chain(self.chain, q, ax, limits=np.array(lim), title=self.spec["title"])
        draw_joint_velocities(ax, self.chain, q, scale=self.scale)
        if not self.answers:  # the students' version: no bar chart of the contributions
            fig.tight_layout()
            buf = io.BytesIO()
            fig.savefig(buf, format="png")
            return buf.getvalue()
        bar = fig.add_subplot(1, 2, 2)
        n, c = self.chain.n, self.contributions
        bar.bar(np.arange(1, n + 1), c, color=self.spec["colors"])
        bar.axhline(0, color="k", lw=0.8)
        bar.set_xticks(np.arange(1, n + 1), [theta_tex(i + 1, dot=True) for i in range(n)])
        bar.set_ylim(-1.2 * self.spec["top"], 1.2 * self.spec["top"])
        bar.set_title(f"{self.name}: {ROW_TEX[row]} for each " + r"$\dot\theta_i = 1$", fontsize=10)
        fig.tight_layout()
        buf = io.BytesIO()
        fig.savefig(buf, format="png")
        return buf.getvalue()

    def _repr_mimebundle_(self, **kwargs):
        text = f"configuration picker for {self.chain.name}: {self.name} (run the cell for the buttons)"
        return {
            "application/javascript": self.javascript,
            "image/png": base64.b64encode(self._static_png()).decode("ascii"),
            "text/plain": text,
        }


def config_picker(chain, configs: Mapping, **kwargs) -> ConfigPicker:
    """A :class:`ConfigPicker` (keywords: rows, params, scale, title, size; figsize and dpi are accepted and
    ignored).

    >>> from kinlib.robots import planar_3r
    >>> config_picker(planar_3r(1, 1, 1), {"a": [0.1, 0.2, 0.3]}).contributions.shape
    (3,)
    """
    return ConfigPicker(chain, configs, **kwargs)
