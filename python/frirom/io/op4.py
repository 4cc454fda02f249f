"""NASTRAN OP4 matrices through pyyeti (optional: ``pip install frirom[op4]``).

OP4 carries matrices only: the DoF map comes from the caller (e.g. from the USET table
of the run that wrote them), or stays unknown.
"""

from __future__ import annotations

import os

import numpy as np
import scipy.sparse as sp

from .._errors import InputError
from ._common import FEModel, symmetric_from_triplets

__all__ = ["read_op4"]


def _op4():
    try:
        from pyyeti.nastran import op4
    except ImportError:
        raise InputError("reading NASTRAN OP4 files needs the optional package pyyeti "
                         "(pip install pyyeti, or pip install frirom[op4])") from None
    return op4


def read_op4(path, stiffness: str = "KAA", mass: str | None = "MAA", dofs=None) -> FEModel:
    """FEModel from the matrices named ``stiffness`` and ``mass`` in an OP4 file."""
    op4 = _op4()
    if not os.path.isfile(path):
        raise InputError(f"{os.fspath(path)}: cannot read (no such file)")
    try:
        mats = op4.read(os.fspath(path), sparse=(True, sp.coo_matrix.tocoo))
    except Exception as exc:  # pyyeti raises assorted errors on a damaged file
        raise InputError(f"{os.fspath(path)}: not a readable OP4 file ({exc})") from None
    names = {k.upper(): k for k in mats}
    out = []
    for want in (stiffness, mass):
        if want is None:
            out.append(None)
            continue
        if want.upper() not in names:
            raise InputError(f"{os.fspath(path)}: expected a matrix named {want}, the file "
                             f"holds {sorted(names)}")
        A = sp.coo_matrix(mats[names[want.upper()]])
        if A.shape[0] != A.shape[1]:
            raise InputError(f"{os.fspath(path)}: matrix {want} is {A.shape}, expected square")
        out.append(symmetric_from_triplets(path, A.row, A.col, A.data, A.shape[0], want))
    K, M = out
    n = K.shape[0]
    if dofs is None:
        dofs = np.column_stack([np.arange(1, n + 1), np.zeros(n, np.int64)])
    dofs = np.asarray(dofs, dtype=np.int64)
    if dofs.shape != (n, 2):
        raise InputError(f"{os.fspath(path)}: DoF map of shape ({n}, 2) expected, got "
                         f"{dofs.shape}")
    return FEModel(K=K, M=M, dofs=dofs, source=[os.fspath(path)])
