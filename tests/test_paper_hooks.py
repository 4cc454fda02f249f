"""The vane segment with hook joints (cases/paper_hooks, paper section 3.2.1), coarse mesh.

ROM_I (Craig-Bampton, every hook DoF nonlinear) is the reference; ROM_II reduces the hooks
by GSI modes (half free, half full-stick). Both run on the same cyclic sector (Tran modes
on the boundary), so their difference is the interface reduction alone. Needs gmsh-free
structured meshing and ccx (calculix-ccx); about 20 s, hence slow.
"""

from __future__ import annotations

import shutil
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "cases" / "paper_hooks"))

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(shutil.which("ccx") is None, reason="needs ccx")]

#: the preload with the most slip in the coarse family (42 % of the hooks' cycle at the
#: peak): where the interface modes are tested hardest
F0 = 1000.0


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    import make_paper_hooks as mk
    work = tmp_path_factory.mktemp("hooks")
    mk.make(work, "coarse")
    return work


def _peak(rom, f0):
    import paper_hooks as ph
    rom.set_preload(f0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # an early stop is a failure here
        res, _ = rom.frf()
    assert res.complete
    return ph._peak(res), res


def test_rom1_stuck_peak_is_the_stick_eigenfrequency(case):
    """With a preload that keeps every hook stuck, ROM_I is linear: its peak lies at the
    first nodal-diameter-2 frequency of the sector with the hooks tied by their stick
    springs (an eigen-solve of the projected pair, independent of the HBM). Tolerance
    1e-4: the 0.3 % modal damping shifts the peak by zeta^2 ~ 1e-5, continuation and the
    peak refinement stay below 1e-5."""
    import paper_hooks as ph
    import scipy.linalg as sla
    r1 = ph.Rom(case, "rom1", "coarse")
    (f, a), res = _peak(r1, 1e5)
    assert res.state_fractions[res.peak(0).index, 0, 0] == pytest.approx(1.0)
    red, cs = r1.deck.reduced, r1.deck.cyclic["sector"]
    G = red.contact_matrix("hooks").toarray()
    k = red.pairs["hooks"].stiffness.ravel()
    Ks = red.K + G.T @ (k[:, None] * G)
    kk = r1.model.harmonic_index(1)
    Kk, Mk = cs.matrices(Ks, red.M, kk)
    lam = sla.eigh(Kk.toarray(), Mk.toarray(), eigvals_only=True, subset_by_index=[0, 0])
    assert f == pytest.approx(np.sqrt(lam[0]) / (2 * np.pi), rel=1e-4)


def test_gsi_error_decreases_with_modes_and_rom2_matches(case):
    """ROM_II against ROM_I at the preload with the most slip: the peak-frequency error
    falls with every step 4 -> 10 -> 20 -> 40 GSI modes, the peak-amplitude error of 40
    modes is below those of 4, 10 and 20, and 40 modes (20 free + 20 stick, the paper's
    ROM_II) are within the issue's targets: 1 % in peak amplitude, 0.1 % in peak
    frequency (measured: 0.08 %, 0.006 %)."""
    import paper_hooks as ph
    (f1, a1), _ = _peak(ph.Rom(case, "rom1", "coarse"), F0)
    errs = {}
    for n in (4, 10, 20, 40):
        (f2, a2), _ = _peak(ph.Rom(case, "rom2", "coarse", n), F0)
        errs[n] = (abs(a2 / a1 - 1), abs(f2 / f1 - 1))
    df = [errs[n][1] for n in (4, 10, 20, 40)]
    assert all(b < a for a, b in zip(df, df[1:])), errs
    assert errs[40][0] < min(errs[n][0] for n in (4, 10, 20)), errs
    assert errs[40][0] < 0.01 and errs[40][1] < 0.001, errs
