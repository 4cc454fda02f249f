"""Stalls detected (issue 29 item 3): a continuation that makes no progress in frequency
over STALL_POINTS = 200 points stops with a diagnosis instead of running on to
max_points and advising "raise continuation.max_points and continue with --resume"
(which repeats the stall). On main before the fix such a run spent every point of
max_points and said only "stopped after max_points".

The stall is made on purpose: a step length capped at 1e-9 (arc-length units) moves the
frequency of a three-mass chain with a Jenkins element by ~1e-9 of the range a point, so
200 points move it less than 1e-6 of the range (the driver's threshold) while the
unknowns and outputs stay fixed to round-off: the "tolerance floor" diagnosis."""

import numpy as np
import pytest
import scipy.sparse as sp

from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.solver import SolverOptions, frf


def _chain():
    K = sp.csr_matrix(np.array([[2e4, -1e4, 0], [-1e4, 2e4, -1e4], [0, -1e4, 1e4]]))
    g = ContactGroup("jenkins", sp.csr_matrix(([1.0], ([0], [0])), shape=(1, 3)),
                     (5e3, 0.3, 2.0), name="c")
    F = np.zeros((3, 2), complex)
    F[2, 1] = 1.0
    return Model(sp.identity(3, format="csr"), K, Damping.rayleigh(0.0, 1e-4), [g]), \
        Excitation(F)


def test_no_progress_in_frequency_stops_with_a_diagnosis():
    model, exc = _chain()
    opts = SolverOptions(harmonics=1, ds=1e-9, ds_min=1e-10, ds_max=1e-9, max_points=600,
                         stability=False, refine_peak=False)
    with pytest.warns(RuntimeWarning, match="continuation stalled"):
        r = frf(model, exc, 20.0, 200.0, opts)
    assert not r.complete
    assert len(r) < 300, (len(r), r.message)       # stopped at the stall, not max_points
    assert "no progress in the parameter" in r.message, r.message
    assert "tolerance floor" in r.message and "tol_stall" in r.message, r.message
    assert "max_points" not in r.message
    assert np.ptp(r.omega) < 1e-6 * (200.0 - 20.0)


def test_stop_messages_give_hz_with_units():
    """Issue 29 item 5: FRF.message named frequencies in rad/s only (and a stall none).
    A curve stopped by max_points and one that stalls: the message ends with the last
    point's frequency in Hz and rad/s, each with its unit, equal to the stored point's."""
    from frirom._errors import with_hz
    model, exc = _chain()
    r = frf(model, exc, 20.0, 200.0, SolverOptions(harmonics=1, max_points=5,
                                                   stability=False, refine_peak=False))
    assert not r.complete and "max_points" in r.message, r.message
    w = float(r.omega[-1])
    assert f"last point at {w / 2 / np.pi:.7g} Hz, {w:.7g} rad/s" in r.message, r.message
    # a Fortran frequency in rad/s gets its Hz beside it, once (idempotent)
    text = "left the range through 11905.52 rad/s (start 11938.05 rad/s)"
    assert with_hz(text) == ("left the range through 11905.52 rad/s (1894.82 Hz) "
                             "(start 11938.05 rad/s (1900 Hz))")
    assert with_hz(with_hz(text)) == with_hz(text)
