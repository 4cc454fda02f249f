"""Time-integration reference for the harmonic balance solver.

Integrates

    M x'' + C x' + K x + sum_groups G^T f(G x, w) = f_e(t),
    f_e(t) = Re sum_h F[:, h] exp(i h omega t),

over many forcing periods with a fixed step until the response is periodic, then returns
the harmonics of the last period. It is written from the contact physics alone (each law's
slider is tracked by its own return map, :mod:`frirom._timeint_maps`; nothing from
:mod:`frirom.contact`, the AFT kernel or the solver is used), so that it is an independent
check of the HBM results.

Scheme: central differences with the damping term centred (explicit Newmark, gamma = 1/2,
beta = 0), ``x[n+1] = E1 (f_e - g) + E2 x[n] - E3 x[n-1]``. It is second order in the step
and needs one contact-force evaluation per step; it is stable for omega_max dt < 2 where
omega_max is the highest natural frequency with every contact stuck and closed. The
return maps are exact for a monotone relative displacement within a step, so the only
error at stick/slip and contact/lift-off transitions is that of locating the kink to
within a step. The step count per period is raised automatically so that omega_max dt
<= ``max_phase_step``.

``method="implicit"`` (:mod:`frirom.timeint_implicit`) integrates with HHT-alpha instead:
a fixed number of steps per period whatever the highest mode, Newton on the contact
coordinates each step, the same return maps. Use it on reduced FE models, whose highest
mode is hundreds to thousands of times the forcing frequency (the explicit step count
grows in proportion: 3874 steps per period on the coarse lap joint, 128 implicit ones
reach 3e-3 in amplitude, cases/bench/timeint.py). On small lumped models the explicit
scheme is faster per step (one force evaluation, no Newton): ``method="auto"`` (the
default) takes it unless it needs more than AUTO_IMPLICIT times ``steps_per_period`` steps. Step
error: both are second order; the frequency of a resolved mode shifts by (2 pi / N)^2 / 24
(explicit) and about (2 pi / N)^2 / 12 (implicit) relatively, N steps per period.

Many forcing frequencies are integrated at once (the leading batch axis of every array):
the per-step Python cost is shared, so a sweep of 100 frequencies costs little more than
one. Only small dense models are meant (lumped test structures, reduced models).

Contact laws (parameters per element, in the order of the ``params`` columns; forces are
those the element exerts against the relative displacement):

``jenkins``  (1 direction u; kt, mu, fn0; 1 slider)  elastic Coulomb, constant normal load
``normal1d`` (u, v; kt, kn, mu, n0; 1 slider)  f_n = max(n0 + kn v, 0), tangential limit
             mu f_n; in lift-off the tangential spring relaxes (slider follows u)
``normal2d`` (u1, u2, v; kt, kn, mu, n0; 2 sliders)  circular friction limit
``cubic``    (u; k1, k3; no slider)  f = k1 u + k3 u^3
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from ._errors import InputError
from ._timeint_maps import _forces, period_change
from .contact import LAWS
from .timeint_implicit import integrate_implicit

#: ``method="auto"`` integrates implicitly when the explicit scheme needs more than this
#: times ``steps_per_period`` steps. An implicit step costs 4 to 7 times an explicit one
#: (Jenkins SDOF, normal1d 3-DoF, reduced lap joint), and at the same steps per period it
#: locates friction transitions less well: on the NLvib friction beam in micro-slip
#: (explicit 8 518 steps per period, 0.16 % from HB) the implicit scheme is 1.0 % off at
#: 512 steps and 0.09 % at 2 048; 32 keeps such models explicit and reduced FE models
#: (highest mode 300 to 3 000 times the forcing) implicit.
AUTO_IMPLICIT = 32

__all__ = ["TimeContact", "TimeResult", "integrate", "harmonics_from_samples",
           "state_from_harmonics"]



@dataclass
class TimeContact:
    """One group of contact elements of the same law.

    law: one of :data:`frirom.contact.LAWS`; G: (n_elem*n_dir, n_dof) dense or sparse, row
    e*n_dir + d gives local relative displacement d of element e; params: (n_elem, n_par);
    w0: (n_elem, n_slider) initial slider positions (default 0: spring unstretched at zero
    relative displacement).
    """

    law: str
    G: np.ndarray
    params: np.ndarray
    w0: np.ndarray | None = None
    name: str = ""

    def __post_init__(self):
        if self.law not in LAWS:
            raise InputError(f"timeint: unknown contact law {self.law!r}; expected one of "
                             f"{sorted(LAWS)}")
        law = LAWS[self.law]
        if law.code < 0:
            raise InputError(f"timeint: contact {self.name!r}: law {self.law!r} is a user "
                             f"law; time integration takes the built-in laws only")
        ndir, npar, nsl = law.n_dir, len(law.parameters), law.n_slider
        G = self.G.toarray() if hasattr(self.G, "toarray") else np.asarray(self.G, float)
        params = np.atleast_2d(np.asarray(self.params, float))
        if G.ndim != 2 or G.shape[0] % ndir:
            raise InputError(f"timeint: contact {self.name!r}: G must have n_elem*{ndir} "
                             f"rows for law {self.law!r}, got shape {G.shape}")
        ne = G.shape[0] // ndir
        if params.shape != (ne, npar):
            raise InputError(f"timeint: contact {self.name!r}: params must be ({ne}, {npar})"
                             f", got {params.shape}")
        if not np.all(np.isfinite(params)):
            raise InputError(f"timeint: contact {self.name!r}: non-finite parameter")
        if self.w0 is None:
            w0 = np.zeros((ne, nsl))
        else:
            w0 = np.asarray(self.w0, float).reshape(ne, nsl)
        self.G, self.params, self.w0 = G, params, w0

    @property
    def n_elem(self) -> int:
        return self.G.shape[0] // LAWS[self.law].n_dir

    def stuck_stiffness(self) -> np.ndarray:
        """(n_dof, n_dof) stiffness the group adds when every element sticks and is closed."""
        ndir = LAWS[self.law].n_dir
        p = self.params
        if self.law == "jenkins":
            k = p[:, [0]]
        elif self.law == "iwan":
            k = p[:, 0::2].sum(axis=1, keepdims=True)
        elif self.law == "iwan4":
            k = p[:, [1]]
        elif self.law == "normal1d":
            k = p[:, [0, 1]]
        elif self.law == "normal2d":
            k = p[:, [0, 0, 1]]
        else:
            k = p[:, [0]]
        k = np.abs(k).reshape(-1)
        assert k.size == self.G.shape[0] and ndir >= 1
        return self.G.T @ (k[:, None] * self.G)


@dataclass
class TimeResult:
    """Steady-state response from :func:`integrate` (batch axis first).

    omega (nb,) rad/s; harmonics (nb, n_dof, 2H+1) real coefficients [a0, a1, b1, ...] of
    the last period, x(tau) = a0 + sum a_h cos(h tau) + b_h sin(h tau), tau = omega t;
    amp_max (nb, n_dof) max |x(t)| over the last period; samples (nb, N, n_dof) the last
    period at tau_k = 2 pi k / N; drift (nb,) max change between the last two periods
    relative to the amplitude; periods: periods integrated; state_fractions
    (nb, n_groups, 3) stick/slip/lift-off sample fractions over the last period (all
    elements of a group pooled); x, x_prev, v, w: final state (see :meth:`restart`);
    method: the scheme used, "explicit" or "implicit".
    """

    omega: np.ndarray
    harmonics: np.ndarray
    amp_max: np.ndarray
    samples: np.ndarray
    drift: np.ndarray
    periods: int
    steps_per_period: int
    state_fractions: np.ndarray
    x: np.ndarray = field(repr=False)
    x_prev: np.ndarray = field(repr=False)
    v: np.ndarray = field(repr=False)
    w: list = field(repr=False)
    method: str = "explicit"

    def restart(self) -> dict:
        """Keyword arguments x0, v0, w0 of :func:`integrate` continuing from the end state
        (v is the backward difference: first-order, good enough as a start)."""
        return {"x0": self.x, "v0": self.v, "w0": self.w}


def harmonics_from_samples(samples: np.ndarray, H: int) -> np.ndarray:
    """Real harmonic coefficients of one period sampled uniformly along the last-but-one
    axis: samples (..., N, n) -> (..., n, 2H+1) ordered [a0, a1, b1, ..., aH, bH]."""
    N = samples.shape[-2]
    if N < 2 * H + 1:
        raise InputError(f"timeint: {N} samples per period cannot resolve H = {H}")
    Xf = np.fft.rfft(samples, axis=-2) / N
    out = np.empty(samples.shape[:-2] + (samples.shape[-1], 2 * H + 1))
    out[..., 0] = Xf[..., 0, :].real
    for h in range(1, H + 1):
        out[..., 2 * h - 1] = 2.0 * Xf[..., h, :].real
        out[..., 2 * h] = -2.0 * Xf[..., h, :].imag
    return out


def state_from_harmonics(coef: np.ndarray, omega) -> tuple[np.ndarray, np.ndarray]:
    """Displacement and velocity at tau = 0 of x(tau) = a0 + sum a_h cos + b_h sin.

    coef (..., n, 2H+1); omega rad/s (scalar or broadcastable to coef[..., 0, 0]).
    Returns x0, v0 of shape (..., n)."""
    coef = np.asarray(coef, float)
    H = (coef.shape[-1] - 1) // 2
    h = np.arange(1, H + 1)
    x0 = coef[..., 0] + coef[..., 1::2].sum(axis=-1)
    v0 = np.asarray(omega, float)[..., None] * (h * coef[..., 2::2]).sum(axis=-1)
    return x0, v0


def _as_dense(A, name):
    A = A.toarray() if hasattr(A, "toarray") else np.asarray(A, float)
    if A.ndim != 2 or A.shape[0] != A.shape[1]:
        raise InputError(f"timeint: {name} must be square, got shape {A.shape}")
    if not np.all(np.isfinite(A)):
        raise InputError(f"timeint: {name} has non-finite entries")
    return A


def integrate(M, C, K, contacts, F, omega, *, H: int = 5, periods: int = 200,
              min_periods: int = 5, steps_per_period: int = 512,
              max_phase_step: float = 0.5, tol: float = 1e-7, x0=None, v0=None,
              w0=None, method: str = "auto", alpha: float = -0.05) -> TimeResult:
    """Integrate to a periodic steady state at each forcing frequency of ``omega``.

    M, C, K: (n, n); contacts: list of :class:`TimeContact`; F: complex (n, H_F+1) with
    f_e(t) = Re sum_h F[:, h] exp(i h omega t) (column 0 a static load); omega: scalar or
    (nb,) rad/s. Integration stops when the largest change of x between two consecutive
    periods, relative to max |x|, is below ``tol`` at every frequency (after
    ``min_periods``), or after ``periods`` periods. x0, v0: (n,) or (nb, n) initial
    displacement and velocity (default rest); w0: list (one per group) of (n_elem,
    n_slider) or (nb, n_elem, n_slider) initial sliders (default each group's ``w0``).

    method: ``"explicit"`` (central differences, the step count raised until omega_max dt
    <= ``max_phase_step``: impractical on reduced FE models whose highest mode is far above
    the forcing), ``"implicit"`` (HHT-alpha with Newton on the contact coordinates,
    :mod:`frirom.timeint_implicit`: ``steps_per_period`` steps whatever the model's highest
    mode; ``max_phase_step`` is not used) or ``"auto"`` (explicit unless it needs more
    than AUTO_IMPLICIT times ``steps_per_period`` steps: see there). alpha: the HHT parameter in [-1/3, 0] (implicit
    only; 0 is Newmark's average acceleration). Both are second order: the frequency of a
    resolved mode is shifted by ~(2 pi / N)^2 / 24 (explicit) or ~(2 pi / N)^2 / 12
    (implicit) relatively, N = steps per period.
    """
    if method not in ("auto", "explicit", "implicit"):
        raise InputError(f"timeint: method = {method!r}; expected 'auto', 'explicit' or "
                         f"'implicit'")
    M, C, K = _as_dense(M, "M"), _as_dense(C, "C"), _as_dense(K, "K")
    n = M.shape[0]
    if C.shape != (n, n) or K.shape != (n, n):
        raise InputError("timeint: M, C and K must have the same shape")
    F = np.asarray(F, complex)
    if F.ndim == 1:
        F = F[:, None]
    if F.shape[0] != n:
        raise InputError(f"timeint: F must have {n} rows, got {F.shape}")
    omega = np.atleast_1d(np.asarray(omega, float))
    if omega.ndim != 1 or np.any(~np.isfinite(omega)) or np.any(omega <= 0.0):
        raise InputError("timeint: omega must be positive and finite")
    nb = omega.size
    for c in contacts:
        if c.G.shape[1] != n:
            raise InputError(f"timeint: contact {c.name!r}: G has {c.G.shape[1]} columns, "
                             f"the model {n} DoFs")

    if method != "implicit":
        # explicit step count: omega_max dt <= max_phase_step, contacts stuck and closed
        Kstuck = K + sum((c.stuck_stiffness() for c in contacts), np.zeros((n, n)))
        wmax = np.sqrt(max(scipy.linalg.eigvalsh(Kstuck, M).max(), 0.0))
        need = int(np.ceil(2.0 * np.pi * wmax / (omega.min() * max_phase_step)))
        if method == "auto":
            method = "implicit" if need > AUTO_IMPLICIT * steps_per_period else "explicit"
    if method == "implicit":
        return _run_implicit(M, C, K, contacts, F, omega, H=H, periods=periods,
                             min_periods=min_periods, steps_per_period=steps_per_period,
                             tol=tol, x0=x0, v0=v0, w0=w0, alpha=alpha)

    N = max(int(steps_per_period), need, 4 * H + 4)
    N += N % 2
    dt = 2.0 * np.pi / (omega * N)                              # (nb,)

    # per-frequency step matrices: x+ = E1 (f - g) + E2 x - E3 x-
    E = np.empty((nb, n, 3 * n))
    for i, h in enumerate(dt):
        D = M + 0.5 * h * C
        lu = scipy.linalg.lu_factor(D)
        E[i, :, :n] = scipy.linalg.lu_solve(lu, h * h * np.eye(n))
        E[i, :, n:2 * n] = scipy.linalg.lu_solve(lu, 2.0 * M - h * h * K)
        E[i, :, 2 * n:] = -scipy.linalg.lu_solve(lu, M - 0.5 * h * C)
    ET = np.ascontiguousarray(np.transpose(E, (0, 2, 1)))       # (nb, 3n, n)

    # external force over one period (same in tau for every frequency)
    fe = _external(F)(2.0 * np.pi * np.arange(N) / N)           # (N, n)

    groups = []
    for c, w in zip(contacts, _start_sliders(contacts, w0, nb)):
        p = [c.params[:, j] for j in range(c.params.shape[1])]
        groups.append([c.law, c.G.T.copy(), c.G.copy(), p, LAWS[c.law].n_dir, w])

    def contact_force(x):
        g = np.zeros_like(x)
        for law, GT, G, p, ndir, w in groups:
            f, _, _ = _forces(law, p, (x @ GT).reshape(nb, -1, ndir), w)
            g += f.reshape(nb, -1) @ G
        return g

    x = np.zeros((nb, n)) if x0 is None else np.broadcast_to(x0, (nb, n)).astype(float)
    v = np.zeros((nb, n)) if v0 is None else np.broadcast_to(v0, (nb, n)).astype(float)
    # x[-1] from a Taylor step backwards, with the initial acceleration
    g = contact_force(x)
    rhs = fe[0] - x @ K.T - v @ C.T - g
    a = np.linalg.solve(M, rhs.T).T
    x_prev = x - dt[:, None] * v + 0.5 * (dt ** 2)[:, None] * a

    last = np.empty((nb, N, n))
    states = [np.empty((N, nb, c.n_elem), np.int8) for c in contacts]
    prev = None
    drift = np.full(nb, np.inf)
    stack = np.empty((nb, 3 * n))
    sl_f, sl_x, sl_p = slice(0, n), slice(n, 2 * n), slice(2 * n, 3 * n)
    n_done = 0
    for period in range(int(periods)):
        for k in range(N):
            last[:, k] = x
            g = np.zeros((nb, n))
            for gi, grp in enumerate(groups):
                law, GT, G, p, ndir, w = grp
                f, grp[5], states[gi][k] = _forces(law, p, (x @ GT).reshape(nb, -1, ndir), w)
                g += f.reshape(nb, -1) @ G
            np.subtract(fe[k], g, out=stack[:, sl_f])
            stack[:, sl_x] = x
            stack[:, sl_p] = x_prev
            x_prev, x = x, np.matmul(stack[:, None, :], ET)[:, 0]
        n_done = period + 1
        drift, done = period_change(last, prev, n_done >= min_periods, tol)
        if done:
            break
        prev = last.copy()
    v_end = (x - x_prev) / dt[:, None]
    return _result(omega, H, last, drift, n_done, N, states, x, x_prev, v_end,
                   [gr[5] for gr in groups])


def _external(F):
    """f_e at phases tau: tau (k,) -> (k, n), f_e = Re sum_h F[:, h] exp(i h tau)."""
    hF = np.arange(F.shape[1])
    return lambda tau: (np.exp(1j * np.outer(tau, hF)) @ F.T).real


def _start_sliders(contacts, w0, nb):
    """Initial sliders per group, (nb, n_elem, n_slider): ``w0[g]`` or the group's own."""
    out = []
    for gi, c in enumerate(contacts):
        shape = (nb, c.n_elem, LAWS[c.law].n_slider)
        given = w0 is not None and w0[gi] is not None
        out.append(np.broadcast_to(np.asarray(w0[gi], float) if given else c.w0,
                                   shape).copy())
    return out


def _result(omega, H, last, drift, n_done, N, states, x, x_prev, v, w,
            method="explicit") -> TimeResult:
    """TimeResult of the last period ``last`` (nb, N, n) and the states per group."""
    nb = omega.size
    fractions = (np.stack([np.stack([(st == j).mean(axis=(0, 2)) for j in range(3)], -1)
                           for st in states], axis=1) if states else np.zeros((nb, 0, 3)))
    return TimeResult(omega=omega, harmonics=harmonics_from_samples(last, H),
                      amp_max=np.abs(last).max(axis=1), samples=last, drift=drift,
                      periods=n_done, steps_per_period=N, state_fractions=fractions,
                      x=x, x_prev=x_prev, v=v, w=w, method=method)


def _run_implicit(M, C, K, contacts, F, omega, *, H, periods, min_periods,
                  steps_per_period, tol, x0, v0, w0, alpha) -> TimeResult:
    """integrate(..., method="implicit"): see :mod:`frirom.timeint_implicit`."""
    n, nb = M.shape[0], omega.size
    N = max(int(steps_per_period), 4 * H + 4)
    N += N % 2
    x = np.zeros((nb, n)) if x0 is None else np.broadcast_to(x0, (nb, n)).astype(float)
    v = np.zeros((nb, n)) if v0 is None else np.broadcast_to(v0, (nb, n)).astype(float)
    last, drift, n_done, states, x, x_prev, v, w = integrate_implicit(
        M, C, K, contacts, _external(F), omega, N=N, alpha=alpha, periods=periods,
        min_periods=min_periods, tol=tol, x0=x, v0=v,
        w_start=_start_sliders(contacts, w0, nb))
    return _result(omega, H, last, drift, n_done, N, states, x, x_prev, v, w, "implicit")
