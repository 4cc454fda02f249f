"""Round trips of every matrix reader, and the errors malformed files must give.

Reference: a random sparse symmetric positive definite matrix with a (node, direction)
map, written in each format. Formats that store 17 significant digits must give the
matrix back exactly (bit for bit); ccx's .sti/.mas keep 14 digits, so 1e-13 relative.
"""

from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from frirom import InputError
from frirom import io


def _model(n_nodes=13, seed=0):
    rng = np.random.default_rng(seed)
    n = 3 * n_nodes
    A = sp.random(n, n, density=0.15, random_state=rng, format="csr")
    A = A + A.T + sp.diags(np.full(n, 10.0))
    B = sp.random(n, n, density=0.1, random_state=rng, format="csr")
    B = B + B.T + sp.diags(np.full(n, 5.0))
    nodes = rng.permutation(np.arange(100, 100 + 2 * n_nodes))[:n_nodes]
    nodes.sort()
    dofs = np.column_stack([np.repeat(nodes, 3), np.tile([1, 2, 3], n_nodes)])
    return A.tocsr(), B.tocsr(), dofs


def _same(A, B, rtol=0.0):
    D = abs(sp.csr_matrix(A) - sp.csr_matrix(B))
    assert D.max() <= rtol * abs(A).max()


def test_matrix_market_round_trip(tmp_path):
    K, M, dofs = _model()
    io.write_mtx(tmp_path / "k.mtx", K)
    io.write_mtx(tmp_path / "m.mtx", M, symmetric=False)
    io.write_dof_table(tmp_path / "dofs.txt", dofs)
    m = io.read_matrix_market(tmp_path / "k.mtx", tmp_path / "m.mtx", tmp_path / "dofs.txt")
    _same(m.K, K)
    _same(m.M, M)
    assert np.array_equal(m.dofs, dofs)
    # scipy's own reader agrees (independent parser of the same format)
    import scipy.io
    _same(scipy.io.mmread(tmp_path / "k.mtx"), K)


def test_calculix_round_trip(tmp_path):
    K, M, dofs = _model()
    io.write_calculix_matrices(tmp_path / "job", K, M, dofs)
    (tmp_path / "job.inp").write_text(
        "** deck\n*NODE, NSET=ALL\n" + "".join(f"{n}, {n}.0, 0.5, 1e-3\n" for n in
                                             np.unique(dofs[:, 0]))
        + "*NSET, NSET=A\n%d, %d\n*NSET, NSET=B, GENERATE\n%d, %d, 1\n*NSET, NSET=C\nA, B\n"
        % (dofs[0, 0], dofs[3, 0], dofs[6, 0], dofs[9, 0]))
    m = io.read_calculix(tmp_path / "job.sti")
    _same(m.K, K, 1e-13)
    _same(m.M, M, 1e-13)
    assert np.array_equal(m.dofs, dofs)
    assert np.array_equal(m.node_sets["A"], [dofs[0, 0], dofs[3, 0]])
    assert np.array_equal(m.node_sets["B"], np.arange(dofs[6, 0], dofs[9, 0] + 1))
    assert set(m.node_sets["C"]) == set(m.node_sets["A"]) | set(m.node_sets["B"])
    assert np.allclose(m.coordinates([dofs[3, 0]]), [[dofs[3, 0], 0.5, 1e-3]])
    idx = m.dof_indices("a", directions=(2,))
    assert np.array_equal(m.dofs[idx], [[dofs[0, 0], 2], [dofs[3, 0], 2]])


@pytest.mark.parametrize("fmt", ["matrix input", "coordinate"])
def test_abaqus_round_trip(tmp_path, fmt):
    K, M, dofs = _model()
    io.write_abaqus_matrix(tmp_path / "job_STIF2.mtx", K, dofs, fmt=fmt)
    io.write_abaqus_matrix(tmp_path / "job_MASS2.mtx", M, dofs, fmt=fmt)
    m = io.read_abaqus(tmp_path / "job_STIF2.mtx", tmp_path / "job_MASS2.mtx",
                       dofs=dofs if fmt == "coordinate" else None)
    _same(m.K, K)
    _same(m.M, M)
    assert np.array_equal(m.dofs, dofs)


def test_abaqus_reads_a_hand_written_matrix_output_file():
    """tests/data/abaqus_{STIF2,MASS2}.mtx, written by hand (not by write_abaqus_matrix) in
    the layout of Abaqus's *MATRIX GENERATE + *MATRIX OUTPUT, FORMAT=MATRIX INPUT: one line
    'row node, row dof, column node, column dof, value' per entry of the lower triangle,
    column by column, 16 significant digits; the stiffness file with Abaqus's '7,1, 7,1,'
    spacing, the mass file with blanks after every comma. Nodes 7, 12 and 40 carry only
    the DoFs the files name (node 12 has x and z, node 40 only y), so the reader must
    build the (node, direction) map from the labels. Decimal values parse to the same
    doubles as the literals below: the comparison is exact."""
    data = Path(__file__).resolve().parent / "data"
    m = io.read_abaqus(data / "abaqus_STIF2.mtx", data / "abaqus_MASS2.mtx")
    assert m.dofs.tolist() == [[7, 1], [7, 2], [12, 1], [12, 3], [40, 2]]
    # the files' entries mirrored into the upper triangle, N/m and kg
    K = np.array([[4.0e6, -1.5e6, -2.0e6, 0.0, 0.0],
                  [-1.5e6, 3.0e6, 0.0, 5.0e5, -1.0e6],
                  [-2.0e6, 0.0, 5.0e6, 0.0, -2.5e6],
                  [0.0, 5.0e5, 0.0, 1.234567890123457e6, 0.0],
                  [0.0, -1.0e6, -2.5e6, 0.0, 3.5e6]])
    M = np.array([[0.2, 0.0, 0.05, 0.0, 0.0],
                  [0.0, 0.2, 0.0, 0.0, 0.0],
                  [0.05, 0.0, 0.3, 0.0, 0.0],
                  [0.0, 0.0, 0.0, 1.0e-3, 0.0],
                  [0.0, 0.0, 0.0, 0.0, 0.15]])
    assert np.array_equal(m.K.toarray(), K)
    assert np.array_equal(m.M.toarray(), M)
    assert np.array_equal(m.dof_indices(nodes=[12], directions=(3,)), [3])


def test_abaqus_square_storage_is_checked(tmp_path):
    K, M, dofs = _model()
    A = sp.coo_matrix(K)
    lines = [f"{r + 1}, {c + 1}, {float(v)!r}" for r, c, v in zip(A.row, A.col, A.data)]
    (tmp_path / "full.mtx").write_text("\n".join(lines) + "\n")
    _same(io.read_abaqus(tmp_path / "full.mtx", fmt="coordinate").K, K)
    B = sp.coo_matrix(K + sp.triu(K, 1) * 1e-3)       # asymmetric square storage
    lines = [f"{r + 1}, {c + 1}, {float(v)!r}" for r, c, v in zip(B.row, B.col, B.data)]
    (tmp_path / "bad.mtx").write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match="bad.mtx.*not symmetric"):
        io.read_abaqus(tmp_path / "bad.mtx")


def test_harwell_boeing_round_trip(tmp_path):
    K, M, dofs = _model()
    io.write_hb(tmp_path / "k.matrix", K)                        # RSA
    io.write_hb(tmp_path / "m.matrix", M, symmetric=False)       # RUA
    io.write_ansys_mapping(tmp_path / "k.mapping", dofs)
    m = io.read_hbmat(tmp_path / "k.matrix", tmp_path / "m.matrix")
    _same(m.K, K)
    _same(m.M, M)
    assert np.array_equal(m.dofs, dofs)
    # scipy reads the unsymmetric (RUA) file: an independent parser agrees
    import scipy.io
    _same(scipy.io.hb_read(tmp_path / "m.matrix"), M)


def test_harwell_boeing_fixed_width_fields(tmp_path):
    """Hand-written RSA file whose E13.6 value fields touch (no separating blanks)."""
    text = (f"{'3x3 test':<72}{'KEY':<8}\n"
            f"{5:14d}{1:14d}{1:14d}{3:14d}{0:14d}\n"
            f"{'RSA':<14}{3:14d}{3:14d}{5:14d}{0:14d}\n"
            f"{'(4I3)':<16}{'(5I3)':<16}{'(2E13.6)':<20}\n"
            "  1  3  5  6\n"
            "  1  2  2  3  3\n"
            "-1.000000E+01-2.500000E+00\n"
            " 2.000000E+01-3.000000D+00\n"
            " 4.000000E+01\n")
    (tmp_path / "t.matrix").write_text(text)
    A = io.read_hb(tmp_path / "t.matrix").toarray()
    ref = np.array([[-10.0, -2.5, 0.0], [-2.5, 20.0, -3.0], [0.0, -3.0, 40.0]])
    assert np.array_equal(A, ref)


def test_op4_round_trip(tmp_path):
    op4 = pytest.importorskip("pyyeti.nastran.op4")
    K, M, dofs = _model()
    op4.write(str(tmp_path / "km.op4"), {"kaa": K.toarray(), "maa": M.tocoo()})
    m = io.read_op4(tmp_path / "km.op4", dofs=dofs)
    _same(m.K, K)
    _same(m.M, M)
    with pytest.raises(InputError, match="KXX"):
        io.read_op4(tmp_path / "km.op4", stiffness="KXX")


# Small MatrixMarket files of each layout and field scipy reads; read_mtx must agree.
_MTX = {
    "array-general": "%%MatrixMarket matrix array real general\n% column by column\n3 3\n"
                     "1.0\n4.0\n0.0\n2.0\n5.0\n7.0\n3.0\n-6.0\n9.5\n",
    "array-symmetric": "%%MatrixMarket matrix array real symmetric\n3 3\n"
                       "10.0\n-1.0\n2.5\n20.0\n0.0\n30.0\n",
    "coordinate-symmetric-upper": "%%MatrixMarket matrix coordinate real symmetric\n"
                                  "3 3 5\n1 1 4.0\n1 2 -1.5\n2 2 5.0\n1 3 0.25\n"
                                  "3 3 6.0\n",
    "coordinate-symmetric-lower": "%%MatrixMarket matrix coordinate real symmetric\n"
                                  "3 3 5\n1 1 4.0\n2 1 -1.5\n2 2 5.0\n3 1 0.25\n"
                                  "3 3 6.0\n",
    "coordinate-integer": "%%MatrixMarket matrix coordinate integer general\n"
                          "3 3 4\n1 1 7\n2 1 -3\n1 2 -3\n3 3 12\n",
    "array-integer": "%%MatrixMarket matrix array integer symmetric\n2 2\n3\n-1\n8\n",
}


@pytest.mark.parametrize("name", list(_MTX))
def test_read_mtx_agrees_with_scipy(tmp_path, name):
    import scipy.io
    p = tmp_path / f"{name}.mtx"
    p.write_text(_MTX[name])
    ref = scipy.io.mmread(p)
    ref = ref.toarray() if sp.issparse(ref) else np.asarray(ref)
    A = io.read_mtx(p, symmetric=False)
    assert sp.isspmatrix_csr(A) and A.dtype == np.float64
    assert np.array_equal(A.toarray(), ref)
    if np.array_equal(ref, ref.T):
        assert np.array_equal(io.read_mtx(p).toarray(), ref)
    else:                                       # array-general holds both triangles
        with pytest.raises(InputError, match="not symmetric"):
            io.read_mtx(p)


def test_read_mtx_refuses_both_triangles_of_a_pair_and_pattern(tmp_path):
    p = tmp_path / "both.mtx"
    p.write_text("%%MatrixMarket matrix coordinate real symmetric\n3 3 4\n1 1 4.0\n"
                 "3 1 0.5\n2 2 5.0\n1 3 0.5\n")
    with pytest.raises(InputError, match=r"both.mtx, line 6: .*line 4 holds the other"):
        io.read_mtx(p, symmetric=False)
    p = tmp_path / "pattern.mtx"
    p.write_text("%%MatrixMarket matrix coordinate pattern symmetric\n2 2 2\n1 1\n2 1\n")
    with pytest.raises(InputError, match=r"pattern.mtx, line 1: .*pattern file holds no "
                                         r"values"):
        io.read_mtx(p)
    p = tmp_path / "short.mtx"
    p.write_text("%%MatrixMarket matrix array real symmetric\n3 3\n1.0\n2.0\n")
    with pytest.raises(InputError, match=r"short.mtx, line 4: expected 6 values"):
        io.read_mtx(p)


@pytest.mark.parametrize("case", [
    ("k.mtx", "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1.0\n2 1 x\n",
     "line 4", lambda p: io.read_mtx(p)),
    ("k.mtx", "%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1.0 0.0\n",
     "line 1", lambda p: io.read_mtx(p)),
    ("k.mtx", "%%MatrixMarket matrix coordinate real general\n2 2 2\n1 1 1.0\n2 2\n",
     "line 4", lambda p: io.read_mtx(p)),
    ("job.dof", "1.1\n1.2\n1,3\n", "line 3", lambda p: io.read_calculix(p)),
    ("k.inp", "*NODE\n1, 0, 0, 0\n2, 0.0, abc, 0\n", "line 3", lambda p: io.read_inp(p)),
    ("k_STIF1.mtx", "1,1, 1,1, 2.0\n1,1, 2,1\n", "line 2", lambda p: io.read_abaqus(p)),
    ("k_STIF1.mtx", "** header\n1,1, 1,1, 2.0\n1,x, 2,1, 1.0\n", "line 3",
     lambda p: io.read_abaqus(p)),
    ("k.matrix", "title\n1 1 1 1 0\nRZA 2 2 2 0\n(3I3) (3I3) (3E13.6)\n",
     "line 3", lambda p: io.read_hb(p)),
    ("k.matrix", f"{'t':<80}\n 3 1 1 1 0\nRSA 2 2 2 0\n(3I3) (3I3) (3E13.6)\n"
     "  1  2  3\n  1 x2\n 1.0E0 2.0E0\n", "line 6", lambda p: io.read_hb(p)),
    ("k.mapping", " Matrix Eqn Node DOF\n 1 1 UX\n 2 1 TEMP\n", "line 3",
     lambda p: io.read_ansys_mapping(p)),
], ids=["mtx-value", "mtx-banner", "mtx-fields", "ccx-dof", "inp-node", "abq-fields",
        "abq-int", "hb-type", "hb-index", "mapping-label"])
def test_malformed_files_name_file_and_line(tmp_path, case):
    name, text, where, reader = case
    p = tmp_path / name
    p.write_text(text)
    if name == "job.dof":
        (tmp_path / "job.sti").write_text("1 1 1.0\n")
        (tmp_path / "job.mas").write_text("1 1 1.0\n")
    with pytest.raises(InputError) as err:
        reader(p)
    msg = str(err.value)
    assert name in msg and where in msg and "expected" in msg, msg


def test_missing_file_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match="nothere.dof"):
        io.read_calculix(tmp_path / "nothere")


def test_constrain_removes_dofs_like_ccx(tmp_path):
    """Removing a node's DoFs from an unconstrained model gives the constrained matrices."""
    K, M, dofs = _model()
    m = io.FEModel(K=K, M=M, dofs=dofs, node_sets={"CLAMP": dofs[[0, 3], 0]})
    c = m.constrain("CLAMP", directions=(1, 2, 3))
    keep = ~np.isin(dofs[:, 0], dofs[[0, 3], 0])
    _same(c.K, K[keep][:, keep])
    _same(c.M, M[keep][:, keep])
    assert np.array_equal(c.dofs, dofs[keep])
    assert c.constrained.shape == (6, 2)
