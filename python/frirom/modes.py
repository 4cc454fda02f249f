"""Linear pre-check of a deck: natural frequencies and linear FRFs with the contacts free
and fully stuck, and a frequency range to sweep (``frirom modes DECK``).

A friction contact moves between two linear limits: free (no contact force: every element
slides at zero friction or is open) and fully stuck (every element a linear spring, its
stick stiffnesses kt, kn of the law, k1 of the cubic law). The nonlinear resonance lies
between the two, so their natural frequencies bracket it and their FRFs are reference
curves for every nonlinear one. Stuck: K_s = K + sum over groups G^T diag(k) G.

A zero natural frequency is a motion the stiffness does not hold: stuck, a warning (no
contact holds it: the static harmonic cannot be solved); free, a body held only by its
contacts (a damper). Each such motion is named: the node sets it moves and its direction
(FE decks), or its DoFs.

With ``[reduction.cyclic]`` the frequencies are per harmonic index (nodal diameter) k_h of
the harmonics 0..H; the stuck ones need contacts inside the sector (a contact with the
next sector is left out with a note), and the linear FRFs are the modal sums of harmonic
1's index.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .contact import LAWS, stuck_stiffness as law_stuck_stiffness
from .model import describe_motion, null_motions
from .results import amplitude_max

__all__ = ["LinearCheck", "linear_check", "linear_response", "stuck_stiffness"]

#: per law, the parameter giving the stuck stiffness of each local direction
_STICK = {"jenkins": ("kt",), "normal1d": ("kt", "kn"), "normal2d": ("kt", "kt", "kn"),
          "cubic": ("k1",)}


@dataclass
class LinearCheck:
    """Free and stuck linear limits of a deck.

    free, stuck : ndarray
        Natural frequencies [rad/s] near the range (all of them up to ``n_show``), lowest
        first (cyclic: those of harmonic 1's index).
    omega : ndarray, (n_grid,)
        Frequencies of the linear FRFs [rad/s].
    amp_free, amp_stuck : ndarray, (n_grid, n_out)
        Max over a period of the linear response at the outputs (loads of harmonics >= 1).
    suggested : (float, float)
        A range [rad/s] holding the free and stuck resonances of the strongest response.
    per_index : dict
        Cyclic: {k: (free, stuck or None)} frequencies per harmonic index.
    notes : list of str
    """

    free: np.ndarray
    stuck: np.ndarray
    omega: np.ndarray
    amp_free: np.ndarray
    amp_stuck: np.ndarray
    suggested: tuple
    per_index: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)

    def linear_curves(self, output: int | None = None) -> dict:
        """{"free": (omega, amp), "stuck": (omega, amp)}: the ``linear=`` argument of
        :func:`frirom.plots.plot_frf` (amp (n_grid, n_out), or one output's column)."""
        sl = slice(None) if output is None else output
        return {"free": (self.omega, self.amp_free[:, sl]),
                "stuck": (self.omega, self.amp_stuck[:, sl])}

    def lines(self, deck) -> list:
        """What ``frirom modes`` and the first lines of ``frirom run`` print."""
        from .plots import frequency_axis
        unit = "Hz" if deck.frequency_unit == "hz" else "rad/s"

        def fmt(w):
            return ", ".join(f"{v:.5g}" for v in frequency_axis(w, deck.frequency_unit)[0])
        a, b = frequency_axis(np.array([deck.omega_start, deck.omega_end]),
                              deck.frequency_unit)[0]
        out = [f"natural frequencies near {min(a, b):.5g}-{max(a, b):.5g} {unit}, "
               f"contacts free: {fmt(self.free)}",
               f"natural frequencies, contacts stuck: {fmt(self.stuck) or '-'}"]
        for k, (fr, st) in sorted(self.per_index.items()):
            out.append(f"  nodal diameter {k}: free {fmt(fr)}; stuck "
                       + (fmt(st) if st is not None else "not computed"))
        s0, s1 = frequency_axis(np.array(self.suggested), deck.frequency_unit)[0]
        out.append(f"suggested range: {s0:.5g}-{s1:.5g} {unit} (the free and stuck "
                   "resonances of the largest linear response)")
        out.extend(self.notes)
        return out


def stuck_stiffness(contacts, n_dof: int) -> sp.csr_matrix:
    """sum over groups of G^T diag(k) G: the contacts' springs when every element sticks.

    contacts : list of objects with ``law``, ``G`` (n_elem*n_dir, n_dof) and ``params``
    (n_elem, n_par) (:class:`frirom.deck.ContactSpec` or ContactGroup) [N/m].
    """
    Ks = sp.csr_matrix((n_dof, n_dof))
    for c in contacts:
        law = LAWS[c.law]
        names = law.parameters
        if c.law in _STICK:
            cols = [names.index(p) for p in _STICK[c.law]]
            k = np.asarray(c.params, float)[:, cols].ravel()        # (n_elem*n_dir,)
        elif law.code > 0:                                          # iwan4, iwan
            k = law_stuck_stiffness(c.law, c.params).ravel()
        else:
            # a user law: its parameters named kt (tangents) and kn (the last direction,
            # when it has one), else none
            p = np.asarray(c.params, float)
            k = np.zeros((p.shape[0], law.n_dir))
            if "kt" in names:
                k[:, :] = p[:, [names.index("kt")]]
            if "kn" in names and law.n_dir > 1:
                k[:, -1] = p[:, names.index("kn")]
            k = k.ravel()
        G = sp.csr_matrix(c.G)
        Ks = Ks + (G.T @ sp.diags(k) @ G)
    return Ks.tocsr()


def _set_motions(deck, phi):
    """{node set: (k, n_nodes, 3) displacements} of the motions phi (n, k) at the reduced
    model's FE node sets (None without them)."""
    rom = getattr(deck, "reduced", None)
    if rom is None or not getattr(rom, "node_sets", None):
        return None
    sets = {}
    for name, nodes in rom.node_sets.items():
        try:
            R = np.array([[rom.load_row(int(nd), d) for d in (1, 2, 3)] for nd in nodes])
        except Exception:           # a set of nodes the reduction does not keep rows of
            continue
        if R.size:
            sets[name] = np.einsum("ndr,rk->knd", R, phi)
    return sets or None


def _free_body(deck, phi) -> str:
    """What the motions ``phi`` (n,) or (n, k) of the model move, in the deck's terms: with
    an FE deck the node sets they move (the others named as still) and, of the motions
    together, the rigid translations among them (from the reduction's rows of the FE
    DoFs); with [model] the DoFs (:func:`frirom.model.describe_motion`)."""
    phi = np.asarray(phi, float)
    phi = phi[:, None] if phi.ndim == 1 else phi
    sets = _set_motions(deck, phi)
    if sets is None:
        return "; ".join(describe_motion(phi[:, j], getattr(deck, "dof_labels", None))
                         for j in range(phi.shape[1]))
    rms = {k: float(np.sqrt(np.mean(np.sum(U * U, axis=2)))) for k, U in sets.items()}
    top = max(rms.values())
    moving = sorted(k for k, v in rms.items() if v >= 0.2 * top)
    U = np.concatenate([sets[k] for k in moving], axis=1)      # (k, nodes, 3)
    means = U.mean(axis=1)                                      # (k, 3) translations
    size = float(np.sqrt(np.mean(np.sum(U * U, axis=2))))
    _, sv, Vt = np.linalg.svd(means)
    dirs = Vt[:int(np.sum(sv > 0.1 * size * np.sqrt(phi.shape[1])))]
    k = phi.shape[1]
    if len(dirs) == 3:
        trans = "translations in every direction"
    elif len(dirs):
        trans = ("a translation along " if len(dirs) == 1 else "translations in the plane of ") \
            + " and ".join("({:.2f}, {:.2f}, {:.2f})".format(*(v * np.sign(v[np.argmax(
                np.abs(v))]) + 0.0)) for v in np.round(dirs, 2))
    else:
        trans = ""
    rest = k - len(dirs)
    how = ", ".join(x for x in (trans, f"{rest} rotation{'s' if rest > 1 else ''} or "
                                f"deformation{'s' if rest > 1 else ''}" if rest else "") if x)
    others = sorted(set(sets) - set(moving))
    return (f"node set{'s' if len(moving) > 1 else ''} {', '.join(moving)}: {how}"
            + (f"; {', '.join(others)} still" if others else ""))


def _zero_modes(deck, K, M, around, which: str) -> list:
    """Notes naming the motions K does not hold (zero natural frequencies), for the
    ``which`` limit ("stuck": a warning, nothing holds them; "free": the body the contacts
    hold)."""
    try:
        lam, phi = null_motions(K, M, n_max=6)
    except (np.linalg.LinAlgError, ValueError, RuntimeError):
        return []
    k = phi.shape[1]
    if k == 0:
        return []
    many = "ies are" if k > 1 else "y is"
    head = (f"WARNING: {k} stuck natural frequenc{many} 0 Hz: a motion no contact holds "
            "even stuck (the static harmonic cannot be solved; constrain the structure or "
            "add a contact)" if which == "stuck" else
            f"contacts free: {k} natural frequenc{many} 0 Hz: a body held only by its "
            "contacts")
    return [head, f"  free motion{'s' if k > 1 else ''}: {_free_body(deck, phi)}"]


def _frequencies(K, M, around: tuple, n_show: int) -> np.ndarray:
    """Natural frequencies [rad/s]: those in ``around`` and ``n_show`` each side."""
    n = K.shape[0]
    if n <= 1500:
        lam = sla.eigh(K.toarray(), M.toarray(), eigvals_only=True)
    else:
        import scipy.sparse.linalg as spla
        sigma = (0.5 * sum(around)) ** 2
        lam = spla.eigsh(K.tocsc(), k=min(3 * n_show + 10, n - 2), M=M.tocsc(),
                         sigma=sigma, return_eigenvectors=False)
    w = np.sqrt(np.clip(np.sort(lam.real), 0.0, None))
    lo, hi = np.searchsorted(w, around[0]), np.searchsorted(w, around[1])
    return w[max(lo - n_show, 0):hi + n_show]


def _response(K, M, C, F, outputs, omega, notes=None, what="") -> np.ndarray:
    """Max over a period at the outputs of the linear response to the loads of harmonics
    >= 1 of F (n, H+1): (n_grid, n_out). A dense model: by its modes, exact where they
    diagonalise C; where they do not (C built on the free structure, the modes stuck) its
    off-diagonal part is dropped (the normal-mode approximation), said in ``notes``; without
    ``notes``, solved per frequency instead."""
    H = F.shape[1] - 1
    out = np.zeros((omega.size, len(outputs)))
    X = np.zeros((len(outputs), 2 * H + 1))
    modal = _modal_receptance(K, M, C, outputs)
    if modal is not None and modal[4] > 1e-8 and notes is None:
        modal = None                   # exact asked for (linear_response): solve per frequency
    if modal is not None:
        # a dense (reduced) model: the modal sum (a sparse factorisation per frequency
        # took minutes on a 1 900-DoF ROM)
        phi_o, phi, w2, c, off = modal
        if off > 1e-8 and notes is not None:
            notes.append(f"linear {what} FRF by modes: the damping's coupling of the modes "
                         f"(up to {off:.1e} of its diagonal) is left out; its frequencies "
                         "are exact")
        Xg = np.zeros((omega.size, len(outputs), 2 * H + 1))
        for h in range(1, H + 1):
            if np.any(F[:, h]):
                hw = h * omega[:, None]
                x = ((phi.T @ F[:, h])[None, :] / (w2[None, :] - hw ** 2 + 1j * hw * c[None, :])
                     ) @ phi_o.T                                   # (n_grid, n_out)
                Xg[:, :, 2 * h - 1], Xg[:, :, 2 * h] = x.real, -x.imag
        for i in range(omega.size):
            out[i] = amplitude_max(Xg[i])
        return out
    import scipy.sparse.linalg as spla
    for i, w in enumerate(omega):
        X[:] = 0.0
        for h in range(1, H + 1):
            if not np.any(F[:, h]):
                continue
            D = (K - (h * w) ** 2 * M + 1j * h * w * C).tocsc()
            x = spla.spsolve(D, F[:, h])[outputs]
            X[:, 2 * h - 1], X[:, 2 * h] = x.real, -x.imag
        out[i] = amplitude_max(X)
    return out


#: the modal sum replaces a sparse solve per frequency above this many DoFs when K holds
#: more than DENSE_FILL of its entries (a reduced model)
DENSE_MIN, DENSE_FILL = 300, 0.05


def _modal_receptance(K, M, C, outputs):
    """(Phi[outputs], Phi, omega_r^2, the diagonal of Phi^T C Phi, the largest off-diagonal
    entry relative to the largest diagonal one) of a dense model (DENSE_MIN, DENSE_FILL),
    Phi its mass-normalised modes; else None."""
    n = K.shape[0]
    if n < DENSE_MIN or K.nnz < DENSE_FILL * n * n:
        return None
    import scipy.linalg as sla
    try:
        w2, phi = sla.eigh(K.toarray(), M.toarray())
    except (np.linalg.LinAlgError, ValueError):
        return None
    ct = phi.T @ (C @ phi) if C is not None else np.zeros((n, n))
    d = np.diag(ct).copy()
    off = np.abs(ct - np.diag(d)).max(initial=0.0) / max(np.abs(d).max(initial=0.0), 1e-300)
    return phi[outputs, :], phi, w2, d, float(off)


def linear_response(deck, omega, stuck: bool) -> np.ndarray:
    """Max over a period at the deck's outputs of the linear response, contacts free or
    stuck, at the frequencies ``omega`` (n,) rad/s: (n, n_out) (non-cyclic decks)."""
    M, K = sp.csr_matrix(deck.M), sp.csr_matrix(deck.K)
    C = deck.damping_object().assemble(M, K)
    if stuck:
        K = K + stuck_stiffness(deck.contacts, deck.n_dof)
    return _response(K, M, C, deck.F, deck.outputs, np.atleast_1d(omega))


def linear_check(deck, n_grid: int | None = None, n_show: int = 2) -> LinearCheck:
    """The free and stuck limits of a built deck (:class:`frirom.deck.Deck`).

    n_grid: frequencies of the linear FRFs over the range widened by 25 % each side
    (default 400, 100 above 2000 coordinates: one sparse factorisation each);
    n_show: natural frequencies shown each side of the range.
    """
    if n_grid is None:
        n_grid = 400 if deck.n_dof <= 2000 else 100
    w0, w1 = sorted((deck.omega_start, deck.omega_end))
    span = w1 - w0
    lo, hi = max(w0 - 0.25 * span, 1e-6 * w1), w1 + 0.25 * span
    omega = np.linspace(lo, hi, n_grid)
    M, K = sp.csr_matrix(deck.M), sp.csr_matrix(deck.K)
    Ks = K + stuck_stiffness(deck.contacts, deck.n_dof)
    notes, per = [], {}
    if deck.cyclic is None:
        free, stuck = _frequencies(K, M, (w0, w1), n_show), _frequencies(Ks, M, (w0, w1),
                                                                          n_show)
        notes += _zero_modes(deck, Ks, M, (w0, w1), "stuck")
        notes += _zero_modes(deck, K, M, (w0, w1), "free")
        C = deck.damping_object().assemble(M, K)
        amp_f = _response(K, M, C, deck.F, deck.outputs, omega, notes, "free")
        amp_s = _response(Ks, M, C, deck.F, deck.outputs, omega, notes, "stuck")
    else:
        free, stuck, amp_f, amp_s = _cyclic(deck, Ks, (w0, w1), n_show, omega, per, notes)
    # the resonances of the largest linear response, free and stuck, with a margin
    peaks = []
    for amp in (amp_f, amp_s):
        if amp is not None and amp.size:
            peaks.append(omega[int(np.argmax(amp.max(axis=1)))])
    a, b = (min(peaks), max(peaks)) if peaks else (w0, w1)
    margin = max(0.1 * (b - a), 0.03 * b)
    return LinearCheck(free=free, stuck=stuck, omega=omega,
                       amp_free=amp_f if amp_f is not None else np.zeros((0, 0)),
                       amp_stuck=amp_s if amp_s is not None else np.zeros((0, 0)),
                       suggested=(a - margin, b + margin), per_index=per, notes=notes)


def _cyclic(deck, Ks, around, n_show, omega, per, notes):
    """Cyclic decks: frequencies per harmonic index, FRFs as modal sums of harmonic 1."""
    from .reduction.cyclic import sector_modes
    c = deck.cyclic
    model = deck.model()
    across = [s.name for s in (deck.settings.contacts if deck.settings else ())
              if getattr(s, "b_sector", 0)]
    if across:
        notes.append(f"stuck frequencies not computed: contact(s) {', '.join(across)} "
                     "join the next sector")
    k1 = model.harmonic_index(1)
    stuck_modes = {}
    for k, m in sorted(c["modes"].items()):
        st = None
        if not across:
            sm = sector_modes(c["sector"], Ks, sp.csr_matrix(deck.M), k, None,
                              min(max(m.omega.size, 1), deck.n_dof))
            stuck_modes[k] = sm
            st = _window(sm.omega, around, n_show)
        per[k] = (_window(m.omega, around, n_show), st)
    free, stuck = per.get(k1, (np.zeros(0), None))
    F1 = deck.F[:, 1]

    def modal(modes, zeta):
        if modes is None:
            return None
        psi = modes.psi
        q = psi.conj().T @ F1
        den = modes.omega[None, :] ** 2 - omega[:, None] ** 2 \
            + 2j * zeta[None, :] * modes.omega[None, :] * omega[:, None]
        x = (q[None, :] / den) @ psi[deck.outputs, :].T                   # (n_grid, n_out)
        return np.abs(x)
    m1 = model.modes_of(k1)
    amp_f = modal(m1, m1.zeta)
    s1 = stuck_modes.get(k1)
    amp_s = modal(s1, np.interp(s1.omega, m1.omega, m1.zeta) if s1 is not None else None)
    return free, (stuck if stuck is not None else np.zeros(0)), amp_f, \
        (amp_s if amp_s is not None else np.zeros_like(amp_f))


def _window(w, around, n_show):
    w = np.sort(np.asarray(w, float))
    lo, hi = np.searchsorted(w, around[0]), np.searchsorted(w, around[1])
    return w[max(lo - n_show, 0):hi + n_show]
