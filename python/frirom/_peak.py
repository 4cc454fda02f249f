"""The peak of a continuation run solved on the curve: for each output, the largest
max-over-the-period amplitude between the points around the largest one, found by a
search along the curve whose every evaluation is one corrector solve (one
search per resonance, for the first output that peaks there; the other outputs reuse its
solves and solve more only where their own peak is not found to the same tolerance).

The curve near the largest point i is parameterised by the arc length s along the tangent
of point i - 1 (pseudo-arc-length: the corrector solves R = 0 on the hyperplane at distance
s along that tangent, as the continuation itself does), so a peak next to a fold, or at a
corner of a friction curve (a contact state appearing there), is found like a smooth one.

The search (`_climb`) steps to the vertex of a smooth model through the best solution and
its two neighbours: a parabola of 1/a^2 in omega (exact for a linear resonance, 1/|H|^2
being a polynomial in omega; near a friction-damped peak close to one), in the arc length
next to a fold. It stops when the amplitude has converged: the same model through the best
solution's neighbours alone predicts the best solution to GAIN_TOL of the amplitude, and
the model through it predicts a further gain below GAIN_TOL. On a smooth peak that takes
one to three solves, and an output peaking with an earlier one (the same solves) none.
While one neighbour of the best solution is more than 10x farther than the other, a
solve on its side comes first (a model through the far point is biased and creeps).
Where the model twice misses its prediction by more than half the gain predicted, the peak
is a corner (a contact state appearing there): the corner model (two lines meeting) takes
over, with Brent's safeguard (golden sections where a step would not shrink the bracket
fast enough), until the peak is bracketed to XTOL of two steps in s, the test of the
search it replaced (at a corner the amplitude is then off by about XTOL times its change
over a step, ~1e-5; measured 10-100x less).

A further candidate of an output (another local maximum of its points within NEAR of
their largest) is skipped once its points lie NEAR below the peak already solved for it:
NEAR is the gain over the points the candidates' rule allows for.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ._pack import START_RESUME, _Packed
from .results import FRFPoint, Peak

#: local maxima of the points within this fraction of the largest are solved for too
#: (at most MAX_CANDIDATES of them, the largest first)
NEAR = 2e-3
MAX_CANDIDATES = 3
#: bracket in arc length, relative to the bracket of two steps, below which the search
#: stops (at a corner the amplitude error is about this times its change over a step)
XTOL = 2e-3
#: amplitude tolerance of the smooth model, relative: the search stops when the model
#: predicts the best solution and a further gain to this (below NOISE: the corrector
#: converges its points well past tol_update, and neighbouring solves share their error)
GAIN_TOL = 1e-9
#: the amplitude's noise, relative, from the corrector's tolerances (tol_update 1e-8 on the
#: unknowns): a step whose solve misses its prediction by less is not taken for a corner
NOISE = 1e-8
#: solves per search at most (a safeguard; a corner takes ~10, a smooth peak 1-3)
MAX_SOLVES = 16
_GOLDEN = 0.5 * (3.0 - math.sqrt(5.0))


def _offset(base: FRFPoint, p: FRFPoint, lscale: float) -> float:
    """Distance of p from base along base's tangent, in the scaled variables of the run."""
    d = np.r_[(p.unknowns - base.unknowns) / base.yscale,
              (p.parameter - base.parameter) / lscale]
    return float(base.tangent @ d)


def refine_peaks(packed: _Packed, points: list, lam_end: float, lam_lo: float,
                 lscale: float, omega_fix: float = 0.0) -> tuple[list, list]:
    """Peak per output of a frequency continuation's points (FRFPoint list, in order).

    Returns (peaks, solved): a list of :class:`frirom.results.Peak` (n_out,) (the largest
    of the solved local maxima, ``method`` 'solve'; the interior local maxima of the points
    within NEAR of the largest are solved for, at most MAX_CANDIDATES), or the largest point
    itself when none is larger (an end of the curve, or a failed solve); and the FRFPoints
    solved on the way (each with the yscale its tangent is in, and its leak)."""
    opts = dataclasses.replace(packed.opts, ds_max=1.0e3, ds_min=1e-12)
    quiet = dataclasses.replace(packed, opts=opts, stability=False, w0=packed.w0.copy())
    cache = {}

    def solve(base_k: int, s: float) -> FRFPoint:
        key = (base_k, s)
        if key not in cache:
            base = points[base_k]
            if base.slider.size:
                quiet.w0 = base.slider.copy()
            res = quiet.call(base.unknowns, base.parameter, base.tangent, START_RESUME, s,
                             lam_end, lam_lo, base.yscale, lscale, 1, omega_fix)
            if res.info != 0 or res.npts != 1:
                raise RuntimeError(res.msg)
            p = quiet.points(res, omega_fix, 0.0)[0]
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
    # one search per candidate point, first for the first output (in the caller's order)
    # that has it, then for the others that have it, from the same solves (the corrector
    # gives every output at once: outputs peaking together, as on a structure with 300
    # outputs in one travelling wave, cost what one output does)
    users = {}
    for j, (_, inner) in enumerate(cands):
        for k in inner:
            users.setdefault(int(k), []).append(j)
    # a candidate whose points stay NEAR below the peak an earlier search solved for that
    # output is not searched (the margin NEAR puts it among the candidates in the first
    # place; the points' own largest may be that far below the peak between them)
    best = amp.max(axis=0)
    for k, js in users.items():
        if cache:
            best = np.maximum(best, np.max([p.amp_max for p in cache.values()], axis=0))
        js = [j for j in js if amp[k, j] >= (1.0 - NEAR) * best[j]]
        if js:
            _search_peak(solve, points, k, js, lscale)
    solved = {}   # candidate k -> the points solved between its neighbours
    for (b, _), p in cache.items():
        solved.setdefault(b + 1, []).append(p)
    peaks = []
    for j, (i, inner) in enumerate(cands):
        best = Peak(points[i].omega, float(amp[i, j]), i)
        for k in inner:
            for p in solved.get(int(k), []):
                if p.amp_max[j] > best.amplitude:
                    best = Peak(p.omega, float(p.amp_max[j]), int(k), "solve")
        peaks.append(best)
    return peaks, list(cache.values())


def _search_peak(solve, points: list, i: int, js: list, lscale: float) -> None:
    """The largest amplitude of each output in js between points i - 1 and i + 1, along the
    tangent of i - 1 (`_climb`, from the bracket the three points make; the outputs in
    turn, each from every solve so far); every point solved stays in `solve`'s cache.
    Nothing is solved when the curve turns too much between the points for that
    parameterisation; a failed solve ends the search."""
    base = points[i - 1]
    s_i, s_hi = (_offset(base, points[k], lscale) for k in (i, i + 1))
    if not 0 < s_i < s_hi:
        return
    known = {s: (p.omega, p.amp_max) for s, p in
             ((0.0, base), (s_i, points[i]), (s_hi, points[i + 1]))}

    def amp_at(s):
        p = solve(i - 1, s)
        return p.omega, p.amp_max

    try:
        for j in js:
            if points[i].amp_max[j] > 0:
                _climb(amp_at, known, j, XTOL * s_hi)
    except RuntimeError:
        pass


def _parabola(x, y):
    """The parabola through three points (x, y) as (c2, c1, c0) in powers of x - x[1]."""
    return np.polyfit(np.asarray(x) - x[1], np.asarray(y) - y[1], 2) + [0.0, 0.0, y[1]]


def _amp(c, x: float) -> float:
    """The amplitude 1/sqrt(p) that the parabola p of 1/a^2 (`_parabola`) gives at x."""
    return float(np.polyval(c, x))**-0.5


def _smooth(s, w, a, idx):
    """The smooth model through the points idx (three indices into s, w, a, sorted by s):
    a parabola of 1/a^2 in omega where omega is monotonic over them (a resonance's
    1/|H|^2 is a polynomial in omega, not in the arc length), in s otherwise (a fold).
    Returns (vertex in s, amplitude there, amplitude the model gives at point k as a
    function of k); the vertex NaN and its amplitude inf when the parabola opens
    downwards. The vertex found in omega is taken to s by the parabola s(omega) through
    the same points."""
    ws = w[list(idx)]
    by_w = (ws[1] - ws[0]) * (ws[2] - ws[1]) > 0
    x = ws if by_w else s[list(idx)]
    c = _parabola(x, a[list(idx)] ** -2.0)

    def at(k):
        return _amp(c, (w[k] if by_w else s[k]) - x[1])
    if not c[0] > 0:
        return math.nan, math.inf, at
    xv = x[1] - c[1] / (2.0 * c[0])
    v = (float(np.polyval(np.polyfit(x - x[1], s[list(idx)], 2), xv - x[1])) if by_w
         else xv)
    return v, _amp(c, xv - x[1]), at


def _kink(s, a, b: int):
    """Corner model around the largest a[b] (s, a sorted by s): where the line through the
    two points left of the corner meets the line through the two right of it, the corner
    between s[b - 1] and s[b] or between s[b] and s[b + 1], rising into it from both sides.
    Returns (s, amplitude) of the higher such meeting point, or None."""
    best = None
    for lo in (b - 1, b):
        if lo < 1 or lo + 2 >= len(s):
            continue
        k1 = (a[lo] - a[lo - 1]) / (s[lo] - s[lo - 1])
        k2 = (a[lo + 2] - a[lo + 1]) / (s[lo + 2] - s[lo + 1])
        if not k1 > 0 > k2:
            continue
        x = (a[lo + 1] - a[lo] + k1 * s[lo] - k2 * s[lo + 1]) / (k1 - k2)
        if s[lo] < x < s[lo + 1] and (best is None or a[lo] + k1 * (x - s[lo]) > best[1]):
            best = (x, a[lo] + k1 * (x - s[lo]))
    return best


def _climb(amp_at, known: dict, j: int, tol_s: float) -> None:
    """Safeguarded model search for the largest amplitude of output j (module docstring:
    its steps and its stopping tests).

    amp_at(s) -> (omega, (n_out,) amplitudes) solved at arc length s (raises RuntimeError
    when the solve fails); known {s: (omega, (n_out,) amplitudes)}, holding at least a
    bracket (an interior largest value of output j), grows by every solve; tol_s: the
    bracket (s) at which the search stops.

    The smooth model (`_smooth`) goes through the best point and its neighbours. Once two
    of its steps in a row miss their predictions by more than half the gain predicted, the
    curve has a corner there and the corner model (`_kink`) takes over. A step of either
    that is not inside the bracket, or not shorter than half the step before last, or
    (corner model) follows one that missed, is a golden-section step instead (Brent's
    safeguard)."""
    last = None     # (s solved, predicted amplitude, predicted gain, by the smooth model)
    steps = [math.inf, math.inf]
    misses = 0                  # smooth model steps in a row that missed their prediction
    for _ in range(MAX_SOLVES):
        s = np.array(sorted(known))
        w = np.array([known[x][0] for x in s])
        a = np.array([known[x][1][j] for x in s])
        b = int(np.argmax(a))
        if not 0 < b < len(s) - 1:
            return
        (l, m, r), am = s[b - 1:b + 2], a[b]
        if r - l <= 2.0 * tol_s:
            return
        verified = hit = False
        if last is not None:
            verified = abs(known[last[0]][1][j] - last[1]) <= GAIN_TOL * am
            hit = abs(known[last[0]][1][j] - last[1]) <= 0.5 * last[2] + NOISE * am
            if misses < 2:
                misses = 0 if hit else misses + 1
        v, top = math.nan, math.inf
        if misses < 2:
            v, top, _ = _smooth(s, w, a, (b - 1, b, b + 1))
            # verified: the model through the nearest points around the best one but not
            # it predicts it (as it did the solve it chose; for a later output, the solves
            # an earlier one made), so its gain can be trusted
            loo = [t for t in ((b - 2, b - 1, b + 1), (b - 1, b + 1, b + 2))
                   if t[0] >= 0 and t[2] < len(s)]
            if loo:
                t = min(loo, key=lambda t: s[t[2]] - s[t[0]])
                verified = abs(_smooth(s, w, a, t)[2](b) - am) <= GAIN_TOL * am
        elif hit or last is None or last[3]:
            # a corner: its model first, after a golden step, or after a step of it that hit
            k = _kink(s, a, b)
            if k is not None:
                v, top = k
        if verified and top - am <= GAIN_TOL * am:
            return
        if hit and min(abs(v - s)) < 0.01 * tol_s:
            return              # the vertex is a solved point: located well within tol_s
        last = None
        near, far = sorted((m - l, r - m))
        if misses < 2 and far > 10.0 * near and v == v and abs(v - m) < near:
            # one neighbour far: a point on its side as close as the other first (a model
            # through the far one is biased, the steps creep towards the peak)
            v = m + math.copysign(max(2.0 * abs(v - m), near), (r - m) - (m - l))
        elif l < v < r and min(abs(v - s)) >= 0.01 * tol_s and abs(v - m) < 0.5 * steps[0]:
            last = (float(v), top, top - am, misses < 2)
        else:
            v = m + _GOLDEN * (r - m) if r - m > m - l else m - _GOLDEN * (m - l)
        known[float(v)] = amp_at(float(v))
        steps = [steps[1], abs(v - m)]
