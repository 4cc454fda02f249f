"""GSI interface reduction (Eq. 14-19) on two lattice blocks in contact over a plane."""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from _lattices import two_blocks
from frirom._errors import InputError
from frirom.reduction.interface import (ContactPairs, contact_matrix, guyan_condense,
                                        gsi_basis, local_frames, reduce_interface,
                                        stick_stiffness)

ETA = 0.01          # loss factor of the hysteretic damping used for the FRFs


@pytest.fixture(scope="module")
def joint():
    m = two_blocks(nx=6, ny=4, nz=6, seed=0)
    na = len(m["dofs_a"])
    # tilted contact normals, so that the local frame matters
    normals = np.tile([0.2, -0.1, 1.0], (na, 1))
    pairs = ContactPairs(m["dofs_a"], m["dofs_b"], local_frames(normals),
                         np.tile([3e5, 3e5, 1e6], (na, 1)))
    m["pairs"] = pairs
    m["iface"] = pairs.dofs
    n = m["K"].shape[0]
    m["f"] = np.zeros(n)
    m["f"][m["active"]] = [1.0, 0.5, 0.2]
    return m


def interface_frf(K, M, G, f, omegas):
    """G x(omega) for (K (1 + i eta) - omega^2 M) x = f, by the (exact) modal sum."""
    K = K.toarray() if sp.issparse(K) else np.asarray(K)
    M = M.toarray() if sp.issparse(M) else np.asarray(M)
    lam, phi = sla.eigh(K, M)
    gp = np.asarray(G @ phi)
    pf = phi.T @ f
    den = lam[None, :] * (1 + 1j * ETA) - omegas[:, None] ** 2
    return (pf[None, :] / den) @ gp.T            # (n_omega, n_rows)


def test_contact_matrix_is_local_relative_displacement(joint):
    pairs, n = joint["pairs"], joint["K"].shape[0]
    rng = np.random.default_rng(1)
    x = rng.standard_normal(n)
    u = contact_matrix(pairs, n) @ x
    # independent: displacement of A minus displacement of B in each element's frame
    rel = x[pairs.dofs_a] - x[pairs.dofs_b]                       # (n_elem, 3)
    expect = np.einsum("edc,ec->ed", pairs.frames, rel).ravel()
    assert np.allclose(u, expect, rtol=0, atol=1e-14 * np.abs(expect).max())
    fr = pairs.frames
    assert np.allclose(np.einsum("eij,ekj->eik", fr, fr), np.eye(3)[None], atol=1e-14)
    assert np.allclose(np.cross(fr[:, 0], fr[:, 1]), fr[:, 2], atol=1e-14)


def test_guyan_condensation_matches_flexibility(joint):
    """Static condensation: inverse of the condensed K = master block of K^-1 (exact)."""
    K, M = joint["K"], joint["M"]
    m = np.concatenate([joint["iface"], joint["active"]])
    kc, mc = guyan_condense(K, M, m)
    flex = np.linalg.inv(K.toarray())[np.ix_(m, m)]
    assert np.linalg.norm(np.linalg.inv(kc) - flex) <= 1e-9 * np.linalg.norm(flex)
    assert np.all(np.linalg.eigvalsh(mc) > 0)
    # a CB-like pair (no master/slave stiffness coupling) is returned as its partition
    n = K.shape[0]
    s = np.setdiff1d(np.arange(n), m)
    kcb = K.toarray()
    kcb[np.ix_(m, s)] = 0.0
    kcb[np.ix_(s, m)] = 0.0
    kc2, _ = guyan_condense(kcb, M, m)
    assert np.array_equal(kc2, kcb[np.ix_(m, m)])


@pytest.mark.parametrize("groups", [False, True])
def test_gsi_bases_orthonormal(joint, groups):
    K, M, pairs, iface = joint["K"], joint["M"], joint["pairs"], joint["iface"]
    grp = None
    if groups:        # one group per side of the joint (Eq. 14 per component)
        side_a = np.isin(iface, pairs.dofs_a)
        grp = [np.nonzero(side_a)[0], np.nonzero(~side_a)[0]]
    for nf, ns in ((10, 0), (0, 10), (12, 8)):
        B, info = gsi_basis(K, M, iface, joint["active"], pairs, nf, ns, groups=grp)
        ng = 2 if groups else 1
        assert B.shape == (iface.size, ng * (nf + ns))
        assert np.abs(B.T @ B - np.eye(B.shape[1])).max() < 1e-12
        if groups:    # each mode lives on one side only
            assert np.all((np.abs(B[grp[0]]).sum(0) == 0) | (np.abs(B[grp[1]]).sum(0) == 0))


def test_complete_basis_is_exact_and_g_map_gives_stick_model(joint):
    K, M, pairs, iface, f = joint["K"], joint["M"], joint["pairs"], joint["iface"], joint["f"]
    n = K.shape[0]
    B, _ = gsi_basis(K, M, iface, joint["active"], pairs, iface.size // 2, iface.size // 2)
    assert B.shape[1] == iface.size
    red = reduce_interface(K, M, iface, B)
    G = red.contact_matrix(pairs)
    ks = sp.diags(pairs.stiffness.ravel())
    # forces of stuck elements (f = k u) projected with G^T: the stick springs of the ROM
    k_stick_red = (G.T @ ks @ G).toarray()
    ref = (red.R.T @ stick_stiffness(pairs, n) @ red.R).toarray()
    assert np.linalg.norm(k_stick_red - ref) <= 1e-12 * np.linalg.norm(ref)
    om = np.linspace(500.0, 3000.0, 40)
    gp = contact_matrix(pairs, n)
    full = interface_frf(K + stick_stiffness(pairs, n), M, gp, f, om)
    rom = interface_frf(red.K + k_stick_red, red.M, G, red.project(f), om)
    err = np.linalg.norm(rom - full) / np.linalg.norm(full)
    assert err < 1e-9, err


def test_gsi_frf_error_decreases(joint, capsys):
    """Linear interface FRF (contact relative displacements) of the free and stuck joint."""
    K, M, pairs, iface, f = joint["K"], joint["M"], joint["pairs"], joint["iface"], joint["f"]
    n = K.shape[0]
    ks_full = stick_stiffness(pairs, n)
    w = np.sqrt(sla.eigh((K + ks_full).toarray(), M.toarray(), eigvals_only=True,
                         subset_by_index=[0, 9]))
    om = np.linspace(0.2 * w[0], 1.1 * w[9], 400)         # first ten stuck modes
    gp = contact_matrix(pairs, n)
    ref_stick = interface_frf(K + ks_full, M, gp, f, om)
    ref_free = interface_frf(K, M, gp, f, om)
    ks = sp.diags(pairs.stiffness.ravel())
    rows = []
    for nk in (8, 12, 16, 24, 32):
        B, _ = gsi_basis(K, M, iface, joint["active"], pairs, nk, nk)
        red = reduce_interface(K, M, iface, B)
        G = red.contact_matrix(pairs)
        fr = red.project(f)
        es = interface_frf(red.K + (G.T @ ks @ G).toarray(), red.M, G, fr, om)
        ef = interface_frf(red.K, red.M, G, fr, om)
        rows.append((2 * nk, np.linalg.norm(es - ref_stick) / np.linalg.norm(ref_stick),
                     np.linalg.norm(ef - ref_free) / np.linalg.norm(ref_free)))
    with capsys.disabled():
        print("\nGSI (free+stick) interface FRF error vs unreduced, "
              f"{iface.size} interface DoFs:")
        for r in rows:
            print(f"  n_k = {r[0]:3d}: stuck {r[1]:.3e}  free {r[2]:.3e}")
    es = np.array([r[1] for r in rows])
    ef = np.array([r[2] for r in rows])
    assert np.all(np.diff(es) < 0) and np.all(np.diff(ef) < 0)
    # 64 of 144 interface DoFs: both FRFs within 1 % over the first ten modes
    assert es[-1] < 1e-2 and ef[-1] < 1e-2


def test_bad_input(joint):
    K, M, pairs, iface = joint["K"], joint["M"], joint["pairs"], joint["iface"]
    with pytest.raises(InputError, match="overlap"):
        gsi_basis(K, M, iface, iface[:3], pairs, 4, 4)
    with pytest.raises(InputError, match="not interface DoFs"):
        gsi_basis(K, M, iface[:-6], (), pairs, 4, 4)
    with pytest.raises(InputError, match="contact pairs"):
        gsi_basis(K, M, iface, (), None, 4, 4)
    with pytest.raises(InputError, match="partition"):
        gsi_basis(K, M, iface, (), pairs, 4, 0, groups=[np.arange(10)])
    with pytest.raises(InputError, match="independent"):
        gsi_basis(K, M, iface[:6], (), None, 7, 0)
    with pytest.raises(InputError):
        ContactPairs(pairs.dofs_a, pairs.dofs_b[:, :2], pairs.frames, pairs.stiffness)


def test_aft_on_reduced_contact_map_gives_the_stuck_rom(joint):
    """The AFT evaluates the physical elements from G x_r; G^T f is the ROM's contact force.

    In full stick with the contact closed (large mu and preload), the 'normal2d' forces
    are kt u_t and n0 + kn v: G^T f must equal the stick springs of the ROM assembled from
    the physical pairs, R^T (sum of element springs) R, plus the static preload."""
    contact = pytest.importorskip("frirom.contact")
    K, M, pairs, iface = joint["K"], joint["M"], joint["pairs"], joint["iface"]
    n = K.shape[0]
    B, _ = gsi_basis(K, M, iface, joint["active"], pairs, 10, 10)
    red = reduce_interface(K, M, iface, B)
    G = red.contact_matrix(pairs)
    h = 3
    rng = np.random.default_rng(7)
    xr = 1e-7 * rng.standard_normal((red.K.shape[0], 2 * h + 1))
    u = (G @ xr).reshape(pairs.n_elem, 3, 2 * h + 1)
    kt, kn, n0 = 3e5, 1e6, 1e3
    res = contact.aft("normal2d", u, {"kt": kt, "kn": kn, "mu": 1e3, "n0": n0},
                      n_samples=64, jacobian=False)
    fr = G.T @ res.forces.reshape(-1, 2 * h + 1)
    k_stick = (red.R.T @ stick_stiffness(pairs, n) @ red.R).toarray()
    expect = k_stick @ xr
    pre = np.zeros((pairs.n_elem, 3))
    pre[:, 2] = n0
    expect[:, 0] += G.T @ pre.ravel()
    assert np.abs(res.states[:, 0] - 1).max() == 0          # every element sticks
    assert np.linalg.norm(fr - expect) < 1e-9 * np.linalg.norm(expect)


def test_contact_group_of_reduced_model(joint):
    model = pytest.importorskip("frirom.model")
    K, M, pairs, iface = joint["K"], joint["M"], joint["pairs"], joint["iface"]
    B, _ = gsi_basis(K, M, iface, joint["active"], pairs, 6, 6)
    red = reduce_interface(K, M, iface, B)
    cg = red.contact_group(pairs, "normal2d", [3e5, 1e6, 0.3, 50.0], name="joint")
    assert isinstance(cg, model.ContactGroup)
    assert cg.G.shape == (3 * pairs.n_elem, red.K.shape[0])
    assert abs(cg.G - red.contact_matrix(pairs)).max() == 0
