"""MatrixMarket files (``.mtx``): coordinate or array, real or integer, general or symmetric.

A DoF map is not part of the format: pass it as an (n_dof, 2) array or as a text file of
``node direction`` lines (one per matrix row), as frirom writes next to exported matrices.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ._common import FEModel, fail, parse_table, read_lines, symmetric_from_triplets

__all__ = ["read_mtx", "write_mtx", "read_matrix_market", "read_dof_table",
           "write_dof_table"]

_BANNER = "'%%MatrixMarket matrix coordinate|array real|integer general|symmetric'"


def read_mtx(path, symmetric: bool = True) -> sp.csr_matrix:
    """Square matrix from a MatrixMarket file (full CSR storage, float64).

    Layouts: ``coordinate`` (one ``row col value`` line per entry) and ``array`` (every
    value, one per line, column by column; a ``symmetric`` array holds the lower triangle
    column by column). Fields ``real`` and ``integer`` (read as real); a ``pattern`` file
    holds no values and is refused. A ``symmetric`` coordinate file may store either
    triangle (the format says lower, some exporters write upper): every off-diagonal entry
    is mirrored, and an (i, j) entry next to a (j, i) one is an error.

    symmetric : True (default) returns a symmetric matrix: a ``symmetric`` file, or a
    ``general`` one holding one triangle, is mirrored; a ``general`` one holding both is
    checked (InputError if it is not symmetric). False returns the matrix the file means:
    a ``symmetric`` file mirrored, a ``general`` one entry by entry, unchecked.
    """
    lines = read_lines(path)
    layout, symmetry = _banner(path, lines)
    i = 1
    while i < len(lines) and (not lines[i].strip() or lines[i].lstrip().startswith("%")):
        i += 1
    if layout == "array":
        n, r, c, v = _array_entries(path, lines, i, symmetry)
    else:
        n, r, c, v = _coordinate_entries(path, lines, i)
        if symmetry == "symmetric":
            _check_one_of_each_pair(path, lines, i + 1, n, r, c)
    if symmetry == "symmetric":
        off = r != c
        r, c, v = (np.concatenate([r, c[off]]), np.concatenate([c, r[off]]),
                   np.concatenate([v, v[off]]))
    elif symmetric:
        return symmetric_from_triplets(path, r - 1, c - 1, v, n)
    A = sp.csr_matrix((v, (r - 1, c - 1)), shape=(n, n))
    A.sum_duplicates()
    A.sort_indices()
    return A


def _banner(path, lines) -> tuple[str, str]:
    """The layout ('coordinate' or 'array') and symmetry ('general' or 'symmetric')."""
    if not lines or not lines[0].lower().startswith("%%matrixmarket"):
        fail(path, 1, f"the banner {_BANNER}", lines[0] if lines else "empty file")
    banner = lines[0].lower().split()
    if len(banner) == 5 and banner[3] == "pattern":
        fail(path, 1, "a real or integer field: a pattern file holds no values (a "
             "stiffness, mass or damping matrix needs them)", lines[0])
    if (len(banner) != 5 or banner[1] != "matrix" or banner[2] not in ("coordinate", "array")
            or banner[3] not in ("real", "integer", "double")
            or banner[4] not in ("symmetric", "general")):
        fail(path, 1, _BANNER, lines[0])
    return banner[2], banner[4]


def _size(path, lines, i: int, fields: str) -> list[int]:
    """The size line lines[i] ('rows cols' or 'rows cols entries') of a square matrix."""
    what = f"a size line '{fields}'"
    if i == len(lines):
        fail(path, i, what, "end of file")
    try:
        size = [int(t) for t in lines[i].split()]
    except ValueError:
        fail(path, i + 1, what, lines[i])
    if len(size) != len(fields.split()):
        fail(path, i + 1, what, lines[i])
    if size[0] != size[1] or size[0] <= 0 or min(size) < 0:
        fail(path, i + 1, f"a square matrix size '{fields}' with n > 0", lines[i])
    return size


def _coordinate_entries(path, lines, i: int):
    """n and the 1-based triplets (rows, cols, values) of a coordinate file."""
    n, _, nnz = _size(path, lines, i, "rows cols entries")
    if nnz == 0:
        return n, np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    r, c, v = parse_table(path, lines, i + 1, 3, "iif", "an entry 'row col value'")
    if r.size != nnz:
        fail(path, len(lines), f"{nnz} entries as the size line says", f"{r.size} entries")
    out = (r < 1) | (c < 1) | (r > n) | (c > n)
    if np.any(out):
        line = _entry_line(lines, i + 1, int(np.argmax(out)))
        fail(path, line, f"row and column indices in 1..{n}", lines[line - 1])
    return n, r, c, v


def _array_entries(path, lines, i: int, symmetry: str):
    """n and the 1-based triplets of the nonzero values of an array file."""
    n, _ = _size(path, lines, i, "rows cols")
    want = n * n if symmetry == "general" else n * (n + 1) // 2
    (v,) = parse_table(path, lines, i + 1, 1, "f", "a value (one per line)")
    if v.size != want:
        held = "n*n values" if symmetry == "general" else "n(n+1)/2 values (lower triangle)"
        fail(path, len(lines), f"{want} values ({held} of a {n} x {n} array)",
             f"{v.size} values")
    if symmetry == "general":
        c, r = np.divmod(np.arange(want, dtype=np.int64), n)
    else:
        c, r = np.triu_indices(n)          # upper (c, r), row by row = lower column-wise
    nz = v != 0.0
    return n, r[nz] + 1, c[nz] + 1, v[nz]


def _check_one_of_each_pair(path, lines, first: int, n: int, r, c) -> None:
    """InputError naming the line if a symmetric file holds both (i, j) and (j, i), i != j.

    first: index in ``lines`` of the first entry line; r, c: 1-based indices in 1..n,
    (nnz,).
    """
    pair = np.minimum(r, c) * (n + 1) + np.maximum(r, c)
    entry = np.arange(r.size)
    seen = []
    for side in (r > c, r < c):
        key, at = np.unique(pair[side], return_index=True)
        seen.append((key, entry[side][at]))
    both, a, b = np.intersect1d(seen[0][0], seen[1][0], return_indices=True)
    if both.size:
        later = np.maximum(seen[0][1][a], seen[1][1][b])
        k = int(np.argmin(later))
        earlier = int(min(seen[0][1][a][k], seen[1][1][b][k]))
        line = _entry_line(lines, first, int(later[k]))
        fail(path, line, "one of (i, j) and (j, i) in a symmetric file (it is mirrored), "
             f"not both: line {_entry_line(lines, first, earlier)} holds the other",
             lines[line - 1])


def _entry_line(lines, first: int, k: int) -> int:
    """1-based line number of entry k (0-based) of a table starting at lines[first]."""
    for j in range(first, len(lines)):
        if lines[j].strip():
            if k == 0:
                return j + 1
            k -= 1
    return len(lines)


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
