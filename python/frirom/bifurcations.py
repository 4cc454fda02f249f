"""Folds followed in a second parameter: the fold locus (issue 30 item 3).

:func:`fold_locus` runs the frequency continuation (:func:`frirom.solver.frf`, the one
driver) at each level of a second parameter, the excitation level (the harmonics >= 1
of the excitation scaled) or the static load (harmonic 0: a normal preload, a damper's
load), and collects the folds each run located on its curve (frirom._fold: a secant on
the parameter part of the tangent, every sample a corrector of that run). The locus is
the fold frequencies and amplitudes against the level: where a design jumps, and the
level below which it does not (the folds meet in a cusp and vanish).

This follows the fold by located folds at given levels, not by continuation of the
extended system (R = 0, R_y v = 0) in two parameters: its points are as exact as the
folds of each run, the levels are the caller's.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ._errors import ParameterError
from .model import Excitation
from .options import SolverOptions
from .solver import frf


@dataclass
class FoldLocus:
    """Result of :func:`fold_locus`.

    levels (n_lvl,): the second parameter's values (factors on the scaled part);
    omega (n_lvl, n_max) rad/s, amp_max (n_lvl, n_max, n_out): the folds located at each
    level, in the order of the curve, NaN-padded to the most folds of any level;
    located (n_lvl, n_max) bool: solved on the curve (False: a flagged point, or no fold);
    complete (n_lvl,) bool: the run at that level covered the range; part: 'dynamic' or
    'static'.
    """

    levels: np.ndarray
    omega: np.ndarray
    amp_max: np.ndarray
    located: np.ndarray
    complete: np.ndarray
    part: str = "dynamic"
    messages: list = field(default_factory=list)

    @property
    def n_folds(self) -> np.ndarray:
        """(n_lvl,) folds found at each level."""
        return np.sum(np.isfinite(self.omega), axis=1)


def scaled_excitation(excitation: Excitation, level: float, part: str) -> Excitation:
    """The excitation with its part ('dynamic': harmonics >= 1; 'static': harmonic 0)
    multiplied by level."""
    F = np.array(excitation.F, complex)
    if part == "dynamic":
        F[:, 1:] *= level
    else:
        F[:, 0] *= level
    return Excitation(F)


def fold_locus(model, excitation: Excitation, omega_start: float, omega_end: float,
               levels, options: SolverOptions | None = None, outputs=None,
               part: str = "dynamic") -> FoldLocus:
    """Folds of the forced response from omega_start to omega_end (rad/s) at each level
    of the excitation part `part` ('dynamic': the excitation level; 'static': the static
    load such as a normal preload), levels (n_lvl,) factors on that part.

    Returns a :class:`FoldLocus`. A level whose run stops early keeps the folds it
    located (``complete`` False, its message in ``messages``)."""
    if part not in ("dynamic", "static"):
        raise ParameterError(f"part: expected 'dynamic' or 'static', got {part!r}")
    lv = np.atleast_1d(np.asarray(levels, float))
    if lv.ndim != 1 or lv.size == 0 or not np.all(np.isfinite(lv)):
        raise ParameterError("levels: expected a non-empty list of finite numbers")
    options = dataclasses.replace(options or SolverOptions(), parameter="frequency")
    found, complete, messages, n_out = [], [], [], 0
    for level in lv:
        r = frf(model, scaled_excitation(excitation, float(level), part), omega_start,
                omega_end, options, outputs=outputs)
        folds = [b for b in (r.bifurcations or []) if b.kind == "fold"]
        n_out = r.amp_max.shape[1] if r.amp_max.ndim == 2 else n_out
        found.append(folds)
        complete.append(r.complete)
        messages.append(r.message)
    n_max = max((len(f) for f in found), default=0)
    omega = np.full((lv.size, n_max), np.nan)
    amp = np.full((lv.size, n_max, n_out), np.nan)
    located = np.zeros((lv.size, n_max), bool)
    for i, folds in enumerate(found):
        for j, b in enumerate(folds):
            omega[i, j] = b.omega
            amp[i, j] = np.ravel(b.amp_max)
            located[i, j] = b.located
    return FoldLocus(lv, omega, amp, located, np.array(complete, bool), part, messages)
