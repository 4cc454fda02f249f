"""Write the matrices of the bundled `joint` case: a lumped blade with a platform friction
damper (SI units: kg, N/m).

    DoF 0  platform, circumferential x      DoF 2  blade lower span, x
    DoF 1  platform, radial y               DoF 3  blade mid span, x
                                            DoF 4  blade tip, x

The blade is a spring-mass chain clamped through the platform to the disk (springs to
ground on DoFs 0 and 1). The damper rests on the platform's inclined face (30 deg from x)
held by centrifugal load; it is modelled as ground, so the contact in joint.toml has the
tangential direction (cos 30, sin 30) in the platform's (x, y) DoFs (and, for a law with
normal load variation, the normal direction (-sin 30, cos 30)). First bending mode: 445 Hz
free; with the damper stuck 469 Hz (joint.toml's kt) or 475 Hz (joint_liftoff.toml's kt
and kn). joint.toml models the damper as a Jenkins element
(constant normal load); joint_liftoff.toml as a 1-D normal-load contact with a balanced
100 N preload, which lifts off near resonance (the periodic response is unstable from
the peak on).

Run `python make_joint.py` in this folder to rewrite M.mtx, K.mtx and dofs.txt.
"""

import sys
from pathlib import Path

import numpy as np
import scipy.sparse as sp

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "models"))
from lumped import write_lumped_case  # noqa: E402

MASS = [0.080, 0.080, 0.030, 0.030, 0.020]          # kg
GROUND = {0: 4.0e6, 1: 8.0e6}                         # N/m, platform to disk
CHAIN = [(0, 2, 1.5e6), (2, 3, 1.0e6), (3, 4, 0.6e6)]  # N/m, blade segments
LABELS = ["platform:x", "platform:y", "blade_low:x", "blade_mid:x", "tip:x"]


def matrices():
    n = len(MASS)
    K = np.zeros((n, n))
    for i, k in GROUND.items():
        K[i, i] += k
    for i, j, k in CHAIN:
        K[[i, j], [i, j]] += k
        K[i, j] -= k
        K[j, i] -= k
    return sp.diags(MASS).tocsr(), sp.csr_matrix(K)


def main():
    M, K = matrices()
    write_lumped_case(HERE, M, K, LABELS, "joint case")


if __name__ == "__main__":
    main()
