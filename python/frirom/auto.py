"""``[solver] harmonics = "auto"`` and ``samples = "auto"``: the smallest H and N whose a
posteriori error estimate on the response amplitude is within a tolerance (docs/deck.md).

The estimate costs a coarse run and a few point solves, not a ladder of FRFs:

1. a run at the smallest H (the highest loaded harmonic, at least 1) finds, per output, the
   point of largest amplitude and its two neighbours on the curve: the **probe points**
   (distinct frequencies; one point alone made the estimate depend on where the
   continuation's points fell on a flat friction peak);
2. at each probe frequency the solution is followed up the harmonics, H -> H+1, each solve
   started from the one below (padded with zeros) and from the coarse point's contact
   history, so it stays on the coarse curve's branch;
3. the **H estimate** e(H) is the largest relative change of the outputs' amplitudes
   (max over the period of |x(t)|) from H to H+2 over the probes: H+2, not H+1, because
   a symmetric friction contact excites odd harmonics only and an even H+1 adds nothing;
   the error of H is taken as the geometric tail e(H) / (1 - r), r = e(H) / e(H-2) the
   observed rate (at most :data:`RATE_MAX`; 1/2 before two rungs or after a failed one),
   and the smallest H whose tail is within the budget is chosen: the tolerance, or half
   of it when N is chosen too (the other half is N's);
4. the **N estimate** e(N) at the chosen H is the same change from N to 2N AFT samples
   (aliasing of the contact forces; it falls like 1/N^2 for smooth laws, slower at state
   switches), N over the powers of two from the first >= 2H+1, with the tail
   e(N) / (1 - e(N) / e(N/2)) within the budget.

Where the estimate does not reach the tolerance within ``max_harmonics`` /
``max_samples`` (it stalls, rises, or a solve above a successful one fails) the choice is the maximum and the
log and ``FRF.solver_info`` say so: never a silent pick.

Interface modes (``[reduction.interface_modes]`` ``free`` / ``stick`` or
``time_harmonics = "auto"``: the MS harmonic indices of the engine orders' time
harmonics 0..j, :func:`choose_modes`) change the reduced coordinates, so no
solution is carried from rung to rung: each rung of the ladder
(:meth:`frirom.deck.schema_study.ModesAuto.rungs`) is its own reduced model (built once,
then read from the content-keyed cache) and its own FRF, the first over the deck's range,
the others only over the **peak region**: the previous rung's peaks +- :data:`WINDOW`
(the whole range again when a peak lands on the window's edge). The estimate e(k) is the
largest relative change of the peak amplitude and the peak frequency from rung k to k+1
over the outputs; the error of rung k is the tail e(k) / (1 - r), r = e(k) / e(k-1) the
observed rate (as for H), and the smallest rung within the tolerance is chosen; the log
gives, per rung, that rule with its numbers. The modes are chosen first, at the smallest H
when H is auto too. The chosen rung's reduced model is the run's (not built again), and
so is its curve when it covered the whole range with the run's settings.

When no probe solve succeeds (every estimate inf), the H or N choice stops with the
reason (:class:`frirom.ConvergenceError`) instead of running the maximum.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np

from ._errors import ConvergenceError, FriromError
from ._probes import _excitation, _first_harmonic, _probes, _rel
from .harmonics import default_samples

__all__ = ["AutoChoice", "choose", "choose_modes", "resolve_deck"]

#: the largest ratio of successive estimates trusted as a rate of convergence
RATE_MAX = 0.9
#: half-width of the peak region a rung of interface modes is run on, relative to the
#: peak frequency (the lap joint's peak moves 1 % between rungs)
WINDOW = 0.05


def _rate(est: list, back: int) -> float:
    """The rate r of :func:`_tail`: the last estimate over the one ``back`` rungs below,
    clamped to [0, RATE_MAX]; 1/2 when there is none (nan or inf below)."""
    e = est[-1][1]
    below = est[-1 - back][1] if len(est) > back else float("nan")
    return min(max(e / max(below, 1e-300), 0.0), RATE_MAX) if np.isfinite(below) else 0.5


def _rule(est: list, back: int, tol: float) -> str:
    """The rule that accepts or rejects the last rung, with its numbers: ``e = 9.0e-04,
    r = 0.90: error e / (1 - r) = 9.0e-03 > tolerance 0.001``."""
    e, r = est[-1][1], _rate(est, back)
    if not np.isfinite(e):
        return "no estimate (a solve or curve failed): not accepted"
    t = e / (1.0 - r)
    how = (f"r = {r:.2f} (the estimate below over this one, at most {RATE_MAX})"
           if len(est) > back and np.isfinite(est[-1 - back][1]) else "r = 1/2 (no rate yet)")
    return (f"e = {e:.2e}, {how}: error e / (1 - r) = {t:.2e} "
            f"{'<=' if t <= tol else '>'} tolerance {tol:g}")


def _tail(est: list, back: int) -> float:
    """The error of the last rung from its estimate e (its change to the next rung) and
    the rate r = e / (the estimate ``back`` rungs below, 2 for H: the same parity, 1 for
    N and modes): the geometric tail e / (1 - r), r clamped to [0, RATE_MAX]; r = 1/2 when
    there is no rate: for the first rungs, and after a rung whose estimate is not finite
    (a failed solve or curve gives no rate, not a rate of 0)."""
    return est[-1][1] / (1.0 - _rate(est, back))



@dataclass
class AutoChoice:
    """What :func:`choose` found.

    harmonics, samples : int
        The chosen H and N (samples None when N was not chosen: the deck's or default).
    tolerance : float
        Relative amplitude error asked for.
    probes : list of float
        Probe frequencies, rad/s.
    h_estimates, n_estimates : list of (int, float)
        (H, e(H)) and (N, e(N)) as climbed (inf: a solve failed).
    met_h, met_n : bool
        The estimate reached the tolerance (False: the maximum was used).
    notes : list of str
        What failed, in words (also in :meth:`lines`).
    seconds : float
        Wall time of the choice.
    modes : dict
        Interface-mode counts chosen {key: value} (empty: not chosen).
    mode_estimates : list of (str, float)
        (rung, e(rung)) as climbed. met_modes : bool. modes_tolerance : float.
    mode_lines : list of str
        The rungs' log lines (logged as they ran).
    """

    harmonics: int
    samples: int | None
    tolerance: float
    probes: list = field(default_factory=list)
    h_estimates: list = field(default_factory=list)
    n_estimates: list = field(default_factory=list)
    met_h: bool = True
    met_n: bool = True
    notes: list = field(default_factory=list)
    seconds: float = 0.0
    modes: dict = field(default_factory=dict)
    mode_estimates: list = field(default_factory=list)
    met_modes: bool = True
    modes_tolerance: float = 0.0
    mode_lines: list = field(default_factory=list)
    #: ``harmonics_kept = "auto"``: the selection chosen (frirom.auto_kept.KeptChoice)
    kept: object = None

    def modes_text(self) -> str:
        """``"free = 20, stick = 20"``: the chosen interface-mode counts."""
        return _rung_label(self.modes)

    def summary(self) -> str:
        """One line for ``FRF.solver_info``."""
        out = []
        if self.modes:
            est = self.mode_estimates
            keys = [k for k, _ in est]
            if self.modes_text() in keys:
                why = _rule(est[:keys.index(self.modes_text()) + 1], 1, self.modes_tolerance)
            else:
                why = "no estimate" + (f"; the last rung's {_rule(est, 1, self.modes_tolerance)}"
                                       if est else "")
            out.append(f"interface modes {self.modes_text()} auto ({why}"
                       + ("" if self.met_modes else "; NOT within the tolerance: the "
                          "largest") + ")")
        parts = []
        for name, v, est, met, back in (
                ("H", self.harmonics, self.h_estimates, self.met_h, 2),
                ("N", self.samples, self.n_estimates, self.met_n, 1)):
            if est:
                keys = [k for k, _ in est]
                upto = est[:keys.index(v) + 1] if v in keys else est
                e = upto[-1][1]
                parts.append(f"{name} = {v} auto (estimate {e:.2e}"
                             + (f", error e / (1 - r) = {_tail(upto, back):.2e}"
                                if np.isfinite(e) else "")
                             + ("" if met else ", NOT within the tolerance: the maximum")
                             + ")")
        if parts:
            out.append("; ".join(parts) + f", tolerance {self.tolerance:g}")
        if self.kept is not None:
            out.append(self.kept.summary())
        return "; ".join(out)

    def title(self) -> str:
        """A short line for a plot's title: the choice, and a failed estimate."""
        text = ", ".join(f"{n} = {v}" for n, v, est in (
            ("H", self.harmonics, self.h_estimates), ("N", self.samples, self.n_estimates))
            if est)
        bad = [n for n, est, met in (("H", self.h_estimates, self.met_h),
                                     ("N", self.n_estimates, self.met_n)) if est and not met]
        out = []
        if self.modes:
            out.append(f"auto: modes {self.modes_text()} for {self.modes_tolerance:g}"
                       + ("" if self.met_modes else " - NOT within it: the largest"))
        if self.kept is not None and self.kept.selection is not None:
            u = self.kept.unknowns
            out.append(f"auto: {u[0]} of {u[1]} unknowns" + (" - RESTORED: all"
                                                             if self.kept.restored else ""))
        if text:
            out.append(f"auto: {text} for {self.tolerance:g}" + (
                f" - {' and '.join(bad)} estimate NOT within it: the maximum" if bad
                else ""))
        return "; ".join(out)

    def lines(self) -> list:
        """The log lines: probes, the estimates climbed, the choice, the failures."""
        out = list(self.mode_lines)
        if self.probes:
            out.append(f"auto: probe points at "
                       f"{', '.join(f'{w / 2 / np.pi:.6g}' for w in self.probes)} Hz "
                       "(largest amplitude of each output and its neighbours on a run at "
                       "the smallest H)")
        for name, est in (("H", self.h_estimates), ("N", self.n_estimates)):
            if est:
                out.append(f"auto: {name} estimate (relative change of the amplitudes at "
                           f"{'H+2' if name == 'H' else '2N'}): "
                           + ", ".join(f"{k}: {e:.2e}" for k, e in est))
        if self.kept is None or self.h_estimates or self.n_estimates or self.modes:
            out.append(f"auto: {self.summary()} ({self.seconds:.1f} s)")
        elif self.kept is not None:
            out += self.kept.lines()
        out += [f"auto: WARNING: {n}" for n in self.notes]
        return out


def _follow(model, F, opts, outputs, probe, H, N, prev, errors=None):
    """The solution at the probe's frequency with H harmonics and N samples, started from
    ``prev`` (a point and its H) and the probe's contact history; None if it fails (the
    reason appended to ``errors``)."""
    from .solver import solve_point
    o = dataclasses.replace(opts, harmonics=H, samples=N, stability=False)
    point, Hp = prev
    try:
        return solve_point(model, _excitation(F, H), probe.omega, o, outputs=outputs,
                           start={"unknowns": point.unknowns, "slider": probe.slider},
                           start_harmonics=Hp)
    except (FriromError, ArithmeticError, np.linalg.LinAlgError) as exc:
        if errors is not None:
            errors.append(f"H = {H}, N = {N} at {probe.omega / 2 / np.pi:.6g} Hz: {exc}")
        return None                 # a failed solve: an estimate of inf, reported


def _no_probe(key: str, ch: AutoChoice, errors: list) -> str:
    """The message of a choice that stops: no probe solve gave an estimate."""
    probes = ", ".join(f"{w / 2 / np.pi:.6g}" for w in ch.probes)
    first = errors[0] if errors else "no solve"
    return (f'solver.{key} = "auto": no probe solve succeeded (probes at {probes} Hz; '
            f"{len(errors)} solves failed, the first: {first}), so there is no estimate "
            f"to choose {'H' if key == 'harmonics' else 'N'} from; nothing was run at the "
            "maximum. Give solver.harmonics and solver.samples as integers (a run that "
            "fails then says where), or check the model")


def choose(model, F, omega_start, omega_end, options, outputs=None, *, harmonics=True,
           samples=True, tolerance=1e-3, max_harmonics=15, max_samples=4096) -> AutoChoice:
    """Choose H (``harmonics``) and/or N (``samples``) by the a posteriori estimate of the
    module docstring.

    Parameters
    ----------
    model : Model
    F : ndarray, complex (n_dof, >= 1)
        Load harmonics 0.. [N]; columns above the H in use are dropped, missing ones zero.
    omega_start, omega_end : float
        Frequency range, rad/s.
    options : SolverOptions
        Everything else; its ``harmonics`` is the H used when ``harmonics`` is False, its
        ``samples`` the N used when ``samples`` is False (None: the default rule).
    outputs : as :func:`frirom.solver.frf`; the amplitudes compared are theirs.
    harmonics, samples : bool
        What to choose.
    tolerance : float
        Relative amplitude change allowed.
    max_harmonics, max_samples : int
        The largest H and N tried (the choice when the estimate does not reach the
        tolerance).

    Returns
    -------
    AutoChoice
    """
    t0 = time.perf_counter()
    budget = tolerance / 2 if harmonics and samples else tolerance
    H_lo = _first_harmonic(F)
    notes = []
    fixed_N = None if samples else options.samples

    def n_for(H):
        return fixed_N if fixed_N is not None else default_samples(H)

    errors = []                 # why each failed probe solve failed
    H = options.harmonics
    H0 = H_lo if harmonics else H
    probes = _probes(model, F, omega_start, omega_end,
                     dataclasses.replace(options, samples=n_for(H0)), outputs, H0, notes)
    ch = AutoChoice(harmonics=H, samples=options.samples, tolerance=tolerance,
                    probes=[p.omega for p in probes], notes=notes)
    sols = [{H0: p} for p in probes]             # per probe: H -> solution
    if harmonics:
        H, ch.met_h = max_harmonics, False
        for h in range(H0, max_harmonics - 1):
            N = n_for(h + 2)
            if N is not None and N < 2 * (h + 2) + 1:
                notes.append(f"samples = {N} is too few for H = {h + 2}: H climbed no "
                             "higher")
                break
            errs = []
            for s, p in zip(sols, probes):
                for k in (h + 1, h + 2):
                    if k not in s and s.get(k - 1) is not None:
                        s[k] = _follow(model, F, options, outputs, p, k, n_for(k),
                                       (s[k - 1], k - 1), errors)
                a, b = s.get(h), s.get(h + 2)
                errs.append(float("inf") if a is None or b is None else
                            _rel(a.amp_max, b.amp_max))
            ch.h_estimates.append((h, max(errs)))
            if _tail(ch.h_estimates, 2) <= budget:
                H, ch.met_h = h, True
                break
        if not ch.met_h and ch.h_estimates and not any(
                np.isfinite(e) for _, e in ch.h_estimates):
            raise ConvergenceError(_no_probe("harmonics", ch, errors))
        if not ch.met_h:
            last = ch.h_estimates[-1][1] if ch.h_estimates else float("nan")
            why = ("a solve failed" if not np.isfinite(last) else
                   "it did not fall" if len(ch.h_estimates) > 1 and
                   last >= ch.h_estimates[0][1] else "it fell too slowly")
            notes.append(f"the H estimate did not reach {budget:g} up to max_harmonics = "
                         f"{max_harmonics} ({why}; last {last:.2e}): the run uses H = "
                         f"{H}, raise solver.max_harmonics or the tolerance")
        ch.harmonics = H
    if samples:
        N = 1 << (2 * H).bit_length()               # first power of two >= 2H+1
        ch.met_n = False
        starts = []
        for s in sols:
            k = H if s.get(H) is not None else max(k for k, v in s.items() if v is not None)
            starts.append((s[k], k))
        cur = [_follow(model, F, options, outputs, p, H, N, st, errors)
               for p, st in zip(probes, starts)]
        while 2 * N <= max_samples:
            nxt = [_follow(model, F, options, outputs, p, H, 2 * N, (c, H), errors)
                   if c is not None else None for p, c in zip(probes, cur)]
            errs = [float("inf") if a is None or b is None else _rel(a.amp_max, b.amp_max)
                    for a, b in zip(cur, nxt)]
            ch.n_estimates.append((N, max(errs)))
            if _tail(ch.n_estimates, 1) <= budget:
                ch.met_n = True
                break
            N, cur = 2 * N, nxt
        if not ch.met_n and ch.n_estimates and not any(
                np.isfinite(e) for _, e in ch.n_estimates):
            raise ConvergenceError(_no_probe("samples", ch, errors))
        if not ch.met_n:
            last = ch.n_estimates[-1][1] if ch.n_estimates else float("nan")
            N = max_samples
            notes.append(f"the N estimate did not reach {budget:g} up to max_samples = "
                         f"{max_samples} (last {last:.2e}): the run uses N = {N}")
        ch.samples = N
    ch.seconds = time.perf_counter() - t0
    return ch


def _rung_label(values: dict) -> str:
    """``free = 20, stick = 20`` / ``time_harmonics = 0-3``."""
    return ", ".join(f"{k} = {v[0]}" + (f"-{v[-1]}" if len(v) > 1 else "")
                     if isinstance(v, tuple) else f"{k} = {v}" for k, v in values.items())


def _rung_deck(deck, values: dict):
    """The deck with the interface-mode counts ``values``, built by the deck builder (the
    reduced model comes from the content-keyed cache when it was built before)."""
    from .deck import build_deck
    from .deck.build import beside_named_cache
    s = deck.settings
    return build_deck(beside_named_cache(dataclasses.replace(
        s, reduction=dataclasses.replace(s.reduction, **values), modes_auto=None), s))


def _rung_peaks(deck, H, opts, window, full):
    """The peaks [(omega rad/s, amplitude)] per output of the deck's FRF at H over
    ``window`` (the whole range ``full`` again when a peak lies on its edge), the
    run's (points, seconds, (lo, hi) range run, message), and the run itself (FRF, its
    FRFPoints, whether it covered ``full``) for reuse; peaks None when the curve
    stopped. Frequencies in rad/s, swept in the direction of ``full``."""
    from .solver import frf
    model, exc = deck.model(), _excitation(deck.F, H)
    t0 = time.perf_counter()
    down = full[0] > full[1]
    for lo, hi in (window, (min(full), max(full))):
        pts = []
        r = frf(model, exc, *((hi, lo) if down else (lo, hi)), opts,
                outputs=deck.solver_outputs, sink=pts.append)
        n = len(r)
        peaks = [r.peak(j) for j in range(r.amp_max.shape[1])] if n else []
        edge = any(p.index in (0, n - 1) for p in peaks)
        if not edge or (lo, hi) == (min(full), max(full)):
            break
    info = (n, time.perf_counter() - t0, (lo, hi), r.message)
    run = (r, pts, (lo, hi) == (min(full), max(full)))
    if not r.complete or not peaks:
        return None, info, run
    return [(p.omega, p.amplitude) for p in peaks], info, run


def _same_options(a, b) -> bool:
    """Two SolverOptions that compute the same curve (no travelling-wave selection: its
    arrays are not compared)."""
    if a.selection is not None or b.selection is not None or \
            isinstance(a.harmonics_kept, np.ndarray) or isinstance(b.harmonics_kept, np.ndarray):
        return False
    return all(getattr(a, f.name) == getattr(b, f.name) for f in dataclasses.fields(a))


def _peak_change(a, b) -> float:
    """Largest relative change of the peak amplitude or frequency from ``a`` to ``b``
    (lists of (omega, amplitude) per output); inf when either is missing."""
    if a is None or b is None:
        return float("inf")
    return max(max(abs(wa - wb) / wb, abs(xa - xb) / xb) for (wa, xa), (wb, xb) in zip(a, b))


def choose_modes(deck, log=print):
    """Choose the interface-mode counts of ``deck.settings.modes_auto`` by the rung
    estimate of the module docstring.

    Parameters
    ----------
    deck : Deck
        Built with the first rung (what the parser gives for ``"auto"``).
    log : callable(str)
        Each rung's line as it finishes.

    Returns
    -------
    (Deck, AutoChoice)
        The deck built with the chosen counts, and the choice (``modes``,
        ``mode_estimates``, ``met_modes``, ``mode_lines``, ``notes``).
    """
    t0 = time.perf_counter()
    s = deck.settings
    ma, sol = s.modes_auto, s.solver
    H = _first_harmonic(deck.F) if sol.auto_harmonics else deck.harmonics
    opts = dataclasses.replace(deck.options(), harmonics=H, stability=False,
                               **({"samples": None} if sol.auto_samples else {}))
    full = (deck.omega_start, deck.omega_end)
    rungs = ma.rungs()
    ch = AutoChoice(harmonics=deck.harmonics, samples=deck.samples,
                    tolerance=sol.tolerance_auto, modes_tolerance=ma.tolerance)
    prev, chosen, d, last, size = None, None, deck, None, None  # last: the rung run before
    built, runs = {}, {}        # rung -> its deck, its run (reused, not built or run again)

    def step(i, line, peaks):
        """Log a rung, and the rule that accepts or rejects the rung before it (its
        change to this one); True when that rung is within the tolerance."""
        log(line)
        ch.mode_lines.append(line)
        if last is None:
            return False
        ch.mode_estimates.append((_rung_label(rungs[last]), _peak_change(prev, peaks)))
        ok = bool(np.isfinite(ch.mode_estimates[-1][1])
                  and _tail(ch.mode_estimates, 1) <= ma.tolerance)
        rule = (f"auto: modes {_rung_label(rungs[last])} "
                f"{'accepted' if ok else 'rejected'} (its change to "
                f"{_rung_label(rungs[i])}): {_rule(ch.mode_estimates, 1, ma.tolerance)}")
        log(rule)
        ch.mode_lines.append(rule)
        return ok

    for i, values in enumerate(rungs):
        window = (min(full), max(full))
        if prev is not None:
            ws = [w for w, _ in prev]
            window = (max(min(full), min(ws) * (1 - WINDOW)),
                      min(max(full), max(ws) * (1 + WINDOW)))
        try:
            d = _rung_deck(deck, values) if i > 0 else deck
            if d.n_dof == size:     # MS: the new time harmonic adds no harmonic index
                line = (f"auto: modes {_rung_label(values)}: the same {size} coordinates "
                        "as the rung before (no new harmonic index): skipped")
                log(line)
                ch.mode_lines.append(line)
                continue
            size = d.n_dof
            built[i] = d
            peaks, (n, sec, (lo, hi), msg), runs[i] = _rung_peaks(d, H, opts, window, full)
        except (FriromError, ArithmeticError, np.linalg.LinAlgError) as exc:
            d = None                # a rung that cannot be built or solved: inf
            ch.notes.append(f"modes {_rung_label(values)}: {exc}")
            step(i, f"auto: modes {_rung_label(values)}: failed ({exc})", None)
            prev, last = None, i
            continue
        rom = d.reduced
        head = (f"auto: modes {_rung_label(values)}: {d.n_dof} coordinates, "
                f"{len(d.model().nonlinear_dofs())} in contact; ")
        tail = (f"{n} points over {lo / 2 / np.pi:.5g}-{hi / 2 / np.pi:.5g} Hz, reduction "
                f"{getattr(rom, 'build_seconds', 0.0) or 0.0:.1f} s"
                f"{' (cached)' if getattr(rom, 'from_cache', False) else ''}, FRF {sec:.1f} s")
        if peaks is None:
            ch.notes.append(f"modes {_rung_label(values)}: the curve stopped ({msg})")
            line = head + f"curve stopped ({msg}); " + tail
        else:
            line = head + "peak " + ", ".join(f"{a:.4g} at {w / 2 / np.pi:.6g} Hz"
                                              for w, a in peaks) + f" ({tail})"
        if step(i, line, peaks):
            chosen = last
            break
        prev, last = peaks, i
    if chosen is None:
        chosen, ch.met_modes = len(rungs) - 1 if last is None else last, False
        e_last = ch.mode_estimates[-1][1] if ch.mode_estimates else float("nan")
        ch.notes.append(f"the interface-mode estimate did not reach {ma.tolerance:g} up to "
                        f"{_rung_label(rungs[-1])} (last {e_last:.2e}): the run uses the "
                        "largest rung; raise max_modes / max_time_harmonic or the tolerance")
    ch.modes = dict(rungs[chosen])
    est = ", ".join(f"{k}: {e:.2e}" for k, e in ch.mode_estimates)
    ch.mode_lines.append(f"auto: interface-mode estimate (relative change of the peak "
                         f"amplitude and frequency to the next rung): {est}")
    d = built[chosen] if chosen in built else _rung_deck(deck, rungs[chosen])
    # the chosen rung's curve is the run's when it covered the whole range with the run's
    # own options (H and N not auto): frirom run writes it instead of computing it again
    run = runs.get(chosen)
    d.auto_response = None
    if (run is not None and run[2] and run[0].complete and not sol.auto_harmonics
            and not sol.auto_samples and _same_options(opts, d.options())):
        d.auto_response = run[:2]
    ch.seconds = time.perf_counter() - t0
    return d, ch


def resolve_deck(deck, log=print):
    """The deck with ``harmonics = "auto"`` / ``samples = "auto"`` and the interface-mode
    counts ``"auto"`` replaced by the chosen values (the deck itself when none is asked);
    ``deck.auto`` is the :class:`AutoChoice` (None without auto), and its lines go to
    ``log`` (the interface-mode rungs as they run)."""
    sol = getattr(deck.settings, "solver", None)
    modes = getattr(deck.settings, "modes_auto", None)
    hn = sol is not None and (sol.auto_harmonics or sol.auto_samples)
    kept = sol is not None and getattr(sol, "harmonics_kept", None) == "auto"
    if modes is None and not hn and not kept:
        deck.auto = None
        return deck
    mc = None
    if modes is not None:
        deck, mc = choose_modes(deck, log)
    if not hn:
        if mc is not None:
            for line in mc.lines()[len(mc.mode_lines) - 1:]:
                log(line)
        deck.auto = mc
        return _resolve_kept(deck, sol, log) if kept else deck
    opts = deck.options()
    if sol.auto_samples:
        opts = dataclasses.replace(opts, samples=None)
    ch = choose(deck.model(), deck.F, deck.omega_start, deck.omega_end, opts,
                deck.solver_outputs, harmonics=sol.auto_harmonics,
                samples=sol.auto_samples, tolerance=sol.tolerance_auto,
                max_harmonics=sol.max_harmonics, max_samples=sol.max_samples)
    if mc is not None:
        for k in ("modes", "mode_estimates", "met_modes", "modes_tolerance"):
            setattr(ch, k, getattr(mc, k))
        ch.mode_lines, ch.notes = mc.mode_lines, mc.notes + ch.notes
        ch.seconds += mc.seconds
        log(mc.mode_lines[-1])
    for line in ch.lines()[len(ch.mode_lines):]:
        log(line)
    H = ch.harmonics
    F = _excitation(deck.F, H).F
    new = dataclasses.replace(deck, harmonics=H, samples=ch.samples, F=F)
    new.auto, new.auto_response = ch, None
    return _resolve_kept(new, sol, log) if kept else new


def _resolve_kept(deck, sol, log):
    """``harmonics_kept = "auto"``: the selection chosen by frirom.auto_kept on the
    deck's H and N (``deck.kept_auto``), its lines logged and kept in ``deck.auto``."""
    from .auto_kept import choose_kept
    opts = deck.options()
    kc = choose_kept(deck.model(), deck.F, deck.omega_start, deck.omega_end, opts,
                     deck.solver_outputs, tolerance=sol.tolerance_auto)
    for line in kc.lines():
        log(line)
    if deck.auto is None:
        deck.auto = AutoChoice(harmonics=deck.harmonics, samples=deck.samples,
                               tolerance=sol.tolerance_auto)
    deck.auto.kept = kc
    deck.kept_auto = kc.selection
    return deck
