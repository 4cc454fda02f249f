"""The continuation keeps the curve's orientation through the folds and contact-state
corners of cases/joint/joint_liftoff.toml (420-470 Hz), with and without the carried
contact history.

Between 446 and 450 Hz that curve folds several times (lift-off onset: a fold at 449.6 Hz,
back to about 447.3 Hz, then up the resonance). Oriented by the previous tangent alone,
the run at H = 8 took a step onto the branch it had just come along, followed it back and
left the range through 420 Hz at 4.2e-4 m, against a peak of 1.29e-3 m at 454 Hz
(N = 256 with chord steps; N = 128 and 1 024 with full Newton). Tangents now keep
sign(det J) t_lam, the orientation of the bordered Jacobian, and a step against it is
rejected (frirom_newton: cont_tangent, retraced); the secant rule (chord_wins) may not
point against the parameter direction of that tangent.

Independent check: fixed-frequency Newton (solve_point from the neighbouring point, no
continuation) at frequencies where the response is unique.
"""

from __future__ import annotations

import copy
import dataclasses
import warnings
from pathlib import Path

import numpy as np
import pytest

from frirom.auto import _excitation
from frirom.deck import build_deck, parse_deck
from frirom.deck.schema import read_toml
from frirom.solver import frf, solve_point

DECK = Path(__file__).resolve().parents[1] / "cases" / "joint" / "joint_liftoff.toml"


@pytest.fixture(scope="module")
def liftoff():
    raw = copy.deepcopy(read_toml(DECK))
    raw["frequency"].update(start=420.0, end=470.0)
    return build_deck(parse_deck(DECK, raw))


def _frf(deck, H, N, reuse, history):
    opts = dataclasses.replace(deck.options(), harmonics=H, samples=N, stability=False,
                               history=history, reuse_jacobian=reuse)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return frf(deck.model(), _excitation(deck.F, H), deck.omega_start, deck.omega_end,
                   opts, outputs=deck.solver_outputs), opts


def _check(deck, H, N, reuse, history, solve_at=()):
    r, opts = _frf(deck, H, N, reuse, history)
    assert r.complete, (H, N, reuse, r.message)
    hz = r.frequency_hz
    # never back below the first fold once past it (the retraced curve went to 420 Hz)
    past = np.argmax(hz > 446.5)
    assert hz[past:].min() > 446.0, (H, N, reuse)
    # points of the curve against fixed-frequency Newton at their frequency, started from
    # the neighbouring point's unknowns, where the response is unique (below the folds, on
    # the resonance, above it)
    for f in solve_at:
        i = int(np.argmin(np.abs(hz - f)))
        p = solve_point(deck.model(), _excitation(deck.F, H), r.omega[i], opts,
                        outputs=deck.solver_outputs, start={"unknowns": r.unknowns[i - 1]})
        assert abs(r.amp_max[i, 0] / p.amp_max[0] - 1) < 1e-6, (H, N, f)
    return r.peak(0).amplitude


@pytest.mark.parametrize("N, reuse, history", [(256, True, False), (128, False, False),
                                               (256, False, True)],
                         ids=["N256-chord", "N128-full_newton", "N256-full_newton-history"])
def test_liftoff_h8_runs_through_the_folds(liftoff, N, reuse, history):
    # (N, Jacobian, history) that turned back before (the last one stopped at the fold
    # near 447.4 Hz, where the secant rule pointed against the orientation, before that
    # took precedence)
    peak = _check(liftoff, 8, N, reuse, history, solve_at=(430.0, 455.0, 465.0))
    assert 1.29e-3 < peak < 1.30e-3


@pytest.mark.slow
@pytest.mark.parametrize("history", [False, True], ids=["no_history", "history"])
@pytest.mark.parametrize("reuse", [True, False], ids=["chord", "full_newton"])
@pytest.mark.parametrize("H", [4, 8])
def test_liftoff_curve_completes_for_every_sample_count(liftoff, H, reuse, history):
    peaks = np.array([_check(liftoff, H, N, reuse, history) for N in (128, 256, 512, 1024)])
    # one resonance, the same to the aliasing of N (1.29e-3 m near 454 Hz)
    assert np.all(np.abs(peaks / peaks[-1] - 1) < 3e-3), peaks
    assert 1.28e-3 < peaks[-1] < 1.30e-3
