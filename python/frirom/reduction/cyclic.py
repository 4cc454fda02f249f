"""Cyclic symmetry: one sector of a tuned rotor solved for a harmonic index (nodal diameter).

Sector s of an N-sector rotor moves as x_s = Q^s x_0 exp(i k s alpha), alpha = 2 pi / N,
Q the rotation by alpha about the rotor axis. The sector's right (dependent) boundary is the
left boundary of the next sector, so x_right = exp(i k alpha) Q x_left: the projection T(k)
keeps every DoF but the right boundary (y = x without x_right, x = T y) and the sector's
matrices become the Hermitian pair T^H K T, T^H M T (:meth:`CyclicSector.matrices`; a real
form of twice the size is also available). For k = 0 and k = N/2 they are real.

Right-boundary nodes must not be constrained unless their left partner is fully constrained
too (ccx has the same rule for the dependent cyclic surface). DoFs missing from the
matrices (removed by boundary conditions) are zero.

:func:`tran_reduce` reduces the left-boundary DoFs of the projected sector with interface
modes (Tran 2001): the lowest eigenvectors of the boundary-condensed pair. Engine-order
travelling-wave excitation: :meth:`CyclicSector.travelling_wave_load` and
:meth:`CyclicSector.expand`.

Nonlinear forced response of a sector: :func:`sector_modes` gives the modes of one harmonic
index on every sector DoF, :func:`cyclic_model` the :class:`frirom.model.CyclicModel` the
solver takes, with the modes of every index k_h = sign h EO mod N that time harmonic h of
an engine-order EO travelling wave lives on.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.spatial import cKDTree

from .._errors import InputError, NumericalError, ParameterError, SingularMatrixError, SizeError
from ..model import CyclicModel, Damping, SectorModes
from .multistage import cylindrical_frame

__all__ = ["CyclicSector", "cyclic_sector", "axis_rotation", "tran_reduce", "sector_modes",
           "cyclic_model", "needed_indices", "engine_order_loads", "sector_free_bodies",
           "sector_stuck_stiffness", "contact_rows"]


def axis_rotation(angle: float, axis=(0.0, 0.0, 1.0)) -> np.ndarray:
    """(3, 3) rotation by ``angle`` [rad] about ``axis`` (right-hand rule)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    c, s = np.cos(angle), np.sin(angle)
    ax = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return c * np.eye(3) + s * ax + (1 - c) * np.outer(a, a)


@dataclass
class CyclicSector:
    """A sector with matched cyclic boundaries.

    n_dof: size of the sector's matrices; n_sectors: N; left, right: (n_b, 3) model DoF
    indices (global x, y, z; -1 = constrained) of matched boundary nodes, right = left
    rotated by +alpha; axis, origin: the rotor axis; node_pairs: (n_b, 2) optional node ids;
    dependent: 'right' (default) or 'left', the boundary eliminated by the constraint
    (ccx's slave surface), x_right = exp(i k alpha) Q x_left either way.
    """

    n_dof: int
    n_sectors: int
    left: np.ndarray
    right: np.ndarray
    axis: np.ndarray
    origin: np.ndarray
    node_pairs: np.ndarray | None = None
    dependent: str = "right"

    def __post_init__(self):
        self.left = np.asarray(self.left, dtype=np.int64).reshape(-1, 3)
        self.right = np.asarray(self.right, dtype=np.int64).reshape(-1, 3)
        if self.left.shape != self.right.shape:
            raise SizeError(f"CyclicSector: left {self.left.shape} and right "
                            f"{self.right.shape} boundary DoFs differ in shape")
        if self.n_sectors < 2:
            raise InputError(f"CyclicSector: n_sectors must be >= 2, got {self.n_sectors}")
        both = np.concatenate([self.left.ravel(), self.right.ravel()])
        both = both[both >= 0]
        if both.size and both.max() >= self.n_dof:
            raise SizeError(f"CyclicSector: boundary DoF {both.max()} >= n_dof {self.n_dof}")
        if np.unique(both).size != both.size:
            raise InputError("CyclicSector: a DoF is on both boundaries or repeated")
        if self.dependent not in ("right", "left"):
            raise InputError(f"CyclicSector: dependent must be 'right' or 'left', got "
                             f"{self.dependent!r}")
        side = 1 if self.dependent == "right" else 0
        self._dep, self._ind = ((self.right, self.left) if side else (self.left, self.right))
        for p in range(len(self._dep)):
            if np.any(self._dep[p] < 0) and not np.all(self._ind[p] < 0):
                node = "" if self.node_pairs is None else f" (node {self.node_pairs[p, side]})"
                raise InputError(f"CyclicSector: {self.dependent}-boundary pair {p}{node} is "
                                 "constrained but its partner is not: nodes with boundary "
                                 "conditions must not lie on the dependent "
                                 f"({self.dependent}) cyclic surface")
        self.Q = axis_rotation(2 * np.pi / self.n_sectors, self.axis)
        dep = self._dep[self._dep >= 0]
        self.independent = np.setdiff1d(np.arange(self.n_dof), dep)

    @property
    def alpha(self) -> float:
        return 2 * np.pi / self.n_sectors

    @property
    def boundary(self) -> np.ndarray:
        """Indices into the projected DoFs y of the kept (independent) boundary DoFs."""
        ind = self._ind[self._ind >= 0]
        return np.searchsorted(self.independent, np.sort(ind))

    def projection(self, k: int) -> sp.csr_matrix:
        """T(k): (n_dof, n_indep) complex, x = T y with y = x[independent]."""
        n_i = self.independent.size
        col = -np.ones(self.n_dof, dtype=np.int64)
        col[self.independent] = np.arange(n_i)
        dep, ind = self._dep, self._ind
        if self.dependent == "right":
            ph, Qd = np.exp(1j * k * self.alpha), self.Q
        else:
            ph, Qd = np.exp(-1j * k * self.alpha), self.Q.T
        rows = [self.independent]
        cols = [np.arange(n_i)]
        vals = [np.ones(n_i, dtype=complex)]
        for c in range(3):
            for cp in range(3):
                ok = (dep[:, c] >= 0) & (ind[:, cp] >= 0)
                if abs(Qd[c, cp]) < 1e-15 or not ok.any():
                    continue
                rows.append(dep[ok, c])
                cols.append(col[ind[ok, cp]])
                vals.append(np.full(ok.sum(), ph * Qd[c, cp]))
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                     np.concatenate(cols))),
                             shape=(self.n_dof, n_i))

    def matrices(self, K, M, k: int, real: bool = False):
        """Projected pair for harmonic index k: Hermitian (n_indep,)^2, sparse.

        real=True returns the real symmetric form [[Re, -Im], [Im, Re]] of twice the size
        (every eigenvalue doubled) for real-only solvers; for k = 0 and k = N/2 the pair is
        real already and returned once.
        """
        if K.shape != (self.n_dof, self.n_dof) or M.shape != K.shape:
            raise SizeError(f"CyclicSector.matrices: K {K.shape}, M {M.shape}, expected "
                            f"({self.n_dof}, {self.n_dof})")
        T = self.projection(k)
        Kk = (T.conj().T @ sp.csr_matrix(K) @ T).tocsr()
        Mk = (T.conj().T @ sp.csr_matrix(M) @ T).tocsr()
        if self._is_real(k):
            return sp.csr_matrix(Kk.real), sp.csr_matrix(Mk.real)
        if real:
            return _real_form(Kk), _real_form(Mk)
        return Kk, Mk

    def _is_real(self, k: int) -> bool:
        return (k % self.n_sectors) == 0 or (2 * k) % self.n_sectors == 0

    def frequencies(self, K, M, k: int, n_modes: int, sigma: float = 0.0,
                    method: str = "auto") -> np.ndarray:
        """Lowest ``n_modes`` natural frequencies [Hz] of harmonic index k (each once).

        method: 'dense' (LAPACK), 'arpack' (shift-invert about sigma [rad^2/s^2] on the
        sparse Hermitian pair) or 'auto' (dense up to 4000 DoFs).
        """
        Kk, Mk = self.matrices(K, M, k)
        lam = _eigvals(Kk, Mk, n_modes, sigma, method)
        return np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi)

    def travelling_wave_load(self, f0, engine_order: int, sign: int = -1):
        """Sector load of an engine-order travelling wave, f_s = Q^s f0 exp(sign i EO s alpha).

        f0: (n_dof,) complex load on sector 0's DoFs (amplitude and phase per DoF); sign:
        -1 (default, the deck's convention: sector s lags by 2 pi EO s / N, a wave that
        travels forward, in +theta, under Re(. exp(i omega t))) or +1. Returns the harmonic
        index k = sign EO mod N of the response and the projected load T(k)^H f0 (n_indep,).
        The response of sector s follows from :meth:`expand` with the same k.
        """
        f0 = np.asarray(f0)
        if f0.shape != (self.n_dof,):
            raise SizeError(f"travelling_wave_load: f0 must be ({self.n_dof},), got "
                            f"{f0.shape}")
        if sign not in (-1, 1):
            raise InputError(f"travelling_wave_load: sign must be -1 or +1, got {sign}")
        k = (sign * int(engine_order)) % self.n_sectors
        return k, self.projection(k).conj().T @ f0

    def expand(self, y, k: int, sector: int, node_dofs=None) -> np.ndarray:
        """Displacements of sector ``sector`` from the solution y of harmonic index k.

        y: (n_indep,) complex; node_dofs: (n_nodes, 3) DoF indices of the x, y, z
        displacements of the sector's nodes (-1 = constrained), whose components are rotated
        by Q^s (other DoFs, e.g. modal coordinates, only take the phase). Returns (n_dof,)
        complex in the layout of sector 0's DoFs, for the rotated nodes of sector s:
        Q^s x_0 exp(i k s alpha); the physical response is Re(x exp(i omega t)).
        """
        x = (self.projection(k) @ np.asarray(y)) * np.exp(1j * k * sector * self.alpha)
        if node_dofs is None:
            return x
        nd = np.asarray(node_dofs, dtype=np.int64).reshape(-1, 3)
        Qs = np.linalg.matrix_power(self.Q, sector % self.n_sectors)
        v = np.where(nd >= 0, x[np.maximum(nd, 0)], 0.0)
        w = v @ Qs.T
        out = x.copy()
        ok = nd >= 0
        out[nd[ok]] = w[ok]
        return out


def _real_form(A):
    A = sp.csr_matrix(A)
    return sp.bmat([[A.real, -A.imag], [A.imag, A.real]]).tocsr()


def _eigvals(Kk, Mk, n_modes, sigma=0.0, method="auto"):
    n = Kk.shape[0]
    if n_modes < 1 or n_modes > n:
        raise InputError(f"n_modes must lie in 1..{n}, got {n_modes}")
    if method not in ("auto", "dense", "arpack"):
        raise InputError(f"method must be 'auto', 'dense' or 'arpack', got {method!r}")
    if method == "dense" or (method == "auto" and (n <= 4000 or n_modes > n // 4)):
        try:
            return sla.eigh(Kk.toarray(), Mk.toarray(), eigvals_only=True,
                            subset_by_index=[0, n_modes - 1])
        except (np.linalg.LinAlgError, ValueError) as exc:
            raise NumericalError(f"cyclic eigen-solve failed ({exc})") from exc
    try:
        w = spla.eigsh(Kk.tocsc(), k=n_modes, M=Mk.tocsc(), sigma=sigma,
                       return_eigenvectors=False)
    except (RuntimeError, spla.ArpackError) as exc:
        raise NumericalError(f"cyclic eigen-solve (ARPACK shift-invert) failed ({exc})"
                             ) from exc
    return np.sort(w.real)


def cyclic_sector(coords_left, dofs_left, coords_right, dofs_right, n_sectors: int,
                  n_dof: int, origin=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), tol=None,
                  nodes_left=None, nodes_right=None, dependent="right") -> CyclicSector:
    """Match the right-boundary nodes to the left ones rotated by +2 pi / N about the axis.

    coords_*: (n_b, 3) node coordinates; dofs_*: (n_b, 3) model DoF indices of their x, y,
    z displacements (-1 where constrained); dependent: 'right' or 'left' (ccx's slave
    surface), the boundary the constraint eliminates. tol: matching distance (default 1e-6 x the
    largest distance to the axis origin). InputError names the first unmatched node.
    """
    cl = np.asarray(coords_left, float).reshape(-1, 3)
    cr = np.asarray(coords_right, float).reshape(-1, 3)
    if len(cl) != len(cr):
        raise InputError(f"cyclic_sector: {len(cl)} left and {len(cr)} right boundary nodes: "
                         "the cyclic boundaries must have matching meshes")
    o = np.asarray(origin, float)
    Q = axis_rotation(2 * np.pi / n_sectors, axis)
    cylindrical_frame(axis)                        # validates the axis
    if tol is None:
        tol = 1e-6 * max(np.abs(cl - o).max(), np.abs(cr - o).max(), 1e-300)
    rot = (cl - o) @ Q.T + o
    dist, j = cKDTree(cr).query(rot)
    bad = np.nonzero(dist > tol)[0]
    names_l = np.arange(len(cl)) if nodes_left is None else np.asarray(nodes_left)
    names_r = np.arange(len(cr)) if nodes_right is None else np.asarray(nodes_right)
    if bad.size:
        p = int(bad[0])
        raise InputError(f"cyclic_sector: left-boundary node {names_l[p]} rotated by "
                         f"{360.0 / n_sectors:.6g} deg lies {dist[p]:.3g} from the nearest "
                         f"right-boundary node (tolerance {tol:.3g}): boundaries do not match")
    if np.unique(j).size != j.size:
        raise InputError("cyclic_sector: two left nodes map to the same right node")
    pairs = np.column_stack([names_l, names_r[j]])
    return CyclicSector(n_dof=int(n_dof), n_sectors=int(n_sectors),
                        left=np.asarray(dofs_left).reshape(-1, 3),
                        right=np.asarray(dofs_right).reshape(-1, 3)[j],
                        axis=np.asarray(axis, float), origin=o, node_pairs=pairs,
                        dependent=dependent)


def tran_reduce(Kk, Mk, boundary, n_modes: int):
    """Reduce the boundary DoFs of a projected sector with Tran's interface modes.

    Kk, Mk: (n, n) Hermitian pair of one harmonic index (sparse or dense, complex or real);
    boundary: indices (into the projected DoFs) of the remaining cyclic-boundary DoFs;
    n_modes: interface modes kept. The modes are the lowest eigenvectors of the pair
    statically condensed on the boundary (the constraint modes' characteristic modes).
    Returns (K_r, M_r dense (n_modes + n - n_b)^2, R sparse (n, n_r), eigenvalues of the
    condensed pair); x = R x_r with x_r = [interface modal coordinates, other DoFs].
    """
    Ks = sp.csr_matrix(Kk)
    Ms = sp.csr_matrix(Mk)
    n = Ks.shape[0]
    b = np.asarray(boundary, dtype=np.int64).ravel()
    if b.size == 0 or b.min() < 0 or b.max() >= n or np.unique(b).size != b.size:
        raise InputError(f"tran_reduce: boundary must be distinct indices in 0..{n - 1}")
    if not 1 <= n_modes <= b.size:
        raise InputError(f"tran_reduce: n_modes must lie in 1..{b.size}, got {n_modes}")
    s = np.setdiff1d(np.arange(n), b)
    kbb = Ks[b][:, b].toarray()
    mbb = Ms[b][:, b].toarray()
    kbs = Ks[b][:, s]
    if s.size and kbs.nnz:
        try:
            lu = spla.splu(Ks[s][:, s].tocsc())
        except RuntimeError as exc:
            raise SingularMatrixError(f"tran_reduce: interior stiffness singular ({exc})")
        psi = -lu.solve(kbs.conj().T.toarray().astype(Ks.dtype))
        msb = Ms[s][:, b]
        kc = kbb + kbs @ psi
        mc = mbb + msb.conj().T @ psi + psi.conj().T @ msb + psi.conj().T @ (Ms[s][:, s] @ psi)
    else:
        kc, mc = kbb, mbb
    kc = 0.5 * (kc + kc.conj().T)
    mc = 0.5 * (mc + mc.conj().T)
    lam, phi = sla.eigh(kc, mc, subset_by_index=[0, n_modes - 1])
    rr, cc = np.nonzero(phi)
    rows = np.concatenate([b[rr], s])
    cols = np.concatenate([cc, n_modes + np.arange(s.size)])
    vals = np.concatenate([phi[rr, cc], np.ones(s.size)])
    R = sp.csr_matrix((vals, (rows, cols)), shape=(n, n_modes + s.size))
    Kr = (R.conj().T @ Ks @ R).toarray()
    Mr = (R.conj().T @ Ms @ R).toarray()
    return 0.5 * (Kr + Kr.conj().T), 0.5 * (Mr + Mr.conj().T), R, lam


def _ratios(damping, omega):
    """Damping ratios of modes of natural frequencies omega [rad/s]."""
    if damping is None:
        return np.zeros_like(omega)
    if not isinstance(damping, Damping):
        raise ParameterError("damping: expected a frirom.model.Damping or None")
    if damping.kind == "rayleigh":
        return damping.alpha / (2.0 * omega) + damping.beta * omega / 2.0
    if damping.kind == "modal":
        return damping.zeta[np.minimum(np.arange(omega.size), damping.zeta.size - 1)]
    raise ParameterError("damping: a cyclic sector takes modal ratios or Rayleigh damping "
                         "(both diagonal in the modes of every harmonic index), not a "
                         "damping matrix")


def contact_rows(n_dof: int, n_sectors: int, contacts, k: int):
    """(G_k (n_rows, n_dof) complex CSR, Ks (n_rows,)): the contacts' rows at harmonic index
    k, stacked over the groups, where a contact on the next sector (columns n_dof.. of G)
    reads x_1 = exp(i k alpha) x_0, alpha = 2 pi / n_sectors, as the solver does
    (frirom._pack._pack_sector): G_k = G_0 + exp(i k alpha) G_1; and each row's stuck
    stiffness (frirom.contact.stuck_stiffness)."""
    from ..contact import stuck_stiffness
    n = int(n_dof)
    ph = np.exp(2j * np.pi * k / n_sectors)
    rows, ks = [], []
    for g in contacts:
        G = sp.csr_matrix(g.G)
        Gk = G[:, :n].astype(complex)
        if G.shape[1] == 2 * n:
            Gk = Gk + ph * G[:, n:]
        rows.append(Gk)
        ks.append(np.asarray(stuck_stiffness(g.law, g.params), float).ravel())
    if not rows:
        return sp.csr_matrix((0, n), dtype=complex), np.zeros(0)
    return sp.csr_matrix(sp.vstack(rows)), np.concatenate(ks)


def sector_stuck_stiffness(sector: CyclicSector, contacts, k: int) -> sp.csr_matrix:
    """sum G_k^H Ks G_k over ``contacts`` (n_dof, n_dof), complex: the contacts closed
    and stuck at harmonic index k (:func:`contact_rows`)."""
    Gk, ks = contact_rows(sector.n_dof, sector.n_sectors, contacts, k)
    return sp.csr_matrix(Gk.conj().T @ sp.diags(ks) @ Gk)


def _definite(A) -> bool:
    from ..model import _positive_definite
    A = sp.csr_matrix(A)
    if np.iscomplexobj(A.data) and np.abs(A.data.imag).max(initial=0.0) > 0:
        A = _real_form(A)
    return _positive_definite(sp.csr_matrix(A.real))


def sector_free_bodies(sector: CyclicSector, K, M, contacts, indices) -> bool:
    """True when K alone does not hold the sector at one of the harmonic indices
    ``indices`` (a body held only by its contacts: an under-platform damper between this
    sector's platform and the next one's), tested as :meth:`frirom.model.Model.free_bodies`
    (a Cholesky of K_k - sigma M_k, sigma = 1e-10 max|K| / max|M|). SingularMatrixError
    when the contacts, stuck, do not hold it either."""
    K, M = sp.csr_matrix(K), sp.csr_matrix(M)
    kmax = abs(K).max() if K.nnz else 0.0
    sigma = 1e-10 * kmax / (abs(M).max() if M.nnz else 1.0)
    free = False
    for k in indices:
        Kk, Mk = sector.matrices(K, M, k)
        if _definite(Kk - sigma * Mk):
            continue
        free = True
        if not contacts:
            break
        T = sector.projection(k)
        Sk = T.conj().T @ sector_stuck_stiffness(sector, contacts, k) @ T
        if not _definite(Kk + Sk):
            raise SingularMatrixError(
                f"cyclic sector: harmonic index {k} has a rigid-body motion that neither "
                "K nor the contacts (stuck) hold; constrain the sector")
    return free and bool(contacts)


def sector_modes(sector: CyclicSector, K, M, k: int, damping=None, n_modes=None,
                 boundary_modes=None, method: str = "auto",
                 stuck_contacts=None) -> SectorModes:
    """Modes of harmonic index k on every DoF of the sector, with their damping ratios.

    K, M: the sector's (n_dof, n_dof) real matrices; damping: Damping.rayleigh (ratios
    alpha / 2w + beta w / 2) or Damping.modal (zeta[r] for the r-th mode of every index,
    the last ratio for the modes above) or None; n_modes: modes kept (default all of the
    projected pair: the receptances are then exact; fewer truncate them with no residual
    flexibility); boundary_modes: Tran's interface modes for the cyclic boundary (default
    none: the boundary is kept whole); method: 'dense', 'arpack' or 'auto' (dense up to
    4000 coordinates; ARPACK needs n_modes).

    stuck_contacts: ContactGroup list of a sector with a body held only by its contacts
    (:func:`sector_free_bodies`): the modes are then those of the stuck structure, K_k +
    T^H G_k^H Ks G_k T (:func:`sector_stuck_stiffness`), whose stiffness the solver takes
    back off the contact forces (fortran/frirom_hbm_free.f90); Rayleigh ratios then come
    from the diagonal of psi^H (alpha M + beta K) psi, K without the contacts (as the
    modal route of a Model with free bodies).
    """
    Kk, Mk = sector.matrices(K, M, k)
    K0 = Kk
    if stuck_contacts:
        T = sector.projection(k)
        Sk = T.conj().T @ sector_stuck_stiffness(sector, stuck_contacts, k) @ T
        Kk = sp.csr_matrix(Kk + (Sk.real if sector._is_real(k) else Sk))
    n = Kk.shape[0]
    R = None
    if boundary_modes is not None:
        Kr, Mr, R, _ = tran_reduce(Kk, Mk, sector.boundary, int(boundary_modes))
        Kk, Mk = sp.csr_matrix(Kr), sp.csr_matrix(Mr)
        n = Kk.shape[0]
    nm = n if n_modes is None else int(n_modes)
    if not 1 <= nm <= n:
        raise InputError(f"sector_modes: n_modes must lie in 1..{n}, got {nm}")
    if method not in ("auto", "dense", "arpack"):
        raise InputError(f"method must be 'auto', 'dense' or 'arpack', got {method!r}")
    dense = method == "dense" or (method == "auto" and (n <= 4000 or nm > n // 4))
    try:
        if dense:
            Kd, Md = Kk.toarray(), Mk.toarray()
            lam, phi = sla.eigh(0.5 * (Kd + Kd.conj().T), 0.5 * (Md + Md.conj().T),
                                subset_by_index=[0, nm - 1])
        else:
            lam, phi = spla.eigsh(Kk.tocsc(), k=nm, M=Mk.tocsc(), sigma=0.0, which="LM")
            order = np.argsort(lam)
            lam, phi = lam[order].real, phi[:, order]
            phi = phi / np.sqrt(np.einsum("ir,ir->r", phi.conj(), Mk @ phi).real)
    except (np.linalg.LinAlgError, ValueError, RuntimeError, spla.ArpackError) as exc:
        raise NumericalError(f"sector_modes: eigen-solve of harmonic index {k} failed "
                             f"({exc}); is the sector's mass matrix positive definite?"
                             ) from None
    if np.any(lam <= 0):
        raise ParameterError(f"sector_modes: harmonic index {k} has a rigid-body (zero "
                             "frequency) mode; the sector needs supports at every nodal "
                             "diameter")
    if R is not None:
        phi = R @ phi
    psi = sector.projection(k) @ phi
    omega = np.sqrt(lam)
    zeta = _ratios(damping, omega)
    if stuck_contacts and damping is not None and damping.kind == "rayleigh":
        kr = np.einsum("ir,ir->r", phi.conj(), K0 @ phi).real
        zeta = (damping.alpha + damping.beta * kr) / (2.0 * omega)
    return SectorModes(k=int(k) % sector.n_sectors, psi=psi, omega=omega, zeta=zeta)


def engine_order_loads(n_dof: int, dofs, eo: int, n_sectors: int, amplitude: complex,
                       harmonic: int = 1, H: int = 1) -> np.ndarray:
    """Complex loads (n_dof, H+1) [N] of an engine-order travelling wave on a whole rotor.

    ``dofs``: one DoF index per sector (or one list of DoFs per sector, all loaded alike);
    sector s gets amplitude * exp(-i 2 pi eo s / n_sectors) on harmonic ``harmonic``, so
    that f_s(t) = |A| cos(h omega t + arg A - 2 pi eo s / n_sectors): sector s lags sector
    0 by 2 pi eo s / n_sectors (a forward travelling wave for eo > 0).
    """
    F = np.zeros((n_dof, H + 1), complex)
    for s, d in enumerate(dofs):
        phase = np.exp(-2j * np.pi * eo * s / n_sectors)
        for j in np.atleast_1d(d):
            F[int(j), harmonic] += amplitude * phase
    return F


def needed_indices(engine_order: int, n_sectors: int, harmonics: int, sign: int = -1,
                   single_index=None) -> list:
    """Harmonic indices whose modes the harmonics 0..H need, k_h = sign h EO mod N, in the
    order of h, one of each pair k, N - k (complex conjugates); [single_index] alone for the
    one-index approximation."""
    if single_index is not None:
        return [int(single_index) % n_sectors]
    ks = []
    for h in range(harmonics + 1):
        k = (sign * h * int(engine_order)) % n_sectors
        if k not in ks and (-k) % n_sectors not in ks:
            ks.append(k)
    return ks


def cyclic_model(sector: CyclicSector, K, M, contacts, engine_order: int, harmonics: int,
                 damping=None, sign: int = -1, n_modes=None, boundary_modes=None,
                 single_index=None, dof_labels=None) -> CyclicModel:
    """The CyclicModel of a sector under an engine-order travelling wave, harmonics 0..H.

    Computes the modes of every index k_h = sign h EO mod N (h = 0..H; one of k and N - k),
    or of ``single_index`` only (the one-index approximation, see CyclicModel). contacts:
    ContactGroup on the sector's DoFs (or on sector 0 and the next sector, 2 n_dof
    columns); the other arguments as in :func:`sector_modes`.
    """
    if not (isinstance(harmonics, (int, np.integer)) and harmonics >= 0):
        raise ParameterError(f"harmonics: expected an integer >= 0, got {harmonics!r}")
    N = sector.n_sectors
    ks = needed_indices(engine_order, N, harmonics, sign, single_index)
    free = sector_free_bodies(sector, K, M, list(contacts), ks)
    modes = {k: sector_modes(sector, K, M, k, damping, n_modes, boundary_modes,
                             stuck_contacts=list(contacts) if free else None)
             for k in ks}
    return CyclicModel(n_dof=sector.n_dof, n_sectors=N, engine_order=int(engine_order),
                       modes=modes, contacts=list(contacts), sign=sign,
                       single_index=single_index, dof_labels=dof_labels, stuck_modes=free)
