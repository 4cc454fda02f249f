"""Readers of assembled FE matrices: one module per format, one result type (FEModel).

    read_calculix(job)                       ccx .sti/.mas/.dof + .inp (nodes, node sets)
    read_matrix_market(K, M, dofs)           MatrixMarket coordinate/array + optional DoFs
    read_abaqus(K, M, fmt, dofs, inp)        Abaqus *MATRIX OUTPUT (MATRIX INPUT/COORDINATE)
    read_hbmat(K, M, mapping)                ANSYS HBMAT Harwell-Boeing (RSA/RUA) + .mapping
    read_op4(path, stiffness, mass, dofs)    NASTRAN OP4 (needs pyyeti)

Every reader returns K and M as full symmetric scipy.sparse CSR matrices and raises
frirom.InputError naming the file, the line and what was expected on malformed input.
"""

from ._common import DIRECTION_NAMES, DIRECTION_NUMBERS, FEModel
from .abaqus import read_abaqus, write_abaqus_matrix
from .calculix import read_calculix, read_ccx_eigenvalues, read_inp, write_calculix_matrices
from .harwell_boeing import (read_ansys_mapping, read_hb, read_hbmat, write_ansys_mapping,
                             write_hb)
from .matrix_market import (read_dof_table, read_matrix_market, read_mtx, write_dof_table,
                            write_mtx)
from .op4 import read_op4

__all__ = ["FEModel", "DIRECTION_NAMES", "DIRECTION_NUMBERS", "read_calculix", "read_inp",
           "write_calculix_matrices", "read_ccx_eigenvalues", "read_matrix_market", "read_mtx",
           "write_mtx",
           "read_dof_table", "write_dof_table", "read_abaqus", "write_abaqus_matrix",
           "read_hbmat", "read_hb", "write_hb", "read_ansys_mapping", "write_ansys_mapping",
           "read_op4"]
