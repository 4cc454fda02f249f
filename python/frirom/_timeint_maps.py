"""The time integrations' own contact return maps and their periodicity test, shared by
the explicit scheme (:mod:`frirom.timeint`) and the implicit one
(:mod:`frirom.timeint_implicit`). Written from the contact physics alone (each law's slider
tracked by its own return map; nothing from :mod:`frirom.contact`, the AFT kernel or the
solver), so that the time integrations are an independent check of the HBM results.
"""

from __future__ import annotations

import numpy as np

from ._errors import InputError


def _forces(law: str, p: list, u: np.ndarray, w: np.ndarray):
    """Contact forces and updated sliders for a batch.

    u: (nb, ne, ndir) local relative displacements; w: (nb, ne, nslider).
    Returns f (nb, ne, ndir), w_new, state (nb, ne) int: 0 stick, 1 slip, 2 lift-off.
    """
    if law == "cubic":
        k1, k3 = p
        x = u[..., 0]
        f = (k1 * x + k3 * x ** 3)[..., None]
        return f, w, np.zeros(x.shape, dtype=np.int8)
    if law == "jenkins":
        kt, mu, fn0 = p
        x = u[..., 0]
        limit = mu * fn0
        trial = kt * (x - w[..., 0])
        slip = np.abs(trial) > limit
        ft = np.where(slip, np.sign(trial) * limit, trial)
        w_new = np.where(slip, x - ft / kt, w[..., 0])[..., None]
        return ft[..., None], w_new, slip.astype(np.int8)
    if law == "normal1d":
        kt, kn, mu, n0 = p
        x, v = u[..., 0], u[..., 1]
        fn = np.maximum(n0 + kn * v, 0.0)
        limit = mu * fn
        trial = kt * (x - w[..., 0])
        slip = np.abs(trial) > limit
        ft = np.where(slip, np.sign(trial) * limit, trial)
        w_new = np.where(slip, x - ft / kt, w[..., 0])[..., None]
        state = np.where(fn <= 0.0, 2, slip.astype(np.int8)).astype(np.int8)
        return np.stack([ft, fn], axis=-1), w_new, state
    if law == "normal2d":
        kt, kn, mu, n0 = p
        x, v = u[..., :2], u[..., 2]
        fn = np.maximum(n0 + kn * v, 0.0)
        limit = mu * fn
        trial = kt[..., None] * (x - w)
        norm = np.sqrt(np.sum(trial ** 2, axis=-1))
        slip = norm > limit
        scale = np.where(slip, limit / np.where(norm > 0.0, norm, 1.0), 1.0)
        ft = trial * scale[..., None]
        w_new = np.where(slip[..., None], x - ft / kt[..., None], w)
        state = np.where(fn <= 0.0, 2, slip.astype(np.int8)).astype(np.int8)
        return np.concatenate([ft, fn[..., None]], axis=-1), w_new, state
    if law in ("iwan", "iwan4"):
        k, fs = _iwan_sliders(law, p)           # (ne, nslider)
        x = u[..., 0][..., None]                # (nb, ne, 1)
        used = k > 0.0
        trial = k * (x - w)
        slip = np.abs(trial) > fs
        fj = np.where(slip, np.sign(trial) * fs, trial)
        w_new = np.where(slip & used, x - fj / np.where(used, k, 1.0), w)
        return fj.sum(axis=-1)[..., None], w_new, (slip & used).any(axis=-1).astype(np.int8)
    raise InputError(f"timeint: unknown law {law!r}")


def _iwan_sliders(law: str, p: list):
    """(k, fs), each (ne, nslider): the Jenkins sliders of Iwan elements.

    iwan: the given pairs. iwan4 (Segalman's density R phi^chi on (0, phi_max) plus
    S delta(phi - phi_max)): 30 geometric bins phi_max 10^(-3 (30 - i)/29), each a slider
    with the bin's moments int rho and int rho phi, and the Dirac slider (S, S phi_max).
    """
    if law == "iwan":
        return np.stack(p[0::2], axis=-1), np.stack(p[1::2], axis=-1)
    fsm, ktm, chi, beta = (np.asarray(a, float)[:, None] for a in p)
    den = beta + (chi + 1.0) / (chi + 2.0)
    phimax = fsm * (1.0 + beta) / (ktm * den)
    r = fsm * (chi + 1.0) / (phimax ** (chi + 2.0) * den)
    s = fsm * beta / (phimax * den)
    nb = 30
    edges = phimax * np.concatenate([[0.0], 10.0 ** (-3.0 * (nb - np.arange(1, nb + 1))
                                                    / (nb - 1))])[None, :]
    a, b = edges[:, :-1], edges[:, 1:]
    k = r * (b ** (chi + 1.0) - a ** (chi + 1.0)) / (chi + 1.0)
    fs = r * (b ** (chi + 2.0) - a ** (chi + 2.0)) / (chi + 2.0)
    return np.concatenate([k, s], axis=1), np.concatenate([fs, s * phimax], axis=1)


def period_change(last, prev, may_stop: bool, tol: float):
    """(drift (nb,), stop): largest change of x between the periods ``prev`` and ``last``
    (nb, N, n) relative to max |x| (inf without ``prev``), and whether every frequency is
    below ``tol`` while ``may_stop``."""
    if prev is None:
        return np.full(last.shape[0], np.inf), False
    scale = np.maximum(np.abs(last).max(axis=(1, 2)), 1e-300)
    drift = np.abs(last - prev).max(axis=(1, 2)) / scale
    return drift, bool(may_stop and np.all(drift < tol))
