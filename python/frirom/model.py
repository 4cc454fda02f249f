"""The structural model the solver works on: matrices, damping, contacts and excitation.

Units are the user's (consistent SI recommended: N, m, kg, s). Every check raises a
:class:`frirom.InputError` subclass naming the field and what was expected.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ._errors import (NonFiniteError, ParameterError, SingularMatrixError, SizeError,
                      as_floats)
from .contact import LAWS
from .reduction.damping import modal_damping

def _as_matrix(a, name: str, n: int | None = None) -> sp.csr_matrix:
    """A square real matrix as CSR, checked for shape and finite values."""
    try:
        m = sp.csr_matrix(a)
        if np.iscomplexobj(m.data):
            if np.any(m.data.imag != 0):
                raise ParameterError(f"{name}: expected a real matrix, got complex entries "
                                     f"(max |imag| = {abs(m.data.imag).max():.3g})")
            m = m.real
        m = sp.csr_matrix(m, dtype=float)
    except (TypeError, ValueError) as exc:
        if isinstance(exc, ParameterError):
            raise
        raise ParameterError(f"{name}: expected a real square matrix ({exc})") from None
    if m.ndim != 2 or m.shape[0] != m.shape[1]:
        raise SizeError(f"{name}: expected a square matrix, got shape {m.shape}")
    if n is not None and m.shape[0] != n:
        raise SizeError(f"{name}: expected shape ({n}, {n}), got {m.shape}")
    if not np.all(np.isfinite(m.data)):
        raise NonFiniteError(f"{name}: contains NaN or Inf")
    m.sum_duplicates()
    m.eliminate_zeros()
    return m


def _check_symmetric(m: sp.csr_matrix, name: str) -> None:
    scale = abs(m).max() if m.nnz else 0.0
    if m.nnz and abs(m - m.T).max() > 1e-10 * scale:
        raise ParameterError(f"{name}: must be symmetric (max |A - A^T| = "
                             f"{abs(m - m.T).max():.3g}, max |A| = {scale:.3g})")


#: Largest matrix checked by a dense Cholesky; larger ones by a sparse LU with diagonal
#: pivots (its pivots are the LDL^T ones: all positive if and only if the matrix is
#: positive definite).
DENSE_CHECK = 2000


def _positive_definite(A: sp.csr_matrix) -> bool:
    """True if the symmetric A is numerically positive definite."""
    if A.shape[0] == 0:
        return True
    if A.shape[0] <= DENSE_CHECK:
        try:
            np.linalg.cholesky(A.toarray())
            return True
        except np.linalg.LinAlgError:
            return False
    import scipy.sparse.linalg as spla
    try:
        lu = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError:           # an exactly zero pivot
        return False
    return bool(np.array_equal(lu.perm_r, lu.perm_c) and np.all(lu.U.diagonal() > 0))


def null_motions(K, M, rtol: float = 1e-9, n_max: int = 6):
    """(lam (m,), phi (n, m)): the motions K does not hold, K phi = lam M phi with lam <=
    rtol max|K| / max|M| (at most ``n_max``, M-orthonormal); dense below
    :data:`DENSE_CHECK` DoFs, else shift-invert Lanczos about a small negative shift."""
    import scipy.linalg as sla
    K, M = sp.csr_matrix(K), sp.csr_matrix(M)
    n = K.shape[0]
    scale = (abs(K).max() if K.nnz else 1.0) / (abs(M).max() if M.nnz else 1.0)
    k = min(n_max, n)
    if n <= DENSE_CHECK:
        lam, phi = sla.eigh(K.toarray(), M.toarray(), subset_by_index=[0, k - 1])
    else:
        import scipy.sparse.linalg as spla
        lam, phi = spla.eigsh(K.tocsc(), k=min(k, n - 2), M=M.tocsc(),
                              sigma=-1e-6 * scale, which="LM")
        order = np.argsort(lam)
        lam, phi = lam[order], phi[:, order]
    keep = lam <= rtol * scale
    return lam[keep], phi[:, keep]


def describe_motion(phi, labels=None, share: float = 0.2, n_names: int = 8) -> str:
    """The DoFs a motion ``phi`` (n,) moves: those above ``share`` of its largest, by label
    (``dof j`` without), and, with "NAME:DIR" labels, its share per direction."""
    phi = np.asarray(phi, float)
    a = np.abs(phi)
    idx = np.flatnonzero(a >= share * a.max())
    names = [labels[i] if labels else f"dof {i}" for i in idx]
    text = ", ".join(names[:n_names]) + (f" and {len(names) - n_names} more"
                                         if len(names) > n_names else "")
    if labels and all(":" in str(lab) for lab in labels):
        per = {}
        for lab, v in zip(labels, phi):
            d = str(lab).rsplit(":", 1)[1]
            per[d] = per.get(d, 0.0) + v * v
        tot = sum(per.values()) or 1.0
        dirs = ", ".join(f"{d} {np.sqrt(v / tot):.2f}" for d, v in
                         sorted(per.items(), key=lambda kv: -kv[1]) if v > 1e-6 * tot)
        text += f" (directions: {dirs})"
    return text


def check_definite(K: sp.csr_matrix, M: sp.csr_matrix, k_name: str = "K",
                   m_name: str = "M", contacts=(), labels=None) -> None:
    """M positive definite and K positive semi-definite and, with the contacts tied
    (each row of their G a spring of K's largest stiffness), not singular.

    Checked by a Cholesky of M, of K + sigma M with sigma = 1e-6 max|K| / max|M| (an
    eigenvalue of K below about -1e-6 max|K| max|M|^-1 min eig(M) fails it) and of K with
    the contacts tied. ParameterError (SingularMatrixError for the last) names the matrix,
    and for the last the DoFs of each free motion (``labels``: one per DoF).
    """
    if not _positive_definite(M):
        raise ParameterError(f"{m_name}: expected a positive definite mass matrix "
                             "(its Cholesky factorisation fails)")
    kmax = abs(K).max() if K.nnz else 0.0
    mmax = abs(M).max() if M.nnz else 1.0
    if kmax == 0.0:
        return
    if not _positive_definite((K + (1e-6 * kmax / mmax) * M).tocsr()):
        raise ParameterError(f"{k_name}: expected a positive semi-definite stiffness "
                             f"matrix (the Cholesky factorisation of K + sigma M, sigma = "
                             f"1e-6 max|K|/max|M|, fails: K has a negative eigenvalue)")
    tied = K
    for G in contacts:
        tied = tied + kmax * (G.T @ G)
    if not _positive_definite(sp.csr_matrix(tied)):
        try:
            _, phi = null_motions(tied, M)
        except (np.linalg.LinAlgError, ValueError, RuntimeError):
            phi = np.zeros((K.shape[0], 0))
        which = "; ".join(f"motion {j + 1} moves {describe_motion(phi[:, j], labels)}"
                          for j in range(phi.shape[1]))
        raise SingularMatrixError(
            f"{k_name}: singular stiffness matrix: a rigid-body motion that no contact "
            "holds (its Cholesky factorisation fails with the contacts tied); the static "
            "harmonic cannot be solved: constrain the structure"
            + (f" ({phi.shape[1]} free motion{'s' if phi.shape[1] > 1 else ''}: {which})"
               if phi.shape[1] else ""))


@dataclass
class Damping:
    """Linear viscous damping: a matrix C, Rayleigh C = alpha M + beta K, or modal
    damping ratios zeta (one per mode, lowest modes first; C = M Phi diag(2 zeta w) Phi^T M
    over those modes, Phi mass-normalised).

    Build with :meth:`matrix`, :meth:`rayleigh` or :meth:`modal`.
    """

    kind: str
    C: object = None
    alpha: float = 0.0
    beta: float = 0.0
    zeta: np.ndarray | None = None

    @classmethod
    def matrix(cls, C) -> "Damping":
        return cls("matrix", C=C)

    @classmethod
    def rayleigh(cls, alpha: float = 0.0, beta: float = 0.0) -> "Damping":
        """C = alpha M + beta K; alpha in 1/s, beta in s, both >= 0."""
        for nm, v in (("alpha", alpha), ("beta", beta)):
            if not np.isfinite(v) or v < 0:
                raise ParameterError(f"damping.{nm}: expected a finite value >= 0, got {v}")
        return cls("rayleigh", alpha=float(alpha), beta=float(beta))

    @classmethod
    def modal(cls, zeta) -> "Damping":
        """zeta: (n_modes,) damping ratios in [0, 1) of the lowest n_modes modes."""
        z = np.atleast_1d(np.asarray(zeta, dtype=float))
        if z.ndim != 1 or z.size == 0:
            raise SizeError("damping.zeta: expected a 1-D array of ratios, one per mode")
        if not np.all(np.isfinite(z)) or np.any(z < 0) or np.any(z >= 1):
            raise ParameterError("damping.zeta: ratios must be finite and in [0, 1)")
        return cls("modal", zeta=z)

    def assemble(self, M: sp.csr_matrix, K: sp.csr_matrix) -> sp.csr_matrix:
        """The damping matrix C for these M and K."""
        n = M.shape[0]
        if self.kind == "matrix":
            C = _as_matrix(self.C, "damping.C", n)
            _check_symmetric(C, "damping.C")
            return C
        if self.kind == "rayleigh":
            return (self.alpha * M + self.beta * K).tocsr()
        if self.kind == "modal":
            nm = self.zeta.size
            if nm > n:
                raise SizeError(f"damping.zeta: {nm} ratios for a model with {n} DoFs")
            return sp.csr_matrix(modal_damping(K, M, self.zeta, n_modes=nm)[0])
        raise ParameterError(f"damping.kind: unknown kind {self.kind!r}")


@dataclass
class ContactGroup:
    """Contact elements sharing one law.

    G: (n_elem*n_dir, n_dof) sparse; row e*n_dir + d gives local relative displacement d of
    element e from the model's coordinates. params: (n_elem, n_par) in the law's order
    (see :data:`frirom.contact.LAWS`). w0: (n_elem, n_slider) initial slider positions or
    None (zeros). patch: the contact patch's extent [m] along the tangents (one number, or
    one per tangential direction) for :func:`frirom.held.patch_warnings`; None: unknown.
    """

    law: str
    G: object
    params: np.ndarray
    w0: np.ndarray | None = None
    name: str = "contact"
    patch: object = None

    def __post_init__(self):
        from .laws import UserLaw, register
        if isinstance(self.law, UserLaw):
            self.law = register(self.law)
        if self.law not in LAWS:
            raise ParameterError(f"contact {self.name!r}: law {self.law!r} unknown; expected "
                                 f"one of {sorted(LAWS)}")
        law = LAWS[self.law]
        ndir, names, nsl = law.n_dir, law.parameters, law.n_slider
        try:
            self.G = sp.csr_matrix(self.G, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"contact {self.name!r}: G is not a matrix ({exc})") from None
        if self.G.shape[0] % ndir:
            raise SizeError(f"contact {self.name!r}: G has {self.G.shape[0]} rows, not a "
                            f"multiple of the {ndir} directions of law {self.law!r}")
        ne = self.G.shape[0] // ndir
        if ne == 0:
            raise SizeError(f"contact {self.name!r}: no element (G has no rows)")
        if not np.all(np.isfinite(self.G.data)):
            raise NonFiniteError(f"contact {self.name!r}: G contains NaN or Inf")
        p = as_floats(f"contact {self.name!r}: params {names}", self.params)
        if p.ndim == 1 and p.size == len(names):
            p = np.tile(p, (ne, 1))
        if p.shape != (ne, len(names)):
            raise SizeError(f"contact {self.name!r}: params must have shape ({ne}, "
                            f"{len(names)}) for columns {names}, got {p.shape}")
        if not np.all(np.isfinite(p)):
            raise NonFiniteError(f"contact {self.name!r}: params contain NaN or Inf")
        col = dict(zip(names, p.T))
        for nm in ("kt", "kn"):
            if nm in col and np.any(col[nm] <= 0):
                raise ParameterError(f"contact {self.name!r}: {nm} must be > 0 (N/m)")
        if "mu" in col and np.any(col["mu"] < 0):
            raise ParameterError(f"contact {self.name!r}: mu must be >= 0")
        if "fn0" in col and np.any(col["fn0"] < 0):
            raise ParameterError(f"contact {self.name!r}: fn0 must be >= 0 (N)")
        if "k1" in col and np.any(col["k1"] < 0):
            raise ParameterError(f"contact {self.name!r}: k1 must be >= 0 (N/m)")
        self.params = p
        if self.w0 is None:
            self.w0 = np.zeros((ne, nsl))
        else:
            w0 = as_floats(f"contact {self.name!r}: w0", self.w0)
            if w0.shape != (ne, nsl):
                raise SizeError(f"contact {self.name!r}: w0 must have shape ({ne}, {nsl}), "
                                f"got {w0.shape}")
            if not np.all(np.isfinite(w0)):
                raise NonFiniteError(f"contact {self.name!r}: w0 contains NaN or Inf")
            self.w0 = w0

    @property
    def n_dir(self) -> int:
        return LAWS[self.law].n_dir

    @property
    def n_elem(self) -> int:
        return self.G.shape[0] // self.n_dir


@dataclass
class Model:
    """M x'' + C x' + K x + sum_g G_g^T f_g(G_g x) = f_e(t).

    M, K: (n_dof, n_dof) sparse or dense, symmetric, M positive definite; damping: Damping;
    contacts: list of ContactGroup; dof_labels: optional names of the DoFs.
    """

    M: object
    K: object
    damping: Damping = field(default_factory=lambda: Damping.rayleigh(0.0, 0.0))
    contacts: list = field(default_factory=list)
    dof_labels: list | None = None

    def __post_init__(self):
        self.M = _as_matrix(self.M, "M")
        n = self.M.shape[0]
        self.K = _as_matrix(self.K, "K", n)
        _check_symmetric(self.M, "M")
        _check_symmetric(self.K, "K")
        d = self.M.diagonal()
        if np.any(d <= 0):
            raise ParameterError(f"M: diagonal entry {int(np.argmin(d))} is {d.min():.3g}; "
                                 "a mass matrix must be positive definite")
        if not isinstance(self.damping, Damping):
            raise ParameterError("damping: expected a frirom.model.Damping")
        self.C = self.damping.assemble(self.M, self.K)
        if not isinstance(self.contacts, (list, tuple)):
            raise ParameterError("contacts: expected a list of ContactGroup")
        for g in self.contacts:
            if not isinstance(g, ContactGroup):
                raise ParameterError("contacts: every entry must be a ContactGroup")
            if g.G.shape[1] != n:
                raise SizeError(f"contact {g.name!r}: G has {g.G.shape[1]} columns, the "
                                f"model has {n} DoFs")
        check_definite(self.K, self.M, contacts=[g.G for g in self.contacts])
        if self.dof_labels is not None and len(self.dof_labels) != n:
            raise SizeError(f"dof_labels: {len(self.dof_labels)} labels for {n} DoFs")

    @property
    def n_dof(self) -> int:
        return self.M.shape[0]

    def free_bodies(self) -> bool:
        """True when K alone does not hold the structure: a body held only by its
        contacts (check_definite has checked that the contacts, tied, hold it). Tested
        by a Cholesky of K - sigma M, sigma = 1e-10 max|K| / max|M|: a zero eigenvalue
        fails it, and so would a mount 1e-5 times softer than the stiffest mode (the
        solver's regularisation is exact, so the few such models lose nothing)."""
        if getattr(self, "_free", None) is None:
            kmax = abs(self.K).max() if self.K.nnz else 0.0
            mmax = abs(self.M).max() if self.M.nnz else 1.0
            self._free = bool(self.contacts) and kmax > 0 and not _positive_definite(
                (self.K - (1e-10 * kmax / mmax) * self.M).tocsr())
        return self._free

    def stuck_stiffness(self) -> sp.csr_matrix:
        """G^T Ks G of every contact group: their stiffness closed and stuck
        (frirom.contact.stuck_stiffness), the stiffness K + G^T Ks G of a structure with
        free bodies the solver factorises."""
        from .contact import stuck_stiffness
        n = self.n_dof
        out = sp.csr_matrix((n, n))
        for g in self.contacts:
            ks = stuck_stiffness(g.law, g.params).ravel()
            G = sp.csr_matrix(g.G)
            out = out + (G.T @ sp.diags(ks) @ G)
        return sp.csr_matrix(out)

    def nonlinear_dofs(self) -> np.ndarray:
        """Sorted DoFs in the column support of all contact G (0-based)."""
        cols = [np.unique(g.G.indices) for g in self.contacts]
        if not cols:
            return np.zeros(0, dtype=int)
        return np.unique(np.concatenate(cols))


@dataclass
class Excitation:
    """f_e(t) = Re sum_h F[:, h] exp(i h omega t); F complex (n_dof, H_F + 1), column 0 a
    real static load (preload). Harmonics above the solver's H are ignored (with a check
    that they are zero), missing ones are zero."""

    F: np.ndarray

    def __post_init__(self):
        F = np.asarray(self.F)
        if F.ndim == 1:
            F = np.stack([np.zeros_like(F), F], axis=1)
        if F.ndim != 2 or F.shape[1] < 1:
            raise SizeError(f"excitation.F: expected (n_dof, H+1), got shape {F.shape}")
        F = F.astype(complex)
        if not np.all(np.isfinite(F)):
            raise NonFiniteError("excitation.F: contains NaN or Inf")
        if np.any(F[:, 0].imag != 0):
            raise ParameterError("excitation.F: column 0 is the static load and must be real")
        self.F = F

    def real_harmonic(self, n_dof: int, H: int) -> np.ndarray:
        """(n_dof, 2H+1) real harmonic coefficients [a0, a1, b1, ...] of f_e."""
        if self.F.shape[0] != n_dof:
            raise SizeError(f"excitation.F: {self.F.shape[0]} rows for a model with {n_dof} "
                            "DoFs")
        if self.F.shape[1] > H + 1 and np.any(self.F[:, H + 1:] != 0):
            raise ParameterError(f"excitation.F: harmonics above H = {H} are nonzero; raise "
                                 "the solver's harmonics")
        out = np.zeros((n_dof, 2 * H + 1))
        out[:, 0] = self.F[:, 0].real
        for h in range(1, min(H, self.F.shape[1] - 1) + 1):
            out[:, 2 * h - 1] = self.F[:, h].real
            out[:, 2 * h] = -self.F[:, h].imag
        return out


@dataclass
class SectorModes:
    """Modes of one harmonic index (nodal diameter) k of a tuned cyclic sector.

    psi: (n_dof, n_modes) complex, the mode shapes on every DoF of the sector (dependent
    cyclic boundary included), normalised so that psi^H M_k psi = I over the sector;
    omega: (n_modes,) natural frequencies [rad/s], > 0; zeta: (n_modes,) damping ratios.
    For k = 0 and k = N/2 the shapes are real (stored complex).
    """

    k: int
    psi: np.ndarray
    omega: np.ndarray
    zeta: np.ndarray

    def __post_init__(self):
        self.psi = np.asarray(self.psi, dtype=complex)
        self.omega = np.asarray(self.omega, dtype=float).ravel()
        self.zeta = np.asarray(self.zeta, dtype=float).ravel()
        nm = self.omega.size
        if self.psi.ndim != 2 or self.psi.shape[1] != nm or self.zeta.size != nm or nm == 0:
            raise SizeError(f"modes of harmonic index {self.k}: psi (n_dof, n_modes), omega "
                            f"and zeta (n_modes,) expected, got {self.psi.shape}, {nm}, "
                            f"{self.zeta.size}")
        if not (np.all(np.isfinite(self.psi)) and np.all(np.isfinite(self.omega))
                and np.all(np.isfinite(self.zeta))):
            raise NonFiniteError(f"modes of harmonic index {self.k}: NaN or Inf")
        if np.any(self.omega <= 0):
            raise ParameterError(f"modes of harmonic index {self.k}: a natural frequency is "
                                 f"{self.omega.min():.3g} rad/s; the sector needs supports "
                                 "that remove rigid-body motion at every nodal diameter")
        if np.any(self.zeta < 0):
            raise ParameterError(f"modes of harmonic index {self.k}: damping ratios must be "
                                 ">= 0")


@dataclass
class CyclicModel:
    """A tuned rotor of N identical sectors under an engine-order travelling wave, solved on
    sector 0 (the harmonic balance is exact for the rotor's travelling-wave response).

    Time harmonic h of the response lives on harmonic index (nodal diameter)
    k_h = sign h EO mod N: sector s moves as x_s^h = Q^s x_0^h exp(i k_h s 2 pi / N). The
    linear part of every harmonic comes from the modes of its own k_h (``modes``, one
    :class:`SectorModes` per k in 0..N-1 needed; k and N - k are complex conjugates, so
    only one of them need be given). ``single_index`` = k* instead uses k* for every
    harmonic, static one included: the shortcut of a ROM built for one harmonic index, an
    approximation that is exact only when the solution has one harmonic on that index.

    n_dof: sector DoFs (the rows of every psi); n_sectors: N; engine_order: EO;
    sign: -1 (the deck's convention: sector s lags sector 0 by 2 pi EO s / N, so
    k_h = -h EO mod N) or +1; contacts: ContactGroup whose G has n_dof columns (DoFs of
    sector 0) or 2 n_dof (sector 0, then the next sector s = 1 in its own frame, i.e. the
    same DoF numbering rotated with the sector: a contact between neighbouring sectors
    such as a shroud or an underplatform damper; its rotation into sector 0's frame is
    part of G). Excitation and outputs are sector 0's DoFs.
    """

    n_dof: int
    n_sectors: int
    engine_order: int
    modes: dict
    contacts: list = field(default_factory=list)
    sign: int = -1
    single_index: int | None = None
    dof_labels: list | None = None

    def __post_init__(self):
        n, N = int(self.n_dof), int(self.n_sectors)
        if N < 2:
            raise ParameterError(f"cyclic model: n_sectors must be >= 2, got {N}")
        if self.sign not in (-1, 1):
            raise ParameterError(f"cyclic model: sign must be -1 or +1, got {self.sign}")
        if self.single_index is not None and not 0 <= int(self.single_index) < N:
            raise ParameterError(f"cyclic model: single_index must lie in 0..{N - 1}, got "
                                 f"{self.single_index}")
        for k, m in self.modes.items():
            if not isinstance(m, SectorModes):
                raise ParameterError("cyclic model: modes must map k to SectorModes")
            if m.psi.shape[0] != n:
                raise SizeError(f"cyclic model: modes of harmonic index {k} have "
                                f"{m.psi.shape[0]} rows, the sector has {n} DoFs")
        if not isinstance(self.contacts, (list, tuple)) or not self.contacts:
            raise ParameterError("cyclic model: at least one ContactGroup is needed")
        for g in self.contacts:
            if not isinstance(g, ContactGroup):
                raise ParameterError("contacts: every entry must be a ContactGroup")
            if g.G.shape[1] not in (n, 2 * n):
                raise SizeError(f"contact {g.name!r}: G has {g.G.shape[1]} columns; a cyclic "
                                f"sector of {n} DoFs needs {n} (sector 0) or {2 * n} (sector "
                                "0, then the next sector)")
        if self.dof_labels is not None and len(self.dof_labels) != n:
            raise SizeError(f"dof_labels: {len(self.dof_labels)} labels for {n} DoFs")
        self.n_dof, self.n_sectors = n, N

    def harmonic_index(self, h: int) -> int:
        """The nodal diameter k_h (0..N-1) time harmonic h lives on."""
        if self.single_index is not None:
            return int(self.single_index)
        return (self.sign * int(h) * int(self.engine_order)) % self.n_sectors

    def modes_of(self, k: int) -> SectorModes:
        """SectorModes of index k, from those of N - k (complex conjugate) if needed."""
        k %= self.n_sectors
        if k in self.modes:
            return self.modes[k]
        kc = (-k) % self.n_sectors
        if kc in self.modes:
            m = self.modes[kc]
            return SectorModes(k, m.psi.conj(), m.omega, m.zeta)
        raise ParameterError(f"cyclic model: no modes of harmonic index {k} (nor "
                             f"{kc}); they are needed for time harmonics h with "
                             f"k_h = {k}")

    def indices(self, H: int) -> list:
        """k_h for h = 0..H."""
        return [self.harmonic_index(h) for h in range(H + 1)]

    def nonlinear_dofs(self) -> np.ndarray:
        """Sorted sector DoFs in the column support of all contact G (0-based; a column of
        the next sector's block counts as the same DoF of sector 0)."""
        cols = [np.unique(g.G.indices) % self.n_dof for g in self.contacts]
        return np.unique(np.concatenate(cols)) if cols else np.zeros(0, dtype=int)
