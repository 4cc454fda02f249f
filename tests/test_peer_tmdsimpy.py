"""cases/bench/peer_tmdsimpy.py: skips cleanly without the peer; its model's frirom side is
the model it says (the stuck start against scipy's eigenvalues of K + the Jenkins
stiffnesses); with the peer installed (FRIROM_PEER_TMDSIMPY), the two EPMCs agree at
H = 1."""

import os
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

BENCH = Path(__file__).resolve().parents[1] / "cases" / "bench"
sys.path.insert(0, str(BENCH))

import peer_tmdsimpy  # noqa: E402


def test_skips_without_the_peer(tmp_path, capsys):
    assert peer_tmdsimpy.main(["--peer", str(tmp_path / "nowhere")]) == 0
    assert "skipped: tmdsimpy is not installed" in capsys.readouterr().out


def test_frirom_side_starts_on_the_stuck_mode_and_slips():
    bb, phi, _ = peer_tmdsimpy.frirom_backbone(1, 64)
    m, k, c = peer_tmdsimpy.matrices()
    ks = k.copy()
    for row, kt, _ in peer_tmdsimpy.JENKINS:
        r = np.array(row)
        ks += kt * np.outer(r, r)
    w0 = np.sqrt(scipy.linalg.eigh(ks, m, eigvals_only=True)[0])
    assert bb.omega0 == pytest.approx(w0, rel=1e-12)
    assert bb.omega[0] == pytest.approx(w0, rel=1e-8)        # stuck: the linear mode
    assert phi @ m @ phi == pytest.approx(1.0, rel=1e-10)
    # Rayleigh damping of the stuck mode: xi = phi^T C phi
    assert bb.damping_ratio[0] == pytest.approx(phi @ c @ phi / (2 * w0), rel=1e-8)
    assert bb.omega[-1] < 0.95 * w0 and bb.damping_ratio.max() > 5 * bb.damping_ratio[0]


@pytest.mark.slow
@pytest.mark.skipif(not os.environ.get("FRIROM_PEER_TMDSIMPY"),
                    reason="tmdsimpy not installed (FRIROM_PEER_TMDSIMPY)")
def test_against_the_peer(capsys):
    assert peer_tmdsimpy.main(["--quick"]) == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    assert "H = 1, N = 128" in line
