"""A body held only by its contacts (issue 29 item 1, the part outside the solver):
`frirom modes` flags a zero stuck frequency and names the free body and its directions,
and the singular-stiffness error names the DoFs of the free motion.

Model: a blade (one DoF "blade:x", grounded by a spring) and a damper body ("damper:x",
"damper:y", no spring) joined by a Jenkins element in x only. Free, the damper moves in
x and y; stuck, the element holds x but nothing holds y: one zero stuck frequency whose
motion is damper:y alone (by construction: exact)."""

from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp

from frirom import SingularMatrixError
from frirom.model import Damping, check_definite
from frirom.modes import _free_body, linear_check

LABELS = ["blade:x", "damper:x", "damper:y"]


def _deck():
    K = sp.csr_matrix(np.diag([1e6, 0.0, 0.0]))
    M = sp.csr_matrix(np.diag([1.0, 0.1, 0.1]))
    G = sp.csr_matrix(np.array([[1.0, -1.0, 0.0]]))
    contact = SimpleNamespace(law="jenkins", G=G, params=np.array([[1e5, 0.3, 10.0]]))
    F = np.zeros((3, 2), complex)
    F[0, 1] = 1.0
    return SimpleNamespace(M=M, K=K, contacts=[contact], dof_labels=LABELS, F=F,
                           outputs=[0], omega_start=2 * np.pi * 100,
                           omega_end=2 * np.pi * 200, cyclic=None, n_dof=3, reduced=None,
                           frequency_unit="hz",
                           damping_object=lambda: Damping.rayleigh(0.0, 1e-5))


def test_modes_flags_zero_stuck_frequency_and_names_the_body():
    chk = linear_check(_deck(), n_grid=20)
    text = "\n".join(chk.notes)
    assert "WARNING: 1 stuck natural frequency is 0 Hz: a motion no contact holds" in text
    stuck_note = text.split("contacts free")[0]
    assert "free motion: damper:y (directions: y 1.00)" in stuck_note, text
    # free: the damper, in x and y (both directions, neither the blade)
    free_note = text.split("contacts free:")[1]
    assert "2 natural frequencies are 0 Hz: a body held only by its contacts" in free_note
    assert "blade:x" not in free_note and "damper:x" in free_note and "damper:y" in free_note


def test_singular_stiffness_error_names_the_free_dofs():
    d = _deck()
    with pytest.raises(SingularMatrixError, match=r"1 free motion: motion 1 moves damper:y "
                       r"\(directions: y 1\.00\)"):
        check_definite(d.K, d.M, "K", "M", [d.contacts[0].G], labels=LABELS)


def test_fe_free_body_named_by_node_sets_and_direction():
    # an FE deck's motion is named by the node sets it moves: here the reduction keeps the
    # FE DoFs themselves (T = I over 3 nodes x 3 directions); the damper's two nodes move
    # along y together, the platform's node not at all
    T = np.eye(9)
    rom = SimpleNamespace(node_sets={"DAMPER": [2, 3], "PLATFORM": [1]},
                          load_row=lambda node, d: T[3 * (node - 1) + d - 1])
    phi = np.zeros(9)
    phi[[4, 7]] = 1.0                   # nodes 2 and 3, direction y
    text = _free_body(SimpleNamespace(reduced=rom, dof_labels=None), phi)
    assert text == ("node set DAMPER: a translation along (0.00, 1.00, 0.00); PLATFORM "
                    "still"), text
