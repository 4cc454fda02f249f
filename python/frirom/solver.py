"""Harmonic balance solver: one frequency, or pseudo-arc-length continuation in frequency
or in a load factor. Python packs the model into arrays; Newton, continuation, AFT and the
linear algebra run in Fortran (frirom_hbm, frirom_newton, frirom_banded).

Formulations (same answer, different cost):

* ``'condensed'`` (Eq. 5-9): unknowns are the harmonics of the contact DoFs only; for
  models with few contact DoFs (reduced models).
* ``'banded'``: all DoFs x harmonics in reverse Cuthill-McKee order, banded LU; for
  unreduced FE and lumped models with many contact DoFs.

A :class:`frirom.model.CyclicModel` (one sector of a tuned rotor under an engine-order
travelling wave) is solved in the condensed formulation with receptances from the modes of
each harmonic's own nodal diameter (time harmonic h on h EO mod N): exact for the
travelling-wave response of the whole rotor, at the cost of one sector.
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ._errors import (CODES, MAX_HARMONICS, MAX_OMEGA, ParameterError, SizeError, check_integer,
                      check_number, raise_for_status, samples_problem)
from ._pack import (HILL_MAX, MODES_MAX, ORBIT_TOL, TIMER_NAMES,  # noqa: F401 - public here
                    kept_unknowns)
from ._pack import _Packed, add_timings, pack
from . import _run
from ._run import DEFAULTS
from .harmonics import default_samples
from .model import CyclicModel, Excitation, Model
from ._peak import refine_peaks
from .results import FRF, FRFPoint

#: Names of the formulations (SolverOptions.formulation).
FORMULATIONS = ("condensed", "banded")

#: Largest leak of a travelling-wave selection (FRFPoint.leak) a run accepts without a
#: warning. A tuned rotor leaks at round-off: 5e-10 on the coarse flange in stick (the
#: cyclic symmetry of the mesh and matrices to their digits), 2.5e-9 with slip and
#: lift-off (the closed-cycle iteration of the slipping elements). A force off the
#: selection of 1e-6 of those on it moves the response by about that fraction (times the
#: amplification of an off-selection resonance), far below the 1e-3 the paper's
#: comparisons resolve; a changed preload or stiffness at one of 12 pairs leaks 4e-2 or
#: more, and so do the sliders a re-stuck flange keeps from slipping (4e-3, static part).
LEAK_TOL = 1e-6


def warn_leak(leak: float, omega: float, stacklevel: int, what: str = "") -> None:
    """Warn (RuntimeWarning) when a travelling-wave selection's leak (FRFPoint.leak) is
    above LEAK_TOL; omega: rad/s, where; stacklevel: 1 = the caller of warn_leak, 2 = its
    caller, and so on; what: names the point when it is not one of the run's."""
    if leak > LEAK_TOL:
        warnings.warn(f"frirom: the travelling-wave selection leaks: contact forces off "
                      f"the selection reach {leak:.2g} of those on it at "
                      f"{omega / 2 / np.pi:.6g} Hz{f' ({what})' if what else ''} (tolerance "
                      f"{LEAK_TOL:g}); the rotor, its "
                      "contacts, its load or the contact history carried from point "
                      "to point (sliders frozen at different phases) are not a "
                      "travelling wave there, and the selected solution is not the "
                      "full one (solve without the selection to see how far)",
                      RuntimeWarning, stacklevel=stacklevel + 1)


@dataclass
class SolverOptions:
    """Settings of the harmonic balance solver.

    Attributes
    ----------
    harmonics : int
        H: the response keeps harmonics 0..H (2H+1 real coefficients per DoF).
    samples : int or None
        AFT time samples per period, >= 2H+1; None: the default of
        :func:`frirom.harmonics.default_samples` (:attr:`n_samples`).
    formulation : {'condensed', 'banded'}
        'condensed' (Eq. 5-9): unknowns are the contact DoFs' harmonics, receptances from
        the linear part; 'banded': all DoFs x harmonics, banded LU in RCM order.
    tol_residual : float
        Newton converges when ||R|| is below this times the size of the terms of R.
    tol_update : float
        ... and ||dy|| below this times ||y|| (both tests relative: the same in N and mN).
    tol_stall : float
        After max_iter iterations a residual stagnating below this is accepted (a contact
        state changing inside one time sample makes R non-differentiable); 0 disables.
    max_iter : int
        Newton iterations per corrector.
    ds, ds_min, ds_max : float
        Initial, smallest and largest arc-length step, in scaled variables (unknowns /
        |first point|, parameter / range): dimensionless.
    max_points : int
        Points per run; a run that reaches it stops with ``complete`` False (a run resumed
        from a checkpoint counts the points made before it).
    parameter : {'frequency', 'load'}
        The continuation parameter: frequency omega (rad/s) or a load factor (set by
        :func:`frf`, :func:`load_curve` and :func:`solve_point` themselves).
    reuse_jacobian : bool
        Keep a factorisation while Newton contracts by a factor 10 per iteration (a
        corrector that fails with reuse is retried with a fresh Jacobian every iteration).
    stability : bool
        Hill's method at every point: the Floquet exponents in the strip |Im s| <= omega/2
        (and the centred copies of modes above (H + 1/2) omega); a dense eigen-solve of
        size 2 n_dof (2H+1) up to :data:`HILL_MAX`, shift-invert Arnoldi about s = 0 above
        (strip only).
    history : bool
        Carry the contact history along the curve: each point starts its sliders where the
        previous point's closed cycles left them. False restarts every point from the
        model's w0, which makes a contact stuck all cycle snap back to it.
    modes : int or None
        Condensed formulation only: receptances by superposition of this many lowest modes
        (mass-normalised; damping ratios from Damping.modal or the diagonal of
        Phi^T C Phi) instead of factorising the dynamic stiffness at every frequency
        (truncation: no residual flexibility). None: exact receptances.
    batch : int
        Points per call into Fortran: how often `sink` receives points (and where a
        resumed run may start); the points themselves do not depend on it.
    refine_peak : bool
        Frequency runs: solve each output's peak on the curve between the points around
        the largest one (FRF.peaks, FRF.peak; per resonance one to three corrector solves
        on a smooth peak, about ten at a corner, shared by the outputs peaking there).
    coordinates : {'auto', 'dofs', 'contact'}
        Condensed formulation: unknowns are the harmonics of the contact DoFs ('dofs') or
        of the contact elements' local relative displacements G x ('contact'); 'auto' takes
        the shorter ('dofs' when stability is asked: Hill's method needs them).
    receptances : {'auto', 'modes', 'factorization', 'sparse'}
        Condensed formulation, without `modes`: how the receptances T D_h^-1 T^T are
        found at each frequency. 'modes': from all modes of the model, one dense
        eigen-decomposition (exact; needs damping that the modes diagonalise: modal,
        Rayleigh, none); 'factorization': a banded LU of the dynamic stiffness per
        harmonic (any damping); 'sparse': a sparse LU (MUMPS) per harmonic (any
        damping; large unreduced FE). 'auto': 'modes' for a model of at most
        :data:`MODES_MAX` DoFs whose band LUs over an FRF (``_pack.EIG_EVALS``
        evaluations) would cost more than one dense eigen-solve (a reduced model) and
        whose damping the modes diagonalise, else 'sparse' when the band LU would cost
        more than ``_pack.SPARSE_FLOPS`` per harmonic, else 'factorization'. The choice is in
        ``FRF.solver_info``.
    krylov : bool
        Condensed formulation: solve with each new Jacobian by GMRES preconditioned by
        the LU of an earlier one, factorising again only when GMRES needs many
        iterations (same answers, 2-10x fewer dense LUs). Off by default. Measured at ROM_I
        size (2 800 unknowns, cases/bench/condensed.py): GMRES iterations are memory
        bound (~25 ms each, 2 cores shared) and the stale preconditioner needs ~8-18 per
        solve, so the FRF takes as long as with a new LU per Jacobian.
    selection : ndarray or None
        (n_dof, H+1) bool: a travelling-wave selection of the condensed unknowns. Harmonic
        h of nonlinear DoF j is solved for only where ``selection[j, h]``; the others are
        held at zero and their equations dropped. Exact for a tuned rotor under an
        engine-order travelling wave on multi-stage coordinates
        (:func:`frirom.reduction.multistage.travelling_wave_selection`), several times
        fewer unknowns. Each point reports its leak (``FRFPoint.leak``: contact forces off
        the selection over those on it); a run warns above :data:`LEAK_TOL`. Needs the
        condensed formulation in the nonlinear DoFs, no Krylov solves and no stability.
    pairs : ndarray or None
        (n_dof, H+1) int, with ``selection``: the wave's direction, ``pairs[j, h] = s (k +
        1)`` ties harmonic h of nonlinear DoF j to that of k by x_k,sin = s x_j,cos and
        x_k,cos = -s x_j,sin, and each pair's four unknowns become two
        (:func:`frirom.reduction.multistage.travelling_wave_pairs`); 0: no pair. Exact
        when the selection is, for one travelling direction; the leak then also counts
        the other direction.
    orbits : bool
        With ``pairs``: Newton's evaluations run the contact law (AFT) on one contact
        element per orbit, the elements whose motion on the wave is another's turned in
        time (one sector's copies; found from the model, matched to :data:`ORBIT_TOL`,
        with equal parameters), and the Jacobian from those alone (50x less AFT and
        assembly on 50 sectors). Every element still runs at the points kept (contact
        history, states, outputs), where the leak also counts what the orbits left out:
        the AFT samples a turned cycle at other instants, and a carried history need not
        be a wave. No effect without pairs.
    """

    # the defaults of Fortran's run_settings (frirom._run.DEFAULTS), the one place they
    # are written: C callers get the same from frirom_settings_default
    harmonics: int = DEFAULTS["harmonics"]
    samples: int | None = None
    formulation: str = "condensed"
    tol_residual: float = DEFAULTS["tol_residual"]
    tol_update: float = DEFAULTS["tol_update"]
    tol_stall: float = DEFAULTS["tol_stall"]
    max_iter: int = DEFAULTS["max_iter"]
    ds: float = DEFAULTS["ds"]
    ds_min: float = DEFAULTS["ds_min"]
    ds_max: float = DEFAULTS["ds_max"]
    max_points: int = DEFAULTS["max_points"]
    parameter: str = "frequency"
    reuse_jacobian: bool = bool(DEFAULTS["reuse_jacobian"])
    stability: bool = bool(DEFAULTS["stability"])
    history: bool = bool(DEFAULTS["history"])
    modes: int | None = None
    batch: int = DEFAULTS["batch"]
    refine_peak: bool = True
    coordinates: str = "auto"
    receptances: str = "auto"
    krylov: bool = False
    selection: np.ndarray | None = field(default=None, repr=False)
    pairs: np.ndarray | None = field(default=None, repr=False)
    orbits: bool = True

    def check(self) -> None:
        """Raise ParameterError naming the first invalid field."""
        check_integer("options.harmonics", self.harmonics, minimum=0, maximum=MAX_HARMONICS)
        if self.samples is not None and samples_problem(self.harmonics, self.samples):
            raise ParameterError(f"options.samples: expected "
                                 f"{samples_problem(self.harmonics, self.samples)}, got "
                                 f"{self.samples!r}")
        for nm in ("max_iter", "max_points", "batch"):
            check_integer(f"options.{nm}", getattr(self, nm), minimum=1, maximum=2**31 - 1)
        if self.formulation not in FORMULATIONS:
            raise ParameterError(f"options.formulation: expected one of "
                                 f"{sorted(FORMULATIONS)}, got {self.formulation!r}")
        if self.parameter not in ("frequency", "load"):
            raise ParameterError("options.parameter: expected 'frequency' or 'load'")
        if not (np.isfinite(self.tol_stall) and self.tol_stall >= 0):
            raise ParameterError("options.tol_stall: expected a number >= 0")
        for nm in ("tol_residual", "tol_update", "ds", "ds_min", "ds_max"):
            v = getattr(self, nm)
            if not (np.isfinite(v) and v > 0):
                raise ParameterError(f"options.{nm}: expected a positive number, got {v}")
        if self.ds_min > self.ds_max:
            raise ParameterError("options.ds_min must not exceed options.ds_max")
        if self.ds > self.ds_max:
            raise ParameterError(f"options.ds: expected a first step at most ds_max = "
                                 f"{self.ds_max:g}, got {self.ds:g}")
        if self.modes is not None and (self.modes < 1 or self.formulation != "condensed"):
            raise ParameterError("options.modes: a positive number of modes, with "
                                 "formulation 'condensed'")
        for nm in ("refine_peak", "krylov", "stability", "history", "reuse_jacobian",
                   "orbits"):
            if not isinstance(getattr(self, nm), (bool, np.bool_)):
                raise ParameterError(f"options.{nm}: expected true or false, got "
                                     f"{getattr(self, nm)!r}")
        if self.coordinates == "contact" and self.stability:
            raise ParameterError("options.coordinates: 'contact' cannot be used with "
                                 "stability (Hill's method needs the contact DoFs)")
        if self.selection is not None:
            for bad, why in ((self.formulation != "condensed", "the 'condensed' formulation"),
                             (self.stability, "stability = false (Hill's method would see "
                                              "only perturbations inside the selection)"),
                             (self.krylov, "krylov = false (direct solves)"),
                             (self.coordinates == "contact", "coordinates 'dofs' or 'auto'")):
                if bad:
                    raise ParameterError(f"options.selection: a travelling-wave selection "
                                         f"needs {why}")
        if self.pairs is not None and self.selection is None:
            raise ParameterError("options.pairs: needs options.selection")
        for nm, allowed in (("coordinates", ("auto", "dofs", "contact")),
                            ("receptances", ("auto", "modes", "factorization", "sparse"))):
            if getattr(self, nm) not in allowed:
                raise ParameterError(f"options.{nm}: expected one of {list(allowed)}, got "
                                     f"{getattr(self, nm)!r}")

    @property
    def n_samples(self) -> int:
        """AFT time samples per period actually used: `samples`, else the measured default
        :func:`frirom.harmonics.default_samples` (1e-4 relative on a friction resonance)."""
        return self.samples or default_samples(self.harmonics)


@dataclass
class _Continuation:
    """The Python side of one continuation run from lam_start to lam_end on the Fortran
    run object (frirom._run.Run, the one driver): :meth:`start` starts it (the first
    point, a point or a checkpoint), :meth:`batches` advances it `batch` points at a
    time and hands each point to `sink`, :meth:`finish` makes the FRF."""

    packed: _Packed
    lam_start: float
    lam_end: float
    sink: Callable[[FRFPoint], None] | None
    points: list = field(default_factory=list)
    timings: dict = field(default_factory=dict)
    n_before: int = 0             # points a resumed run made before (count to max_points)
    leak_before: tuple | None = None  # their largest leak and its omega (FRFWriter file)
    t0: float = 0.0               # perf_counter at the start of the current call

    @property
    def lscale(self) -> float:
        return abs(self.lam_end - self.lam_start) or 1.0

    @property
    def lam_lo(self) -> float:
        return self.lam_start - 0.02 * (self.lam_end - self.lam_start)

    def start(self, start, H_start) -> None:
        """From nothing, or from a saved point (FRFPoint or dict): resume from its tangent,
        or solve at its parameter first (no tangent, other H or unknown history). A
        checkpoint (dict with 'ds', the step the run continued with, and 'n_points', the
        points made up to it; FRFWriter.resume_point) continues exactly as the
        uninterrupted run did: same step, arc-length scale, history and call boundaries;
        its 'lscale' (parameter range of the run that wrote it) rescales the tangent when
        the range was extended since."""
        p = self.packed
        run = p.run
        self.t0 = time.perf_counter()
        if start is None:
            timings = run.start(_run.START_COLD, self.lam_start, self.lam_end)
        else:
            if isinstance(start, FRFPoint):
                start = {"parameter": start.parameter, "unknowns": start.unknowns,
                         "tangent": start.tangent, "yscale": start.yscale,
                         "slider": start.slider}
            sliders = p.checked_slider(start.get("slider"))
            y0 = p.pad_start(start["unknowns"], H_start if H_start is not None else p.H)
            lam0 = float(start.get("parameter", start.get("omega")))
            tan = start.get("tangent")
            # without the history the point was computed with (a file from before it was
            # kept), the saved point need not solve the equations: re-solve it first; a
            # tangent without a scale (a solve at fixed parameter: solve_point, a run's
            # first point) is in no scale to resume in: from the point, a new tangent
            unknown_history = p.nw and p.opts.history and start.get("slider") is None
            if tan is None or not start.get("yscale") or H_start not in (None, p.H) or \
                    unknown_history:
                timings = run.start(_run.START_POINT, self.lam_start, self.lam_end,
                                    lam0=lam0, y0=y0, sliders=sliders)
            else:
                tan = np.asarray(tan, dtype=float)
                if tan.size != p.ny + 1:
                    raise SizeError("start.tangent: size does not match the unknowns")
                self.n_before = int(start.get("n_points", 0))
                timings = run.start(_run.START_RESUME, self.lam_start, self.lam_end,
                                    lam0=lam0, y0=y0, tan0=tan, yscale=float(start["yscale"]),
                                    ds=float(start.get("ds") or 0.0),
                                    lscale_old=float(start.get("lscale") or 0.0),
                                    n_before=self.n_before, sliders=sliders)
            # the stored points' worst leak, whichever way the run goes on from them
            self.leak_before = start.get("leak")
        add_timings(self.timings, timings)

    def _emit(self, p: FRFPoint) -> None:
        if self.sink is not None:
            self.sink(p)

    def batches(self) -> tuple[bool, str]:
        """Advance until the run stops; returns (complete, message)."""
        run, o = self.packed.run, self.packed.opts
        while True:
            res = run.advance(o.batch)
            t_call = time.perf_counter() - self.t0
            self.t0 = time.perf_counter()
            add_timings(self.timings, res.timings)
            if res.info != 0:       # no point at all
                raise_for_status(res.info, res.msg + self._advice(res))
            for pt in self.packed.points(res, t_call):
                self.points.append(pt)
                self._emit(pt)
            if res.status == _run.GOING:
                continue
            if res.status == _run.DONE:
                return True, ""
            if res.status == _run.FAILED:
                return False, self._stopped(res)
            return False, res.message

    def _advice(self, res) -> str:
        if res.fail_info == CODES["FRIROM_ERR_CONT"] and self.packed.nw:
            return _contact_advice(self.packed.opts, res.advice, res.stalled)
        return ""

    def _stopped(self, res) -> str:
        """Explain a run Fortran stopped, with the advice that would change its outcome."""
        message = res.message.strip() + self._advice(res)
        warnings.warn(f"frirom: continuation stopped early, {len(self.points)} points kept: "
                      f"{message}", RuntimeWarning, stacklevel=5)
        return message

    def finish(self, complete: bool, message: str) -> FRF:
        p, pts = self.packed, self.points
        name = "omega" if p.opts.parameter == "frequency" else "load"
        out = FRF.from_points(pts, p.outputs, p.group_names, parameter_name=name,
                              complete=complete, message=message,
                              stability_computed=p.stability)
        out.timings = self.timings
        out.solver_info = p.info
        if p.keep is not None and (pts or self.leak_before):
            k = int(np.argmax(out.leak)) if pts else 0
            worst, at = (float(out.leak[k]), pts[k].omega) if pts else (-1.0, 0.0)
            if self.leak_before is not None and self.leak_before[0] > worst:
                worst, at = self.leak_before      # a point stored before the resume
            out.solver_info += f"; leak max {worst:.1e}"
            warn_leak(worst, at, stacklevel=4)
        return out


def _contact_advice(opts: SolverOptions, bits: int, stalled: float) -> str:
    """What to change after a continuation with friction contacts stopped at ds_min: the
    settings the driver found would change the outcome (frirom_run run_advice's bits,
    from the options in use and the last corrector's stalled |R|/rref).

    The AFT samples the contacts at N points per period; a contact state switching at one
    of them makes the equations piecewise smooth and Newton can stall at a residual below
    the sampling error (which falls like 1/N^2). Advised: tol_stall above a stalled
    residual below 1/N^2 (such a point is then accepted); max_iter when the residual had
    met tol_residual and only the update test was missing; ds_min when it is so large
    that the step could not shrink much; the default N for this H when fewer samples are
    in use.
    """
    N = opts.n_samples
    default_N = dataclasses.replace(opts, samples=None).n_samples
    tips = []
    if bits & _run.ADVISE["tol_stall"]:
        tips.append(f"tol_stall = {float(f'{2.0 * stalled:.0e}'):g} (now "
                    f"{opts.tol_stall:g}): a corrector stalling below it is accepted (the "
                    f"last one stalled at |R|/rref = {stalled:.2e})")
    if bits & _run.ADVISE["max_iter"]:
        tips.append(f"max_iter = {2 * opts.max_iter} (now {opts.max_iter}): the last "
                    "corrector had met tol_residual and missed only the update test")
    if bits & _run.ADVISE["ds_min"]:
        tips.append(f"ds_min = {opts.ds_min / 100:g} (now {opts.ds_min:g}): the step "
                    "could not shrink further")
    if bits & _run.ADVISE["samples"]:
        tips.append(f"samples = {default_N} (the default for H = {opts.harmonics}; now "
                    f"{N}): smaller corners where a contact state switches")
    text = (f" [N = {N} AFT samples per period (samples = {opts.samples}); where a "
            "contact state switches at one of them the curve has a corner")
    if tips:
        return text + "; try " + "; or ".join(tips) + "]"
    return text + "]"


def _run_curve(packed: _Packed, lam_start, lam_end, sink, start, H_start) -> FRF:
    run = _Continuation(packed, lam_start, lam_end, sink)
    run.start(start, H_start)
    complete, message = run.batches()
    out = run.finish(complete, message)
    if packed.opts.refine_peak and packed.opts.parameter == "frequency" and run.points:
        out.peaks, solved = refine_peaks(packed, run.points, run.lscale)
        if packed.keep is not None:
            k = int(np.argmax([q.leak for q in solved])) if solved else -1
            if k >= 0:
                warn_leak(solved[k].leak, solved[k].omega, stacklevel=3,
                          what="a peak solved between points")
    return out


def frf(model: Model | CyclicModel, excitation: Excitation, omega_start: float,
        omega_end: float, options: SolverOptions | None = None, outputs=None, sink=None,
        start=None, start_harmonics: int | None = None) -> FRF:
    """Forced response from omega_start to omega_end by pseudo-arc-length continuation in
    frequency, through turning points.

    Parameters
    ----------
    model : Model or CyclicModel
    excitation : Excitation
    omega_start, omega_end : float
        Frequency range, rad/s (either direction).
    options : SolverOptions, optional
        Its ``parameter`` is set to 'frequency'.
    outputs : array_like of int, or (n_out, n_dof) array, optional
        DoF indices (0-based) whose harmonics are kept, or a matrix P whose rows give each
        output as P x (physical DoFs through a reduction basis); default all DoFs up to
        100, else the contact DoFs.
    sink : callable, optional
        ``sink(point)`` receives every converged FRFPoint as it comes.
    start : FRFPoint or dict, optional
        Resume from a saved point: {'parameter' (or 'omega'), 'unknowns', 'tangent',
        'slider', 'yscale'}; a checkpoint (FRFWriter.resume_point) adds 'ds' and
        'n_points' (and 'lscale' when the range was extended) and continues exactly as the
        uninterrupted run did.
    start_harmonics : int, optional
        H of the start's unknowns when it differs from options.harmonics: they are padded
        or cut and re-solved first.

    Returns
    -------
    FRF
        A run that cannot continue returns the points made so far (``complete`` False,
        ``message`` says why) and warns.
    """
    options = options or SolverOptions()
    if options.parameter != "frequency":
        options = dataclasses.replace(options, parameter="frequency")
    for nm, v in (("omega_start [rad/s]", omega_start), ("omega_end [rad/s]", omega_end)):
        check_number(nm, v, positive=True, maximum=MAX_OMEGA)
    if omega_start == omega_end:
        raise ParameterError("omega_start and omega_end must differ")
    packed = pack(model, excitation, options, outputs)
    return _run_curve(packed, float(omega_start), float(omega_end), sink, start,
                      start_harmonics)


def load_curve(model: Model | CyclicModel, excitation: Excitation, omega: float,
               scale_start: float, scale_end: float, options: SolverOptions | None = None,
               outputs=None, sink=None, start=None, part: str = "dynamic") -> FRF:
    """Continuation in a load factor s at a fixed frequency: the excitation is
    F_other + s F_part.

    Parameters
    ----------
    omega : float
        Frequency, rad/s.
    scale_start, scale_end : float
        Range of the load factor s (dimensionless).
    part : {'dynamic', 'static'}
        The scaled part: harmonics >= 1 (excitation level) or harmonic 0 (preload).
    model, excitation, options, outputs, sink, start
        As in :func:`frf` (``options.parameter`` is set to 'load').

    Returns
    -------
    FRF
        ``parameter`` holds s, ``omega`` the fixed frequency.
    """
    options = options or SolverOptions()
    options = dataclasses.replace(options, parameter="load")
    check_number("omega [rad/s]", omega, positive=True, maximum=MAX_OMEGA)
    check_number("scale_start", scale_start)
    check_number("scale_end", scale_end)
    if scale_start == scale_end:
        raise ParameterError("scale_start and scale_end must differ")
    packed = pack(model, excitation, options, outputs, load_part=part)
    packed.omega_fix = float(omega)
    return _run_curve(packed, float(scale_start), float(scale_end), sink, start, None)


def solve_point(model: Model | CyclicModel, excitation: Excitation, omega: float,
                options: SolverOptions | None = None, outputs=None, start=None,
                start_harmonics: int | None = None) -> FRFPoint:
    """The periodic response at one frequency, by Newton's method.

    Newton starts from the linear solution, or from `start`; if Newton from the linear
    solution fails, the point is reached by continuation in the excitation level.

    Parameters
    ----------
    omega : float
        Frequency, rad/s.
    start : FRFPoint or dict, optional
        'unknowns' of a solution with `start_harmonics` harmonics (default
        options.harmonics; padded with zeros or cut) and/or 'slider', the contact history
        to start from (FRFPoint.slider). Without 'unknowns' Newton starts from the linear
        solution; without 'slider' the model's w0 is the history.
    model, excitation, options, outputs, start_harmonics
        As in :func:`frf`.

    Returns
    -------
    FRFPoint
        Its ``slider`` is the history it leaves: pass the point as the next start to
        follow a path. ``timings`` holds the Fortran time split (TIMER_NAMES).
    """
    options = options or SolverOptions()
    options = dataclasses.replace(options, parameter="frequency")
    if not (np.isfinite(omega) and omega > 0):
        raise ParameterError(f"omega: expected a positive frequency in rad/s, got {omega}")
    packed = pack(model, excitation, options, outputs)
    if isinstance(start, FRFPoint):
        start = {"unknowns": start.unknowns, "slider": start.slider}
    sliders = packed.checked_slider(start.get("slider")) if start is not None else None
    cold = start is None or start.get("unknowns") is None
    y0 = np.zeros(packed.ny) if cold else packed.pad_start(
        start["unknowns"], options.harmonics if start_harmonics is None else start_harmonics)
    t0 = time.perf_counter()
    # from the linear solution, a failed Newton is retried from the homotopy start
    # (continuation in the excitation level, in the same Fortran run)
    res = packed.run.solve(_run.SOLVE_FIXED, float(omega), y0, sliders=sliders,
                           stability=packed.stability, cold=cold)
    raise_for_status(res.info, res.msg)
    pt = packed.points(res, time.perf_counter() - t0)[0]
    if pt.leak is not None:
        warn_leak(pt.leak, pt.omega, stacklevel=2)
    pt.output_dofs = packed.outputs
    pt.timings = {}
    add_timings(pt.timings, res.timings)
    return pt
