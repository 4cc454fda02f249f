"""Write the matrices of the bundled `bladed_disk` case: a lumped 12-sector bladed disk
with underplatform dampers between neighbouring blades (SI units: kg, N/m).

Per sector s (0..11), three circumferential DoFs:

    3s    disk rim        ring springs to the neighbouring sectors' rims and to the hub
    3s+1  blade platform  on the rim
    3s+2  blade tip       on the platform

The damper between the platforms of sectors s and s+1 (bladed_disk.toml, node to node)
rubs on both as the platforms move out of phase, which they do under an engine-order
excitation that travels around the disk. The disk is tuned (all sectors equal), so the
response to an engine-order load is a travelling wave with equal amplitude on every blade.

Run `python make_bladed_disk.py` in this folder to rewrite M.mtx, K.mtx and dofs.txt.
"""

import sys
from pathlib import Path

import numpy as np
import scipy.sparse as sp

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "models"))
from lumped import write_lumped_case  # noqa: E402

N_SECTORS = 12
MASS = (0.40, 0.06, 0.03)      # kg: rim, platform, tip (per sector)
K_HUB = 4.0e7                  # N/m, rim to hub (ground)
K_RING = 2.0e7                 # N/m, rim to neighbouring rim
K_ROOT = 3e6                 # N/m, rim to platform
K_BLADE = 1.0e6                # N/m, platform to tip (first blade bending)


def matrices():
    n = 3 * N_SECTORS
    K = sp.lil_matrix((n, n))

    def spring(i, j, k):
        K[i, i] += k
        if j is not None:
            K[j, j] += k
            K[i, j] -= k
            K[j, i] -= k

    for s in range(N_SECTORS):
        rim, plat, tip = 3 * s, 3 * s + 1, 3 * s + 2
        spring(rim, None, K_HUB)
        spring(rim, 3 * ((s + 1) % N_SECTORS), K_RING)
        spring(rim, plat, K_ROOT)
        spring(plat, tip, K_BLADE)
    M = sp.diags(np.tile(MASS, N_SECTORS))
    return M.tocsr(), K.tocsr()


def labels():
    return [f"s{s}:{part}" for s in range(N_SECTORS) for part in ("rim", "platform", "tip")]


def main():
    M, K = matrices()
    write_lumped_case(HERE, M, K, labels(), "bladed disk")


if __name__ == "__main__":
    main()
