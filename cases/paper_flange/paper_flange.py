"""The reference paper's multi-stage flange (section 3.3.1, Figs. 9-10, Table 1) end to end:
CalculiX mesh -> Craig-Bampton ROM_I and multi-stage ROM_II through frirom decks -> a family
of forced responses over the excitation level F0, the sizes table, and why ROM_II differs
from ROM_I where it does.

    python cases/paper_flange/paper_flange.py make  [--quick] [--work DIR]
    python cases/paper_flange/paper_flange.py family [--quick] [--work DIR] [--rom1 all|ends]
    python cases/paper_flange/paper_flange.py report [--quick] [--work DIR]

``make`` writes the bolted two-stage assembly (cases/models/flange.py: 50 + 50 sectors, 4
contact pairs per sector, one blade node per sector active), runs ccx, and writes the
decks ``rom1.toml`` (Craig-Bampton: every flange DoF physical), ``rom2.toml`` (ms,
``harmonic_indices = [2]``: the paper's ROM_II), ``rom2_eo.toml`` (ms, ``engine_orders =
[2]``: index 2 and its aliases z N +- 2, the family of time harmonic 1) and
``rom2_family.toml`` (ms, the whole family that EO 2 and its time harmonics 0..3 excite) and
``rom2_tw.toml`` (that family with ``travelling_wave = true``: solved only for the (index,
time harmonic) pairs of the tuned rotor's travelling wave, its reduced model shared) with F0 = 20 N, and one deck per
member of the family (``rom1_F0_<F0>.toml`` ...): each runs with ``frirom run``.
``family`` solves the members with every ROM (ROM_I at paper size: each FRF takes minutes;
``--rom1 ends`` runs it at the smallest and largest F0 only and says so), prints Table 1,
the peak errors of both ROM_IIs against ROM_I (a row per member, flagged where the paper's
target, 1 % amplitude and 0.1 % frequency, is missed), the energy of ROM_I's flange motion
per spatial harmonic index and time harmonic, and draws Figs. 9 and 10 (ROM_I lines, ROM_II
markers, amplitude / F0 normalised by the stuck linear peak, frequency by the stuck
resonance) as ``fig9_stage1.png`` and ``fig10_stage2.png`` in the work folder.

The excitation is axial: F0 on each blade's mid-airfoil node, two clocked EO 2 travelling
waves (stage 2 lags by 0.3 rad). The flange: a normal1d element per contact pair (kt = kn =
1e9 N/m, mu 0.3, bolt preload n0 = 1 000 N per pair balanced by a static load), the stages
bolted by shared nodes at one angle per sector.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[0] / "models"))
import flange  # noqa: E402

H = 3                                   # harmonics of the balance
#: 50 + 50 sectors, 200 pairs, 400 CB modes in all; contact stiffness 1e9 N/m per pair (with
#: the stages bolted by shared nodes, 2e8 would leave the EO 2 modes nearly joint-free)
PAPER = flange.FlangeSpec(kt=1e9, kn=1e9)
QUICK = flange.FlangeSpec(sectors=6, z_per_sector=2, n_modes=10, coarse=True, kt=1e9, kn=1e9)
F0_PAPER = (1.0, 10.0, 30.0, 100.0, 300.0)      # N per blade: full stick .. strong slip
F0_QUICK = (1.0, 30.0, 300.0)
F0_DECK = 20.0                                  # the F0 of rom*.toml
#: rom1_stability.toml: ROM_I with Hill stability on, at an F0 whose curve leans over folds
STABILITY_DECK, F0_STABILITY = "rom1_stability.toml", 30.0
NO_STABILITY = "false     # the paper's comparison needs no Hill stability (it costs time)"
STABILITY = "true      # Hill at every point (on a reduced model: the exponents nearest 0)"
BETA_ZETA = 0.002                               # stiffness damping: zeta at the stuck EO mode
TARGET_AMP, TARGET_FREQ = 0.01, 0.001           # the paper's "perfect match"
ROMS = {
    "rom1": ("ROM_I", ""),
    "rom2": ("ROM_II", "\n[reduction.interface_modes]\nmethod = \"ms\"\nsectors = {n}\n"
                       "harmonic_indices = [{eo}]\n"),
    "rom2_eo": ("ROM_II j=1", "\n[reduction.interface_modes]\nmethod = \"ms\"\n"
                              "sectors = {n}\nengine_orders = [{eo}]\n"),
    "rom2_family": ("ROM_II family", "\n[reduction.interface_modes]\nmethod = \"ms\"\n"
                                     "sectors = {n}\nengine_orders = [{eo}]\n"
                                     "time_harmonics = [0, 1, 2, 3]\n"),
    # the family's model, solved only for the travelling wave's (index, harmonic) pairs
    "rom2_tw": ("ROM_II fam. TW", "\n[reduction.interface_modes]\nmethod = \"ms\"\n"
                                  "sectors = {n}\nengine_orders = [{eo}]\n"
                                  "time_harmonics = [0, 1, 2, 3]\ntravelling_wave = true\n"),
}
#: decks that share another's reduced model (the selection is not a reduction setting)
CACHE_OF = {"rom2_tw": "rom2_family"}

DECK = """title = "Two-stage flange, {label}, F0 = {f0:g} N"
# written by cases/paper_flange/paper_flange.py make (reference paper 3.3.1)

[fe_model]
format = "calculix"
job = "flange"

[reduction]
interface = ["CONTACT1", "CONTACT2"]
active = ["ACTIVE1", "ACTIVE2"]
fixed_interface_modes = {modes}
cache = "{rom}.rom.h5"
{ms}
[[contacts]]
name = "flange"
law = "normal1d"
a = "CONTACT2"
b = "CONTACT1"
normal = "axial"      # +z, from stage 2 (a) towards stage 1 (b); tangent: circumferential
kt = {kt:g}
kn = {kn:g}
mu = {mu:g}
n0 = {n0:g}

[damping]
type = "rayleigh"
alpha = 0.0
beta = {beta:.6e}

[[excitation.load]]   # the bolt preload's reaction: stage 2 pushed to +z, stage 1 to -z
dof = "CONTACT2:z"
harmonic = 0
amplitude = {n0:g}

[[excitation.load]]
dof = "CONTACT1:z"
harmonic = 0
amplitude = {mn0:g}

[[excitation.engine_order]]   # stage 1
eo = {eo}
dofs = {dofs1}
amplitude = {f0:g}

[[excitation.engine_order]]   # stage 2, clocked
eo = {eo}
dofs = {dofs2}
amplitude = {f0:g}
phase = {clock:.6f}

[solver]
harmonics = {h}
samples = {samples}
stability = {stability}

[frequency]
start = {f1:.4f}
end = {f2:.4f}

[outputs]
dofs = ["{out1}:z", "{out2}:z"]
"""


def spec_of(quick: bool) -> flange.FlangeSpec:
    return QUICK if quick else PAPER


def family_of(quick: bool) -> tuple:
    return F0_QUICK if quick else F0_PAPER


def _samples(spec) -> int:
    """AFT samples: a multiple of N / gcd(N, EO) (the travelling wave stays cyclic), >= 64."""
    step = spec.sectors // np.gcd(spec.sectors, spec.eo)
    return int(step * int(np.ceil(64 / step)))


def deck_text(spec, rom: str, f0: float, sets: dict, band, beta: float,
              stability: bool = False) -> str:
    label, ms = ROMS[rom]
    return DECK.format(
        label=label, f0=f0, modes=2 * spec.n_modes, rom=CACHE_OF.get(rom, rom),
        ms=ms.format(n=spec.sectors, eo=spec.eo), kt=spec.kt, kn=spec.kn, mu=spec.mu,
        n0=spec.n0, mn0=-spec.n0, beta=beta, eo=spec.eo,
        dofs1=json.dumps([f"{n}:z" for n in sets["ACTIVE1"]]),
        dofs2=json.dumps([f"{n}:z" for n in sets["ACTIVE2"]]),
        clock=-np.degrees(spec.clocking), h=H, samples=_samples(spec), f1=band[0],
        f2=band[1], out1=sets["ACTIVE1"][0], out2=sets["ACTIVE2"][0],
        stability=STABILITY if stability else NO_STABILITY)


def deck_name(rom: str, f0: float | None = None) -> str:
    return f"{rom}.toml" if f0 is None else f"{rom}_F0_{f0:g}.toml"


def _dense(A) -> np.ndarray:
    return np.asarray(A.toarray() if hasattr(A, "toarray") else A, dtype=float)


def linear_frequencies(d) -> tuple[float, float]:
    """EO resonance [Hz] of a deck's model, stuck (contacts as springs kt, kn) and free
    (contacts removed, bolts kept): the mode of largest |phi^T F_1|^2 / lambda."""
    import scipy.linalg as sl
    m = d.model()
    K, M = _dense(m.K), _dense(m.M)
    import scipy.sparse as sp
    g = m.contacts[0]
    G = sp.csr_matrix(g.G)
    Kc = (G.T @ sp.diags(g.params[:, :2].ravel()) @ G).toarray()   # rows t, n per pair
    out = []
    for Kx in (K + Kc, K):
        lam, phi = sl.eigh(Kx, M)
        part = np.abs(phi.T @ d.F[:, 1]) ** 2 / np.maximum(lam, 1e-30)
        out.append(float(np.sqrt(lam[int(np.argmax(part))]) / (2 * np.pi)))
    return out[0], out[1]


def make(work: Path, quick: bool, log=print) -> dict:
    """ccx model, ROM_I reduction (to find the band and the damping), and every deck.
    Returns the info dict (also saved as work/case.json)."""
    from frirom.deck import load_deck
    from frirom.io import read_ccx_eigenvalues
    spec = spec_of(quick)
    work.mkdir(parents=True, exist_ok=True)
    info_path = work / "case.json"
    if info_path.exists():
        info = json.loads(info_path.read_text())
        if info.get("spec_key") == spec.key():
            _write_decks(work, spec, quick, info["sets"], info["band"], info["beta"],
                         missing_only=True)
            return info
    t0 = time.perf_counter()
    n_ref = 20 if quick else 60
    inp = flange.write_assembly_deck(work / "flange.inp", spec, n_ref_modes=n_ref)
    flange.run_ccx(inp, expect=(".sti", ".mas", ".dof", ".dat"))
    t_ccx = time.perf_counter() - t0
    log(f"paper_flange: ccx wrote the assembly's matrices in {t_ccx:.1f} s")
    _, _, _, sets = flange.assembly_mesh(spec)
    sets = {k: [int(v) for v in vals] for k, vals in sets.items()}
    # provisional band and damping: the reduction does not depend on them
    (work / deck_name("rom1")).write_text(deck_text(spec, "rom1", F0_DECK, sets, (1, 2), 0.0))
    d = load_deck(work / deck_name("rom1"))
    f_stuck, f_free = linear_frequencies(d)
    beta = 2 * BETA_ZETA / (2 * np.pi * f_stuck)
    band = (0.97 * f_free, 1.03 * f_stuck)
    # CB check: the ROM's lowest frequencies (joint without contacts) against ccx's
    m = d.model()
    import scipy.linalg as sl
    lam = sl.eigh(_dense(m.K), _dense(m.M), eigvals_only=True)[:n_ref]
    ref = read_ccx_eigenvalues(work / "flange.dat")[:n_ref]
    cb_err = float(np.max(np.abs(np.sqrt(lam / ref) - 1)))
    log(f"paper_flange: EO {spec.eo} resonance {f_stuck:.2f} Hz stuck, {f_free:.2f} Hz free; "
        f"CB ROM within {100 * cb_err:.3f} % of ccx's lowest {n_ref} frequencies")
    _write_decks(work, spec, quick, sets, band, beta)
    info = dict(spec_key=spec.key(), quick=quick, f_stuck=f_stuck, f_free=f_free, beta=beta,
                band=band, t_ccx=t_ccx, cb_err=cb_err, n_ref=n_ref, sets=sets,
                fe_dofs=int(d.reduced.T.shape[0]), t_rom1_reduction=d.reduced.build_seconds)
    info_path.write_text(json.dumps(info))
    log(f"paper_flange: decks written to {work} ({time.perf_counter() - t0:.1f} s)")
    return info


def _write_decks(work, spec, quick, sets, band, beta, missing_only=False) -> None:
    """rom*.toml (F0_DECK), rom*_F0_<F0>.toml of every ROM, and rom1_stability.toml (ROM_I
    at F0_STABILITY with Hill stability on, the same reduced model and cache)."""
    for rom in ROMS:
        for f0, name in [(F0_DECK, deck_name(rom))] + [(f, deck_name(rom, f))
                                                        for f in family_of(quick)]:
            if not (missing_only and (work / name).exists()):
                (work / name).write_text(deck_text(spec, rom, f0, sets, band, beta))
    if not (missing_only and (work / STABILITY_DECK).exists()):
        (work / STABILITY_DECK).write_text(
            deck_text(spec, "rom1", F0_STABILITY, sets, band, beta, stability=True))


# --------------------------------------------------------------------------------------------
# solving
# --------------------------------------------------------------------------------------------

def load(work: Path, rom: str):
    """The deck of one ROM (reduced model built or read from its cache) and its seconds."""
    from frirom.deck import load_deck
    t0 = time.perf_counter()
    d = load_deck(work / deck_name(rom))
    return d, time.perf_counter() - t0


def derived(d1, rom: str, spec):
    """The deck ``rom``'s ROM_II built from ROM_I's deck ``d1`` in milliseconds: the same
    per-face ``ms_basis`` and ``reduce_interface`` that the deck applies to the
    Craig-Bampton matrices (ROM_I keeps them with the flange physical), so the same model
    without a second Craig-Bampton run (tests/test_paper_flange.py checks the equality).
    Returns a Deck with K, M, F, contacts, outputs replaced and ``reduced`` a namespace of
    labels, node_sets, build_seconds (the MS step)."""
    import types
    from scipy.linalg import block_diag
    from frirom.reduction.interface import reduce_interface
    from frirom.reduction.multistage import harmonic_indices, ms_basis, \
        radial_line_segments
    t0 = time.perf_counter()
    r1 = d1.reduced
    bases, ifaces, mlab = [], [], []
    for name in ("CONTACT1", "CONTACT2"):
        nodes = np.unique(r1.node_sets[name])
        pos = np.array([[r1.dof_index(f"N{n}:U{c}") for c in "XYZ"] for n in nodes])
        xyz = r1.node_xyz[np.searchsorted(r1.node_ids, nodes)]
        if rom == "rom2":
            idx = [spec.eo]
        else:
            nz = radial_line_segments(xyz, spec.sectors).n_segments
            idx = harmonic_indices(spec.eo, spec.sectors, nz,
                                   (1,) if rom == "rom2_eo" else (0, 1, 2, 3))
        ms = ms_basis(xyz, pos, spec.sectors, idx)
        bases.append(ms.basis)
        ifaces.append(ms.interface)
        mlab += ms.labels(f"{name} ")
    red = reduce_interface(d1.K, d1.M, np.concatenate(ifaces), block_diag(*bases),
                           labels=r1.labels, mode_labels=mlab)
    R = red.R.tocsr()
    import scipy.sparse as sp
    contacts = [dataclasses.replace(c, G=sp.csr_matrix(c.G @ R)) for c in d1.contacts]
    outputs = [int(R[o].indices[0]) for o in d1.outputs]
    info = types.SimpleNamespace(labels=red.labels, node_sets=r1.node_sets,
                                 build_seconds=time.perf_counter() - t0)
    settings = d1.settings
    if rom == "rom2_tw":
        # the deck's [reduction.interface_modes] (travelling_wave = true): d.options() then
        # carries the selection, as for the deck itself
        settings = dataclasses.replace(settings, reduction=dataclasses.replace(
            settings.reduction, method="ms", sectors=spec.sectors, engine_orders=(spec.eo,),
            time_harmonics=(0, 1, 2, 3), travelling_wave=True))
    return dataclasses.replace(d1, K=sp.csr_matrix(red.K), M=sp.csr_matrix(red.M),
                               F=np.asarray(R.T @ d1.F), contacts=contacts,
                               outputs=outputs, reduced=info, settings=settings,
                               dof_labels=red.labels)


def unknowns(d) -> int:
    """The condensed solver's unknowns for a deck's model (its LU is that size): the
    nonlinear DoFs or the contact coordinates, whichever is fewer ('auto'), times 2H+1;
    with a travelling-wave selection, the pairs it keeps, two fewer for each pair of
    its direction (SolverOptions.pairs)."""
    from frirom.solver import kept_unknowns
    m, o = d.model(), d.options()
    nl = m.nonlinear_dofs()
    if o.selection is not None:
        n = kept_unknowns(o.selection[nl])
        return n - (0 if o.pairs is None else 2 * int(np.count_nonzero(o.pairs[nl])))
    rows = sum(g.G.shape[0] for g in m.contacts)
    return min(rows, nl.size) * (2 * o.harmonics + 1)


def sizes(d) -> dict:
    """Table 1 partition of a deck's reduced model: interface (physical flange DoFs or MS
    coordinates), active (the blade nodes), CB modal, total, nonlinear (contact DoFs),
    unknowns (of the condensed solver, :func:`unknowns`)."""
    rom = d.reduced
    lab = rom.labels
    n_cb = sum(s.startswith("cb ") for s in lab)
    n_ms = sum("ms h=" in s for s in lab)
    act = {f"N{n}:U{c}" for s in ("ACTIVE1", "ACTIVE2") for n in rom.node_sets[s]
           for c in "XYZ"}
    active = sum(s in act for s in lab)
    return dict(interface=len(lab) - n_cb - active, ms=n_ms, active=active, modal=n_cb,
                total=len(lab), nonlinear=int(d.model().nonlinear_dofs().size),
                unknowns=unknowns(d))


def sweep(d, f0: float, band=None) -> dict:
    """One FRF of a deck's model with the EO load scaled to F0: per stage (the deck's two
    outputs) the curve and the refined peak, the seconds and the evaluations."""
    from frirom.solver import frf
    model, exc = d.model(), d.excitation()
    exc.F[:, 1:] *= f0 / F0_DECK
    w1, w2 = (d.omega_start, d.omega_end) if band is None else band
    t0 = time.perf_counter()
    # peaks solved on the curve; no Hill stability (decks written before it was off)
    opts = dataclasses.replace(d.options(), refine_peak=True, stability=False)
    r = frf(model, exc, w1, w2, opts, outputs=d.outputs)
    sec = time.perf_counter() - t0
    peaks = [r.peak(k) for k in range(2)]
    return dict(f0=f0, seconds=sec, evals=int(r.timings.get("evaluations", 0)),
                complete=bool(r.complete), f=(r.omega / 2 / np.pi).tolist(),
                amp=r.amp_max.T.tolist(), peak_amp=[p.amplitude for p in peaks],
                leak=float(r.leak.max()) if r.leak is not None and len(r) else 0.0,
                peak_f=[p.omega / 2 / np.pi for p in peaks],
                lift=float(np.max(r.state_fractions[:, 0, 2])),
                slip=float(np.max(r.state_fractions[:, 0, 1])))


def seconds_per_eval(d, f0: float, freqs) -> float:
    """solve_point at a few frequencies (each from the previous): seconds per Newton
    evaluation, to extrapolate a slow FRF."""
    from frirom.solver import solve_point
    model, exc = d.model(), d.excitation()
    exc.F[:, 1:] *= f0 / F0_DECK
    t, n, prev = 0.0, 0, None
    for f in freqs:
        t0 = time.perf_counter()
        prev = solve_point(model, exc, 2 * np.pi * f,
                           dataclasses.replace(d.options(), stability=False),
                           outputs=d.outputs, start=prev)
        t += time.perf_counter() - t0
        n += int(prev.timings.get("evaluations", 0))
    return t / max(n, 1)


def spectrum(d, f0: float, f_hz: float, spec) -> dict:
    """Energy of ROM_I's flange motion at (F0, f_hz) per spatial harmonic index and time
    harmonic, per stage: {stage: (NZ/2 + 1, H + 1) fractions of the stage's total}."""
    from frirom.reduction.multistage import harmonic_content
    from frirom.solver import load_curve
    rom = d.reduced
    model, exc = d.model(), d.excitation()
    exc.F[:, 1:] *= f0 / F0_DECK
    out = {}
    dofs, coords = [], []
    for s in ("CONTACT1", "CONTACT2"):
        nodes = rom.node_sets[s]
        dofs.append([rom.dof_index(f"N{n}:U{c}") for n in nodes for c in "XYZ"])
        coords.append(rom.node_xyz[np.searchsorted(rom.node_ids, nodes)])
    # load continuation at the frequency (a cold solve_point near the slipping peak's fold
    # does not converge): its last point is the answer at F0
    curve = load_curve(model, exc, 2 * np.pi * f_hz, 0.01, 1.0,
                       dataclasses.replace(d.options(), stability=False),
                       outputs=np.concatenate(dofs))
    X = curve.X[-1]                                            # (n_out, 2H+1)
    n1 = len(dofs[0])
    for k, (x, c) in enumerate(zip((X[:n1], X[n1:]), coords), start=1):
        e = harmonic_content(c, x.reshape(-1, 3, X.shape[1]), spec.sectors)
        per_j = np.column_stack([e[:, 0]] + [e[:, 2 * j - 1] + e[:, 2 * j]
                                             for j in range(1, H + 1)])
        out[k] = per_j / per_j.sum()
    out["states"] = curve.state_fractions[-1, 0].tolist()
    out["scale"] = float(curve.parameter[-1])      # < 1: the continuation stopped early
    return out


def print_spectrum(sp_: dict, f0: float, f_hz: float, top: int = 4) -> list:
    """Print the energy table; returns the indices that carry > 1e-6 of a stage's energy."""
    keep = set()
    st = sp_["states"]
    sc = float(sp_.get("scale", 1.0))
    if sc < 1 - 1e-9:
        print(f"  (load continuation stopped at {sc:.2f} F0: the table is at F0 = "
              f"{sc * f0:.3g} N, not the peak's load)")
    print(f"  F0 {f0:g} N at {f_hz:.2f} Hz (stick {st[0]:.2f}, slip {st[1]:.2f}, lift-off "
          f"{st[2]:.2f}): energy of the flange motion per time harmonic j and spatial index h")
    for k in (1, 2):
        e = sp_[k]
        for j in range(H + 1):
            col = e[:, j]
            idx = np.argsort(col)[::-1][:top]
            keep |= {int(h) for h in np.nonzero(col > 1e-6)[0]}
            items = ", ".join(f"h={h}: {col[h]:.1e}" for h in idx if col[h] > 0)
            print(f"    stage {k} j={j}: {col.sum():.2e} of the total  [{items}]")
    return sorted(keep)


def row_flag(amp_err: float, f_err: float, complete: bool = True) -> str:
    """'match' within the paper's targets, 'DIFFERS' outside; 'UNKNOWN' when one of the
    two FRFs stopped before the end of the band (its peak may not be the peak)."""
    if not complete:
        return "UNKNOWN (an FRF stopped early)"
    ok = abs(amp_err) <= TARGET_AMP and abs(f_err) <= TARGET_FREQ
    return "match" if ok else "DIFFERS"


def stopped(r: dict) -> str:
    """'' for a complete FRF, else where it stopped: ' STOPPED at <f> Hz'."""
    return "" if r.get("complete", True) else f" STOPPED at {r['f'][-1]:.1f} Hz"


def family(work: Path, quick: bool, rom1: str = "all", log=print) -> dict:
    """Every member with every ROM; ROM_I at the members `rom1` asks for. Saves
    work/family.json and the figures; returns the results."""
    info = make(work, quick, log)
    spec = spec_of(quick)
    fam = family_of(quick)
    res_path = work / "family.json"
    res = json.loads(res_path.read_text()) if res_path.exists() else {}
    if res.get("spec_key") != spec.key():
        res = {"spec_key": spec.key()}
    want1 = fam if rom1 == "all" else (fam[0], fam[-1])
    d1, _ = load(work, "rom1")
    res["rom1_sizes"] = sizes(d1)
    res["rom1_reduction_s"] = d1.reduced.build_seconds
    # the ROM_IIs first (fast), then ROM_I; ROM_II family at paper size costs more than
    # ROM_I (every pair reads its 168 MS coordinates: the solver's entry-by-entry G^T J G
    # assembly is ~90 % of its time), so it follows `rom1` too
    for rom in ("rom2", "rom2_eo", "rom2_tw", "rom1", "rom2_family"):
        d = d1 if rom == "rom1" else derived(d1, rom, spec)
        res.setdefault(rom, {})
        res[rom + "_sizes"] = sizes(d)
        if rom != "rom1":
            res[rom + "_reduction_s"] = info["t_rom1_reduction"] + d.reduced.build_seconds
        slow = rom in ("rom1", "rom2_family") and not quick
        for f0 in sorted(fam, reverse=True):
            key = f"{f0:g}"
            if key in res[rom] or (slow and f0 not in want1):
                continue
            r = sweep(d, f0)
            res[rom][key] = r
            log(f"  {ROMS[rom][0]:<14} F0 {f0:6g} N: peak {r['peak_amp'][0]:.4e} m at "
                f"{r['peak_f'][0]:.3f} Hz (stage 1), {r['seconds']:.1f} s, "
                f"{'complete' if r['complete'] else 'INCOMPLETE'}")
            res_path.write_text(json.dumps(res))
    # the spectrum of ROM_I's answer at its peak, at the weakest and strongest F0
    res.setdefault("spectrum", {})
    for f0 in (fam[0], fam[-1]):
        key = f"{f0:g}"
        if key in res["rom1"] and key not in res["spectrum"]:
            sp_ = spectrum(d1, f0, res["rom1"][key]["peak_f"][0], spec)
            res["spectrum"][key] = {str(k): (np.asarray(v).tolist()) for k, v in sp_.items()}
    res_path.write_text(json.dumps(res))
    return res


def report(work: Path, quick: bool, res: dict) -> None:
    info = json.loads((work / "case.json").read_text())
    spec = spec_of(quick)
    print(f"\nTable 1 (this model: {spec.sectors} + {spec.sectors} sectors, "
          f"{info['fe_dofs']} FE DoFs; paper: 1000 interface DoFs, ROM_I 1700, ROM_II 712)")
    print(f"  {'ROM':<14} {'interface':>9} {'active':>7} {'CB modal':>9} {'total':>6} "
          f"{'nonlinear':>9} {'unknowns':>8} {'reduction s':>11}")
    for rom in ROMS:
        s = res.get(rom + "_sizes")
        if s is None:
            print(f"  {ROMS[rom][0]:<14} not built in this run")
            continue
        print(f"  {ROMS[rom][0]:<14} {s['interface']:9d} {s['active']:7d} {s['modal']:9d} "
              f"{s['total']:6d} {s['nonlinear']:9d} {s.get('unknowns', 0):8d} "
              f"{res[rom + '_reduction_s']:11.1f}")
    print("  unknowns: of the condensed solver (its LU is that size): harmonics of the "
          "nonlinear DoFs or contact coordinates; ROM_II fam. TW: only the (index, harmonic) "
          "pairs of the tuned rotor's travelling wave")
    print(f"  CB ROM within {100 * info['cb_err']:.3f} % of ccx over its lowest "
          f"{info['n_ref']} frequencies (target 0.3 %)")
    print("\nPeaks (stage 1 | stage 2) and errors of ROM_II against ROM_I "
          f"(targets {100 * TARGET_AMP:g} % amplitude, {100 * TARGET_FREQ:g} % frequency)")
    for f0 in family_of(quick):
        key = f"{f0:g}"
        r1 = res["rom1"].get(key)
        for rom in ROMS:
            r = res.get(rom, {}).get(key)
            if r is None:
                print(f"  F0 {f0:6g} {ROMS[rom][0]:<14} not run (--rom1 ends, or stopped)")
                continue
            line = (f"  F0 {f0:6g} {ROMS[rom][0]:<14} {r['peak_amp'][0]:.4e} m "
                    f"{r['peak_f'][0]:9.3f} Hz | {r['peak_amp'][1]:.4e} m "
                    f"{r['peak_f'][1]:9.3f} Hz  {r['seconds']:7.1f} s  slip {r['slip']:.2f} "
                    f"lift {r['lift']:.2f}{stopped(r)}")
            if rom != "rom1" and r1 is not None:
                ea = max(abs(r["peak_amp"][k] / r1["peak_amp"][k] - 1) for k in range(2))
                ef = max(abs(r["peak_f"][k] / r1["peak_f"][k] - 1) for k in range(2))
                done = r.get("complete", True) and r1.get("complete", True)
                line += f"  err {100 * ea:.3f} % / {100 * ef:.4f} % {row_flag(ea, ef, done)}"
            elif rom != "rom1":
                line += "  (no ROM_I at this F0)"
            print(line)
    for key, sp_ in res.get("spectrum", {}).items():
        sp2 = {int(k) if k.isdigit() else k: (np.asarray(v) if k.isdigit() else v)
               for k, v in sp_.items()}
        print()
        keep = print_spectrum(sp2, float(key), res["rom1"][key]["peak_f"][0])
        print(f"    indices above 1e-6 of a stage's energy: {keep}")


def figures(work: Path, quick: bool, res: dict) -> list:
    """Figs. 9 and 10: ROM_I lines, ROM_II markers; amplitude / F0 over the stuck linear
    peak per unit load (ROM_I at the smallest F0, fully stuck), frequency over f_stuck."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    info = json.loads((work / "case.json").read_text())
    fam = family_of(quick)
    ref = res["rom1"].get(f"{fam[0]:g}")
    paths = []
    for k, name in ((0, "fig9_stage1.png"), (1, "fig10_stage2.png")):
        norm = ref["peak_amp"][k] / ref["f0"] if ref else 1.0
        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        names = {"rom1": "ROM_I (line)", "rom2": "ROM_II (h = 2)",
                 "rom2_eo": "ROM_II (EO 2 family, j = 1)",
                 "rom2_family": "ROM_II (family, j = 0..3)",
                 "rom2_tw": "ROM_II (family, travelling wave)"}
        styles = (("rom1", dict(ls="-", lw=1.4)),
                  ("rom2", dict(ls="none", marker="o", ms=3.5, mfc="none")),
                  ("rom2_eo", dict(ls="none", marker="s", ms=3, mfc="none")),
                  ("rom2_family", dict(ls="none", marker="x", ms=3)),
                  ("rom2_tw", dict(ls="none", marker="+", ms=5)))
        drawn = set()
        for i, f0 in enumerate(fam):
            c = f"C{i}"
            for rom, style in styles:
                r = res.get(rom, {}).get(f"{f0:g}")
                if r is None:
                    continue
                f = np.asarray(r["f"]) / info["f_stuck"]
                a = np.asarray(r["amp"][k]) / f0 / norm
                step = max(1, len(f) // 40) if rom != "rom1" else 1
                ax.plot(f[::step], a[::step], color=c, **style)
                drawn.add(rom)
        # the legend names each colour (F0) and each line or marker style (the model), so
        # every marker of every F0 is named
        for i, f0 in enumerate(fam):
            if any(f"{f0:g}" in res.get(rom, {}) for rom, _ in styles):
                ax.plot([], [], color=f"C{i}", lw=4, label=f"F0 = {f0:g} N")
        for rom, style in styles:
            if rom in drawn:
                ax.plot([], [], color="k", label=names[rom], **style)
        ax.set_xlabel("frequency / stuck EO 2 resonance")
        ax.set_ylabel("amplitude / F0, over the stuck peak")
        ax.set_title(f"Stage {k + 1}: ROM_I (lines) vs ROM_II (markers)")
        ax.legend(fontsize=7, loc="best", ncol=2)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        p = work / name
        fig.savefig(p, dpi=120)
        plt.close(fig)
        paths.append(p)
    return paths


# --------------------------------------------------------------------------------------------
# benchmark rows (cases/bench/paper.py)
# --------------------------------------------------------------------------------------------

def bench_rows(work: Path, quick: bool) -> list[dict]:
    """Rows of cases/bench/paper.py: per member of the F0 family, ROM_II (h = 2, the
    paper's) and ROM_II (the family) against ROM_I.

    Keys: case, member, rom2 ('h=2' or 'family'), fe_dofs, rom1_dofs, rom2_dofs,
    rom1_nonlinear, rom2_nonlinear, reduction_s (ROM_II's CB + MS, when its cache was
    built), rom1_frf_s, rom1_extrapolated, rom1_stored, rom2_frf_s, speedup,
    peak_amp_err, peak_freq_err (largest over the two stages' peaks, relative), complete
    (False when the ROM_I or ROM_II FRF stopped before the band's end). The ROM_II FRFs
    run in this call. ROM_I at paper size: a complete FRF stored by ``paper_flange.py
    family`` gives its peaks and its time (``rom1_stored``: timed in that run, not this
    one); for a stopped one the time is sampled (solve_point at 3 frequencies:
    seconds per Newton evaluation x the evaluations of the family ROM_II's FRF, which
    follows the same solution path; ``rom1_extrapolated``) and its peaks are those of the
    case's stored run (family.json, from ``paper_flange.py family``; a member without one
    is run in full here). quick: the coarse model, ROM_I run in full.
    """
    work = Path(work)
    info = make(work, quick, log=lambda *a: None)
    spec = spec_of(quick)
    res_path = work / "family.json"
    res = json.loads(res_path.read_text()) if res_path.exists() else {}
    if res.get("spec_key") != spec.key():
        res = {"spec_key": spec.key(), "rom1": {}}
    d1, _ = load(work, "rom1")
    s1 = sizes(d1)
    two = {rom: derived(d1, rom, spec) for rom in ("rom2", "rom2_eo", "rom2_family",
                                                   "rom2_tw")}
    rows = []
    for f0 in family_of(quick):
        r2 = {rom: sweep(d, f0) for rom, d in two.items()}
        stored = res.get("rom1", {}).get(f"{f0:g}")
        kept = not quick and stored is not None and stored.get("complete", False)
        if quick or stored is None:
            r1 = sweep(d1, f0)
            t1, extrap = r1["seconds"], False
        elif kept:
            # the stored run's whole FRF, timed by `family` (not in this run)
            r1, t1, extrap = stored, stored["seconds"], False
        else:
            r1 = stored
            band = info["band"]
            pe = seconds_per_eval(d1, f0, np.linspace(band[0], band[1], 5)[1:4])
            t1, extrap = pe * r2["rom2_family"]["evals"], True
        for rom, d in two.items():
            r, s2 = r2[rom], sizes(d)
            ea = max(abs(r["peak_amp"][k] / r1["peak_amp"][k] - 1) for k in range(2))
            ef = max(abs(r["peak_f"][k] / r1["peak_f"][k] - 1) for k in range(2))
            rows.append(dict(case="flange", member=f"F0 = {f0:g} N",
                             rom2={"rom2": "h=2", "rom2_eo": "j=1",
                                   "rom2_tw": "fam.TW"}.get(rom, "family"),
                             fe_dofs=info["fe_dofs"], rom1_dofs=s1["total"],
                             rom2_dofs=s2["total"], rom1_nonlinear=s1["nonlinear"],
                             rom2_nonlinear=s2["nonlinear"], rom2_unknowns=s2["unknowns"],
                             leak=r.get("leak", 0.0),
                             reduction_s=info["t_rom1_reduction"] + d.reduced.build_seconds,
                             rom1_frf_s=t1,
                             rom1_extrapolated=extrap, rom1_stored=kept,
                             rom2_frf_s=r["seconds"],
                             speedup=t1 / max(r["seconds"], 1e-12), peak_amp_err=ea,
                             peak_freq_err=ef,
                             complete=bool(r["complete"] and r1.get("complete", True))))
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("what", choices=("make", "family", "report"),
                    help="report: Table 1, the peaks and the figures of the stored results "
                         "(family.json) without solving")
    ap.add_argument("--quick", action="store_true", help="the coarse 6-sector model")
    ap.add_argument("--work", default=None,
                    help="folder of the model, decks and results (default "
                         "results/paper_flange[_quick])")
    ap.add_argument("--rom1", choices=("all", "ends"), default="all",
                    help="members at which ROM_I is solved (paper size: minutes each)")
    a = ap.parse_args(argv)
    work = Path(a.work or f"results/paper_flange{'_quick' if a.quick else ''}").resolve()
    if a.what == "make":
        make(work, a.quick)
        print(f"run one with: frirom run {work / deck_name('rom2')} --out "
              f"{work / 'run_rom2'}")
        return
    t0 = time.perf_counter()
    if a.what == "report":
        res = json.loads((work / "family.json").read_text())
    else:
        res = family(work, a.quick, a.rom1)
    report(work, a.quick, res)
    for p in figures(work, a.quick, res):
        print(f"wrote {p}")
    print(f"total {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
