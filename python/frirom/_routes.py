"""Route policy of the solver: which receptances a condensed system takes (modes: all,
the lowest, or per harmonic; a banded or sparse LU of D_h), the band order of the DoFs,
the contact-coordinates rule and Hill's memory. :mod:`frirom._pack` asks it, then packs
the arrays; nothing here crosses into Fortran but the rules it reads from it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.sparse.linalg import eigsh

from . import _kernels
from ._errors import ParameterError, _physical_memory, int_constant, raise_for_status
from .model import Model

if TYPE_CHECKING:
    from .options import SolverOptions

#: Largest Hill eigenproblem (2 n_dof (2H+1)) solved densely (all exponents, dgeev);
#: above it the exponents of the strip |Im s| <= omega/2 come from shift-invert Arnoldi.
HILL_MAX = int_constant("HILL_DENSE_MAX")
#: Largest model whose receptances 'auto' takes from all its modes (a dense eigen-solve):
#: a memory bound (a few n^2 arrays, 0.5 GB each at 8 000); below it the flop test decides.
#: The 800-pair flange's ROM_I (5 500 DoFs, dense CB interface block) takes the modes:
#: ~2e12 flops once, where a sparse LU per harmonic costs ~1e12 at every frequency.
MODES_MAX = 8000
#: Evaluations of an FRF that 'auto' weighs one eigen-decomposition against (a 100-point
#: curve takes some 500 to 1 500)
EIG_EVALS = 500
#: Damping counts as diagonal in the modes when every |Phi^T C Phi|_rs is below this
#: times sqrt(c_rr c_ss) (plus 1e-13 of the largest c_rr): the receptances then differ
#: from the factorised ones by about this, relative.
DIAG_TOL = 1e-10


@dataclass
class _Modes:
    """Modes for receptances by superposition, as the run takes them (frun_set_modes); arrays of the
    kind not used (count 0) keep one column so that f2py gets their shapes.

    Attributes
    ----------
    nmodes : real modes (SolverOptions.modes), 0 for none
    phi : (n_dof, max(nmodes, 1)) mass-normalised shapes
    omega, zeta : (max(nmodes, 1),) natural frequencies (rad/s), damping ratios
    hmodes : modes per harmonic (a cyclic sector's nodal diameters), 0 for none
    psi : (n_dof, max(hmodes, 1), H + 1) complex shapes of harmonic h's nodal diameter
    omega_h, zeta_h : (max(hmodes, 1), H + 1) their frequencies (rad/s), damping ratios
    """

    nmodes: int
    phi: np.ndarray
    omega: np.ndarray
    zeta: np.ndarray
    hmodes: int
    psi: np.ndarray
    omega_h: np.ndarray
    zeta_h: np.ndarray

    @classmethod
    def none(cls, nrows: int, H: int) -> _Modes:
        return cls(0, np.zeros((nrows, 1)), np.ones(1), np.zeros(1),
                   0, np.zeros((nrows, 1, H + 1), complex, order="F"),
                   np.ones((1, H + 1)), np.zeros((1, H + 1)))


def _lowest_modes(model: Model, nm: int, H: int) -> _Modes:
    """Lowest nm mass-normalised modes, natural frequencies (rad/s) and damping ratios."""
    n = model.n_dof
    if nm > n:
        raise ParameterError(f"options.modes: {nm} modes for a model with {n} DoFs")
    if n <= 3000 or nm > n // 2:
        w2, phi = sla.eigh(model.K.toarray(), model.M.toarray(), subset_by_index=[0, nm - 1])
    else:
        w2, phi = eigsh(model.K.tocsc(), k=nm, M=model.M.tocsc(), sigma=0.0, which="LM")
        order = np.argsort(w2)
        w2, phi = w2[order], phi[:, order]
        phi = phi / np.sqrt(np.einsum("ir,ir->r", phi, model.M @ phi))
    if np.any(w2 <= 0):
        raise ParameterError("options.modes: the model has rigid-body (zero-frequency) modes; "
                             "modal superposition needs a constrained model")
    w = np.sqrt(w2)
    if model.damping.kind == "modal" and model.damping.zeta.size >= nm:
        z = model.damping.zeta[:nm].copy()
    else:
        z = np.einsum("ir,ir->r", phi, model.C @ phi) / (2.0 * w)
    m = _Modes.none(n, H)
    m.nmodes, m.phi, m.omega, m.zeta = w.size, np.asfortranarray(phi), w, z
    return m


def _all_modes(model: Model, H: int, need_diagonal: bool) -> _Modes | str:
    """All modes of the model (dense eigh of K, M) with the damping ratios that make the
    modal receptances exact: diag(Phi^T C Phi) / (2 w) when Phi^T C Phi is diagonal
    (modal, Rayleigh or no damping). Otherwise the reason they do not apply (a str)."""
    w2, phi = sla.eigh(model.K.toarray(), model.M.toarray())
    if np.any(w2 <= 0):
        return "rigid-body (zero-frequency) modes"
    if model.damping.kind == "rayleigh":
        # Phi^T (alpha M + beta K) Phi = alpha + beta w^2 exactly: no test of round-off
        # (a cyclic rotor's mode pairs are degenerate, and their computed Phi^T K Phi
        # couples them at ~1e-10 of their eigenvalue)
        d = model.damping.alpha + model.damping.beta * w2
    else:
        cm = phi.T @ model.C.toarray() @ phi
        d = np.diag(cm).copy()
        off = cm - np.diag(d)
        scale = np.sqrt(np.outer(np.abs(d), np.abs(d))) + 1e-13 * max(np.abs(d).max(), 1e-300)
        if need_diagonal and np.any(np.abs(off) > DIAG_TOL * scale):
            return "damping not diagonal in the modes (a general C)"
    w = np.sqrt(w2)
    m = _Modes.none(model.n_dof, H)
    m.nmodes, m.phi, m.omega, m.zeta = w.size, np.asfortranarray(phi), w, d / (2.0 * w)
    return m


#: Models up to this many DoFs have their band pattern formed densely (_Band).
SMALL_DENSE = 300


class _Band:
    """The RCM order of a model (K, M, C and the contact couplings G^T G) and its
    half-bandwidth under it, computed at the first use: the banded formulation, Hill's
    method and the factorised receptances need them, the modal receptances do not."""

    def __init__(self, model: Model, G: sp.csr_matrix):
        self._model, self._G = model, G
        self._perm: np.ndarray | None = None
        self._bw = 0

    @property
    def perm(self) -> np.ndarray:
        """(n_dof,) int32, the RCM order, 1-based."""
        if self._perm is None:
            self._order()
        return self._perm

    @property
    def bw(self) -> int:
        """Half-bandwidth of the pattern under perm."""
        if self._perm is None:
            self._order()
        return self._bw

    def _order(self) -> None:
        model, G, n = self._model, self._G, self._model.n_dof
        if n <= SMALL_DENSE:
            # a small model's pattern densely: scipy.sparse's per-call cost would dominate
            d = (model.K.toarray() != 0) | (model.M.toarray() != 0) | (model.C.toarray() != 0)
            if model.contacts:
                gd = G.toarray() != 0
                d |= (gd.T.astype(np.int64) @ gd.astype(np.int64)) != 0
            d |= d.T
            d[np.diag_indices(n)] = True
            pat = sp.csr_matrix(d)
        else:
            pat = (abs(model.K) + abs(model.M) + abs(model.C)).tocsr()
            if model.contacts:
                pat = pat + (abs(G).T @ abs(G))
            pat = (pat + pat.T + sp.identity(n)).tocsr()
        pat.sort_indices()
        perm, info, msg = _kernels.hbm_rcm(pat.indptr.astype(np.int32) + 1,
                                           pat.indices.astype(np.int32) + 1)
        raise_for_status(info, msg.decode(errors="replace"))
        iperm = np.empty(n, dtype=np.int64)
        iperm[perm - 1] = np.arange(n)
        pc = pat.tocoo()
        self._perm, self._bw = perm, int(np.abs(iperm[pc.row] - iperm[pc.col]).max())


def _bw_floor(model: Model) -> int:
    """A lower bound of the half-bandwidth of K's and M's pattern under any order: a row
    with d entries off the diagonal reaches at least ceil(d / 2) from it on one side. 0
    when a matrix is not in canonical CSR (duplicates would be counted twice)."""
    d = 0
    for a in (model.K, model.M):
        if a.format != "csr" or not a.has_canonical_format:
            return 0
        if a.nnz:
            nz = np.concatenate(([0], np.cumsum(a.data != 0)))
            d = max(d, int(np.diff(nz[a.indptr]).max()) - 1)
    return (d + 1) // 2


#: 'auto' factorises D_h by sparse LU (MUMPS) instead of a band when the band LU would
#: take more than this many flops per harmonic (n_dof bw^2, bw the RCM half-bandwidth).
SPARSE_FLOPS = 5e8


def _receptance_route(model: Model, opts: SolverOptions, H: int,
                      band: _Band) -> tuple[_Modes, str, bool]:
    """Modes, a description of how the condensed receptances are found (see
    SolverOptions.receptances) and whether D_h is factorised by sparse LU. The RCM
    half-bandwidth (band.bw) is computed only when the choice needs it."""
    n = model.n_dof
    if opts.modes:
        return (_lowest_modes(model, int(opts.modes), H),
                f"receptances from the lowest {opts.modes} modes (truncated)", False)
    why = ""
    if opts.receptances == "modes":
        m = _all_modes(model, H, True)
        if isinstance(m, str):
            raise ParameterError(f"options.receptances: 'modes' not possible: {m}; use "
                                 "'factorization'")
        return m, f"receptances from all {n} modes (exact)", False
    if opts.receptances == "sparse":
        return _Modes.none(n, H), "receptances by sparse LU (MUMPS) per harmonic", True
    if opts.receptances == "auto":
        # one dense eigen-decomposition (~10 n^3 flops) against the band LUs it saves
        # (n bw^2 per harmonic, some EIG_EVALS evaluations of an FRF): a Craig-Bampton
        # model (a dense interface block beside a diagonal modal block) takes the modes,
        # a lumped chain or an FE mesh keeps its narrow band
        # a lower bound of the half-bandwidth under any order decides as the RCM one
        # would whenever it passes the test already (a reduced model's dense rows)
        def dense(b: int) -> bool:
            return 10.0 * n ** 3 <= EIG_EVALS * (H + 1) * n * float(b) ** 2
        if n <= MODES_MAX and (dense(_bw_floor(model)) or dense(band.bw)):
            m = _all_modes(model, H, True)
            if not isinstance(m, str):
                return m, f"receptances from all {n} modes (exact; reduced model)", False
            why = f" ({m})"
        else:
            why = " (sparse or large model)"
        if n * float(band.bw) ** 2 > SPARSE_FLOPS:
            return (_Modes.none(n, H), f"receptances by sparse LU (MUMPS) per harmonic "
                    f"(half-bandwidth {band.bw} of {n} DoFs{why})", True)
    return (_Modes.none(n, H), f"receptances by banded LU per harmonic{why}", False)


def _contact_coords(opts: SolverOptions, nrows: int, nnl: int) -> bool:
    """Whether the condensed unknowns are the contact coordinates G x (nrows) rather than
    the contact DoFs (nnl): SolverOptions.coordinates by Fortran's one rule (frirom_run
    run_contact_coords: 'auto' takes the shorter unless stability or a selection needs
    the DoFs)."""
    code = int_constant("COORD_" + opts.coordinates.upper())
    return bool(_kernels.contact_coords(code, nrows, nnl, int(bool(opts.stability)),
                                        int(opts.selection is not None)))


#: How Hill's method goes (fortran/frirom_hbm_hill.f90 hbm_hill's rule), as logged
HILL_ROUTES = {
    "dense": "stability: Hill, dense (all exponents)",
    "near0": "stability: Hill by shift-invert Arnoldi at s = 0 through the point solve's "
             "Newton matrix (the exponents nearest 0: folds, the resonant pair)",
    "modal": "stability: Hill by shift-invert Arnoldi on the modes, the contacts by "
             "Woodbury on the contact DoFs",
    "banded": "stability: Hill by shift-invert Arnoldi on the banded matrices",
}


def _hill_route(n_dof: int, H: int, nmodes: int, nnl: int, strip: bool = False) -> str:
    """'dense', 'near0', 'modal' or 'banded': Fortran's rule (hbm_hill): dense up to
    HILL_MAX unknowns, then, when a condensed system takes its receptances from real modes
    on the contact DoFs (nmodes > 0: pass 0 otherwise), the exponents nearest 0 through
    the Newton matrix ('near0') or, with stability = 'strip', the whole strip by the
    modes ('modal'); else banded."""
    if 2 * n_dof * (2 * H + 1) <= HILL_MAX:
        return "dense"
    if nmodes > 0 and nnl > 0:
        return "modal" if strip else "near0"
    return "banded"


def hill_bytes(n_dof: int, H: int, bw: int, modal: tuple[int, int] | None = None,
               near0: bool = False) -> int:
    """Memory [bytes] Hill's method needs at one point for n_dof DoFs (band half-width bw
    after RCM) and H harmonics: the dense 2n(2H+1) eigenproblem up to HILL_MAX; by the
    modes (modal = (modes, contact DoFs)): the contact Jacobian and the LU of I + Jc R
    (m = contact DoFs x (2H+1) squared, twice) and the Arnoldi basis; else the banded J,
    D1, M and the factored complex Q(s) (LAPACK band storage, 2 kl + ku + 1 rows) and the
    Arnoldi basis (fortran/frirom_hbm_hill.f90, NEV_MAX = 256); near0 (the exponents
    nearest 0 through the solver's own Newton matrix, frirom_hbm_hill_s0.f90): the real
    Arnoldi basis of 28 vectors over 2 modes (2H+1) and ARPACK's work, nothing of the
    contact DoFs' size beyond the solver's own."""
    nh = n_dof * (2 * H + 1)
    if 2 * nh <= HILL_MAX:
        return 16 * (2 * nh) ** 2 * 3
    if modal is not None and near0:
        return 8 * 2 * modal[0] * (2 * H + 1) * (28 + 6) + 8 * 3 * 28 * 28
    if modal is not None:
        nm, nnl = modal
        m = nnl * (2 * H + 1)
        return 16 * m * m + 2 * nm * (2 * H + 1) * 520 * 16
    kl = min((2 * H + 1) * (bw + 1) - 1, nh - 1)
    return nh * (3 * kl + 1) * (3 * 8 + 16) + 2 * nh * 513 * 16


def _check_hill_memory(n_dof: int, H: int, bw: int,
                       modal: tuple[int, int] | None = None) -> None:
    """Refuse Hill's method (ParameterError naming options.stability) when it needs more
    than half of this machine's memory: a dense reduced model of thousands of DoFs fills
    its band, and the Linux kernel would kill the run rather than fail the allocation."""
    need = hill_bytes(n_dof, H, bw, modal)
    avail = _physical_memory()
    if avail and need > avail // 2:
        raise ParameterError(
            f"options.stability: Hill's method on this model needs {need / 2**30:.3g} GiB "
            f"({n_dof} DoFs x {2 * H + 1} harmonic coefficients, "
            + (f"{modal[0]} modes, {modal[1]} contact DoFs" if modal else
               f"band half-width {bw} after reordering")
            + f"), more than half of this machine's {avail / 2**30:.3g} GiB; set "
            "stability = false (`[solver] stability = false` in a deck)")
