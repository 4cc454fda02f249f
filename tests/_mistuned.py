"""A bladed lattice disk of N sectors for the mistuning tests and benchmark: the tuned
lattice rotor of tests/_lattices.py on linear supports, each sector with normal1d friction
contacts to ground on its mid-radius interface nodes and a Jenkins damper from its blade tip
to the next blade's tip (a shroud contact, tangential at mid-angle): one friction interface
per blade, and one that couples neighbouring blades as shrouds and under-platform dampers
do."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from _lattices import tuned_rotor
from frirom.model import ContactGroup
from _rotor import rotor_sector
from frirom.reduction.cyclic import CyclicSector, axis_rotation

K_SUPPORT = 3e5                   # N/m, springs tying the interface nodes to ground
P_GROUND = (4e5, 8e5, 0.3, 8.0)   # normal1d: kt, kn, mu, n0
P_TIP = (2e5, 0.3, 3.0)           # jenkins: kt, mu, fn0
FORCE = 20.0                      # N, tangential tip load of sector 0


def disk(n_sectors: int, ground: bool = True):
    """Everything a test needs: a dict with the full rotor (K, M), the sector (Ks, Ms,
    CyclicSector), its contacts on sector DoFs, blade DoFs, tip DoFs and the tip load."""
    N = n_sectors
    r = tuned_rotor(n_sectors=N, per_sector=3, blade=2)
    s = r["sector"]
    owner = r["node_owner"]
    sup = np.zeros(r["K"].shape[0])
    sup[(3 * r["iface_nodes"][:, None] + np.arange(3)).ravel()] = K_SUPPORT
    K = (r["K"] + sp.diags(sup)).tocsr()
    glob = r["dofs"][s["nodes"]].ravel()
    own0 = np.repeat(owner[s["nodes"]] == 0, 3)
    Ks = (s["K"] + sp.diags(np.where(own0, sup[glob], 0.0))).tocsr()
    n_s = Ks.shape[0]
    loc = -np.ones(glob.max() + 1, dtype=np.int64)
    loc[glob] = np.arange(glob.size)
    sector = rotor_sector(r, N)
    n_ring = r["nz"] * 3 * 3
    blade_nodes = [i for i in range(n_ring, owner.size) if owner[i] == 0]
    blade = loc[(3 * np.array(blade_nodes)[:, None] + np.arange(3)).ravel()]
    tip0 = loc[3 * r["tips"][0] + np.arange(3)]
    # contacts of sector 0
    iface = r["iface_nodes"].reshape(r["nz"], 3)
    Q = axis_rotation(2 * np.pi / N)
    th_tip = np.arctan2(r["coords"][r["tips"][0], 1], r["coords"][r["tips"][0], 0])
    th = th_tip + np.pi / N
    e_tip = np.array([-np.sin(th), np.cos(th), 0.0])
    G1 = sp.lil_matrix((6, n_s))
    for e, st in enumerate(range(3)):
        node = iface[st, 1]
        fr = r["frames"][np.nonzero(r["iface_nodes"] == node)[0][0]]
        d = loc[3 * node + np.arange(3)]
        G1[2 * e, d] = fr[0]
        G1[2 * e + 1, d] = fr[2]
    G2 = sp.lil_matrix((1, 2 * n_s))
    G2[0, tip0] = e_tip
    G2[0, n_s + tip0] = -(e_tip @ Q)
    contacts = [ContactGroup("normal1d", G1, P_GROUND, name="ground"),
                ContactGroup("jenkins", G2, P_TIP, name="shroud")][0 if ground else 1:]
    f0 = FORCE * np.array([-np.sin(th_tip), np.cos(th_tip), 0.3])
    F = np.zeros((n_s, 2), complex)
    F[tip0, 1] = f0
    keep = np.unique(np.concatenate([tip0, G1.tocsr().indices,
                                     G2.tocsr().indices % n_s]))
    return {"r": r, "K": K, "M": r["M"], "Ks": Ks, "Ms": s["M"], "sector": sector,
            "contacts": contacts, "blade": blade, "tip": tip0, "keep": keep, "F": F,
            "glob": glob, "loc": loc, "blade_nodes_full": _blade_nodes(r, n_ring)}


def _blade_nodes(r, n_ring):
    """Global blade node ids of every sector, (N, n_blade_nodes)."""
    owner = r["node_owner"]
    return np.array([[i for i in range(n_ring, owner.size) if owner[i] == s]
                     for s in range(r["n_sectors"])])


def lumped_disk(n_sectors: int, k_blade=1e6, m_blade=0.1, k_coupling=2e5, k_ground=1e6,
                m_disk=0.3):
    """One blade DoF per sector (the classic single-family model of the mistuning
    literature): disk node z with a ground spring and a coupling spring to the next
    disk node, a blade mass on a spring to its disk node, all in the axial direction z
    (which the rotation about z leaves alone); the in-plane x, y of the disk node sit on
    stiff ground springs. Sector DoFs: left disk node (0-2), blade (3-5), right (6-8)."""
    import scipy.sparse as sp_
    K = np.zeros((9, 9))
    M = np.zeros((9, 9))

    def spring(a, b, k):
        K[a, a] += k
        K[b, b] += k
        K[a, b] -= k
        K[b, a] -= k

    spring(2, 5, k_blade)            # blade on its disk node
    spring(2, 8, k_coupling)         # disk to the next disk node
    K[2, 2] += k_ground
    for d in (0, 1):
        K[d, d] += 100 * k_ground    # in-plane: stiff
        K[3 + d, 3 + d] += k_blade   # blade in-plane on its own springs
        M[d, d] = m_disk
        M[3 + d, 3 + d] = m_blade
    M[2, 2] = m_disk
    M[5, 5] = m_blade
    sector = CyclicSector(n_dof=9, n_sectors=n_sectors, left=np.array([[0, 1, 2]]),
                          right=np.array([[6, 7, 8]]), axis=np.array([0.0, 0.0, 1.0]),
                          origin=np.zeros(3))
    F = np.zeros((9, 2), complex)
    F[5, 1] = 1.0
    return {"Ks": sp_.csr_matrix(K), "Ms": sp_.csr_matrix(M), "sector": sector,
            "blade": np.array([3, 4, 5]), "tip": np.array([5]), "F": F}
