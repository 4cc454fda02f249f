"""What a free body's pin held, per point, and the contact-patch warning (issue 29 item 1).

Model: tests/test_free_bodies.py's blade and damper (a mass tied to the blade by one
Jenkins element only, K singular). References: the stuck pair's relative displacement
amplitude |X1 - X2| from the closed-form 2-DoF solve (the patch warning fires at 0.9 of
it and not at 1.1), and the law's physics (a contact that slips has its mean decided by the
pin alone, its slider following any shift; a stuck one has not)."""

import re
from pathlib import Path

import numpy as np
import pytest

from frirom.held import FREE_PIN, held_directions, held_lines, patch_warnings
from frirom.model import ContactGroup, Damping, Model
from frirom.show import contact_fields
from frirom.solver import SolverOptions, solve_point
from test_free_bodies import ALPHA, EXC, F, K1, KT, M1, M2, blade_damper

ROOT = Path(__file__).resolve().parents[1]
OPTS = SolverOptions(harmonics=3)


def _fields(model, w):
    p = solve_point(model, EXC, w, OPTS, outputs=np.arange(2))
    return contact_fields(model, np.asarray(p.X, float), np.asarray(p.slider, float),
                          OPTS.n_samples)


def test_free_pin_is_fortrans():
    src = (ROOT / "fortran" / "frirom_hbm.fypp").read_text()
    m = re.search(r"FREE_PIN\s*=\s*([0-9.eE+-]+)_wp", src)
    assert m and float(m.group(1)) == FREE_PIN


def test_gross_slip_mean_held_stuck_not():
    model = blade_damper(5e-4)                  # slips all cycle near resonance
    held = held_directions(model, _fields(model, 1.0))
    assert len(held) == 1 and held[0].tangential.tolist() == [0]
    assert held[0].normal.size == 0             # Jenkins: no normal direction
    assert held[0].pin_force[0] < 1e-12          # the picked member: the pin carries 0
    line = held_lines(held)[0]
    assert "1 of 1 elements (slipping or open)" in line and "damper" in line
    model = blade_damper(100.0)                 # stuck all cycle
    held = held_directions(model, _fields(model, 1.0))
    assert held[0].tangential.size == 0
    grounded = Model(np.diag([M1, M2]), np.diag([K1, 0.1]), Damping.rayleigh(ALPHA, 0.0),
                     model.contacts)
    assert held_directions(grounded, _fields(grounded, 1.0)) == []


@pytest.mark.parametrize("w", [0.8, 1.2])
def test_patch_warning_at_the_closed_form_excursion(w):
    D = np.array([[K1 + KT - w * w * M1 + 1j * w * ALPHA * M1, -KT],
                  [-KT, KT - w * w * M2 + 1j * w * ALPHA * M2]])
    x = np.linalg.solve(D, [F, 0.0])
    reach = abs(x[0] - x[1])                    # stuck: u(t) = Re((X1 - X2) e^{iwt})
    base = blade_damper(100.0)
    for factor, warned in ((0.9, True), (1.1, False), (None, False)):
        g = base.contacts[0]
        g2 = ContactGroup(g.law, g.G, g.params, name=g.name,
                          patch=None if factor is None else factor * reach)
        model = Model(base.M, base.K, base.damping, [g2])
        msgs = patch_warnings(model, _fields(model, w))
        assert bool(msgs) == warned, (factor, msgs)
        if warned:
            assert "contact damper" in msgs[0] and "1 of 1 elements" in msgs[0]
            got = float(re.search(r"largest ([0-9.e+-]+) mm", msgs[0]).group(1))
            assert got * 1e-3 == pytest.approx(reach, rel=2e-3)   # sampled max, N = 64+
