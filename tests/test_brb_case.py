"""The bundled Brake-Reuss beam (cases/brb/, issue 27 item 4): two beams in a lap joint,
free-free on soft strings, gmsh C3D10 mesh, CalculiX matrices.

Fast: the mesh itself (gmsh only): the two beams share no node, the two faces of the lap
coincide node for node, the strings hold each beam on its own.
Slow (gmsh + ccx three times + a Craig-Bampton/GSI reduction of ~10 500 DoFs, about a
minute): `frirom modes` on the case's deck against CalculiX's own eigenfrequencies of the
full FE model, interface stuck (every pair joined by the deck's kt, kn springs: stuck.dat)
and open (free.dat); then the forced response at a low shaker force, whose peak must sit
on the stuck first bending mode of CalculiX with the linear receptance, and at a high
one, whose peak must lie below it (microslip softens the joint) with far less response
per newton (friction damping).
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


@pytest.fixture(scope="module")
def brb_case(tmp_path_factory):
    if shutil.which("ccx") is None:
        pytest.skip("ccx not installed")
    pytest.importorskip("gmsh")
    import build_brb
    out = tmp_path_factory.mktemp("brb")
    build_brb.make(out, "coarse")
    shutil.copy(ROOT / "cases" / "brb" / "brb.toml", out / "brb.toml")
    return out


@pytest.mark.slow
def test_brb_linear_limits_against_calculix(brb_case, monkeypatch):
    from upd import read_eigenfrequencies
    from frirom.deck import load_deck
    from frirom.modes import linear_check
    monkeypatch.setenv("FRIROM_CACHE", str(brb_case / "cache"))
    deck = load_deck(brb_case / "brb.toml")
    # three bolts' 36.75 kN spread over the pairs of the lap (parallel faces: one n0)
    n0 = deck.contacts[0].params[:, 3]
    assert n0 * n0.size == pytest.approx(36750.0, rel=1e-12)
    assert np.ptp(n0) == 0.0
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
    text = text.replace("harmonics = 3", "harmonics = 1").replace("samples = 32",
                                                                  "samples = 16")
    peaks, amps = [], []
    for level in (0.1, 20.0):
        deck = brb_case / f"level{level:g}.toml"
        deck.write_text(text.replace("amplitude = 10.0", f"amplitude = {level}"))
        code = main(["run", str(deck), "--out", str(brb_case / deck.stem), "--quiet"])
        r = FRF.load(brb_case / deck.stem / "frf.h5")
        assert code == 0 and r.complete, r.message
        i = int(np.argmax(r.amp_max[:, 0]))
        assert 0 < i < len(r) - 1
        peaks.append(r.omega[i] / (2 * np.pi))
        amps.append(r.amp_max[i, 0] / level)
    # linear: on CalculiX's tied first bending mode (the curve's point spacing near the
    # peak and the CB error, ~1e-3), with the linear stuck receptance (a sparse solve of
    # the reduced model's K + contact stiffness, no harmonic balance): measured 1e-4
    assert peaks[0] == pytest.approx(f1, rel=3e-3)
    from frirom.deck import load_deck
    from frirom.modes import linear_response
    lin = load_deck(brb_case / "level0.1.toml")
    f = np.linspace(f1 * 0.998, f1 * 1.002, 201)
    r_lin = linear_response(lin, 2 * np.pi * f, stuck=True)[:, 0].max() / 0.1
    assert amps[0] == pytest.approx(r_lin, rel=1e-2)
    assert amps[1] < 0.2 * amps[0]                  # friction damping at 20 N
    # microslip: clearly softer, but still far above the lower end of the range
    assert peaks[1] < peaks[0] * 0.995
    assert peaks[1] > 160.0
