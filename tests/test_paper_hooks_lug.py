"""ROM_II of the vane with hooks (cases/paper_hooks) with the interlocking lug as a joint
of its own: the hooks reduced by their GSI modes, the lug by its own full-stick GSI modes
(``[reduction.interface_modes] separate``, ``separate_stick``) or kept physical; and the
deck's checks of those keys.

The case's tests need ccx (coarse mesh, about 15 s: slow); the deck checks use the small
block model of tests/test_reduction_deck.py (conftest.py's block_dir, _models.GSI_DECK).
"""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from _models import GSI_DECK, HOOKS_F0, hooks_peak
from frirom._errors import InputError
from frirom.deck import load_deck

needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None, reason="needs ccx")


@pytest.mark.slow
@needs_ccx
def test_hooks_gsi_error_decreases_and_40_modes_match_with_the_lug_apart(hooks_case):
    """The lug apart from the hooks' basis (its own 12 full-stick GSI modes), ROM_II
    against ROM_I at the preload with the most slip: the errors in peak amplitude and in
    peak frequency both fall with every step 10 -> 20 -> 40 -> 80 hook GSI modes (the
    lug's coordinates fixed, so the hooks' basis alone changes; measured 1.9 %, 0.76 %,
    0.10 %, 0.009 % and 4.6e-4, 3.0e-4, 2.4e-5, 5.8e-6), the paper's 40 modes are within
    the issue's targets (1 % / 0.1 %), and the lug stays stuck at every point. The lug's
    own modes against the lug kept physical (48 DoFs) with the same 40 hook modes: within
    1e-3 in peak amplitude and 1e-5 in frequency (measured 2e-5, 8e-7): 12 modes carry the
    stuck lug (six rigid motions per face)."""
    import paper_hooks as ph
    (f1, a1), _ = hooks_peak(ph.Rom(hooks_case, "rom1", "coarse"), HOOKS_F0)
    errs, lugs, peaks = {}, {}, {}
    for n in (10, 20, 40, 80):
        r2 = ph.Rom(hooks_case, "rom2", "coarse", n)
        assert r2.sizes["contact_dofs"] == n + 12
        peaks[n], res = hooks_peak(r2, HOOKS_F0)
        f2, a2 = peaks[n]
        errs[n] = (abs(a2 / a1 - 1), abs(f2 / f1 - 1))
        lugs[n] = ph.lug_stick(r2, res)
    for k in (0, 1):
        e = [errs[n][k] for n in (10, 20, 40, 80)]
        assert all(b < a for a, b in zip(e, e[1:])), errs
    assert errs[40][0] < 0.01 and errs[40][1] < 0.001, errs
    assert all(v == 1.0 for v in lugs.values()), lugs
    rp = ph.Rom(hooks_case, "rom2", "coarse", 40, lug_reduction="physical")
    assert rp.sizes["contact_dofs"] == 40 + 48
    (fp, ap), _ = hooks_peak(rp, HOOKS_F0)
    fo, ao = peaks[40]                  # the lug's own modes, from the loop
    assert ao == pytest.approx(ap, rel=1e-3)
    assert fo == pytest.approx(fp, rel=1e-5)


@pytest.mark.slow
@needs_ccx
def test_lug_kept_physical_points_are_converged_not_accepted_at_the_preloads_round_off(hooks_case):
    """The lug kept physical (48 DoFs), everything stuck (10 000 N): its 300 kN preload's
    static image through the 12 N/m soft mount (|R_0 G^T f_rest| ~ 1.7e5 m) dominates
    the residual's reference, 1e9 x the vibration. A round-off rule on that reference
    alone ("|R| <= 100 eps rref accepts") took points after 2 Newton iterations, 2e-5
    (median) to 1.4e-4 off: that, not the lug's own basis, made the physical lug look
    twice as fast (4.5 against 7.5 evaluations per point). Every third point of the FRF,
    solved again at its frequency from its contact history to 1e-13, equals the FRF's
    harmonics 1..H within 1e-6 of their largest (measured 6.8e-8; the update test,
    1e-8 of |y|, decides each point)."""
    import dataclasses

    import paper_hooks as ph
    from frirom.solver import solve_point
    rom = ph.Rom(hooks_case, "rom2", "coarse", 40, lug_reduction="physical")
    rom.set_preload(1e4)
    res, _ = rom.frf()
    assert res.complete and np.all(res.state_fractions[:, :, 0] == 1.0)
    tight = dataclasses.replace(rom.options, tol_residual=1e-13, tol_update=1e-13,
                                max_iter=60)
    errs = []
    for i in range(0, len(res.omega), 3):
        p = solve_point(rom.model, rom.excitation, res.omega[i], tight,
                        outputs=rom.deck.outputs, start={"slider": res.slider[i]})
        errs.append(np.abs(p.X[:, 1:] - res.X[i][:, 1:]).max() / np.abs(p.X[:, 1:]).max())
    assert max(errs) < 1e-6, errs


BAD_SEPARATE = [
    ('stick = 6', 'stick = 6\nseparate = ["ACTIVE"]',
     "reduction.interface_modes.separate: expected node sets of reduction.interface"),
    ('stick = 6', 'stick = 6\nseparate = ["IFACE"]',
     "reduction.interface_modes.separate: expected some interface sets left"),
    ('stick = 6', 'stick = 6\nseparate_stick = 4',
     "reduction.interface_modes.separate_stick: expected with separate"),
    ('stick = 6', 'stick = 6\nseparate_stick = -1',
     "reduction.interface_modes.separate_stick: expected"),
]


@pytest.mark.parametrize("old, new, expected", BAD_SEPARATE)
def test_separate_keys_are_checked(block_dir, old, new, expected):
    """A joint of its own must be interface sets, not all of them, and its stick-mode
    count needs the sets: each bad deck names the key."""
    good = GSI_DECK.format(kt="2.0e8", h=3, mu=0.5)
    assert old in good
    deck = block_dir / "bad.toml"
    deck.write_text(good.replace(old, new))
    with pytest.raises(InputError) as exc:
        load_deck(deck)
    assert expected in str(exc.value) and "bad.toml" in str(exc.value), str(exc.value)
