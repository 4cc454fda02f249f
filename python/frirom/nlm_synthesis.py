"""Forced responses synthesised from a nonlinear mode's backbone: single nonlinear mode
theory (SNMT; W. Szemplinska-Stupnicka, "The modified single mode method in the
investigations of the resonant vibrations of non-linear systems", J. Sound Vib. 63 (1979)
475-489; M. Krack, L. Panning-von Scheidt, J. Wallaschek, "A method for nonlinear modal
analysis and synthesis: application to harmonically forced and self-excited mechanical
systems", J. Sound Vib. 332 (2013) 6798-6814).

Near an isolated resonance the forced motion is taken to be the nonlinear mode at some
modal amplitude a and phase theta,

    x(t) = X_0(a) + Re sum_h a psi_h(a) exp(i h (Omega t + theta)),

psi_h the mode's harmonics per unit modal amplitude (harmonic 1 mass-normalised, from
:class:`frirom.nonlinear_modes.Backbone`). Projected on psi_1, the equations of motion
under the load f(t) = Re F_1 exp(i Omega t) become the modal equation

    (omega(a)^2 - Omega^2 + i (Omega c(a) + omega(a) (xi(a) - c(a)))) a exp(i theta)
        = psi_1(a)^H F_1 = q(a)

with the backbone's frequency omega(a) and artificial damping xi(a) = 2 D(a) omega(a),
split into its viscous part c(a) = psi_1^H C psi_1 (Backbone.xi_viscous), whose force
grows with the frequency, and the contacts' part xi - c, whose force does not (friction
and every law here are rate-independent: at H = 1 on one DoF this is the harmonic
balance equation itself; c = xi gives the textbook 2 D omega Omega). Its modulus,

    P(Omega) = (omega^2 - Omega^2)^2 + (Omega c + omega (xi - c))^2 = R^2,   R = |q| / a,

is a quartic in Omega with one minimum near omega: every amplitude with P_min <= R^2 has a
response frequency below and one above the resonance (found by bisection on either side
of the minimum), and P_min = R^2 is the peak. The curve is the lower branch up the
amplitudes to the peak and the upper branch back down (folds included); the phase follows
from the modal equation and gives every harmonic at the outputs. Cost: interpolating the
backbone and evaluating P, milliseconds per curve.

A cyclic sector's backbone (frirom.nonlinear_modes_cyclic: one nodal diameter, a
travelling wave) synthesises the same way: psi_1 is sector 0's harmonic 1, mass-normalised
over the sector in the modes of its nodal diameter, and the load F_1 sector 0's under the
engine order whose harmonic 1 lives on that diameter (each sector carries it delayed, as in
frirom.frf on the CyclicModel); tests/test_nlm_synthesis_cyclic.py.

Where it does not hold: a load that also excites another mode near the frequency range
(several resonances close together, or modal interaction), and motions whose higher
harmonics are not those of the free mode (internal resonances, strong harmonic content
under the load); tests/test_nlm_synthesis.py shows both.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.interpolate import CubicHermiteSpline, CubicSpline
from scipy.optimize import brentq

from ._errors import ParameterError
from .model import Excitation

__all__ = ["forced_response"]

#: points of the dense amplitude grid per backbone interval (at least _DENSE_MIN in all)
_DENSE_PER = 10
_DENSE_MIN = 2000
_INTERP = CubicSpline


def _load_vector(load, n_dof: int, rows=None) -> np.ndarray:
    """The complex harmonic-1 load F_1 (n_dof,) of an Excitation or an array: (n_dof,)
    complex (harmonic 1) or (n_dof, H+1) as Excitation.F. rows: the model DoFs of the
    backbone's n_dof rows when it keeps only some (Backbone.harmonic_dofs): a load on the
    whole model is then taken on them, every loaded DoF among them."""
    if not isinstance(load, Excitation):
        arr = np.asarray(load)
        if arr.ndim == 1:
            arr = np.stack([np.zeros(arr.size), arr], axis=1)
        try:
            load = Excitation(arr)
        except Exception as exc:       # SizeError, NonFiniteError, ParameterError
            raise ParameterError(f"load: {exc}") from None
    F = load.F
    if rows is not None and F.shape[0] != n_dof:
        rows = np.asarray(rows, int)
        if F.shape[0] <= rows.max():
            raise ParameterError(f"load: {F.shape[0]} rows; the backbone keeps DoFs up to "
                                 f"{rows.max()} of its model")
        loaded = np.flatnonzero(np.any(F[:, 1:] != 0, axis=1))
        missing = np.setdiff1d(loaded, rows)
        if missing.size:
            raise ParameterError(f"load: DoFs {missing[:8].tolist()} are loaded but the "
                                 "backbone does not keep them (a cyclic sector above 400 "
                                 "coordinates keeps its contact DoFs and outputs): give "
                                 "them among the outputs (nonlinear_mode's outputs, a "
                                 "deck's [outputs])")
        F = F[rows]
    if F.shape[0] != n_dof:
        raise ParameterError(f"load: {F.shape[0]} rows for a backbone of {n_dof} DoFs")
    if F.shape[1] > 2 and np.any(F[:, 2:] != 0):
        raise ParameterError("load: harmonics above 1 are nonzero; the single nonlinear mode "
                             "synthesis takes a harmonic-1 load (use frirom.frf)")
    if F.shape[1] < 2 or not np.any(F[:, 1] != 0):
        raise ParameterError("load: the harmonic-1 load is zero")
    return np.asarray(F[:, 1], complex)


def _amplitude_sampled(X: np.ndarray) -> np.ndarray:
    """max_t |x(t)| of harmonics X (..., 2H+1): the largest of 32 (2H+1) samples refined
    by a parabola through it and its neighbours (to ~1e-6 relatively; a vectorised
    stand-in for frirom.results.amplitude_max, which solves each row's extrema)."""
    nc = X.shape[-1]
    n = 32 * nc
    tau = 2 * np.pi * np.arange(n) / n
    h = np.arange(1, (nc - 1) // 2 + 1)
    B = np.zeros((nc, n))
    B[0] = 1.0
    B[1::2], B[2::2] = np.cos(np.outer(h, tau)), np.sin(np.outer(h, tau))
    y = np.abs(X @ B)                                            # (..., n)
    k = np.argmax(y, axis=-1)[..., None]
    y0 = np.take_along_axis(y, (k - 1) % n, -1)[..., 0]
    y1 = np.take_along_axis(y, k, -1)[..., 0]
    y2 = np.take_along_axis(y, (k + 1) % n, -1)[..., 0]
    curv = y0 - 2 * y1 + y2
    safe = np.where(curv < 0, curv, -1.0)
    return np.where(curv < 0, y1 - 0.125 * (y2 - y0) ** 2 / safe, y1)


def _slopes(bb, order):
    """(n, 2) d omega / d ln a and d xi / d ln a at the backbone's points from the
    continuation's tangents (unknowns scaled by yscale, log10 a by lscale), or None when
    the backbone does not keep them."""
    t = bb.tans
    if (t is None or bb.yscales is None or not bb.lscale or t.shape[0] != len(bb)
            or bb.y is None or t.shape[1] != bb.y.shape[1] + 1):
        return None
    t, ysc = t[order], bb.yscales[order]
    if np.any(np.abs(t[:, -1]) < 1e-12 * np.abs(t).max(axis=1)) or np.any(ysc <= 0):
        return None                 # a point where the amplitude turns: no slope in ln a
    dy = t[:, -3:-1] * (ysc / (bb.lscale * t[:, -1] * np.log(10.0)))[:, None]
    return dy * bb.omega0           # omega = omega0 y[-2], xi = omega0 y[-1]


class _Mode:
    """The backbone as functions of s = ln a (cubic splines, omega and xi Hermite cubics on
    the continuation's slopes; constant outside its range)."""

    def __init__(self, bb, F1):
        if len(bb) < 2:
            raise ParameterError("backbone: at least 2 points are needed to synthesise")
        da = np.diff(bb.amplitude)
        if not (np.all(da > 0) or np.all(da < 0)):
            raise ParameterError("backbone: its modal amplitude turns back along the "
                                 "continuation (a fold of the backbone, e.g. an internal "
                                 "resonance): single nonlinear mode theory does not apply")
        order = np.argsort(bb.amplitude)
        a = bb.amplitude[order]
        s = np.log(a)
        self.s0, self.s1 = float(s[0]), float(s[-1])
        Xd = bb.harmonics[order]                                  # (n, n_dof, nc)
        psi1 = (Xd[:, :, 1] - 1j * Xd[:, :, 2]) / a[:, None]
        q = np.conj(psi1) @ F1
        Y = np.array(bb.outputs[order], float)                    # (n, n_out, nc)
        Y[:, :, 1:] /= a[:, None, None]
        st = bb.states[order]
        frac = st.mean(axis=2) if st.shape[2] else np.zeros((len(a), 0))
        self.n_groups = 1 if st.shape[2] else 0
        cv = (bb.xi_viscous[order] if getattr(bb, "xi_viscous", None) is not None
              else bb.xi[order])           # not kept: all of xi taken as viscous
        vals = np.column_stack([bb.omega[order], bb.xi[order], q.real, q.imag, cv])
        self._f = _INTERP(s, vals, axis=0, extrapolate=False)
        slopes = _slopes(bb, order)
        if slopes is not None:      # omega and xi: Hermite cubics on the exact slopes
            self._wx = CubicHermiteSpline(s, vals[:, :2], slopes, axis=0, extrapolate=False)
        else:
            self._wx = _INTERP(s, vals[:, :2], axis=0, extrapolate=False)
        self._Y = _INTERP(s, Y, axis=0, extrapolate=False)
        # max_t |x| is that of the mode at a whatever the phase (a shift in time): from the
        # backbone's points, interpolated in log
        am = np.maximum(_amplitude_sampled(bb.outputs[order]), 1e-300)
        self._amp = _INTERP(s, np.log(am), axis=0, extrapolate=False)
        self._static = bool(np.any(bb.outputs[:, :, 0]))
        self._st = (s, frac)

    def _clip(self, s):
        return np.clip(s, self.s0, self.s1)

    def scalars(self, s):
        """omega, xi, c (viscous part of xi), |q|, arg q at s (arrays)."""
        sc = self._clip(np.asarray(s, float))
        v = self._f(sc)
        wx = self._wx(sc)
        return (wx[..., 0], wx[..., 1], v[..., 4], np.hypot(v[..., 2], v[..., 3]),
                np.arctan2(v[..., 3], v[..., 2]))

    def disc(self, s):
        """R^2 - min P: >= 0 where the amplitude a = e^s is reached."""
        w, xi, cv, qa, _ = self.scalars(s)
        return (qa * np.exp(-np.asarray(s))) ** 2 - _p_min(w, xi, cv)[1]

    def shapes(self, s):
        return self._Y(self._clip(s))

    def amp_max(self, s, cw=None):
        """(m, n_out) max_t |x| at the outputs at s = ln a (below the backbone: scaled
        with a, or evaluated when the outputs have a static part)."""
        s = np.asarray(s, float)
        out = np.exp(self._amp(self._clip(s)))
        low = s < self.s0
        if np.any(low):
            if self._static:
                from .results import amplitude_max
                out[low] = amplitude_max(_harmonics(self, s[low], cw[low]))
            else:
                out[low] *= np.exp(s[low] - self.s0)[:, None]
        return out

    def fractions(self, s):
        sk, frac = self._st
        return np.stack([np.interp(s, sk, frac[:, j]) for j in range(frac.shape[1])],
                        axis=-1) if frac.shape[1] else np.zeros((np.size(s), 0))


def _modal_term(W, w, xi, cv):
    """omega^2 - Omega^2 + i (Omega c + omega (xi - c)): the modal equation's factor."""
    return w * w - W * W + 1j * (W * cv + w * (xi - cv))


def _p_min(w, xi, cv):
    """(Omega_m, P(Omega_m)): the minimum of P = |_modal_term|^2 near omega (Newton)."""
    g0 = w * (xi - cv)
    W = np.array(w, float, copy=True)
    for _ in range(12):
        dP = -4 * W * (w * w - W * W) + 2 * cv * (cv * W + g0)
        W = W - dP / (12 * W * W - 4 * w * w + 2 * cv * cv)
    return W, np.abs(_modal_term(W, w, xi, cv)) ** 2


def _branches(w, xi, cv, R):
    """The frequencies below and above Omega_m where P = R^2 (bisection, 44 halvings:
    1e-13 of the bracket); NaN below where P(0) < R^2 (no root under the resonance)."""
    Wm, _ = _p_min(w, xi, cv)
    g0, R2, w2 = w * (xi - cv), R * R, w * w

    def f(W):
        return (w2 - W * W) ** 2 + (W * cv + g0) ** 2 - R2

    out = []
    for a, b in ((np.zeros_like(Wm), Wm), (Wm, np.sqrt(w2 + 2 * R))):
        up = f(a) < 0                   # f rises from a to b (else falls)
        for _ in range(44):
            m = 0.5 * (a + b)
            move_a = (f(m) < 0) == up
            a = np.where(move_a, m, a)
            b = np.where(move_a, b, m)
        out.append(0.5 * (a + b))
    lower, upper = out
    lower[f(np.zeros_like(Wm)) < 0] = np.nan
    return lower, upper


def _intervals(mode: _Mode, s: np.ndarray, d: np.ndarray) -> list:
    """[(sa, sb)] where disc >= 0 along the grid s, ends refined to disc = 0."""
    pos = np.r_[False, d >= 0, False].astype(np.int8)
    starts = np.flatnonzero(np.diff(pos) == 1)          # first index of each run
    ends = np.flatnonzero(np.diff(pos) == -1) - 1       # last index of each run
    n, out = s.size, []
    for i, j in zip(starts, ends):
        sa = s[i] if i == 0 else brentq(mode.disc, s[i - 1], s[i], xtol=1e-14)
        sb = s[j] if j == n - 1 else brentq(mode.disc, s[j], s[j + 1], xtol=1e-14)
        out.append((sa, sb))
    return out


def _window(cs, cw, lo, hi):
    """The curve's points with lo <= Omega <= hi, a point added where it crosses lo or hi
    (linear between the dense points)."""
    inside = (cw >= lo) & (cw <= hi)
    k = np.flatnonzero(inside[1:] != inside[:-1])        # crossings between k and k + 1
    add_s, add_w, at = [], [], []
    for i in k:
        for edge in (lo, hi):
            if (cw[i] - edge) * (cw[i + 1] - edge) < 0:
                f = (edge - cw[i]) / (cw[i + 1] - cw[i])
                add_s.append(cs[i] + f * (cs[i + 1] - cs[i]))
                add_w.append(edge)
                at.append(i + 1)
    cs, cw = np.insert(cs, at, add_s), np.insert(cw, at, add_w)
    keep = np.insert(inside, at, True)
    return cs[keep], cw[keep]


def forced_response(bb, load, omega=None, points: int = 400):
    """The forced response near the backbone's resonance by single nonlinear mode theory.

    Parameters
    ----------
    bb : Backbone
        From :func:`frirom.nonlinear_mode` (any H; its damping is the model's, so the
        synthesised response is the same model's under the load).
    load : Excitation or array_like
        Harmonic-1 load: an Excitation (harmonics above 1 must be zero; a static column is
        ignored, the backbone has its own) or F_1 (n_dof,) complex, f = Re F_1 e^{i Omega t}.
        A cyclic sector's backbone: sector 0's load under the engine order of its nodal
        diameter (the CyclicModel's Excitation for frirom.frf).
    omega : (float, float), optional
        Frequency range, rad/s; default 0.95 and 1.05 times the backbone's lowest and
        highest frequency.
    points : int
        Points along the curve (by arc length in normalised frequency and log amplitude;
        the peak is always one of them).

    Returns
    -------
    FRF
        At the backbone's outputs, ``parameter_name`` 'omega', ``meta['method'] =
        'snmt'``; ``complete`` False (and ``message`` why) when the response leaves the
        backbone's amplitude range (raise its upper amplitude). ``state_fractions`` are the
        backbone's mean over every contact element (one group, 'contacts').
    """
    from .results import FRF
    t0 = time.perf_counter()
    F1 = _load_vector(load, bb.harmonics.shape[1], getattr(bb, "harmonic_dofs", None))
    mode = _Mode(bb, F1)
    if omega is None:
        lo, hi = 0.95 * float(bb.omega.min()), 1.05 * float(bb.omega.max())
    else:
        try:
            lo, hi = sorted(float(w) for w in omega)
        except (TypeError, ValueError):
            raise ParameterError("omega: expected (from, to) in rad/s") from None
        if not (0 < lo < hi < np.inf):
            raise ParameterError("omega: two different positive finite frequencies expected")
    if not (isinstance(points, (int, np.integer)) and points >= 3):
        raise ParameterError("points: an integer >= 3 expected")
    # lowest amplitude needed: the response at the window's ends in the linear limit
    w, xi, cv, qa, _ = mode.scalars(np.array([mode.s0]))
    a_ends = [qa[0] / abs(_modal_term(W, w[0], xi[0], cv[0])) for W in (lo, hi)]
    s_lo = min(mode.s0, float(np.log(0.5 * min(a_ends))))
    n = max(_DENSE_MIN, _DENSE_PER * len(bb))
    s = np.linspace(s_lo, mode.s1, n)
    d = mode.disc(s)
    complete, message = True, ""
    if d[-1] > 0:
        complete = False
        message = (f"the response reaches the backbone's largest amplitude a = "
                   f"{np.exp(mode.s1):.4g}: raise it")
    curve_s, curve_w = [], []
    for sa, sb in _intervals(mode, s, d):
        ss = np.r_[sa, s[(s > sa) & (s < sb)], sb]
        w, xi, cv, qa, _ = mode.scalars(ss)
        lo_b, hi_b = _branches(w, xi, cv, qa * np.exp(-ss))
        # lower branch up, upper branch down; they meet at sb (the peak) unless cut there
        met = not (d[-1] > 0 and sb >= mode.s1)
        back = slice(-2, None, -1) if met else slice(None, None, -1)
        br_s, br_w = np.r_[ss, ss[back]], np.r_[lo_b, hi_b[back]]
        ok = np.isfinite(br_w) & (br_w > 0)
        curve_s.append(br_s[ok])
        curve_w.append(br_w[ok])
    if not curve_s:
        raise ParameterError("the load reaches no amplitude on the backbone at any frequency")
    cs, cw = np.concatenate(curve_s), np.concatenate(curve_w)
    cs, cw = _window(cs, cw, lo, hi)
    if cs.size < 2:
        raise ParameterError(f"omega: the synthesised curve has no points in "
                             f"[{lo:g}, {hi:g}] rad/s")
    # resample by arc length in (omega / span, ln a / span), the peak kept
    arc = np.r_[0.0, np.cumsum(np.hypot(np.diff(cw) / (hi - lo),
                                        np.diff(cs) / max(np.ptp(cs), 1e-12)))]
    pick = np.interp(np.linspace(0.0, arc[-1], points), arc, np.arange(cs.size))
    idx = np.unique(np.r_[np.round(pick).astype(int), np.argmax(cs)])
    X = _harmonics(mode, cs[idx], cw[idx])
    peaks = _peaks(mode, cs, cw, idx)
    cs, cw = cs[idx], cw[idx]
    dw = np.diff(cw)
    fold = np.zeros(cw.size, bool)
    fold[1:-1] = dw[:-1] * dw[1:] < 0
    m = cw.size
    frac = mode.fractions(cs)
    elapsed = time.perf_counter() - t0
    groups = ["contacts"] if mode.n_groups else []
    return FRF(omega=cw, parameter=cw.copy(), X=X, amp_max=mode.amp_max(cs, cw),
               state_fractions=frac.reshape(m, mode.n_groups, 3),
               stable=np.ones(m, bool), fold=fold, iterations=np.zeros(m, int),
               time_s=np.full(m, elapsed / m), output_dofs=np.asarray(bb.output_dofs),
               group_names=groups, complete=complete, message=message,
               solver_info=f"single nonlinear mode synthesis from a backbone of {len(bb)} "
                           f"points (mode {bb.mode + 1}, H = {bb.H})",
               meta={"method": "snmt"}, timings={"snmt_seconds": elapsed}, peaks=peaks)


def _harmonics(mode: _Mode, cs, cw) -> np.ndarray:
    """(m, n_out, nc) harmonics at the outputs of the curve points (ln a, Omega): the
    mode's harmonics at a turned by the phase of the modal equation."""
    a = np.exp(cs)
    w, xi, cv, _, qarg = mode.scalars(cs)
    theta = qarg - np.angle(_modal_term(cw, w, xi, cv))
    Y = mode.shapes(cs)                                          # (m, n_out, nc)
    X = np.empty_like(Y)
    X[:, :, 0] = Y[:, :, 0]
    for h in range(1, (Y.shape[-1] - 1) // 2 + 1):
        c = (Y[:, :, 2 * h - 1] - 1j * Y[:, :, 2 * h]) * (a * np.exp(1j * h * theta))[:, None]
        X[:, :, 2 * h - 1], X[:, :, 2 * h] = c.real, -c.imag
    return X


def _peaks(mode: _Mode, cs, cw, idx) -> list:
    """Peak per output on the dense curve (index: the nearest resampled point)."""
    from .results import Peak
    am = mode.amp_max(cs, cw)
    out = []
    for j in range(am.shape[1]):
        i = int(np.argmax(am[:, j]))
        out.append(Peak(float(cw[i]), float(am[i, j]), int(np.argmin(np.abs(idx - i))),
                        "snmt"))
    return out
