"""Floquet multipliers by time integration: an independent reference for Hill's method.

The monodromy matrix of frirom's explicit time integration (:func:`frirom.timeint.integrate`,
central differences) over one period, started on a periodic solution (a harmonic balance
point), by central finite differences: the discrete map takes the state (x_k, x_{k-1})
over N steps (here as (x_k, (x_k - x_{k-1}) / dt)), so the initial states of the perturbed
runs (x_0 and the Taylor step x_{-1} that integrate builds from x0, v0) are read back
from integrate itself (zero periods) and the matrix is Phi = dOut dIn^-1 in those
coordinates. All perturbed runs go as one batch
(integrate's batch axis), each with the point's contact history (sliders).

For hysteretic contacts the map is piecewise linear in the perturbation (a slider sticks or
slips at each step); a perturbation of relative size ``eps`` keeps the switching steps of
the base run when eps is small against the margins of the stick/slip tests, and the
one-sided differences then agree (the result reports their mismatch, ``asymmetry``).
The multipliers mu give the exponents s = log(mu) / T, T = 2 pi / omega, defined modulo
i omega: the copy in the strip |Im s| <= omega / 2, which is the one Hill keeps.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .timeint import TimeContact, integrate, state_from_harmonics


@dataclass
class Monodromy:
    """Result of :func:`monodromy`.

    phi: (2n, 2n) monodromy matrix in the coordinates (x_k, (x_k - x_{k-1}) / dt);
    multipliers (2n,)
    its eigenvalues, largest modulus first; exponents (2n,) log(mu) / T in the strip;
    asymmetry: max |forward - backward difference| / max |central| (0 where the map is
    linear over +-eps); steps: steps per period; drift: the base run's change over the
    period relative to its amplitude (how periodic the start was).
    """

    phi: np.ndarray
    multipliers: np.ndarray
    exponents: np.ndarray
    asymmetry: float
    steps: int
    drift: float

    @property
    def max_re(self) -> float:
        """Largest real part of the exponents, 1/s (log of the largest |mu|, over T)."""
        return float(self.exponents.real.max())


def monodromy(M, C, K, contacts: list[TimeContact], F, omega: float, X: np.ndarray,
              *, eps: float = 1e-6, steps_per_period: int = 2048,
              max_phase_step: float = 0.05) -> Monodromy:
    """Monodromy matrix over one period of the explicit integration started on the
    periodic solution with harmonics X (n, 2H+1) at omega (rad/s); contacts carry the
    point's sliders in their ``w0`` (frirom.solver's FRFPoint.slider). eps: the
    perturbation relative to max |x| (and max |v| for the velocities). The step count
    is the larger of steps_per_period and the one that resolves the stuck model's
    highest mode to max_phase_step rad per step."""
    M, C, K = (np.asarray(a.toarray() if hasattr(a, "toarray") else a, float)
               for a in (M, C, K))
    n = M.shape[0]
    x0, v0 = state_from_harmonics(np.asarray(X, float), omega)
    dx = eps * max(np.abs(x0).max(), np.abs(X).max(), 1e-300)
    dv = eps * max(np.abs(v0).max(), omega * np.abs(X).max(), 1e-300)
    # batch: base, then +-dx e_i, then +-dv e_i
    nb = 1 + 4 * n
    xs = np.tile(x0, (nb, 1))
    vs = np.tile(v0, (nb, 1))
    i = np.arange(n)
    xs[1 + i, i] += dx
    xs[1 + n + i, i] -= dx
    vs[1 + 2 * n + i, i] += dv
    vs[1 + 3 * n + i, i] -= dv
    w0 = [np.broadcast_to(c.w0, (nb,) + c.w0.shape).copy() for c in contacts]
    kw = dict(H=(X.shape[1] - 1) // 2, min_periods=0, tol=0.0, method="explicit",
              steps_per_period=steps_per_period, max_phase_step=max_phase_step,
              x0=xs, v0=vs, w0=w0)
    om = np.full(nb, float(omega))
    start = integrate(M, C, K, contacts, F, om, periods=0, **kw)
    end = integrate(M, C, K, contacts, F, om, periods=1, **kw)
    # states (x_k, (x_k - x_{k-1}) / dt): the same multipliers as (x_k, x_{k-1}), better
    # scaled (a velocity perturbation moves x_{k-1} by dt dv only)
    dt = 2.0 * np.pi / (omega * end.steps_per_period)
    sin = np.concatenate([start.x, (start.x - start.x_prev) / dt], axis=1)   # (nb, 2n)
    sout = np.concatenate([end.x, (end.x - end.x_prev) / dt], axis=1)

    def central(a, lo, hi):
        return 0.5 * (a[lo:hi] - a[hi:hi + n]).T

    din = np.concatenate([central(sin, 1, 1 + n), central(sin, 1 + 2 * n, 1 + 3 * n)], 1)
    dout = np.concatenate([central(sout, 1, 1 + n), central(sout, 1 + 2 * n, 1 + 3 * n)], 1)
    fwd = np.concatenate([(sout[1:1 + n] - sout[0]).T, (sout[1 + 2 * n:1 + 3 * n] - sout[0]).T],
                         1)
    bwd = np.concatenate([(sout[0] - sout[1 + n:1 + 2 * n]).T,
                          (sout[0] - sout[1 + 3 * n:1 + 4 * n]).T], 1)
    asym = float(np.abs(fwd - bwd).max() / max(np.abs(dout).max(), 1e-300))
    phi = np.linalg.solve(din.T, dout.T).T
    mu = np.linalg.eigvals(phi)
    mu = mu[np.argsort(-np.abs(mu))]
    T = 2.0 * np.pi / omega
    s = np.log(mu.astype(complex)) / T
    drift = float(np.abs(end.x[0] - x0).max() / max(np.abs(X).max(), 1e-300))
    return Monodromy(phi, mu, s, asym, int(end.steps_per_period), drift)
