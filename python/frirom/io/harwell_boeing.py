"""Harwell-Boeing files as ANSYS ``HBMAT`` writes them, symmetric (RSA) included.

scipy.io.hb_read refuses symmetric matrices, so this reader parses the format itself:
four or five header lines (title/key; card counts; type and sizes; Fortran formats),
then column pointers, row indices and values in fixed-width Fortran fields. RSA stores
one triangle by columns; it is expanded to full storage. ``HBMAT, ..., Mapping=YES``
also writes ``Fname.mapping`` (one line per equation: equation number, node, DoF label),
which gives the DoF map.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ._common import (DIRECTION_NAMES, DIRECTION_NUMBERS, FEModel, fail, read_lines,
                      symmetric_from_triplets)

__all__ = ["read_hb", "write_hb", "read_ansys_mapping", "write_ansys_mapping", "read_hbmat"]

_FMT = re.compile(r"(\d*)\s*([IEDFG])\s*(\d+)", re.IGNORECASE)


def _fortran_format(path, line_no, fmt: str):
    """(fields per line, field width) of a Fortran format like (1P,4E20.12) or (10I8)."""
    m = None
    for m in _FMT.finditer(fmt.upper().replace("1P", "")):
        pass
    if m is None:
        fail(path, line_no, "a Fortran format like (10I8) or (1P,4E20.12)", fmt)
    count = int(m.group(1)) if m.group(1) else 1
    return count, int(m.group(3))


def _read_block(path, lines, first, ncards, count, width, nitems, kind, what):
    """nitems numbers from lines[first:first+ncards] in fixed fields (count per line)."""
    block = lines[first:first + ncards]
    if len(block) < ncards:
        fail(path, len(lines) + 1, f"{ncards} lines of {what}", "end of file")
    tokens = " ".join(block).split()
    if len(tokens) == nitems:       # fields separated by blanks: fast path
        try:
            if kind == "i":
                return np.array(tokens).astype(np.int64)
            vals = np.array([t.replace("D", "E").replace("d", "e") for t in tokens]
                            if any(("D" in t or "d" in t) for t in tokens[:50]) else tokens)
            out = vals.astype(np.float64)
            if np.all(np.isfinite(out)):
                return out
        except ValueError:
            pass
    out = []
    for k, line in enumerate(block):    # fields run together: cut by width
        for j in range(count):
            if len(out) == nitems:
                break
            field = line[j * width:(j + 1) * width].strip()
            if not field:
                break
            try:
                out.append(int(field) if kind == "i"
                           else float(field.replace("D", "E").replace("d", "e")))
            except ValueError:
                fail(path, first + k + 1, f"{what} ({'integer' if kind == 'i' else 'number'}"
                     f" fields of width {width})", line)
    if len(out) != nitems:
        fail(path, first + ncards, f"{nitems} {what}", f"{len(out)}")
    arr = np.array(out, dtype=np.int64 if kind == "i" else np.float64)
    if kind != "i" and not np.all(np.isfinite(arr)):
        fail(path, first + 1, f"finite {what}", "NaN or Inf")
    return arr


def read_hb(path) -> sp.csr_matrix:
    """Square real matrix (RSA or RUA, assembled) from a Harwell-Boeing file, full CSR."""
    lines = read_lines(path)
    if len(lines) < 4:
        fail(path, len(lines) + 1, "the 4 Harwell-Boeing header lines", "end of file")
    try:
        cards = [int(t) for t in lines[1].split()]
        if len(cards) == 4:
            cards.append(0)
        totcrd, ptrcrd, indcrd, valcrd, rhscrd = cards[:5]
    except ValueError:
        fail(path, 2, "card counts 'TOTCRD PTRCRD INDCRD VALCRD [RHSCRD]'", lines[1])
    if len(cards) < 4:
        fail(path, 2, "card counts 'TOTCRD PTRCRD INDCRD VALCRD [RHSCRD]'", lines[1])
    mxtype = lines[2][:3].upper()
    if len(mxtype) != 3 or mxtype[0] not in "RP" or mxtype[1] not in "SU" or mxtype[2] != "A":
        fail(path, 3, "matrix type RSA or RUA (real, symmetric or unsymmetric, assembled)",
             lines[2][:3])
    try:
        nrow, ncol, nnz = (int(t) for t in lines[2][3:].split()[:3])
    except ValueError:
        fail(path, 3, "'MXTYPE NROW NCOL NNZERO [NELTVL]'", lines[2])
    if nrow != ncol:
        fail(path, 3, "a square matrix", f"{nrow} x {ncol}")
    fmts = re.findall(r"\([^)]*\)", lines[3])
    if len(fmts) < 2 or (mxtype[0] == "R" and len(fmts) < 3):
        fail(path, 4, "Fortran formats 'PTRFMT INDFMT VALFMT [RHSFMT]'", lines[3])
    first = 4 + (1 if rhscrd > 0 else 0)
    pc, pw = _fortran_format(path, 4, fmts[0])
    ic, iw = _fortran_format(path, 4, fmts[1])
    ptr = _read_block(path, lines, first, ptrcrd, pc, pw, ncol + 1, "i", "column pointers")
    ind = _read_block(path, lines, first + ptrcrd, indcrd, ic, iw, nnz, "i", "row indices")
    if mxtype[0] == "P":
        val = np.ones(nnz)
    else:
        vc, vw = _fortran_format(path, 4, fmts[2])
        val = _read_block(path, lines, first + ptrcrd + indcrd, valcrd, vc, vw, nnz, "f",
                          "values")
    if ptr[0] != 1 or np.any(np.diff(ptr) < 0) or ptr[-1] != nnz + 1:
        fail(path, first + 1, f"column pointers rising from 1 to {nnz + 1}",
             f"{ptr[0]} .. {ptr[-1]}")
    if nnz and (ind.min() < 1 or ind.max() > nrow):
        fail(path, first + ptrcrd + 1, f"row indices in 1..{nrow}",
             f"{ind.min()} .. {ind.max()}")
    col = np.repeat(np.arange(ncol), np.diff(ptr))
    if mxtype[1] == "S":
        return symmetric_from_triplets(path, ind - 1, col, val, nrow)
    return symmetric_from_triplets(path, ind - 1, col, val, nrow)


def write_hb(path, A, title: str = "frirom", key: str = "frirom",
             symmetric: bool = True) -> None:
    """Write A as RSA (lower triangle by columns) or RUA, with 17 significant digits."""
    A = sp.csc_matrix(A)
    if symmetric:
        A = sp.csc_matrix(sp.tril(A))
    A.sort_indices()
    n = A.shape[0]
    ptr = A.indptr + 1
    ind = A.indices + 1
    iw = len(str(max(int(ptr[-1]), n))) + 1
    ic = 80 // iw
    vw, vc = 26, 3

    def ints(a):
        return ["".join(f"{v:{iw}d}" for v in a[k:k + ic]) for k in range(0, len(a), ic)]

    vals = ["".join(f"{v:{vw}.16E}" for v in A.data[k:k + vc])
            for k in range(0, len(A.data), vc)]
    pl, il = ints(ptr), ints(ind)
    with open(path, "w") as fh:
        fh.write(f"{title:<72.72}{key:<8.8}\n")
        fh.write(f"{len(pl) + len(il) + len(vals):14d}{len(pl):14d}{len(il):14d}"
                 f"{len(vals):14d}{0:14d}\n")
        fh.write(f"{'RSA' if symmetric else 'RUA':<14}{n:14d}{n:14d}{A.nnz:14d}{0:14d}\n")
        fh.write(f"{f'({ic}I{iw})':<16}{f'({ic}I{iw})':<16}{f'({vc}E{vw}.16)':<20}"
                 f"{'':<20}\n")
        for block in (pl, il, vals):
            fh.write("\n".join(block) + "\n")


def read_ansys_mapping(path, n: int | None = None) -> np.ndarray:
    """(n_dof, 2) DoF map from an ANSYS ``.mapping`` file ('eqn node label' lines)."""
    lines = read_lines(path)
    eq, nd, dr = [], [], []
    for i, raw in enumerate(lines):
        parts = raw.split()
        if not parts or not parts[0].lstrip("-").isdigit():
            if eq:
                fail(path, i + 1, "'equation node DoF-label'", raw)
            continue        # header line(s)
        if len(parts) != 3 or not parts[1].lstrip("-").isdigit():
            fail(path, i + 1, "'equation node DoF-label'", raw)
        lab = parts[2].upper()
        if lab not in DIRECTION_NUMBERS:
            fail(path, i + 1, f"a structural DoF label {sorted(DIRECTION_NUMBERS)}", parts[2])
        eq.append(int(parts[0]))
        nd.append(int(parts[1]))
        dr.append(DIRECTION_NUMBERS[lab])
    if not eq:
        fail(path, len(lines), "'equation node DoF-label' lines", "none")
    eq = np.array(eq)
    if not np.array_equal(np.sort(eq), np.arange(1, eq.size + 1)):
        fail(path, 0, f"equation numbers 1..{eq.size}, each once", "gaps or repeats")
    if n is not None and eq.size != n:
        fail(path, 0, f"{n} equations (the matrix size)", str(eq.size))
    dofs = np.zeros((eq.size, 2), np.int64)
    dofs[eq - 1, 0] = nd
    dofs[eq - 1, 1] = dr
    return dofs


def write_ansys_mapping(path, dofs) -> None:
    with open(path, "w") as fh:
        fh.write(" Matrix Eqn   Node       DOF\n")
        for i, (nd, d) in enumerate(np.asarray(dofs)):
            fh.write(f"{i + 1:11d} {nd:8d} {DIRECTION_NAMES[int(d)]:>9}\n")


def read_hbmat(stiffness, mass=None, mapping=None) -> FEModel:
    """FEModel from ANSYS HBMAT stiffness (and mass) files and the ``.mapping`` file.

    mapping : default ``<stiffness without extension>.mapping`` if it exists.
    """
    K = read_hb(stiffness)
    M = read_hb(mass) if mass is not None else None
    if M is not None and M.shape != K.shape:
        fail(mass, 3, f"size {K.shape[0]} like {stiffness}", str(M.shape[0]))
    source = [str(stiffness)] + ([str(mass)] if mass is not None else [])
    if mapping is None:
        cand = Path(stiffness).with_suffix(".mapping")
        mapping = cand if cand.exists() else None
    if mapping is not None:
        dofs = read_ansys_mapping(mapping, K.shape[0])
        source.append(str(mapping))
    else:
        dofs = np.column_stack([np.arange(1, K.shape[0] + 1), np.zeros(K.shape[0], np.int64)])
    return FEModel(K=K, M=M, dofs=dofs, source=source)
