"""The peak of a continuation run solved on the curve: for each output, the largest
max-over-the-period amplitude between the points around the largest one, found by
successive parabolic interpolation along the curve whose every sample is one corrector
solve, shared by the outputs (one search per resonance for the first MAX_SOLVED outputs,
each converging on its own peak; the others take the largest of those solves). Shared
samples cost a fraction of a Brent search per output: on the 200-pair flange ROM_I
(16 outputs) 146 solves became a few dozen.

The curve near the largest point i is parameterised by the arc length s along the tangent
of point i - 1 (pseudo-arc-length: the corrector solves R = 0 on the hyperplane at distance
s along that tangent, as the continuation itself does), so a peak next to a fold, or at a
corner of a friction curve (a contact state appearing there), is found like a smooth one.
"""

from __future__ import annotations

import numpy as np

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
    # one search per candidate point for the first MAX_SOLVED outputs (in the caller's
    # order) that have it: each output's peak is its own, even where the outputs peak at
    # one resonance (at other arc lengths along it), and every solve serves them all (the
    # corrector gives every output at once). Outputs past MAX_SOLVED take the largest of
    # those solves, to the spacing of the solves: their Peak.method says 'shared'.
    by_point = {}
    for j, (_, inner) in enumerate(cands[:MAX_SOLVED]):
        for k in inner:
            by_point.setdefault(int(k), []).append(j)
    for k, outs in by_point.items():
        _search_peaks(solve, points, k, outs, lscale)
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


def _search_peaks(solve, points: list, i: int, outs: list, lscale: float) -> None:
    """The largest amplitude of each output j in `outs` between points i - 1 and i + 1,
    along the tangent of i - 1 (arc length s from 0 to s_hi, point i at s_i): successive
    parabolic interpolation on the solved samples that all outputs share. In each round
    every output not yet converged proposes the vertex of the parabola through its largest
    sample and the two beside it (the middle of the longer side where the parabola does not
    fall strictly inside them, as Brent's method does); proposals closer than the
    tolerance are merged and solved. An output is converged when the samples beside its
    largest lie within 2 tol (tol = XTOL s_hi, the arc-length tolerance Brent was given),
    or its largest sample is an end of the bracket. Every solved point stays in `solve`'s
    cache. Nothing is solved when the curve turns too much between the points for that
    parameterisation; a failed solve ends the search."""
    base = points[i - 1]
    s_i, s_hi = (_offset(base, points[k], lscale) for k in (i, i + 1))
    if not 0 < s_i < s_hi:
        return
    tol = XTOL * s_hi
    known = {0.0: base, s_i: points[i], s_hi: points[i + 1]}
    todo = [0.5 * s_i, 0.5 * (s_i + s_hi)]
    live = [j for j in outs if points[i].amp_max[j] > 0]
    for _ in range(40):
        for x in todo:
            try:
                known[x] = solve(i - 1, x)
            except RuntimeError:
                return
        ss = np.array(sorted(known))
        amps = np.array([known[x].amp_max for x in ss])
        props = []
        for j in list(live):
            m = int(np.argmax(amps[:, j]))
            if m == 0 or m == len(ss) - 1 or ss[m + 1] - ss[m - 1] <= 2.0 * tol:
                live.remove(j)
                continue
            props.append(_next_sample(ss[m - 1:m + 2], amps[m - 1:m + 2, j], tol))
        todo = []
        for x in sorted(props):
            near = min((abs(x - y) for y in todo), default=np.inf)
            if min(abs(ss - x).min(), near) > 0.5 * tol:
                todo.append(float(x))
        if not todo:
            return


def _next_sample(x, y, tol: float) -> float:
    """The next arc length to solve for the largest of y over (x[0], x[2]), y[1] the
    largest of the three: the parabola's vertex where it lies inside and at least tol / 2
    from x[1], else the middle of the longer side."""
    d1, d2 = x[1] - x[0], x[2] - x[1]
    den = d1 * (y[1] - y[2]) + d2 * (y[1] - y[0])
    if den > 0:
        v = x[1] - 0.5 * (d1 * d1 * (y[1] - y[2]) - d2 * d2 * (y[1] - y[0])) / den
        if x[0] < v < x[2] and abs(v - x[1]) >= 0.5 * tol:
            return float(v)
    return float(x[1] - 0.5 * d1 if d1 > d2 else x[1] + 0.5 * d2)
