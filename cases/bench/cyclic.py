"""Benchmark: one cyclic sector against the whole tuned rotor (nonlinear FRF).

Model: the lumped bladed disk of cases/bench/solver.py (nb sectors x disk, platform, tip;
Jenkins shroud contacts between neighbouring platforms; engine order nb // 4 on the tips).
The whole rotor is solved by the banded harmonic balance on all 3 nb DoFs with nb contact
elements; the sector by frirom.model.CyclicModel: 3 DoFs, one contact element reaching
the next sector, and per time harmonic h the modes of nodal diameter -h EO mod nb.

Prints per size: FRF times of both (same continuation settings, over 0.9 .. 1.1 of the
stuck ND-EO frequency), the number of points, the speed-up, and the largest difference of
the tip harmonics between the two at five of the full FRF's frequencies (samples per
period a multiple of nb, so both AFTs see the same samples). Last line: the speed-up at
the largest size.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python cases/bench/cyclic.py [--quick]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

sys.path.insert(0, str(Path(__file__).resolve().parent))
from solver import bladed_disk, resonance  # noqa: E402

from frirom.model import ContactGroup, CyclicModel, Excitation, SectorModes  # noqa: E402
from frirom.solver import SolverOptions, frf, solve_point  # noqa: E402

MASSES = (2.0, 0.3, 0.5)                 # kg: disk, platform, tip (cases/bench/solver.py)
KD, KDP, KPT, KHUB = 4e7, 2e7, 5e6, 1e7  # N/m
BETA = 2e-6                              # s, Rayleigh stiffness-proportional damping


def sector_model(nb: int, eo: int, H: int) -> CyclicModel:
    """The bench rotor as one sector: modes of each nodal diameter from the 3 x 3 sector
    matrices at inter-sector phase k 2 pi / nb (independent of frirom's CyclicSector)."""
    modes = {}
    for h in range(H + 1):
        k = (-h * eo) % nb
        if k in modes or (-k) % nb in modes:
            continue
        c = 2.0 - 2.0 * np.cos(2 * np.pi * k / nb)
        K = np.array([[KD * c + KDP + KHUB, -KDP, 0.0], [-KDP, KDP + KPT, -KPT],
                      [0.0, -KPT, KPT]])
        lam, phi = sla.eigh(K, np.diag(MASSES))
        w = np.sqrt(lam)
        modes[k] = SectorModes(k, phi, w, BETA * w / 2.0)
    G = sp.csr_matrix(np.array([[0.0, 1.0, 0.0, 0.0, -1.0, 0.0]]))
    shroud = ContactGroup("jenkins", G, [1e6, 0.3, 40.0], name="shroud")
    return CyclicModel(n_dof=3, n_sectors=nb, engine_order=eo, modes=modes,
                       contacts=[shroud])


def run(nb: int, H: int, pts: int):
    eo = max(1, nb // 4)
    full, ex_full = bladed_disk(nb, eo)
    sec = sector_model(nb, eo, H)
    F = np.zeros((3, 2), complex)
    F[2, 1] = ex_full.F[2, 1]
    ex_sec = Excitation(F)
    samples = nb * int(np.ceil(64 / nb))
    w0 = resonance(nb, eo)
    kw = dict(harmonics=H, samples=samples, ds=0.05, ds_max=0.2, max_points=pts)
    t0 = time.perf_counter()
    rf = frf(full, ex_full, 0.9 * w0, 1.1 * w0, SolverOptions(formulation="banded", **kw),
             outputs=[2])
    tf = time.perf_counter() - t0
    t0 = time.perf_counter()
    rs = frf(sec, ex_sec, 0.9 * w0, 1.1 * w0, SolverOptions(**kw), outputs=[2])
    ts = time.perf_counter() - t0
    diff = 0.0
    for i in np.linspace(0, rf.omega.size - 1, 5).astype(int):
        p = solve_point(sec, ex_sec, rf.omega[i], SolverOptions(harmonics=H, samples=samples),
                        outputs=[2])
        diff = max(diff, np.abs(p.X - rf.X[i]).max() / np.abs(rf.X[i]).max())
    return eo, samples, tf, rf.omega.size, ts, rs.omega.size, diff


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes only")
    a = ap.parse_args()
    sizes = (12, 48) if a.quick else (12, 48, 192, 768)
    H = 3
    print(f"{'sectors':>7} {'EO':>3} {'N':>4} {'full DoFs':>9} {'full s':>8} {'pts':>4} "
          f"{'sector s':>8} {'pts':>4} {'speed-up':>8} {'max rel diff':>12}")
    last = None
    for nb in sizes:
        eo, ns, tf, nf, ts, nsec, d = run(nb, H, 400)
        last = tf / ts
        print(f"{nb:7d} {eo:3d} {ns:4d} {3 * nb:9d} {tf:8.3f} {nf:4d} {ts:8.3f} {nsec:4d} "
              f"{last:8.1f} {d:12.1e}")
    print(f"speed-up of the sector over the whole rotor at {sizes[-1]} sectors, H = {H}: "
          f"{last:.1f}")


if __name__ == "__main__":
    from _results import record
    record("cyclic", main)
