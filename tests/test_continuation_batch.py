"""The continuation's path does not depend on `batch` (how many points each Fortran call
makes before Python takes them).

The arc-length scale of the unknowns grows with the solution after every point, in
Fortran (hbm_run), and a call that resumes a run factorises J at its start point as the
run that made the point held it. Before, the scale was only grown at call boundaries:
with a large batch it stayed at the first point's |y| while |y| grew tens of times near
the resonance, steps at ds_min moved the unknowns by corrector noise, and the run crawled
(the coarse hooks ROM_II at 300 N: 1 019 points against 77 with batch = 10) or, on the
paper mesh at 1 000 N, misread a contact-state corner as a fold and turned back.

Needs ccx (the coarse hooks sector, about 4 s to build).
"""

from __future__ import annotations

import dataclasses
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.skipif(shutil.which("ccx") is None, reason="needs ccx")


@pytest.mark.slow
def test_hooks_path_is_the_same_for_batch_10_and_1000(tmp_path):
    """Coarse hooks ROM_II at 300 N (40 % slip at the peak): batch = 1 000 (one call) and
    batch = 10 (a call boundary, with its checkpoint, every 10 points) make the same
    points. The same arithmetic in both, only split into calls differently, so the
    parameters, unknowns and peak agree to 1e-12 relative (not bit for bit only to leave
    room for the LU carried between calls, which this model does not use). max_points
    = 300 makes the crawl of the old scaling (1 019 points) a failure to complete."""
    import make_paper_hooks as mk
    import paper_hooks as ph
    from frirom.solver import frf
    mk.make(tmp_path, "coarse")
    rom = ph.Rom(tmp_path, "rom2", "coarse", 40)
    rom.set_preload(300.0)
    runs, pts = {}, {}
    for batch in (1000, 10):
        pts[batch] = []
        opts = dataclasses.replace(rom.options, batch=batch, max_points=300)
        with warnings.catch_warnings():
            warnings.simplefilter("error")          # an early stop is a failure here
            runs[batch] = frf(rom.model, rom.excitation, rom.deck.omega_start,
                              rom.deck.omega_end, opts, outputs=rom.deck.outputs,
                              sink=pts[batch].append)
    a, b = runs[1000], runs[10]
    assert a.complete and b.complete
    assert len(a) == len(b) < 150
    np.testing.assert_allclose(a.omega, b.omega, rtol=1e-12, atol=0)
    ya = np.array([p.unknowns for p in pts[1000]])
    yb = np.array([p.unknowns for p in pts[10]])
    assert np.abs(ya - yb).max() <= 1e-12 * np.abs(yb).max()
    assert a.peak().amplitude == pytest.approx(b.peak().amplitude, rel=1e-12)
    assert a.peak().omega == pytest.approx(b.peak().omega, rel=1e-12)
