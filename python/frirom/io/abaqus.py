"""Abaqus ``*MATRIX OUTPUT`` files (``job_STIF2.mtx``, ``job_MASS2.mtx``).

FORMAT=MATRIX INPUT lines are ``row node, row dof, col node, col dof, value``; FORMAT=
COORDINATE lines are ``row, col, value`` with 1-based equation numbers (the DoF map then
comes from the caller, or stays unknown). Either triangle or both may be stored. Nodes and
node sets can be taken from the Abaqus deck (same keywords as CalculiX's).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ._common import FEModel, fail, parse_table, read_lines, symmetric_from_triplets
from .calculix import read_inp

__all__ = ["read_abaqus", "write_abaqus_matrix"]


def _data_start(lines):
    i = 0
    while i < len(lines) and (not lines[i].strip() or lines[i].lstrip().startswith("*")):
        i += 1
    return i


def _detect(path, lines) -> str:
    i = _data_start(lines)
    if i == len(lines):
        fail(path, i, "matrix data lines", "end of file")
    n = len([t for t in lines[i].replace(",", " ").split()])
    if n == 5:
        return "matrix input"
    if n == 3:
        return "coordinate"
    fail(path, i + 1, "'node, dof, node, dof, value' (MATRIX INPUT) or 'row, col, value' "
         "(COORDINATE)", lines[i])


def _read_entries(path, fmt):
    lines = read_lines(path)
    fmt = _detect(path, lines) if fmt == "auto" else fmt
    i = _data_start(lines)
    if fmt == "matrix input":
        cols = parse_table(path, lines, i, 5, "iiiif",
                           "'row node, row dof, col node, col dof, value'", sep=",")
    elif fmt == "coordinate":
        cols = parse_table(path, lines, i, 3, "iif", "'row, col, value'", sep=",")
    else:
        raise ValueError(f"unknown Abaqus matrix format {fmt!r}")
    return fmt, cols


def read_abaqus(stiffness, mass=None, fmt: str = "auto", dofs=None, inp=None) -> FEModel:
    """FEModel from Abaqus ``*MATRIX OUTPUT`` files.

    Parameters
    ----------
    stiffness, mass : path
        The stiffness and (optional) mass matrix files.
    fmt : {"auto", "matrix input", "coordinate"}
        The files' format.
    dofs : (n_dof, 2) array_like of int, optional
        DoF map for COORDINATE files (ignored for MATRIX INPUT, which labels every entry
        itself).
    inp : path, optional
        Abaqus deck for node coordinates and node sets.
    """
    files = [stiffness] + ([mass] if mass is not None else [])
    parsed = [_read_entries(f, fmt) for f in files]
    kinds = {p[0] for p in parsed}
    if len(kinds) > 1:
        fail(mass, 0, f"the same format as {stiffness}", " and ".join(sorted(kinds)))
    kind = parsed[0][0]
    mats = []
    if kind == "matrix input":
        keys = np.unique(np.concatenate([np.concatenate([c[0] * 100 + c[1], c[2] * 100 + c[3]])
                                         for _, c in parsed]))
        dof_map = np.column_stack([keys // 100, keys % 100])
        n = dof_map.shape[0]
        for f, (_, c) in zip(files, parsed):
            r = np.searchsorted(keys, c[0] * 100 + c[1])
            q = np.searchsorted(keys, c[2] * 100 + c[3])
            mats.append(symmetric_from_triplets(f, r, q, c[4], n))
    else:
        n = int(max(max(c[0].max(), c[1].max()) for _, c in parsed))
        if dofs is not None:
            dof_map = np.asarray(dofs, dtype=np.int64)
            if dof_map.shape[0] < n:
                fail(stiffness, 0, f"a DoF map with at least {n} rows", str(dof_map.shape))
            n = dof_map.shape[0]
        else:
            dof_map = np.column_stack([np.arange(1, n + 1), np.zeros(n, np.int64)])
        for f, (_, c) in zip(files, parsed):
            mats.append(symmetric_from_triplets(f, c[0] - 1, c[1] - 1, c[2], n))
    model = FEModel(K=mats[0], M=mats[1] if mass is not None else None,
                    dofs=dof_map.astype(np.int64), source=[str(f) for f in files])
    if inp is not None:
        model.node_ids, model.coords, model.node_sets, _ = read_inp(inp)
        model.source.append(str(inp))
    return model


def write_abaqus_matrix(path, A, dofs=None, fmt: str = "matrix input") -> None:
    """Write the lower triangle of A as Abaqus writes it (for round-trip tests)."""
    L = sp.tril(sp.coo_matrix(A)).tocoo()
    order = np.lexsort((L.col, L.row))
    with open(path, "w") as fh:
        for r, c, v in zip(L.row[order], L.col[order], L.data[order]):
            if fmt == "matrix input":
                fh.write(f"{dofs[r][0]},{dofs[r][1]}, {dofs[c][0]},{dofs[c][1]},  {v:.16e}\n")
            else:
                fh.write(f"{r + 1} {c + 1} {v:.16e}\n")
