"""The deck's multi-stage reduction of two stages joined at a flange (issue 11): one MS
basis per interface node set (stage face), harmonic indices named explicitly, and the
circumferential default tangent of `normal = "axial"` contacts."""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.sparse as sp

from _lattices import tuned_rotor
from frirom._errors import InputError
from frirom.deck import load_deck
from frirom.io import write_calculix_matrices
from frirom.reduction.multistage import harmonic_indices

N, Z = 7, 3                 # sectors, radial line segments per sector
K_FLANGE = 3e5              # isotropic springs tying the coincident flange nodes [N/m]

DECK = """
[fe_model]
format = "calculix"
job = "stages"

[reduction]
interface = ["FLANGE1", "FLANGE2"]
active = ["TIPS1", "TIPS2"]

[reduction.interface_modes]
method = "ms"
sectors = 7
{indices}

[[contacts]]
name = "flange"
law = "normal1d"
a = "FLANGE1"
b = "FLANGE2"
normal = "axial"
kt = 1.0e5
kn = 1.0e5
mu = 0.3
n0 = 10.0

[damping]
type = "modal"
zeta = 0.01

[[excitation.load]]
dof = "TIP0:y"
amplitude = 2.0
phase = 30.0

[solver]
harmonics = 2

[frequency]
start = 50.0
end = 80.0

[outputs]
dofs = ["TIP0:x", "TIP0:y"]
"""


@pytest.fixture(scope="module")
def stages(tmp_path_factory):
    """Two tuned lattice rotors (stage 2: the same rotor mirrored through its flange face,
    1.5 x stiffer) whose flange faces coincide node to node, tied by isotropic springs (a
    rotation-invariant coupling: the pair stays cyclic with N sectors). Written as ccx
    matrix files plus an .inp with the nodes and sets."""
    out = tmp_path_factory.mktemp("ms_deck")
    r = tuned_rotor(n_sectors=N, per_sector=Z)
    n1 = len(r["coords"])
    c2 = r["coords"] * np.array([1.0, 1.0, -1.0])
    K = sp.block_diag([r["K"], 1.5 * r["K"]]).tolil()
    M = sp.block_diag([r["M"], r["M"]]).tocsr()
    f1 = r["iface_nodes"]
    for a in f1:
        for c in range(3):
            i, j = 3 * a + c, 3 * (a + n1) + c
            K[i, i] += K_FLANGE
            K[j, j] += K_FLANGE
            K[i, j] -= K_FLANGE
            K[j, i] -= K_FLANGE
    K = K.tocsr()
    coords = np.vstack([r["coords"], c2])
    n = len(coords)
    ids = np.arange(1, n + 1)
    dofs = np.column_stack([np.repeat(ids, 3), np.tile([1, 2, 3], n)])
    write_calculix_matrices(out / "stages", K, M, dofs)
    with open(out / "stages.inp", "w") as fh:
        fh.write("*NODE\n")
        for i, (x, y, z) in zip(ids, coords):
            fh.write(f"{i}, {x:.17g}, {y:.17g}, {z:.17g}\n")
        sets = {"FLANGE1": f1 + 1, "FLANGE2": f1 + n1 + 1, "TIPS1": r["tips"] + 1,
                "TIPS2": r["tips"] + n1 + 1, "TIP0": r["tips"][:1] + 1}
        for name, nodes in sets.items():
            fh.write(f"*NSET, NSET={name}\n" + "\n".join(str(v) for v in nodes) + "\n")
    return dict(dir=out, K=K, M=M, n1=n1, r=r)


def _load(stages, indices, name="stages.toml"):
    path = stages["dir"] / name
    path.write_text(DECK.format(indices=indices))
    return load_deck(path)


def test_one_ms_basis_per_stage_is_exact_for_the_travelling_wave(stages):
    """interface = two coincident faces: each MS coordinate moves one stage only (one
    ms_basis per set; a single call would group both faces' nodes into one segment), the
    sizes are 2 stages x family columns x 9 DoFs per segment, and the reduced model is
    exact for an EO 2 travelling wave on both stages' tips (1e-10 relative: round-off of
    two dense solves)."""
    d = _load(stages, "engine_orders = [2]")
    rom = d.reduced
    n1, r = stages["n1"], stages["r"]
    fam = harmonic_indices(2, N, N * Z)
    n_if = 2 * 3 * r["iface_nodes"].size
    n_ms = 2 * (2 * fam.size - int(0 in fam)) * 9
    assert rom.K.shape[0] == stages["K"].shape[0] - n_if + n_ms
    T = rom.T.toarray() if sp.issparse(rom.T) else np.asarray(rom.T)
    node = rom.fe_dofs[:, 0]                       # FE node id of each row of T
    ms_cols = [j for j, lab in enumerate(rom.labels) if "ms h=" in lab]
    assert len(ms_cols) == n_ms
    for j in ms_cols:
        stage = node[np.abs(T[:, j]) > 1e-14] > n1
        assert stage.all() or (~stage).all(), rom.labels[j]
        assert rom.labels[j].startswith("FLANGE2 " if stage[0] else "FLANGE1 ")
    f = np.zeros(stages["K"].shape[0], complex)
    for off, amp in ((0, 1.0), (n1, 0.7 * np.exp(0.3j))):
        for s, tip in enumerate(r["tips"]):
            th = 2 * np.pi * s / N
            f[3 * (tip + off):3 * (tip + off) + 3] = (amp * np.array([np.cos(th), np.sin(th),
                                                                      0.4])
                                                      * np.exp(-2j * th))
    om = 1500.0
    K, M = stages["K"].toarray(), stages["M"].toarray()
    x = np.linalg.solve(K * (1 + 0.01j) - om**2 * M, f)
    y = np.linalg.solve(rom.K * (1 + 0.01j) - om**2 * rom.M, rom.T.T @ f)
    assert np.linalg.norm(rom.expand(y) - x) < 1e-10 * np.linalg.norm(x)


def test_harmonic_indices_named_explicitly(stages):
    """`harmonic_indices = [2]` keeps index 2 alone (2 columns x 9 DoFs per stage), not its
    aliasing family; naming the family's indices gives the engine-order deck's model."""
    fam = harmonic_indices(2, N, N * Z)
    assert fam.size > 1                           # 2 alone differs from the family
    one = _load(stages, "harmonic_indices = [2]", "one.toml").reduced
    n_if = 2 * 3 * stages["r"]["iface_nodes"].size
    assert one.K.shape[0] == stages["K"].shape[0] - n_if + 2 * 2 * 9
    eo = _load(stages, "engine_orders = [2]", "eo.toml").reduced
    named = _load(stages, f"harmonic_indices = {fam.tolist()}", "named.toml").reduced
    assert np.allclose(named.K, eo.K, rtol=0, atol=1e-12 * np.abs(eo.K).max())


@pytest.mark.parametrize("indices, expected", [
    ("harmonic_indices = [2]\nengine_orders = [2]",
     "reduction.interface_modes.engine_orders: expected no engine_orders"),
    ("harmonic_indices = [-1]",
     "reduction.interface_modes.harmonic_indices: expected a non-empty list of integers >= 0"),
    ("harmonic_indices = [40]", "harmonic indices must lie in 0..NZ/2"),
])
def test_bad_harmonic_indices_name_the_field(stages, indices, expected):
    with pytest.raises(InputError) as exc:
        _load(stages, indices, "bad.toml")
    assert expected in str(exc.value), str(exc.value)


def test_axial_normal_has_the_circumferential_tangent(stages):
    """normal = "axial" without `tangent`: t1 is the circumferential direction at each
    pair (-sin theta, cos theta, 0), the same at every sector (docs/deck.md), and n the
    axis."""
    d = _load(stages, "harmonic_indices = [2]", "tangent.toml")
    pairs = d.reduced.pairs["flange"]
    xyz = stages["r"]["coords"][stages["r"]["iface_nodes"]]
    node_of_row = {tuple(np.round(x, 9)) for x in xyz}
    assert len(node_of_row) == xyz.shape[0]
    fr = pairs.frames                                    # (n_elem, 2, 3): t1, n
    assert fr.shape == (xyz.shape[0], 2, 3)
    # the pairs' order is set a's: FLANGE1 in node-id order = iface_nodes sorted
    order = np.sort(stages["r"]["iface_nodes"])
    th = np.arctan2(stages["r"]["coords"][order, 1], stages["r"]["coords"][order, 0])
    t_ref = np.column_stack([-np.sin(th), np.cos(th), np.zeros_like(th)])
    assert np.allclose(fr[:, 0], t_ref, atol=1e-12)
    assert np.allclose(fr[:, 1], [0.0, 0.0, 1.0], atol=1e-12)
