"""Interface reduction of contact DoFs: characteristic constraint and GSI modes (Eq. 14-19).

A matrix pair (K, M) (an FE model, or a Craig-Bampton model whose masters are the interface
and active DoFs) is reduced by replacing its interface DoFs x_i by a few interface modes,
x_i = Phi_ik eta_k (Eq. 14), every other coordinate being kept (Eq. 15, R); the reduced
matrices are R^T K R and R^T M R (Eq. 16).

The interface modes are Gram-Schmidt interface (GSI) modes: the characteristic constraint
(CC) modes of the master partition (Eq. 17-18), whose interface rows Phi_ii (Eq. 19) are
orthonormalised by Gram-Schmidt in the order of increasing eigenvalue. A mixed basis joins
the GSI modes of the *free* interface with those of the *full-stick* interface (each contact
pair tied by springs of its contact stiffnesses in its local frame).

The physical contact elements are described by :class:`ContactPairs`; their local relative
displacements are ``contact_matrix(pairs, n_dof) @ x``. After reduction,
:meth:`InterfaceReduction.contact_matrix` gives G = (local frame x (side A - side B)) @ R, the
map the AFT needs (frirom.model.ContactGroup.G): forces return as G.T @ f.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .._errors import InputError, NumericalError, SingularMatrixError, SizeError
from ..model import ContactGroup
from .eigen import canonical_modes

#: reduced models up to this size are returned as dense matrices, larger ones as CSR
DENSE_LIMIT = 3000

__all__ = ["ContactPairs", "InterfaceReduction", "local_frames", "contact_matrix",
           "stick_stiffness", "guyan_condense", "characteristic_constraint_modes",
           "gram_schmidt", "gsi_basis", "reduce_interface"]


# --------------------------------------------------------------------------------------------
# physical contact pairs
# --------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class ContactPairs:
    """Physical contact elements between two sides of an interface.

    dofs_a: (n_elem, n_comp) int, model DoF indices of the displacement components (global
        x, y, z for a 3-D node) of the side-A point of each element.
    dofs_b: (n_elem, n_comp) int, same for side B; -1 where side B is ground (fixed).
    frames: (n_elem, n_dir, n_comp), local direction d of element e as a unit vector in the
        global components (rows t1[, t2], n for the laws 'jenkins', 'normal1d', 'normal2d').
    stiffness: (n_elem, n_dir) N/m, stick stiffness per local direction (kt[, kt], kn), used
        for the full-stick interface modes.
    """

    dofs_a: np.ndarray
    dofs_b: np.ndarray
    frames: np.ndarray
    stiffness: np.ndarray

    def __post_init__(self):
        a = np.asarray(self.dofs_a, dtype=np.int64)
        b = np.asarray(self.dofs_b, dtype=np.int64)
        fr = np.asarray(self.frames, dtype=float)
        k = np.asarray(self.stiffness, dtype=float)
        if a.ndim == 1:
            a = a[:, None]
        if b.ndim == 1:
            b = b[:, None]
        if fr.ndim == 2:
            fr = fr[:, None, :]
        if k.ndim == 1:
            k = k[:, None]
        if a.shape != b.shape:
            raise SizeError(f"ContactPairs: dofs_a has shape {a.shape} but dofs_b {b.shape}")
        n_elem, n_comp = a.shape
        if fr.ndim != 3 or fr.shape[0] != n_elem or fr.shape[2] != n_comp:
            raise SizeError(f"ContactPairs: frames must be (n_elem={n_elem}, n_dir, "
                            f"n_comp={n_comp}), got {fr.shape}")
        if k.shape != fr.shape[:2]:
            raise SizeError(f"ContactPairs: stiffness must be (n_elem, n_dir) = "
                            f"{fr.shape[:2]}, got {k.shape}")
        if np.any(a < 0):
            raise InputError("ContactPairs: dofs_a must be DoF indices >= 0 (side A cannot "
                             "be ground)")
        if not np.all(np.isfinite(fr)) or not np.all(np.isfinite(k)) or np.any(k < 0):
            raise InputError("ContactPairs: frames must be finite and stiffness finite >= 0")
        object.__setattr__(self, "dofs_a", a)
        object.__setattr__(self, "dofs_b", b)
        object.__setattr__(self, "frames", fr)
        object.__setattr__(self, "stiffness", k)

    @property
    def n_elem(self) -> int:
        return self.dofs_a.shape[0]

    @property
    def n_dir(self) -> int:
        return self.frames.shape[1]

    @property
    def dofs(self) -> np.ndarray:
        """Sorted unique model DoFs touched by the contact elements."""
        d = np.concatenate([self.dofs_a.ravel(), self.dofs_b.ravel()])
        return np.unique(d[d >= 0])


def local_frames(normals: np.ndarray, tangents: np.ndarray | None = None) -> np.ndarray:
    """Right-handed local frames (t1, t2, n) from contact normals, shape (n_elem, 3, 3).

    normals: (n_elem, 3) contact normals (any length); tangents: optional (n_elem, 3) first
    tangential directions (projected on the tangent plane); by default the global axis least
    aligned with the normal. Rows of each frame are t1, t2, n (unit vectors).
    """
    n = np.atleast_2d(np.asarray(normals, dtype=float))
    if n.shape[1] != 3:
        raise SizeError(f"local_frames: normals must be (n_elem, 3), got {n.shape}")
    nn = np.linalg.norm(n, axis=1)
    if np.any(nn <= 0) or not np.all(np.isfinite(nn)):
        raise InputError("local_frames: every normal must be finite and nonzero")
    n = n / nn[:, None]
    if tangents is None:
        t = np.zeros_like(n)
        t[np.arange(len(n)), np.argmin(np.abs(n), axis=1)] = 1.0
    else:
        t = np.atleast_2d(np.asarray(tangents, dtype=float))
        if t.shape != n.shape:
            raise SizeError(f"local_frames: tangents must be {n.shape}, got {t.shape}")
    t = t - np.sum(t * n, axis=1)[:, None] * n
    tn = np.linalg.norm(t, axis=1)
    if np.any(tn < 1e-12):
        raise InputError("local_frames: a tangent is parallel to its normal")
    t1 = t / tn[:, None]
    t2 = np.cross(n, t1)
    return np.stack([t1, t2, n], axis=1)


def contact_matrix(pairs: ContactPairs, n_dof: int) -> sp.csr_matrix:
    """Physical contact map, (n_elem*n_dir, n_dof): row e*n_dir+d = frame_d . (x_A - x_B)."""
    if pairs.dofs.size and pairs.dofs.max() >= n_dof:
        raise SizeError(f"contact pairs reference DoF {pairs.dofs.max()} but the model has "
                        f"{n_dof} DoFs")
    n_elem, n_dir, n_comp = pairs.frames.shape
    rows = np.repeat(np.arange(n_elem * n_dir), n_comp).reshape(n_elem, n_dir, n_comp)
    cols_a = np.broadcast_to(pairs.dofs_a[:, None, :], rows.shape)
    cols_b = np.broadcast_to(pairs.dofs_b[:, None, :], rows.shape)
    keep_b = cols_b >= 0
    r = np.concatenate([rows.ravel(), rows[keep_b]])
    c = np.concatenate([cols_a.ravel(), cols_b[keep_b]])
    v = np.concatenate([pairs.frames.ravel(), -pairs.frames[keep_b]])
    return sp.csr_matrix((v, (r, c)), shape=(n_elem * n_dir, n_dof))


def stick_stiffness(pairs: ContactPairs, n_dof: int) -> sp.csr_matrix:
    """Stiffness of the full-stick springs, G^T diag(k) G, (n_dof, n_dof)."""
    g = contact_matrix(pairs, n_dof)
    return (g.T @ sp.diags(pairs.stiffness.ravel()) @ g).tocsr()


# --------------------------------------------------------------------------------------------
# characteristic constraint modes and Gram-Schmidt
# --------------------------------------------------------------------------------------------

def _as_index(idx, n: int, what: str) -> np.ndarray:
    a = np.asarray(idx, dtype=np.int64).ravel()
    if a.size and (a.min() < 0 or a.max() >= n):
        raise InputError(f"{what}: DoF indices must lie in 0..{n - 1}")
    if np.unique(a).size != a.size:
        raise InputError(f"{what}: repeated DoF indices")
    return a


def _check_pair(K, M):
    if K.shape != M.shape or K.ndim != 2 or K.shape[0] != K.shape[1]:
        raise SizeError(f"K {K.shape} and M {M.shape} must be square of the same size")


def guyan_condense(K, M, masters) -> tuple[np.ndarray, np.ndarray]:
    """Static (Guyan) condensation of (K, M) onto ``masters``: dense (n_m, n_m) pair.

    For a Craig-Bampton model (K_ms = 0) this is exactly its master partition (Eq. 17), so
    the same call serves FE and CB-reduced models; K_ss is factorised (sparse LU) only when
    the coupling K_ms is not zero.
    """
    _check_pair(K, M)
    n = K.shape[0]
    m = _as_index(masters, n, "guyan_condense masters")
    s = np.setdiff1d(np.arange(n), m)
    Ks = sp.csr_matrix(K)
    Ms = sp.csr_matrix(M)
    kmm = Ks[m][:, m].toarray()
    mmm = Ms[m][:, m].toarray()
    if s.size == 0:
        return kmm, mmm
    kms = Ks[m][:, s]
    if kms.nnz == 0 or abs(kms).max() <= 1e-14 * abs(Ks).max():
        return kmm, mmm
    kss = Ks[s][:, s].tocsc()
    try:
        lu = spla.splu(kss)
    except RuntimeError as exc:
        raise SingularMatrixError(f"guyan_condense: K_ss (non-master partition) is singular "
                                  f"({exc}); are the masters enough to restrain the body?"
                                  ) from None
    psi = -lu.solve(kms.T.toarray())              # (n_s, n_m) static constraint modes
    if not np.all(np.isfinite(psi)):
        raise SingularMatrixError("guyan_condense: K_ss is singular (non-finite solve)")
    kc = kmm + (kms @ psi)
    msm = Ms[s][:, m]
    mss = Ms[s][:, s]
    mc = mmm + msm.T @ psi + psi.T @ msm + psi.T @ (mss @ psi)
    kc = 0.5 * (kc + kc.T)
    mc = 0.5 * (mc + mc.T)
    return np.asarray(kc), np.asarray(mc)


def characteristic_constraint_modes(K, M, masters, n_modes: int | None = None):
    """Characteristic constraint modes (Eq. 18): eigenpairs of the master partition.

    Returns (eigenvalues (n,) in (rad/s)^2 ascending, modes (n_m, n) mass-normalised), n =
    n_modes (default all n_m).
    """
    kc, mc = guyan_condense(K, M, masters)
    n_m = kc.shape[0]
    n = n_m if n_modes is None else int(min(max(n_modes, 1), n_m))
    try:
        w, v = sla.eigh(kc, mc, subset_by_index=[0, n - 1])
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise NumericalError(f"characteristic_constraint_modes: eigh failed ({exc}); is M_mm "
                             "positive definite on the masters?") from exc
    return w, v


def gram_schmidt(columns: np.ndarray, n_keep: int, basis: np.ndarray | None = None,
                 tol: float = 1e-8) -> np.ndarray:
    """Orthonormalise ``columns`` in order (classical Gram-Schmidt, twice) into ``basis``.

    Columns whose component orthogonal to the basis is below ``tol`` times their norm (or
    whose norm is negligible against the largest column) are dependent and skipped. Stops
    when ``n_keep`` new vectors were accepted. Returns the new basis (n_rows, n_old + k),
    k <= n_keep.
    """
    c = np.asarray(columns, dtype=float)
    q = np.zeros((c.shape[0], 0)) if basis is None else np.asarray(basis, dtype=float)
    scale = np.max(np.linalg.norm(c, axis=0)) if c.size else 0.0
    count = 0
    cur = q
    for j in range(c.shape[1]):
        if count >= n_keep:
            break
        v = c[:, j].copy()
        nv = np.linalg.norm(v)
        if nv <= 1e-12 * scale:
            continue
        for _ in range(2):
            v -= cur @ (cur.T @ v)
        nr = np.linalg.norm(v)
        if nr <= tol * nv:
            continue
        cur = np.hstack([cur, (v / nr)[:, None]])
        count += 1
    return cur


class _CCModes:
    """Characteristic constraint modes of one condensed pair, computed on demand."""

    def __init__(self, K, M, masters):
        self.kc, self.mc = guyan_condense(K, M, masters)
        self.w = None
        self.v = None

    def first(self, n: int):
        n = min(n, self.kc.shape[0])
        if self.v is None or self.v.shape[1] < n:
            try:
                self.w, self.v = canonical_modes(
                    *sla.eigh(self.kc, self.mc, subset_by_index=[0, n - 1]))
            except (np.linalg.LinAlgError, ValueError) as exc:
                raise NumericalError(f"GSI: eigen-solve of the master partition failed "
                                     f"({exc}); is M_mm positive definite?") from exc
        return self.w[:n], self.v[:, :n]


def _gsi_stream(cc: _CCModes, rows, n_keep, basis, tol):
    """Accept n_keep new GSI vectors from the CC modes, in eigenvalue order."""
    n_m = cc.kc.shape[0]
    start = 0 if basis is None else basis.shape[1]
    n_eig = min(n_m, max(4 * (n_keep + start) + 20, 60))
    while True:
        w, v = cc.first(n_eig)
        q = gram_schmidt(v[rows, :], n_keep, basis, tol)
        if q.shape[1] - start >= n_keep or n_eig == n_m:
            break
        n_eig = min(n_m, 2 * n_eig)
    if q.shape[1] - start < n_keep:
        raise InputError(f"GSI: only {q.shape[1] - start} independent interface modes "
                         f"could be added, {n_keep} were requested")
    return q, w


def gsi_basis(K, M, interface, active=(), pairs: ContactPairs | None = None,
              n_free: int = 10, n_stick: int = 0, groups=None, tol: float = 1e-8):
    """GSI interface modes: mixed basis of ``n_free`` free and ``n_stick`` full-stick modes.

    K, M: (n, n) matrices (sparse or dense); interface: (n_i,) model DoFs to reduce; active:
    other master DoFs (kept physical, but part of the CC eigenproblem); pairs: the contact
    elements, all tied for the full-stick modes (needed when n_stick > 0; their DoFs must be
    interface DoFs, or active ones: a joint kept physical); groups: optional
    list of index arrays into ``interface`` (e.g. side A and side B of a joint, Eq. 14 per
    component): each group gets its own orthonormal modes, n_free + n_stick per group.

    Returns (basis (n_i, n_k) with orthonormal columns, info dict with the CC eigenvalues of
    the free and stick master partitions and the per-group mode counts).
    """
    _check_pair(K, M)
    n = K.shape[0]
    i = _as_index(interface, n, "gsi_basis interface")
    a = _as_index(active, n, "gsi_basis active")
    if np.intersect1d(i, a).size:
        raise InputError("gsi_basis: interface and active DoFs overlap")
    masters = np.concatenate([i, a])
    if groups is None:
        groups = [np.arange(i.size)]
    groups = [_as_index(g, i.size, "gsi_basis group") for g in groups]
    allg = np.concatenate(groups)
    if np.unique(allg).size != i.size or allg.size != i.size:
        raise InputError("gsi_basis: groups must partition the interface rows exactly once")
    if n_free < 0 or n_stick < 0 or n_free + n_stick == 0:
        raise InputError("gsi_basis: n_free, n_stick must be >= 0 and not both zero")
    Kstick = None
    if n_stick > 0:
        if pairs is None:
            raise InputError("gsi_basis: n_stick > 0 needs the contact pairs")
        outside = np.setdiff1d(pairs.dofs, masters)
        if outside.size:
            raise InputError(f"gsi_basis: contact DoFs {outside[:5].tolist()}... are not "
                             "interface DoFs (nor active ones)")
        Kstick = sp.csr_matrix(K) + stick_stiffness(pairs, n)
    basis = np.zeros((i.size, 0))
    info = {"eig_free": None, "eig_stick": None, "groups": []}
    cc_free = _CCModes(K, M, masters) if n_free else None
    cc_stick = _CCModes(Kstick, M, masters) if n_stick else None
    for g in groups:
        q = None
        if n_free:
            q, w = _gsi_stream(cc_free, g, n_free, None, tol)
            info["eig_free"] = w
        if n_stick:
            q, w = _gsi_stream(cc_stick, g, n_stick, q, tol)
            info["eig_stick"] = w
        block = np.zeros((i.size, q.shape[1]))
        block[g] = q
        basis = np.hstack([basis, block])
        info["groups"].append(q.shape[1])
    return basis, info


# --------------------------------------------------------------------------------------------
# the reduced model
# --------------------------------------------------------------------------------------------

@dataclass
class InterfaceReduction:
    """A model whose interface DoFs were replaced by interface modes (Eq. 15-16).

    Reduced coordinates x_r = [eta_k (n_k), x_kept (n - n_i)]; x = R @ x_r.
    K, M: (n_r, n_r) reduced matrices (dense up to DENSE_LIMIT, else CSR); R: (n, n_r)
    sparse; interface: (n_i,) reduced DoFs; basis: (n_i, n_k) interface modes; kept: the
    other model DoFs in their order; labels: one label per reduced coordinate.
    """

    K: np.ndarray
    M: np.ndarray
    R: sp.csr_matrix
    interface: np.ndarray
    basis: np.ndarray
    kept: np.ndarray
    labels: list = field(default_factory=list)

    @property
    def n_modes(self) -> int:
        return self.basis.shape[1]

    def contact_matrix(self, pairs: ContactPairs) -> sp.csr_matrix:
        """G in reduced coordinates: local frame x (side A - side B) x R, (n_elem*n_dir, n_r)."""
        g = contact_matrix(pairs, self.R.shape[0]) @ self.R
        return sp.csr_matrix(g)

    def contact_group(self, pairs: ContactPairs, law: str, params, w0=None, name: str = ""):
        """frirom.model.ContactGroup of the physical elements on the reduced coordinates."""
        return ContactGroup(law=law, G=self.contact_matrix(pairs), params=params, w0=w0,
                            name=name)

    def expand(self, x_r: np.ndarray) -> np.ndarray:
        """Physical DoFs from reduced coordinates (n_r, ...) -> (n, ...)."""
        return self.R @ x_r

    def project(self, f: np.ndarray) -> np.ndarray:
        """Reduced load R^T f from a physical load (n, ...) -> (n_r, ...)."""
        return self.R.T @ f


def reduce_interface(K, M, interface, basis: np.ndarray, labels=None,
                     mode_labels=None) -> InterfaceReduction:
    """Replace the ``interface`` DoFs of (K, M) by ``basis`` (n_i, n_k) (Eq. 14-16).

    The reduced K, M are dense up to DENSE_LIMIT coordinates (CB models), sparse CSR above
    (an FE model whose interface alone is reduced keeps its sparsity).
    """
    _check_pair(K, M)
    n = K.shape[0]
    i = _as_index(interface, n, "reduce_interface interface")
    phi = np.asarray(basis, dtype=float)
    if phi.ndim != 2 or phi.shape[0] != i.size:
        raise SizeError(f"reduce_interface: basis must be (n_i={i.size}, n_k), got "
                        f"{phi.shape}")
    if not np.all(np.isfinite(phi)):
        raise InputError("reduce_interface: basis has non-finite entries")
    n_k = phi.shape[1]
    kept = np.setdiff1d(np.arange(n), i)
    # R = [[Phi_ik, 0], [0, I]] in the model's DoF order
    rr, cc = np.nonzero(phi)
    rows = np.concatenate([i[rr], kept])
    cols = np.concatenate([cc, n_k + np.arange(kept.size)])
    vals = np.concatenate([phi[rr, cc], np.ones(kept.size)])
    R = sp.csr_matrix((vals, (rows, cols)), shape=(n, n_k + kept.size))
    Ks = sp.csr_matrix(K)
    Ms = sp.csr_matrix(M)
    Kr = (R.T @ Ks @ R).tocsr()
    Mr = (R.T @ Ms @ R).tocsr()
    Kr = 0.5 * (Kr + Kr.T)
    Mr = 0.5 * (Mr + Mr.T)
    if Kr.shape[0] <= DENSE_LIMIT:
        Kr, Mr = Kr.toarray(), Mr.toarray()
    else:
        Kr, Mr = Kr.tocsr(), Mr.tocsr()
    if mode_labels is None:
        mode_labels = [f"interface mode {j + 1}" for j in range(n_k)]
    if labels is None:
        kept_labels = [f"dof {d}" for d in kept]
    else:
        if len(labels) != n:
            raise SizeError(f"reduce_interface: {len(labels)} labels for {n} DoFs")
        kept_labels = [labels[d] for d in kept]
    return InterfaceReduction(K=Kr, M=Mr, R=R, interface=i, basis=phi, kept=kept,
                              labels=list(mode_labels) + kept_labels)
