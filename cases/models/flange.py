"""Two bladed-disk stages joined at a circular flange: CalculiX decks, Craig-Bampton
ROM_I and multi-stage ROM_II (reference paper section 3.3.1, Table 1), cached as npz.

    python cases/models/flange.py [--pairs 200] [--sectors 50] [--coarse] [--work DIR]

Geometry (steel E 210 GPa, nu 0.33, rho 7800; C3D8 hexahedra on a structured
(r, theta, z) grid, ``z_per_sector`` angular cells per sector):

* stage 1 (z >= 0): a flange arm (r 0.10..0.12, z 0..0.03) carrying a disk (r 0.10..0.20,
  z 0.03..0.06) and one blade per sector (r 0.20..0.30, half the sector wide, twisted so
  that bending and torsion couple). It is free: it hangs on stage 2 through the flange.
* stage 2 (z <= 0): the mirrored flange arm, a disk of its own thickness reaching in to a
  hub (r 0.07, clamped: node set HUB) and shorter blades (to r 0.26).

The flange faces z = 0 of both stages have matching meshes; their nodes on the middle
circle r = 0.11 (node set CONTACT, ``z_per_sector`` per sector, one per radial line segment)
form the contact pairs: ``normal1d`` elements with the circumferential tangent and the axial
normal (pointing from stage 1 into stage 2), bolt preload ``n0`` per pair balanced by the
static load (docs/deck.md). One pair per sector also carries a linear bolt (stiffness
``k_bolt`` in x, y and z), so that stage 1 stays attached when every contact slips or
lifts off (the linear part must be nonsingular at harmonic 0). ACTIVE: one node per blade
in the middle of the airfoil, loaded by an engine-order (EO) travelling wave, stage 2 clocked
by ``clocking`` rad.

ROM_I: Craig-Bampton per stage (frirom.reduction.cb) with masters CONTACT + ACTIVE (x, y, z)
and ``n_modes`` fixed-interface modes per stage; with 50 sectors, 4 segments per sector and
200 modes: 1 200 interface + 300 active + 400 modal = 1 900 DoFs. ROM_II: the multi-stage
reduction (frirom.reduction.multistage) of each stage's interface to the harmonic indices
``ms_indices`` (default 2: 6 coordinates per stage), one ``ms_basis`` call per stage (one
call over both faces would mix the coincident nodes of the two stages in a segment).

The paper case (cases/paper_flange) uses the same stages as one bolted assembly in one ccx
job (:func:`assembly_mesh`, :func:`write_assembly_deck`): the stages share one face node
per sector on the inner edge of the flange arm (the bolt), the contact circle keeps its
pairs, and frirom's decks do the reductions.

Nothing generated is committed: :func:`flange_roms` writes the decks, runs ccx, reduces and
saves everything in one npz in ``work`` (named after the parameters); a rerun loads it.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ccx import matrix_storage_steps, nset, run_ccx, solid_material  # noqa: E402

PAPER_STEEL = dict(E=2.1e11, nu=0.33, rho=7800.0)   # Pa, -, kg/m^3 (paper 3.3.1)
CACHE_VERSION = 3


@dataclass(frozen=True)
class FlangeSpec:
    """Parameters of the two-stage model (lengths m, stiffness N/m, forces N).

    sectors: N (both stages); z_per_sector: contact nodes (radial line segments) per sector
    and face, so pairs = sectors * z_per_sector; n_modes: fixed-interface modes per stage;
    coarse: a small cross-section (few nodes, for tests); kt, kn, mu, n0: normal1d
    parameters per pair; k_bolt: linear bolt stiffness (x, y, z) at one pair per sector;
    eo: engine order; f0: load amplitude per blade (axial and tangential components
    f0 / sqrt(2) each); clocking: phase lag of stage 2's wave [rad]; zeta: damping ratio of
    the stiffness-proportional Rayleigh damping at the stuck EO resonance; ms_indices:
    harmonic indices kept by ROM_II.
    """

    sectors: int = 50
    z_per_sector: int = 4
    n_modes: int = 200
    coarse: bool = False
    kt: float = 2e8
    kn: float = 2e8
    mu: float = 0.3
    n0: float = 1000.0
    k_bolt: float = 2e8
    eo: int = 2
    f0: float = 20.0
    clocking: float = 0.3
    zeta: float = 0.002
    ms_indices: tuple = (2,)

    @property
    def pairs(self) -> int:
        return self.sectors * self.z_per_sector

    def key(self) -> str:
        d = asdict(self)
        d.pop("ms_indices")           # ROM_II is built from the cache (rom2): not keyed
        text = json.dumps([CACHE_VERSION, d], sort_keys=True)
        return hashlib.sha1(text.encode()).hexdigest()[:12]


# --------------------------------------------------------------------------------------------
# mesh and decks
# --------------------------------------------------------------------------------------------

def _section(stage: int, coarse: bool):
    """Radial grid, axial grid and cell masks of a stage's cross-section.

    Returns r (n_r,), z (n_z,), solid (n_r-1, n_z-1) bool of the axisymmetric cells
    (flange arm + disk), blade (n_r-1, n_z-1) bool of the blade cells, i_contact (radial
    node index of the contact circle), i_hub (radial node index clamped, or None), the
    radial node index of the middle of the airfoil.
    """
    if stage == 1:
        r = [0.10, 0.11, 0.12, 0.16, 0.20, 0.235, 0.27, 0.30]
        z = [0.0, 0.015, 0.03, 0.045, 0.06]
        if coarse:
            r, z = [0.10, 0.11, 0.12, 0.20, 0.30], [0.0, 0.03, 0.06]
        i_hub = None
    else:
        r = [0.07, 0.085, 0.10, 0.11, 0.12, 0.16, 0.20, 0.23, 0.26]
        z = [0.0, -0.015, -0.03, -0.0425, -0.055]
        if coarse:
            r, z = [0.07, 0.10, 0.11, 0.12, 0.20, 0.26], [0.0, -0.03, -0.055]
        i_hub = 0
    r, z = np.array(r), np.array(z)
    i_arm = int(np.searchsorted(r, 0.10 - 1e-9))          # arm: r 0.10 .. 0.12
    i_rim = int(np.searchsorted(r, 0.20 - 1e-9))          # disk rim, blade root
    k_disk = int(np.argmin(np.abs(np.abs(z) - 0.03)))     # arm meets disk
    solid = np.zeros((r.size - 1, z.size - 1), bool)
    solid[i_arm:i_arm + 2, :k_disk] = True                # flange arm
    solid[:i_rim, k_disk:] = True                         # disk (and hub)
    blade = np.zeros_like(solid)
    blade[i_rim:, k_disk:] = True
    i_mid = i_rim + (r.size - 1 - i_rim + 1) // 2
    return r, z, solid, blade, i_arm + 1, i_hub, i_mid


def stage_mesh(stage: int, n_sectors: int, z_per_sector: int, coarse: bool = False,
               twist: float = 0.6):
    """Nodes and C3D8 elements of a whole stage and its node sets.

    Returns ids (n,), xyz (n, 3), elems (n_e, 8) node ids, sets {name: node ids}: CONTACT
    (contact circle of the flange face, in increasing angle from theta = 0), BOLT (one
    CONTACT node per sector), ACTIVE (mid-airfoil node per blade, sector order), HUB (stage
    2: the clamped bore).
    """
    r, z, solid, blade, i_con, i_hub, i_mid = _section(stage, coarse)
    nth = int(z_per_sector)
    n_st = n_sectors * nth
    alpha = 2 * np.pi / n_sectors
    # blade: the middle half of the sector's angular cells (at least one cell)
    nb = max(1, nth // 2)
    jb0 = (nth - nb) // 2
    cells = []
    for j in range(n_st):
        in_blade = jb0 <= j % nth < jb0 + nb
        for i in range(r.size - 1):
            for k in range(z.size - 1):
                if solid[i, k] or (blade[i, k] and in_blade):
                    cells.append((i, j, k))
    used = {}
    for i, j, k in cells:
        for di in (0, 1):
            for dj in (0, 1):
                for dk in (0, 1):
                    used.setdefault((i + di, (j + dj) % n_st, k + dk), None)
    keys = sorted(used, key=lambda q: (q[1], q[0], q[2]))
    for n, q in enumerate(keys, start=1):
        used[q] = n
    i_rim = int(np.searchsorted(r, 0.20 - 1e-9))
    th_mid = (jb0 + 0.5 * nb) * alpha / nth
    xyz = np.empty((len(keys), 3))
    for n, (i, j, k) in enumerate(keys):
        rr, tt, zz = r[i], j * alpha / nth, z[k]
        if i > i_rim:          # blade nodes: twisted about the blade's mid plane
            local = (j % nth) * alpha / nth
            zz = zz + twist * (rr - r[i_rim]) * (local - th_mid) * rr
        xyz[n] = (rr * np.cos(tt), rr * np.sin(tt), zz)
    elems = np.array([[used[(i + a, (j + b) % n_st, k + c)] for a, b, c in
                       ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
                        (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1))]
                      for i, j, k in cells], dtype=np.int64)
    if stage == 2:             # mirrored in z: keep positive element volumes
        elems = elems[:, [0, 3, 2, 1, 4, 7, 6, 5]]
    ids = np.arange(1, len(keys) + 1)
    contact = np.array([used[(i_con, j, 0)] for j in range(n_st)])
    bolt = contact[nth // 2::nth]
    k_mid = (z.size - 1 + int(np.argmin(np.abs(np.abs(z) - 0.03)))) // 2
    active = np.array([used[(i_mid, s * nth + jb0 + nb // 2, k_mid)]
                       for s in range(n_sectors)])
    sets = {"CONTACT": contact, "BOLT": bolt, "ACTIVE": active}
    if i_hub is not None:
        sets["HUB"] = np.array(sorted(n for q, n in used.items() if q[0] == i_hub))
    return ids, xyz, elems, sets


def _write_hex_deck(path, title: str, ids, xyz, elems, sets: dict, material,
                    n_ref_modes: int = 0) -> Path:
    """A CalculiX deck of C3D8 elements: nodes, elements, node sets (written in the given
    order: CONTACT and ACTIVE keep their (angle, sector) order), steel, HUB clamped when
    there is one, the matrix-storage steps (``n_ref_modes`` > 0: ccx's reference modes
    first)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as fh:
        fh.write(f"** {title}, C3D8\n*NODE, NSET=ALL\n")
        fh.writelines(f"{i}, {x:.13g}, {y:.13g}, {zz:.13g}\n" for i, (x, y, zz) in
                      zip(ids, xyz))
        fh.write("*ELEMENT, TYPE=C3D8, ELSET=EALL\n")
        fh.writelines(f"{e}, " + ", ".join(str(c) for c in conn) + "\n"
                      for e, conn in enumerate(elems, start=1))
        for name, nodes in sets.items():
            fh.write(nset(name, nodes))
        fh.write(solid_material(material))
        if "HUB" in sets:
            fh.write("*BOUNDARY\nHUB, 1, 3\n")
        fh.write(matrix_storage_steps(n_ref_modes))
    return path


def write_stage_deck(path, stage: int, n_sectors: int, z_per_sector: int,
                     coarse: bool = False, material=PAPER_STEEL) -> Path:
    """``stage<k>.inp``: mesh, node sets, steel, HUB clamped (stage 2), matrix storage."""
    ids, xyz, elems, sets = stage_mesh(stage, n_sectors, z_per_sector, coarse)
    return _write_hex_deck(path, f"flange model stage {stage}, {n_sectors} sectors", ids,
                           xyz, elems, sets, material)


def assembly_mesh(spec: FlangeSpec, bolt_radii=(0.10,), sectors2: int | None = None):
    """Both stages in one mesh, bolted: at the angle of each sector's BOLT pair, the flange
    face nodes at ``bolt_radii`` (default the inner edge of the arm, r 0.10, z = 0) are
    shared by the two stages (a bolt circle of shared nodes); every other face node stays
    double, and the contact circle r = 0.11 keeps its node pairs (the normal1d contacts).
    Sharing the outer edge too (r 0.12) stiffens the joint so much that the EO 2 modes
    barely load the contacts (stuck and free EO 2 frequencies within 1 % on the coarse
    model, against 7 % with the inner edge alone and kt = kn = 1e9 N/m).

    Returns ids (n,), xyz (n, 3), elems (n_e, 8) node ids, sets {name: node ids}:
    CONTACT1, CONTACT2 (the two faces' contact circles, pair by pair in increasing angle),
    ACTIVE1, ACTIVE2 (mid-airfoil node per blade), BOLT (the shared nodes), HUB (stage 2's
    clamped bore). Stage 1's nodes keep their ids, stage 2's are offset; stage 1's
    elements come first.

    sectors2: stage 2's sector count when it differs from stage 1's (``spec.sectors``);
    both faces keep the ``spec.pairs`` contact segments, so ``spec.pairs`` must be a
    multiple of it, and the bolts sit at both stages' bolt angles (the union).
    """
    from scipy.spatial import cKDTree
    n2 = spec.sectors if sectors2 is None else int(sectors2)
    if n2 < 1 or spec.pairs % n2:
        raise ValueError(f"sectors2: the {spec.pairs} contact segments are not a multiple "
                         f"of stage 2's {n2} sectors")
    i1, x1, e1, s1 = stage_mesh(1, spec.sectors, spec.z_per_sector, spec.coarse)
    i2, x2, e2, s2 = stage_mesh(2, n2, spec.pairs // n2, spec.coarse)
    xb = np.vstack([x1[s1["BOLT"] - 1], x2[s2["BOLT"] - 1]])
    xb = xb[np.unique(np.round(xb, 9), axis=0, return_index=True)[1]]
    th = np.arctan2(xb[:, 1], xb[:, 0])
    targets = np.vstack([np.column_stack([r * np.cos(th), r * np.sin(th), 0 * th])
                         for r in bolt_radii])
    tol = 1e-9
    d1, k1 = cKDTree(x1).query(targets)
    d2, k2 = cKDTree(x2).query(targets)
    if max(d1.max(), d2.max()) > tol:
        raise RuntimeError("flange: no face node on the bolt circle of one stage")
    off = int(i1.max())
    new_id = i2 + off
    new_id[k2] = i1[k1]                                   # shared bolt nodes
    keep2 = np.setdiff1d(np.arange(i2.size), k2)
    ids = np.concatenate([i1, new_id[keep2]])
    xyz = np.vstack([x1, x2[keep2]])
    elems = np.vstack([e1, new_id[e2 - 1]])
    sets = {"CONTACT1": s1["CONTACT"], "CONTACT2": new_id[s2["CONTACT"] - 1],
            "ACTIVE1": s1["ACTIVE"], "ACTIVE2": new_id[s2["ACTIVE"] - 1],
            "BOLT": np.sort(i1[k1]), "HUB": new_id[s2["HUB"] - 1]}
    return ids, xyz, elems, sets


def write_assembly_deck(path, spec: FlangeSpec, n_ref_modes: int = 0,
                        material=PAPER_STEEL, sectors2: int | None = None) -> Path:
    """``flange.inp``: the bolted assembly (:func:`assembly_mesh`), HUB clamped, steel; an
    optional ``*FREQUENCY`` step of ``n_ref_modes`` modes (ccx's reference eigenvalues in
    the .dat, joint without contacts: the bolts alone) before the matrix storage.
    sectors2: stage 2's sector count, if not ``spec.sectors``."""
    ids, xyz, elems, sets = assembly_mesh(spec, sectors2=sectors2)
    title = f"bolted two-stage flange, {spec.sectors} sectors per stage"
    if sectors2 is not None:
        title = f"bolted two-stage flange, {spec.sectors} + {sectors2} sectors"
    return _write_hex_deck(path, title, ids, xyz, elems, sets, material, n_ref_modes)


# --------------------------------------------------------------------------------------------
# reduction
# --------------------------------------------------------------------------------------------

def _positions(cb, nodes) -> np.ndarray:
    """(n, 3) positions in the CB coordinates of the x, y, z masters of node ids."""
    nodes = np.asarray(nodes, dtype=np.int64)
    lab = np.column_stack([np.repeat(nodes, 3), np.tile([1, 2, 3], nodes.size)])
    return cb.master_position(lab).reshape(-1, 3)


def _reduce_stage(job, spec: FlangeSpec, stage: int):
    """Read ccx's matrices of one stage and reduce them by Craig-Bampton (ROM_I part)."""
    from frirom.io import read_calculix
    from frirom.reduction.cb import craig_bampton

    fe = read_calculix(job)
    cb = craig_bampton(fe, spec.n_modes, interface="CONTACT", active="ACTIVE")
    _, _, _, sets = stage_mesh(stage, spec.sectors, spec.z_per_sector, spec.coarse)
    contact, active = sets["CONTACT"], sets["ACTIVE"]
    xyz = fe.coordinates(contact)
    return dict(fe_dofs=fe.n_dof, K=cb.K, M=cb.M, contact_pos=_positions(cb, contact),
                active_pos=_positions(cb, active), contact_xyz=xyz,
                bolt_rows=np.nonzero(np.isin(contact, sets["BOLT"]))[0],
                theta=np.arctan2(xyz[:, 1], xyz[:, 0]), cutoff=cb.cutoff_frequency)


def _assemble(st1, st2, spec: FlangeSpec):
    """ROM_I matrices, contact map, bolts and loads from the two stages' CB models."""
    n1, n2 = st1["K"].shape[0], st2["K"].shape[0]
    n = n1 + n2
    K = np.zeros((n, n))
    M = np.zeros((n, n))
    K[:n1, :n1], K[n1:, n1:] = st1["K"], st2["K"]
    M[:n1, :n1], M[n1:, n1:] = st1["M"], st2["M"]
    pa = st1["contact_pos"]
    pb = st2["contact_pos"] + n1
    th = st1["theta"]
    if np.max(np.abs(np.angle(np.exp(1j * (th - st2["theta"]))))) > 1e-9:
        raise RuntimeError("flange: the contact nodes of the two stages do not match")
    ne = th.size
    tang = np.column_stack([-np.sin(th), np.cos(th), np.zeros(ne)])
    norm = np.tile([0.0, 0.0, -1.0], (ne, 1))          # from stage 1 into stage 2
    rows, cols, vals = [], [], []
    for d, fr in enumerate((tang, norm)):
        for c in range(3):
            keep = np.abs(fr[:, c]) > 1e-14                # no stored zeros
            e = np.nonzero(keep)[0]
            rows += [2 * e + d, 2 * e + d]
            cols += [pa[e, c], pb[e, c]]
            vals += [fr[e, c], -fr[e, c]]
    G = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(2 * ne, n))
    # bolts: k_bolt (x_A - x_B) in x, y, z at one pair per sector
    b = st1["bolt_rows"]
    for c in range(3):
        ia, ib = pa[b, c], pb[b, c]
        K[ia, ia] += spec.k_bolt
        K[ib, ib] += spec.k_bolt
        K[ia, ib] -= spec.k_bolt
        K[ib, ia] -= spec.k_bolt
    # loads: harmonic 0 balances the preload, harmonic 1 the EO travelling waves
    F = np.zeros((n, 2), complex)
    F[pa[:, 2], 0] += spec.n0 * norm[:, 2]
    F[pb[:, 2], 0] -= spec.n0 * norm[:, 2]
    outputs = []
    for stage, (st, off) in enumerate(((st1, 0), (st2, n1))):
        act = st["active_pos"] + off
        s = np.arange(act.shape[0])
        ph = np.exp(-2j * np.pi * spec.eo * s / spec.sectors - 1j * spec.clocking * stage)
        thb = 2 * np.pi * (s + 0.5) / spec.sectors
        amp = spec.f0 / np.sqrt(2.0)
        F[act[:, 0], 1] += -amp * np.sin(thb) * ph
        F[act[:, 1], 1] += amp * np.cos(thb) * ph
        F[act[:, 2], 1] += amp * ph
        outputs.append(act[:, 2])
    return dict(K=K, M=M, G=G, F=F, outputs=np.concatenate(outputs), contact_a=pa,
                contact_b=pb, n1=n1, xyz1=st1["contact_xyz"], xyz2=st2["contact_xyz"])


def rom2(roms: dict, indices) -> dict:
    """ROM_II of the cached ROM_I for the harmonic ``indices`` (0..NZ/2, NZ = pairs):
    one ``ms_basis`` per stage (each face's own radial line segments; one call over both
    faces would put the two coincident nodes of a segment in arbitrary order).

    Returns K2, M2 (n_II, n_II), G2 (CSR), F2 (n_II, 2), outputs2, R (n_I, n_II CSR:
    x_I = R x_II), ms (the two MultistageInterface objects), indices.
    """
    from frirom.reduction.interface import reduce_interface
    from frirom.reduction.multistage import ms_basis

    n = int(roms["spec"]["sectors"])
    m1 = ms_basis(roms["xyz1"], roms["contact_a"], n, indices)
    m2 = ms_basis(roms["xyz2"], roms["contact_b"], n, indices)
    from scipy.linalg import block_diag
    red = reduce_interface(roms["K"], roms["M"], np.concatenate([m1.interface, m2.interface]),
                           block_diag(m1.basis, m2.basis))
    R = red.R.tocsr()
    out2 = np.array([R[o].indices[0] for o in roms["outputs"]])
    return dict(K2=np.asarray(red.K), M2=np.asarray(red.M), G2=sp.csr_matrix(roms["G"] @ R),
                F2=np.asarray(R.T @ roms["F"]), outputs2=out2, R=R, ms=(m1, m2),
                indices=tuple(int(h) for h in np.atleast_1d(indices)))


def _stuck_eo_frequency(K, M, G, spec: FlangeSpec, F,
                        n_low: int = 40) -> tuple[float, float]:
    """Frequency [Hz] of the mode with the largest EO load participation |phi^T F|^2 / lambda,
    stuck and free (contacts removed, bolts kept), among the ``n_low`` lowest modes.

    The dominant mode is the EO pair of the lowest family (mode 3 or 4 of 1 300 to 3 100
    at 100 to 400 pairs), so a partial eigh (LAPACK dsygvx, the lowest ``n_low`` pairs)
    replaces every mode of the dense ROM_I (dsygvd): about half the time (a window of 200:
    7.8 s against 16 s per call at 400 pairs), the same frequencies to 6e-10. A maximum at
    the top of the window falls back to every mode.
    """
    import scipy.linalg as sl
    Kc = (G.T @ sp.diags(np.tile([spec.kt, spec.kn], G.shape[0] // 2)) @ G).toarray()
    n = K.shape[0]
    out = []
    for Kx in (K + Kc, K):
        sub = [0, min(n_low, n) - 1]
        lam, phi = sl.eigh(Kx, M, subset_by_index=sub, driver="gvx")
        part = np.abs(phi.T @ F[:, 1]) ** 2 / np.maximum(lam, 1e-30)
        if n_low < n and int(np.argmax(part)) >= n_low - 2:
            lam, phi = sl.eigh(Kx, M)        # the window may cut the maximum off
            part = np.abs(phi.T @ F[:, 1]) ** 2 / np.maximum(lam, 1e-30)
        out.append(float(np.sqrt(lam[int(np.argmax(part))]) / (2 * np.pi)))
    return out[0], out[1]


def flange_roms(spec: FlangeSpec | None = None, work=None, log=print) -> dict:
    """The model's arrays (ROM_I, ROM_II, sizes, timings): from ``work``'s npz cache, or
    generated (decks, ccx, CB, MS) and saved there.

    Keys: K, M (n_I, n_I) ROM_I; G (2 pairs, n_I) CSR normal1d map (rows t, n per pair);
    params (pairs, 4) kt kn mu n0; F (n_I, 2) complex loads (harmonics 0, 1); outputs (axial
    DoFs of the active nodes); contact_a, contact_b (pairs, 3) ROM_I positions of the x, y,
    z DoFs of each pair's stage-1 and stage-2 node; K2, M2, G2, F2, outputs2: ROM_II;
    beta: Rayleigh stiffness coefficient [s]; f_stuck, f_free: EO resonance [Hz] of the
    linear stuck / free ROM_I; sizes (dict); t_ccx, t_reduce: generation times [s] (ccx,
    CB + assembly); t_ms: the MS reduction of this call [s]; spec (dict); cache (path);
    generated (False when read from the cache). The npz holds ROM_I only (with xyz1, xyz2
    the stages' contact node coordinates and n1 stage 1's size); ROM_II (K2 ... outputs2,
    R, ms) is built by :func:`rom2` for ``spec.ms_indices`` on every call (milliseconds).
    """
    spec = spec or FlangeSpec()
    work = Path(work or "/tmp/frirom_flange")
    work.mkdir(parents=True, exist_ok=True)
    cache = work / f"flange_{spec.pairs}p_{spec.key()}.npz"
    generated = not cache.exists()
    if generated:
        _generate(spec, work, cache, log)
    out = _load(cache)
    out["generated"] = generated
    out["spec"]["ms_indices"] = tuple(int(h) for h in np.atleast_1d(spec.ms_indices))
    t0 = time.perf_counter()
    out.update(rom2(out, spec.ms_indices))
    out["t_ms"] = time.perf_counter() - t0
    s = out["sizes"]
    s["rom2"] = out["K2"].shape[0]
    s["ms_interface"] = s["rom2"] - s["active"] - s["modes"]
    return out


def _generate(spec: FlangeSpec, work: Path, cache: Path, log) -> None:
    """Decks, ccx, CB of both stages, ROM_I assembly: saved to ``cache``."""
    jobdir = work / f"flange_{spec.key()}"
    t0 = time.perf_counter()
    jobs = []
    for stage in (1, 2):
        deck = write_stage_deck(jobdir / f"stage{stage}.inp", stage, spec.sectors,
                                spec.z_per_sector, spec.coarse)
        jobs.append(run_ccx(deck, expect=(".sti", ".mas", ".dof")))
    t_ccx = time.perf_counter() - t0
    log(f"flange: ccx wrote both stages' matrices in {t_ccx:.1f} s")
    t0 = time.perf_counter()
    st = [_reduce_stage(job, spec, k + 1) for k, job in enumerate(jobs)]
    a = _assemble(st[0], st[1], spec)
    f_stuck, f_free = _stuck_eo_frequency(a["K"], a["M"], a["G"], spec, a["F"])
    t_reduce = time.perf_counter() - t0
    log(f"flange: CB + assembly in {t_reduce:.1f} s; EO {spec.eo} resonance "
        f"{f_stuck:.1f} Hz stuck, {f_free:.1f} Hz free")
    beta = 2 * spec.zeta / (2 * np.pi * f_stuck)
    sizes = dict(fe_dofs=[s["fe_dofs"] for s in st], rom1=a["K"].shape[0],
                 interface=2 * 3 * spec.pairs,
                 active=sum(s["active_pos"].size for s in st),
                 modes=2 * spec.n_modes, pairs=spec.pairs,
                 contact_rows=a["G"].shape[0], cutoff_hz=[s["cutoff"] for s in st])
    params = np.tile([spec.kt, spec.kn, spec.mu, spec.n0], (spec.pairs, 1))
    G = a["G"]
    d = asdict(spec)
    d["ms_indices"] = list(d["ms_indices"])
    np.savez(cache, K=a["K"], M=a["M"], G_data=G.data, G_indices=G.indices,
             G_indptr=G.indptr, G_shape=G.shape, params=params, F=a["F"],
             outputs=a["outputs"], contact_a=a["contact_a"], contact_b=a["contact_b"],
             xyz1=a["xyz1"], xyz2=a["xyz2"], n1=a["n1"],
             beta=beta, f_stuck=f_stuck, f_free=f_free,
             t_ccx=t_ccx, t_reduce=t_reduce, sizes=json.dumps(sizes), spec=json.dumps(d))


def _load(path) -> dict:
    z = np.load(path)
    out = {k: z[k] for k in z.files if not k.startswith("G_")}
    out["G"] = sp.csr_matrix((z["G_data"], z["G_indices"], z["G_indptr"]),
                             shape=tuple(z["G_shape"]))
    out["sizes"] = json.loads(str(z["sizes"]))
    out["spec"] = json.loads(str(z["spec"]))
    for k in ("beta", "f_stuck", "f_free", "t_ccx", "t_reduce"):
        out[k] = float(out[k])
    out["n1"] = int(out["n1"])
    out["cache"] = str(path)
    out["generated"] = False
    return out


def frirom_models(roms: dict, which: str = "I"):
    """(Model, Excitation, outputs) of ROM_I (``which`` 'I') or ROM_II ('II')."""
    from frirom.model import ContactGroup, Damping, Excitation, Model
    s = "" if which == "I" else "2"
    if which not in ("I", "II"):
        raise ValueError(f"which: expected 'I' or 'II', got {which!r}")
    contact = ContactGroup("normal1d", roms["G" + s], roms["params"], name="flange")
    model = Model(roms["M" + s], roms["K" + s], Damping.rayleigh(0.0, roms["beta"]),
                  [contact])
    return model, Excitation(roms["F" + s]), roms["outputs" + s]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=200)
    ap.add_argument("--sectors", type=int, default=50)
    ap.add_argument("--modes", type=int, default=200, help="fixed-interface modes per stage")
    ap.add_argument("--coarse", action="store_true")
    ap.add_argument("--work", default="/tmp/frirom_flange")
    a = ap.parse_args(argv)
    if a.pairs % a.sectors:
        ap.error("--pairs must be a multiple of --sectors")
    spec = FlangeSpec(sectors=a.sectors, z_per_sector=a.pairs // a.sectors, n_modes=a.modes,
                      coarse=a.coarse)
    roms = flange_roms(spec, a.work)
    print(json.dumps(roms["sizes"]), f"f_stuck {roms['f_stuck']:.2f} Hz",
          f"f_free {roms['f_free']:.2f} Hz", roms["cache"])


if __name__ == "__main__":
    main()
