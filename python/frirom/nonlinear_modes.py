"""Nonlinear modes by the extended periodic motion concept (EPMC; M. Krack, "Nonlinear
modal analysis of nonconservative systems: extension of the periodic motion concept",
J. Sound Vib. 338 (2015) 90-104): the backbone of a mode, its frequency and damping
ratio against its amplitude, from the one continuation driver (frirom_run, mode 3).

The EPMC makes the free, damped motion periodic with an artificial damping term that
feeds back the energy the structure dissipates:

    M x'' + (C - xi M) x' + K x + sum_g G_g^T f_g(G_g x) = f_static,

x = X_0 + a sum_h (Xc_h cos(h w t) + Xs_h sin(h w t)) with harmonic 1 mass-normalised
(Xc_1^T M Xc_1 + Xs_1^T M Xs_1 = 1: a is the modal amplitude) and its phase fixed
((M phi)^T Xs_1 = 0, phi the linear mode it starts from). The unknowns are the harmonics,
w and xi; the continuation parameter is log10 a. The damping ratio is xi / (2 w), and the
energy the structure dissipates per cycle is pi xi w a^2 sum_h h^2 (|Xc_h|_M^2 +
|Xs_h|_M^2).
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ._errors import ConvergenceError, ParameterError
from .model import Excitation, Model
from .options import SolverOptions

__all__ = ["Backbone", "nonlinear_mode", "linear_mode"]

#: largest model solved densely for its linear mode (scipy.linalg.eigh); above, ARPACK
_DENSE_EIG = 400


@dataclass
class Backbone:
    """The backbone of a nonlinear mode, one entry per point in the order of the
    continuation.

    Attributes
    ----------
    amplitude : ndarray
        (n,) modal amplitude a (harmonic 1 mass-normalised), sqrt(kg) m.
    omega : ndarray
        (n,) frequency, rad/s (``frequency``: Hz).
    xi : ndarray
        (n,) artificial damping, 1/s (``damping_ratio`` = xi / (2 omega)).
    energy : ndarray
        (n,) energy dissipated per cycle, J.
    harmonics : ndarray
        (n, n_dof, 2H+1) real harmonics [a0, a1, b1, ...] of every DoF.
    outputs : ndarray
        (n, n_out, 2H+1) the same at the outputs (``output_dofs``).
    states : ndarray
        (n, 3, n_elements) stick, slip, lift-off fractions of each contact element.
    omega0 : float
        The linear mode's natural frequency, rad/s (``start``: 'stuck' or 'free').
    status, message : str
        Why the run stopped ('done', 'max_points', 'failed', ...).
    """

    amplitude: np.ndarray
    omega: np.ndarray
    xi: np.ndarray
    energy: np.ndarray
    harmonics: np.ndarray
    outputs: np.ndarray
    output_dofs: np.ndarray
    states: np.ndarray
    mode: int
    start: str
    omega0: float
    H: int
    status: str = ""
    message: str = ""
    iterations: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    y: np.ndarray = field(default=None, repr=False)   #: (n, ny) the run's unknowns
    #: the continuation's state at each point (resume, frirom._run.Points): tangents
    #: (n, ny + 1), their scales (n,), the step after a checkpoint (n,; 0: none), the
    #: contact history each point leaves (n, nw)
    tans: np.ndarray = field(default=None, repr=False)
    yscales: np.ndarray = field(default=None, repr=False)
    ds_next: np.ndarray = field(default=None, repr=False)
    sliders: np.ndarray = field(default=None, repr=False)
    #: |log10 a_end - log10 a_start| of the run: the tangents' scale of log10 a (0: unknown)
    lscale: float = 0.0
    #: (n,) the viscous part of xi along harmonic 1, psi_1^H C psi_1 (psi_1 the harmonic 1
    #: per unit modal amplitude), 1/s: xi - xi_viscous is the contacts' share (None: not
    #: kept, files written before it)
    xi_viscous: np.ndarray = field(default=None, repr=False)
    #: a cyclic sector's mode: the nodal diameter of its harmonic 1 (None: not cyclic);
    #: amplitude, energy and harmonics are then the sector's (the rotor's amplitude is
    #: sqrt(N) times it, its energy N times)
    nodal_diameter: int | None = None
    #: the model DoFs of the rows of ``harmonics`` (None: every DoF, in order; a cyclic
    #: sector above 400 coordinates keeps its contact DoFs and outputs only)
    harmonic_dofs: np.ndarray | None = field(default=None, repr=False)

    def __len__(self) -> int:
        return int(self.amplitude.size)

    def checkpoint(self) -> dict | None:
        """Where a run continues exactly (``nonlinear_mode(resume=...)``): the last point
        that ends a segment (ds_next > 0), as {'index', 'y', 'lam', 'tan', 'yscale', 'ds',
        'n_points', 'sliders'}; None when there is none."""
        if self.ds_next is None:
            return None
        k = np.flatnonzero(self.ds_next > 0)
        if k.size == 0:
            return None
        i = int(k[-1])
        return {"index": i, "y": self.y[i], "lam": float(np.log10(self.amplitude[i])),
                "tan": self.tans[i], "yscale": float(self.yscales[i]),
                "ds": float(self.ds_next[i]), "n_points": i + 1,
                "sliders": self.sliders[i]}

    def head(self, n: int) -> "Backbone":
        """The first n points."""
        return _map_points(self, lambda v: v[:n])

    def extended(self, other: "Backbone") -> "Backbone":
        """These points followed by other's (a resumed run's)."""
        return _map_points(self, lambda v, w: np.concatenate([v, w]), other)

    @property
    def frequency(self) -> np.ndarray:
        """Frequency, Hz."""
        return self.omega / (2 * np.pi)

    @property
    def damping_ratio(self) -> np.ndarray:
        """Modal damping ratio xi / (2 omega)."""
        return self.xi / (2 * self.omega)

    def output_amplitude(self, j: int = 0) -> np.ndarray:
        """Amplitude of harmonic 1 at output j (m): hypot(a1, b1)."""
        return np.hypot(self.outputs[:, j, 1], self.outputs[:, j, 2])

    def forced_response(self, load, omega=None, points: int = 400):
        """The forced response near this mode's resonance under a harmonic-1 load, by
        single nonlinear mode theory (:func:`frirom.nlm_synthesis.forced_response`): an
        FRF at the backbone's outputs, in milliseconds."""
        from .nlm_synthesis import forced_response
        return forced_response(self, load, omega, points)

    def table(self) -> np.ndarray:
        """(n, 5 + n_out) columns: amplitude, frequency (Hz), damping ratio, energy per
        cycle (J), slip fraction (mean over the elements), harmonic-1 amplitude at each
        output."""
        slip = (self.states[:, 1, :].mean(axis=1) if self.states.shape[2]
                else np.zeros(self.amplitude.size))
        cols = [self.amplitude, self.frequency, self.damping_ratio, self.energy, slip]
        cols += [self.output_amplitude(j) for j in range(self.outputs.shape[1])]
        return np.column_stack(cols)


_POINT_FIELDS = ("amplitude", "omega", "xi", "energy", "harmonics", "outputs", "states",
                 "iterations", "y", "tans", "yscales", "ds_next", "sliders", "xi_viscous")


def _map_points(bb: Backbone, f, other: Backbone | None = None) -> Backbone:
    """A copy of bb with f applied to every per-point array (with other's alike)."""
    new = {}
    for name in _POINT_FIELDS:
        v = getattr(bb, name)
        w = None if other is None else getattr(other, name)
        if v is None or (other is not None and w is None):
            new[name] = None        # not kept by one of them (an older file)
            continue
        new[name] = f(v) if other is None else f(v, w)
    out = dataclasses.replace(bb, **new)
    if other is not None:
        out.status, out.message = other.status, other.message
    return out


def linear_mode(model: Model, mode: int = 0, start: str = "stuck") -> tuple[np.ndarray, float]:
    """The linear mode a nonlinear mode starts from: shape (mass-normalised) and natural
    frequency (rad/s) of K + G^T Ks G (start 'stuck': every contact element a linear spring
    of its law's stick stiffness) or of K ('free'), mode index counted from the lowest
    mode with a nonzero frequency."""
    if start not in ("stuck", "free"):
        raise ParameterError("start: expected 'stuck' or 'free'")
    K = model.K + model.stuck_stiffness() if start == "stuck" else model.K
    n = model.n_dof
    if not (isinstance(mode, (int, np.integer)) and 0 <= mode < n):
        raise ParameterError(f"mode: expected an index 0..{n - 1}")
    if n <= _DENSE_EIG:
        lam, phi = sla.eigh(np.asarray(sp.csr_matrix(K).todense()),
                            np.asarray(sp.csr_matrix(model.M).todense()))
    else:
        k = min(n - 2, mode + 8)
        lam, phi = spla.eigsh(sp.csc_matrix(K), k=k, M=sp.csc_matrix(model.M), sigma=0.0)
        order = np.argsort(lam)
        lam, phi = lam[order], phi[:, order]
    keep = lam > 1e-10 * max(abs(lam).max(), 1e-300)
    lam, phi = lam[keep], phi[:, keep]
    if mode >= lam.size:
        raise ParameterError(f"mode: index {mode}, the {start} structure has {lam.size} "
                             "modes with a nonzero frequency")
    near = [lam[j] for j in (mode - 1, mode + 1) if 0 <= j < lam.size]
    if near and min(abs(x / lam[mode] - 1) for x in near) < 1e-4:
        warnings.warn(f"mode {mode} of the {start} structure has a neighbour within 1e-4 "
                      "of its frequency (a symmetric pair): their nonlinear modes interact "
                      "1:1 and the EPMC may not converge; choose another mode or break the "
                      "symmetry", stacklevel=3)
    v = phi[:, mode]
    v = v / np.sqrt(v @ (model.M @ v))
    v = v * np.sign(v[np.argmax(np.abs(v))])
    return v, float(np.sqrt(lam[mode]))


def nonlinear_mode(model: Model, mode: int = 0, amplitudes=(1e-6, 1e-2), start: str = "stuck",
                   options: SolverOptions | None = None, outputs=None, static=None,
                   max_points: int | None = None, batch: int | None = None,
                   callback=None, resume: dict | None = None,
                   nodal_diameter: int | None = None) -> Backbone:
    """The backbone of a nonlinear mode by the extended periodic motion concept.

    The run object's mode 3 (frirom_run RUN_MODE) from modal amplitude amplitudes[0] to
    amplitudes[1] in log steps (harmonic 1 mass-normalised).

    Parameters
    ----------
    model : Model or CyclicModel
        Any contact law and damping. A cyclic sector (:class:`frirom.model.CyclicModel`):
        the mode of one nodal diameter as a travelling wave
        (:mod:`frirom.nonlinear_modes_cyclic`), condensed with each harmonic's receptance
        from the modes of its own nodal diameter; amplitude, energy and harmonics are
        sector 0's.
    mode : int
        Index of the linear mode it starts from, 0 = the lowest with a nonzero frequency
        (a cyclic sector: among those of its nodal diameter).
    amplitudes : (float, float)
        Modal amplitudes from and to, sqrt(kg) m.
    start : {'stuck', 'free'}
        The linear limit of that mode (:func:`linear_mode`).
    options : SolverOptions, optional
        Harmonics, samples, tolerances, steps and the formulation: 'condensed' (the
        default) takes the contact DoFs' harmonics as unknowns with receptances by modal
        superposition of the free structure's modes (all of them up to 400 DoFs: exact;
        above, ``options.modes`` of them), the artificial damping a change of each mode's
        damping term; 'banded' every DoF's harmonics (a dense Jacobian: small or reduced
        models). Hill's method is off.
    outputs : array_like of int or (n_out, n_dof) array, optional
        Reported in Backbone.outputs; default all DoFs up to 100, else the contact DoFs.
    static : array_like, optional
        (n_dof,) static load (a preload).
    max_points, batch : int, optional
        Points at most; points per segment (default ``options.batch``).
    callback : callable, optional
        Called with the Backbone so far after every segment.
    resume : dict, optional
        A :meth:`Backbone.checkpoint` of an earlier run with the same settings: the run
        continues from it as the uninterrupted run did, and the Backbone returned holds
        the points after it.

    nodal_diameter : int, optional
        A cyclic sector's nodal diameter k (default the model's engine_order): harmonic h
        on nodal diameter sign h k mod N. Not for a Model.

    Returns
    -------
    Backbone
    """
    from ._run import GOING, START_COLD, START_RESUME
    from .model import CyclicModel

    cyclic = isinstance(model, CyclicModel)
    if not (isinstance(model, Model) or cyclic):
        raise ParameterError("model: expected a frirom.Model or frirom.model.CyclicModel")
    if nodal_diameter is not None and not cyclic:
        raise ParameterError("nodal_diameter: only for a cyclic sector (CyclicModel)")
    a0, a1 = (float(a) for a in amplitudes)
    if not (a0 > 0 and a1 > 0 and a0 != a1 and np.isfinite(a0) and np.isfinite(a1)):
        raise ParameterError("amplitudes: two different positive finite modal amplitudes "
                             "expected")
    opts = options or SolverOptions()
    if not isinstance(opts, SolverOptions):
        raise ParameterError("options: expected a frirom.SolverOptions")
    if opts.harmonics < 1:
        raise ParameterError("options.harmonics: a nonlinear mode needs H >= 1")
    condensed = opts.formulation == "condensed" and bool(model.contacts)
    n_modes = opts.modes
    if cyclic and n_modes:
        raise ParameterError("options.modes: a cyclic model brings its own modes per nodal "
                             "diameter (frirom.reduction.cyclic.cyclic_model)")
    # a harmonic selection (harmonics_kept, where SolverOptions has it) is not for modes
    extra = {"harmonics_kept": None} if hasattr(opts, "harmonics_kept") else {}
    opts = dataclasses.replace(opts, formulation="banded", stability=False, modes=None,
                               parameter="frequency", selection=None, pairs=None,
                               krylov=False, receptances="auto", **extra)
    if max_points is not None:
        opts = dataclasses.replace(opts, max_points=int(max_points))
    if cyclic:
        from .nonlinear_modes_cyclic import open_cyclic
        packed, run, w0, kw = open_cyclic(model, mode, start, opts, outputs, static,
                                          nodal_diameter)

        def make(*pts):
            return _backbone_from(packed, w0, mode, start, *pts, **kw)
    else:
        packed, run, phi, w0 = _open(model, mode, start, opts, outputs, static,
                                     condensed=condensed, n_modes=n_modes)

        def make(*pts):
            return _backbone(model, packed, phi, w0, mode, start, *pts)
    if resume is None:
        run.start(START_COLD, np.log10(a0), np.log10(a1))
    else:
        run.start(START_RESUME, np.log10(a0), np.log10(a1), lam0=resume["lam"],
                  y0=resume["y"], tan0=resume["tan"], yscale=resume["yscale"],
                  ds=resume["ds"], n_before=int(resume["n_points"]),
                  sliders=resume["sliders"] if run.nw else None)
    ys, lams, xos, sts, its, cks = [], [], [], [], [], []
    status, message = GOING, ""
    k = int(batch or opts.batch)
    try:
        while status == GOING:
            res = run.advance(k)
            raise_info = res.info
            m = res.npts
            ys.append(res.ys[:, :m])
            lams.append(res.lams[:m])
            xos.append(res.xo[:, :, :m])
            sts.append(res.states[:, :, :m])
            its.append(res.iters[:m])
            cks.append((res.tans[:, :m], res.yscales[:m], res.ds_next[:m],
                        res.sliders[:, :m]))
            status, message = res.status, res.message
            if raise_info:
                raise ConvergenceError(res.msg)
            if callback is not None:
                callback(make(ys, lams, xos, sts, its, cks, status, message))
    finally:
        run.close()
    bb = make(ys, lams, xos, sts, its, cks, status, message)
    bb.lscale = abs(np.log10(a1) - np.log10(a0))
    if bb.amplitude.size == 0 and resume is None:
        raise ConvergenceError(f"nonlinear mode: no point converged ({message})")
    return bb


def receptance_modes(model: Model, n_modes: int | None = None):
    """(Phi (n_dof, nm) mass-normalised, omega (nm,) rad/s, zeta (nm,)) of the free
    structure (K, M) for the condensed mode run: all modes up to _DENSE_EIG DoFs, else the
    n_modes lowest; zeta_r = phi_r^T C phi_r / (2 omega_r) (exact for modal and Rayleigh
    damping, the diagonal part of another C)."""
    n = model.n_dof
    if n <= _DENSE_EIG and n_modes is None:
        lam, Phi = sla.eigh(np.asarray(sp.csr_matrix(model.K).todense()),
                            np.asarray(sp.csr_matrix(model.M).todense()))
    else:
        if n_modes is None:
            raise ParameterError(f"options.modes: the condensed nonlinear mode of a model "
                                 f"of {n} DoFs needs the number of modes of its receptances "
                                 f"(or options.formulation = 'banded')")
        k = int(n_modes)
        if not 1 <= k < n - 1:
            raise ParameterError(f"options.modes: expected 1..{n - 2}")
        lam, Phi = spla.eigsh(sp.csc_matrix(model.K), k=k, M=sp.csc_matrix(model.M),
                              sigma=0.0)
    if lam.min() <= 1e-10 * max(abs(lam).max(), 1e-300):
        raise ParameterError("the free structure (contacts open) has a rigid-body mode: "
                             "its receptances have no modal form; use options.formulation "
                             "= 'banded'")
    Phi = Phi / np.sqrt(np.einsum("ir,ir->r", Phi, model.M @ Phi))
    w = np.sqrt(lam)
    zeta = np.einsum("ir,ir->r", Phi, model.C @ Phi) / (2 * w)
    return Phi, w, np.maximum(zeta, 0.0)


def _open(model, mode, start, opts, outputs=None, static=None, condensed=False,
          n_modes=None):
    """The packed model, a mode run opened on it (frirom._run.Run, RUN_MODE) and the linear
    mode (phi, omega0) it starts from; opts: the mode run's SolverOptions (banded: the
    model's K, M, C go to Fortran as they are); condensed: by the free structure's modes
    (:func:`receptance_modes`). The run's outputs are all DoFs (the Backbone's harmonics);
    `outputs` selects from them (Backbone.outputs)."""
    from ._pack import _output_map, pack
    from ._run import Run
    phi, w0 = linear_mode(model, mode, start)
    modes = receptance_modes(model, n_modes) if condensed else None
    F = np.zeros((model.n_dof, 1))
    if static is not None:
        st = np.asarray(static, float).ravel()
        if st.size != model.n_dof or not np.all(np.isfinite(st)):
            raise ParameterError(f"static: {model.n_dof} finite values expected")
        F[:, 0] = st
    n = model.n_dof
    out, P = _output_map(outputs, n)
    if P is None:
        if out is None:
            out = np.arange(n) if n <= 100 else model.nonlinear_dofs()
        P = np.eye(n)[np.asarray(out, dtype=int)]
    packed = pack(model, Excitation(F), opts, np.arange(n))
    packed.select = P
    packed.select_dofs = np.asarray(out) if out is not None else np.zeros(0, int)
    run = Run(packed, mode_shape=(phi, w0, modes))
    packed.mode_ny = run.ny
    return packed, run, phi, w0


#: frirom._run stop reasons by name
def _status_name(status: int) -> str:
    from ._run import DONE, FAILED, GOING, LEFT_RANGE, MAX_POINTS, STALLED
    return {DONE: "done", MAX_POINTS: "max_points", LEFT_RANGE: "left_range",
            FAILED: "failed", STALLED: "stalled", GOING: "going"}.get(status, str(status))


def _backbone(model, packed, phi, w0, mode, start, ys, lams, xos, sts, its, cks, status,
              message) -> Backbone:
    """A Backbone from the run's points so far."""
    H = packed.H
    nc = 2 * H + 1

    def energy_viscous(omega, xi, a, Xp):
        M = model.M
        h2 = np.zeros(nc)
        h2[1::2] = h2[2::2] = np.arange(1, H + 1) ** 2
        mnorm = np.einsum("pic,pic->pc", Xp, np.stack([M @ Xp[p] for p in range(len(a))])
                          if len(a) else Xp)
        energy = np.pi * xi * omega * (mnorm * h2).sum(axis=1)
        C = model.C
        xi_visc = (np.einsum("pi,pi->p", Xp[:, :, 1], (C @ Xp[:, :, 1].T).T)
                   + np.einsum("pi,pi->p", Xp[:, :, 2], (C @ Xp[:, :, 2].T).T)) / np.maximum(
                       a, 1e-300) ** 2 if len(a) else np.zeros(0)
        return energy, xi_visc
    return _backbone_from(packed, w0, mode, start, ys, lams, xos, sts, its, cks, status,
                          message, n_out=model.n_dof, energy_viscous=energy_viscous)


def _backbone_from(packed, w0, mode, start, ys, lams, xos, sts, its, cks, status, message,
                   n_out, energy_viscous, nodal_diameter=None,
                   harmonic_dofs=None) -> Backbone:
    """A Backbone from a mode run's points so far: n_out, the run's outputs per point;
    energy_viscous(omega, xi, a, Xp) -> (energy per cycle, xi's viscous part)."""
    n, H = n_out, packed.H
    nc = 2 * H + 1
    ny = packed.mode_ny
    y = np.concatenate(ys, axis=1).T if ys else np.zeros((0, ny))
    a = 10.0 ** np.concatenate(lams) if lams else np.zeros(0)
    omega, xi = w0 * y[:, -2], w0 * y[:, -1]
    # the motion's harmonics at every DoF (the run's outputs)
    Xp = (np.concatenate(xos, axis=2).transpose(2, 0, 1) if xos else np.zeros((0, n, nc)))
    energy, xi_visc = energy_viscous(omega, xi, a, Xp)
    xo = np.einsum("oj,pjc->poc", packed.select, Xp)
    st = (np.concatenate(sts, axis=2).transpose(2, 0, 1) if sts else np.zeros((0, 3, 0)))
    st = st[:, :, :packed.ne_tot]
    tans = (np.concatenate([c[0] for c in cks], axis=1).T if cks else np.zeros((0, ny + 1)))
    ysc = np.concatenate([c[1] for c in cks]) if cks else np.zeros(0)
    dsn = np.concatenate([c[2] for c in cks]) if cks else np.zeros(0)
    sl = (np.concatenate([c[3] for c in cks], axis=1).T if cks
          else np.zeros((0, max(packed.nw, 1))))
    return Backbone(amplitude=a, omega=omega, xi=xi, energy=energy, harmonics=Xp,
                    outputs=xo, output_dofs=packed.select_dofs, states=st,
                    mode=int(mode), start=start, omega0=w0, H=H,
                    status=_status_name(status), message=message,
                    iterations=np.concatenate(its) if its else np.zeros(0, int), y=y,
                    tans=tans, yscales=ysc, ds_next=dsn, sliders=sl, xi_viscous=xi_visc,
                    nodal_diameter=nodal_diameter, harmonic_dofs=harmonic_dofs)
