"""Vane segment with hook joints (paper section 3.2.1): ROM_I against ROM_II over the hook
preload f0, the sizes table and the Fig. 6-style family.

    python cases/paper_hooks/paper_hooks.py [--size coarse|paper] [--work DIR]
        [--f0 300 1000 3000 10000] [--gsi 40] [--rom1 full|sample]
        [--law normal1d|normal2d] [--interlock contact|tied] [--lug own|physical|shared]

Makes the model (cases/paper_hooks/make_paper_hooks.py) in WORK (default
results/paper_hooks/<size>), builds ROM_I (Craig-Bampton, every hook and lug DoF
nonlinear) and ROM_II (the hook faces reduced by n_gsi GSI modes, half free, half
full-stick; the contact lug a joint of its own, reduced by its own 12 full-stick GSI
modes, or with --lug kept physical or in the span of the hooks' basis), both with the cyclic boundary reduced by Tran's interface modes, and solves
one FRF per hook preload f0 (total over both hooks, N; n0 = f0 / pairs per pair; the lug's
preload stays make_paper_hooks.F_LUG). Prints the sizes table (the paper's DoF partitions)
and one row per f0: peaks, the errors of ROM_II against ROM_I in peak amplitude and peak
frequency (flagged where they miss 1 % / 0.1 %), the lug's smallest stick fraction over
the FRFs, the FRF times and the speed-up; writes fig6.png (ROM_I lines, ROM_II markers)
in WORK.

Where a continuation stops before the end of the range, a second sweep runs from the end
of the range down to the stop, and the peak is the larger of the two (the row says
``<>``; ``!`` when the sweeps do not meet). ``--rom1 sample`` solves ROM_I only at a few
frequencies around ROM_II's peak, following them from the linear solution, finds its peak
from a parabola through the three highest, and extrapolates the FRF time from the time
per point times the number of points of ROM_II's FRF (``*`` in the table).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import make_paper_hooks as mk  # noqa: E402

#: the family of hook preloads (total over both hooks, N), from slip to stick
F0_FAMILY = (300.0, 1000.0, 3000.0, 10000.0)
F0_QUICK = (1000.0, 3000.0)     # the coarse 300 N's ROM_I may stop (README)


def static_loads(red, pairs, n0: float) -> np.ndarray:
    """The reduced static load (n_r,) of a preload n0 [N per pair] on ``pairs``
    (:func:`make_paper_hooks.hook_geometry`): +n0 n on each vane node, -n0 n on its
    casing node, through the reduction's rows (as the deck's [[excitation.load]] tables)."""
    out = 0.0
    for va, ca, n in zip(*pairs):
        for node, sign in ((va, 1.0), (ca, -1.0)):
            for d in (0, 1):
                if abs(n[d]) > 1e-14:
                    out = out + sign * n0 * n[d] * red.load_row(int(node), d + 1)
    return out


def _dofs(red, groups) -> int:
    """Number of distinct FE DoFs of the contact groups ``groups`` (names)."""
    return (np.unique(np.concatenate([np.ravel(red.pairs[g].dofs) for g in groups])).size
            if groups else 0)


class Rom:
    """One ROM of the case, built from its deck once; ``set_preload`` changes f0.

    law: the contact law of the hooks and the lug; the model in ``work`` decides whether
    the lug is a contact (LUG_V, LUG_C sets; preloaded by make_paper_hooks.F_LUG whatever
    f0) or tied."""

    def __init__(self, work: Path, rom: str, size: str, n_gsi: int = 40,
                 law: str = "normal1d", lug_reduction: str = "own"):
        from frirom.contact import LAWS
        from frirom.deck import load_deck
        self.name = rom
        pairs = mk.hook_geometry(work / "hooks")
        lug = mk.lug_geometry(work / "hooks")
        self.n_pairs = len(pairs[0])
        tag = ("" if law == "normal1d" else f"_{law}") + (
            f"_lug{lug_reduction}" if lug is not None and lug_reduction != "own" else "")
        deck = work / (f"{rom}{tag}.toml" if rom == "rom1" else f"rom2_gsi{n_gsi}{tag}.toml")
        deck.write_text(mk.deck_text(rom, size, self.n_pairs, mk.F0_DEFAULT, n_gsi,
                                     pairs=pairs, law=law, lug=lug,
                                     lug_reduction=lug_reduction))
        t0 = time.perf_counter()
        self.deck = load_deck(deck)
        self.model = self.deck.model()
        self.seconds = time.perf_counter() - t0
        red = self.deck.reduced
        #: reduction time: the reduced model (CB + GSI, from the cache's record when it
        #: was reused) and the cyclic modes of every nodal diameter
        self.reduction_s = red.build_seconds + self.deck.cyclic["seconds"]
        self.excitation = self.deck.excitation()
        #: the static load of the hooks' preload per N of n0, and the rest of the deck's
        #: static load (the lug's preload, which f0 leaves alone)
        self._hooks_unit = static_loads(red, pairs, 1.0)
        self._static_rest = (self.excitation.F[:, 0]
                             - self._hooks_unit * (mk.F0_DEFAULT / self.n_pairs))
        # the deck's amplitudes have 9 digits, and the loads on the two faces nearly cancel
        # in the reduced coordinates: 1e-6 of the hooks' part
        scale = np.abs(self._hooks_unit).max() * mk.F0_DEFAULT / self.n_pairs
        if lug is None and np.abs(self._static_rest).max() > 1e-6 * scale:
            raise RuntimeError("the hooks' static loads differ from the deck's")
        self.options = self.deck.options()
        self.groups = [c.name for c in self.deck.settings.contacts]
        spec = self.deck.settings.reduction
        #: ROM_II's lug coordinates: its own stick modes, or its DoFs kept physical
        self.lug_dofs = (0 if rom == "rom1" or not spec.separate else spec.separate_stick
                         or _dofs(red, [g for g in self.groups if g.startswith("lug")]))
        self._hooks = self.groups.index("hooks")
        self._n0 = LAWS[self.model.contacts[self._hooks].law].parameters.index("n0")
        cyc = self.deck.cyclic
        n_b = cyc["sector"].boundary.size
        nm = max(m.omega.size for m in cyc["modes"].values())
        self.sizes = dict(fe=red.n_fe, coords=self.model.n_dof,
                          contact_dofs=(_dofs(red, self.groups) if rom == "rom1" else
                                        n_gsi + self.lug_dofs),
                          law=self.model.contacts[self._hooks].law,
                          nonlinear=len(self.model.nonlinear_dofs()),
                          contact_pairs=self.model.contacts[self._hooks].n_elem,
                          lug_pairs=0 if lug is None else len(lug[0]),
                          boundary=n_b, tran=self.deck.settings.cyclic.boundary_modes,
                          cb=self.deck.settings.reduction.fixed_interface_modes,
                          sector_coords=n_b and (cyc["sector"].independent.size
                                                 - n_b + self.deck.settings.cyclic
                                                 .boundary_modes),
                          modes=nm)

    def set_preload(self, f0: float):
        """Hook preload f0 [N, total]: n0 of every pair and the static loads that press
        the hook faces together (scaled from the deck's, written for F0_DEFAULT)."""
        self.model.contacts[self._hooks].params[:, self._n0] = f0 / self.n_pairs
        self.excitation.F[:, 0] = self._static_rest + self._hooks_unit * (f0 / self.n_pairs)

    def frf(self, reverse: bool = False):
        """The FRF over the deck's range (reverse: from its end to its start) and the
        seconds it took; an early stop gives an incomplete FRF, not a warning."""
        import warnings
        from frirom.solver import frf
        w = (self.deck.omega_start, self.deck.omega_end)
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", "frirom: continuation stopped early")
            r = frf(self.model, self.excitation, *(w[::-1] if reverse else w),
                    self.options, outputs=self.deck.outputs)
        return r, time.perf_counter() - t0

    def sampled_peak(self, f_centre: float, half_width: float, n: int = 7):
        """Peak from n solve_point calls over f_centre +- half_width [Hz]: parabola through
        the three highest. Returns (f_peak, amp_peak, seconds, n, omegas, amps)."""
        from frirom.solver import solve_point
        fs = np.linspace(f_centre - half_width, f_centre + half_width, n)
        amps, t0, prev = [], time.perf_counter(), None
        for f in fs:
            p = solve_point(self.model, self.excitation, 2 * np.pi * f, self.options,
                            outputs=self.deck.outputs, start=prev)
            amps.append(p.amp_max[0])
            prev = p
        dt = time.perf_counter() - t0
        amps = np.array(amps)
        j = int(np.clip(np.argmax(amps), 1, n - 2))
        c = np.polyfit(fs[j - 1:j + 2], amps[j - 1:j + 2], 2)
        fp = -c[1] / (2 * c[0]) if c[0] < 0 else fs[j]
        return fp, float(np.polyval(c, fp)), dt, n, fs, amps


def fe_check(rom: Rom, n_modes: int = 10) -> tuple:
    """The sector's ROM (Craig-Bampton + Tran, no contact) against the FE sector at the
    excited nodal diameter: (ROM frequencies, FE frequencies [Hz], largest relative error)
    over the lowest n_modes above 10 Hz, the FE ones by ARPACK on ccx's matrices projected
    on the same harmonic index (independent of the reduction)."""
    from frirom.reduction.cyclic import cyclic_sector
    from frirom.reduction.rom import read_fe_model
    fe = read_fe_model(rom.deck.settings.fe_model)

    def nd(name):
        nodes = fe.node_sets[name]
        key = {(int(a), int(b)): i for i, (a, b) in enumerate(fe.dofs)}
        return fe.coordinates(nodes), np.array([[key.get((int(q), c), -1) for c in (1, 2, 3)]
                                                for q in nodes])
    (cl, dl), (cr, dr) = nd("LEFT"), nd("RIGHT")
    cs = cyclic_sector(cl, dl, cr, dr, rom.deck.settings.cyclic.sectors, fe.n_dof)
    k = rom.model.harmonic_index(1)
    # the vane's six soft-mount modes (below 10 Hz, cases/models/hooks.py) are left out:
    # their relative error says nothing of the modes that matter
    f_fe = cs.frequencies(fe.K, fe.M, k, n_modes + 6, method="arpack")
    f_rom = rom.model.modes_of(k).omega[:n_modes + 6] / (2 * np.pi)
    keep = f_fe > 10.0
    f_fe, f_rom = f_fe[keep][:n_modes], f_rom[keep][:n_modes]
    return f_rom, f_fe, float(np.max(np.abs(f_rom / f_fe - 1)))


def _peak(r):
    p = r.peak(0)
    return p.omega / (2 * np.pi), p.amplitude


def lug_stick(rom: Rom, res) -> float | None:
    """The smallest stick fraction of the lug's groups over every point of ``res`` (1.0:
    the lug stuck all the time at every point); None when the lug is tied."""
    j = [i for i, g in enumerate(rom.groups) if g.startswith("lug")]
    return float(res.state_fractions[:, j, 0].min()) if j else None


def sweep(rom: Rom, log=print, what: str = "") -> dict:
    """One FRF of ``rom`` over the deck's range; when the continuation stops before the
    end, a second one from the end of the range down to the stop (the two branches then
    cover the range between them, and the peak is the larger of their refined peaks).

    Returns dict: peak (f [Hz], amplitude [m]), seconds (both sweeps), points, curves
    [(f, amp), ...], complete (the range covered), two_way, lug (the lug's smallest stick
    fraction over every point, None when tied), slip (the hooks' slip fraction at the
    peak).
    """
    from frirom._errors import ConvergenceError
    runs, t = [], 0.0
    for reverse in (False, True):
        t0 = time.perf_counter()
        try:
            r, dt = rom.frf(reverse=reverse)
        except ConvergenceError as exc:         # Newton found no first point there
            t += time.perf_counter() - t0
            log(f"{what}: no first point at the {'end' if reverse else 'start'} of the "
                f"range ({str(exc)[:120]})")
            continue
        t += dt
        if reverse and runs:
            log(f"{what}: the continuation stopped at {runs[0].omega[-1] / (2 * np.pi):.3f}"
                " Hz; from the end of the range down, it " + (
                    "reached the start" if r.complete else
                    f"stopped at {r.omega[-1] / (2 * np.pi):.3f} Hz"))
        runs.append(r)
        if r.complete:
            break
    if not runs:
        return dict(peak=(np.nan, np.nan), seconds=t, points=0, timings={}, curves=[],
                    complete=False, two_way=False, lug=None, slip=np.nan)
    covered = runs[-1].complete or (len(runs) == 2
                                    and runs[1].omega[-1] <= runs[0].omega[-1])
    best = max(runs, key=lambda r: r.peak(0).amplitude)
    peak = _peak(best)
    lugs = [x for x in (lug_stick(rom, r) for r in runs) if x is not None]
    curves = [(r.omega / (2 * np.pi), r.amp_max[:, 0]) for r in runs]
    tim = {k: sum(r.timings.get(k, 0.0) for r in runs)
           for k in ("evaluations", "factorizations", "aft", "assembly", "factorization",
                     "solve", "receptance", "fortran_total")}
    log(f"{what}: {t:.2f} s, {sum(len(r) for r in runs)} points, "
        f"{tim['evaluations']:.0f} evaluations, {tim['factorizations']:.0f} LUs; Fortran "
        f"{tim['fortran_total']:.2f} s: " + ", ".join(
            f"{k} {tim[k]:.2f}" for k in ("aft", "assembly", "factorization", "solve",
                                          "receptance")))
    return dict(peak=peak, seconds=t, points=sum(len(r) for r in runs), timings=tim,
                curves=curves, complete=covered, two_way=len(runs) == 2,
                lug=min(lugs) if lugs else None,
                slip=float(best.state_fractions[best.peak(0).index, rom._hooks, 1]))


def run_family(work: Path, size: str = "coarse", f0s=F0_FAMILY, n_gsi=(40,),
               rom1: str = "full", log=print, law: str = "normal1d",
               interlock: str = "contact", lug: str = "own") -> dict:
    """ROM_I and a ROM_II per GSI mode count in n_gsi over the preloads f0s; returns the
    sizes and one row per f0 and mode count."""
    work = Path(work)
    n_gsi = tuple(np.atleast_1d(n_gsi).tolist())
    mk.make(work, size, law=law, interlock=interlock)
    r1 = Rom(work, "rom1", size, law=law)
    r2s = {n: Rom(work, "rom2", size, n, law=law, lug_reduction=lug) for n in n_gsi}
    rows = []
    for f0 in f0s:
        s2s = {}
        for n, r2 in r2s.items():
            r2.set_preload(f0)
            s2s[n] = sweep(r2, log, f"f0 = {f0:g} N: ROM_II ({n} GSI modes)")
        r1.set_preload(f0)
        if rom1 == "full":
            s1 = sweep(r1, log, f"f0 = {f0:g} N: ROM_I")
            (f1, a1), t1 = s1["peak"], s1["seconds"]
            extrap = False
        else:
            f2 = s2s[n_gsi[0]]["peak"][0]
            f1, a1, ts, n, fs, amps = r1.sampled_peak(f2, 0.004 * f2 + 0.5)
            t1 = ts / n * s2s[n_gsi[0]]["points"]
            s1 = dict(curves=[(fs, amps)], complete=True, two_way=False, lug=None,
                      points=None)
            extrap = True
        for n, s2 in s2s.items():
            (f2, a2), t2 = s2["peak"], s2["seconds"]
            row = dict(f0=f0, n_gsi=n, f1=f1, a1=a1, f2=f2, a2=a2, t1=t1, t2=t2,
                       extrap=extrap, complete=s1["complete"] and s2["complete"],
                       two_way=[s1["two_way"], s2["two_way"]],
                       pts1=s1["points"], pts2=s2["points"],
                       amp_err=a2 / a1 - 1.0, freq_err=f2 / f1 - 1.0, slip=s2["slip"],
                       timings1=s1.get("timings", {}), timings2=s2.get("timings", {}),
                       lug_stick=[s1["lug"], s2["lug"]],
                       curve1=s1["curves"], curve2=s2["curves"])
            rows.append(row)
            lug1 = s1["lug"]
            log(f"f0 = {f0:g} N: ROM_I {a1:.4e} m at {f1:.3f} Hz, ROM_II ({n} GSI) "
                f"{a2:.4e} m at {f2:.3f} Hz ({row['amp_err']:+.2e}, "
                f"{row['freq_err']:+.2e}); {t1:.1f} s{' (extrapolated)' if extrap else ''}"
                f" vs {t2:.1f} s"
                + ("" if row["lug_stick"][1] is None else
                   f"; lug stick fraction, smallest over the FRF: ROM_I "
                   f"{'-' if lug1 is None else f'{lug1:.4f}'}, "
                   f"ROM_II {row['lug_stick'][1]:.4f}"))
    f_rom, f_fe, err = fe_check(r1)
    log(f"ROM_I sector (CB + Tran, no contact) vs FE at nodal diameter "
        f"{min(r1.model.harmonic_index(1), 24 - r1.model.harmonic_index(1))}: largest "
        f"error {err:.2e} over {f_fe.size} modes ({f_fe[0]:.2f} .. {f_fe[-1]:.2f} Hz)")
    r2 = r2s[n_gsi[0]]
    return dict(size=size, n_gsi=n_gsi, sizes1=r1.sizes, sizes2=r2.sizes,
                sizes2_all={n: r.sizes for n, r in r2s.items()}, fe_err=err,
                reduction_s=r2.reduction_s, rows=rows, rom1=r1, rom2=r2)


def sizes_table(res) -> str:
    """The paper's DoF partitions of ROM_I and ROM_II (section 3.2.1)."""
    s1, s2 = res["sizes1"], res["sizes2"]
    act = s1["coords"] - s1["contact_dofs"] - 2 * s1["boundary"] - s1["cb"]
    lug = (f"the lug's {s1['lug_pairs']} pairs a stuck contact" if s1["lug_pairs"]
           else "the lug tied")
    lines = [f"vane segment with hooks, {res['size']} mesh: {s1['fe']} FE DoFs, "
             f"{s1['contact_pairs']} hook pairs ({s1['law']}), {lug}, {act} active DoFs, "
             f"cyclic boundary {s1['boundary']} DoFs (each side) -> {s1['tran']} Tran modes "
             f"per nodal diameter, {s1['cb']} CB modes",
             f"{'ROM':>9} {'contact DoFs':>13} {'nonlinear':>10} {'CB coords':>10}"
             f" {'ROM DoFs':>9}",
             ]
    for nm, s in (("ROM_I", s1), *((f"ROM_II {n}", sz) for n, sz in
                                       res.get("sizes2_all", {0: s2}).items())):
        lines.append(f"{nm:>9} {s['contact_dofs']:13d} {s['nonlinear']:10d} {s['coords']:10d}"
                     f" {s['sector_coords']:9d}")
    lines.append("contact DoFs: both sides of the hooks and the lug (ROM_II: the hooks' GSI "
                 "modes + the lug's own coordinates); "
                 "nonlinear: the contact elements' columns; CB coords: the sector with both "
                 "cyclic boundaries; ROM DoFs: contacts + active + Tran + CB modes (the "
                 "paper's 1316 / 436)")
    return "\n".join(lines)


def family_table(res) -> str:
    lines = [f"{'f0 N':>8} {'GSI':>4} {'ROM_I Hz':>10} {'ROM_I m':>10} {'ROM_II Hz':>10} "
             f"{'ROM_II m':>10} {'dA':>9} {'df':>9} {'slip':>5} {'lug':>5} {'t_I s':>8}"
             f" {'t_II s':>7} {'speed-up':>8}"]

    def lug(r):
        v = [x for x in r["lug_stick"] if x is not None]
        return f"{min(v):5.3f}" if v else f"{'tied':>5}"
    for r in res["rows"]:
        lines.append(f"{r['f0']:8g} {r['n_gsi']:4d} {r['f1']:10.3f} {r['a1']:10.4e} "
                     f"{r['f2']:10.3f} "
                     f"{r['a2']:10.4e} {r['amp_err']:+9.2e} {r['freq_err']:+9.2e} "
                     f"{r['slip']:5.2f} {lug(r)} {r['t1']:8.1f}{'*' if r['extrap'] else ' '}"
                     f"{r['t2']:7.1f} {r['t1'] / r['t2']:8.1f}"
                     + ("" if not r["complete"] or (abs(r["amp_err"]) <= 0.01
                                                      and abs(r["freq_err"]) <= 0.001)
                        else "  MISSES 1 % / 0.1 %")
                     + "".join(f"  <> {nm}: two sweeps" for nm, two in
                               zip(("ROM_I", "ROM_II"), r["two_way"]) if two)
                     + ("" if r["complete"] else "  ! the range is not covered"))
    lines.append("dA, df: ROM_II's peak amplitude and frequency against ROM_I's; slip: the "
                 "hooks' slip fraction at ROM_II's peak; lug: the lug's smallest stick "
                 "fraction over both FRFs (1: stuck at every point)")
    if any(any(r["two_way"]) for r in res["rows"]):
        lines.append("<> that ROM's continuation stopped before the end of the range "
                     "(printed above); a second sweep from the end of the range down to the "
                     "stop gave the rest, the peak is the larger of the two refined peaks, "
                     "the time is both sweeps'")
    if not all(r["complete"] for r in res["rows"]):
        lines.append("! the two sweeps of a ROM did not meet: its peak may lie in the gap "
                     "between them (the row is not a comparison)")
    if any(r["extrap"] for r in res["rows"]):
        lines.append("* ROM_I sampled at a few frequencies around ROM_II's peak; its FRF "
                     "time extrapolated (time per point x ROM_II's points)")
    return "\n".join(lines)


#: ROM_II markers, one per GSI mode count
MARKERS = (("o", "tab:blue"), ("x", "tab:red"), ("s", "tab:green"))


def plot_family(res, path: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for r in res["rows"]:
        for x1, y1 in r["curve1"] if r["n_gsi"] == res["n_gsi"][0] else ():
            ax.plot(x1, y1, "k-" if not r["extrap"] else "k.", lw=1.2)
        mark, col = MARKERS[res["n_gsi"].index(r["n_gsi"]) % len(MARKERS)]
        for x2, y2 in r["curve2"]:
            step = max(1, len(x2) // 40)
            ax.plot(x2[::step], y2[::step], mark, mfc="none", color=col, ms=5)
        if r["n_gsi"] == res["n_gsi"][0] and np.isfinite(r["a1"]):  # staggered: close
            i = [q["f0"] for q in res["rows"]].index(r["f0"])
            ax.annotate(f"f0 = {r['f0']:g} N", (r["f1"], r["a1"]),
                        textcoords="offset points", xytext=(30, -12 * i - 6), fontsize=8,
                        arrowprops=dict(arrowstyle="-", lw=0.5))
    ax.plot([], [], "k-", label="ROM_I (every contact DoF)")
    for i, n in enumerate(res["n_gsi"]):
        mark, col = MARKERS[i % len(MARKERS)]
        ax.plot([], [], mark, mfc="none", color=col, label=f"ROM_II ({n} GSI modes)")
    peaks = [f for r in res["rows"] for f in (r["f1"], r["f2"]) if np.isfinite(f)]
    ax.set_xlim(min(peaks) - 3.0, max(peaks) + 3.0)       # the resonances, not the flanks
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("airfoil amplitude (OUT:y) [m]")
    ax.set_title(f"Vane segment with hooks ({res['size']}): FRF over the hook preload f0")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def bench_rows(work: Path, quick: bool) -> list[dict]:
    """Rows for cases/bench/paper.py: one per member of the f0 family and GSI mode count
    (the paper's 40, and 80).

    quick: the coarse mesh and two preloads; otherwise the paper-size mesh and the whole
    family. ROM_I's FRFs are run whole and timed in the same run.
    """
    size = "coarse" if quick else "paper"
    res = run_family(Path(work) / "paper_hooks" / size, size,
                     F0_QUICK if quick else F0_FAMILY, n_gsi=(40, 80), rom1="full",
                     log=lambda s: None)
    s1, s2 = res["sizes1"], res["sizes2_all"]
    return [dict(case="hooks", member=f"f0 = {r['f0']:g} N", rom2=f"gsi{r['n_gsi']}",
                 fe_dofs=s1["fe"], rom1_dofs=s1["sector_coords"],
                 rom2_dofs=s2[r["n_gsi"]]["sector_coords"],
                 rom1_nonlinear=s1["nonlinear"],
                 rom2_nonlinear=s2[r["n_gsi"]]["nonlinear"],
                 reduction_s=res["reduction_s"], rom1_frf_s=r["t1"],
                 rom1_extrapolated=r["extrap"], rom2_frf_s=r["t2"],
                 speedup=r["t1"] / r["t2"], peak_amp_err=r["amp_err"],
                 peak_freq_err=r["freq_err"], complete=r["complete"],
                 profile={"ROM_I": (r["t1"], r["pts1"], r["timings1"]),
                          "ROM_II": (r["t2"], r["pts2"], r["timings2"])})
            for r in res["rows"]]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="coarse", choices=sorted(mk.SETTINGS))
    ap.add_argument("--work", type=Path, default=None)
    ap.add_argument("--f0", type=float, nargs="+", default=list(F0_FAMILY))
    ap.add_argument("--gsi", type=int, nargs="+", default=[40],
                    help="GSI mode counts of ROM_II, one ROM each (default 40)")
    ap.add_argument("--rom1", choices=("full", "sample"), default="full")
    ap.add_argument("--law", choices=mk.LAWS, default="normal1d")
    ap.add_argument("--interlock", choices=mk.INTERLOCKS, default="contact")
    ap.add_argument("--lug", choices=mk.LUG_REDUCTIONS, default="own",
                    help="ROM_II's contact lug: its own full-stick GSI modes (default), "
                         "kept physical, or shared with the hooks' GSI basis")
    a = ap.parse_args(argv)
    work = a.work or Path("results/paper_hooks") / a.size
    res = run_family(work, a.size, a.f0, a.gsi, a.rom1, law=a.law, interlock=a.interlock,
                     lug=a.lug)
    print()
    print(sizes_table(res))
    print(family_table(res))
    plot_family(res, work / "fig6.png")
    print(f"wrote {work / 'fig6.png'}")


if __name__ == "__main__":
    main()
