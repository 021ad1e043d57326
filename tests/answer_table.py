"""The shared table of answers (issue 31, item 3): every kind of answer the course grades, on the course's own
robots (computed here with kinlib, independently of the notebooks), each with its right value, other valid forms
of it, and the typical wrong forms, with the words that must name each mistake.

Both judges must agree on every row: the workbook self-check (public sample points, fingerprints) and the grader
(secret points, descriptions): tests/course/test_course_answers.py. The feedback on every row, and on every other
row's answer given for it, must state no graded value: tests/course/test_grade_verdicts.py.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from kinlib import robots
from kinlib.singularities import task_rows

pi = sp.pi
L = sp.Symbol("L", positive=True)
L1, L2 = sp.symbols("L1 L2", positive=True)
th1, th2, th3, th4 = sp.symbols("theta1:5", real=True)
Fx, Fy = sp.symbols("F_x F_y", real=True)


@dataclass
class Row:
    part: str  # "5.1"
    name: str  # the answer's variable
    kind: str  # as the solution notebook declares it
    right: object
    valid: list = field(default_factory=list)  # other right forms
    wrong: list = field(default_factory=list)  # (value, words that must be in both judges' messages, or "")

    @property
    def salt(self):
        return f"{self.part}:{self.name}"


def _planar():
    r = robots.planar_offset_3r()
    Js = r.jacobian_space()
    return r, Js, task_rows(Js, "planar")


def rows() -> list[Row]:
    r3, Js3, Jt = _planar()
    Jb3 = r3.jacobian_body()
    Jg3 = r3.jacobian_geometric()
    detJ = sp.sqrt(2) * L**2 * sp.sin(th2 + pi / 4)
    w = sp.sqrt(2) * L**2 * sp.Abs(sp.sin(th2 + pi / 4))
    two = robots.planar_2r()
    J2 = task_rows(two.jacobian_geometric(), "planar")[1:, :]  # (v_x, v_y) of the 2R arm
    A_v = J2 * J2.T
    tau = J2.T * sp.Matrix([Fx, Fy])
    rppr = robots.spatial_rppr()
    Jg4 = rppr.jacobian_geometric()
    JtJ = sp.simplify(Jg4.T * Jg4)
    can_move = sp.Matrix([[1, 0], [0, sp.sqrt(2) / 2], [0, -sp.sqrt(2) / 2]])
    cannot = sp.Matrix([0, 1, 1])
    semi = sp.Matrix([L1 + L2, L1 - L2])  # the velocity ellipse's semi-axes at a configuration (σ)
    return [
        Row("2.1", "M", "expr", r3.M, [r3.M.tolist()], [(r3.M.T, "transposed"), (-r3.M, "wrong sign")]),
        Row(
            "2.1",
            "S2",
            "expr",
            r3.screws[:, 1],
            [list(r3.screws[:, 1])],
            [(sp.Matrix([*r3.screws[3:, 1], *r3.screws[:3, 1]]), "[v; ω]")],
        ),
        Row(
            "2.2",
            "Js",
            "expr",
            Js3,
            [Js3.applyfunc(sp.expand_trig), Js3.evalf(12), Js3.evalf(3)],
            [(Js3.subs(L, 1), "does not depend on L"), (Js3.T, "transposed"), (Jb3, "")],
        ),
        Row("2.3", "Jb", "expr", Jb3, [], [(Js3, ""), (-Jb3, "wrong sign")]),
        Row(  # J_s or J_b for the geometric J: the same angular rows; the same columns in rotated axes
            "2.4", "J", "expr", Jg3, [], [(Js3, "right angular rows"), (Jb3, "rotation of the axes")]
        ),
        Row(
            "5.1",
            "detJ",
            "expr",
            detJ,
            [sp.expand(sp.expand_trig(detJ)), L**2 * (sp.sin(th2) + sp.cos(th2))],
            [
                (sp.Abs(detJ), "wrong sign at some configurations"),
                (-detJ, "wrong sign"),
                (detJ.subs(L, 1), "does not depend on L"),
                (sp.sqrt(2) * L**2 * sp.sin(th2 + 45), "degrees"),
                (sp.Float(1.414) * L**2 * sp.sin(th2 + pi / 4), "round"),
                (sp.Integer(0), "constant"),
            ],
        ),
        Row(
            "5.1",
            "singular_configs",
            "set",
            {th2: sp.FiniteSet(-pi / 4, 3 * pi / 4)},
            [
                {th2: sp.FiniteSet(3 * pi / 4, 7 * pi / 4)},
                sp.FiniteSet(3 * pi / 4, 7 * pi / 4),
                [{th2: {-pi / 4, 3 * pi / 4}}],
            ],
            [
                ({th2: sp.FiniteSet(pi / 4, 5 * pi / 4)}, ""),
                ({th1: sp.FiniteSet(-pi / 4, 3 * pi / 4)}, "another joint"),
                ({th2: sp.FiniteSet(-45, 135)}, "degrees"),
                (sp.EmptySet, ""),
                ({th2: sp.FiniteSet(3 * pi / 4)}, ""),
            ],
        ),
        Row("5.3", "rank53", "expr", sp.Integer(2), [2, 2.0], [(3, "generic rank"), (1, "generic rank")]),
        Row(
            "5.3",
            "can_move",
            "subspace",
            can_move,
            [[[1, 0, 0], [0, 1, -1]], can_move * 5],
            [(cannot, ""), (sp.Matrix([[1, 0], [0, 1], [0, 1]]), "")],
        ),
        Row("5.3", "cannot_move", "subspace", cannot, [[0, 2, 2]], [(can_move, "")]),
        Row(
            "5.4",
            "w",
            "expr",
            w,
            [sp.sqrt(2 * L**4 * sp.sin(th2 + pi / 4) ** 2), sp.Abs(detJ)],
            [(detJ, "wrong sign at some configurations"), (w.subs(L, 1), "does not depend on L"), (w**2, "")],
        ),
        Row(
            "5.4",
            "maximizers",
            "set",
            {th2: sp.FiniteSet(pi / 4, 5 * pi / 4)},
            [sp.FiniteSet(pi / 4, -3 * pi / 4)],
            [({th2: sp.FiniteSet(-pi / 4, 3 * pi / 4)}, ""), ({th2: sp.FiniteSet(45, 225)}, "degrees")],
        ),
        Row(
            "5.4",
            "w_max",
            "expr",
            sp.sqrt(2) * L**2,
            [sp.Float(1.4142135624) * L**2],
            [(sp.sqrt(2), "depends on L"), (sp.Float(1.41) * L**2, "round")],
        ),
        Row("6.1", "rank_J", "expr", sp.Integer(4), [4], [(3, "generic rank")]),
        Row("6.1", "singular_set", "set", sp.EmptySet, [[], set()], [({th3: sp.FiniteSet(-L2)}, "")]),
        Row("6.2", "JtJ_62", "expr", JtJ, [], [(sp.simplify(Jg4 * Jg4.T), "other order")]),
        Row(
            "7.1",
            "A_v",
            "expr",
            A_v,
            [sp.expand(A_v)],
            [(A_v.xreplace({L1: L2, L2: L1}), "L1 and L2 swapped"), (J2.T * J2, "other order")],  # J square: Jᵀ J
        ),
        Row("7.1", "length_ratio", "expr", L1 / L2, [L1 * L2**-1], [(L2 / L1, "upside down")]),
        Row("7.2", "removes_all", "choice", False, [0, sp.false], [(True, ""), (1, "")]),
        Row(
            "7.2",
            "singular_4r",
            "set",
            {th2: sp.FiniteSet(0, pi)},
            [{th2: [0, pi, 2 * pi]}],
            [(sp.EmptySet, ""), ({th3: sp.FiniteSet(0, pi)}, "another joint")],
        ),
        Row(
            "7.4",
            "tau",
            "expr",
            tau,
            [sp.expand(tau)],
            [(-tau, "wrong sign"), (J2 * sp.Matrix([Fx, Fy]), "τ = Jᵀ F")],  # τ = J F for Jᵀ F (J is square here)
        ),
        Row("7.4", "force_semi_axes", "expr", semi.applyfunc(lambda s: 1 / s), [], [(semi, "upside down")]),
        Row("4.1", "joint_a", "choice", (1, 3), [[3, 1], sp.Matrix([1, 3])], [((1,), ""), ((0, 2), "numbered from 1")]),
    ]


def graded_tokens(value) -> set[str]:
    """The strings a message could state ``value`` by: its non-trivial entries, members and terms as SymPy
    prints them, and their 3-decimal values."""
    out = set()

    def add(e):
        try:
            e = sp.sympify(e)
        except (sp.SympifyError, TypeError):
            return
        if isinstance(e, sp.Set):
            for m in getattr(e, "args", ()):
                add(m)
            return
        if isinstance(e, sp.MatrixBase):
            for x in e:
                add(x)
            return
        text = sp.sstr(e)
        if len(text) >= 4 and not text.lstrip("-").isdigit():
            out.add(text)
        if e.is_number and not e.is_Integer:
            try:
                out.add(f"{float(e):.3f}")
            except TypeError:
                pass

    if isinstance(value, dict):
        for v in value.values():
            add(v)
    elif isinstance(value, (list, tuple)) and value and all(isinstance(v, dict) for v in value):
        for d in value:
            for v in d.values():
                add(v)
    elif isinstance(value, (sp.Basic, sp.MatrixBase)):
        add(value)
    return out


_ENTRIES: dict = {}


def grader_verdict(value, row, seed):
    """The grader's ``(ok, message)``: both answers exported as a kernel exports them, the reference read as
    build_reference reads it, judged at secret points drawn as the grader draws them (make_points, from the
    reference's symbols and their assumptions)."""
    from kinlib.course.grader.grade import make_points
    from kinlib.course.grader.in_kernel.export import exported
    from kinlib.course.grader.judge import judge_answer, n_points
    from kinlib.course.grader.refdata import Reference, reference_answers

    if row.salt not in _ENTRIES:
        _ENTRIES[row.salt] = reference_answers({row.name: exported(row.right)}, {row.name: row.kind})
    entry = _ENTRIES[row.salt]
    assert "error" not in entry[row.name], entry
    kind = entry[row.name]["kind"]
    pts = make_points(entry[row.name].get("symbols", {}), seed, max(n_points(kind), 1))
    ref = Reference("t", "t", "p", "0" * 64, [], entry)
    v = judge_answer(row.name, kind, exported(value), ref, pts, seed)
    return v.passed, v.message


_SPECS: dict = {}


def home_verdict(value, row):
    """The workbook self-check's ``(status, message)`` against the row's fingerprint (as the build makes it)."""
    from kinlib.course.workbook.selfcheck import fingerprint, verdict

    kind = "default" if row.kind == "expr" else row.kind
    if row.salt not in _SPECS:
        _SPECS[row.salt] = fingerprint(row.right, kind, salt=row.salt)
    return verdict(value, _SPECS[row.salt], salt=row.salt)
