"""The probes of the automatic choices (frirom.auto: harmonics, samples and interface
modes; frirom.auto_kept: the harmonics kept): a coarse run's largest-amplitude points and
their neighbours, the excitation cut to H harmonics, and the relative change of the
outputs between two solutions."""

from __future__ import annotations

import dataclasses

import numpy as np

from ._errors import ConvergenceError


def _first_harmonic(F: np.ndarray) -> int:
    """The smallest H: the highest loaded harmonic of F (n, H+1), at least 1."""
    return max([1] + [h for h in range(F.shape[1]) if np.any(F[:, h] != 0)])


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    """Largest |a - b| / |b| over the outputs whose amplitude is not negligible."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    keep = np.abs(b) > 1e-12 * max(np.max(np.abs(b)), 1e-300)
    return float(np.max(np.abs(a[keep] - b[keep]) / np.abs(b[keep]))) if keep.any() else 0.0


def _excitation(F: np.ndarray, H: int):
    from .model import Excitation
    G = np.zeros((F.shape[0], H + 1), complex)
    k = min(H + 1, F.shape[1])
    G[:, :k] = F[:, :k]
    return Excitation(G)


def _probes(model, F, omega_start, omega_end, opts, outputs, H0, notes) -> list:
    """The coarse run at H0: per output its largest-amplitude point and that point's
    neighbours on the curve (distinct omegas)."""
    from .solver import frf
    pts = []
    o = dataclasses.replace(opts, harmonics=H0, stability=False, refine_peak=False)
    r = frf(model, _excitation(F, H0), omega_start, omega_end, o, outputs=outputs,
            sink=pts.append)
    if not r.complete:
        notes.append(f"the coarse run at H = {H0} stopped ({r.message}); probes from the "
                     "points it made")
    if not pts:
        raise ConvergenceError(f"solver.harmonics = \"auto\": the coarse run at H = {H0} "
                               f"made no point ({r.message}); give integers")
    amp = np.array([p.amp_max for p in pts])
    out = []
    for j in range(amp.shape[1]):
        i = int(np.argmax(amp[:, j]))
        for p in pts[max(i - 1, 0):i + 2]:
            if all(abs(p.omega - q.omega) > 1e-9 * p.omega for q in out):
                out.append(p)
    return out
