"""What every CalculiX model generator here shares: the steel, deck snippets, running ccx.

The generators (block.py, lap_joint.py, bladed_sector.py) import this module from the
same folder.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

STEEL = dict(E=2.1e11, nu=0.3, rho=7850.0)   # Pa, -, kg/m^3


def nset(name: str, nodes) -> str:
    """A *NSET block, ten node ids a line."""
    nodes = list(nodes)
    lines = [f"*NSET, NSET={name}"]
    lines += [", ".join(str(v) for v in nodes[k:k + 10]) for k in range(0, len(nodes), 10)]
    return "\n".join(lines) + "\n"


def solid_material(material=STEEL, elset: str = "EALL") -> str:
    """An isotropic elastic material with density and the solid section of `elset`."""
    return ("*MATERIAL, NAME=STEEL\n*ELASTIC\n"
            f"{material['E']:.6g}, {material['nu']:.6g}\n*DENSITY\n{material['rho']:.6g}\n"
            f"*SOLID SECTION, ELSET={elset}, MATERIAL=STEEL\n")


def matrix_storage_steps(n_ref_modes: int = 0) -> str:
    """An optional ``*FREQUENCY`` step of n_ref_modes modes (ccx prints their eigenvalues
    in job.dat: the reference), then ``*FREQUENCY, SOLVER=MATRIXSTORAGE``, which writes
    job.sti/.mas/.dof and ends the run, so it comes last."""
    ref = f"*STEP\n*FREQUENCY\n{n_ref_modes}\n*END STEP\n" if n_ref_modes > 0 else ""
    return ref + "*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n1\n*END STEP\n"


def write_mesh(fh, title: str, ids, xyz, elems, sets: dict, etype: str) -> None:
    """The mesh part of a CalculiX deck into the open file fh: the title, the nodes (NSET
    ALL), the elements of type etype (ELSET EALL) and the node sets."""
    fh.write(f"** {title}\n*NODE, NSET=ALL\n")
    for i, (x, y, z) in zip(ids, xyz):
        fh.write(f"{i}, {x:.12g}, {y:.12g}, {z:.12g}\n")
    fh.write(f"*ELEMENT, TYPE={etype}, ELSET=EALL\n")
    for e, conn in enumerate(elems, start=1):
        fh.write(f"{e}, " + ", ".join(str(c) for c in conn) + "\n")
    for name, nodes in sets.items():
        fh.write(nset(name, nodes))


def write_tet10_deck(path, title: str, ids, xyz, elems, sets: dict, n_ref_modes: int = 0,
                     material=STEEL) -> Path:
    """A CalculiX deck of C3D10 elements (gmsh meshes): the nodes (NSET ALL), the
    elements (ELSET EALL), the node sets, the material, FIX clamped, the matrix-storage
    steps; returns the deck path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as fh:
        write_mesh(fh, title, ids, xyz, elems, sets, "C3D10")
        fh.write(solid_material(material) + "*BOUNDARY\nFIX, 1, 3\n"
                 + matrix_storage_steps(n_ref_modes))
    return path


def run_ccx(inp, timeout: float = 1800, expect=(".sti",)) -> Path:
    """Run ccx on a deck in its own directory and return the job path (deck without
    suffix). RuntimeError with the log tail when ccx fails, prints *ERROR, or leaves any
    of the `expect`ed files unwritten (.sti for matrix storage, .dat for eigenvalues)."""
    inp = Path(inp)
    ccx = shutil.which("ccx")
    if ccx is None:
        raise RuntimeError("ccx (Debian package calculix-ccx) is not on PATH")
    env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "1"))
    res = subprocess.run([ccx, "-i", inp.stem], cwd=inp.parent, capture_output=True,
                         text=True, timeout=timeout, env=env)
    job = inp.with_suffix("")
    missing = [e for e in expect if not job.with_suffix(e).exists()]
    if res.returncode != 0 or missing or "*ERROR" in res.stdout:
        tail = "\n".join((res.stdout + res.stderr).splitlines()[-20:])
        raise RuntimeError(f"ccx failed on {inp} (exit {res.returncode}):\n{tail}")
    return job
