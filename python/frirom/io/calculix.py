"""CalculiX matrices: ``job.sti`` / ``job.mas`` / ``job.dof`` with nodes from ``job.inp``.

ccx writes them for ``*FREQUENCY, SOLVER=MATRIXSTORAGE`` (which ends the run, so it goes
in the last step): ``.sti`` and ``.mas`` hold the upper triangle as ``row col value``
lines (1-based), ``.dof`` one ``node.direction`` line per matrix row; DoFs fixed by
``*BOUNDARY`` are left out of the matrices. The deck gives node coordinates, node sets
(``*NODE, NSET=``, ``*NSET`` with or without GENERATE, ``*INCLUDE``) and the element
connectivity, from which the removed (constrained) DoFs are recovered.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ._common import (FEModel, fail, parse_table, read_lines, read_text,
                      symmetric_from_triplets)

__all__ = ["read_calculix", "read_inp", "write_calculix_matrices", "read_ccx_eigenvalues"]


def _jobname(path) -> Path:
    p = Path(path)
    if p.suffix.lower() in (".sti", ".mas", ".dof", ".inp"):
        p = p.with_suffix("")
    return p


def read_dof_file(path) -> np.ndarray:
    """(n_dof, 2) array of (node, direction) from a ccx ``.dof`` file."""
    lines = read_lines(path)
    node, dirn = [], []
    for i, raw in enumerate(lines):
        s = raw.strip()
        if not s:
            continue
        a, dot, b = s.partition(".")
        if not dot or not a.isdigit() or not b.isdigit():
            fail(path, i + 1, "'node.direction' (e.g. 12.3)", raw)
        node.append(int(a))
        dirn.append(int(b))
    if not node:
        fail(path, 1, "'node.direction' lines", "empty file")
    return np.column_stack([np.array(node, np.int64), np.array(dirn, np.int64)])


def read_matrix_file(path, n: int, what: str):
    """Full symmetric CSR (n, n) from a ccx ``row col value`` upper-triangle file."""
    r, c, v = parse_table(path, read_text(path), 0, 3, "iif",
                          f"'row col value' ({what} entry)")
    return symmetric_from_triplets(path, r - 1, c - 1, v, n, what)


def read_inp(path):
    """Nodes, node sets and element-connected node ids of a CalculiX/Abaqus deck.

    Returns (node_ids (n,), coords (n, 3), node_sets {NAME: ids}, element_nodes (m,)).
    Follows ``*INCLUDE, INPUT=``. Unknown keywords are skipped.
    """
    ids, xyz = [], []
    sets: dict[str, list] = {}
    elem_nodes = []
    _scan_inp(Path(path), ids, xyz, sets, elem_nodes, depth=0)
    node_ids = np.array(ids, dtype=np.int64)
    coords = np.array(xyz, dtype=np.float64).reshape(-1, 3)
    # Resolve set references (an *NSET line may name another set).
    resolved: dict[str, np.ndarray] = {}

    def resolve(name, stack=()):
        if name in resolved:
            return resolved[name]
        if name in stack:
            raise fail(path, 0, f"node sets without cycles (set {name} refers to itself)")
        out = []
        for item in sets[name]:
            if isinstance(item, str):
                if item not in sets:
                    fail(path, 0, f"a known node set or node id in *NSET {name}", item)
                out.append(resolve(item, stack + (name,)))
            else:
                out.append(np.asarray(item, dtype=np.int64))
        resolved[name] = np.unique(np.concatenate(out)) if out else np.zeros(0, np.int64)
        return resolved[name]

    for name in sets:
        resolve(name)
    en = np.unique(np.concatenate(elem_nodes)) if elem_nodes else np.zeros(0, np.int64)
    return node_ids, coords, resolved, en


def _params(line: str):
    parts = [p.strip() for p in line.split(",")]
    key = parts[0].upper()
    params = {}
    for p in parts[1:]:
        if not p:
            continue
        k, _, v = p.partition("=")
        params[k.strip().upper()] = v.strip()
    return key, params


def _scan_inp(path: Path, ids, xyz, sets, elem_nodes, depth):
    if depth > 10:
        fail(path, 0, "*INCLUDE nesting of at most 10 levels")
    lines = read_lines(path)
    mode = None
    cur = None
    generate = False
    for i, raw in enumerate(lines):
        s = raw.strip()
        if not s or s.startswith("**"):
            continue
        if s.startswith("*"):
            key, params = _params(s)
            mode = None
            if key == "*INCLUDE":
                inc = params.get("INPUT")
                if not inc:
                    fail(path, i + 1, "*INCLUDE, INPUT=file", raw)
                incp = Path(inc) if os.path.isabs(inc) else path.parent / inc
                _scan_inp(incp, ids, xyz, sets, elem_nodes, depth + 1)
            elif key == "*NODE":
                mode = "node"
                cur = params.get("NSET", "").upper() or None
                if cur:
                    sets.setdefault(cur, [])
            elif key == "*NSET":
                cur = params.get("NSET", "").upper()
                if not cur:
                    fail(path, i + 1, "*NSET, NSET=name", raw)
                sets.setdefault(cur, [])
                generate = "GENERATE" in params
                mode = "nset"
            elif key == "*ELEMENT":
                mode = "elem"
                cur = None
            continue
        if mode is None:
            continue
        parts = [p.strip() for p in s.split(",")]
        if parts and parts[-1] == "":
            parts = parts[:-1]
        if mode == "node":
            try:
                nid = int(parts[0])
                x = [float(p) for p in parts[1:4]] + [0.0] * (4 - len(parts))
            except (ValueError, IndexError):
                fail(path, i + 1, "a node line 'id, x, y, z'", raw)
            ids.append(nid)
            xyz.append(x[:3])
            if cur:
                sets[cur].append([nid])
        elif mode == "nset":
            if generate:
                try:
                    a, b, *st = (int(p) for p in parts)
                    step = st[0] if st else 1
                    if step <= 0 or b < a:
                        raise ValueError
                except ValueError:
                    fail(path, i + 1, "'first, last[, increment]' in *NSET, GENERATE", raw)
                sets[cur].append(np.arange(a, b + 1, step))
            else:
                for p in parts:
                    if p.lstrip("-").isdigit():
                        sets[cur].append([int(p)])
                    else:
                        sets[cur].append(p.upper())
        elif mode == "elem":
            # Continuation lines (ending with a comma) carry only node ids: every field
            # after the first on a line that starts an element, all fields otherwise.
            try:
                vals = [int(p) for p in parts if p]
            except ValueError:
                fail(path, i + 1, "an element line 'id, node, node, ...'", raw)
            if _elem_starts(lines, i):
                vals = vals[1:]
            elem_nodes.append(np.array(vals, dtype=np.int64))


def _elem_starts(lines, i) -> bool:
    """True if line i starts an element (the previous data line did not end with ',')."""
    j = i - 1
    while j >= 0:
        s = lines[j].strip()
        if s and not s.startswith("**"):
            return s.startswith("*") or not s.endswith(",")
        j -= 1
    return True


def read_calculix(path, inp=None, mass: bool = True) -> FEModel:
    """Read ccx's ``job.sti``, ``job.mas``, ``job.dof`` and the deck ``job.inp``.

    path : job name, or any of its files (the extension is dropped).
    inp : deck to take nodes and node sets from; default ``job.inp`` if it exists.
    mass : read ``job.mas`` (a static MATRIXSTORAGE run writes no mass matrix).
    """
    job = _jobname(path)
    dofs = read_dof_file(job.with_suffix(".dof"))
    n = dofs.shape[0]
    K = read_matrix_file(job.with_suffix(".sti"), n, "stiffness")
    M = read_matrix_file(job.with_suffix(".mas"), n, "mass") if mass else None
    source = [str(job.with_suffix(s)) for s in ((".dof", ".sti", ".mas") if mass
                                               else (".dof", ".sti"))]
    inp = job.with_suffix(".inp") if inp is None else Path(inp)
    model = FEModel(K=K, M=M, dofs=dofs, source=source)
    if inp.exists():
        node_ids, coords, sets, elem_nodes = read_inp(inp)
        model.node_ids, model.coords, model.node_sets = node_ids, coords, sets
        model.source.append(str(inp))
        dirs = np.unique(dofs[:, 1])
        allp = np.array(np.meshgrid(elem_nodes, dirs, indexing="ij")).reshape(2, -1).T
        key_all = allp[:, 0] * 10 + allp[:, 1]
        key_have = dofs[:, 0] * 10 + dofs[:, 1]
        model.constrained = allp[~np.isin(key_all, key_have)]
    return model


def write_calculix_matrices(job, K, M, dofs) -> None:
    """Write ``job.sti``, ``job.mas`` (upper triangles) and ``job.dof`` as ccx does."""
    job = _jobname(job)
    for A, ext in ((K, ".sti"), (M, ".mas")):
        if A is None:
            continue
        U = sp.triu(sp.csr_matrix(A)).tocsc()
        U.sort_indices()
        col = np.repeat(np.arange(U.shape[1]), np.diff(U.indptr))
        with open(job.with_suffix(ext), "w") as fh:
            for r, c, v in zip(U.indices + 1, col + 1, U.data):
                fh.write(f"{r} {c}  {v:.13e}\n")
    with open(job.with_suffix(".dof"), "w") as fh:
        for nd, d in dofs:
            fh.write(f"{nd}.{d}\n")


def read_ccx_eigenvalues(path) -> np.ndarray:
    """Eigenvalues [rad^2/s^2] of the first *FREQUENCY step in a ccx ``.dat`` file."""
    lines = read_lines(path)
    start = None
    for i, line in enumerate(lines):
        if "E I G E N V A L U E   O U T P U T" in line:
            start = i
            break
    if start is None:
        fail(path, 0, "an 'E I G E N V A L U E   O U T P U T' block", "none")
    vals = []
    for i in range(start + 1, len(lines)):
        parts = lines[i].split()
        if not parts:
            if vals:
                break
            continue
        if not parts[0].isdigit():
            if vals:
                break
            continue
        if len(parts) != 5:
            fail(path, i + 1, "'mode eigenvalue omega frequency imaginary'", lines[i])
        try:
            vals.append(float(parts[1]))
        except ValueError:
            fail(path, i + 1, "a number in the eigenvalue column", lines[i])
    return np.array(vals)
