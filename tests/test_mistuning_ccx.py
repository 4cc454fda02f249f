"""One mistuned sample, linear, against CalculiX's FE annulus: its modes and its forced
response.

The model: the steel bladed disk of cases/models/bladed_sector.py (C3D8, N = 8 sectors, the
flange face clamped, no contact: the linear "stuck" state of a disk without friction
joints). CalculiX meshes the whole stage with the blades of each sector given their own
Young's modulus E (1 + delta_s) (``*MATERIAL`` per blade), solves its eigenproblem and
writes its matrices; frirom reads only ccx's matrices of one tuned sector and of that
sector's blade elements alone (a matrix run of the blade, free at its root), reduces the
sector by Craig-Bampton (30 fixed-interface modes; masters: the cyclic boundaries, the tip
and the blade's root), expands it to the annulus and mistunes it by component mode
mistuning with the blade's condensed root stiffness (every blade mode): the same mistuning
as E scaled per blade.

Tolerances, measured in brackets (printed by the test): the first two blade-disk families
(2 x 8 modes, 584..831 Hz and 1669..2352 Hz), tuned and mistuned, within 1e-4 of ccx (2e-6,
3e-5: Craig-Bampton truncation); the mistuning shifts of the frequencies (mistuned minus
tuned, up to 0.5 and 2.2 Hz for +-6 % of E) within 2e-3 of the largest shift (2e-4, 2e-4).
Without the root term (the blade's stiffness against its root nodes moving relative to one
another, which E also scales and which the assembled sector cannot separate from the
disk's) the shifts were 37 % and 29 % off, and with the root term but the root DoFs left
to the fixed-interface modes 4.7 % and 2.5 %; with every fixed-interface mode, 2e-4.
Forced response, engine order 3 on the blade tips, 0.23 % damping, 725..750 Hz around the
first family's EO-3 pair: each blade tip's amplitude at the FE annulus's peak within 2e-3
of the FE annulus solved directly (1.1e-4; 11 % without the root term), the whole band
within 2e-3 of the peak (2.2e-4), the peak frequency within 1e-4. (ccx's own *STEADY STATE
DYNAMICS of the same annulus, a sum of its first 60 modes, differed from the direct FE
solution by 5-20 % per blade here, so the reference is the direct solve of ccx's matrices.)
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "cases" / "models"))
import bladed_sector  # noqa: E402
from ccx import STEEL, run_ccx, write_mesh  # noqa: E402

from frirom.io import read_calculix, read_ccx_eigenvalues  # noqa: E402
from frirom.mistuning import LinearAnnulus  # noqa: E402
from frirom.reduction.cyclic import axis_rotation, cyclic_sector  # noqa: E402
from frirom.reduction.mistuning import mistuning_sector  # noqa: E402

pytestmark = pytest.mark.slow

N = 8
R_ROOT = 0.20                 # blade root radius of bladed_sector.sector_mesh
DELTA = np.array([0.04, -0.03, 0.0, 0.06, -0.05, 0.02, 0.0, -0.02])

EO = 3                        # engine order of the forced response
F0 = np.array([0.0, 1.0, 0.5])  # N, sector 0's tip force (global axes)
BETA = 1e-6                   # s, stiffness-proportional damping (zeta 0.23 % at 740 Hz)
BAND = (725.0, 750.0)         # Hz, around the EO 3 pair of the first family (738.7 Hz)
SHIFT_TOL = 2e-3              # of the largest mistuning shift
PEAK_TOL = 2e-3               # blade amplitudes at the peak, relative

MESH = dict(n_theta=4, blade_cells=(1, 3), z_disk=(0.0, 0.02), z_flange=(-0.04,))


def _material(name, E):
    return (f"*MATERIAL, NAME={name}\n*ELASTIC\n{E:.10g}, {STEEL['nu']:.6g}\n*DENSITY\n"
            f"{STEEL['rho']:.6g}\n")


def _blade_elements(xyz, elems):
    """(blade element mask, sector of each element) of a mesh."""
    c = xyz[elems - 1].mean(axis=1)
    blade = np.hypot(c[:, 0], c[:, 1]) > R_ROOT
    sector = (np.floor(np.mod(np.arctan2(c[:, 1], c[:, 0]), 2 * np.pi)
                       / (2 * np.pi / N))).astype(int)
    return blade, sector


def _write_sector(out: Path) -> tuple[Path, Path]:
    """The tuned sector's matrix run, and the matrix run of its blade's elements alone
    (free: the blade's own stiffness, root nodes included)."""
    ids, xyz, elems, grid, (nr, nth, zg) = bladed_sector.sector_mesh(N, **MESH)
    sets = {"LEFT": ids[grid[:, 1] == 0], "RIGHT": ids[grid[:, 1] == nth],
            "FLANGE": ids[grid[:, 2] == 0],
            "TIP": ids[[_tip_index(grid)]]}
    p = out / "sector.inp"
    with open(p, "w") as fh:
        write_mesh(fh, "tuned sector", ids, xyz, elems, sets, "C3D8")
        fh.write(_material("STEEL", STEEL["E"])
                 + "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n*BOUNDARY\nFLANGE, 1, 3\n"
                 + "*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n1\n*END STEP\n")
    blade, _ = _blade_elements(xyz, elems)
    used = np.unique(elems[blade])
    pb = out / "blade.inp"
    with open(pb, "w") as fh:
        write_mesh(fh, "blade elements alone", used, xyz[used - 1], elems[blade], {}, "C3D8")
        fh.write(_material("STEEL", STEEL["E"])
                 + "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n"
                 + "*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n1\n*END STEP\n")
    return p, pb


def _tip_index(grid) -> int:
    """The blade tip node of sector 0: outermost radial station, first angular and axial
    one (by grid index: the radii of a ring's nodes differ in their last bits)."""
    outer = np.nonzero(grid[:, 0] == grid[:, 0].max())[0]
    return int(outer[np.lexsort((grid[outer, 2], grid[outer, 1]))[0]])


def _tips(ids, grid, n_theta):
    """Node id of each sector's blade tip (sector 0's TIP node, repeated)."""
    i0 = _tip_index(grid)
    key = {tuple(g): n for g, n in zip(grid.tolist(), ids)}
    i, j, k = grid[i0]
    return np.array([key[(i, (j + s * n_theta) % (N * n_theta), k)] for s in range(N)])


def _write_stage(out: Path, name: str, delta, matrices: bool = False) -> Path:
    """The whole stage with blade s of Young's modulus E (1 + delta[s]); *FREQUENCY, and
    with ``matrices`` its stiffness and mass matrices (the FE annulus)."""
    ids, xyz, elems, grid, _ = bladed_sector.sector_mesh(N, n_copies=N, **MESH)
    blade, sector = _blade_elements(xyz, elems)
    tips = _tips(ids, grid, MESH["n_theta"])
    p = out / f"{name}.inp"
    with open(p, "w") as fh:
        write_mesh(fh, name, ids, xyz, elems, {"FLANGE": ids[grid[:, 2] == 0], "TIPS": tips},
                   "C3D8")
        eids = np.arange(1, len(elems) + 1)
        groups = {"DISK": eids[~blade]}
        groups.update({f"BLADE{s}": eids[blade & (sector == s)] for s in range(N)})
        for g, e in groups.items():
            fh.write(f"*ELSET, ELSET={g}\n" + "\n".join(
                ", ".join(str(v) for v in e[k:k + 10]) for k in range(0, len(e), 10)) + "\n")
        fh.write(_material("DISK", STEEL["E"])
                 + "*SOLID SECTION, ELSET=DISK, MATERIAL=DISK\n")
        for s in range(N):
            fh.write(_material(f"B{s}", STEEL["E"] * (1 + delta[s]))
                     + f"*SOLID SECTION, ELSET=BLADE{s}, MATERIAL=B{s}\n")
        fh.write(f"*BOUNDARY\nFLANGE, 1, 3\n*STEP\n*FREQUENCY\n{3 * N}\n*END STEP\n")
        if matrices:                 # last: a matrix-storage step ends the run
            fh.write("*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n1\n*END STEP\n")
    return p


def _load():
    """(N, 3) complex tip force of each sector in global axes: sector 0's F0 rotated to
    sector s and lagging by the engine-order phase 2 pi EO s / N (frirom's convention)."""
    out = np.empty((N, 3), complex)
    for s in range(N):
        out[s] = axis_rotation(2 * np.pi * s / N) @ F0 * np.exp(-2j * np.pi * EO * s / N)
    return out


@pytest.fixture(scope="module")
def ccx_runs(tmp_path_factory):
    if shutil.which("ccx") is None:
        pytest.skip("ccx (calculix-ccx) not installed")
    out = tmp_path_factory.mktemp("mistuned_ccx")
    ps, pb = _write_sector(out)
    sec = run_ccx(ps, expect=(".sti", ".mas", ".dof"))
    bl = run_ccx(pb, expect=(".sti", ".dof"))
    lam = {}
    for name, d in (("tuned", np.zeros(N)), ("mistuned", DELTA)):
        job = run_ccx(_write_stage(out, name, d, matrices=name == "mistuned"),
                      expect=(".dat",) + ((".sti", ".mas", ".dof") if name == "mistuned"
                                          else ()))
        lam[name] = read_ccx_eigenvalues(job.with_suffix(".dat"))
    m = read_calculix(sec)
    return m, _blade_stiffness(m, read_calculix(bl, mass=False)), lam, read_calculix(job)


def _blade_stiffness(m, b):
    """The blade-alone run's stiffness on the sector's DoFs."""
    key = {(a, c): i for i, (a, c) in enumerate(m.dofs)}
    idx = np.array([key[(a, c)] for a, c in b.dofs])
    K = b.K.tocoo()
    return sp.csr_matrix((K.data, (idx[K.row], idx[K.col])), shape=(m.n_dof, m.n_dof))


def _node_dofs(m, nodes):
    key = {(a, b): i for i, (a, b) in enumerate(m.dofs)}
    return np.array([[key.get((nd, c), -1) for c in (1, 2, 3)] for nd in nodes])


def _sector(m, n_modes, blade_stiffness=None):
    L, R = m.node_sets["LEFT"], m.node_sets["RIGHT"]
    cs = cyclic_sector(m.coordinates(L), _node_dofs(m, L), m.coordinates(R),
                       _node_dofs(m, R), N, m.n_dof, nodes_left=L, nodes_right=R)
    nodes = m.dofs[:, 0]
    xyz = m.coordinates(nodes)
    blade = np.nonzero(np.hypot(xyz[:, 0], xyz[:, 1]) > R_ROOT + 1e-9)[0]
    tip = m.dof_indices("TIP")
    return mistuning_sector(cs, m.K, m.M, n_modes, blade, keep=tip,
                            blade_stiffness=blade_stiffness,
                            keep_root=blade_stiffness is not None), tip


def _frequencies(ms, delta):
    lam = sla.eigh(ms.stiffness(delta).toarray(), ms.mass().toarray(), eigvals_only=True)
    return np.sqrt(lam) / (2 * np.pi)


def _compare(f_ccx, f_t, f_m):
    """Per family: tuned and mistuned relative frequency errors, and the error of the
    mistuning shifts relative to the largest ccx shift."""
    rows = []
    for fam in (slice(0, N), slice(N, 2 * N)):
        shift = f_ccx["mistuned"][fam] - f_ccx["tuned"][fam]
        rows.append((f_ccx["mistuned"][fam][[0, -1]],
                     np.abs(f_t[fam] / f_ccx["tuned"][fam] - 1).max(),
                     np.abs(f_m[fam] / f_ccx["mistuned"][fam] - 1).max(),
                     np.abs(f_m[fam] - f_t[fam] - shift).max() / np.abs(shift).max(),
                     np.abs(shift).max()))
    return rows


def test_mistuned_annulus_against_ccx_modes(ccx_runs, capsys):
    m, Kb, lam, _ = ccx_runs
    f_ccx = {k: np.sqrt(v) / (2 * np.pi) for k, v in lam.items()}
    ms, _ = _sector(m, 30, Kb)
    ms0, _ = _sector(m, 30)                         # without the root term
    rows = _compare(f_ccx, _frequencies(ms, None), _frequencies(ms, DELTA))
    rows0 = _compare(f_ccx, _frequencies(ms0, None), _frequencies(ms0, DELTA))
    lines = [f"{fr[0]:.1f}..{fr[1]:.1f} Hz: tuned {et:.1e}, mistuned {em:.1e}, shifts "
             f"{es:.1e} of {sh:.2f} Hz (without the root term {r0[3]:.2f})"
             for (fr, et, em, es, sh), r0 in zip(rows, rows0)]
    with capsys.disabled():
        print(f"\nmistuned annulus vs ccx ({m.n_dof} sector DoFs, {ms.n_annulus} reduced "
              "annulus coordinates): " + "; ".join(lines))
    for (fr, et, em, es, sh), line in zip(rows, lines):
        assert et < 1e-4, line
        assert em < 1e-4, line
        assert es < SHIFT_TOL, line


def _fe_response(st, omegas):
    """Every blade tip's (n_w, N, 3) complex displacement of CalculiX's FE annulus (its
    assembled K, M with the blades' own E) under the engine-order tip load, solved
    directly (sparse LU per frequency), damping BETA K."""
    ids, xyz, elems, grid, _ = bladed_sector.sector_mesh(N, n_copies=N, **MESH)
    tips = _tips(ids, grid, MESH["n_theta"])
    dofs = _node_dofs(st, tips)                      # (N, 3)
    f = np.zeros(st.n_dof, complex)
    f[dofs] = _load()
    K, M = st.K.tocsc(), st.M.tocsc()
    return np.array([spla.splu((K - w * w * M + 1j * w * BETA * K).tocsc()).solve(f)[dofs]
                     for w in omegas])


def test_mistuned_forced_response_against_ccx_annulus(ccx_runs, capsys):
    """The reduced mistuned annulus (stuck state: no contact; its modes, Rayleigh damping)
    against CalculiX's FE annulus with the same blades stiffened, solved directly: every
    blade tip's displacement amplitude over the band and at the peak of the largest."""
    m, Kb, _, st = ccx_runs
    w = 2 * np.pi * np.linspace(BAND[0], BAND[1], 201)
    a_fe = np.sqrt((np.abs(_fe_response(st, w)) ** 2).sum(axis=2))      # (n_w, N)
    k = int(np.argmax(a_fe.max(axis=1)))
    w = np.sort(np.concatenate([w, np.linspace(w[k - 1], w[k + 1], 41)[1:-1]]))
    a_fe = np.sqrt((np.abs(_fe_response(st, w)) ** 2).sum(axis=2))     # the peak refined
    res = {}
    for name, kb in (("root term", Kb), ("without", None)):
        ms, tip = _sector(m, 30, kb)
        F = np.zeros((m.n_dof, 2), complex)
        F[tip, 1] = F0
        ex = ms.excitation(ms.T.T @ F, EO)
        out = np.array([[ms.position(p, s) for p in ms.reduced(tip)] for s in range(N)])
        lin = LinearAnnulus(ms.stiffness(DELTA), ms.mass(), 0.0, BETA)
        u = lin.solve(ex.F[:, 1], w, out.ravel()).reshape(w.size, N, 3)
        res[name] = np.sqrt((np.abs(u) ** 2).sum(axis=2))
    a = res["root term"]
    k = int(np.argmax(a_fe.max(axis=1)))
    k_fr = int(np.argmax(a.max(axis=1)))
    err = np.abs(a[k] / a_fe[k] - 1).max()
    err0 = np.abs(res["without"][k] / a_fe[k] - 1).max()
    err_all = np.abs(a - a_fe).max() / a_fe.max()
    f_pk, f_fr = w[k] / (2 * np.pi), w[k_fr] / (2 * np.pi)
    with capsys.disabled():
        print(f"\nforced mistuned annulus vs ccx's FE annulus, EO {EO}, {w.size} frequencies "
              f"in {BAND[0]:g}..{BAND[1]:g} Hz: peak {f_pk:.3f} Hz (reduced {f_fr:.3f}), "
              f"largest blade {int(np.argmax(a_fe[k]))} {a_fe[k].max():.4e} m, largest over "
              f"mean {a_fe[k].max() / a_fe[k].mean():.3f}; each blade at the peak within "
              f"{err:.2e} (without the root term {err0:.2e}), the band within {err_all:.2e} "
              "of the peak")
    assert abs(f_fr / f_pk - 1) < 1e-4
    assert err < PEAK_TOL
    assert err_all < PEAK_TOL
