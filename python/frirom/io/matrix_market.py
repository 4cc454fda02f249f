"""MatrixMarket coordinate files (``.mtx``), real or integer, general or symmetric.

A DoF map is not part of the format: pass it as an (n_dof, 2) array or as a text file of
``node direction`` lines (one per matrix row), as frirom writes next to exported matrices.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ._common import FEModel, fail, parse_table, read_lines, symmetric_from_triplets

__all__ = ["read_mtx", "write_mtx", "read_matrix_market", "read_dof_table",
           "write_dof_table"]


def read_mtx(path, symmetric: bool = True) -> sp.csr_matrix:
    """Square matrix from a MatrixMarket coordinate file (full CSR storage).

    symmetric : True (default) returns a symmetric matrix: a ``symmetric`` file, or a
    ``general`` one holding one triangle, is mirrored; a ``general`` one holding both is
    checked (InputError if it is not symmetric). False returns the matrix the file means:
    a ``symmetric`` file mirrored, a ``general`` one entry by entry, unchecked.
    """
    lines = read_lines(path)
    if not lines or not lines[0].lower().startswith("%%matrixmarket"):
        fail(path, 1, "the banner '%%MatrixMarket matrix coordinate real symmetric|general'",
             lines[0] if lines else "empty file")
    banner = lines[0].lower().split()
    if (len(banner) != 5 or banner[1] != "matrix" or banner[2] != "coordinate"
            or banner[3] not in ("real", "integer", "double")
            or banner[4] not in ("symmetric", "general")):
        fail(path, 1, "'%%MatrixMarket matrix coordinate real|integer symmetric|general'",
             lines[0])
    i = 1
    while i < len(lines) and (not lines[i].strip() or lines[i].lstrip().startswith("%")):
        i += 1
    if i == len(lines):
        fail(path, i, "a size line 'rows cols entries'", "end of file")
    try:
        m, n, nnz = (int(t) for t in lines[i].split())
    except ValueError:
        fail(path, i + 1, "a size line 'rows cols entries'", lines[i])
    if m != n or m <= 0 or nnz < 0:
        fail(path, i + 1, "a square matrix size 'n n entries' with n > 0", lines[i])
    if nnz == 0:
        return sp.csr_matrix((n, n))
    r, c, v = parse_table(path, lines, i + 1, 3, "iif", "an entry 'row col value'")
    if r.size != nnz:
        fail(path, len(lines), f"{nnz} entries as the size line says", f"{r.size} entries")
    if banner[4] == "symmetric" and np.any(r < c):
        bad = int(np.argmax(r < c))
        fail(path, 0, "lower-triangle entries only in a symmetric MatrixMarket file",
             f"entry {bad + 1}: ({r[bad]}, {c[bad]})")
    if not symmetric and banner[4] == "general":
        out = (r < 1) | (c < 1) | (r > n) | (c > n)
        if np.any(out):
            bad = int(np.argmax(out))
            fail(path, 0, f"row and column indices in 1..{n}",
                 f"entry {bad + 1}: ({r[bad]}, {c[bad]})")
        A = sp.csr_matrix((v, (r - 1, c - 1)), shape=(n, n))
        A.sum_duplicates()
        return A
    return symmetric_from_triplets(path, r - 1, c - 1, v, n)


def write_mtx(path, A, symmetric: bool = True, comment: str = "") -> None:
    """Write A as MatrixMarket coordinate real (lower triangle when symmetric)."""
    A = sp.coo_matrix(A)
    if symmetric:
        A = sp.tril(A).tocoo()
    with open(path, "w") as fh:
        fh.write(f"%%MatrixMarket matrix coordinate real "
                 f"{'symmetric' if symmetric else 'general'}\n")
        for line in comment.splitlines():
            fh.write(f"% {line}\n")
        fh.write(f"{A.shape[0]} {A.shape[1]} {A.nnz}\n")
        for r, c, v in zip(A.row + 1, A.col + 1, A.data):
            fh.write(f"{r} {c} {v:.17g}\n")


def read_dof_table(path, n: int | None = None) -> np.ndarray:
    """(n_dof, 2) array from a text file of ``node direction`` lines ('#' comments)."""
    lines = read_lines(path)
    first = 0
    while first < len(lines) and (not lines[first].strip()
                                  or lines[first].lstrip().startswith("#")):
        first += 1
    nd, d = parse_table(path, lines, first, 2, "ii", "'node direction'")
    if np.any((d < 0) | (d > 6)):
        fail(path, 0, "directions 1..6", str(d[(d < 0) | (d > 6)][0]))
    if n is not None and nd.size != n:
        fail(path, len(lines), f"{n} DoF lines (one per matrix row)", f"{nd.size} lines")
    return np.column_stack([nd, d])


def write_dof_table(path, dofs) -> None:
    with open(path, "w") as fh:
        fh.write("# node direction\n")
        for nd, d in np.asarray(dofs):
            fh.write(f"{nd} {d}\n")


def read_matrix_market(stiffness, mass=None, dofs=None) -> FEModel:
    """FEModel from MatrixMarket K (and M) files and an optional DoF map (array or file)."""
    K = read_mtx(stiffness)
    M = read_mtx(mass) if mass is not None else None
    if M is not None and M.shape != K.shape:
        fail(mass, 0, f"a {K.shape[0]} x {K.shape[0]} matrix like {stiffness}",
             f"{M.shape[0]} x {M.shape[1]}")
    source = [str(stiffness)] + ([str(mass)] if mass is not None else [])
    if dofs is None:
        dofs = np.column_stack([np.arange(1, K.shape[0] + 1), np.zeros(K.shape[0], int)])
    elif isinstance(dofs, np.ndarray) or isinstance(dofs, (list, tuple)):
        dofs = np.asarray(dofs, dtype=np.int64)
        if dofs.shape != (K.shape[0], 2):
            fail(stiffness, 0, f"a DoF map of shape ({K.shape[0]}, 2)", str(dofs.shape))
    else:
        source.append(str(dofs))
        dofs = read_dof_table(dofs, K.shape[0])
    return FEModel(K=K, M=M, dofs=dofs.astype(np.int64), source=source)
