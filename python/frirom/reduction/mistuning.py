"""Mistuned bladed disks: the tuned sector's Craig-Bampton model expanded to the annulus,
with blade-by-blade scatter of the blade-alone modal stiffnesses.

The model is component mode mistuning (CMM, Lim, Bladh, Castanier and Pierre, AIAA J.
45 (2007) 2285-2298; Bladh, Castanier and Pierre, J. Eng. Gas Turb. Power 123 (2001)
89-99): the stiffness of blade b deviates from the tuned blade's by

    dK_b = C^T M_B Phi_B diag(delta_bj lambda_j) Phi_B^T M_B C,

Phi_B the mass-normalised modes of the blade alone, clamped at its root (the sector's
blade DoFs with every other DoF fixed), lambda_j their eigenvalues, delta_bj the
fractional deviation of blade b's j-th modal stiffness (a blade frequency f_bj =
f_j sqrt(1 + delta_bj)), and C x = x_B - Psi x_root the blade's motion relative to its root
(Psi = -K_BB^-1 K_B,root, the static root modes of the blade: its fixed-interface modal
coordinates are q = Phi_B^T M_B C x), so that the blade moving rigidly with its root, which
strains no blade element, carries no mistuning energy. With every blade mode kept and one
delta per blade, dK_b = delta_b C^T K_BB C. That is Young's modulus of the blade scaled but
for the root: the blade elements also stiffen the root nodes against one another (the
blade's stiffness statically condensed onto its root, S_b = K^b_rr - K_rB K_BB^-1 K_Br,
K^b the blade elements' own matrix), and assembled sector matrices cannot separate K^b_rr
from the disk's share of the root nodes. Given the blade elements' matrix
(``blade_stiffness``: a matrix run of the blade alone), the model adds delta_b R^T S_b R
(R: the root DoFs), and with every blade mode dK_b = delta_b K^b: exactly what scaling the
blade's E does. Without it, the root term is missing: against CalculiX's annulus with E
per blade the mistuning's frequency shifts were 29-37 % off (tests/test_mistuning_ccx.py).
Fewer modes project the blade term onto the modes that matter; the root term is a static
stiffness and stays whole. No FE run per sample: the vectors U = (C T)^T M_B Phi_B (T the
sector's Craig-Bampton basis) and the root term W = (R T)^T S_b (R T) are computed once and
a sample adds U diag(delta lambda) U^T + delta W to each sector's reduced stiffness.

The annulus is assembled from the reduced sector without any FE annulus: sector s keeps its
reduced coordinates but its dependent (right) boundary, which is the next sector's left
boundary rotated into sector s's frame, x_R^s = Q x_L^{s+1}. Every sector's coordinates are
in its own rotated frame (the cyclic convention of :class:`frirom.model.CyclicModel`), so a
contact of sector 0 with the next sector (2 n_r columns) repeats around the annulus
unchanged, and with zero deviations the annulus is the block-circulant model whose response
to an engine-order travelling wave the cyclic sector solution gives exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .._errors import InputError, ParameterError, SizeError
from ..contact import LAWS
from ..model import ContactGroup, Damping, Excitation, Model
from .cb import craig_bampton
from .cyclic import CyclicSector, axis_rotation

__all__ = ["MistuningSector", "mistuning_sector", "deviations", "blade_deviations_from_file",
           "deviations_from_table",
           "whitehead_bound"]


def whitehead_bound(n_blades: int) -> float:
    """Largest amplification of one blade's forced response by mistuning, one mode family,
    light damping (Whitehead 1998): (1 + sqrt N) / 2."""
    return 0.5 * (1.0 + np.sqrt(float(n_blades)))


def deviations(n_blades: int, std: float = 0.0, seed: int | None = 0, values=None,
               mean: float = 0.0) -> np.ndarray:
    """Per-blade fractional deviations of the blade modal stiffness, (n_blades,).

    ``values`` (one per blade) are taken as given; otherwise normal with standard deviation
    ``std`` about ``mean`` from numpy's PCG64 with ``seed`` (the same seed, the same blades).
    A deviation must stay above -1 (a blade of zero or negative stiffness).
    """
    N = int(n_blades)
    if N < 2:
        raise ParameterError(f"mistuning: n_blades must be >= 2, got {n_blades}")
    if values is not None:
        d = np.asarray(values, dtype=float).ravel()
        if d.size != N:
            raise SizeError(f"mistuning.deviations: {d.size} values for {N} blades")
    else:
        if not np.isfinite(std) or std < 0:
            raise ParameterError(f"mistuning.std: expected a finite value >= 0, got {std}")
        d = mean + std * np.random.default_rng(seed).standard_normal(N)
    if not np.all(np.isfinite(d)) or np.any(d <= -1.0):
        raise ParameterError("mistuning: deviations must be finite and > -1 (a blade "
                             f"stiffness factor 1 + delta > 0); got min {np.min(d):.3g}")
    return d


def blade_deviations_from_file(path, n_blades: int, reference: float | None = None):
    """Stiffness deviations from a file of measured blade frequencies (one per line, blade
    0 first, '#' comments): delta_b = (f_b / f_ref)^2 - 1, f_ref = ``reference`` or the
    mean of the file's frequencies (then the mean blade is the tuned one)."""
    p = Path(path)
    try:
        f = np.loadtxt(p, comments="#", ndmin=1, dtype=float)
    except (OSError, ValueError) as exc:
        raise InputError(f"{p}: cannot read blade frequencies ({exc})") from None
    f = f.ravel()
    if f.size != int(n_blades):
        raise SizeError(f"{p}: {f.size} blade frequencies for {n_blades} blades")
    if not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ParameterError(f"{p}: blade frequencies must be finite and > 0")
    ref = float(np.mean(f)) if reference is None else float(reference)
    if not ref > 0:
        raise ParameterError(f"mistuning.reference: expected a frequency > 0, got {reference}")
    return (f / ref) ** 2 - 1.0


@dataclass
class MistuningSector:
    """A tuned sector reduced by Craig-Bampton, its blade-alone modes and the map to the
    annulus. Build with :func:`mistuning_sector`.

    K, M: (n_r, n_r) reduced matrices; T: (n_dof, n_r) sparse basis (sector DoFs from
    reduced coordinates); left, right: (n_b, 3) reduced positions of the cyclic boundaries
    (-1 constrained); n_sectors, axis; U: (n_r, n_bm) T^T M_B Phi_B; blade_lambda: (n_bm,)
    clamped-blade eigenvalues [rad^2/s^2]; root_K: (n_r, n_r) the blade's condensed root
    stiffness in reduced coordinates, W = (R T)^T S_b (R T), or None (not known: left out).
    """

    K: np.ndarray
    M: np.ndarray
    T: sp.csr_matrix
    left: np.ndarray
    right: np.ndarray
    n_sectors: int
    axis: np.ndarray
    U: np.ndarray
    blade_lambda: np.ndarray
    master_dofs: np.ndarray
    root_K: np.ndarray | None = None
    L0: sp.csr_matrix = field(init=False, repr=False)

    def __post_init__(self):
        n_r = self.K.shape[0]
        rmask = np.zeros(n_r, bool)
        rv = self.right[self.right >= 0]
        rmask[rv] = True
        self.independent = np.nonzero(~rmask)[0]
        n_i = self.independent.size
        col = -np.ones(n_r, dtype=np.int64)
        col[self.independent] = np.arange(n_i)
        Q = axis_rotation(2 * np.pi / self.n_sectors, self.axis)
        rows, cols, vals = list(self.independent), list(np.arange(n_i)), [1.0] * n_i
        for a in range(self.left.shape[0]):
            for c in range(3):
                r = self.right[a, c]
                if r < 0:
                    continue
                for d in range(3):
                    lft = self.left[a, d]
                    if lft >= 0 and Q[c, d] != 0.0:
                        rows.append(r)
                        cols.append(n_i + col[lft])        # the next sector's left
                        vals.append(Q[c, d])
        # columns n_i.. are those of sector s+1; wrapped by :meth:`sector_map`
        self.L0 = sp.csr_matrix((vals, (rows, cols)), shape=(n_r, 2 * n_i))

    @property
    def n_reduced(self) -> int:
        return self.K.shape[0]

    @property
    def n_per_sector(self) -> int:
        return self.independent.size

    @property
    def n_annulus(self) -> int:
        return self.n_sectors * self.n_per_sector

    @property
    def n_blade_modes(self) -> int:
        return self.blade_lambda.size

    def sector_map(self, s: int) -> sp.csr_matrix:
        """(n_r, n_annulus) map from the annulus coordinates to sector s's reduced ones."""
        N, n_i = self.n_sectors, self.n_per_sector
        s %= N
        L = self.L0.tocoo()
        c = np.where(L.col < n_i, s * n_i + L.col, ((s + 1) % N) * n_i + L.col - n_i)
        return sp.csr_matrix((L.data, (L.row, c)), shape=(L.shape[0], N * n_i))

    def reduced(self, dofs) -> np.ndarray:
        """Reduced coordinates of master sector DoFs (kept physical by the reduction)."""
        d = np.atleast_1d(np.asarray(dofs, dtype=np.int64))
        pos = np.searchsorted(self.master_dofs, d)
        pos = np.minimum(pos, self.master_dofs.size - 1)
        if not np.array_equal(self.master_dofs[pos], d):
            raise InputError(f"DoFs {d[self.master_dofs[pos] != d][:5].tolist()} are not "
                             "masters of the sector's reduction (add them to keep)")
        return pos

    def position(self, p: int, s: int) -> int:
        """Annulus coordinate of reduced coordinate p (not a right-boundary one) of sector
        s."""
        hit = np.nonzero(self.independent == int(p))[0]
        if hit.size == 0:
            raise InputError(f"reduced coordinate {p} lies on the dependent cyclic boundary; "
                             "take its partner on the left boundary")
        return int((s % self.n_sectors) * self.n_per_sector + hit[0])

    def reduce_contacts(self, groups) -> list:
        """Contact groups on the sector's DoFs (n_dof or 2 n_dof columns) on the reduced
        coordinates (G T)."""
        out, n = [], self.T.shape[0]
        for g in groups:
            nb = g.G.shape[1] // n
            if g.G.shape[1] != nb * n or nb not in (1, 2):
                raise SizeError(f"contact {g.name!r}: {g.G.shape[1]} columns; the sector has "
                                f"{n} DoFs (n or 2 n columns)")
            G = sp.hstack([g.G[:, b * n:(b + 1) * n] @ self.T for b in range(nb)]).tocsr()
            out.append(ContactGroup(g.law, G, g.params, g.w0, name=g.name))
        return out

    def stiffness(self, delta=None) -> sp.csr_matrix:
        """Annulus stiffness with blade deviations ``delta``: (N,) one per blade, or
        (N, n_bm) one per blade and blade mode; None or zeros: the tuned annulus. The root
        term (:attr:`root_K`, if known) takes the blade's first-mode deviation."""
        N = self.n_sectors
        d = np.zeros((N, self.n_blade_modes))
        if delta is not None:
            a = np.asarray(delta, dtype=float)
            if a.ndim == 1 and a.size == N:
                a = a[:, None]
            if a.ndim != 2 or a.shape[0] != N or a.shape[1] not in (1, self.n_blade_modes):
                raise SizeError(f"mistuning: deviations of shape {a.shape} for {N} blades "
                                f"and {self.n_blade_modes} blade modes")
            d = d + a
        W = self.root_K

        def block(s):
            k = self.K + (self.U * (d[s] * self.blade_lambda)) @ self.U.T
            return k if W is None else k + d[s, 0] * W
        return self._assemble(block)

    def mass(self) -> sp.csr_matrix:
        return self._assemble(lambda s: self.M)

    def _assemble(self, block) -> sp.csr_matrix:
        out = None
        for s in range(self.n_sectors):
            L = self.sector_map(s)
            term = L.T @ sp.csr_matrix(block(s)) @ L
            out = term if out is None else out + term
        out = out.tocsr()
        return (0.5 * (out + out.T)).tocsr()

    def contacts(self, groups) -> list:
        """Reduced-sector contact groups (n_r or 2 n_r columns) repeated on every sector."""
        N, n_r = self.n_sectors, self.n_reduced
        out = []
        for g in groups:
            nb = g.G.shape[1] // n_r
            if g.G.shape[1] != nb * n_r or nb not in (1, 2):
                raise SizeError(f"contact {g.name!r}: {g.G.shape[1]} columns; the reduced "
                                f"sector has {n_r} (n_r or 2 n_r columns)")
            rows = []
            for s in range(N):
                G = g.G[:, :n_r] @ self.sector_map(s)
                if nb == 2:
                    G = G + g.G[:, n_r:] @ self.sector_map(s + 1)
                rows.append(G)
            out.append(ContactGroup(g.law, sp.vstack(rows).tocsr(), np.tile(g.params, (N, 1)),
                                    np.tile(g.w0, (N, 1)), name=g.name))
        return out

    def excitation(self, F, engine_order: int, sign: int = -1) -> Excitation:
        """Sector 0's reduced load F (n_r, H+1) as an engine-order travelling wave on the
        annulus: sector s gets harmonic h times exp(i sign h EO s 2 pi / N)."""
        F = np.asarray(F, dtype=complex)
        if F.ndim == 1:
            F = np.stack([np.zeros_like(F), F], axis=1)
        if F.shape[0] != self.n_reduced:
            raise SizeError(f"excitation: {F.shape[0]} rows, the reduced sector has "
                            f"{self.n_reduced}")
        h = np.arange(F.shape[1])
        out = np.zeros((self.n_annulus, F.shape[1]), complex)
        for s in range(self.n_sectors):
            ph = np.exp(1j * sign * h * engine_order * s * 2 * np.pi / self.n_sectors)
            out += self.sector_map(s).T @ (F * ph)
        return Excitation(out)

    def model(self, delta=None, damping: Damping | None = None, contacts=(),
              interfaces: str = "friction") -> Model:
        """The mistuned annulus as a :class:`frirom.model.Model`.

        contacts: reduced-sector groups (see :meth:`contacts`); interfaces: 'friction'
        (the contact laws), 'stuck' (each contact replaced by its stick stiffness: kt
        tangential, kn normal, k1 for 'cubic'; Rayleigh damping stays that of the structure,
        as with friction) or 'free' (contacts removed).
        """
        if interfaces not in ("friction", "stuck", "free"):
            raise ParameterError(f"interfaces: expected 'friction', 'stuck' or 'free', got "
                                 f"{interfaces!r}")
        K = self.stiffness(delta)
        groups = self.contacts(contacts)
        damping = damping or Damping.rayleigh(0.0, 0.0)
        M = self.mass()
        if interfaces == "stuck":
            if damping.kind == "rayleigh":    # the structure's damping, not the contacts'
                damping = Damping.matrix(damping.alpha * M + damping.beta * K)
            K = (K + sum(stick_matrix(g) for g in groups)).tocsr()
        if interfaces != "friction":
            groups = []
        return Model(M, K, damping, groups)


def stick_stiffnesses(g: ContactGroup) -> np.ndarray:
    """(n_elem n_dir,) stiffness of each row of G with the contact stuck: kt tangential,
    kn normal ('v'), k1 for 'cubic'."""
    law = LAWS[g.law]
    col = dict(zip(law.parameters, g.params.T))
    k = np.empty((g.n_elem, g.n_dir))
    for d, name in enumerate(law.directions):
        k[:, d] = col["kn" if name == "v" else ("k1" if g.law == "cubic" else "kt")]
    return k.ravel()


def stick_matrix(g: ContactGroup) -> sp.csr_matrix:
    """G^T diag(k) G: the contact stuck (see :func:`stick_stiffnesses`)."""
    return (g.G.T @ sp.diags(stick_stiffnesses(g)) @ g.G).tocsr()


def mistuning_sector(sector: CyclicSector, K, M, n_modes: int | None, blade_dofs, keep=(),
                     n_blade_modes: int | None = None, blade_stiffness=None,
                     keep_root: bool = False) -> MistuningSector:
    """Craig-Bampton of a tuned sector for the annulus, with its clamped-blade modes.

    sector: the sector's cyclic boundaries (its n_dof DoFs); K, M: its matrices; n_modes:
    fixed-interface modes kept (None: all of them, a dense eigen-solve, the
    reduction then exact); blade_dofs: the sector DoFs of the blade (its root fixed:
    every other DoF is the clamp); keep: more masters (contact DoFs, loaded and output DoFs:
    they stay physical coordinates); n_blade_modes: clamped-blade modes that carry the
    mistuning (default all of them); blade_stiffness: (n_dof, n_dof) the stiffness of the
    blade's elements alone on the sector's DoFs (free at the root; e.g. a CalculiX matrix
    run of the blade's elements), which adds the blade's condensed root stiffness to the
    mistuning: with every blade mode, a deviation delta is then exactly the blade's E
    scaled by 1 + delta. Its blade block must be the sector's. keep_root: the blade's root
    DoFs (those its DoFs couple to) become masters too: the root term then acts on
    physical coordinates and no fixed-interface mode has to carry it (against CalculiX
    with 30 modes: the mistuning's frequency shifts to 2e-4 with, 5 % without).
    """
    K = sp.csr_matrix(K)
    M = sp.csr_matrix(M)
    n = sector.n_dof
    if K.shape != (n, n) or M.shape != (n, n):
        raise SizeError(f"mistuning_sector: K {K.shape}, M {M.shape} for a sector of {n} DoFs")
    left, right = sector.left, sector.right
    bd = np.unique(np.asarray(blade_dofs, dtype=np.int64).ravel())
    if bd.size == 0 or bd[0] < 0 or bd[-1] >= n:
        raise InputError(f"blade_dofs: expected DoFs in 0..{n - 1}")
    kp = np.asarray(keep, dtype=np.int64).ravel()
    rest = np.setdiff1d(np.arange(n), bd)
    root = rest[np.unique(K[bd][:, rest].nonzero()[1])]
    if keep_root:
        kp = np.concatenate([kp, root])
    masters = np.unique(np.concatenate([left[left >= 0], right[right >= 0], kp]))
    if np.intersect1d(bd, np.concatenate([left.ravel(), right.ravel()])).size:
        raise InputError("blade_dofs: a blade DoF lies on a cyclic boundary")
    nm = masters.size
    slaves = np.setdiff1d(np.arange(n), masters)
    if n_modes is None:
        # every fixed-interface mode (dense; the reduction is then exact): small sectors
        Kss = K[slaves][:, slaves].toarray()
        psi = -np.linalg.solve(Kss, K[slaves][:, masters].toarray())
        _, phi_s = sla.eigh(Kss, M[slaves][:, slaves].toarray())
    else:
        cb = craig_bampton((K, M), int(n_modes), masters=masters)
        psi, phi_s = cb.psi, cb.phi
    n_r = nm + phi_s.shape[1]
    T = np.zeros((n, n_r))
    T[masters, np.arange(nm)] = 1.0
    T[np.ix_(slaves, np.arange(nm))] = psi
    T[np.ix_(slaves, nm + np.arange(phi_s.shape[1]))] = phi_s
    pos = -np.ones(n, dtype=np.int64)
    pos[masters] = np.arange(nm)

    def where(a):
        return np.where(a >= 0, pos[np.maximum(a, 0)], -1)

    Kb = K[bd][:, bd].toarray()
    Mb = M[bd][:, bd].toarray()
    nb = bd.size if n_blade_modes is None else int(n_blade_modes)
    if not 1 <= nb <= bd.size:
        raise InputError(f"n_blade_modes: expected 1..{bd.size}, got {n_blade_modes}")
    lam, phi = sla.eigh(Kb, Mb, subset_by_index=[0, nb - 1])
    if np.any(lam <= 0):
        raise ParameterError("mistuning_sector: the clamped blade has a zero-frequency mode; "
                             "blade_dofs must be tied to the rest of the sector")
    # blade b's modal coordinates measure its motion relative to its root: q = Phi^T M_B
    # (x_B - Psi x_root), Psi = -K_BB^-1 K_B,root the static root modes, so a rigid motion
    # of the blade with its root (no blade strain) carries no mistuning energy.
    Ke = None
    if blade_stiffness is not None:
        Ke = _blade_element_stiffness(blade_stiffness, n, bd, Kb)
    psi_b = -np.linalg.solve(Kb, K[bd][:, root].toarray())
    U = (T[bd] - psi_b @ T[root]).T @ (Mb @ phi)
    W = None
    if Ke is not None:
        # the blade's stiffness condensed onto its root: S_b = K^b_rr - K_rB K_BB^-1 K_Br
        S = Ke[root][:, root].toarray() + K[root][:, bd].toarray() @ psi_b
        W = T[root].T @ (0.5 * (S + S.T)) @ T[root]
        W = 0.5 * (W + W.T)
    Kr, Mr = T.T @ (K @ T), T.T @ (M @ T)
    return MistuningSector(K=0.5 * (Kr + Kr.T), M=0.5 * (Mr + Mr.T), T=sp.csr_matrix(T),
                           left=where(left), right=where(right), n_sectors=sector.n_sectors,
                           axis=np.asarray(sector.axis, float), U=U, blade_lambda=lam,
                           master_dofs=masters, root_K=W)


def _blade_element_stiffness(Ke, n: int, bd, Kb) -> sp.csr_matrix:
    """The blade elements' stiffness (``blade_stiffness``) checked: (n, n), its blade block
    the sector's (no other element touches a blade DoF), stiffness only on the blade and
    its root (the DoFs the blade rows reach)."""
    Ke = sp.csr_matrix(Ke, dtype=float)
    if Ke.shape != (n, n):
        raise SizeError(f"blade_stiffness: shape {Ke.shape}, the sector has {n} DoFs")
    scale = np.abs(Kb).max()
    diff = np.abs(Ke[bd][:, bd].toarray() - Kb).max()
    if not diff <= 1e-8 * scale:
        raise InputError(f"blade_stiffness: its blade block differs from the sector's K by "
                         f"{diff:.3g} (of {scale:.3g}): not the same blade elements and DoFs")
    rest = np.setdiff1d(np.arange(n), bd)
    root = rest[np.unique(Ke[bd][:, rest].nonzero()[1])]
    rows = np.setdiff1d(np.unique(Ke.nonzero()[0]), bd)
    if np.setdiff1d(rows, root).size:
        raise InputError(f"blade_stiffness: {np.setdiff1d(rows, root).size} DoFs outside the "
                         "blade have stiffness but no coupling to it: give the matrix of the "
                         "blade's elements alone")
    return Ke


def deviations_from_table(table: dict, n_blades: int, folder=".") -> np.ndarray:
    """Blade deviations from a deck's ``[mistuning]`` table (its keys, one of three forms):

    - ``std`` (fraction, e.g. 0.02) and optional ``seed`` (integer, default 0) and
      ``mean`` (default 0): normal scatter;
    - ``deviations``: one value per blade;
    - ``frequencies``: a file (relative to ``folder``) of measured blade frequencies, one
      per line, with optional ``reference`` [Hz] (default: their mean).
    """
    if not isinstance(table, dict):
        raise InputError("[mistuning]: expected a table")
    forms = [k for k in ("std", "deviations", "frequencies") if k in table]
    if len(forms) != 1:
        raise InputError("[mistuning]: give exactly one of 'std', 'deviations' or "
                         f"'frequencies' (got {forms or 'none'})")
    allowed = {"std": {"std", "seed", "mean"}, "deviations": {"deviations"},
               "frequencies": {"frequencies", "reference"}}[forms[0]]
    extra = sorted(set(table) - allowed)
    if extra:
        raise InputError(f"[mistuning]: unknown key(s) {extra} with '{forms[0]}' (allowed: "
                         f"{sorted(allowed)})")
    if forms[0] == "std":
        seed = table.get("seed", 0)
        if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
            raise InputError(f"[mistuning].seed: expected an integer >= 0, got {seed!r}")
        try:
            std, mean = float(table["std"]), float(table.get("mean", 0.0))
        except (TypeError, ValueError):
            raise InputError("[mistuning].std and .mean: expected numbers") from None
        return deviations(n_blades, std, seed=seed, mean=mean)
    if forms[0] == "deviations":
        try:
            vals = np.asarray(table["deviations"], dtype=float)
        except (TypeError, ValueError):
            raise InputError("[mistuning].deviations: expected a list of numbers") from None
        return deviations(n_blades, values=vals)
    return blade_deviations_from_file(Path(folder) / str(table["frequencies"]), n_blades,
                                      table.get("reference"))
