"""``[solver] harmonics_kept = "auto"``: an automatic harmonic selection, per unknown (a
nonlinear DoF's harmonic), chosen before the run and checked after it.

1. **Probes**: a coarse run at the smallest H finds, per output, its largest-amplitude
   point and that point's neighbours (:func:`frirom._probes._probes`, the points the H and N
   estimates use); at each probe frequency the solution with the run's H and N is solved
   from it (every harmonic, the contact DoFs as unknowns).
2. **Candidates**: harmonic h of nonlinear DoF j is dropped when its amplitude stays
   below ``tolerance`` times that DoF's largest harmonic amplitude at every probe, and no
   load acts on it there (harmonic 0 counts like the others: a contact without static
   load or preload has none).
3. **Check at the probes**: each probe is solved again with the selection; the selection
   is accepted when its leak (contact forces on the dropped harmonics over those on the
   kept ones) and the relative change of every output's amplitude stay within
   ``tolerance``. Otherwise the threshold is divided by 10 and the candidates made again
   (three times at most, then nothing is dropped).
4. **Along the curve** (:func:`restore`): after the run, a curve whose leak exceeds
   ``tolerance`` anywhere is run again with every harmonic, and the log says where the
   leak grew; the selection never stands where it was not checked.

The choice is logged, written to ``FRF.solver_info`` and to the results' metadata like
the other automatic choices. It pays where whole harmonics carry nothing: a symmetric
friction contact without static load (odd harmonics only, half the unknowns: a dense LU
8x cheaper), or contact DoFs that barely move at some harmonics.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np

from ._errors import FriromError

__all__ = ["KeptChoice", "choose_kept", "restore"]

#: Thresholds tried, as multiples of the tolerance (then nothing is dropped)
STEPS = (1.0, 0.1, 0.01)


@dataclass
class KeptChoice:
    """What :func:`choose_kept` found.

    selection : ndarray (n_dof, H+1) bool or None
        The harmonics solved for (None: all of them).
    tolerance : float
    unknowns : (int, int)
        Condensed unknowns with the selection (on the contact DoFs) and without it (the
        contact coordinates or DoFs, whichever the run takes); a selection is chosen only
        when it has fewer.
    dropped : dict
        harmonic -> number of nonlinear DoFs it was dropped on.
    probes : list of float
        Probe frequencies, rad/s.
    leak, change : float
        The largest leak and relative output change at the probes (nan: not checked).
    threshold : float
        The amplitude threshold (relative to a DoF's largest harmonic) that was accepted.
    notes : list of str
    seconds : float
    restored : str
        Empty, or why the run was made again with every harmonic (:func:`restore`).
    """

    selection: np.ndarray | None
    tolerance: float
    unknowns: tuple = (0, 0)
    dropped: dict = field(default_factory=dict)
    probes: list = field(default_factory=list)
    leak: float = float("nan")
    change: float = float("nan")
    threshold: float = 0.0
    notes: list = field(default_factory=list)
    seconds: float = 0.0
    restored: str = ""

    def summary(self) -> str:
        """One line for ``FRF.solver_info``."""
        if self.selection is None:
            why = "; ".join(self.notes) or "every harmonic carries more than the tolerance"
            return f"harmonic selection auto: every harmonic kept ({why})"
        drop = ", ".join(f"h{h} on {n}" for h, n in sorted(self.dropped.items()))
        out = (f"harmonic selection auto: {self.unknowns[0]} of {self.unknowns[1]} unknowns "
               f"(dropped {drop}; amplitude threshold {self.threshold:.1e} of each DoF's "
               f"largest harmonic; at the probes leak {self.leak:.1e}, output change "
               f"{self.change:.1e}; tolerance {self.tolerance:g})")
        if self.restored:
            out += f"; RESTORED every harmonic: {self.restored}"
        return out

    def lines(self) -> list:
        """The log lines."""
        out = [f"auto: {self.summary()} ({self.seconds:.1f} s)"]
        out += [f"auto: note: {n}" for n in self.notes if self.selection is not None]
        return out


def _amplitudes(y: np.ndarray, nnl: int, H: int) -> np.ndarray:
    """(nnl, H+1) amplitudes of the condensed unknowns y (harmonic-major on the contact
    DoFs: y[j + nnl c], c = a0, a1, b1, ...)."""
    U = y.reshape(2 * H + 1, nnl).T
    a = np.empty((nnl, H + 1))
    a[:, 0] = np.abs(U[:, 0])
    a[:, 1:] = np.hypot(U[:, 1::2], U[:, 2::2])
    return a


def _loaded(F: np.ndarray, nl: np.ndarray, H: int) -> np.ndarray:
    """(nnl, H+1) bool: the load has harmonic h on nonlinear DoF j."""
    G = np.zeros((F.shape[0], H + 1), complex)
    k = min(H + 1, F.shape[1])
    G[:, :k] = F[:, :k]
    return np.abs(G[nl]) > 0


def choose_kept(model, F, omega_start, omega_end, options, outputs=None, *,
                tolerance=1e-3, probes=None) -> KeptChoice:
    """Choose the harmonics to solve for per nonlinear DoF (module docstring).

    Parameters
    ----------
    model : Model
    F : ndarray complex (n_dof, >= 1)
        Load harmonics 0.. (columns above options.harmonics dropped).
    omega_start, omega_end : float
        Range, rad/s.
    options : SolverOptions
        The run's options (H, N, tolerances); its selection, if any, is kept within.
    outputs : as :func:`frirom.solver.frf`.
    tolerance : float
        On the leak and on the outputs' relative amplitude change at the probes.
    probes : list of FRFPoint, optional
        Probe points (a coarse run's) instead of running one.
    """
    from ._probes import _excitation, _first_harmonic, _probes, _rel
    from .solver import solve_point
    t0 = time.perf_counter()
    H = options.harmonics
    base = dataclasses.replace(options, stability=False, coordinates="dofs",
                               harmonics_kept=None, refine_peak=False)
    nl = model.nonlinear_dofs()
    ch = KeptChoice(selection=None, tolerance=tolerance)
    if nl.size == 0:
        ch.notes.append("the model has no contact DoFs")
        return ch
    notes: list = []
    if probes is None:
        H0 = min(_first_harmonic(F), H)
        probes = _probes(model, F, omega_start, omega_end, base, outputs, H0, notes)
    ch.notes += notes
    ex = _excitation(F, H)
    full, amps = [], []
    for p in probes:
        Hp = (p.unknowns.size // nl.size - 1) // 2
        try:
            q = solve_point(model, ex, p.omega, base, outputs=outputs,
                            start={"unknowns": p.unknowns, "slider": p.slider},
                            start_harmonics=Hp)
        except (FriromError, ArithmeticError, np.linalg.LinAlgError) as exc:
            ch.notes.append(f"probe at {p.omega / 2 / np.pi:.6g} Hz failed ({exc})")
            continue
        full.append(q)
        amps.append(_amplitudes(q.unknowns, nl.size, H))
    ch.probes = [q.omega for q in full]
    if not full:
        ch.notes.append("no probe solve succeeded")
        ch.seconds = time.perf_counter() - t0
        return ch
    rel = np.max([a / np.maximum(a.max(axis=1, keepdims=True), 1e-300) for a in amps],
                 axis=0)                                          # (nnl, H+1)
    loaded = _loaded(F, nl, H)
    prior = (np.ones((model.n_dof, H + 1), bool) if options.selection is None
             else np.asarray(options.selection, bool))
    for step in STEPS:
        thr = tolerance * step
        keep_nl = (rel > thr) | loaded | (rel.max(axis=1, keepdims=True) == 0)
        sel = prior.copy()
        sel[nl] &= keep_nl
        if sel[nl].all() or not sel[nl].any():
            break
        o = dataclasses.replace(base, selection=sel)
        leak = change = 0.0
        ok = True
        for q in full:
            try:
                s = solve_point(model, ex, q.omega, o, outputs=outputs,
                                start={"unknowns": q.unknowns, "slider": q.slider})
            except (FriromError, ArithmeticError, np.linalg.LinAlgError):
                ok = False
                break
            leak = max(leak, float(s.leak))
            change = max(change, _rel(s.amp_max, q.amp_max))
        if ok and leak <= tolerance and change <= tolerance:
            from ._pack import kept_unknowns
            n_sel, n_run = kept_unknowns(sel[nl]), _run_unknowns(model, options, nl.size)
            if n_sel >= n_run:
                ch.notes.append(f"the selection would solve {n_sel} unknowns on the contact "
                                f"DoFs where the run without it solves {n_run} (contact "
                                "coordinates G x, fewer): nothing saved")
                break
            ch.selection, ch.threshold, ch.leak, ch.change = sel, thr, leak, change
            ch.unknowns = (n_sel, n_run)
            ch.dropped = {h: int((~sel[nl, h]).sum()) for h in range(H + 1)
                          if (~sel[nl, h]).any()}
            break
        ch.notes.append(f"threshold {thr:.1e}: " + ("a probe failed with the selection"
                        if not ok else f"leak {leak:.1e}, output change {change:.1e} "
                        f"> tolerance {tolerance:g}"))
    ch.seconds = time.perf_counter() - t0
    return ch


def _run_unknowns(model, options, nnl: int) -> int:
    """Condensed unknowns of the run without a selection: the contact coordinates G x or
    the contact DoFs, whichever the coordinates rule takes (frirom._routes)."""
    from ._routes import _contact_coords
    rows = sum(g.G.shape[0] for g in model.contacts)
    o = dataclasses.replace(options, selection=None, harmonics_kept=None)
    n = rows if _contact_coords(o, rows, nnl) else nnl
    return n * (2 * options.harmonics + 1)


def restore(choice: KeptChoice, result) -> bool:
    """Whether a curve run with ``choice.selection`` must be run again with every
    harmonic: its leak exceeds the tolerance at some point (then ``choice.restored`` says
    where)."""
    if choice.selection is None or result.leak is None or not len(result.leak):
        return False
    leak = np.asarray(result.leak, float)
    k = int(np.nanargmax(leak))
    if not leak[k] > choice.tolerance:
        return False
    choice.restored = (f"leak {leak[k]:.1e} > tolerance {choice.tolerance:g} at "
                       f"{result.omega[k] / 2 / np.pi:.6g} Hz")
    return True
