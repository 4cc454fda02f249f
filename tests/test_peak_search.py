"""The peak search between continuation points (frirom._peak._climb) on curves with a
known maximum: a linear resonance along an arc length that is not the frequency, a corner
(a contact state appearing at the peak), and outputs sharing solves. Each is compared with
the closed form and with the search it replaced (scipy's Brent to XTOL of the bracket, the
old refine_peak) on the same curve: at least as accurate, with fewer solves."""

import numpy as np
import pytest
import scipy.optimize

from frirom import _peak

ZETA = 0.01


def resonance(w):
    """|H| of x'' + 2 zeta x' + x = cos(w t); its largest value 1 / (2 zeta sqrt(1 - zeta^2))
    at w = sqrt(1 - 2 zeta^2)."""
    return 1.0 / np.sqrt((1.0 - w**2)**2 + (2.0 * ZETA * w)**2)


def omega_of(s):
    """Frequency along the curve: the arc length is not the frequency (near a resonance
    the unknowns move much more than the frequency)."""
    return 0.99 + 0.02 * s - 0.004 * s**2


def corner(s, c=0.37):
    """A corner at s = c (slopes +1.3 and -0.2 there, curved branches), largest value 1."""
    d = s - c
    return 1.0 + (1.3 * d - 0.5 * d**2 if d < 0 else -0.2 * d - 0.3 * d**2)


def search(curves, s_pts, tol_s=None):
    """_climb on outputs given as functions of s, from the bracket s_pts (three points, the
    middle largest for the first output); returns (the largest solved value per output
    with its s, number of solves)."""
    calls = []

    def amp_at(s):
        calls.append(s)
        return omega_of(s), np.array([f(s) for f in curves])

    known = {s: (omega_of(s), np.array([f(s) for f in curves])) for s in s_pts}
    tol_s = _peak.XTOL * s_pts[2] if tol_s is None else tol_s
    for j in range(len(curves)):
        _peak._climb(amp_at, known, j, tol_s)
    s = np.array(sorted(known))
    a = np.array([known[x][1] for x in s])
    return [(a[:, j].max(), s[np.argmax(a[:, j])]) for j in range(len(curves))], len(calls)


def brent(f, s_pts):
    """The old refine_peak's search on f: (largest value, solves)."""
    known, calls = {s: f(s) for s in s_pts}, []

    def neg(s):
        if s not in known:
            calls.append(s)
            known[s] = f(s)
        return -known[s]
    scipy.optimize.minimize_scalar(neg, bracket=tuple(s_pts), method="brent",
                                   tol=_peak.XTOL * s_pts[2] / s_pts[1])
    return max(known.values()), len(calls)


def test_linear_resonance_along_the_arc_length():
    """Three points of a drawn resonance (the middle one 0.3 % below the peak): the
    largest solved value within 1e-9 of the closed form (GAIN_TOL, the search's amplitude
    tolerance; measured 1e-13) in at most 3 solves, where the old search took 6 and came
    within 3e-10."""
    f = lambda s: resonance(omega_of(s))               # noqa: E731
    top = 1.0 / (2.0 * ZETA * np.sqrt(1.0 - ZETA**2))
    pts = (0.0, 0.5, 1.0)
    assert f(pts[1]) > max(f(pts[0]), f(pts[2])) and f(pts[1]) < (1 - 1e-3) * top
    [(a, s)], n = search([f], pts)
    a_old, n_old = brent(f, pts)
    print(f"linear: {n} solves, error {1 - a / top:.1e}; old {n_old} solves, "
          f"{1 - a_old / top:.1e}")
    assert abs(a / top - 1) < 1e-9 and n <= 3
    assert abs(omega_of(s) / np.sqrt(1.0 - 2.0 * ZETA**2) - 1) < 1e-6
    assert n < n_old and abs(a / top - 1) <= abs(a_old / top - 1) + 1e-12


@pytest.mark.parametrize("pts", [(0.0, 0.45, 1.0), (0.0, 0.3, 0.8), (0.2, 0.4, 1.0)])
def test_corner_found_as_the_old_search_finds_it(pts):
    """A corner (the curve's amplitude is not smooth there, no parabola fits): the search
    falls back to the corner model and golden sections; the largest solved value within the
    old search's own error on the same curve (or 1e-6 relative), with at most as many
    solves."""
    [(a, s)], n = search([corner], pts)
    a_old, n_old = brent(corner, pts)
    print(f"corner {pts}: {n} solves, error {1 - a:.1e}; old {n_old} solves, {1 - a_old:.1e}")
    assert 1 - a <= max(1 - a_old, 1e-6) and n <= n_old


def test_outputs_share_solves():
    """Outputs peaking together (one mode shape, as the 300 blades of a travelling wave)
    cost what one does; an output peaking elsewhere gets its own solves and its own
    maximum to the same tolerance (the old search gave it only the first's solves)."""
    f = lambda s: resonance(omega_of(s))               # noqa: E731
    g = lambda s: 0.5 * f(s)                           # noqa: E731
    pts = (0.0, 0.5, 1.0)
    _, n1 = search([f], pts)
    res, n2 = search([f, g, g], pts)
    assert n2 == n1
    top = 1.0 / (2.0 * ZETA * np.sqrt(1.0 - ZETA**2))
    assert abs(res[1][0] / (0.5 * top) - 1) < 1e-9
    h = lambda s: resonance(omega_of(s) - 3e-4)        # noqa: E731  (peaks 3e-4 higher)
    res, n3 = search([f, h], pts)
    assert n3 > n1 and abs(res[1][0] / top - 1) < 1e-9 and res[1][1] > res[0][1]
