"""Harmonic balance solver: one frequency, or pseudo-arc-length continuation in frequency
or in a load factor. Python packs the model into arrays; the continuation driver (the run
object of frirom_run), Newton, AFT and the linear algebra run in Fortran.

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

from . import _run
from ._errors import (CODES, MAX_OMEGA, ParameterError, SizeError, check_number,
                      raise_for_status, with_hz)
from ._pack import ORBIT_TOL, TIMER_NAMES, kept_unknowns  # noqa: F401 - public here
from ._pack import _Packed, add_timings, pack
from ._routes import HILL_MAX, MODES_MAX  # noqa: F401 - public here
from .options import FORMULATIONS, SolverOptions  # noqa: F401 - public here
from .model import CyclicModel, Excitation, Model
from ._fold import find_bifurcations
from ._peak import refine_peaks
from .results import FRF, FRFPoint

#: Largest leak of a travelling-wave selection (FRFPoint.leak) a run accepts without a
#: warning. A tuned rotor leaks at round-off: 5e-10 on the coarse flange in stick (the
#: cyclic symmetry of the mesh and matrices to their digits), 2.5e-9 with slip and
#: lift-off (the closed-cycle iteration of the slipping elements). A force off the
#: selection of 1e-6 of those on it moves the response by about that fraction (times the
#: amplification of an off-selection resonance), far below the 1e-3 the paper's
#: comparisons resolve; a changed preload or stiffness at one of 12 pairs leaks 4e-2 or
#: more, and so do the sliders a re-stuck flange keeps from slipping (4e-3, static part).
LEAK_TOL = 1e-6


def warn_leak(leak: float, omega: float, stacklevel: int, what: str = "",
              label: str = "travelling-wave selection") -> None:
    """Warn (RuntimeWarning) when a selection's leak (FRFPoint.leak) is above LEAK_TOL;
    omega: rad/s, where; stacklevel: 1 = the caller of warn_leak, 2 = its caller, and so
    on; what: names the point when it is not one of the run's; label: the kind of
    selection (_Packed.sel_label)."""
    if leak <= LEAK_TOL:
        return
    where = (f"contact forces off the selection reach {leak:.2g} of those on it at "
             f"{omega / 2 / np.pi:.6g} Hz{f' ({what})' if what else ''} (tolerance "
             f"{LEAK_TOL:g})")
    if label == "harmonic selection":
        warnings.warn(f"frirom: the harmonic selection leaks: {where}; the dropped "
                      "harmonics carry that much of the contact forces there, and the "
                      "selected solution is not the full one (keep more harmonics, or "
                      "solve without options.harmonics_kept to see how far)",
                      RuntimeWarning, stacklevel=stacklevel + 1)
    else:
        warnings.warn(f"frirom: the travelling-wave selection leaks: {where}; the rotor, "
                      "its contacts, its load or the contact history carried from point "
                      "to point (sliders frozen at different phases) are not a "
                      "travelling wave there, and the selected solution is not the "
                      "full one (solve without the selection to see how far)",
                      RuntimeWarning, stacklevel=stacklevel + 1)


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
    before: list = field(default_factory=list)  # those points, when the checkpoint has them
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
                                    n_before=self.n_before, sliders=sliders,
                                    held_lu=start.get("held_lu"))
            # the stored points' worst leak, whichever way the run goes on from them
            self.leak_before = start.get("leak")
            if self.n_before and len(start.get("before") or ()) == self.n_before:
                self.before = list(start["before"])
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
            pts = self.packed.points(res, t_call)
            if pts and np.isfinite(pts[-1].ds_next):
                # a checkpoint: the LU the run goes on with, for an exact resume
                pts[-1].held_lu = run.lu_state()
            for pt in pts:
                self.points.append(pt)
                self._emit(pt)
            if res.status == _run.GOING:
                continue
            if res.status == _run.DONE:
                return True, ""
            if res.status == _run.FAILED:
                return False, self._stopped(res)
            message = self._located(res.message)
            if res.status == _run.STALLED:
                warnings.warn(f"frirom: continuation stalled, {len(self.points)} points kept: "
                              f"{message}", RuntimeWarning, stacklevel=4)
            return False, message

    def _located(self, message: str) -> str:
        """A stop message with its frequencies in Hz too (rad/s kept: the API's unit) and,
        for a frequency curve, the last point's frequency."""
        message = with_hz(message.strip())
        if self.points and self.packed.opts.parameter == "frequency":
            w = float(self.points[-1].omega)
            message += f" (last point at {w / 2 / np.pi:.7g} Hz, {w:.7g} rad/s)"
        return message

    def _advice(self, res) -> str:
        if res.fail_info == CODES["FRIROM_ERR_CONT"] and self.packed.nw:
            return _contact_advice(self.packed.opts, res.advice, res.stalled)
        return ""

    def _stopped(self, res) -> str:
        """Explain a run Fortran stopped, with the advice that would change its outcome."""
        message = self._located(res.message) + self._advice(res)
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
        if p.stability and self.timings:
            # the cost of stability beside the curve's (Fortran T_HILL, in the total)
            t_h, t_all = self.timings.get("hill", 0.0), self.timings.get("fortran_total", 0.0)
            out.solver_info += (f"; stability (Hill) {t_h:.3g} s of the run's {t_all:.3g} s "
                                f"in Fortran")
        if p.keep is not None and (pts or self.leak_before):
            k = int(np.argmax(out.leak)) if pts else 0
            worst, at = (float(out.leak[k]), pts[k].omega) if pts else (-1.0, 0.0)
            if self.leak_before is not None and self.leak_before[0] > worst:
                worst, at = self.leak_before      # a point stored before the resume
            out.solver_info += f"; leak max {worst:.1e}"
            warn_leak(worst, at, stacklevel=4, label=p.sel_label)
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
    # folds located on the curve, stability changes: of the whole curve (a resumed run's
    # points before the resume too; Bifurcation.index counts them)
    out.bifurcations = find_bifurcations(packed, run.before + run.points, run.lscale)
    if packed.opts.refine_peak and packed.opts.parameter == "frequency" and run.points:
        # a resumed run: the peak of the whole curve, as the uninterrupted run solves it
        # (Peak.index then counts the points before the resume)
        out.peaks, solved = refine_peaks(packed, run.before + run.points, run.lscale)
        if packed.keep is not None:
            k = int(np.argmax([q.leak for q in solved])) if solved else -1
            if k >= 0:
                warn_leak(solved[k].leak, solved[k].omega, stacklevel=3,
                          what="a peak solved between points", label=packed.sel_label)
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
        warn_leak(pt.leak, pt.omega, stacklevel=2, label=packed.sel_label)
    pt.output_dofs = packed.outputs
    pt.timings = {}
    add_timings(pt.timings, res.timings)
    return pt
