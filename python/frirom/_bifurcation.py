"""What a bifurcation of a curve is (FRF.bifurcations): a leaf that results (which stores
and loads them) and _fold (which finds and locates them) both read."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Bifurcation:
    """A bifurcation of the curve (FRF.bifurcations).

    kind: 'fold' (a turning point in the parameter), 'ns_or_pd' (a Floquet exponent
    crossed the imaginary axis away from 0: Neimark-Sacker or period doubling);
    omega (rad/s), parameter: where it is (a fold: located on the curve; 'ns_or_pd': the
    midpoint of the bracketing points); amp_max (n_out,): the outputs' max over the period
    there; index: the point after it (it lies between points index - 1 and index);
    located: True where solved on the curve (t_lam: the parameter part of the tangent
    there, 0 at the fold), False where only bracketed.
    """

    kind: str
    omega: float
    parameter: float
    amp_max: np.ndarray
    index: int
    located: bool = False
    t_lam: float = float("nan")
    solves: int = 0
