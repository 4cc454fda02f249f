"""The paper's multi-stage flange case (cases/paper_flange) at its coarse size (6 + 6
sectors, 12 contact pairs, ccx at run time): the decks build the ROMs, the MS ROM with the
whole EO 2 family is exact for the tuned rotor, its nonlinear peaks match ROM_I's, and the
index-2 ROM_II's error is reported, not hidden; the family solved as a travelling wave
(the selection of the condensed unknowns) is the family."""

import dataclasses
import inspect
import os
import shutil
import warnings

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.sparse as sp

import paper_flange as pf  # cases/paper_flange/paper_flange.py

from frirom import InputError, ParameterError
from frirom.deck import load_deck
from frirom.reduction.multistage import (travelling_wave_pairs,
                                        travelling_wave_selection)
from frirom.results import FRF, FRFWriter
from frirom.solver import LEAK_TOL, frf, kept_unknowns, solve_point

pytestmark = pytest.mark.skipif(shutil.which("ccx") is None, reason="ccx not installed")


@pytest.fixture(scope="module")
def work(tmp_path_factory):
    w = tmp_path_factory.mktemp("paper_flange")
    pf.make(w, quick=True, log=lambda *a: None)
    return w


@pytest.fixture(scope="module")
def decks(work):
    return {rom: pf.load(work, rom)[0] for rom in pf.ROMS}


def _stuck(d, omega):
    """Harmonic 1 at the outputs of the linear model with every contact two springs."""
    m = d.model()
    g = m.contacts[0]
    G = sp.csr_matrix(g.G)
    Kc = (G.T @ sp.diags(g.params[:, :2].ravel()) @ G).toarray()
    K, M = pf._dense(m.K), pf._dense(m.M)
    beta = d.damping["beta"]
    D = K + Kc - omega ** 2 * M + 1j * omega * beta * K
    return np.linalg.solve(D, d.F[:, 1])[d.outputs]


def test_table_1_sizes(decks):
    """ROM_I keeps 3 x 2 x 12 flange DoFs, ROM_II 2 stages x (cos, sin) x 3 = 12 MS
    coordinates (the paper's 12), the family of time harmonics 0..3 (indices 0, 2, 4, 6
    over 12 segments: 1 + 2 + 2 + 1 columns) 2 x 6 x 3 = 36; the nonlinear DoFs are those
    interface coordinates (ROM_I: but the radial DoFs at the pairs where the radial
    direction is a global axis: x or y has no tangential or axial component there)."""
    s = {rom: pf.sizes(d) for rom, d in decks.items()}
    assert s["rom2_eo"]["ms"] == 24              # indices 2, 4 (= 6 - 2): 2 x 2 x 2 x 3
    assert s["rom1"]["interface"] == 72 and s["rom1"]["ms"] == 0
    assert s["rom2"]["interface"] == s["rom2"]["ms"] == 12
    assert s["rom2_family"]["ms"] == 36
    for v in s.values():
        assert v["active"] == 36 and v["modal"] == 20
        assert v["interface"] - 4 <= v["nonlinear"] <= v["interface"]
    assert s["rom2"]["nonlinear"] == 12


def test_ms_family_exact_for_the_tuned_rotor(decks, work):
    """Linear stuck response to the two clocked EO 2 waves: ROM_II with the family equals
    ROM_I to 1e-9 relative (round-off of two dense solves; the MS basis spans every
    interface motion of that travelling wave), ROM_II with index 2 alone does not (> 1 %)."""
    info = pf.make(work, quick=True)
    omega = 2 * np.pi * info["f_stuck"] * 0.995
    ref = _stuck(decks["rom1"], omega)
    fam = _stuck(decks["rom2_family"], omega)
    two = _stuck(decks["rom2"], omega)
    assert np.max(np.abs(fam - ref)) < 1e-9 * np.max(np.abs(ref))
    assert np.max(np.abs(two - ref)) > 1e-2 * np.max(np.abs(ref))


@pytest.mark.parametrize("f0", [1.0, 300.0])
def test_family_rom2_peaks_match_rom1(decks, f0):
    """Nonlinear FRFs, stuck (F0 1 N) and with much of the flange slipping and lifting off
    (300 N): the family ROM_II's peaks (solved on the curve) within the paper's 1 % in
    amplitude and 0.1 % in frequency of ROM_I's on both stages; the index-2 ROM_II misses
    the frequency target and is flagged 'DIFFERS' by the case's table. ROM_II j=1 (index 2
    and its aliases z N +- 2) matches while the flange is stuck and is flagged once the
    time harmonics 0, 2, 3 (indices 0, 4, 6) matter."""
    r1 = pf.sweep(decks["rom1"], f0)
    rf = pf.sweep(decks["rom2_family"], f0)
    rt = pf.sweep(decks["rom2_tw"], f0)     # its deck's travelling_wave = true
    r2 = pf.sweep(decks["rom2"], f0)
    re = pf.sweep(decks["rom2_eo"], f0)
    ea = max(abs(re["peak_amp"][k] / r1["peak_amp"][k] - 1) for k in range(2))
    ee = max(abs(re["peak_f"][k] / r1["peak_f"][k] - 1) for k in range(2))
    assert pf.row_flag(ea, ee) == ("match" if f0 < 10 else "DIFFERS")
    assert r1["complete"] and rf["complete"] and r2["complete"]
    if f0 > 100:
        assert r1["lift"] > 0.2 and r1["slip"] > 0.1
    for k in range(2):
        assert abs(rf["peak_amp"][k] / r1["peak_amp"][k] - 1) < pf.TARGET_AMP
        assert abs(rf["peak_f"][k] / r1["peak_f"][k] - 1) < pf.TARGET_FREQ
        # the family solved for the travelling wave's pairs only: the family's peaks
        # within 1e-4 / 1e-5 (measured up to 7.7e-6 / 1.6e-7 at 300 N: the deck's family
        # runs in contact coordinates, another Newton path through the slipping peak;
        # equality point for point in the same coordinates: below)
        assert abs(rt["peak_amp"][k] / rf["peak_amp"][k] - 1) < 1e-2 * pf.TARGET_AMP
        assert abs(rt["peak_f"][k] / rf["peak_f"][k] - 1) < 1e-2 * pf.TARGET_FREQ
    assert rt["leak"] < 1e-8 and rt["complete"]
    ef = abs(r2["peak_f"][0] / r1["peak_f"][0] - 1)
    assert ef > pf.TARGET_FREQ
    assert pf.row_flag(0.0, ef) == "DIFFERS"
    # a member whose FRF stopped early is never called a match (its peak may be missing)
    assert pf.row_flag(0.0, 0.0, complete=False).startswith("UNKNOWN")
    assert pf.stopped(dict(r1, complete=False)).startswith(" STOPPED at")


@pytest.mark.parametrize("rom", ["rom2", "rom2_eo", "rom2_family"])
def test_derived_rom2_equals_the_decks(decks, rom):
    """The case's ROM_II built from ROM_I (paper_flange.derived: MS on the CB matrices that
    ROM_I keeps) is the deck's ROM_II (CB, then MS): K, M, contact map, loads and outputs
    equal to 1e-12 relative (the same products in another order)."""
    d = pf.derived(decks["rom1"], rom, pf.QUICK)
    ref = decks[rom]
    for a, b in ((d.K, ref.K), (d.M, ref.M), (d.contacts[0].G, ref.contacts[0].G)):
        a, b = pf._dense(a), pf._dense(b)
        assert a.shape == b.shape and np.abs(a - b).max() <= 1e-12 * np.abs(b).max()
    assert np.abs(d.F - ref.F).max() <= 1e-12 * np.abs(ref.F).max()
    assert list(d.outputs) == list(ref.outputs)


# ---- travelling-wave selection of the condensed unknowns (SolverOptions.selection, the
# deck's [reduction.interface_modes] travelling_wave): the selected family ROM_II is the
# unselected one point for point, in stick and with the flange slipping and lifting off;
# its leak is at round-off there and large for a mistuned rotor (with the warning); resume
# stays exact; bad decks and options get errors naming their field.

class Killed(Exception):
    pass


@pytest.fixture(scope="module")
def fam(work):
    """The family ROM_II (indices 0, 2, 4, 6 at every time harmonic) and its selection."""
    d1, _ = pf.load(work, "rom1")
    d = pf.derived(d1, "rom2_family", pf.QUICK)
    sel = travelling_wave_selection(d.reduced.labels, pf.QUICK.eo, pf.QUICK.sectors, pf.H)
    return d1, d, sel


def _run(d, f0, selection=None, contacts=None, pairs=None, orbits=True, **kw):
    model, exc = (dataclasses.replace(d, contacts=contacts) if contacts else d).model(), \
        d.excitation()
    exc.F[:, 1:] *= f0 / pf.F0_DECK
    o = dataclasses.replace(d.options(), stability=False, coordinates="dofs",
                            selection=selection, pairs=pairs, orbits=orbits)
    return frf(model, exc, d.omega_start, d.omega_end, o, outputs=d.outputs, **kw)


@pytest.fixture(scope="module")
def selected(fam):
    """The selected family ROM_II's FRF at F0 (computed once per F0 for the tests below)."""
    runs = {}

    def get(f0):
        if f0 not in runs:
            with warnings.catch_warnings():
                warnings.simplefilter("error")      # no leak warning for the tuned rotor
                runs[f0] = _run(fam[1], f0, fam[2])
        return runs[f0]
    return get


def test_selection_counts(fam):
    """6 sectors, EO 2, 12 segments per stage: time harmonic h lives on the indices
    +-2h mod 6, so indices {0, 6} at h = 0 and 3 (2 columns x 3 components x 2 stages =
    12 coordinates), {2, 4} at h = 1 and 2 (24); the 56 modal and blade DoFs keep every
    harmonic. Unknowns 12 + 2 (24 + 24 + 12) = 132 of 36 x 7 = 252."""
    _, d, sel = fam
    labels = d.reduced.labels
    ms = np.array(["ms h=" in s for s in labels])
    assert ms.sum() == 36 and sel[~ms].all()
    assert sel[ms].sum(axis=0).tolist() == [12, 24, 24, 12]
    r = _run(d, 1.0, sel, sink=None)
    assert "travelling-wave selection: 132 of 252 unknowns" in r.solver_info
    assert kept_unknowns(sel[full_nl(d)]) == 132        # what the case's Table 1 shows


@pytest.mark.parametrize("f0", [1.0, 300.0])
def test_selected_equals_unselected_point_for_point(fam, selected, f0):
    """Same unknowns (coordinates 'dofs'), with and without the selection: the same number
    of points, every output harmonic within 1e-7 of the largest and the peaks within 1e-8
    relative. Not bits: both runs converge each point to Newton's 1e-8 (tol_residual,
    tol_update) with Jacobians rounded differently, and the next point's place on the arc
    inherits that difference (frequencies up to 9e-9 apart at 300 N), which the steep
    flanks near lift-off amplify in the outputs compared index by index (measured 2.2e-10
    stuck at 1 N, 3.3e-8 at 300 N with slip and lift-off, where the peaks still agree
    to 6e-10). The leak is at round-off: below 1e-8
    (measured 5e-10 at 1 N, the linear model's cyclic round-off; 2.5e-9 at 300 N, the
    closed-cycle iteration of the slipping elements)."""
    _, d, sel = fam
    full = _run(d, f0)
    part = selected(f0)
    assert full.complete and part.complete and len(full) == len(part)
    if f0 > 100:
        assert full.state_fractions[:, 0, 2].max() > 0.2     # lifts off
        assert full.state_fractions[:, 0, 1].max() > 0.1     # slips
    scale = np.abs(full.X).max()
    assert np.abs(part.X - full.X).max() < 1e-7 * scale
    for k in range(2):
        a, b = full.peak(k), part.peak(k)
        assert abs(b.amplitude / a.amplitude - 1) < 1e-8
        assert abs(b.omega / a.omega - 1) < 1e-8
    assert part.leak.max() < 1e-8 and full.leak is None     # no selection, no leak
    # the selected Jacobian is the unselected one's kept block to round-off (its
    # receptance blocks skip only the modes whose terms are below round-off): Newton takes
    # the same iterations (measured 622 at 1 N, 1 109 at 300 N; skipping every mode below
    # 1e-3 of the largest term fails this test's X comparison above)
    assert part.timings["evaluations"] == full.timings["evaluations"]
    # the unknowns left out stay zero
    keep = np.concatenate([sel[full_nl(d)][:, (c + 1) // 2] for c in range(2 * pf.H + 1)])
    assert np.all(part.unknowns[:, ~keep] == 0)


def full_nl(d):
    return d.model().nonlinear_dofs()


def _pairing(d, U, pairs):
    """Per point, the largest |x_k,sin - s x_j,cos| and |x_k,cos + s x_j,sin| over the
    pairs (j, k, s) of ``pairs``, over |unknowns| (U: (n_pts, nnl (2H+1)), the condensed
    unknowns coefficient by coefficient)."""
    nl = full_nl(d)
    pos = {int(dof): i for i, dof in enumerate(nl)}
    col = U.reshape(len(U), 2 * pf.H + 1, nl.size)
    worst = np.zeros(len(U))
    for j, dof in enumerate(nl):
        for h in range(1, pf.H + 1):
            if pairs[dof, h] == 0:
                continue
            k, s = pos[abs(int(pairs[dof, h])) - 1], np.sign(pairs[dof, h])
            worst = np.maximum(worst, np.maximum(
                np.abs(col[:, 2 * h, k] - s * col[:, 2 * h - 1, j]),
                np.abs(col[:, 2 * h - 1, k] + s * col[:, 2 * h, j])))
    return worst / np.linalg.norm(U, axis=1)


@pytest.mark.parametrize("f0", [1.0, 300.0])
def test_selected_solution_travels_one_way(fam, selected, f0):
    """The sign convention of travelling_wave_pairs, shown on the selected solution
    (solved without pairs): each MS index p's sine column at harmonic h is its cosine
    column a quarter period on, with the sign of p = +-h EO (mod N): within 1e-8 of
    |unknowns| at every point (measured median 2.9e-10 / 2.0e-10, largest 1.3e-9 /
    2.1e-9 at 1 / 300 N: the model's own cyclic round-off, as its leak; Newton's
    tolerance at 1e-12 changes nothing). The opposite direction misses by more than 0.3
    of |unknowns| everywhere (measured at least 0.71 at 1 N: the pairing's two terms
    add), so the sign is tested, not assumed."""
    _, d, _ = fam
    pairs = travelling_wave_pairs(d.reduced.labels, pf.QUICK.eo, pf.QUICK.sectors, pf.H)
    # 6 sectors, EO 2: indices 2 (p = +2h at h = 1, -2h at h = 2) and 4 (the reverse), not
    # 0, 6 (no sine column; 2h EO = 0 mod 6 at h = 3): 2 x 2 stages x 3 components x 2
    assert np.count_nonzero(pairs) == 24 and not pairs[:, [0, 3]].any()
    U = selected(f0).unknowns
    assert _pairing(d, U, pairs).max() < 1e-8
    assert _pairing(d, U, -pairs).min() > 0.3


def _same_steps(ref, new, x_tol, peak_tol):
    """new took ref's steps: complete, the same points and Newton evaluations, X within
    x_tol of its largest, both outputs' peaks within peak_tol relative."""
    assert new.complete and len(new) == len(ref)
    assert new.timings["evaluations"] == ref.timings["evaluations"]
    assert np.abs(new.X - ref.X).max() < x_tol * np.abs(ref.X).max()
    for k in range(2):
        a, b = ref.peak(k), new.peak(k)
        assert abs(b.amplitude / a.amplitude - 1) < peak_tol
        assert abs(b.omega / a.omega - 1) < peak_tol


@pytest.mark.parametrize("f0", [1.0, 300.0])
def test_paired_equals_selected_point_for_point(fam, selected, f0):
    """The selection with the wave's direction (SolverOptions.pairs: 84 unknowns of 132,
    J_z = T^T J T) against the selection alone: the same points and Newton evaluations, X
    within 1e-7 of its largest and the peaks within 1e-8 relative (measured 1.3e-9 / 4.0e-8
    and 4.4e-10 / 3.0e-10 at 1 / 300 N: both converge to Newton's 1e-8 on Jacobians
    rounded differently, and at 300 N the steep flanks near lift-off amplify the
    frequencies' 1e-8 differences in X compared index by index, as selected against
    unselected above); the leak stays at round-off (below 1e-8) and each pair's members
    hold the pairing exactly."""
    _, d, sel = fam
    pairs = travelling_wave_pairs(d.reduced.labels, pf.QUICK.eo, pf.QUICK.sectors, pf.H)
    part = selected(f0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        two = _run(d, f0, sel, pairs=pairs)
    assert "132 of 252 unknowns, 84 in one direction" in two.solver_info
    if f0 > 100:
        assert two.state_fractions[:, 0, 2].max() > 0.2     # lifts off
        assert two.state_fractions[:, 0, 1].max() > 0.1     # slips
    _same_steps(part, two, 1e-7, 1e-8)
    assert two.leak.max() < 1e-8
    assert _pairing(d, two.unknowns, pairs).max() == 0.0


@pytest.mark.parametrize("f0", [1.0, 300.0])
def test_orbits_equal_every_element_point_for_point(fam, f0):
    """SolverOptions.orbits (the default with pairs): Newton's evaluations run the AFT on
    one element per orbit, 2 of the 12 (one sector's pairs), against every element
    (orbits=False): the same points and evaluations, X within 1e-8 of its largest and the
    peaks within 1e-10 (measured 7e-15 / 2.4e-9 and 3e-16 / 3e-13 at 1 / 300 N: the
    orbits' sums differ from every element's only in rounding, which the steep flanks
    near lift-off amplify at 300 N); the leak, which at the points also counts the
    orbits' forces against every element's, stays at round-off."""
    _, d, sel = fam
    pairs = travelling_wave_pairs(d.reduced.labels, pf.QUICK.eo, pf.QUICK.sectors, pf.H)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        every = _run(d, f0, sel, pairs=pairs, orbits=False)
        orb = _run(d, f0, sel, pairs=pairs)
    assert "AFT of Newton's evaluations on 2 of 12 contact elements" in orb.solver_info
    assert "AFT of Newton" not in every.solver_info
    _same_steps(every, orb, 1e-8, 1e-10)
    assert orb.leak.max() < 1e-8


def test_orbits_history_that_is_no_wave_leaks(fam):
    """At 30 N the flange slips near the peak and sticks again towards the band's end,
    each pair keeping the slider its last slip left, at its own phase: that history is no
    travelling wave. Newton's evaluations on the orbits use one sector's sliders; the
    points, which run every element with its own, measure the difference and warn there
    (measured 3.5e-2 over 873-884 Hz, as every element's run, 2.8e-2), while before it the
    leak stays at round-off (1e-9)."""
    _, d, sel = fam
    pairs = travelling_wave_pairs(d.reduced.labels, pf.QUICK.eo, pf.QUICK.sectors, pf.H)
    with pytest.warns(RuntimeWarning, match="travelling-wave selection leaks"):
        r = _run(d, 30.0, sel, pairs=pairs)
    f = r.omega / 2 / np.pi
    assert r.state_fractions[:, 0, 1].max() > 0.05          # slips on the way
    assert r.leak[f < 865].max() < 1e-8
    assert r.leak[f > 875].min() > 1e-3


def test_orbits_of_a_mistuned_rotor(fam):
    """One flange pair's stiffness 1.5 x the others': that element is an orbit of its own
    (3 AFT elements of 12) and the others keep theirs, so on the wave the orbits still
    equal every element (X within 1e-8; the pairs themselves are what no longer fits the
    rotor, and the leak says so as without orbits, 0.04-0.08)."""
    _, d, sel = fam
    pairs = travelling_wave_pairs(d.reduced.labels, pf.QUICK.eo, pf.QUICK.sectors, pf.H)
    c = d.contacts[0]
    p = c.params.copy()
    p[0, :2] *= 1.5
    mist = [dataclasses.replace(c, params=p)]
    with pytest.warns(RuntimeWarning, match="travelling-wave selection leaks"):
        every = _run(d, 1.0, sel, contacts=mist, pairs=pairs, orbits=False)
    with pytest.warns(RuntimeWarning, match="travelling-wave selection leaks"):
        orb = _run(d, 1.0, sel, contacts=mist, pairs=pairs)
    assert "on 3 of 12 contact elements" in orb.solver_info
    assert len(orb) == len(every)
    assert np.abs(orb.X - every.X).max() < 1e-8 * np.abs(every.X).max()
    assert np.abs(orb.leak - every.leak).max() < 1e-6 * every.leak.max()
    assert orb.leak.min() > 1e-3


def test_pairs_of_the_wrong_direction_leak(fam):
    """Pairs of the other direction (every sign flipped) force a wave the load does not
    make: the leak, which counts the forces in the other direction, says so at every
    point (measured 1.0) with the warning."""
    _, d, sel = fam
    pairs = travelling_wave_pairs(d.reduced.labels, pf.QUICK.eo, pf.QUICK.sectors, pf.H)
    with pytest.warns(RuntimeWarning, match="travelling-wave selection leaks"):
        r = _run(d, 1.0, sel, pairs=-pairs)
    assert r.leak.min() > 0.1


@pytest.mark.parametrize("what", ["stiffness", "preload"])
def test_mistuned_rotor_leaks_and_warns(fam, what):
    """One flange pair's contact stiffness (kt, kn) or preload 1.5 x the others': the
    rotor is no longer cyclic, the selection drops real coupling, and the leak says so
    (measured 0.04-0.08 at 1 N) with the warning, for the run's points and for the peak
    solved between them (refine_peak's points are checked the same way)."""
    _, d, sel = fam
    c = d.contacts[0]
    p = c.params.copy()
    if what == "stiffness":
        p[0, :2] *= 1.5
    else:
        p[0, 3] *= 1.5
    with pytest.warns(RuntimeWarning, match="travelling-wave selection leaks") as got:
        r = _run(d, 1.0, sel, contacts=[dataclasses.replace(c, params=p)])
    assert r.leak.max() > 100 * LEAK_TOL and r.leak.min() > 1e-3
    # the warning points at the line that called frf (in _run)
    src, first = inspect.getsourcelines(_run)
    at = first + next(i for i, line in enumerate(src) if "frf(" in line)
    assert all((w.filename, w.lineno) == (__file__, at) for w in got
               if "leaks" in str(w.message))
    assert r.peak(0).method == "solve"
    assert any("a peak solved between points" in str(w.message) for w in got)


@pytest.mark.slow
def test_keeping_everything_equals_no_selection(fam):
    """ROM_I (physical flange DoFs: the sparse rows of G, the element loops of the
    selected Jacobian) with a selection that keeps every pair: the same solutions as
    without one. Both runs take the same steps (frequencies within 1e-13) over most of
    the path (measured: all 130 points; before the arc-length scale grew per point, the
    first 129 of 134), X within 5e-13 of its largest. Should a step-size decision fall
    the other way, the later points sit elsewhere on the same curve (and a stuck end point
    keeps another slip history: 5e-8), so the points are compared up to the first step
    taken apart (at least 90 % of them), and the peaks (solved on the curve) within 1e-10."""
    d1, _, _ = fam
    sel = np.ones((d1.n_dof, pf.H + 1), bool)
    a, b = _run(d1, 30.0), _run(d1, 30.0, sel)
    assert len(a) == len(b) and a.complete and b.complete
    apart = np.abs(a.omega / b.omega - 1) > 1e-13
    k = int(np.argmax(apart)) if apart.any() else len(a)      # first step taken apart
    assert k > 0.9 * len(a)
    assert np.abs(a.X[:k] - b.X[:k]).max() < 1e-8 * np.abs(a.X).max()
    for k in range(2):
        assert abs(a.peak(k).amplitude / b.peak(k).amplitude - 1) < 1e-10
        assert abs(a.peak(k).omega / b.peak(k).omega - 1) < 1e-10


@pytest.mark.slow
def test_resume_with_a_selection_is_exact(fam, tmp_path):
    """Killed after 25 points, resumed from the last checkpoint: the file equals the
    uninterrupted run's bit for bit (the points hold the full layout, zeros where left
    out; tolerance 0)."""
    _, d, sel = fam
    names = [c.name for c in d.contacts]
    files = {k: FRFWriter(tmp_path / f"{k}.h5", d.outputs, names, pf.H) for k in ("ref", "cut")}
    full = _run(d, 300.0, sel, sink=files["ref"].append)
    files["ref"].close(full.complete, full.message)
    cut = files["cut"]

    def until_25(p):            # the process dies inside the 26th point's record
        (cut.append if cut._commit[0] < 25 else _die)(p)
    with pytest.raises(Killed):
        _run(d, 300.0, sel, sink=until_25)
    cut.f.close()
    start = FRFWriter.resume_point(tmp_path / "cut.h5")
    again = FRFWriter(tmp_path / "cut.h5", d.outputs, names, pf.H, append=True)
    rest = _run(d, 300.0, sel, sink=again.append, start=start)
    again.close(rest.complete, rest.message)
    got, ref = FRF.load(tmp_path / "cut.h5"), FRF.load(tmp_path / "ref.h5")
    assert start["n_points"] < 25 and len(got) == len(ref)
    for name in ("omega", "X", "state_fractions", "slider"):
        np.testing.assert_array_equal(getattr(got, name), getattr(ref, name), err_msg=name)


def _die(p):
    raise Killed


@pytest.mark.slow
def test_leak_is_stored_per_point(fam, tmp_path):
    """frf.h5 (FRFWriter and FRF.save_h5) and the CSV keep each point's leak, the very
    floats of the run (tolerance 0 in the file; the CSV's 3 digits to 5e-3 relative); a
    run without a selection keeps none (FRF.leak None, no dataset, no column), and a file
    written before the leak was kept still loads (the dataset removed: leak None)."""
    _, d, sel = fam
    names = [c.name for c in d.contacts]
    files = {}
    for key, s in (("sel", sel), ("full", None)):
        w = FRFWriter(tmp_path / f"{key}.h5", d.outputs, names, pf.H)
        r = _run(d, 1.0, s, sink=w.append)
        w.close(r.complete, r.message)
        files[key] = (r, FRF.load(tmp_path / f"{key}.h5"))
    r, got = files["sel"]
    np.testing.assert_array_equal(got.leak, r.leak)
    assert r.leak.max() > 0
    got.save_h5(tmp_path / "again.h5")
    np.testing.assert_array_equal(FRF.load(tmp_path / "again.h5").leak, r.leak)
    got.save_csv(tmp_path / "sel.csv")
    rows = np.genfromtxt(tmp_path / "sel.csv", delimiter=",", names=True)
    np.testing.assert_allclose(rows["leak"], r.leak, rtol=5e-3, atol=0)
    r, got = files["full"]
    assert r.leak is None and got.leak is None
    got.save_csv(tmp_path / "full.csv")
    assert "leak" not in (tmp_path / "full.csv").read_text().splitlines()[0]
    import h5py
    with h5py.File(tmp_path / "full.h5", "r") as f:
        assert "leak" not in f
    with h5py.File(tmp_path / "sel.h5", "a") as f:      # as written before the leak was kept
        del f["leak"], f.attrs["content_sha256"]        # (and before checksums)
    assert FRF.load(tmp_path / "sel.h5").leak is None


def test_resumed_run_warns_on_a_stored_leak(fam, tmp_path):
    """A run killed after 25 points whose stored points leak (one doctored to 0.5: a
    tuned rotor's run leaks at round-off), resumed from its checkpoint: the resumed run
    warns, naming that point's frequency, as the uninterrupted run would have; the tuned
    rotor's own resumed points do not (the same resume without the doctored point is
    silent)."""
    _, d, sel = fam
    names = [c.name for c in d.contacts]
    cut = FRFWriter(tmp_path / "cut.h5", d.outputs, names, pf.H)

    def until_25(p):
        (cut.append if cut._commit[0] < 25 else _die)(p)
    with pytest.raises(Killed):
        _run(d, 1.0, sel, sink=until_25)
    cut.f.close()
    shutil.copyfile(tmp_path / "cut.h5", tmp_path / "quiet.h5")
    import h5py
    with h5py.File(tmp_path / "cut.h5", "a") as f:
        f["leak"][3] = 0.5
        hz = float(f["omega"][3]) / 2 / np.pi
    for name, leaks in (("quiet", False), ("cut", True)):
        start = FRFWriter.resume_point(tmp_path / f"{name}.h5")
        assert 3 < start["n_points"] < 25
        with warnings.catch_warnings(record=True) as got:
            warnings.simplefilter("always")
            _run(d, 1.0, sel, start=start)
        msgs = [str(w.message) for w in got if issubclass(w.category, RuntimeWarning)]
        assert any("selection leaks" in m and f"{hz:.6g} Hz" in m for m in msgs) == leaks
        # the quiet resume warns of no leak at all
        assert any("selection leaks" in m for m in msgs) == leaks


def test_solve_point_warns_on_a_leak(fam):
    """solve_point with a selection warns on a leak as frf does: the mistuned rotor (one
    pair's preload x1.5, leak 0.04-0.08 along the FRF) warns and reports its leak; the
    tuned rotor does not (leak below 1e-8, as along its FRF); without a selection the
    point has no leak (None)."""
    _, d, sel = fam
    c = d.contacts[0]
    p = c.params.copy()
    p[0, 3] *= 1.5
    w = 0.5 * (d.omega_start + d.omega_end)
    o = dataclasses.replace(d.options(), stability=False, coordinates="dofs", selection=sel)
    with pytest.warns(RuntimeWarning, match="travelling-wave selection leaks") as got:
        pt = solve_point(dataclasses.replace(d, contacts=[dataclasses.replace(c, params=p)])
                         .model(), d.excitation(), w, o, outputs=d.outputs)
    assert pt.leak > 1e-3
    assert all(w.filename == __file__ for w in got if "leaks" in str(w.message))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pt = solve_point(d.model(), d.excitation(), w, o, outputs=d.outputs)
    assert pt.leak < 1e-8
    o = dataclasses.replace(o, selection=None)
    assert solve_point(d.model(), d.excitation(), w, o, outputs=d.outputs).leak is None


def _deck(work, name, edit):
    text = (work / pf.deck_name("rom2_family", 300.0)).read_text()
    text = text.replace('time_harmonics = [0, 1, 2, 3]\n',
                        'time_harmonics = [0, 1, 2, 3]\ntravelling_wave = true\n')
    path = work / name
    path.write_text(edit(text))
    return path


#: EO 2 on 6 sectors: time harmonic h lives on the indices +-2h mod 6, written out for
#: the MS indices 0, 2, 4, 6 of the coarse flange (12 segments per stage), h = 0..3
_WAVE = {0: {0, 6}, 1: {2, 4}, 2: {2, 4}, 3: {0, 6}}


def test_deck_key_builds_the_selection(work, fam):
    """The deck's key keeps, of each MS coordinate 'ms h=p', the harmonics h whose
    indices (_WAVE, by hand) hold p, and every harmonic of the other coordinates (modal,
    blade DoFs); the case's selection is that too."""
    _, _, sel = fam
    d = load_deck(_deck(work, "tw.toml", lambda t: t))
    got = d.options().selection
    want = np.ones_like(got)
    for i, lab in enumerate(d.dof_labels):
        if "ms h=" in lab:
            p = int(lab.split("ms h=")[1].split()[0])
            want[i] = [p in _WAVE[h] for h in range(pf.H + 1)]
    assert pf.H == 3 and (~want).any() and want.any(axis=1).all()
    assert np.array_equal(got, want) and np.array_equal(sel, want)
    # and the wave's direction (the key always pairs: exact under the same assumptions)
    assert np.array_equal(d.options().pairs, travelling_wave_pairs(
        d.dof_labels, pf.QUICK.eo, pf.QUICK.sectors, pf.H))
    assert "travelling_wave" in d.result_meta()["solver_settings"]


_STAGE1 = '["12:z", "38:z", "64:z", "90:z", "116:z", "142:z"]'
_STAGE2 = '["170:z", "200:z", "230:z", "260:z", "290:z", "320:z"]'


@pytest.mark.parametrize("eo", [8, -4])
def test_the_same_wave_modulo_n_is_accepted(work, eo):
    """Stage 2's engine order 8 or -4 on 6 sectors is stage 1's wave eo 2 (each load's
    phases exp(-2 pi i eo s / 6) alias): the deck is accepted, with the same loads (to
    1e-12 of the largest: the phases' round-off) and the same selection as eo 2."""
    ref = load_deck(_deck(work, "tw.toml", lambda t: t))
    d = load_deck(_deck(work, f"tw{eo}.toml",
                        lambda t: f"eo = {eo}".join(t.rsplit("eo = 2", 1))))
    assert _STAGE2 in d.path.read_text() and f"eo = {eo}" in d.path.read_text()
    assert np.abs(d.F - ref.F).max() < 1e-12 * np.abs(ref.F).max()
    assert np.array_equal(d.options().selection, ref.options().selection)


def test_standing_wave_leaks(work, fam):
    """Why eo 4 with eo 2 on 6 sectors is refused: stage 2's eo 4 is eo -2, the wave
    running backwards, and the pair a standing wave, which the selection of eo 2 does not
    hold: its leak at 1 N is 3.7e-2 (above 1e-2 asserted; eo 2 on both: 5e-10)."""
    _, _, sel = fam
    d = load_deck(_deck(work, "standing.toml", lambda t: "eo = 4".join(
        t.rsplit("eo = 2", 1)).replace("travelling_wave = true\n", "")))
    with pytest.warns(RuntimeWarning, match="selection leaks"):
        r = _run(d, 1.0, sel)
    assert r.leak.max() > 1e-2


@pytest.mark.parametrize("edit, field", [
    (lambda t: t.replace("stability = false", "stability = true"), "solver.stability"),
    (lambda t: t.replace("[solver]", "[solver]\nmax_harmonics = 5")
     .replace("harmonics = 3\n", "harmonics = \"auto\"\n"), "solver.harmonics"),
    (lambda t: t.replace("[solver]", "[solver]\nformulation = \"banded\""),
     "solver.formulation"),
    # eo 4 on 6 sectors is eo -2: stage 2 under the wave running backwards, with stage
    # 1's a standing wave (test_standing_wave_leaks); eo 3 another wave
    (lambda t: "eo = 4".join(t.rsplit("eo = 2", 1)), "excitation.engine_order[1].eo"),
    (lambda t: "eo = 3".join(t.rsplit("eo = 2", 1)), "excitation.engine_order[1].eo"),
    # sector counts: stated against the DoFs, the selection's N, and the geometry
    (lambda t: t.replace("eo = 2\n", "eo = 2\nn_sectors = 12\n", 1),
     "excitation.engine_order[0].n_sectors"),
    (lambda t: t.replace("sectors = 6\n", "sectors = 12\n"),
     "excitation.engine_order[0].n_sectors"),
    (lambda t: t.replace(_STAGE1, '["12:z", "64:z", "116:z", "12:z", "64:z", "116:z"]'),
     "excitation.engine_order[0].n_sectors"),
    (lambda t: t.replace(_STAGE1, '["12:z", "64:z", "38:z", "90:z", "116:z", "142:z"]'),
     "excitation.engine_order[0].dofs"),
    (lambda t: t.replace(_STAGE2, '["170:z", "320:z", "290:z", "260:z", "230:z", "200:z"]'),
     "excitation.engine_order[1].dofs"),
    (lambda t: t.replace("harmonic = 0\namplitude = -", "harmonic = 1\namplitude = -"),
     "excitation.load[1].harmonic"),
    (lambda t: t.replace('method = "ms"', 'method = "gsi"\nfree = 4')
     .replace("engine_orders = [2]\n", "").replace("time_harmonics = [0, 1, 2, 3]\n", "")
     .replace("sectors = 6\n", ""), "travelling_wave"),
])
def test_bad_decks_name_their_field(work, edit, field):
    with pytest.raises(InputError, match=field.replace("[", r"\[").replace("]", r"\]")):
        load_deck(_deck(work, "bad.toml", edit))


def test_bad_options_name_their_field(fam):
    """Formulation, stability, the excitation outside the selection, labels without MS
    coordinates."""
    _, d, sel = fam
    for kw in (dict(formulation="banded"), dict(stability=True), dict(krylov=True),
               dict(coordinates="contact")):
        with pytest.raises(ParameterError, match="options.selection"):
            dataclasses.replace(d.options(), selection=sel, **kw).check()
    model, exc = d.model(), d.excitation()
    nl = model.nonlinear_dofs()
    off = nl[~sel[nl, 1]][0]
    exc.F[off, 1] = 1.0                    # a load at harmonic 1 on an index-0 coordinate
    o = dataclasses.replace(d.options(), stability=False, selection=sel)
    with pytest.raises(ParameterError, match="outside the selection"):
        frf(model, exc, d.omega_start, d.omega_end, o, outputs=d.outputs)
    with pytest.raises(InputError, match="no DoF is a multi-stage"):
        travelling_wave_selection(["cb 1", "N3:UX"], 2, 6, 3)
    pairs = travelling_wave_pairs(d.reduced.labels, pf.QUICK.eo, pf.QUICK.sectors, pf.H)
    with pytest.raises(ParameterError, match="options.pairs: needs options.selection"):
        dataclasses.replace(d.options(), selection=None, pairs=pairs).check()
    bad = pairs.copy()
    bad[:, 0] = bad[:, 1]
    o = dataclasses.replace(d.options(), stability=False, selection=sel, pairs=bad)
    with pytest.raises(ParameterError, match="options.pairs: no pair at harmonic 0"):
        frf(model, d.excitation(), d.omega_start, d.omega_end, o, outputs=d.outputs)
    bad = pairs.copy()
    j = np.flatnonzero(pairs[:, 1])[0]
    bad[j, 1] = np.sign(bad[j, 1]) * (j + 1)                  # to itself: Fortran refuses
    o = dataclasses.replace(d.options(), stability=False, selection=sel, pairs=bad)
    with pytest.raises(ParameterError, match="pair names no other coordinate"):
        frf(model, d.excitation(), d.omega_start, d.omega_end, o, outputs=d.outputs)
