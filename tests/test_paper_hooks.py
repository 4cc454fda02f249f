"""The vane segment with hook joints (cases/paper_hooks, paper section 3.2.1), coarse mesh.

ROM_I (Craig-Bampton, every contact DoF nonlinear) is the reference; ROM_II reduces the
hook and lug faces by GSI modes (half free, half full-stick). Both run on the same cyclic
sector (Tran modes on the boundary), so their difference is the interface reduction alone.
The interlocking lug is a preloaded contact; the same mesh with the lug tied is its
reference. Needs gmsh-free structured meshing and ccx (calculix-ccx). The FRFs take about
40 s, hence slow; the first-point check (one ROM_I, three points) runs in the fast loop.
"""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from _models import HOOKS_F0, hooks_peak

pytestmark = pytest.mark.skipif(shutil.which("ccx") is None, reason="needs ccx")


@pytest.fixture(scope="module")
def tied(tmp_path_factory):
    import make_paper_hooks as mk
    work = tmp_path_factory.mktemp("hooks_tied")
    mk.make(work, "coarse", interlock="tied")
    return work


@pytest.mark.slow
@pytest.mark.parametrize("law", ["normal1d", "normal2d"])
def test_rom1_stuck_peak_is_the_stick_eigenfrequency(hooks_case, law):
    """With a preload that keeps every hook stuck, ROM_I is linear: its peak lies at the
    first nodal-diameter-2 frequency of the sector with the hooks tied by their stick
    springs (an eigen-solve of the projected pair, independent of the HBM; normal2d
    springs in both tangents, normal1d in the circumferential one). Tolerance 1e-4: the
    0.3 % modal damping shifts the peak by zeta^2 ~ 1e-5, continuation and the peak
    refinement stay below 1e-5."""
    import paper_hooks as ph
    import scipy.linalg as sla
    r1 = ph.Rom(hooks_case, "rom1", "coarse", law=law)
    (f, a), res = hooks_peak(r1, 1e5)
    assert np.all(res.state_fractions[res.peak(0).index, :, 0] == pytest.approx(1.0))
    red, cs = r1.deck.reduced, r1.deck.cyclic["sector"]
    Ks = red.K.copy()
    for g in r1.groups:                 # the hooks and the lug, all stuck
        G = red.contact_matrix(g).toarray()
        k = red.pairs[g].stiffness.ravel()
        Ks = Ks + G.T @ (k[:, None] * G)
    kk = r1.model.harmonic_index(1)
    Kk, Mk = cs.matrices(Ks, red.M, kk)
    lam = sla.eigh(Kk.toarray(), Mk.toarray(), eigvals_only=True, subset_by_index=[0, 0])
    assert f == pytest.approx(np.sqrt(lam[0]) / (2 * np.pi), rel=1e-4)


@pytest.mark.slow
def test_contact_lug_stays_stuck_and_equals_the_tied_lug(hooks_case, tied):
    """The interlocking lug as a preloaded contact (F_LUG = 300 kN, mu 0.3) against the
    same mesh with the lug's face tied to the platform, ROM_I at the preload where the
    hooks slip most: the lug's groups stick at every time sample of every point of the
    FRF (the results' state fractions), and the peak equals the tied one within 1e-3 in
    amplitude and 1e-4 in frequency. Why so close: stuck, the lug is a spring of 2e11 N/m
    per pair, about 200 times the sector's stiffness at the lug (E x 6 mm ~ 1e9 N/m), so
    the stuck sector's frequency moves by 1e-6 (measured); through the hooks' friction,
    which amplifies it, the peak moves by 1e-4 in amplitude and 1e-6 in frequency
    (measured), and the soft mount is in both models."""
    import paper_hooks as ph
    rc, rt = ph.Rom(hooks_case, "rom1", "coarse"), ph.Rom(tied, "rom1", "coarse")
    assert [g for g in rc.groups if g.startswith("lug")] == ["lug_t", "lug_z"]
    assert rt.groups == ["hooks"]
    (fc, ac), res_c = hooks_peak(rc, HOOKS_F0)
    (ft, at), res_t = hooks_peak(rt, HOOKS_F0)
    assert ph.lug_stick(rc, res_c) == 1.0
    slip = res_c.state_fractions[:, rc._hooks, 1].max()
    assert slip > 0.3                   # the hooks do slip: the lug is loaded by it
    assert ac == pytest.approx(at, rel=1e-3)
    assert fc == pytest.approx(ft, rel=1e-4)


@pytest.mark.slow
def test_gsi_error_decreases_with_modes_and_rom2_matches(hooks_case):
    """ROM_II against ROM_I at the preload with the most slip: the peak-frequency error
    falls with every step 10 -> 20 -> 40 -> 80 GSI modes, the peak-amplitude error of 80
    modes is below those of 10, 20 and 40, and 80 modes (40 free + 40 stick) are within
    the issue's targets: 1 % in peak amplitude, 0.1 % in peak frequency (measured: 0.26 %,
    8e-6). The paper's 40 modes miss 1 % here (measured 1.8 %: the lug's 48 DoFs share the
    basis with the hooks'; with the lug tied, 40 modes are within 0.1 %); the case's table
    shows that row flagged."""
    import paper_hooks as ph
    (f1, a1), _ = hooks_peak(ph.Rom(hooks_case, "rom1", "coarse"), HOOKS_F0)
    errs = {}
    for n in (10, 20, 40, 80):
        r2 = ph.Rom(hooks_case, "rom2", "coarse", n, lug_reduction="shared")
        (f2, a2), _ = hooks_peak(r2, HOOKS_F0)
        errs[n] = (abs(a2 / a1 - 1), abs(f2 / f1 - 1))
    df = [errs[n][1] for n in (10, 20, 40, 80)]
    assert all(b < a for a, b in zip(df, df[1:])), errs
    assert errs[80][0] < min(errs[n][0] for n in (10, 20, 40)), errs
    assert errs[80][0] < 0.01 and errs[80][1] < 0.001, errs


@pytest.mark.slow
def test_normal2d_hooks_rom2_matches_rom1_with_the_lug_tied(tied):
    """The paper's 2-D friction on the hooks (normal2d), lug tied, at the preload with the
    most slip: ROM_I runs through the range (the 2-D cycle closes at the onset of partial
    slip; it used to stop there: "not closed in 200 periods"), the hooks slip and lift
    off, and ROM_II's 40 GSI modes are within the issue's targets, 1 % in peak amplitude
    and 0.1 % in peak frequency (measured -0.34 %, +4.9e-5). Its ROM_I used to stop at
    180.2 Hz, where a carried slider made the 2-D march need thousands of periods
    (frirom_aft_march settle_step2d, tests/test_aft.f90)."""
    import paper_hooks as ph
    r1 = ph.Rom(tied, "rom1", "coarse", law="normal2d")
    (f1, a1), res = hooks_peak(r1, HOOKS_F0)
    assert res.state_fractions[:, r1._hooks, 1].max() > 0.3
    assert res.state_fractions[:, r1._hooks, 2].max() > 0.1
    (f2, a2), _ = hooks_peak(ph.Rom(tied, "rom2", "coarse", 40, law="normal2d"), HOOKS_F0)
    assert a2 == pytest.approx(a1, rel=0.01)
    assert f2 == pytest.approx(f1, rel=0.001)


@pytest.mark.slow
def test_rom1_first_point_does_not_depend_on_the_stuck_lug_preload(hooks_case):
    """The lug stays stuck, so its preload P only adds a constant force that its static
    load balances: ROM_I's first point (f0 = 300 N, hooks slipping) is the same for
    P = 100 kN, 300 kN and 1 MN. The static load over the vane's 12 N/m soft mount used to
    appear at the contact DoFs as T D_0^-1 f_e ~ 1e5 m, cancelled by the contact term to
    rounding: a floor of ~1e-11 m on unknowns of 6e-8 m (measured 2.3e-4 and 4.5e-4
    relative). With the forces relative to rest (frirom_hbm contact_set) nothing large
    cancels; what differs is Newton's stop (tol_update 1e-8 of the deck, converging
    quadratically: measured 5e-12): tolerance 1e-9."""
    import make_paper_hooks as mk
    import paper_hooks as ph
    from frirom.contact import LAWS
    from frirom.solver import solve_point
    rom = ph.Rom(hooks_case, "rom1", "coarse")
    rom.set_preload(300.0)
    lug = mk.lug_geometry(hooks_case / "hooks")
    unit = ph.static_loads(rom.deck.reduced, lug, 1.0)       # per N of n0 on every pair
    other = rom.excitation.F[:, 0] - unit * (mk.F_LUG / len(lug[0]))
    groups = [i for i, g in enumerate(rom.groups) if g.startswith("lug")]
    y = {}
    for p in (1e5, 3e5, 1e6):
        for i in groups:                 # normal1d: two groups share each pair's preload
            c = rom.model.contacts[i]
            c.params[:, LAWS[c.law].parameters.index("n0")] = p / len(lug[0]) / len(groups)
        rom.excitation.F[:, 0] = other + unit * (p / len(lug[0]))
        pt = solve_point(rom.model, rom.excitation, rom.deck.omega_start, rom.options,
                         outputs=rom.deck.outputs)
        assert pt.state_fractions[groups, 0].min() == 1.0     # the lug sticks
        y[p] = pt.unknowns
    for p in (3e5, 1e6):
        assert np.abs(y[p] - y[1e5]).max() < 1e-9 * np.abs(y[1e5]).max(), p
