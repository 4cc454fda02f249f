"""The model every reader returns, and the parsing helpers the readers share."""

from __future__ import annotations

import contextvars
import os
from pathlib import Path
import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .._errors import InputError

#: Direction numbers used in ``FEModel.dofs[:, 1]``: 1-3 translations, 4-6 rotations.
DIRECTION_NAMES = {1: "UX", 2: "UY", 3: "UZ", 4: "ROTX", 5: "ROTY", 6: "ROTZ"}
#: The inverse map: direction name ("UX".."ROTZ") -> direction number 1..6.
DIRECTION_NUMBERS = {name: d for d, name in DIRECTION_NAMES.items()}


@dataclass
class FEModel:
    """Assembled finite-element matrices with their DoF map.

    Attributes
    ----------
    K, M : scipy.sparse.csr_matrix, (n_dof, n_dof)
        Stiffness [N/m] and mass [kg], full symmetric storage (both triangles). ``M`` is
        None when only a stiffness matrix was read.
    dofs : ndarray of int64, (n_dof, 2)
        Row i is (node id, direction 1..6) of matrix row/column i. Direction 0 means
        "unknown" (a file without a DoF map: the node column then holds the 1-based
        equation number).
    node_ids : ndarray of int64, (n_node,)
    coords : ndarray of float64, (n_node, 3)
        Node coordinates [m] when the format carries them (CalculiX with its .inp),
        otherwise empty arrays.
    node_sets : dict[str, ndarray of int64]
        Node sets by upper-case name (node ids, sorted, unique).
    constrained : ndarray of int64, (n_con, 2)
        (node, direction) pairs known to be constrained and therefore absent from the
        matrices (CalculiX: DoFs of the deck's nodes that ccx removed).
    source : list of str
        Files read.
    """

    K: sp.csr_matrix
    M: sp.csr_matrix | None
    dofs: np.ndarray
    node_ids: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    coords: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    node_sets: dict = field(default_factory=dict)
    constrained: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    source: list = field(default_factory=list)

    def __post_init__(self):
        check_matrices(self.K, self.M, ", ".join(map(str, self.source)) or "the model")

    @property
    def n_dof(self) -> int:
        return self.K.shape[0]

    def coordinates(self, nodes) -> np.ndarray:
        """Coordinates (n, 3) of the given node ids; InputError for an unknown id."""
        nodes = np.asarray(nodes, dtype=np.int64).ravel()
        order = np.argsort(self.node_ids)
        pos = np.searchsorted(self.node_ids, nodes, sorter=order)
        pos = np.minimum(pos, len(order) - 1) if len(order) else pos
        ok = len(order) > 0 and np.all(self.node_ids[order[pos]] == nodes)
        if not ok:
            missing = nodes if len(order) == 0 else nodes[self.node_ids[order[pos]] != nodes]
            raise InputError(f"no coordinates for node(s) {missing[:10].tolist()}")
        return self.coords[order[pos]]

    def node_set(self, name: str) -> np.ndarray:
        """The node ids of a node set (case-insensitive); InputError naming the sets the
        model has (and where node sets come from when it has none)."""
        ids = self.node_sets.get(name.upper())
        if ids is None:
            raise InputError(f"unknown node set {name!r}; the model has "
                             f"{sorted(self.node_sets)}" + ("" if self.node_sets else
                             " (matrix files carry no node sets: give [fe_model] inp, "
                             "a file of *NODE and *NSET blocks, see docs/deck.md)"))
        return ids

    def dof_indices(self, node_set=None, nodes=None, directions=(1, 2, 3),
                    missing: str = "error") -> np.ndarray:
        """Matrix indices of the DoFs of some nodes in some directions.

        node_set : str or list of str, names in ``node_sets`` (case-insensitive);
        nodes : extra node ids; directions : direction numbers 1..6 to keep.
        missing : "error" raises InputError if a requested node has none of the requested
        DoFs in the matrices; "ignore" skips it (constrained nodes). Indices come sorted
        by (node, direction).
        """
        ids = [] if nodes is None else [np.asarray(nodes, dtype=np.int64).ravel()]
        names = [] if node_set is None else ([node_set] if isinstance(node_set, str)
                                             else list(node_set))
        for name in names:
            ids.append(self.node_set(name))
        want = np.unique(np.concatenate(ids)) if ids else np.zeros(0, np.int64)
        sel = np.isin(self.dofs[:, 0], want) & np.isin(self.dofs[:, 1], list(directions))
        idx = np.nonzero(sel)[0]
        if missing == "error":
            absent = np.setdiff1d(want, self.dofs[idx, 0])
            if absent.size:
                raise InputError(f"node(s) {absent[:10].tolist()} have no DoF in directions "
                                 f"{list(directions)} in the matrices (constrained or "
                                 f"not in the model)")
        order = np.lexsort((self.dofs[idx, 1], self.dofs[idx, 0]))
        return idx[order]

    def constrain(self, node_set=None, nodes=None, directions=(1, 2, 3)) -> "FEModel":
        """A copy without the DoFs of some nodes (e.g. a clamped face of an unconstrained
        export, such as Abaqus or ANSYS matrices written before boundary conditions).

        The removed (node, direction) pairs are added to ``constrained``.
        """
        drop = self.dof_indices(node_set, nodes, directions, missing="ignore")
        keep = np.setdiff1d(np.arange(self.n_dof), drop)
        K = self.K[keep][:, keep].tocsr()
        M = None if self.M is None else self.M[keep][:, keep].tocsr()
        con = np.concatenate([self.constrained, self.dofs[drop]]).astype(np.int64)
        return FEModel(K=K, M=M, dofs=self.dofs[keep], node_ids=self.node_ids,
                       coords=self.coords, node_sets=dict(self.node_sets), constrained=con,
                       source=list(self.source))


def check_matrices(K, M, where) -> None:
    """What every reader returns: K (and M) real, square, of one size and finite;
    InputError naming ``where`` (the file read) otherwise."""
    where = os.fspath(where)
    for A, what in ((K, "stiffness"), (M, "mass")):
        if A is None:
            continue
        if np.iscomplexobj(A.data if sp.issparse(A) else A):
            raise InputError(f"{where}: {what} matrix: expected real entries, got complex")
        if A.ndim != 2 or A.shape[0] != A.shape[1]:
            raise InputError(f"{where}: {what} matrix: expected square, got shape {A.shape}")
        data = A.data if sp.issparse(A) else np.asarray(A)
        if not np.all(np.isfinite(data)):
            raise InputError(f"{where}: {what} matrix: expected finite entries, got NaN or "
                             "Inf")
    if M is not None and M.shape != K.shape:
        raise InputError(f"{where}: mass matrix: expected the stiffness matrix's shape "
                         f"{K.shape}, got {M.shape}")


#: The folder whose files' content an error may quote (a deck's folder while the deck
#: is built: deck.build.build_deck); None: any file. A deck may name any readable file,
#: and an error must not print a line of one outside its folder (docs/security.md).
QUOTE_UNDER: contextvars.ContextVar = contextvars.ContextVar("quote_under", default=None)


def fail(path, line, expected: str, got: str | None = None):
    """Raise InputError naming the file, the 1-based line and what was expected, quoting
    what was found when the file lies under QUOTE_UNDER (or that is unset)."""
    where = f"{os.fspath(path)}" + (f", line {line}" if line else "")
    msg = f"{where}: expected {expected}"
    root = QUOTE_UNDER.get()
    if got is not None and root is not None and not _under(path, root):
        msg += " (its content is not shown: the file is outside the deck's folder)"
    elif got is not None:
        got = got.strip()
        msg += f", got {got[:80]!r}"
    raise InputError(msg)


def _under(path, root) -> bool:
    try:
        return Path(os.path.realpath(path)).is_relative_to(os.path.realpath(root))
    except (OSError, ValueError):
        return False


def read_text(path) -> str:
    """The whole text of a file, decoded as UTF-8 (ASCII is UTF-8); InputError if it is
    missing, unreadable or not UTF-8 (naming the line and the byte)."""
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except OSError as exc:
        raise InputError(f"{os.fspath(path)}: cannot read ({exc.strerror})") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        col = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise InputError(f"{os.fspath(path)}, line {line}: expected UTF-8 text (ASCII "
                         f"is UTF-8), got byte 0x{data[exc.start]:02x} at column {col}; "
                         "save the file as UTF-8") from None


def read_lines(path):
    """All lines of a text file (:func:`read_text`)."""
    return read_text(path).splitlines()


def parse_table(path, lines, first: int, ncols: int, kinds: str, what: str,
                sep: str | None = None):
    """Parse lines[first:] as a table of ``ncols`` numbers per line.

    ``lines`` is a list of lines or the whole text of the file (cheaper for big files).
    kinds: one character per column, 'i' (integer) or 'f' (float; Fortran D exponents
    allowed). Blank lines are skipped; ``sep`` (e.g. ',') is treated as white space.
    Returns one 1-D array per column. A malformed line raises InputError naming the file,
    the line (1-based, from the start of the file) and what was expected.
    """
    if isinstance(lines, str):
        text = lines
        pos = 0
        for _ in range(first):
            pos = text.find("\n", pos) + 1
            if pos == 0:
                pos = len(text)
                break
        text = text[pos:]
    else:
        text = "\n".join(lines[first:])
    if sep:
        text = text.replace(sep, " ")
    if "D" in text or "d" in text:
        text = text.replace("D", "E").replace("d", "e")
    n_lines = text.count("\n") + (0 if text.endswith("\n") or not text else 1)
    # Fast path: numpy's C parser, accepted only if every line holds ncols numbers.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            flat = np.fromstring(text, sep=" ")
        except ValueError:
            flat = np.zeros(0)
    if n_lines and flat.size == ncols * n_lines and np.all(np.isfinite(flat)):
        table = flat.reshape(-1, ncols)
        cols = []
        for c, k in enumerate(kinds):
            col = table[:, c]
            if k == "i":
                ic = col.astype(np.int64)
                if not np.array_equal(ic, col):
                    break
                col = ic
            cols.append(col)
        else:
            return cols
    # Slow path: parse line by line and name the first bad one.
    body = text.split("\n")
    rows = []
    for i, line in enumerate(body):
        parts = line.split()
        if not parts:
            continue
        if len(parts) != ncols:
            fail(path, first + i + 1, f"{what} ({ncols} fields)", line)
        row = []
        for f, (p, k) in enumerate(zip(parts, kinds)):
            try:
                v = int(p) if k == "i" else float(p)
            except ValueError:
                fail(path, first + i + 1, f"{what} ({'an integer' if k == 'i' else 'a number'}"
                     f" in field {f + 1})", line)
            if k == "f" and not np.isfinite(v):
                fail(path, first + i + 1, f"{what} (a finite number in field {f + 1})", line)
            row.append(v)
        rows.append(row)
    if not rows:
        fail(path, first + 1, what, "end of file")
    return [np.array(col, dtype=np.int64 if k == "i" else np.float64)
            for col, k in zip(zip(*rows), kinds)]


def symmetric_from_triplets(path, rows, cols, vals, n: int, what="matrix",
                            rtol: float = 1e-10) -> sp.csr_matrix:
    """Full symmetric CSR from 0-based triplets holding one triangle or both.

    One triangle (upper or lower, diagonal included) is mirrored. When both triangles are
    present the matrix is taken as stored and checked for symmetry: an asymmetric
    matrix raises InputError (frirom's reductions assume symmetric K and M).
    """
    if rows.size and (rows.min() < 0 or cols.min() < 0 or rows.max() >= n or cols.max() >= n):
        raise InputError(f"{os.fspath(path)}: {what} index out of range 1..{n}")
    upper = rows <= cols
    lower = rows >= cols
    if np.all(upper) or np.all(lower):
        off = rows != cols
        r = np.concatenate([rows, cols[off]])
        c = np.concatenate([cols, rows[off]])
        v = np.concatenate([vals, vals[off]])
        A = sp.csr_matrix((v, (r, c)), shape=(n, n))
    else:
        A = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
        diff = abs(A - A.T).max() if A.nnz else 0.0
        scale = abs(A).max() if A.nnz else 1.0
        if diff > rtol * scale:
            raise InputError(f"{os.fspath(path)}: {what} holds both triangles but is not "
                             f"symmetric (max |A - A^T| = {diff:.3e}, max |A| = {scale:.3e})")
    A.sum_duplicates()
    A.sort_indices()
    return A
