"""Cyclic symmetry: sector projection per harmonic index, Tran's boundary reduction and
engine-order excitation, checked against a full 360-degree lattice rotor and against
CalculiX's *CYCLIC SYMMETRY MODEL eigenvalues of a bladed-disk sector with a flange."""

import os
import shutil

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.linalg as sla

from _lattices import stuck_rotor
from frirom._errors import InputError
from frirom.io import read_calculix
from frirom.reduction.cyclic import cyclic_sector, tran_reduce
from frirom.reduction.interface import ContactPairs, stick_stiffness

import bladed_sector  # cases/models/bladed_sector.py

AXIS = (0.3, 0.2, 1.0)
ORIGIN = (0.5, -0.2, 0.1)
ETA = 0.01


@pytest.fixture(scope="module")
def rotor():
    r = stuck_rotor(AXIS, ORIGIN)
    s = r["sector"]
    ns = s["K"].shape[0]
    g = ContactPairs(s["node_dofs"][s["ground_nodes"]], -np.ones((len(s["ground_nodes"]), 3),
                     int), s["ground_frames"], r["k_ground"][: len(s["ground_nodes"])])
    s["Kt"] = s["K"] + stick_stiffness(g, ns)
    c = r["coords"][s["nodes"]]
    s["cs"] = cyclic_sector(c[s["left"]], s["node_dofs"][s["left"]], c[s["right"]],
                            s["node_dofs"][s["right"]], 7, ns, origin=ORIGIN, axis=AXIS)
    return r


def test_all_harmonic_indices_give_the_full_rotor_spectrum(rotor):
    """The union over k = 0..N-1 of the sector spectra is the spectrum of the whole rotor."""
    s = rotor["sector"]
    cs = s["cs"]
    lam = np.sort(np.concatenate([sla.eigh(*(A.toarray() for A in cs.matrices(s["Kt"],
                                  s["M"], k)), eigvals_only=True) for k in range(7)]))
    full = sla.eigh(rotor["Kt"], rotor["M"].toarray(), eigvals_only=True)
    assert lam.size == full.size
    assert np.abs(lam / full - 1).max() < 1e-10
    # k and N - k are complex conjugates (same frequencies); the real form doubles them
    f2 = cs.frequencies(s["Kt"], s["M"], 2, 6)
    f5 = cs.frequencies(s["Kt"], s["M"], 5, 6)
    assert np.abs(f2 / f5 - 1).max() < 1e-12
    kr, mr = cs.matrices(s["Kt"], s["M"], 2, real=True)
    lr = sla.eigh(kr.toarray(), mr.toarray(), eigvals_only=True)[:12]
    assert np.abs(np.sqrt(lr[::2]) / (2 * np.pi) / f2 - 1).max() < 1e-10
    assert np.abs(lr[::2] / lr[1::2] - 1).max() < 1e-10


@pytest.mark.parametrize("eo,sign", [(2, -1), (5, -1), (9, -1), (0, -1), (2, 1), (4, 1)])
def test_engine_order_travelling_wave_matches_full_rotor(rotor, eo, sign):
    """Sector solution of an EO wave, expanded to every sector = full-rotor response."""
    s, cs = rotor["sector"], rotor["sector"]["cs"]
    n_sec, alpha = 7, 2 * np.pi / 7
    tip0 = rotor["tips"][0]
    f_dir = np.array([0.4, -1.0, 0.7]) + 1j * np.array([0.1, 0.3, -0.2])
    full_f = np.zeros(rotor["K"].shape[0], complex)
    for q, tip in enumerate(rotor["tips"]):
        full_f[rotor["dofs"][tip]] = np.linalg.matrix_power(cs.Q, q) @ f_dir * \
            np.exp(sign * 1j * eo * q * alpha)
    om = 1.01 * np.sqrt(sla.eigh(rotor["Kt"], rotor["M"].toarray(), eigvals_only=True,
                                 subset_by_index=[4, 4])[0])
    x_full = np.linalg.solve(rotor["Kt"] * (1 + 1j * ETA) - om**2 * rotor["M"].toarray(),
                             full_f)
    f0 = np.zeros(s["K"].shape[0], complex)
    p0 = int(np.nonzero(s["nodes"] == tip0)[0][0])
    f0[s["node_dofs"][p0]] = f_dir
    k, fk = cs.travelling_wave_load(f0, eo, sign)
    assert k == (sign * eo) % n_sec
    kk, mk = cs.matrices(s["Kt"], s["M"], k)
    y = np.linalg.solve(kk.toarray() * (1 + 1j * ETA) - om**2 * mk.toarray(), fk)
    coords0 = rotor["coords"][s["nodes"]] - np.asarray(ORIGIN)
    full_xyz = rotor["coords"] - np.asarray(ORIGIN)
    err = 0.0
    for q in range(n_sec):
        xs = cs.expand(y, k, q, s["node_dofs"])
        pos = coords0 @ np.linalg.matrix_power(cs.Q, q).T
        d = np.linalg.norm(pos[:, None, :] - full_xyz[None, :, :], axis=2)
        match = np.argmin(d, axis=1)
        assert d[np.arange(len(match)), match].max() < 1e-9
        ref = x_full[rotor["dofs"][match]]
        err = max(err, np.abs(xs[s["node_dofs"]] - ref).max())
    assert err < 1e-10 * np.abs(x_full).max(), err


def test_tran_reduction_converges(rotor, capsys):
    s, cs = rotor["sector"], rotor["sector"]["cs"]
    kk, mk = cs.matrices(s["Kt"], s["M"], 2)
    exact = sla.eigh(kk.toarray(), mk.toarray(), eigvals_only=True, subset_by_index=[0, 9])
    b = cs.boundary
    assert b.size == 27
    errs = []
    for nu in (3, 6, 12, 20, 27):
        kr, mr, R, _ = tran_reduce(kk, mk, b, nu)
        lam = sla.eigh(kr, mr, eigvals_only=True, subset_by_index=[0, 9])
        assert np.all(lam >= exact * (1 - 1e-12))         # Rayleigh-Ritz: from above
        errs.append(np.abs(lam / exact - 1).max())
    with capsys.disabled():
        print("\nTran boundary reduction, k = 2, max rel. eigenvalue error of 10 modes: "
              + ", ".join(f"n_u={nu}: {e:.2e}" for nu, e in zip((3, 6, 12, 20, 27), errs)))
    assert np.all(np.diff(errs) < 0) and errs[-1] < 1e-10


def test_boundary_errors(rotor):
    s = rotor["sector"]
    c = rotor["coords"][s["nodes"]]
    nd = s["node_dofs"]
    ns = s["K"].shape[0]
    bad = c[s["right"]].copy()
    bad[3] += 1e-3
    with pytest.raises(InputError, match="do not match"):
        cyclic_sector(c[s["left"]], nd[s["left"]], bad, nd[s["right"]], 7, ns,
                      origin=ORIGIN, axis=AXIS)
    with pytest.raises(InputError, match="do not match"):
        cyclic_sector(c[s["left"]], nd[s["left"]], c[s["right"]], nd[s["right"]], 8, ns,
                      origin=ORIGIN, axis=AXIS)
    fixed = nd[s["right"]].copy()
    fixed[2] = -1
    with pytest.raises(InputError, match="dependent"):
        cyclic_sector(c[s["left"]], nd[s["left"]], c[s["right"]], fixed, 7, ns,
                      origin=ORIGIN, axis=AXIS)


N_SEC, N_PAIRS = 12, 8


@pytest.fixture(scope="module")
def ccx_sector(tmp_path_factory):
    """ccx's cyclic eigenvalues per nodal diameter and the sector's matrices."""
    if shutil.which("ccx") is None:
        pytest.skip("ccx (calculix-ccx) not installed")
    out = tmp_path_factory.mktemp("sector")
    cyc, sec = bladed_sector.write_sector_decks(out, N_SEC, n_modes=2 * N_PAIRS)
    bladed_sector.run_ccx(cyc, expect=(".dat",))
    bladed_sector.run_ccx(sec, expect=(".sti", ".mas", ".dof"))
    ref = bladed_sector.read_cyclic_eigenvalues(out / "cyclic.dat")
    return ref, read_calculix(out / "sector")


def _node_dofs(m, nodes):
    key = {(a, b): i for i, (a, b) in enumerate(m.dofs)}
    return np.array([[key.get((nd, c), -1) for c in (1, 2, 3)] for nd in nodes])


def test_bladed_sector_matches_ccx_cyclic_symmetry(ccx_sector, capsys):
    """frirom's cyclic projection of ccx's own sector matrices vs ccx's cyclic model."""
    ref, m = ccx_sector
    n_sec, n_pairs = N_SEC, N_PAIRS
    assert sorted(ref) == list(range(n_sec // 2 + 1))

    def node_dofs(nodes):
        return _node_dofs(m, nodes)

    L, R = m.node_sets["LEFT"], m.node_sets["RIGHT"]
    # ccx's slave (dependent) surface is LEFT; the flange nodes on RIGHT are clamped
    cs = cyclic_sector(m.coordinates(L), node_dofs(L), m.coordinates(R), node_dofs(R),
                       n_sec, m.n_dof, nodes_left=L, nodes_right=R, dependent="left")
    worst = {}
    for k, lam in sorted(ref.items()):
        f_ccx = np.sqrt(lam) / (2 * np.pi)
        f = cs.frequencies(m.K, m.M, k, len(lam))
        worst[k] = np.abs(f / f_ccx - 1).max()
        if k in (0, 5):       # the sparse shift-invert path (large sectors) agrees
            fa = cs.frequencies(m.K, m.M, k, len(lam), method="arpack")
            assert np.abs(fa / f - 1).max() < 1e-9
    with capsys.disabled():
        print(f"\nccx cyclic sector ({m.n_dof} DoFs, {n_pairs} modes per ND): max rel. "
              "frequency error per ND: "
              + ", ".join(f"{k}: {e:.1e}" for k, e in worst.items()))
    # ccx prints eigenvalues with 7 significant digits: 1e-6 leaves room for that rounding
    assert max(worst.values()) < 1e-6
    # the dependent surface must be the unconstrained one
    with pytest.raises(InputError, match="dependent"):
        cyclic_sector(m.coordinates(L), node_dofs(L), m.coordinates(R), node_dofs(R),
                      n_sec, m.n_dof, dependent="right")


def test_cb_sector_with_tran_reduction_converges_to_ccx(ccx_sector, capsys):
    """CB of the sector (masters: both cyclic boundaries and the blade tip), projected per
    nodal diameter: frequencies converge to ccx's as fixed-interface modes are added, and
    Tran's boundary modes converge to the unreduced boundary."""
    from frirom.reduction.cb import craig_bampton
    ref, m = ccx_sector
    L, R = m.node_sets["LEFT"], m.node_sets["RIGHT"]
    masters = m.dof_indices(["LEFT", "RIGHT", "TIP"], missing="ignore")
    errs, tran = [], []
    for n_modes in (10, 20, 40):
        cb = craig_bampton(m, n_modes, masters=masters)
        pos = -np.ones(m.n_dof, np.int64)
        pos[cb.master_index] = np.arange(cb.n_masters)

        def cb_dofs(nodes):
            d = _node_dofs(m, nodes)
            return np.where(d >= 0, pos[np.maximum(d, 0)], -1)

        cs = cyclic_sector(m.coordinates(L), cb_dofs(L), m.coordinates(R), cb_dofs(R), N_SEC,
                           cb.K.shape[0], dependent="left")
        worst = 0.0
        for k, lam in ref.items():
            f = cs.frequencies(cb.K, cb.M, k, 4)
            f_ccx = np.sqrt(lam[:4]) / (2 * np.pi)
            assert np.all(f >= f_ccx * (1 - 1e-6))               # Rayleigh-Ritz bound
            worst = max(worst, np.abs(f / f_ccx - 1).max())
        errs.append(worst)
    kk, mk = cs.matrices(cb.K, cb.M, 3)
    exact = sla.eigh(kk.toarray(), mk.toarray(), eigvals_only=True, subset_by_index=[0, 3])
    for nu in (5, 10, 20, 40):
        kr, mr, _, _ = tran_reduce(kk, mk, cs.boundary, nu)
        lam = sla.eigh(kr, mr, eigvals_only=True, subset_by_index=[0, 3])
        tran.append(np.abs(np.sqrt(lam / exact) - 1).max())
    with capsys.disabled():
        print("\nCB sector vs ccx cyclic, max rel. freq. error of 4 modes x 7 NDs: "
              + ", ".join(f"{n} modes {e:.1e}" for n, e in zip((10, 20, 40), errs))
              + "\nTran (ND 3, CB 40): " + ", ".join(f"n_u={n} {e:.1e}" for n, e in
                                                    zip((5, 10, 20, 40), tran)))
    assert np.all(np.diff(errs) < 0) and errs[-1] < 1e-4
    assert np.all(np.diff(tran) < 0) and tran[-1] < 1e-5
