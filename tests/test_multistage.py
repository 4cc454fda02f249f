"""Multi-stage spatial-Fourier interface reduction (Eq. 20-23) on tuned lattice rotors."""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from _lattices import stuck_rotor, tuned_rotor
from frirom._errors import InputError
from frirom.reduction.interface import (ContactPairs, contact_matrix, reduce_interface,
                                        stick_stiffness)
from frirom.reduction.multistage import (assemble, fourier_columns, fourier_matrix,
                                         harmonic_indices, ms_basis, radial_line_segments,
                                         stage_contact_matrix, stage_indices)

AXIS = (0.3, 0.2, 1.0)          # a tilted rotor axis off the origin: the frame matters
ORIGIN = (0.5, -0.2, 0.1)
ETA = 0.01


@pytest.mark.parametrize("nz", [1, 2, 7, 12, 21])
def test_fourier_matrix_orthonormal_and_ordered(nz):
    F = fourier_matrix(nz)
    assert np.abs(F.T @ F - np.eye(nz)).max() < 1e-13
    k = np.arange(nz)
    phi = 2 * np.pi * k / nz
    rbar = nz // 2
    # Eq. 22: a0, c1 .. c_{Rbar} (alternating column last when NZ even), s_{..} .. s1
    assert np.allclose(F[:, 0], 1 / np.sqrt(nz))
    if nz >= 3:
        assert np.allclose(F[:, 1], np.sqrt(2 / nz) * np.cos(phi))
        assert np.allclose(F[:, -1], np.sqrt(2 / nz) * np.sin(phi))
    if nz % 2 == 0 and nz > 1:
        assert np.allclose(F[:, rbar], (-1.0) ** k / np.sqrt(nz))
    if nz >= 5:
        assert np.allclose(F[:, 2], np.sqrt(2 / nz) * np.cos(2 * phi))
        assert np.allclose(F[:, -2], np.sqrt(2 / nz) * np.sin(2 * phi))
    assert fourier_columns(nz, range(rbar + 1)).tolist() == list(range(nz))


@pytest.mark.parametrize("n_sec,z,eo,j", [(7, 3, 2, 1), (7, 3, 2, 2), (8, 2, 3, 3),
                                          (6, 4, 3, 1), (5, 4, 0, 1), (9, 2, 4, 0)])
def test_harmonic_indices_match_spectrum_of_travelling_wave(n_sec, z, eo, j):
    """Indices = the DFT bins (folded to 0..NZ/2) of a sector-periodic wave of index j*EO."""
    nz = n_sec * z
    rng = np.random.default_rng(3)
    g = rng.standard_normal(z) + 1j * rng.standard_normal(z)    # arbitrary in-sector shape
    k = np.arange(nz)
    x = g[k % z] * np.exp(2j * np.pi * j * eo * (k // z) / n_sec)
    spec = np.abs(np.fft.fft(x.real)) + np.abs(np.fft.fft(x.imag))
    bins = {min(b, nz - b) for b in np.nonzero(spec > 1e-9 * spec.max())[0]}
    assert set(harmonic_indices(eo, n_sec, nz, [j]).tolist()) == bins


@pytest.fixture(scope="module")
def rotor():
    r = stuck_rotor(AXIS, ORIGIN)
    r["Md"] = r["M"].toarray()
    r["lam"] = sla.eigh(r["Kt"], r["Md"], eigvals_only=True)
    return r


def _basis(r, indices, **kw):
    nodes = r["iface_nodes"]
    return ms_basis(r["coords"][nodes], r["dofs"][nodes], r["n_sectors"], indices,
                    origin=ORIGIN, axis=AXIS, **kw)


def _travelling_wave(r, eo):
    n = r["K"].shape[0]
    f = np.zeros(n, complex)
    for s, tip in enumerate(r["tips"]):
        th = 2 * np.pi * s / r["n_sectors"]
        v = r["rot"] @ np.array([np.cos(th), np.sin(th), 0.4])    # rotates with the sector
        f[r["dofs"][tip]] = v * np.exp(1j * eo * th)
    return f


def test_segments_found_and_basis_orthonormal(rotor):
    nodes = rotor["iface_nodes"]
    seg = radial_line_segments(rotor["coords"][nodes], 7, ORIGIN, AXIS)
    assert seg.nodes.shape == (21, 3) and seg.per_sector == 3
    assert not seg.equally_spaced          # the rotor's in-sector stations are irregular
    ms = _basis(rotor, range(11))          # all indices: a square orthogonal transformation
    assert ms.basis.shape == (189, 189)
    assert np.abs(ms.basis.T @ ms.basis - np.eye(189)).max() < 1e-13
    ms = _basis(rotor, [2, 5, 9])
    assert ms.basis.shape == (189, 54)
    assert np.abs(ms.basis.T @ ms.basis - np.eye(54)).max() < 1e-13


@pytest.mark.parametrize("eo", [0, 2, 3])
def test_ms_exact_for_tuned_rotor_under_travelling_wave(rotor, eo):
    K, M = rotor["Kt"], rotor["Md"]
    f = _travelling_wave(rotor, eo)
    om = 1.01 * np.sqrt(rotor["lam"][5])
    x = np.linalg.solve(K * (1 + 1j * ETA) - om**2 * M, f)
    idx = harmonic_indices(eo, 7, 21)
    red = reduce_interface(K, M, _basis(rotor, idx).interface, _basis(rotor, idx).basis)
    xr = np.linalg.solve(red.K * (1 + 1j * ETA) - om**2 * red.M, red.project(f))
    err = np.linalg.norm(red.expand(xr) - x) / np.linalg.norm(x)
    assert err < 1e-10, err
    # dropping one index of the aliasing family is not exact
    ms = _basis(rotor, idx[:-1] if idx.size > 1 else [1])
    red = reduce_interface(K, M, ms.interface, ms.basis)
    xr = np.linalg.solve(red.K * (1 + 1j * ETA) - om**2 * red.M, red.project(f))
    assert np.linalg.norm(red.expand(xr) - x) / np.linalg.norm(x) > 1e-3


def test_ms_frf_error_decreases_with_indices(rotor, capsys):
    """A force on one blade excites every index; keep the families of harmonic indices
    H = 0..m (Eq. 1, all their aliases), interface FRF error vs the full model."""
    K, M = rotor["Kt"], rotor["Md"]
    n = K.shape[0]
    f = np.zeros(n)
    f[rotor["dofs"][rotor["tips"][0]]] = [1.0, 0.3, 0.5]
    lam = rotor["lam"]
    om = np.linspace(0.5 * np.sqrt(lam[0]), 1.05 * np.sqrt(lam[30]), 150)
    gp = contact_matrix(rotor["pairs"], n)

    def frf(k, m, g, ff):
        w, phi = sla.eigh(k, m)
        den = w[None, :] * (1 + 1j * ETA) - om[:, None] ** 2
        return ((phi.T @ ff)[None, :] / den) @ np.asarray(g @ phi).T

    ref = frf(K, M, gp, f)
    errs = []
    for m in range(4):          # harmonic index families H = 0..m of the 7 sectors
        ms = _basis(rotor, harmonic_indices(range(m + 1), 7, 21))
        red = reduce_interface(K, M, ms.interface, ms.basis)
        x = frf(red.K, red.M, red.contact_matrix(rotor["pairs"]), red.project(f))
        errs.append((m, ms.basis.shape[1], np.linalg.norm(x - ref) / np.linalg.norm(ref)))
    with capsys.disabled():
        print("\nMS interface FRF error vs unreduced (189 interface DoFs), single-blade force:")
        for m, nk, e in errs:
            print(f"  H = 0..{m} (n_k = {nk:3d}): {e:.3e}")
    e = np.array([x[2] for x in errs])
    assert np.all(np.diff(e) < 0)
    assert e[-1] < 1e-10          # all families: the full square transformation


def test_not_cyclic_interface_is_reported(rotor):
    nodes = rotor["iface_nodes"]
    x = rotor["coords"][nodes].copy()
    with pytest.raises(InputError, match="not a multiple of the 5 sectors"):
        radial_line_segments(x, 5, ORIGIN, AXIS)
    with pytest.raises(InputError, match="segment 1 .* has 3 nodes, segment 0 has 2"):
        radial_line_segments(x[1:], 7, ORIGIN, AXIS)
    y = x.copy()
    y[4] += 0.01 * np.asarray(AXIS) / np.linalg.norm(AXIS)      # one node moved axially
    with pytest.raises(InputError, match="not at the radial and axial positions"):
        radial_line_segments(y, 7, ORIGIN, AXIS)
    with pytest.raises(InputError, match="harmonic indices must lie"):
        _basis(rotor, [11])


def _stage(n_sec, z, seed):
    return tuned_rotor(n_sectors=n_sec, per_sector=z, uniform=True, seed=seed, axis=AXIS,
                       origin=ORIGIN, n_axial=2)


def test_two_stages_non_matching_meshes_on_common_harmonics():
    """Stage A: 6 sectors x 4 segments, stage B: 8 sectors x 2 (NZ 24 vs 16, non-matching).

    The contact map must give zero relative displacement for any common physical field of
    spatial index < 8 (rigid translations, rotation about the axis, cos/sin(h theta)
    patterns), and the imposed gap for an axial separation.
    """
    a, b = _stage(6, 4, 1), _stage(8, 2, 2)
    keep = range(0, 8)                          # indices both stages resolve
    msa = ms_basis(a["coords"][a["iface_nodes"]], a["dofs"][a["iface_nodes"]], 6, keep,
                   origin=ORIGIN, axis=AXIS)
    msb = ms_basis(b["coords"][b["iface_nodes"]], b["dofs"][b["iface_nodes"]], 8, keep,
                   origin=ORIGIN, axis=AXIS)
    ra = reduce_interface(a["K"], a["M"], msa.interface, msa.basis)
    rb = reduce_interface(b["K"], b["M"], msb.interface, msb.basis)
    both = assemble([ra, rb])
    na = msa.segments.nodes.size
    frames = a["frames"][msa.segments.nodes.ravel()]
    G = stage_contact_matrix(msa, msb, frames, ra.K.shape[0], rb.K.shape[0])
    assert G.shape == (3 * na, both.K.shape[0])
    rot = a["rot"]

    def coords_cyl(r):
        loc = (r["coords"][r["iface_nodes"]] - np.asarray(ORIGIN)) @ rot
        return np.arctan2(loc[:, 1], loc[:, 0]), loc

    def field(r, fn):
        th, loc = coords_cyl(r)
        x = np.zeros(r["K"].shape[0])
        x[r["dofs"][r["iface_nodes"]]] = fn(th, loc)
        return x

    def reduced(x, ms, red):      # interface modal coordinates of a field in the span
        eta = ms.basis.T @ x[ms.interface]
        assert np.linalg.norm(ms.basis @ eta - x[ms.interface]) < 1e-10 * np.linalg.norm(x)
        return np.concatenate([eta, x[red.kept]])

    cases = {
        "translation": lambda th, loc: np.tile(rot @ [0.3, -0.2, 0.1], (len(th), 1)),
        "rotation": lambda th, loc: (np.cross(rot[:, 2], loc @ rot.T)),
        "index 3": lambda th, loc: np.cos(3 * th)[:, None] * np.column_stack(
            [np.cos(th), np.sin(th), 0 * th]) @ rot.T,
        "index 7": lambda th, loc: np.sin(7 * th + 0.3)[:, None] * rot[:, 2][None, :],
    }
    for name, fn in cases.items():
        xa, xb = field(a, fn), field(b, fn)
        q = np.concatenate([reduced(xa, msa, ra), reduced(xb, msb, rb)])
        rel = G @ q
        assert np.abs(rel).max() < 1e-12 * np.abs(q).max(), name
    # stage B moved by 1e-3 along the axis: every element opens by -1e-3 along its normal
    xb = field(b, lambda th, loc: np.tile(1e-3 * rot[:, 2], (len(th), 1)))
    q = np.concatenate([np.zeros(ra.K.shape[0]), reduced(xb, msb, rb)])
    rel = (G @ q).reshape(-1, 3)
    assert np.allclose(rel[:, 2], -1e-3, rtol=0, atol=1e-15)
    assert np.abs(rel[:, :2]).max() < 1e-15



@pytest.mark.parametrize("eo", [1, 2, 3])
def test_two_stages_different_sector_counts_exact_under_travelling_wave(eo):
    """Stage A (6 sectors x 4 segments) stuck to stage B (12 sectors x 2 segments) by
    contact springs at coincident interface nodes. The assembly is cyclic with
    gcd(6, 12) = 6 sectors, so an EO wave on stage A's blades excites, on both stages, the
    indices +-EO mod 6: the MS model that keeps them (with the contact map evaluated on
    common harmonics) reproduces the full physical model."""
    a, b = _stage(6, 4, 1), _stage(12, 2, 2)
    na, nb = a["K"].shape[0], b["K"].shape[0]
    ia, ib = a["iface_nodes"], b["iface_nodes"]
    # physical model: block-diagonal stages + stick springs between coincident nodes
    d = np.linalg.norm(a["coords"][ia][:, None] - b["coords"][ib][None], axis=2)
    match = ib[np.argmin(d, axis=1)]
    assert d.min(axis=1).max() < 1e-12
    kc = np.tile([3e5, 3e5, 1e6], (len(ia), 1))
    pairs = ContactPairs(a["dofs"][ia], na + b["dofs"][match], a["frames"], kc)
    K = sla.block_diag(a["K"].toarray(), b["K"].toarray()) + \
        stick_stiffness(pairs, na + nb).toarray()
    M = sla.block_diag(a["M"].toarray(), b["M"].toarray())
    f = np.zeros(na + nb, complex)
    for s, tip in enumerate(a["tips"]):
        th = 2 * np.pi * s / 6
        f[a["dofs"][tip]] = a["rot"] @ np.array([np.cos(th), np.sin(th), 0.4]) * \
            np.exp(1j * eo * th)
    lam = sla.eigh(K, M, eigvals_only=True, subset_by_index=[0, 9])
    om = 1.02 * np.sqrt(lam[6])
    x = np.linalg.solve(K * (1 + 1j * ETA) - om**2 * M, f)
    # MS model
    ind_a, ind_b = stage_indices(eo, [6, 12], [24, 24])
    msa = ms_basis(a["coords"][ia], a["dofs"][ia], 6, ind_a, origin=ORIGIN, axis=AXIS)
    msb = ms_basis(b["coords"][ib], b["dofs"][ib], 12, ind_b, origin=ORIGIN, axis=AXIS)
    ra = reduce_interface(a["K"], a["M"], msa.interface, msa.basis)
    rb = reduce_interface(b["K"], b["M"], msb.interface, msb.basis)
    both = assemble([ra, rb])
    frames = a["frames"][msa.segments.nodes.ravel()]         # elements in segment order
    G = stage_contact_matrix(msa, msb, frames, ra.K.shape[0], rb.K.shape[0])
    kr = both.K + (G.T @ sp.diags(kc.ravel()) @ G).toarray()
    y = np.linalg.solve(kr * (1 + 1j * ETA) - om**2 * both.M, both.project(f))
    err = np.linalg.norm(both.expand(y) - x) / np.linalg.norm(x)
    assert err < 1e-10, err
    assert both.K.shape[0] < K.shape[0] - 100          # and it is a reduction


@pytest.fixture(scope="module")
def fe_stage(tmp_path_factory):
    """The whole 12-sector bladed-disk stage meshed by cases/models/bladed_sector.py and
    assembled by ccx; its flange face tied to ground by stick springs in cylindrical
    frames (axial normal)."""
    import shutil
    if shutil.which("ccx") is None:
        pytest.skip("ccx not installed")
    import bladed_sector
    from frirom.io import read_calculix
    from frirom.reduction.rom import pairs_from_node_sets
    out = tmp_path_factory.mktemp("stage")
    deck = bladed_sector.write_stage_deck(out, 12)
    m = read_calculix(bladed_sector.run_ccx(deck, expect=(".sti", ".mas", ".dof")))
    pairs = pairs_from_node_sets(m, "FLANGE", None, "axial", 2e8, 8e8)
    return m, pairs


@pytest.mark.parametrize("eo", [0] + [pytest.param(eo, marks=pytest.mark.slow) for eo in (3, 5, 8)])
def test_ms_exact_on_fe_stage_from_ccx(fe_stage, eo):
    """MS on ccx's matrices of a whole tuned stage (72 radial line segments of 2 nodes):
    exact under an EO travelling wave on the blade tips when the family of EO is kept."""
    import scipy.sparse.linalg as spla
    from frirom.reduction.cyclic import axis_rotation
    m, pairs = fe_stage
    n = m.n_dof
    K = (m.K + stick_stiffness(pairs, n)).tocsc()
    key = {(a, b): i for i, (a, b) in enumerate(m.dofs)}
    tips = m.node_sets["TIPS"]
    xt = m.coordinates(tips)
    sector = np.rint(np.mod(np.arctan2(xt[:, 1], xt[:, 0]), 2 * np.pi) / (np.pi / 6)
                     - 0.5).astype(int)
    assert sorted(sector) == list(range(12))
    f = np.zeros(n, complex)
    f0 = np.array([0.3, 1.0, 0.5])
    for tip, s in zip(tips, sector):
        dof = [key[(tip, c)] for c in (1, 2, 3)]
        f[dof] = axis_rotation(s * np.pi / 6) @ f0 * np.exp(-1j * eo * s * np.pi / 6)
    om = 2 * np.pi * 900.0
    A = K * (1 + 0.01j) - om**2 * m.M
    x = spla.spsolve(A.tocsc(), f)
    nodes = m.node_sets["FLANGE"]
    nd = np.array([[key[(v, c)] for c in (1, 2, 3)] for v in nodes])
    idx = harmonic_indices(eo, 12, 72)
    ms = ms_basis(m.coordinates(nodes), nd, 12, idx)
    assert ms.segments.n_segments == 72 and ms.segments.nodes.shape[1] == 2
    red = reduce_interface(K, m.M, ms.interface, ms.basis)
    Ar = sp.csc_matrix(red.K) * (1 + 0.01j) - om**2 * sp.csc_matrix(red.M)
    y = spla.spsolve(Ar.tocsc(), red.project(f))
    err = np.linalg.norm(red.expand(y) - x) / np.linalg.norm(x)
    print(f"\nMS on the ccx stage, EO {eo}: n_k = {ms.basis.shape[1]}, rel. error {err:.1e}")
    assert err < 1e-10, err                  # 13-digit node coordinates: tuned to ~1e-13
    assert red.K.shape[0] == n - 432 + 6 * (2 * idx.size - np.isin(idx, [0, 36]).sum())


@pytest.mark.parametrize("h", [0, 2, 5, 10])
def test_harmonic_content_of_one_index_field(rotor, h):
    """A field built from the MS columns of index h alone (random coefficients) has all its
    energy at h, and the energies sum to |x|^2 (F orthonormal): 1e-12 relative, round-off;
    a sum of two indices splits as their coefficients do."""
    from frirom.reduction.multistage import harmonic_content
    nodes = rotor["iface_nodes"]
    xyz = rotor["coords"][nodes]
    rng = np.random.default_rng(h)
    ms = _basis(rotor, [h])
    a = rng.standard_normal(ms.basis.shape[1])
    v = np.zeros(rotor["K"].shape[0])
    v[ms.interface] = ms.basis @ a
    field = v[rotor["dofs"][nodes]]                           # (n_nodes, 3)
    e = harmonic_content(xyz, field, 7, ORIGIN, AXIS)[:, 0]
    assert e.shape == (11,)
    assert abs(e.sum() - np.sum(field ** 2)) < 1e-12 * np.sum(field ** 2)
    assert abs(e[h] - a @ a) < 1e-12 * (a @ a)
    ms2 = _basis(rotor, [3])
    b = rng.standard_normal(ms2.basis.shape[1])
    v[ms2.interface] += ms2.basis @ b
    e2 = harmonic_content(xyz, v[rotor["dofs"][nodes]], 7, ORIGIN, AXIS)[:, 0]
    assert abs(e2[3] - b @ b) < 1e-12 * (b @ b) and abs(e2[h] - a @ a) < 1e-12 * (a @ a)


def test_travelling_wave_pairs_by_hand():
    """travelling_wave_pairs on hand-made labels, N = 6, EO 2, H = 3 (expected values
    written out, not computed by the function): index 2 moves forward at h = 1 (2 = +2)
    and backward at h = 2 (2 = -4 mod 6); index 4 the reverse; index 0 and 3 have no
    sine column (3 is NZ/2 of 6 segments); at h = 3 (2 h EO = 12 = 0 mod 6) no pair; a
    cosine column without its sine (another node) stays single."""
    from frirom.reduction.multistage import travelling_wave_pairs
    labels = ["cb 1", "s1:ms h=0 0 node0 r", "s1:ms h=2 c node0 r", "s1:ms h=2 s node0 r",
              "s1:ms h=4 c node1 t", "s1:ms h=4 s node1 t", "s1:ms h=3 n node0 r",
              "s1:ms h=2 c node2 a"]
    got = travelling_wave_pairs(labels, 2, 6, 3)
    want = np.zeros((8, 4), dtype=int)
    want[2, 1], want[2, 2] = 4, -4           # cosine DoF 2 with sine DoF 3 (1-based 4)
    want[4, 1], want[4, 2] = -6, 6           # cosine DoF 4 with sine DoF 5
    assert np.array_equal(got, want)
    with pytest.raises(InputError, match="no DoF is a multi-stage"):
        travelling_wave_pairs(["cb 1"], 2, 6, 3)
