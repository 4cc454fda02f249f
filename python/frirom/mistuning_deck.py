"""Mistuning decks: a deck with a ``[mistuning]`` table (docs/deck.md, "Mistuning decks").

The tuned sector comes from a sector file (``[model] sector = "sector.npz"``, written by
:func:`write_sector`: the sector's K and M, cyclic boundaries, blade DoFs, reduction
masters, output DoF, the engine-order load of sector 0 and its contacts). ``frirom run``
gives one mistuned disk (the deviations of ``[mistuning]``) against the tuned one in every
interface state of ``study.interfaces`` (default friction); ``frirom study`` with
``[study] kind = "mistuning"`` runs the Monte Carlo study of :func:`frirom.mistuning.
monte_carlo` (sample i seeded from (mistuning.seed, i)), prints partial statistics as
samples arrive and writes the amplification factors and figures. Every malformed field
raises :class:`frirom.InputError` naming the deck and the key path.
"""

from __future__ import annotations

import csv
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ._errors import InputError
from .deck.fields import Context, number, string, table, unknown
from .deck.schema import read_toml

__all__ = ["MistuningDeck", "is_mistuning_deck", "parse_mistuning_deck", "build_disk",
           "run_mistuning_deck", "run_mistuning_study", "write_sector", "read_sector"]

INTERFACES = ("friction", "stuck", "free")
_TOP = {"title", "model", "mistuning", "damping", "excitation", "solver", "frequency",
        "study", "outputs"}


def is_mistuning_deck(path) -> bool:
    """True when the deck file has a ``[mistuning]`` table (read by this module)."""
    return "mistuning" in read_toml(Path(path))


@dataclass(frozen=True)
class MistuningDeck:
    """A checked mistuning deck (see the module doc and docs/deck.md)."""

    path: Path
    title: str
    sector_file: Path
    fixed_interface_modes: int | None
    blade_modes: int | None
    mistuning: dict
    alpha: float
    beta: float
    engine_order: int
    harmonics: int
    samples: int | None
    start_hz: float
    end_hz: float
    linear_points: int
    n_samples: int
    interfaces: tuple
    scheduler: str
    workers: int | None
    study: bool


def parse_mistuning_deck(path) -> MistuningDeck:
    """Check every field of a mistuning deck (no file but the deck is read)."""
    path = Path(path)
    raw = read_toml(path)
    ctx = Context(path)
    unknown(ctx, raw, _TOP, "")
    title = raw.get("title", path.stem)
    if not isinstance(title, str):
        raise ctx.error("title", "a string", title)
    mdl = table(ctx, raw, "model")
    unknown(ctx, mdl, {"sector", "fixed_interface_modes", "blade_modes"}, "model")
    sfile = string(ctx, mdl, "sector", "model.sector", required=True)
    nfi = number(ctx, mdl, "fixed_interface_modes", "model.fixed_interface_modes",
                 integer=True, minimum=1)
    nbm = number(ctx, mdl, "blade_modes", "model.blade_modes", integer=True, minimum=1)
    mis = table(ctx, raw, "mistuning")
    _check_mistuning(ctx, mis)
    dmp = table(ctx, raw, "damping", required=False)
    unknown(ctx, dmp, {"type", "alpha", "beta"}, "damping")
    string(ctx, dmp, "type", "damping.type", default="rayleigh", choices=("rayleigh",))
    alpha = number(ctx, dmp, "alpha", "damping.alpha", default=0.0, nonneg=True)
    beta = number(ctx, dmp, "beta", "damping.beta", default=0.0, nonneg=True)
    exc = table(ctx, raw, "excitation")
    unknown(ctx, exc, {"engine_order"}, "excitation")
    eo = number(ctx, exc, "engine_order", "excitation.engine_order", required=True,
                integer=True, minimum=0)
    sol = table(ctx, raw, "solver", required=False)
    unknown(ctx, sol, {"harmonics", "samples", "linear_points"}, "solver")
    H = number(ctx, sol, "harmonics", "solver.harmonics", default=3, integer=True, minimum=1,
               maximum=64)
    ns = number(ctx, sol, "samples", "solver.samples", integer=True, minimum=2 * H + 1)
    nlin = number(ctx, sol, "linear_points", "solver.linear_points", default=401,
                  integer=True, minimum=3)
    fr = table(ctx, raw, "frequency")
    unknown(ctx, fr, {"start", "end"}, "frequency")
    f0 = number(ctx, fr, "start", "frequency.start", required=True, positive=True)
    f1 = number(ctx, fr, "end", "frequency.end", required=True, positive=True)
    if f1 <= f0:
        raise ctx.error("frequency.end", f"a frequency above frequency.start = {f0:g} Hz",
                        f1)
    if "outputs" in raw:
        raise ctx.error("outputs", "no [outputs] table: the output of every blade is the "
                        "sector file's output DoF")
    st = raw.get("study", {})
    if not isinstance(st, dict):
        raise ctx.error("study", "a table [study]", st)
    study = bool(st)
    if study:
        unknown(ctx, st, {"kind", "samples", "interfaces", "scheduler", "workers"}, "study")
        string(ctx, st, "kind", "study.kind", required=True, choices=("mistuning",))
    n = number(ctx, st, "samples", "study.samples", default=100, integer=True, minimum=1,
               maximum=100000)
    itf = st.get("interfaces", ["friction"])
    if (not isinstance(itf, list) or not itf or len(set(itf)) != len(itf)
            or any(i not in INTERFACES for i in itf)):
        raise ctx.error("study.interfaces", "a non-empty list of distinct names among "
                        "\"friction\", \"stuck\", \"free\"", itf)
    from .deck.schema_study import scheduler_and_workers
    sched, workers = scheduler_and_workers(ctx, st)
    if study and "std" not in mis:
        raise ctx.error("mistuning.std", "a standard deviation (and seed) for a [study] of "
                        "kind \"mistuning\": each sample draws its own deviations (the "
                        "table gives " + ", ".join(sorted(mis)) + ")")
    if study and mis.get("mean", 0.0) != 0.0:
        raise ctx.error("mistuning.mean", "0 (or absent) in a Monte Carlo study: samples "
                        "scatter about the tuned blade", mis["mean"])
    return MistuningDeck(path=path, title=title, sector_file=path.parent / sfile,
                         fixed_interface_modes=nfi, blade_modes=nbm, mistuning=dict(mis),
                         alpha=float(alpha), beta=float(beta), engine_order=int(eo),
                         harmonics=int(H), samples=ns, start_hz=float(f0), end_hz=float(f1),
                         linear_points=int(nlin), n_samples=int(n), interfaces=tuple(itf),
                         scheduler=sched, workers=workers, study=study)


def _check_mistuning(ctx: Context, mis: dict) -> None:
    forms = [k for k in ("std", "deviations", "frequencies") if k in mis]
    if len(forms) != 1:
        raise ctx.error("mistuning", "exactly one of std (with seed, mean), deviations = "
                        "[...] or frequencies = \"file\" (with reference)",
                        forms or "none of them")
    allowed = {"std": {"std", "seed", "mean"}, "deviations": {"deviations"},
               "frequencies": {"frequencies", "reference"}}[forms[0]]
    unknown(ctx, mis, allowed, "mistuning")
    if forms[0] == "std":
        number(ctx, mis, "std", "mistuning.std", nonneg=True, maximum=0.5)
        number(ctx, mis, "seed", "mistuning.seed", integer=True, minimum=0)
        number(ctx, mis, "mean", "mistuning.mean", minimum=-0.5, maximum=0.5)
    elif forms[0] == "deviations":
        v = mis["deviations"]
        if (not isinstance(v, list) or not v or any(isinstance(x, bool) or not isinstance(
                x, (int, float)) or not math.isfinite(x) or x <= -1 for x in v)):
            raise ctx.error("mistuning.deviations", "a list of numbers above -1, one per "
                            "blade", v)
    else:
        string(ctx, mis, "frequencies", "mistuning.frequencies")
        number(ctx, mis, "reference", "mistuning.reference", positive=True)


# --- the sector file ----------------------------------------------------------------------

def _put(d: dict, name: str, A) -> None:
    A = sp.csr_matrix(A)
    d[f"{name}_data"], d[f"{name}_indices"] = A.data, A.indices
    d[f"{name}_indptr"], d[f"{name}_shape"] = A.indptr, np.array(A.shape)


def _get(z, name: str) -> sp.csr_matrix:
    return sp.csr_matrix((z[f"{name}_data"], z[f"{name}_indices"], z[f"{name}_indptr"]),
                         shape=tuple(z[f"{name}_shape"]))


def write_sector(path, K, M, sector, *, blade, keep, output: int, F, contacts,
                 blade_stiffness=None) -> None:
    """Write a tuned sector for a mistuning deck: K, M (n, n); sector: its CyclicSector;
    blade: blade DoFs; keep: more reduction masters (contact, load, output DoFs); output:
    the blade's output DoF; F: (n, H+1) sector 0's load; contacts: ContactGroups on the
    sector's DoFs (n or 2 n columns); blade_stiffness: the blade elements' own stiffness
    (n, n), optional: the mistuning then includes the blade's condensed root stiffness
    and the root DoFs become masters (see :func:`frirom.reduction.mistuning.
    mistuning_sector`)."""
    d = {"left": sector.left, "right": sector.right, "axis": np.asarray(sector.axis, float),
         "n_sectors": sector.n_sectors, "blade": np.asarray(blade), "keep": np.asarray(keep),
         "output": int(output), "F": np.asarray(F, complex),
         "contact_names": np.array([g.name for g in contacts]),
         "contact_laws": np.array([g.law for g in contacts])}
    _put(d, "K", K)
    _put(d, "M", M)
    for i, g in enumerate(contacts):
        _put(d, f"G{i}", g.G)
        d[f"P{i}"] = np.asarray(g.params, float)
    if blade_stiffness is not None:
        _put(d, "Kblade", blade_stiffness)
    np.savez(path, **d)


def read_sector(path: Path, deck: Path | None = None) -> dict:
    """The sector file's contents (InputError naming the deck's model.sector if missing)."""
    from .model import ContactGroup
    from .reduction.cyclic import CyclicSector
    if not path.exists():
        raise InputError(f"{deck or path}: model.sector: {path} does not exist (a sector "
                         "file written by frirom.mistuning_deck.write_sector; for the bundled "
                         "disk run cases/mistuned_disk/make_mistuned_disk.py)")
    try:
        with np.load(path) as z:
            K, M = _get(z, "K"), _get(z, "M")
            sector = CyclicSector(n_dof=K.shape[0], n_sectors=int(z["n_sectors"]),
                                  left=z["left"], right=z["right"], axis=z["axis"],
                                  origin=np.zeros(3))
            groups = [ContactGroup(str(law), _get(z, f"G{i}"), z[f"P{i}"], name=str(name))
                      for i, (name, law) in enumerate(zip(z["contact_names"],
                                                          z["contact_laws"]))]
            kb = _get(z, "Kblade") if "Kblade_data" in z.files else None
            return {"K": K, "M": M, "sector": sector, "blade": z["blade"],
                    "keep": z["keep"], "output": int(z["output"]), "F": z["F"],
                    "contacts": groups, "blade_stiffness": kb}
    except (KeyError, ValueError, OSError) as exc:
        raise InputError(f"{deck or path}: model.sector: {path} is not a sector file "
                         f"({exc})") from None


def build_disk(md: MistuningDeck):
    """The deck's MistunedDisk and its blade count."""
    from .mistuning import MistunedDisk
    from .model import Damping
    from .reduction.mistuning import mistuning_sector
    s = read_sector(md.sector_file, md.path)
    n = s["K"].shape[0]
    nb = np.unique(s["blade"]).size
    if md.blade_modes is not None and md.blade_modes > nb:
        raise InputError(f"{md.path}: model.blade_modes: expected 1..{nb} (the blade has "
                         f"{nb} DoFs), got {md.blade_modes}")
    if md.fixed_interface_modes is not None and md.fixed_interface_modes >= n:
        raise InputError(f"{md.path}: model.fixed_interface_modes: expected fewer than the "
                         f"sector's {n} DoFs, got {md.fixed_interface_modes}")
    if s["F"].shape[1] < 2:
        raise InputError(f"{md.path}: model.sector: the load has no harmonic 1")
    kb = s["blade_stiffness"]
    try:
        ms = mistuning_sector(s["sector"], s["K"], s["M"], md.fixed_interface_modes,
                              s["blade"], keep=s["keep"], n_blade_modes=md.blade_modes,
                              blade_stiffness=kb, keep_root=kb is not None)
    except InputError as exc:
        raise InputError(f"{md.path}: model.sector: {md.sector_file}: {exc}") from None
    contacts = ms.reduce_contacts(s["contacts"])
    opts = {"harmonics": md.harmonics}
    if md.samples is not None:
        opts["samples"] = md.samples
    w = 2 * np.pi * np.array([md.start_hz, md.end_hz])
    disk = MistunedDisk(ms, contacts, ms.T.T @ s["F"], md.engine_order,
                        int(ms.reduced(s["output"])[0]), (float(w[0]), float(w[1])),
                        Damping.rayleigh(md.alpha, md.beta), options=opts,
                        n_linear=md.linear_points)
    return disk


def _deviations(md: MistuningDeck, n_blades: int) -> np.ndarray:
    from .reduction.mistuning import deviations_from_table
    try:
        return deviations_from_table(md.mistuning, n_blades, md.path.parent)
    except InputError as exc:
        raise InputError(f"{md.path}: {exc}") from None


def run_mistuning_deck(path, out=None, log=print) -> dict:
    """``frirom run`` on a mistuning deck: the mistuned disk of ``[mistuning]`` against the
    tuned one in each state of ``study.interfaces``. Writes OUT/blades.csv (each blade's
    deviation and amplitude at the mistuned peak), OUT/frf.csv (largest blade amplitude
    against frequency), OUT/mistuning.json and OUT/blades_<state>.png."""
    from .mistuning_plots import plot_blade_amplitudes
    md = parse_mistuning_deck(path)
    out = Path(out) if out is not None else Path("results") / md.path.stem
    out.mkdir(parents=True, exist_ok=True)
    disk = build_disk(md)
    N = disk.n_blades
    delta = _deviations(md, N)
    log(f"mistuned disk: {N} blades, reduced sector {disk.sector.n_reduced}, annulus "
        f"{disk.sector.n_annulus} coordinates, {disk.sector.n_blade_modes} blade modes; "
        f"deviations mean {delta.mean():+.4f}, std {delta.std():.4f}")
    summary, rows, frf = {}, {}, {}
    for state in md.interfaces:
        tuned = disk.response(None, state)
        mist = disk.response(delta, state)
        af = mist.peak / tuned.peak
        f_pk = float(mist.omega[int(np.argmax(mist.envelope))] / (2 * np.pi))
        log(f"{state}: tuned peak {tuned.peak:.4e}, mistuned {mist.peak:.4e} at "
            f"{f_pk:.2f} Hz (blade {int(np.argmax(mist.blade_peaks))}), amplification "
            f"{af:.4f} ({tuned.seconds + mist.seconds:.1f} s)")
        summary[state] = {"tuned_peak": tuned.peak, "peak": mist.peak, "amplification": af,
                          "peak_hz": f_pk, "blade": int(np.argmax(mist.blade_peaks))}
        rows[state] = mist.blade_peaks
        frf[state] = (tuned, mist)
        fig = plot_blade_amplitudes(mist, tuned, f"{md.title}: {state}")
        fig.savefig(out / f"blades_{state}.png", dpi=110)
    with open(out / "blades.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["blade", "deviation"] + [f"amplitude_{s}" for s in md.interfaces])
        for b in range(N):
            w.writerow([b, f"{delta[b]:.8g}"] + [f"{rows[s][b]:.8g}" for s in md.interfaces])
    with open(out / "frf.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["state", "disk", "frequency_hz", "largest_blade_amplitude"])
        for s, (tuned, mist) in frf.items():
            for name, r in (("tuned", tuned), ("mistuned", mist)):
                for om, a in zip(r.omega, r.envelope):
                    w.writerow([s, name, f"{om / (2 * np.pi):.10g}", f"{a:.8g}"])
    res = {"deck": str(md.path), "title": md.title, "blades": N,
           "deviations": delta.tolist(), "states": summary}
    (out / "mistuning.json").write_text(json.dumps(res, indent=1))
    log(f"results in {out}")
    return res


def _partial(state: str, done: int, total: int, af: np.ndarray) -> str:
    from .mistuning import statistics
    s = f"{state} {done}/{total}: amplification mean {af.mean():.3f}, max {af.max():.3f}"
    if af.size >= 2:
        p = {r["percentile"]: r for r in statistics(af)["percentiles"]}[95]
        s += f", P95 {p['value']:.3f} [{p['low']:.3f}, {p['high']:.3f}]".replace("nan",
                                                                                   "-")
    return s


def run_mistuning_study(path, out=None, scheduler=None, workers=None, log=print,
                        quiet=False, trust_deck_scheduler=False) -> dict:
    """``frirom study`` on a mistuning deck: ``study.samples`` samples per interface state
    (resumable in OUT/samples). Writes OUT/amplification.csv, OUT/statistics.json and the
    figures OUT/amplification.png and OUT/envelope_<state>.png.

    scheduler: ``"serial"``, ``"local"`` or an address; None: FRIROM_SCHEDULER, else the
    deck's study.scheduler (an address from the deck only with ``trust_deck_scheduler``,
    as for every study: :func:`frirom._cluster.choose_scheduler`)."""
    from types import SimpleNamespace

    from ._cluster import choose_scheduler
    from .mistuning import monte_carlo
    from .mistuning_plots import plot_amplification, plot_envelopes
    md = parse_mistuning_deck(path)
    if not md.study:
        raise InputError(f"{md.path}: study: expected a table [study] with kind = "
                         "\"mistuning\" for `frirom study` (`frirom run` runs one disk)")
    out = Path(out) if out is not None else Path("results") / md.path.stem
    out.mkdir(parents=True, exist_ok=True)
    sched = choose_scheduler(SimpleNamespace(scheduler=md.scheduler), scheduler,
                             trust_deck_scheduler, md.path)
    disk = build_disk(md)
    N = disk.n_blades
    std, seed = float(md.mistuning["std"]), int(md.mistuning.get("seed", 0))
    log(f"mistuning study: {md.n_samples} samples x {list(md.interfaces)}, {N} blades, "
        f"std {std:g}, seed {seed}, scheduler {sched}")
    res = {}
    cluster = client = None
    if sched == "local":            # one cluster for every interface state
        from .mistuning import local_cluster
        cluster, client, _ = local_cluster(workers or md.workers or 2)
    try:
        for state in md.interfaces:
            shown = []

            def progress(done, total, af, state=state, shown=shown):
                if not quiet:
                    log(_partial(state, done, total, af))
                    shown.append(done)
            r = monte_carlo(disk, md.n_samples, std, seed=seed, interfaces=state,
                            out=out / "samples",
                            scheduler=None if sched == "serial" else (client or sched),
                            workers=workers or md.workers, progress=progress)
            res[state] = r
            if not shown or shown[-1] != md.n_samples:   # quiet, or resumed with all done
                log(_partial(state, md.n_samples, md.n_samples, r["af"]))
            plot_envelopes(r["samples"], r["tuned"]).savefig(out / f"envelope_{state}.png",
                                                             dpi=110)
    finally:
        if client is not None:
            client.close()
            cluster.close()
    with open(out / "amplification.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["sample"] + [f"af_{s}" for s in md.interfaces])
        for i in range(md.n_samples):
            w.writerow([i] + [f"{res[s]['af'][i]:.8g}" for s in md.interfaces])
    stats = {s: {**r["stats"], "tuned_peak": r["tuned"].peak} for s, r in res.items()}
    (out / "statistics.json").write_text(json.dumps(
        {"deck": str(md.path), "blades": N, "std": std, "seed": seed,
         "samples": md.n_samples, "statistics": stats}, indent=1))
    plot_amplification({s: r["af"] for s, r in res.items()}, N).savefig(
        out / "amplification.png", dpi=110)
    log(f"results in {out}")
    return {"statistics": stats, "results": res}
