"""End to end: cases/lap_joint through `frirom run` (gmsh + ccx matrices made here).

The case's deck (Craig-Bampton 20 modes, GSI interface reduction with 20 free + 20
full-stick modes, normal1d friction on every node pair of the overlap, bolt preload) is
checked against the same model without interface reduction (CB only: every contact pair
its own element on physical DoFs) through the first bending resonance, where the joint
slips over about half of the period at the peak.

Run small: a coarser mesh (element size 12 mm: 65 node pairs, 390 interface DoFs, the
preload per pair raised so that the bolt load stays 2.1 kN), H = 1, a 12 N shaker, 825-880
Hz. The paper (Sec. 3.2.1) finds the GSI-reduced nonlinear FRF on top of the unreduced one
with 40 GSI modes; measured here: 6e-4 in peak frequency and 4e-4 in peak amplitude, so
the bounds are 2e-3 and 2e-2, which 60 modes meet too (1e-4, 5e-3). Where GSI breaks
down: with 10 or 20 modes the joint opens over 35 % and 90 % of the period at the peak
(CB: 3 %) and the peak amplitude is 6x and 11x the CB one; asserted as more than 2x with
lift-off above 25 %.
At the case's own size and H = 3, cases/lap_joint/convergence.py gives the same study.
Slow (~25 s: the CB reference alone has 413 coordinates, 260 in contact).
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest

from _models import copy_job, small_lap_joint_deck
from frirom.cli import main
from frirom.deck import load_deck
from frirom.results import FRF


@pytest.fixture(scope="module")
def case(lap_joint_mesh, tmp_path_factory):
    """The coarse mesh in a folder of this module's own (its decks and reduced models)."""
    return copy_job(lap_joint_mesh, tmp_path_factory.mktemp("lap_case"))


def run(case, name, text, capsys, complete=True):
    """Peak frequency [Hz], amplitude, state fractions there and the log of a deck's run;
    complete=False accepts a curve that stopped early (the poor ROMs of the table: with
    GSI 20 the joint opens over ~90 % of the period and the H = 1, N = 16 curve folds back
    and forth until it leaves the range, depending on round-off in the reduction)."""
    (case / f"{name}.toml").write_text(text)
    code = main(["run", str(case / f"{name}.toml"), "--out", str(case / name), "--quiet"])
    r = FRF.load(case / name / "frf.h5")
    assert code == (0 if r.complete else 3)       # a run that stopped early exits 3
    assert r.complete or not complete, r.message
    i = int(np.argmax(r.amp_max[:, 0]))
    assert 0 < i < len(r) - 1                     # a peak inside the range
    return r.omega[i] / (2 * np.pi), r.amp_max[i, 0], r.state_fractions[i, 0], \
        capsys.readouterr().out


@pytest.mark.slow
def test_gsi_lap_joint_reuses_its_reduction_and_cb_agrees_at_its_peak(tmp_path, lap_joint_mesh,
                                                                      capsys):
    """The fast variant of the next test: the GSI-40 deck's reduction is built, `frirom
    run` after a change of friction coefficient reuses it, and the CB-only model (every
    contact pair on physical DoFs) solved at the GSI curve's peak frequency alone (one
    point, not its 133-point FRF) has the GSI peak amplitude within the next test's 2e-2
    (measured 2.3e-3) and the joint slipping there too."""
    from frirom.solver import solve_point
    case = copy_job(lap_joint_mesh, tmp_path)
    (case / "gsi.toml").write_text(small_lap_joint_deck(40))
    built = load_deck(case / "gsi.toml")
    assert not built.reduced.from_cache and "built" in built.log[0]
    no_plot = small_lap_joint_deck(40, mu="0.30000001").replace("[outputs]\n",
                                                                  "[outputs]\nplot = false\n")
    f_g, a_g, st, log = run(case, "gsi", no_plot, capsys)
    assert "not recomputed" in log, log
    (case / "cb.toml").write_text(small_lap_joint_deck(None))
    cb = load_deck(case / "cb.toml")
    p = solve_point(cb.model(), cb.excitation(), 2 * np.pi * f_g, cb.options(),
                    outputs=cb.outputs)
    assert abs(p.amp_max[0] / a_g - 1) < 2e-2, (p.amp_max[0], a_g)
    assert st[1] > 0.3 and p.state_fractions[0, 1] > 0.3          # slipping at the peak


@pytest.mark.slow
def test_gsi_lap_joint_matches_cb_and_reuses_its_reduction(case, capsys):
    (case / "gsi.toml").write_text(small_lap_joint_deck(40))
    built = load_deck(case / "gsi.toml")
    assert not built.reduced.from_cache and "built" in built.log[0]
    # `frirom run` after a change of friction coefficient: the reduction is reused
    f_g, a_g, st, log = run(case, "gsi", small_lap_joint_deck(40, mu="0.30000001"), capsys)
    assert "not recomputed" in log, log
    again = load_deck(case / "gsi.toml")
    assert again.reduced.from_cache
    assert np.array_equal(again.K, built.K) and np.array_equal(again.M, built.M)

    f_c, a_c, st_c, log_cb = run(case, "cb", small_lap_joint_deck(None), capsys)
    m_g, m_c = built.model(), load_deck(case / "cb.toml").model()
    rows = [(n, *run(case, f"gsi{n}", small_lap_joint_deck(n), capsys, complete=n > 20)[:3])
            for n in (10, 20, 60)]
    rows.insert(2, (40, f_g, a_g, st))
    with capsys.disabled():
        print(f"\nlap joint (65 pairs, H = 1): CB only {m_c.n_dof} coordinates, "
              f"{len(m_c.nonlinear_dofs())} contact DoFs; peak {f_c:.2f} Hz {a_c:.4e} m, "
              f"stick/slip/lift-off {np.round(st_c, 2)}")
        for n, f, a, s in rows:
            print(f"  GSI {n:3d} modes: peak {f:8.2f} Hz {a:.4e} m  df {f / f_c - 1:+.1e}  "
                  f"dA {a / a_c - 1:+.1e}  lift-off {s[2]:.2f}")
        print("  " + (log + log_cb).strip().replace("\n", "\n  "))
    assert len(m_g.nonlinear_dofs()) == 40 and m_g.contacts[0].n_elem == 65
    assert st[1] > 0.3 and st_c[1] > 0.3          # the joint slips at the peak
    for n, f, a, s in rows:
        if n >= 40:          # converged: on the CB curve
            assert abs(f / f_c - 1) < 2e-3, (n, f, f_c)
            assert abs(a / a_c - 1) < 2e-2, (n, a, a_c)
        else:                # too few modes: the joint opens, the amplitude is far off
            assert a > 2 * a_c and s[2] > 0.25, (n, a, a_c, s)
