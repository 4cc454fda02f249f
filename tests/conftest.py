"""Fixtures that several test files share. The models and deck texts they are built from
are in tests/_models.py; the case generators of cases/ import by their module names
(pyproject.toml's [tool.pytest.ini_options] pythonpath).

`pytest -m "not slow"` is the fast loop (under two minutes on two cores): every feature
keeps at least one test there; the tests marked slow are the end-to-end and paper-size
runs and their finer variants (`bash scripts/test.sh` runs everything).
"""

from __future__ import annotations

import shutil

import pytest


def _needs_ccx():
    if shutil.which("ccx") is None:
        pytest.skip("ccx (calculix-ccx) not installed")


@pytest.fixture(scope="module")
def block_dir(tmp_path_factory):
    """cases/models/block.py's 10 x 3 x 3 block through ccx (K, M, DoF table and node sets
    IFACE, ACTIVE), in a folder of the test module's own: the decks of _models.GSI_DECK and
    OUTPUTS_DECK (job "block") run there."""
    _needs_ccx()
    import block
    out = tmp_path_factory.mktemp("block")
    block.run_ccx(block.write_block_deck(out / "block.inp", 10, 3, 3, n_ref_modes=0))
    return out


@pytest.fixture(scope="session")
def hooks_case(tmp_path_factory):
    """The coarse vane with hooks of cases/paper_hooks (ccx), shared by the test files of
    the case: the reduced models cached in it are built once."""
    _needs_ccx()
    import make_paper_hooks as mk
    work = tmp_path_factory.mktemp("hooks")
    mk.make(work, "coarse")
    return work


@pytest.fixture(scope="session")
def lap_joint_mesh(tmp_path_factory):
    """cases/lap_joint's mesh, coarse (element size 12 mm: 65 node pairs), through gmsh and
    ccx once: the folder holding lap.inp/.sti/.mas/.dof. Tests copy these files into a
    folder of their own (copy_job) and run their decks there."""
    _needs_ccx()
    pytest.importorskip("gmsh")
    import make_lap_joint
    out = tmp_path_factory.mktemp("lap_mesh")
    make_lap_joint.make(out, size=0.012)
    return out
