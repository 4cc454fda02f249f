"""Bifurcations of a continuation run located on the curve (issue 30 item 3).

Folds: the run flags point i when the parameter part of its tangent has the other sign
than point i - 1's (frirom_run_drive). The fold lies between them, where that part is
zero (the Jacobian R_y is singular there). It is located by a safeguarded secant
(Illinois regula falsi) on t_lam(s), the parameter part of the tangent of the point at
arc length s along the tangent of point i - 1 (pseudo-arc-length, as the continuation and
the peak search of frirom._peak parameterise the curve): every sample is one corrector of
the run itself (frirom_run run_solve, a step of given length from a point, from the
contact history that point left; no set-up, the held factorisation kept). The parameter
at the fold is an extremum of lam(s), so its error is second order in the error on s.

Stability changes: where stability was computed and consecutive points differ in their
verdict without a fold between them, a Floquet exponent crossed the imaginary axis away
from s = 0: a Neimark-Sacker (a complex pair) or a period-doubling crossing (a real
multiplier through -1, Im s = omega / 2). The crossing is bracketed by the two points,
listed with kind 'ns_or_pd' (the run keeps only the largest real part of the exponents,
so the two are not told apart yet).
"""

from __future__ import annotations

import numpy as np

from . import _run
from ._bifurcation import Bifurcation
from ._peak import _offset
from .results import FRFPoint

#: the fold is located when |t_lam| at a sample is below this (the tangent is unit
#: length in the scaled variables), or the bracket on s below FOLD_STOL of its first size
FOLD_TLAM = 1e-10
FOLD_STOL = 1e-9
#: at most this many correctors per fold
FOLD_MAX_SOLVES = 40


def locate_fold(solve, base: FRFPoint, after: FRFPoint, lscale: float):
    """The fold between base and after (their tangents' parameter parts of opposite
    signs): (point, t_lam, solves) with point the sample of smallest |t_lam|, or None when
    the curve turns too much between them for base's tangent to parameterise it."""
    s_hi = _offset(base, after, lscale)
    if not s_hi > 0:
        return None
    lo, f_lo = 0.0, float(base.tangent[-1])
    hi, f_hi = s_hi, float(after.tangent[-1])
    if f_lo == 0.0 or np.sign(f_lo) == np.sign(f_hi):
        return None
    best, f_best = (base, f_lo) if abs(f_lo) <= abs(f_hi) else (after, f_hi)
    side = 0
    n = 0
    while n < FOLD_MAX_SOLVES:
        s = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        if not lo < s < hi:
            s = 0.5 * (lo + hi)
        p = solve(s)
        n += 1
        f = float(p.tangent[-1])
        if abs(f) < abs(f_best):
            best, f_best = p, f
        if abs(f) <= FOLD_TLAM or hi - lo <= FOLD_STOL * s_hi:
            break
        if np.sign(f) == np.sign(f_lo):
            lo, f_lo = s, f
            if side == -1:
                f_hi *= 0.5         # Illinois: the stale end's value halved
            side = -1
        else:
            hi, f_hi = s, f
            if side == 1:
                f_lo *= 0.5
            side = 1
    return best, f_best, n


def find_bifurcations(packed, points: list, lscale: float, first: int = 0) -> list:
    """Bifurcations of a run's points (FRFPoint list in order; those before `first` were
    made before a resume and are searched too): the folds the run flagged, located on
    the curve, and the stability changes away from them (with stability computed)."""
    run = packed.run
    out = []

    def solver(base):
        def solve(s):
            res = run.solve(_run.SOLVE_STEP, base.parameter, base.unknowns,
                            tan0=base.tangent, yscale=base.yscale, ds=s,
                            sliders=base.slider if base.slider.size else None)
            if res.info != 0 or res.npts != 1:
                raise RuntimeError(res.msg)
            return packed.points(res, 0.0)[0]
        return solve

    for i in range(1, len(points)):
        a, b = points[i - 1], points[i]
        if b.fold:
            found = None
            if a.yscale > 0:
                try:
                    found = locate_fold(solver(a), a, b, lscale)
                except RuntimeError:
                    found = None
            if found is not None:
                p, t, n = found
                out.append(Bifurcation("fold", p.omega, p.parameter, np.array(p.amp_max),
                                       i, True, t, n))
            else:
                k = i if abs(b.tangent[-1]) < abs(a.tangent[-1]) else i - 1
                q = points[k]
                out.append(Bifurcation("fold", q.omega, q.parameter, np.array(q.amp_max),
                                       i, False, float(q.tangent[-1])))
        elif packed.stability and a.stable != b.stable:
            out.append(Bifurcation("ns_or_pd", 0.5 * (a.omega + b.omega),
                                   0.5 * (a.parameter + b.parameter),
                                   0.5 * (np.asarray(a.amp_max) + np.asarray(b.amp_max)), i))
    return [bif for bif in out if bif.index >= first]
