"""Implicit time integration (HHT-alpha) for :func:`frirom.timeint.integrate`.

Integrates the same equations as :mod:`frirom.timeint`,

    M x'' + C x' + K x + G^T f(G x, w) = f_e(t),

with the Hilber-Hughes-Taylor alpha scheme (alpha in [-1/3, 0]; Newmark beta = (1 - alpha)^2
/ 4, gamma = 1/2 - alpha): at every step

    M a[n+1] + (1 + alpha) (C v + K x + g)[n+1] - alpha (C v + K x + g)[n] = f_e(t[n+1+alpha]).

Why HHT and not Newmark's average acceleration (alpha = 0): reduced FE models keep modes
thousands of times above the forcing frequency, which the contact kinks excite every
period. Average acceleration does not damp them (spectral radius 1 as omega dt -> inf), so
they ring through the period-to-period change and the steady state is never declared. HHT
damps them (spectral radius (1 + alpha) / (1 - alpha) per step at omega dt -> inf, 0.905 for
the default alpha = -0.05) while it stays second order and unconditionally stable; its
damping of the resolved modes is third order in omega dt, negligible next to any physical
damping at the step counts used (see :func:`algorithmic_properties`).

Accuracy: both schemes shift the frequency of a resolved mode by O((omega dt)^2) =
O((2 pi / N)^2) relatively, N steps per period (Newmark average acceleration: (omega
dt)^2 / 12; HHT with alpha = -0.05 about the same), e.g. 5e-5 at N = 256 and 1.3e-5 at
N = 512. Near a resonance of damping ratio zeta, the amplitude error is of the order of that
shift divided by zeta on the flanks and second order in it at the peak.

The linear part is factorised once per frequency (the effective stiffness K_eff = M /
(beta dt^2) + (1 + alpha) gamma / (beta dt) C + (1 + alpha) K is constant for a fixed step).
The contact forces act through G only, so each step solves a small nonlinear system in
contact coordinates z (the relative displacements u = G x, or the DoFs G touches, whichever
are fewer) by Newton's method,

    z - z_lin + (1 + alpha) W f(B z) = 0,     W = T K_eff^-1 G^T,

with the exact (generalised) Jacobian of the return maps. The return maps are those of
:func:`frirom._timeint_maps._forces` (the time integrations' own, not the HB code's): the
slider is updated from the step's start, exact for a monotone relative displacement within
the step. Newton converges in a finite number of iterations for the piecewise-linear laws
(jenkins, normal1d, normal2d in 1-D slip) once the stick/slip/lift-off states are right.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from ._errors import ConvergenceError, InputError
from ._timeint_maps import _forces, period_change  # the same return maps
from .contact import LAWS


def hht_coefficients(alpha: float) -> tuple[float, float]:
    """Newmark beta and gamma of the HHT scheme with this alpha (second order, A-stable)."""
    if not -1.0 / 3.0 <= alpha <= 0.0:
        raise InputError(f"timeint: alpha = {alpha!r} must lie in [-1/3, 0] (HHT)")
    return 0.25 * (1.0 - alpha) ** 2, 0.5 - alpha


def algorithmic_properties(alpha: float, omega_dt) -> tuple[np.ndarray, np.ndarray,
                                                            np.ndarray]:
    """Spectral radius, relative frequency error and algorithmic damping ratio of the HHT
    scheme on an undamped oscillator x'' + omega^2 x = 0 at the phase steps omega_dt."""
    beta, gamma = hht_coefficients(alpha)
    rho, dfreq, zeta = [], [], []
    for h in np.atleast_1d(np.asarray(omega_dt, float)):
        # state [x, v dt, a dt^2]; the step in matrix form L s[n+1] = R s[n]
        L = np.array([[1.0, 0.0, -beta], [0.0, 1.0, -gamma], [(1 + alpha) * h * h, 0.0, 1.0]])
        R = np.array([[1.0, 1.0, 0.5 - beta], [0.0, 1.0, 1.0 - gamma],
                      [alpha * h * h, 0.0, 0.0]])
        lam = np.linalg.eigvals(np.linalg.solve(L, R))
        rho.append(np.abs(lam).max())
        osc = lam[np.argmax(lam.imag)]
        if osc.imag <= 0.0:
            dfreq.append(np.nan)
            zeta.append(np.nan)
            continue
        s = np.log(osc)                          # = (-zeta + i sqrt(1 - zeta^2)) w dt
        wd = abs(s)
        dfreq.append(wd / h - 1.0)
        zeta.append(-s.real / wd)
    return np.array(rho), np.array(dfreq), np.array(zeta)


def _forces_and_tangent(law: str, p: list, u: np.ndarray, w: np.ndarray):
    """Forces, updated sliders, states (as :func:`frirom._timeint_maps._forces`) and the
    tangent D (nb, ne, ndir, ndir) = d f / d u of the return map from the sliders w."""
    f, w_new, state = _forces(law, p, u, w)
    nb, ne, nd = u.shape
    D = np.zeros((nb, ne, nd, nd))
    if law == "cubic":
        k1, k3 = p
        D[..., 0, 0] = k1 + 3.0 * k3 * u[..., 0] ** 2
    elif law == "jenkins":
        D[..., 0, 0] = np.where(state == 0, p[0], 0.0)
    elif law == "normal1d":
        kt, kn, mu, _ = p
        closed = state != 2
        D[..., 1, 1] = np.where(closed, kn, 0.0)
        D[..., 0, 0] = np.where(state == 0, kt, 0.0)
        D[..., 0, 1] = np.where(state == 1, np.sign(f[..., 0]) * mu * kn, 0.0)
    elif law == "normal2d":
        kt, kn, mu, _ = p
        closed = state != 2
        D[..., 2, 2] = np.where(closed, kn, 0.0)
        ft = f[..., :2]
        fn = f[..., 2]
        x = u[..., :2]
        trial_norm = np.sqrt(np.sum((kt[..., None] * (x - w)) ** 2, axis=-1))
        slip = state == 1
        nrm = np.sqrt(np.sum(ft ** 2, axis=-1))
        n = ft / np.where(nrm > 0.0, nrm, 1.0)[..., None]
        ratio = np.where(slip, mu * fn * kt / np.where(trial_norm > 0, trial_norm, 1.0), 0.0)
        eye = np.eye(2)
        stick = (state == 0)[..., None, None]
        Dtt = np.where(stick, kt[..., None, None] * eye,
                       ratio[..., None, None] * (eye - n[..., :, None] * n[..., None, :]))
        D[..., :2, :2] = Dtt
        D[..., :2, 2] = np.where(slip[..., None], (mu * kn)[..., None] * n, 0.0)
    else:
        raise InputError(f"timeint: unknown law {law!r}")
    return f, w_new, state, D


def integrate_implicit(M, C, K, contacts, fe_at, omega, *, N: int, alpha: float,
                       periods: int, min_periods: int, tol: float, x0, v0, w_start,
                       newton_tol: float = 1e-12, max_newton: int = 50, on_period=None):
    """The HHT-alpha march behind ``integrate(..., method="implicit")``.

    M, C, K: (n, n) dense; contacts: list of TimeContact; fe_at(tau) -> (len(tau), n) the
    external force at phases tau; omega (nb,) rad/s; N steps per period; x0, v0 (nb, n);
    w_start: list of (nb, n_elem, n_slider); on_period(k, samples): called after each
    period k = 1, 2, ... with its samples (nb, N, n). Returns (samples (nb, N, n), drift
    (nb,), periods done, states per group (N, nb, n_elem), x, x_prev, v, w list).
    """
    beta, gamma = hht_coefficients(alpha)
    n = M.shape[0]
    nb = omega.size
    c1 = 1.0 + alpha
    dt = 2.0 * np.pi / (omega * N)                              # (nb,)

    # contact coordinates: u = G x (all groups stacked), z = T x, u = B z
    Gs = [c.G for c in contacts]
    G = np.vstack(Gs) if Gs else np.zeros((0, n))
    m = G.shape[0]
    touched = np.flatnonzero(np.any(G != 0.0, axis=0))
    if touched.size < m:
        T_idx, B = touched, G[:, touched]
    else:
        T_idx, B = None, np.eye(m)
    k = B.shape[1]

    # per-frequency operators: x_lin = P [x; v; a] + Kinv (fe + alpha g_n),
    # x[n+1] = x_lin - (1 + alpha) Z f[n+1], Z = Kinv G^T
    P = np.empty((nb, 3 * n, n))
    Kinv = np.empty((nb, n, n))
    for i, h in enumerate(dt):
        if i and h == dt[i - 1]:        # a batch at one frequency: the same operators
            Kinv[i], P[i] = Kinv[i - 1], P[i - 1]
            continue
        Keff = M / (beta * h * h) + c1 * gamma / (beta * h) * C + c1 * K
        lu = scipy.linalg.lu_factor(Keff)
        Kinv[i] = scipy.linalg.lu_solve(lu, np.eye(n))
        # b = fe + alpha (C v + K x + g) + M xt / (beta h^2) + c1 C (gamma/(beta h) xt - vt)
        # xt = x + h v + h^2 (1/2 - beta) a, vt = v + h (1 - gamma) a
        cx = alpha * K + M / (beta * h * h) + c1 * gamma / (beta * h) * C
        cv = (alpha * C + M / (beta * h) + c1 * gamma / beta * C - c1 * C)
        ca = (M * (0.5 - beta) / beta + c1 * C * h * (gamma * (0.5 - beta) / beta
                                                      - (1.0 - gamma)))
        for j, A in enumerate((cx, cv, ca)):
            P[i, j * n:(j + 1) * n] = (Kinv[i] @ A).T
    Z = Kinv @ G.T                                               # (nb, n, m)
    W = Z[:, T_idx, :] if T_idx is not None else G @ Z            # (nb, k, m)
    # external force at t[n+1+alpha] for the step from tau_j, through Kinv
    tau = 2.0 * np.pi * (np.arange(N) + 1.0 + alpha) / N
    fe = fe_at(tau)                                              # (N, n)
    Y = np.einsum("bij,kj->bki", Kinv, fe)                       # (nb, N, n)

    groups = []
    row = 0
    for gi, c in enumerate(contacts):
        ndir = LAWS[c.law].n_dir
        rows = slice(row, row + c.G.shape[0])
        row += c.G.shape[0]
        groups.append((c.law, [c.params[:, j] for j in range(c.params.shape[1])], ndir,
                       rows, B[rows].reshape(c.n_elem, ndir, k)))
    w = [np.array(ws, float) for ws in w_start]
    # piecewise-linear laws: f is affine in z while the pattern (state and slip direction
    # of every element) stays, so a Newton step that keeps the pattern its Jacobian was
    # built with lands exactly on the solution
    by_pattern = all(c.law in _PIECEWISE_LINEAR for c in contacts)

    def contact(z, w):
        """f (nb, m), new sliders, states per group, pattern (nb, n_elem total)."""
        f = np.empty((nb, m))
        out_w, out_s, pat = [], [], []
        u = z @ B.T
        for (law, p, ndir, rows, _), wg in zip(groups, w):
            fg, wn, st = _forces(law, p, u[:, rows].reshape(nb, -1, ndir), wg)
            f[:, rows] = fg.reshape(nb, -1)
            out_w.append(wn)
            out_s.append(st)
            pat.append(st + 3 * (fg[..., 0] > 0.0))
        return f, out_w, out_s, np.concatenate(pat, axis=1) if pat else None

    def jacobian_inverse(z, w, pat):
        """(I + c1 W D B)^-1 (nb, k, k) at z from the sliders w; D from the pattern pat
        where the laws are piecewise linear."""
        DB = np.empty((nb, m, k))
        u = z @ B.T
        e0 = 0
        for (law, p, ndir, rows, Be), wg in zip(groups, w):
            ne = Be.shape[0]
            if by_pattern:
                D = _tangent_of_pattern(law, p, pat[:, e0:e0 + ne])
            else:
                D = _forces_and_tangent(law, p, u[:, rows].reshape(nb, -1, ndir), wg)[3]
            e0 += ne
            DB[:, rows] = np.matmul(D, Be).reshape(nb, -1, k)
        return np.linalg.inv(np.eye(k) + c1 * np.matmul(W, DB))

    def select(x):
        return x[:, T_idx] if T_idx is not None else x @ G.T

    x = x0.copy()
    v = v0.copy()
    f = contact(select(x), w)[0]
    rhs = fe_at(np.zeros(1))[0] - x @ K.T - v @ C.T - f @ G
    a = np.linalg.solve(M, rhs.T).T
    z_prev = z = select(x)
    x_prev = x
    Jinv, pat_J = None, None

    last = np.empty((nb, N, n))
    states = [np.empty((N, nb, c.n_elem), np.int8) for c in contacts]
    prev = None
    drift = np.full(nb, np.inf)
    s = np.empty((nb, 3 * n))
    dt2 = dt[:, None] ** 2
    n_done = 0
    for period in range(int(periods)):
        for j in range(N):
            last[:, j] = x
            s[:, :n], s[:, n:2 * n], s[:, 2 * n:] = x, v, a
            x_lin = np.matmul(s[:, None, :], P)[:, 0] + Y[:, j]
            if m:
                x_lin += alpha * np.matmul(Z, f[:, :, None])[:, :, 0]
                z_lin = select(x_lin)
                zt = 2.0 * z - z_prev                    # extrapolated start
                scale = np.abs(z_lin).max() + np.abs(z).max() + 1e-300
                fn, wn, st, pat = contact(zt, w)
                for it in range(max_newton):
                    if not by_pattern or pat_J is None or (pat != pat_J).any():
                        Jinv, pat_J = jacobian_inverse(zt, w, pat), pat
                    R = zt - z_lin + c1 * np.matmul(W, fn[:, :, None])[:, :, 0]
                    dz = np.matmul(Jinv, R[:, :, None])[:, :, 0]
                    zt = zt - dz
                    fn, wn, st, pat = contact(zt, w)
                    if ((by_pattern and not (pat != pat_J).any())
                            or np.abs(dz).max() <= newton_tol * scale):
                        break
                else:
                    raise ConvergenceError(
                        f"timeint: Newton on the contact coordinates did not converge in "
                        f"{max_newton} iterations (step {j} of period {period + 1}; last "
                        f"update {np.abs(dz).max():.3e}, scale {scale:.3e})")
                w = wn
                for gi in range(len(groups)):
                    states[gi][j] = st[gi]
                x_new = x_lin - c1 * np.matmul(Z, fn[:, :, None])[:, :, 0]
                f = fn
                z_prev, z = z, select(x_new)
            else:
                x_new = x_lin
            # Newmark: a[n+1] from x[n+1], then v[n+1]
            a_new = (x_new - x - dt[:, None] * v) / (beta * dt2) - (0.5 - beta) / beta * a
            v = v + dt[:, None] * ((1.0 - gamma) * a + gamma * a_new)
            a = a_new
            x_prev, x = x, x_new
        n_done = period + 1
        if on_period is not None:
            on_period(n_done, last)
        drift, done = period_change(last, prev, n_done >= min_periods, tol)
        if done:
            break
        prev = last.copy()
    return last, drift, n_done, states, x, x_prev, v, w


_PIECEWISE_LINEAR = ("jenkins", "normal1d")


def _tangent_of_pattern(law: str, p: list, pat: np.ndarray) -> np.ndarray:
    """d f / d u (nb, ne, ndir, ndir) of a piecewise-linear law from the pattern
    state + 3 (f_t > 0) (state 0 stick, 1 slip, 2 lift-off): the tangent of
    :func:`_forces_and_tangent` without evaluating the forces again."""
    state = pat % 3
    if law == "jenkins":
        return np.where(state == 0, p[0], 0.0)[..., None, None]
    kt, kn, mu, _ = p
    D = np.zeros(pat.shape + (2, 2))
    D[..., 0, 0] = np.where(state == 0, kt, 0.0)
    D[..., 1, 1] = np.where(state != 2, kn, 0.0)
    D[..., 0, 1] = np.where(state == 1, np.where(pat >= 3, mu * kn, -mu * kn), 0.0)
    return D
