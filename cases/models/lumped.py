"""The files of a bundled lumped-parameter case (cases/joint, cases/bladed_disk): M.mtx and
K.mtx (MatrixMarket, symmetric) and dofs.txt (one DoF label a line).

The case generators (make_joint.py, make_bladed_disk.py) import this module from
cases/models.
"""

from __future__ import annotations

from pathlib import Path

import scipy.io


def write_lumped_case(folder: Path, M, K, labels, title: str) -> None:
    """Write M.mtx, K.mtx and dofs.txt of a case into folder.

    Parameters
    ----------
    folder : Path
        The case folder.
    M, K : scipy.sparse matrix, shape (n, n)
        Mass (kg) and stiffness (N/m) matrices, symmetric.
    labels : sequence of str, length n
        One label per DoF, in matrix order.
    title : str
        What the matrices are, for the file comments: "joint case" gives
        "joint case mass matrix, kg".
    """
    folder = Path(folder)
    for name, A, what in (("M", M, "mass matrix, kg"), ("K", K, "stiffness matrix, N/m")):
        scipy.io.mmwrite(str(folder / f"{name}.mtx"), A, comment=f"{title} {what}",
                         symmetry="symmetric")
    (folder / "dofs.txt").write_text("\n".join(labels) + "\n")
