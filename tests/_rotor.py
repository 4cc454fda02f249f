"""The lattice rotor with friction contacts of tests/test_cyclic_solver.py (also read by
tests/test_cyclic_gsi.py): the full N-sector rotor of tests/_lattices.py on linear
supports, ground contacts (normal1d) and tip-to-tip Jenkins dampers, and the same contacts
on sector 0 alone for the cyclic model."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from _lattices import tuned_rotor
from frirom.model import ContactGroup, Damping, Model
from frirom.reduction.cyclic import CyclicSector, axis_rotation

N, EO, H = 7, 2, 3
ALPHA, BETA = 2.0, 2e-6           # Rayleigh damping (1/s, s)
K_SUPPORT = 3e5                   # N/m, linear springs tying the interface nodes to ground
FORCE = 20.0                      # N, tangential tip load amplitude of sector 0
# normal1d ground contacts: kt, kn, mu, n0 (preload); jenkins tip dampers: kt, mu, fn0
P_GROUND = (4e5, 8e5, 0.3, 8.0)
P_TIP = (2e5, 0.3, 3.0)
OPTS = dict(harmonics=H, samples=16 * N, tol_residual=1e-11, tol_update=1e-11, max_iter=40)


def rotor(per_sector: int = 3):
    """The rotor (per_sector angular stations per sector; its contacts, rotor_contacts,
    sit on stations 0..2 of each group of three: the cyclic sector's are sector 0's for any
    per_sector >= 3, the full model's need per_sector = 3)."""
    r = tuned_rotor(n_sectors=N, per_sector=per_sector, blade=2)
    s = r["sector"]
    n_full = r["K"].shape[0]
    owner = r["node_owner"]
    # linear supports on every interface node (removes the rigid-body motion)
    sup_nodes = r["iface_nodes"]
    sup = np.zeros(n_full)
    sup[(3 * sup_nodes[:, None] + np.arange(3)).ravel()] = K_SUPPORT
    K = (r["K"] + sp.diags(sup)).tocsr()
    glob = r["dofs"][s["nodes"]].ravel()          # sector DoF -> global DoF
    own0 = np.repeat(owner[s["nodes"]] == 0, 3)
    Ks = (s["K"] + sp.diags(np.where(own0, sup[glob], 0.0))).tocsr()
    return r, K, Ks, glob


def rotor_sector(r, n_sectors: int = N) -> CyclicSector:
    """The cyclic sector of a ``tuned_rotor`` ``r``: its left and right boundary DoFs, the z
    axis through the origin."""
    s = r["sector"]
    return CyclicSector(n_dof=s["K"].shape[0], n_sectors=n_sectors,
                        left=s["node_dofs"][s["left"]], right=s["node_dofs"][s["right"]],
                        axis=np.array([0.0, 0.0, 1.0]), origin=np.zeros(3))


def rotor_contacts(r, per_sector_rows):
    """Ground contacts (normal1d, tangential + axial) on the middle-radius interface nodes
    and tip-to-tip Jenkins dampers (tangential at mid-angle) of the sectors listed."""
    Q = axis_rotation(2 * np.pi / N)
    nz = r["nz"]
    iface = r["iface_nodes"].reshape(nz, 3)          # (station, radius)
    tips = r["tips"]
    theta_tip = np.arctan2(r["coords"][tips[0], 1], r["coords"][tips[0], 0])
    th = theta_tip + np.pi / N
    e_tip = np.array([-np.sin(th), np.cos(th), 0.0])
    ground, tip = [], []
    for s in per_sector_rows:
        for st in range(3 * s, 3 * s + 3):
            node = iface[st, 1]
            fr = r["frames"][np.nonzero(r["iface_nodes"] == node)[0][0]]
            ground.append((node, fr[0], fr[2]))
        Qs = np.linalg.matrix_power(Q, s)
        tip.append((tips[s], tips[(s + 1) % N], Qs @ e_tip))
    return ground, tip, e_tip


def full_model(r, K):
    n = K.shape[0]
    ground, tip, _ = rotor_contacts(r, range(N))
    G1 = sp.lil_matrix((2 * len(ground), n))
    for e, (node, et, ea) in enumerate(ground):
        G1[2 * e, 3 * node:3 * node + 3] = et
        G1[2 * e + 1, 3 * node:3 * node + 3] = ea
    G2 = sp.lil_matrix((len(tip), n))
    for e, (a, b, d) in enumerate(tip):
        G2[e, 3 * a:3 * a + 3] = d
        G2[e, 3 * b:3 * b + 3] = -d
    groups = [ContactGroup("normal1d", G1, P_GROUND, name="ground"),
              ContactGroup("jenkins", G2, P_TIP, name="tips")]
    return Model(r["M"], K, Damping.rayleigh(ALPHA, BETA), groups)


def sector_contacts(r, glob, n_s):
    """The same contacts on sector 0 only, in sector DoFs; the tip damper reaches the next
    sector's tip (columns n_s.., that sector's own frame: its global vector is Q x)."""
    Q = axis_rotation(2 * np.pi / N)
    ground, tip, e_tip = rotor_contacts(r, [0])
    loc = -np.ones(glob.max() + 1, dtype=np.int64)
    loc[glob] = np.arange(glob.size)
    G1 = sp.lil_matrix((2 * len(ground), n_s))
    for e, (node, et, ea) in enumerate(ground):
        d = loc[3 * node + np.arange(3)]
        G1[2 * e, d] = et
        G1[2 * e + 1, d] = ea
    G2 = sp.lil_matrix((1, 2 * n_s))
    tip0 = loc[3 * r["tips"][0] + np.arange(3)]
    G2[0, tip0] = e_tip
    G2[0, n_s + tip0] = -(e_tip @ Q)
    return [ContactGroup("normal1d", G1, P_GROUND, name="ground"),
            ContactGroup("jenkins", G2, P_TIP, name="tips")]
