"""The bundled Brake-Reuss beam (cases/brb/, issue 27 item 4): two beams in a lap joint,
free-free on soft strings, gmsh C3D10 mesh, CalculiX matrices, the bolts' preload from a
static contact solve of the FE model.

Fast: the mesh itself (gmsh only): the two beams share no node, the two faces of the lap
coincide node for node, the strings hold each beam on its own, the washers' footprints
sit on the outer faces over the lap; the static contact solve on a small spring model
whose contact forces follow from statics by hand.
Slow (gmsh + ccx three times + a Craig-Bampton/GSI reduction of ~10 500 DoFs, about a
minute): `frirom modes` on the case's deck against CalculiX's own eigenfrequencies of the
full FE model, interface stuck (the loaded pairs joined by the decks' kt, kn springs:
stuck.dat) and open (free.dat); the forced response at a low and a high shaker force;
the backbone (EPMC, H = 1) from the stuck mode of CalculiX and the mass-proportional
damping's closed form into microslip.
"""

import os
import shutil
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_brb_mesh_pairs_and_bodies():
    pytest.importorskip("gmsh")
    import brb
    ids, xyz, elems, sets = brb.brb_mesh(size=brb.SIZES["coarse"])
    row = {int(i): k for k, i in enumerate(ids)}
    a = xyz[[row[int(n)] for n in sets["CONTACT_A"]]]
    b = xyz[[row[int(n)] for n in sets["CONTACT_B"]]]
    np.testing.assert_array_equal(a, b)                  # node to node, exactly
    h, lap, length = brb.GEOMETRY["height"], brb.GEOMETRY["lap"], brb.GEOMETRY["length"]
    assert np.all(np.abs(a[:, 2] - h / 2) < 1e-9)
    lo, hi = (length - lap) / 2, (length + lap) / 2
    assert a[:, 0].min() == pytest.approx(lo) and a[:, 0].max() == pytest.approx(hi)
    # the beams: elements left of the lap and right of it, joined through shared nodes
    # nowhere (a graph walk from one end never reaches the other end)
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components
    k = np.array([row[int(n)] for n in elems.ravel()]).reshape(elems.shape)
    i = np.repeat(np.arange(len(elems)), 10)
    g = sp.csr_matrix((np.ones(k.size), (i, k.ravel())), shape=(len(elems), len(ids)))
    n, lab = connected_components(g @ g.T, directed=False)
    assert n == 2
    side = {lab[np.flatnonzero((k == row[int(sets[s][0])]).any(axis=1))[0]]
            for s in ("EXC", "OUT")}
    assert len(side) == 2
    # the strings: nodes on both beams' top faces
    s = xyz[[row[int(n)] for n in sets["SUSP"]]]
    assert np.all(np.abs(s[:, 2] - h) < 1e-9)
    assert (s[:, 0] < length / 2).any() and (s[:, 0] > length / 2).any()
    # the washers: B's top face and A's bottom face over the lap, within the washer's
    # radius of the three bolts' axes, on both sides of every bolt
    for name, z in (("WASHER_A", 0.0), ("WASHER_B", h)):
        w = xyz[[row[int(n)] for n in sets[name]]]
        assert np.all(np.abs(w[:, 2] - z) < 1e-9)
        r = np.min(np.hypot(w[:, [0]] - brb.bolt_centres()[None, :],
                            w[:, [1]] - brb.GEOMETRY["width"] / 2), axis=1)
        assert r.max() <= brb.BOLTS["washer"] + 1e-9
        for c in brb.bolt_centres():
            mine = w[np.abs(w[:, 0] - c) < brb.BOLTS["washer"]]
            assert (mine[:, 0] < c).any() and (mine[:, 0] > c).any()


def test_bolt_hardware_against_hand_numbers():
    import brb
    m, k = brb.bolt_hardware()
    # by hand: head and nut 6.5e-7 m^3 and 5.3e-7 m^3 less the shank's hole, shank
    # 1.88e-6 m^3, washers 2 x 2.8e-7 m^3, steel 7800 kg/m^3: ~28 g; shank EA / grip
    # with A = pi (3.97 mm)^2, grip 28.6 mm: 3.46e8 N/m at 200 GPa
    assert m == pytest.approx(0.0284, rel=0.03)
    assert k == pytest.approx(200e9 * np.pi * (0.15625 * 0.0254) ** 2 / 0.028575, rel=1e-12)


def test_static_preload_of_two_rigid_blocks_against_statics():
    """Two rigid blocks (z motion: translation and tilt only) on three contact pairs at
    x = 0, 1, 2, clamped by one bolt at x = c. Statics by hand: the contact forces are
    linear in x where closed, sum to P and have their centroid at c. c = 0.25: pairs 0
    and 1 carry 3/4 and 1/4 of P, pair 2 would pull and opens; c = 0.5: all three closed,
    (7, 4, 1) / 12 of P."""
    import scipy.sparse as sp
    import brb_preload as bp
    from frirom.io._common import FEModel
    x = np.array([0.0, 1.0, 2.0, 0.0])           # node 4 of each block: the washer
    P, kb, kp = 1000.0, 1e16, 1e10
    for c, expect, closed in ((0.25, [0.75, 0.25, 0.0], 2),
                              (0.5, [7 / 12, 4 / 12, 1 / 12], 3)):
        x[3] = c
        q, _ = np.linalg.qr(np.column_stack([np.ones(4), x]))
        rigid = kb * (np.eye(4) - q @ q.T)       # resists all but translation and tilt
        K = np.kron(np.eye(2), rigid) + np.eye(8)   # + the strings, 1 N/m
        ids = np.arange(1, 9)
        fe = FEModel(K=sp.csr_matrix(K), M=sp.identity(8, format="csr"),
                     dofs=np.column_stack([ids, np.full(8, 3)]))
        fe.node_ids = ids
        fe.coords = np.array([[v, 0.0, 0.0] for v in x] * 2)
        fe.node_sets = {"CONTACT_A": ids[:3], "CONTACT_B": ids[4:7],
                        "WASHER_A": ids[[3]], "WASHER_B": ids[[7]]}
        n0, info = bp.static_preload(fe, [c], load=P, kp=kp)
        assert info["closed"] == closed
        np.testing.assert_allclose(n0, P * np.array(expect), rtol=1e-6, atol=1e-6 * P)


@pytest.fixture(scope="module")
def brb_case(tmp_path_factory):
    if shutil.which("ccx") is None:
        pytest.skip("ccx not installed")
    pytest.importorskip("gmsh")
    import build_brb
    out = tmp_path_factory.mktemp("brb")
    for d in build_brb.DECKS:
        shutil.copy(ROOT / "cases" / "brb" / d, out / d)
    build_brb.make(out, "coarse", deck_dir=out)
    return out


@pytest.mark.slow
def test_brb_linear_limits_against_calculix(brb_case, monkeypatch):
    from upd import read_eigenfrequencies
    from frirom.deck import load_deck
    from frirom.modes import linear_check
    monkeypatch.setenv("FRIROM_CACHE", str(brb_case / "cache"))
    deck = load_deck(brb_case / "brb.toml")
    # the three bolts' loads carried by the contact groups, most near the bolts
    import brb_preload as bp
    n0 = np.concatenate([c.params[:, 3] for c in deck.contacts])
    assert n0.sum() == pytest.approx(3 * bp.BOLT_LOAD, rel=1e-6)
    assert n0.max() > 20 * n0.min() > 0
    chk = linear_check(deck, n_grid=10, n_show=3)
    stuck_ref = read_eigenfrequencies(brb_case / "stuck.dat")
    free_ref = read_eigenfrequencies(brb_case / "free.dat")
    elastic = stuck_ref[stuck_ref > 50.0]     # above the six string modes (< 10 Hz)
    stuck = chk.stuck / 2 / np.pi
    free = chk.free / 2 / np.pi
    # the two bending modes around the band: normal to the lap (the one of the case) and
    # in its plane; Craig-Bampton with 20 fixed-interface modes: measured 3e-5 to 5e-5
    near = stuck[stuck > 50.0][:2]
    np.testing.assert_allclose(near, elastic[:2], rtol=2e-4)
    f_free = free[free > 50.0][:2]
    np.testing.assert_allclose(f_free, free_ref[free_ref > 50.0][:2], rtol=2e-4)
    assert "WARNING" not in "\n".join(chk.notes)


@pytest.mark.slow
def test_brb_forced_response_softens_with_level(brb_case, monkeypatch):
    from upd import read_eigenfrequencies
    from frirom.cli import main
    from frirom.results import FRF
    monkeypatch.setenv("FRIROM_CACHE", str(brb_case / "cache"))
    f_stuck = read_eigenfrequencies(brb_case / "stuck.dat")
    f1 = f_stuck[f_stuck > 50.0][0]
    text = (brb_case / "brb.toml").read_text().split("\n[study]")[0]
    text = text.replace("harmonics = 3", "harmonics = 1\ntol_stall = 2e-6")
    # brb_mode.toml's interface reduction (GSI 60 + 60), so that the forced responses and
    # the backbone below are of one reduced model
    assert "free = 20\nstick = 20" in text
    text = text.replace("free = 20\nstick = 20", "free = 60\nstick = 60")
    peaks, amps = [], []
    for level in (0.0005, 0.3):
        deck = brb_case / f"level{level:g}.toml"
        deck.write_text(text.replace("amplitude = 0.1", f"amplitude = {level}"))
        code = main(["run", str(deck), "--out", str(brb_case / deck.stem), "--quiet"])
        r = FRF.load(brb_case / deck.stem / "frf.h5")
        assert code == 0 and r.complete, r.message
        i = int(np.argmax(r.amp_max[:, 0]))
        assert 0 < i < len(r) - 1
        peaks.append(r.omega[i] / (2 * np.pi))
        amps.append(r.amp_max[i, 0] / level)
    # linear (0.0005 N, tip ~0.3 m/s^2): on CalculiX's stuck first bending mode (the
    # curve's point spacing near the peak and the CB error, ~1e-3), with the linear stuck
    # receptance (a sparse solve of the reduced model's K + contact stiffness, no
    # harmonic balance)
    assert peaks[0] == pytest.approx(f1, rel=3e-3)
    from frirom.deck import load_deck
    from frirom.modes import linear_response
    lin = load_deck(brb_case / "level0.0005.toml")
    f = np.linspace(f1 * 0.998, f1 * 1.002, 201)
    r_lin = linear_response(lin, 2 * np.pi * f, stuck=True)[:, 0].max() / 0.0005
    assert amps[0] == pytest.approx(r_lin, rel=1e-2)
    assert amps[1] < 0.5 * amps[0]                  # friction damping at 0.3 N
    assert peaks[1] < peaks[0] * 0.995              # microslip softens the joint
    # phase resonance: the peak of the forced response lies on the backbone (EPMC of
    # the same deck, H = 1) at the peak's tip acceleration; the load is not the mode's
    # shape, so only to within the backbone's slope over the peak's width.
    import run_brb
    bb, _, _ = run_brb.backbone(brb_case / "brb_mode.toml", harmonics=1,
                                amplitudes=(5e-8, 1.5e-4), check_start=False)
    r = FRF.load(brb_case / "level0.3" / "frf.h5")
    i = int(np.argmax(r.amp_max[:, 0]))
    acc = r.omega[i] ** 2 * r.amp_max[i, 1]          # OUT:z, the far tip
    (f_bb, _), = run_brb.at_accelerations(bb, (acc,))
    assert peaks[1] == pytest.approx(f_bb, rel=5e-3)


@pytest.mark.slow
def test_brb_backbone_from_the_stuck_mode_into_microslip(brb_case, monkeypatch):
    """The EPMC backbone at H = 1 (brb_mode.toml; ~20 s): its low-amplitude end is the
    stuck first bending mode of CalculiX's full model (the CB error, measured 4e-6) with
    the damping ratio of the mass-proportional damping, alpha / (2 omega) (EPMC of a
    linear system: exact to the solver's tolerance); then the joint slips: the frequency
    falls and the damping ratio rises monotonically into microslip."""
    import run_brb
    from upd import read_eigenfrequencies
    monkeypatch.setenv("FRIROM_CACHE", str(brb_case / "cache"))
    bb, deck, _ = run_brb.backbone(brb_case / "brb_mode.toml", harmonics=1,
                                   amplitudes=(5e-8, 1e-4))
    assert bb.status == "done", bb.message
    f1 = read_eigenfrequencies(brb_case / "stuck.dat")[6]
    assert bb.frequency[0] == pytest.approx(f1, rel=2e-4)
    alpha = deck.settings.damping.alpha
    assert bb.damping_ratio[0] == pytest.approx(alpha / (4 * np.pi * bb.frequency[0]),
                                                rel=1e-6)
    assert np.all(np.diff(bb.frequency) <= 1e-9 * f1)
    assert bb.frequency[-1] < 0.98 * f1
    assert bb.damping_ratio[-1] > 10 * bb.damping_ratio[0]
    acc = run_brb.at_accelerations(bb)
    assert np.all(np.isfinite(acc))
