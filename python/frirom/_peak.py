"""The peak of a continuation run solved on the curve: for each output, the largest
max-over-the-period amplitude between the points around the largest one, found by a
bounded Brent search along the curve whose every evaluation is one corrector solve (one
search per resonance and output, for the first MAX_SOLVED outputs; the others take the
largest of those solves).

The curve near the largest point i is parameterised by the arc length s along the tangent
of point i - 1 (pseudo-arc-length: the corrector solves R = 0 on the hyperplane at distance
s along that tangent, as the continuation itself does), so a peak next to a fold, or at a
corner of a friction curve (a contact state appearing there), is found like a smooth one.
"""

from __future__ import annotations

import numpy as np
import scipy.optimize

from . import _run
from ._pack import _Packed
from .results import FRFPoint, Peak

#: local maxima of the points within this fraction of the largest are solved for too
#: (at most MAX_CANDIDATES of them, the largest first)
NEAR = 2e-3
MAX_CANDIDATES = 3
#: outputs whose peaks are each searched for (a Brent search per output and candidate);
#: the others take the largest of those solves (Peak.method 'shared')
MAX_SOLVED = 16
#: Brent's tolerance on the arc length, relative to the bracket (two steps): at a corner
#: the amplitude error is this times the amplitude change over a step (~1e-5 relative)
XTOL = 2e-3


def _offset(base: FRFPoint, p: FRFPoint, lscale: float) -> float:
    """Distance of p from base along base's tangent, in the scaled variables of the run."""
    d = np.r_[(p.unknowns - base.unknowns) / base.yscale,
              (p.parameter - base.parameter) / lscale]
    return float(base.tangent @ d)


def refine_peaks(packed: _Packed, points: list, lscale: float) -> tuple[list, list]:
    """Peak per output of a frequency continuation's points (FRFPoint list, in order).

    Returns (peaks, solved). peaks: a list of :class:`frirom.results.Peak` (n_out,), the
    largest of the solved local maxima (``method`` 'solve'; the interior local maxima of
    the points within NEAR of the largest are solved for, at most MAX_CANDIDATES, each
    output's own for the first MAX_SOLVED outputs, 'shared' past them), or the largest
    point itself when none is larger (an end of the curve, or a failed solve).
    solved: the FRFPoints the searches solved (their leak is checked like the run's).
    Every solve is one corrector on the run that made the points (frirom_run run_solve:
    a step of given length along a point's tangent, from the history that point left;
    no set-up, the held factorisation kept)."""
    run = packed.run
    cache = {}

    def solve(base_k: int, s: float) -> FRFPoint:
        key = (base_k, s)
        if key not in cache:
            base = points[base_k]
            res = run.solve(_run.SOLVE_STEP, base.parameter, base.unknowns,
                            tan0=base.tangent, yscale=base.yscale, ds=s,
                            sliders=base.slider if base.slider.size else None)
            if res.info != 0 or res.npts != 1:
                raise RuntimeError(res.msg)
            # the point keeps the yscale Fortran returns: its tangent is in that scale
            p = packed.points(res, 0.0)[0]
            if abs(_offset(base, p, lscale) - s) > 1e-6 * s:
                raise RuntimeError("the corrector did not keep the step")
            cache[key] = p
        return cache[key]

    amp = np.array([p.amp_max for p in points])
    # candidates per output: every interior local maximum of the points close to the
    # largest (two resonances of about the same height may swap once solved)
    cands = []
    for j in range(amp.shape[1]):
        a = amp[:, j]
        i = int(np.argmax(a))
        inner = np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1
        inner = inner[a[inner] >= (1.0 - NEAR) * a[i]]
        cands.append((i, inner[np.argsort(-a[inner], kind="stable")][:MAX_CANDIDATES]))
    # one Brent search per candidate point and output, for the first MAX_SOLVED outputs
    # (in the caller's order): each output's peak is its own, even where the outputs peak
    # at one resonance (at other arc lengths along it). Outputs past MAX_SOLVED take the
    # largest of those solves (the corrector gives every output at once), to the spacing
    # of the solves: their Peak.method says 'shared'.
    for j, (_, inner) in enumerate(cands[:MAX_SOLVED]):
        for k in inner:
            _search_peak(solve, points, int(k), j, lscale)
    solved = {}   # candidate k -> the points solved between its neighbours
    for (b, _), p in cache.items():
        solved.setdefault(b + 1, []).append(p)
    peaks = []
    for j, (i, inner) in enumerate(cands):
        best = Peak(points[i].omega, float(amp[i, j]), i)
        how = "solve" if j < MAX_SOLVED else "shared"
        for k in inner:
            for p in solved.get(int(k), []):
                if p.amp_max[j] > best.amplitude:
                    best = Peak(p.omega, float(p.amp_max[j]), int(k), how)
        peaks.append(best)
    return peaks, list(cache.values())


def _search_peak(solve, points: list, i: int, j: int, lscale: float) -> None:
    """Brent's method for the largest amplitude of output j between points i - 1 and
    i + 1, along the tangent of i - 1 from the bracket the three points make; every point
    it solves stays in `solve`'s cache. Nothing is solved when the curve turns too much
    between the points for that parameterisation; a failed solve ends the search."""
    base = points[i - 1]
    s_i, s_hi = (_offset(base, points[k], lscale) for k in (i, i + 1))
    if not 0 < s_i < s_hi or not points[i].amp_max[j] > 0:
        return
    known = {0.0: base, s_i: points[i], s_hi: points[i + 1]}
    try:
        scipy.optimize.minimize_scalar(
            lambda s: -(known[s] if s in known else solve(i - 1, s)).amp_max[j],
            bracket=(0.0, s_i, s_hi), method="brent", tol=XTOL * s_hi / s_i)
    except (RuntimeError, ValueError):
        pass
