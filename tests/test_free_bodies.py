"""Bodies held only by their contacts (issue 29 item 1): a blade (m1 on k1 to the ground,
forced) and a damper mass m2 tied to it by nothing but one Jenkins element, so K is
singular. Its limits have closed forms: a friction limit mu fn0 that the element never
reaches leaves the pair stuck (the linear 2-DoF system with kt between the masses), and
fn0 = 0 leaves the blade alone (the damper's harmonics 1..H are zero, its mean is not
determined: held at the assembled position). Tolerance 1e-9 relative: the regularisation
(stuck stiffness moved into K and subtracted back) is exact, the pin on the mean moves a
stuck contact's mean by 1e-6 of itself and the mean is zero here. On main every route
failed: a singular D_0 (zgbtrf: zero pivot) or K."""

import numpy as np
import pytest

from _models import resume_into, run_then_kill
from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.options import SolverOptions
from frirom.solver import frf, solve_point

M1, K1, M2, KT, F, ALPHA = 1.0, 1.0, 0.3, 2.0, 0.01, 0.02
ROUTES = [("condensed", "factorization"), ("condensed", "modes"), ("condensed", "sparse"),
          ("banded", "auto")]


def blade_damper(fn0):
    """C = ALPHA M (Rayleigh): diagonal in any modes, so the modal route applies."""
    g = ContactGroup(law="jenkins", G=np.array([[1.0, -1.0]]),
                     params=np.array([[KT, 1.0, fn0]]), name="damper")
    return Model(np.diag([M1, M2]), np.diag([K1, 0.0]), Damping.rayleigh(ALPHA, 0.0), [g])


EXC = Excitation(np.array([[0.0, F], [0.0, 0.0]], complex))


def stuck_amplitudes(w):
    D = np.array([[K1 + KT - w * w * M1 + 1j * w * ALPHA * M1, -KT],
                  [-KT, KT - w * w * M2 + 1j * w * ALPHA * M2]])
    return np.abs(np.linalg.solve(D, [F, 0.0]))


def free_amplitude(w):
    return abs(F / (K1 - w * w * M1 + 1j * w * ALPHA * M1))


def test_free_body_detected():
    assert blade_damper(1.0).free_bodies()
    grounded = Model(np.diag([M1, M2]), np.diag([K1, 0.1]), Damping.rayleigh(ALPHA, 0.0),
                     blade_damper(1.0).contacts)
    assert not grounded.free_bodies()


@pytest.mark.parametrize("form,rec", ROUTES)
@pytest.mark.parametrize("w", [0.6, 1.0, 1.4])
def test_stuck_and_free_limits(form, rec, w):
    opts = SolverOptions(harmonics=3, formulation=form, receptances=rec)
    p = solve_point(blade_damper(100.0), EXC, w, opts)       # mu fn0 >> kt |x1 - x2|
    np.testing.assert_allclose(np.hypot(p.X[:, 1], p.X[:, 2]), stuck_amplitudes(w),
                               rtol=1e-9)
    assert p.state_fractions[0, 0] == 1.0                     # stuck all cycle
    p = solve_point(blade_damper(0.0), EXC, w, opts)          # no friction: blade alone
    assert np.hypot(p.X[0, 1], p.X[0, 2]) == pytest.approx(free_amplitude(w), rel=1e-9)
    assert np.abs(p.X[1]).max() < 1e-12                       # the damper stays put


@pytest.mark.parametrize("form", ["condensed", "banded"])
def test_gross_slip_sweep_has_no_family(form):
    """mu fn0 = 5e-4 against a 0.01 force: the damper slips all cycle near resonance, its
    mean free; the sweep ends (no stall), the mean stays at the assembled position, and
    the peak lies between the free and stuck limits' (0.5 and 0.033 at w = 1)."""
    r = frf(blade_damper(5e-4), EXC, 0.5, 1.6,
            SolverOptions(harmonics=5, formulation=form))
    assert r.omega.max() >= 1.6 - 1e-9 and r.omega.size < 300
    assert np.abs(r.X[:, :, 0]).max() < 1e-9
    peak = np.hypot(r.X[:, 0, 1], r.X[:, 0, 2]).max()
    assert 0.1 < peak < 0.5


@pytest.mark.parametrize("form", ["condensed", pytest.param("banded", marks=pytest.mark.slow)])
def test_free_body_killed_and_resumed_equals_uninterrupted(form, tmp_path):
    """Issue 29: bit-for-bit resume with a free body. The gross-slip sweep (the damper's
    mean held by the pin, its stuck stiffness moved into K) killed after 27 points and
    resumed from its last checkpoint gives the uninterrupted run's points and peak bit for
    bit (tolerance 0): the regularisation and the pin are stateless, so the restored run
    sees the same equations."""
    from frirom.results import FRF, FRFWriter
    model = blade_damper(5e-4)
    opts = SolverOptions(harmonics=5, formulation=form)
    out = np.array([0, 1])

    def writer(path, append=False):
        return FRFWriter(path, out, ["damper"], 5, append=append)

    def run(sink, start=None):
        return frf(model, EXC, 0.5, 1.6, opts, outputs=out, sink=sink, start=start)
    full, ref, path = run_then_kill(run, writer, tmp_path, 27)
    assert full.complete and len(ref) > 40
    start, rest = resume_into(run, writer, path)
    assert 0 < start["n_points"] < 27
    got = FRF.load(path)
    assert len(got) == len(ref)
    for name in ("omega", "X", "amp_max", "state_fractions", "slider", "iterations"):
        np.testing.assert_array_equal(getattr(got, name), getattr(ref, name), err_msg=name)
    assert rest.peak(0) == full.peak(0)
