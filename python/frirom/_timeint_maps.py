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
    raise InputError(f"timeint: unknown law {law!r}")


def period_change(last, prev, may_stop: bool, tol: float):
    """(drift (nb,), stop): largest change of x between the periods ``prev`` and ``last``
    (nb, N, n) relative to max |x| (inf without ``prev``), and whether every frequency is
    below ``tol`` while ``may_stop``."""
    if prev is None:
        return np.full(last.shape[0], np.inf), False
    scale = np.maximum(np.abs(last).max(axis=(1, 2)), 1e-300)
    drift = np.abs(last - prev).max(axis=(1, 2)) / scale
    return drift, bool(may_stop and np.all(drift < tol))
