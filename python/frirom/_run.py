"""The Fortran run object (module frirom_run) behind an opaque handle: the one continuation
driver of frirom, which C and legacy Fortran callers drive through the same calls
(frirom.h ``frirom_run_*``). Python owns the run's lifetime: it is closed when the
:class:`Run` is garbage-collected (``weakref.finalize``) or by :meth:`Run.close`.

A run is opened once per solve with the packed model (:mod:`frirom._pack`), started, and
advanced a batch of points at a time; peak refinement, the first point and the homotopy
start run on the same system, which is never set up again.
"""

from __future__ import annotations

import weakref
from typing import NamedTuple

import numpy as np

from . import _kernels
from ._errors import ParameterError, SizeError, int_constant, raise_for_status

#: run_start kinds, stop reasons, solve kinds and advice bits (frirom_run RUN_*, ADVISE_*)
START_COLD, START_POINT, START_RESUME = (int_constant(f"RUN_START_{k}")
                                         for k in ("COLD", "POINT", "RESUME"))
GOING, DONE, MAX_POINTS, LEFT_RANGE, FAILED, STALLED = (
    int_constant(f"RUN_{k}") for k in ("GOING", "DONE", "MAX_POINTS", "LEFT_RANGE", "FAILED",
                                       "STALLED"))
SOLVE_FIXED, SOLVE_STEP = int_constant("RUN_SOLVE_FIXED"), int_constant("RUN_SOLVE_STEP")
ADVISE = {k.lower(): int_constant(f"ADVISE_{k}")
          for k in ("TOL_STALL", "MAX_ITER", "DS_MIN", "SAMPLES")}
_N_ISET, _N_RSET = int_constant("N_ISET"), int_constant("N_RSET")
_N_TIMERS = int_constant("N_TIMERS")


def _settings_defaults() -> tuple[dict, tuple, tuple]:
    """The solver settings' defaults as Fortran defines them (frirom_run run_settings):
    name -> value, and the integer and real field names in Fortran's order."""
    iv, rv, names = _kernels.settings_defaults(_N_ISET, _N_RSET)
    names = names.decode().split()
    inames, rnames = tuple(names[:_N_ISET]), tuple(names[_N_ISET:])
    values = dict(zip(inames, (int(v) for v in iv)))
    values.update(zip(rnames, (float(v) for v in rv)))
    return values, inames, rnames


#: Solver defaults (frirom.solver.SolverOptions, frirom.h frirom_settings_default): one
#: place, Fortran's run_settings.
DEFAULTS, _INAMES, _RNAMES = _settings_defaults()


class Points(NamedTuple):
    """Points of one run_advance or run_solve call, in the full layout of the unknowns
    (ny = unknowns per point); arrays have room for more than npts points."""
    ys: np.ndarray          #: (ny, m) unknowns
    lams: np.ndarray        #: (m,) parameter
    tans: np.ndarray        #: (ny + 1, m) unit tangents in scaled variables
    iters: np.ndarray       #: (m,) Newton iterations
    xo: np.ndarray          #: (n_out, 2H+1, m) output harmonics
    states: np.ndarray      #: (3, n_elements, m) stick, slip, lift-off fractions
    hill_re: np.ndarray     #: (m,) largest real part of the Floquet exponents, 1/s
    sliders: np.ndarray     #: (max(nw, 1), m) the contact history each point leaves
    yscales: np.ndarray     #: (m,) the scale of each tangent
    leak: np.ndarray        #: (m,) a selection's leak
    ds_next: np.ndarray     #: (m,) the step after a checkpoint (0: no checkpoint)
    fold: np.ndarray        #: (m,) 1 where the tangent turned in the parameter
    npts: int
    status: int             #: GOING, DONE, MAX_POINTS, LEFT_RANGE, FAILED, STALLED
    fail_info: int          #: the failure's status code (FAILED)
    message: str            #: why the run stopped ('' while it goes on)
    advice: int             #: ADVISE bits of a failure at ds_min
    stalled: float          #: the failed corrector's |R|/rref (-1: not known)
    timings: np.ndarray     #: (N_TIMERS,) the call's timers and counters
    info: int               #: status code of the call itself (0: ok)
    msg: str


def _text(b) -> str:
    return (b.decode(errors="replace") if isinstance(b, bytes) else str(b)).strip()


class Run:
    """An open Fortran run on a packed model (frirom._pack._Packed)."""

    def __init__(self, packed, omega_fix: float = 0.0, mode_shape=None):
        """mode_shape: (phi (n_dof,), omega0 rad/s, modes) opens a nonlinear-mode run
        (EPMC, frirom_run RUN_MODE) starting from that linear mode: on all DoFs when modes
        is None, else condensed to the contact DoFs by modes = (Phi (n_dof, nm), omega
        (nm,) rad/s, zeta (nm,))."""
        modal = mode_shape is not None and mode_shape[2] is not None
        p, o, m = packed, packed.opts, packed.modes
        iset = np.array([_setting(o, n) for n in _INAMES], np.int32)
        rset = np.array([_setting(o, n) for n in _RNAMES], float)
        nl = (p.nl + 1).astype(np.int32) if p.nl.size else np.ones(1, np.int32)
        (kp, ki, kx), (mp, mi, mx), (cp, ci, cx), (gp, gi, gx) = p.K, p.M, p.C, p.G
        h, ny, nw, netot, info, msg = _kernels.frun_open(
            formulation=int_constant("RUN_CONDENSED" if (o.formulation == "condensed"
                                                         if mode_shape is None else modal)
                                     else "RUN_BANDED"),
            mode=int_constant("RUN_MODE" if mode_shape is not None else
                              "RUN_FREQUENCY" if o.parameter == "frequency" else "RUN_LOAD"),
            nh=p.H, nsamp=o.n_samples, ndof=p.n_dof, kp=kp, ki=ki, kx=kx, mp=mp, mi=mi,
            mx=mx, cp=cp, ci=ci, cx=cx, perm=p.perm, nl=nl, nnl=p.nl.size or 1,
            fe0=np.asfortranarray(p.fe0), fe1=np.asfortranarray(p.fe1), omega_fix=omega_fix,
            ginfo=p.ginfo, gp=gp, gi=gi, gx=gx, params=p.params, w0=p.w0,
            outdofs=(p.out_f + 1).astype(np.int32), tcontact=int(p.tcontact),
            krylov=int(o.krylov), sparse=int(p.sparse), iset=iset, rset=rset)
        raise_for_status(info, _text(msg))
        self.handle = int(h)
        self._close = weakref.finalize(self, _kernels.frun_close, self.handle)
        self.ny, self.nw, self.netot = int(ny), int(nw), int(netot)
        self.nout, self.nc = p.out_f.size, 2 * p.H + 1
        self.orbits = None
        if np.any(p.ginfo[0] < 0):
            if p.keep is not None and p.pair is not None and o.orbits:
                raise ParameterError("orbits: the AFT on one element per orbit takes the "
                                     "built-in laws only; a contact group has a user law "
                                     "(set orbits = false)")
            from .laws import solver_callback
            self._user_law = solver_callback(p.group_laws)   # kept alive with the run
            raise_for_status(*self._msg(_kernels.frun_set_user_law(
                self.handle, self._user_law.address, 0)))
        if getattr(p, "free", False):
            raise_for_status(*self._msg(_kernels.frun_set_free_bodies(self.handle, 1)))
        if mode_shape is not None:
            phi_m, w_m, z_m = (mode_shape[2] if modal else
                               (np.zeros((p.n_dof, 1)), np.ones(1), np.zeros(1)))
            ny, info, msg = _kernels.frun_set_nonlinear_mode(
                self.handle, np.asarray(mode_shape[0], float), float(mode_shape[1]),
                int(modal), np.asfortranarray(phi_m, dtype=float), np.asarray(w_m, float),
                np.asarray(z_m, float))
            raise_for_status(info, _text(msg))
            self.ny = int(ny)
        if m.nmodes:
            raise_for_status(*self._msg(_kernels.frun_set_modes(
                self.handle, 0, np.asfortranarray(m.phi),
                np.zeros((1, m.nmodes, 1), complex), m.omega[:, None], m.zeta[:, None],
                nh1=1)))
        if m.hmodes:
            raise_for_status(*self._msg(_kernels.frun_set_modes(
                self.handle, 1, np.zeros((p.n_dof, m.hmodes)), np.asfortranarray(m.psi),
                np.asfortranarray(m.omega_h), np.asfortranarray(m.zeta_h))))
        if p.keep is not None:
            nnl = max(p.nl.size, 1)
            pair = (np.zeros((nnl, p.H + 1), np.int32) if p.pair is None
                    else p.pair.astype(np.int32))
            orb, info, msg = _kernels.frun_set_selection(
                self.handle, np.asfortranarray(p.keep.astype(np.int32)),
                np.asfortranarray(pair), int(p.pair is not None),
                int(p.pair is not None and o.orbits), p.orbit_tol)
            raise_for_status(info, _text(msg))
            if p.pair is not None and o.orbits:
                self.orbits = (int(orb[0]), float(orb[1]))

    @staticmethod
    def _msg(res) -> tuple[int, str]:
        info, msg = res
        return int(info), _text(msg)

    def _sliders(self, sliders) -> tuple[np.ndarray, int]:
        if sliders is None or self.nw == 0:
            return np.zeros(max(self.nw, 1)), 0
        return np.ascontiguousarray(sliders, dtype=float).ravel(), 1

    def start(self, kind: int, lam_start: float, lam_end: float, lam0: float | None = None,
              y0=None, tan0=None, yscale: float = 0.0, ds: float = 0.0,
              lscale_old: float = 0.0, n_before: int = 0, sliders=None,
              held_lu=None) -> np.ndarray:
        """run_start; returns the call's timings; raises on failure (no first point).
        held_lu: a checkpoint's :meth:`lu_state` (resume: the LU is made again)."""
        sl, has = self._sliders(sliders)
        lu = np.zeros(0) if held_lu is None else np.asarray(held_lu, float).ravel()
        if lu.size and lu.size != self.lu_size:
            raise SizeError(f"held_lu: {self.lu_size} values expected (this run's "
                            f"Run.lu_state), got {lu.size}: a checkpoint of another model?")
        timings, info, msg = _kernels.frun_start(
            self.handle, kind, lam_start, lam_end, lam_start if lam0 is None else lam0,
            np.zeros(self.ny) if y0 is None else np.asarray(y0, float),
            np.zeros(self.ny + 1) if tan0 is None else np.asarray(tan0, float),
            yscale, ds, lscale_old, n_before, sl, has, lu, _N_TIMERS)
        raise_for_status(info, _text(msg))
        return timings

    @property
    def lu_size(self) -> int:
        """Length of :meth:`lu_state`."""
        return int(_kernels.frun_lu_size(self.handle))

    def lu_state(self) -> np.ndarray:
        """What the LU the continuation holds depends on (frirom_run run_lu_state):
        [held, single, parameter, counters..., unknowns, sliders]; [0, ...]: none."""
        v, info, msg = _kernels.frun_lu_state(self.handle, self.lu_size)
        raise_for_status(info, _text(msg))
        return v

    def advance(self, k: int) -> Points:
        """run_advance: up to k more points."""
        r = _kernels.frun_advance(self.handle, k, k + 1, self.ny, self.nout, self.nc,
                                  max(self.netot, 1), max(self.nw, 1), _N_TIMERS)
        *head, message, advice, stalled, timings, info, msg = r
        return Points(*head, message=_text(message), advice=int(advice),
                      stalled=float(stalled), timings=timings, info=int(info), msg=_text(msg))

    def solve(self, kind: int, lam0: float, y0, tan0=None, yscale: float = 0.0,
              ds: float = 0.0, sliders=None, stability: bool = False,
              cold: bool = False) -> Points:
        """run_solve: one corrector (SOLVE_FIXED at lam0, or SOLVE_STEP of ds from the
        point along tan0), as a one-point Points (npts 0 when it failed: info, msg)."""
        sl, has = self._sliders(sliders)
        (y, lam, tan, iters, xo, states, hill, slo, ysc, leak, timings, info,
         msg) = _kernels.frun_solve(
            self.handle, kind, lam0, np.asarray(y0, float),
            np.zeros(self.ny + 1) if tan0 is None else np.asarray(tan0, float), yscale, ds,
            sl, has, int(stability), int(cold), self.nout, self.nc, max(self.netot, 1),
            _N_TIMERS)
        ok = int(info) == 0
        return Points(ys=y[:, None], lams=np.array([lam]), tans=tan[:, None],
                      iters=np.array([iters]), xo=xo[:, :, None], states=states[:, :, None],
                      hill_re=np.array([hill]), sliders=slo[:, None],
                      yscales=np.array([ysc]), leak=np.array([leak]),
                      ds_next=np.zeros(1), fold=np.zeros(1, np.int32), npts=int(ok),
                      status=DONE if ok else FAILED, fail_info=int(info), message=_text(msg),
                      advice=0, stalled=-1.0, timings=timings, info=int(info),
                      msg=_text(msg))

    def close(self) -> None:
        """Free the Fortran run now (also done when the object is collected)."""
        self._close()


def _setting(opts, name: str):
    """SolverOptions' value of a run_settings field (Fortran's int/real encodings)."""
    if name == "samples":
        return opts.samples or 0
    if name == "formulation":
        return int_constant("RUN_CONDENSED" if opts.formulation == "condensed"
                            else "RUN_BANDED")
    if name == "reuse_jacobian":
        return int(opts.reuse_jacobian)
    if name == "stability":     # 2: Hill's whole strip on reduced models (hill_strip)
        return 2 if opts.stability == "strip" else int(bool(opts.stability))
    v = getattr(opts, name)
    return int(v) if isinstance(v, (bool, np.bool_)) else v
