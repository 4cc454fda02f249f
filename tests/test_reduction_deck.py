"""Decks with [fe_model] + [reduction]: FE files -> CB -> GSI/MS -> cached reduced model,
contacts on node sets, loads and outputs by node."""

import os
import shutil

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from _lattices import tuned_rotor
from _models import GSI_DECK
from frirom._errors import InputError
from frirom.io import read_calculix, write_calculix_matrices
from frirom.deck import load_deck
from frirom.reduction.interface import contact_matrix, stick_stiffness
from frirom.reduction import rom as rom_module
from frirom.reduction.multistage import harmonic_indices


def _write(path, text):
    path.write_text(text)
    return path


def test_gsi_deck_builds_composes_and_caches(block_dir):
    deck = _write(block_dir / "joint.toml", GSI_DECK.format(kt="2.0e8", h=3, mu=0.5))
    d = load_deck(deck)
    rom = d.reduced
    fe = read_calculix(block_dir / "block")
    n_act = fe.dof_indices("ACTIVE").size
    assert rom.K.shape == (12 + n_act + 30,) * 2 and not rom.from_cache
    # the composed map reproduces the reduced matrices and the contact map
    assert np.linalg.norm(rom.T.T @ (fe.K @ rom.T) - rom.K) < 1e-9 * np.linalg.norm(rom.K)
    assert np.linalg.norm(rom.T.T @ (fe.M @ rom.T) - rom.M) < 1e-9 * np.linalg.norm(rom.M)
    G = rom.contact_matrix("end")
    g_fe = contact_matrix(rom.pairs["end"], fe.n_dof)
    assert abs(G - sp.csr_matrix(g_fe @ rom.T)).max() < 1e-12 * abs(G).max()
    assert G.shape == (3 * fe.node_sets["IFACE"].size, rom.K.shape[0])
    i = rom.dof_index(f"N{fe.node_sets['ACTIVE'][0]}:UZ")
    assert np.isclose(rom.T[fe.dof_indices("ACTIVE", directions=(3,))[0], i], 1.0)
    # the deck's contacts, loads and outputs are the physical ones seen through T
    c = d.contacts[0]
    assert c.law == "normal2d" and abs(c.G - G).max() == 0.0
    assert c.params.shape == (fe.node_sets["IFACE"].size, 4) and np.all(c.params[:, 2] == 0.5)
    iz = fe.dof_indices("ACTIVE", directions=(3,))[0]
    assert np.allclose(d.F[:, 1], rom.T[iz]) and not np.any(d.F[:, 0])
    assert d.outputs[0] == i and d.output_names == ["ACTIVE:z", "ACTIVE:x"]
    assert "built" in d.log[0] and d.model().n_dof == rom.K.shape[0]
    # stuck frequencies of the ROM close to the FE model's (CB 30 + 12 GSI modes)
    ks = stick_stiffness(rom.pairs["end"], fe.n_dof)
    lam_fe = sla.eigh((fe.K + ks).toarray(), fe.M.toarray(), eigvals_only=True,
                      subset_by_index=[0, 4])
    kr = rom.K + (G.T @ sp.diags(rom.pairs["end"].stiffness.ravel()) @ G).toarray()
    lam = sla.eigh(kr, rom.M, eigvals_only=True, subset_by_index=[0, 4])
    assert np.all(lam >= lam_fe * (1 - 1e-9)) and np.abs(np.sqrt(lam / lam_fe) - 1).max() < 1e-2
    # nonlinear/solver data changed only: reused; stick stiffness changed: rebuilt
    deck = _write(block_dir / "joint.toml", GSI_DECK.format(kt="2.0e8", h=7, mu=0.3))
    again = load_deck(deck).reduced
    assert again.from_cache and np.array_equal(again.K, rom.K)
    assert "not recomputed" in load_deck(deck).log[0]
    deck = _write(block_dir / "joint.toml", GSI_DECK.format(kt="3.0e8", h=7, mu=0.3))
    other = load_deck(deck).reduced
    assert not other.from_cache and not np.allclose(other.K, rom.K)


#: One edit of the good GSI deck each (old text -> new text), and what the error must say.
BAD_DECK_EDITS = [
    # [fe_model] and [reduction]
    ('format = "calculix"', 'format = "nastran"', "fe_model.format"),
    ('job = "block"', 'job = "blob"', "fe_model.job: expected a job name"),
    ('method = "gsi"', 'method = "pod"',
     "reduction.interface_modes.method: expected one of 'none', 'gsi', 'ms'"),
    ("free = 6", "free = -1", "reduction.interface_modes.free"),
    ("fixed_interface_modes = 30", "fixed_modes = 30",
     "reduction.fixed_modes: expected one of the known keys"),
    ('interface = "IFACE"\nactive = ["ACTIVE"]', 'interface = "ACTIVE"',
     "is not in the node sets of reduction.interface"),
    # [[contacts]]
    ('a = "IFACE"', 'a = "NOPE"', "contacts[0]: unknown node set"),
    ("kn = 8.0e8", "kn = -1.0", "contacts[0].kn: expected a number >= 0"),
    ("mu = 0.5", "mu = [0.5]", "contacts[0].mu: expected a number"),
    ("normal = [1.0, 0.0, 0.0]", 'normal = "up"', "contacts[0].normal: expected one of 'axial'"),
    ("normal = [1.0, 0.0, 0.0]", "normal = [1.0, 0.0, 0.0]\ntangent = [2.0, 0.0, 0.0]",
     "contacts[0]: local_frames: a tangent"),
    # loads and outputs by node
    ('dof = "ACTIVE:z"', 'dof = "ACTIVE:w"', 'excitation.load[0].dof: expected a DoF "NODE:DIR"'),
    ('dof = "ACTIVE:z"', 'dof = "TIP:z"',
     "excitation.load[0].dof: expected a node id or a node set name"),
    ('dofs = ["ACTIVE:z", "ACTIVE:x"]', 'dofs = ["ACTIVE:z", "IFACE:x"]',
     "outputs.dofs[1]: expected one node (set IFACE has"),
    # any FE DoF is an output (recovered through the basis): only unknown ones fail
    ('dofs = ["ACTIVE:z", "ACTIVE:x"]', 'dofs = ["999999:z"]',
     "outputs.dofs[0]: node 999999 has no DoF"),
    # tables that do not go with [fe_model]
    ("[reduction]", "[model]\nmass = 'M.mtx'\n\n[reduction]", "model: expected either [model]"),
    ("[[contacts]]", "[[reduction.pairs]]", "reduction.pairs: expected no"),
    ('type = "modal"\nzeta = 0.01', 'type = "matrix"\nfile = "C.mtx"',
     "damping.type: expected 'rayleigh' or 'modal' with [fe_model]"),
]


@pytest.mark.parametrize("old, new, expected", BAD_DECK_EDITS)
def test_deck_errors_name_the_key(block_dir, old, new, expected):
    good = GSI_DECK.format(kt="2.0e8", h=3, mu=0.5)
    assert old in good
    deck = _write(block_dir / "bad.toml", good.replace(old, new))
    with pytest.raises(InputError) as exc:
        load_deck(deck)
    assert expected in str(exc.value) and "bad.toml" in str(exc.value), str(exc.value)


def test_ms_deck_on_a_rotor_is_exact_for_its_engine_order(tmp_path):
    """A tuned lattice rotor written as ccx matrix files + an .inp with nodes and sets,
    reduced through the deck with MS for EO 2: exact for an EO-2 travelling wave."""
    r = tuned_rotor(axis=(0.0, 0.0, 1.0), origin=(0.0, 0.0, 0.0))
    n_nodes = len(r["coords"])
    ids = np.arange(1, n_nodes + 1)
    dofs = np.column_stack([np.repeat(ids, 3), np.tile([1, 2, 3], n_nodes)])
    write_calculix_matrices(tmp_path / "rotor", r["K"], r["M"], dofs)
    with open(tmp_path / "rotor.inp", "w") as fh:
        fh.write("*NODE\n")
        for i, (x, y, z) in zip(ids, r["coords"]):
            fh.write(f"{i}, {x:.17g}, {y:.17g}, {z:.17g}\n")
        for name, nodes in (("FLANGE", r["iface_nodes"] + 1), ("TIPS", r["tips"] + 1),
                            ("TIP0", r["tips"][:1] + 1)):
            fh.write(f"*NSET, NSET={name}\n")
            fh.write("\n".join(str(v) for v in nodes) + "\n")
    deck = _write(tmp_path / "rotor.toml", """
[fe_model]
format = "calculix"
job = "rotor"

[reduction]
interface = "FLANGE"
active = "TIPS"

[reduction.interface_modes]
method = "ms"
sectors = 7
engine_orders = [2]

[damping]
type = "rayleigh"

[[excitation.load]]
dof = "TIP0:x"
amplitude = 1.0

[solver]
harmonics = 1

[frequency]
start = 100.0
end = 200.0

[outputs]
dofs = ["TIP0:x"]
""")
    d = load_deck(deck)
    rom = d.reduced
    tip0 = r["tips"][0]
    assert d.outputs == [rom.dof_index(f"N{tip0 + 1}:UX")]
    n_if = 3 * r["iface_nodes"].size
    idx = harmonic_indices(2, 7, 21)
    assert rom.K.shape[0] == r["K"].shape[0] - n_if + 2 * idx.size * 9
    f = np.zeros(r["K"].shape[0], complex)
    for s, tip in enumerate(r["tips"]):
        th = 2 * np.pi * s / 7
        f[r["dofs"][tip]] = np.array([np.cos(th), np.sin(th), 0.4]) * np.exp(-2j * th)
    om = 1500.0
    K, M = r["K"].toarray(), r["M"].toarray()
    x = np.linalg.solve(K * (1 + 0.01j) - om**2 * M, f)
    y = np.linalg.solve(rom.K * (1 + 0.01j) - om**2 * rom.M, rom.T.T @ f)
    assert np.linalg.norm(rom.expand(y) - x) < 1e-10 * np.linalg.norm(x)


def test_cache_is_keyed_by_content_not_by_deck_name(block_dir, tmp_path, monkeypatch):
    """Two decks (other names, other excitation) share one cache entry, read back
    unchanged; an edit of an FE file's content (a CalculiX comment line: same matrices)
    or another reduction code version builds a new entry. The entry sits beside the FE files, whatever the decks' names."""
    monkeypatch.delenv("FRIROM_CACHE", raising=False)
    fe = tmp_path / "fe"
    fe.mkdir()
    for f in block_dir.glob("block.*"):
        shutil.copy(f, fe / f.name)
    text = GSI_DECK.format(kt="2.0e8", h=3, mu=0.5).replace('job = "block"',
                                                          'job = "fe/block"')
    a = load_deck(_write(tmp_path / "variant_a.toml", text))
    b = load_deck(_write(tmp_path / "other_name.toml",
                         text.replace("amplitude = 1.0", "amplitude = 5.0")))
    entries = sorted((fe / ".frirom_cache").glob("rom-*.h5"))
    assert len(entries) == 1 and not a.reduced.from_cache and b.reduced.from_cache
    assert f"reused from {entries[0]}" in b.log[0]
    assert np.array_equal(a.reduced.K, b.reduced.K) and np.array_equal(a.reduced.T, b.reduced.T)
    assert np.allclose(b.F, 5.0 * a.F, rtol=0, atol=0)
    assert not list(tmp_path.glob("*.rom.h5"))
    inp = fe / "block.inp"
    inp.write_text(inp.read_text() + "** edited\n")
    c = load_deck(tmp_path / "variant_a.toml")
    assert not c.reduced.from_cache and "built" in c.log[0]
    assert len(list((fe / ".frirom_cache").glob("rom-*.h5"))) == 2
    # another version of the reduction code: not reused
    monkeypatch.setattr(rom_module, "_code_version", lambda: "another")
    assert not load_deck(tmp_path / "variant_a.toml").reduced.from_cache
    # an explicit folder is a shared cache too; an explicit *.h5 file is used as before
    d = load_deck(_write(tmp_path / "in_folder.toml", text.replace(
        "fixed_interface_modes = 30", 'fixed_interface_modes = 30\ncache = "store"')))
    assert len(list((tmp_path / "store").glob("rom-*.h5"))) == 1 and not d.reduced.from_cache


def test_mtx_fe_model_with_node_set_file(block_dir, tmp_path):
    """[fe_model] format = "mtx" takes its nodes and node sets from `inp` (the matrix
    files carry none): the same block as the calculix deck gives the same reduced model
    (the MatrixMarket copies hold the matrices to 17 digits: to round-off)."""
    from frirom.io import write_dof_table, write_mtx
    fe = read_calculix(block_dir / "block")
    write_mtx(tmp_path / "K.mtx", fe.K)
    write_mtx(tmp_path / "M.mtx", fe.M)
    write_dof_table(tmp_path / "dofs.txt", fe.dofs)
    shutil.copy(block_dir / "block.inp", tmp_path / "nodes.inp")
    fe_mtx = ('format = "mtx"\nstiffness = "K.mtx"\nmass = "M.mtx"\ndofs = "dofs.txt"\n'
              'inp = "nodes.inp"')
    text = GSI_DECK.format(kt="2.0e8", h=3, mu=0.5)
    ref = load_deck(_write(block_dir / "ref.toml", text)).reduced
    rom = load_deck(_write(tmp_path / "mtx.toml", text.replace(
        'format = "calculix"\njob = "block"', fe_mtx))).reduced
    assert abs(rom.K - ref.K).max() <= 1e-9 * abs(ref.K).max()
    # without inp the deck's node sets are unknown, and the message says where they go
    with pytest.raises(InputError, match="inp"):
        load_deck(_write(tmp_path / "bare.toml", text.replace(
            'format = "calculix"\njob = "block"', fe_mtx.replace('\ninp = "nodes.inp"', ""))))
