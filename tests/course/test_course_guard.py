"""kinlib.course.grader.in_kernel.guard: what a notebook replaced is put back and reported; what the libraries change by
themselves (SymPy's RealField builds mpmath contexts, which re-wrap MPContext's class functions) is put back
silently, so an honest notebook is never told it tampered with anything."""

import math

import mpmath
import sympy
from mpmath.ctx_mp import MPContext
from sympy.polys.domains import RealField

from kinlib.course.grader.in_kernel import guard


def test_library_side_effects_are_not_reported():
    snap = guard.snapshot()
    before = MPContext.__dict__["cot"]
    RealField(120)  # constructs an mpmath context: MPContext.cot and friends are re-created
    mpmath.MPContext()
    assert MPContext.__dict__["cot"] is not before  # the library really did change the class
    assert guard.restore(snap) == []
    assert MPContext.__dict__["cot"] is before


def test_notebook_replacements_are_reported_and_undone():
    snap = guard.snapshot()
    real_simplify, real_cot, real_sqrt = sympy.simplify, MPContext.__dict__["cot"], math.sqrt
    try:
        sympy.simplify = lambda e: 0
        MPContext.cot = lambda ctx, z: 0
        math.sqrt = lambda x: 0.0
        fixed = guard.restore(snap)
    finally:
        sympy.simplify, math.sqrt = real_simplify, real_sqrt
        MPContext.cot = real_cot
    assert {"sympy.simplify", "mpmath.ctx_mp.MPContext.cot", "math.sqrt"} <= set(fixed)
