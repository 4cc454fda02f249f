"""Craig-Bampton component mode synthesis (paper Eq. 12-16).

The DoFs split into masters m (interface DoFs, where contact elements attach, plus the
active DoFs where loads act or responses are read) and slaves s. The basis

    x = T q,   T = [[I, 0], [Psi, Phi]],   q = [x_m; eta]

holds the static constraint modes Psi = -K_ss^-1 K_sm (one factorisation of K_ss,
many right-hand sides) and the k lowest fixed-interface normal modes Phi (K_ss Phi =
M_ss Phi Lambda, M_ss-orthonormal; ARPACK shift-invert in Fortran). The reduced matrices
are the Galerkin projections K_r = T^T K T, M_r = T^T M T (Eq. 16).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .._errors import InputError
from .eigen import canonical_modes, default_ncv, eigsh_shift_invert

__all__ = ["CraigBampton", "craig_bampton"]


@dataclass
class CraigBampton:
    """A Craig-Bampton reduced model.

    Attributes
    ----------
    K, M : ndarray (n_r, n_r), n_r = n_masters + n_modes
        Reduced stiffness and mass; coordinates q = [x_m (physical master DoFs);
        eta (modal amplitudes of the fixed-interface modes)].
    master_index : ndarray (n_masters,)  rows of the full matrices that are masters
    slave_index : ndarray (n_slaves,)    the remaining rows
    master_dofs : ndarray (n_masters, 2) (node, direction) label of each master
    psi : ndarray (n_slaves, n_masters)  static constraint modes
    phi : ndarray (n_slaves, n_modes)    fixed-interface modes, M_ss-orthonormal
    eigenvalues : ndarray (n_modes,)     fixed-interface eigenvalues [rad^2/s^2]
    n_dof : int                          size of the full model
    """

    K: np.ndarray
    M: np.ndarray
    master_index: np.ndarray
    slave_index: np.ndarray
    master_dofs: np.ndarray
    psi: np.ndarray
    phi: np.ndarray
    eigenvalues: np.ndarray
    n_dof: int

    @property
    def n_masters(self) -> int:
        return self.master_index.size

    @property
    def n_modes(self) -> int:
        return self.eigenvalues.size

    @property
    def cutoff_frequency(self) -> float:
        """Frequency [Hz] of the highest retained fixed-interface mode."""
        return float(np.sqrt(max(self.eigenvalues[-1], 0.0)) / (2 * np.pi))

    def expand(self, q) -> np.ndarray:
        """Physical DoFs (n_dof, ...) of the full model from reduced coordinates (n_r, ...).

        Works for real or complex q (e.g. harmonic amplitudes), one column per vector.
        """
        q = np.asarray(q)
        if q.shape[0] != self.K.shape[0]:
            raise InputError(f"q has {q.shape[0]} rows, expected {self.K.shape[0]} "
                             f"(n_masters + n_modes)")
        xm = q[:self.n_masters]
        eta = q[self.n_masters:]
        x = np.zeros((self.n_dof,) + q.shape[1:], dtype=np.result_type(q, float))
        x[self.master_index] = xm
        x[self.slave_index] = (np.tensordot(self.psi, xm, axes=1)
                               + np.tensordot(self.phi, eta, axes=1))
        return x

    def master_position(self, dofs) -> np.ndarray:
        """Positions in q of the given (node, direction) master DoFs (n, 2)."""
        dofs = np.atleast_2d(np.asarray(dofs, dtype=np.int64))
        key = self.master_dofs[:, 0] * 10 + self.master_dofs[:, 1]
        want = dofs[:, 0] * 10 + dofs[:, 1]
        order = np.argsort(key)
        pos = np.searchsorted(key, want, sorter=order)
        pos = np.minimum(pos, key.size - 1)
        hit = key[order[pos]] == want
        if not np.all(hit):
            raise InputError(f"DoF(s) {dofs[~hit][:5].tolist()} are not masters")
        return order[pos]


def craig_bampton(model, n_modes: int, interface=None, active=None, directions=(1, 2, 3),
                  masters=None, sigma: float = 0.0, tol: float = 0.0,
                  ncv: int = 0, solver: str = "frirom") -> CraigBampton:
    """Craig-Bampton reduction of an FEModel (frirom.io) or of (K, M).

    Parameters
    ----------
    model : frirom.io.FEModel or tuple
        An FEModel (K, M, dofs, node_sets), or a tuple (K, M).
    n_modes : int
        Fixed-interface normal modes kept (0 = Guyan reduction).
    interface, active : str or list of str, optional
        Node-set name(s) whose DoFs in ``directions`` become masters.
    masters : array_like of int, optional
        Extra master rows (indices into the full matrices).
    sigma : float
        Shift of the fixed-interface eigen-solve [rad^2/s^2]; 0 unless K_ss is singular
        (then the constraint modes do not exist either: add masters).
    tol, ncv : float, int
        ARPACK tolerance and Lanczos basis size (0 = defaults).
    solver : {"frirom", "scipy"}
        "frirom" (Fortran: ARPACK + MUMPS, the default) or "scipy" (eigsh on one SuperLU
        factor of K_ss, reused for the constraint modes, same Lanczos basis size;
        reference and fallback).

    Returns
    -------
    CraigBampton
    """
    if isinstance(model, tuple):
        K, M = model
        dofs = np.column_stack([np.arange(1, K.shape[0] + 1), np.zeros(K.shape[0], int)])
        idx = []
        if interface is not None or active is not None:
            raise InputError("node sets need an FEModel (frirom.io), not a bare (K, M)")
    else:
        K, M, dofs = model.K, model.M, model.dofs
        idx = []
        for sets in (interface, active):
            if sets is not None:
                idx.append(model.dof_indices(sets, directions=directions))
    if M is None:
        raise InputError("Craig-Bampton needs the mass matrix (the model has only K)")
    K = sp.csr_matrix(K)
    M = sp.csr_matrix(M)
    n = K.shape[0]
    if masters is not None:
        idx.append(np.asarray(masters, dtype=np.int64).ravel())
    if not idx or sum(i.size for i in idx) == 0:
        raise InputError("no master DoFs: give interface/active node sets or masters")
    mi = np.unique(np.concatenate(idx))
    if mi.min() < 0 or mi.max() >= n:
        raise InputError(f"master index outside 0..{n - 1}")
    is_master = np.zeros(n, bool)
    is_master[mi] = True
    si = np.nonzero(~is_master)[0]
    if n_modes < 0 or n_modes > si.size - 2:
        raise InputError(f"n_modes = {n_modes}: expected 0..{si.size - 2} "
                         f"(slave DoFs - 2)")

    Kss = K[si][:, si]
    Mss = M[si][:, si]
    Ksm = K[si][:, mi]
    if solver == "frirom":
        rhs = np.asfortranarray((-Ksm).toarray(order="F"))
        lam, phi, psi = eigsh_shift_invert(Kss, Mss, n_modes, sigma=sigma, rhs=rhs, tol=tol,
                                           ncv=ncv, overwrite_rhs=True)
        del rhs
    elif solver == "scipy":
        lam, phi, psi = _scipy_modes_and_statics(Kss, Mss, Ksm, n_modes, sigma, tol, ncv)
    else:
        raise InputError(f"solver must be 'frirom' or 'scipy', got {solver!r}")
    del Ksm
    # Galerkin projection (Eq. 16). K_r is block diagonal: the constraint modes are
    # K-orthogonal to the fixed-interface modes by construction.
    Kmm = K[mi][:, mi].toarray()
    Kms = K[mi][:, si]
    Mmm = M[mi][:, mi].toarray()
    Mms = M[mi][:, si]
    Mss_psi = Mss @ psi                              # (n_s, n_m)
    nm = mi.size
    nr = nm + n_modes
    Kr = np.zeros((nr, nr))
    Mr = np.zeros((nr, nr))
    Kr[:nm, :nm] = Kmm + Kms @ psi
    Kr[nm:, nm:] = np.diag(lam)
    Mms_psi = Mms @ psi
    Mr[:nm, :nm] = Mmm + Mms_psi + Mms_psi.T + psi.T @ Mss_psi
    coupling = (Mms @ phi) + Mss_psi.T @ phi       # (n_m, k)
    Mr[:nm, nm:] = coupling
    Mr[nm:, :nm] = coupling.T
    Mr[nm:, nm:] = np.eye(n_modes)
    Kr = 0.5 * (Kr + Kr.T)
    Mr = 0.5 * (Mr + Mr.T)
    return CraigBampton(K=Kr, M=Mr, master_index=mi, slave_index=si,
                        master_dofs=np.asarray(dofs)[mi], psi=psi, phi=phi, eigenvalues=lam,
                        n_dof=n)


def _scipy_modes_and_statics(Kss, Mss, Ksm, n_modes, sigma, tol, ncv):
    """scipy reference: eigsh in shift-invert mode on a SuperLU factor of K_ss - sigma M_ss
    (the factor eigsh would make itself), reused for the constraint modes when sigma = 0."""

    A = (Kss - sigma * Mss).tocsc() if sigma else Kss.tocsc()
    lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A")
    n = Kss.shape[0]
    if n_modes > 0:
        op = spla.LinearOperator((n, n), matvec=lu.solve, dtype=np.float64)
        lam, phi = spla.eigsh(Kss, k=n_modes, M=Mss, sigma=sigma, OPinv=op, tol=tol,
                              ncv=ncv or default_ncv(n_modes, n))
        order = np.argsort(lam)
        lam, phi = canonical_modes(lam[order], phi[:, order])
    else:
        lam, phi = np.zeros(0), np.zeros((n, 0))
    if sigma:
        lu = spla.splu(Kss.tocsc(), permc_spec="MMD_AT_PLUS_A")
    psi = lu.solve(-Ksm.toarray())
    return lam, phi, psi
