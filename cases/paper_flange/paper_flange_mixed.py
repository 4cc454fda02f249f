"""The multi-stage flange with different sector counts (issue 11, item 1's variant): stage 1
of N1 sectors, stage 2 of N2, coupled at the flange on their common spatial harmonics.

    python cases/paper_flange/paper_flange_mixed.py [--quick] [--sectors N1 N2] [--work DIR]
                                                    [--f0 1 300] [--descending] [--spectrum]

Model: the bolted assembly of cases/paper_flange (cases/models/flange.py, ``sectors2``):
both stages full annulus, steel, ccx writes the matrices at run time. The contact-circle
nodes of the two faces coincide, so both faces have NZ = a common multiple of N1 and N2
radial line segments (paper size 50 + 60 sectors, NZ = 300; ``--quick`` 20 + 30 sectors,
NZ = 60; ``--sectors N1 N2`` any pair, NZ = lcm); the stages share the face nodes on the
bolt circle at both stages' bolt angles.
Excitation: one EO 2 travelling wave per stage (stage 2 clocked), on the mid-airfoil node
of every blade.

ROMs (decks in the work folder, each runs with ``frirom run``):

* ``rom1``: Craig-Bampton, every flange DoF physical (ROM_I);
* ``rom2``: multi-stage reduction per face keeping the shared set: the indices that both
  stages' aliasing families z N_s +- j EO share, for the time harmonics j = 0..H
  (:func:`frirom.reduction.multistage.shared_indices`; the case prints the reasoning);
* ``rom2_h2``: index 2 only (the paper's ROM_II for equal sector counts);
* ``rom2_gap``: the shared set without index 0 (the static part of the slipping and lifting
  flange): a basis missing a needed index, to show the failure as a flagged row.

The case prints the index reasoning, Table 1 (sizes), ROM_I's flange energy per spatial
index at the slipping peak (which indices the solution really uses) and the peaks of every
ROM_II against ROM_I at a stuck and a slipping F0 (both stages), each row flagged 'match'
or 'DIFFERS' against the paper's 1 % amplitude / 0.1 % frequency (measured tables and
times: cases/paper_flange/MIXED.md).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import sys
import time
import types
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import paper_flange as pf  # noqa: E402
from paper_flange import flange  # noqa: E402

H = pf.H


@dataclasses.dataclass(frozen=True)
class Mixed:
    """Stage 1 as ``spec`` (sectors N1, ``z_per_sector`` segments per sector, contact and
    damping parameters) and stage 2's sector count ``sectors2`` (N2); NZ = spec.pairs."""

    spec: flange.FlangeSpec
    sectors2: int

    @property
    def n1(self) -> int:
        return self.spec.sectors

    @property
    def n2(self) -> int:
        return self.sectors2

    @property
    def nz(self) -> int:
        return self.spec.pairs

    @property
    def gcd(self) -> int:
        return math.gcd(self.n1, self.n2)

    def key(self) -> str:
        return f"{self.spec.key()}_{self.sectors2}"


def mixed(n1: int, n2: int, quick: bool) -> Mixed:
    """N1 + N2 sectors, NZ = lcm(N1, N2) segments per face; paper mesh and 200 CB modes per
    stage, or (quick) the coarse cross-section and 10 modes; kt = kn = 1e9 N/m as the
    50 + 50 case."""
    nz = math.lcm(n1, n2)
    kw = dict(n_modes=10, coarse=True) if quick else {}
    return Mixed(flange.FlangeSpec(sectors=n1, z_per_sector=nz // n1, kt=1e9, kn=1e9, **kw),
                 n2)


#: the paper's variant: 50 + 60 sectors, NZ = 300; shared set {0, 2, 4, 6}
PAPER = mixed(50, 60, quick=False)
#: coarse, with the paper variant's index structure: gcd 10 (as 50 + 60), so the shared
#: set is {0, 2, 4, 6} and the first index of the exact family besides them is 8; NZ = 60.
#: Fewer sectors alias too low: 10 + 15 (gcd 5) couples index 2 to 3, 5 + 6 (gcd 1) to
#: every index, and the shared set misses there (the case flags it).
QUICK = mixed(20, 30, quick=True)
F0_STUCK, F0_SLIP = 1.0, 300.0          # N per blade (as the 50 + 50 family's ends)
ROMS = {"rom1": "ROM_I", "rom2": "ROM_II shared", "rom2_h2": "ROM_II h=2",
        "rom2_gap": "ROM_II no h=0"}


def spec_of(quick: bool, sectors=None) -> Mixed:
    """PAPER, QUICK, or ``sectors`` = (N1, N2) at the chosen mesh."""
    if sectors is not None:
        return mixed(int(sectors[0]), int(sectors[1]), quick)
    return QUICK if quick else PAPER


# --------------------------------------------------------------------------------------------
# which harmonic indices
# --------------------------------------------------------------------------------------------

def index_sets(m: Mixed) -> dict:
    """Harmonic indices (0..NZ/2) of each ROM, and per time harmonic j = 0..H the families:
    {'j': [(j, k = j EO, family of stage 1, of stage 2, shared, closure mod gcd)],
    'rom2', 'rom2_h2', 'rom2_gap': index lists}."""
    from frirom.reduction.multistage import harmonic_indices, shared_indices
    eo, rows = m.spec.eo, []
    for j in range(H + 1):
        f1 = harmonic_indices(eo, m.n1, m.nz, (j,)).tolist()
        f2 = harmonic_indices(eo, m.n2, m.nz, (j,)).tolist()
        sh = shared_indices(eo, (m.n1, m.n2), m.nz, (j,)).tolist()
        cl = harmonic_indices(eo, m.gcd, m.nz, (j,)).tolist()
        rows.append((j, j * eo, f1, f2, sh, cl))
    shared = shared_indices(eo, (m.n1, m.n2), m.nz, range(H + 1)).tolist()
    return {"j": rows, "rom2": shared, "rom2_h2": [eo],
            "rom2_gap": [h for h in shared if h != 0]}


def _short(v: list, n: int = 8) -> str:
    return str(v) if len(v) <= n else f"[{', '.join(map(str, v[:n]))}, ... {len(v)} in all]"


def print_reasoning(m: Mixed, sets: dict) -> None:
    """The harmonic-index reasoning, printed with the case's numbers."""
    print(f"\nHarmonic indices (NZ = {m.nz} segments per face: indices 0..{m.nz // 2}); "
          f"stage 1 has N1 = {m.n1} sectors, stage 2 N2 = {m.n2}, EO {m.spec.eo}")
    print("  Time harmonic j of an EO excitation has spatial index k = j EO. A stage of N "
          "sectors couples k to its aliases z N +- k (its blades and sectors repeat N "
          "times), so each stage's flange face moves in its own family. The contact pairs "
          "join the two faces index by index (same angle, same segment), so an index "
          "passes between the stages where the two families meet: the shared set. The "
          f"tuned assembly repeats only gcd(N1, N2) = {m.gcd} times, so its exact family is "
          f"z {m.gcd} +- k (the closure, reached through repeated aliasing).")
    for j, k, f1, f2, sh, cl in sets["j"]:
        print(f"  j={j} k={k}: stage 1 {_short(f1)}; stage 2 {_short(f2)}; shared {sh}; "
              f"closure {_short(cl)}")
    print(f"  ROM_II keeps the shared set over j = 0..{H} on each face: {sets['rom2']} "
          f"(h = 2: the forced index; the others: the static part j = 0 and the higher "
          f"time harmonics once the flange slips or lifts off). Index 2 alone is the "
          f"paper's choice; the set without index 0 is a basis missing a needed index.")


# --------------------------------------------------------------------------------------------
# model and decks
# --------------------------------------------------------------------------------------------

def _samples(m: Mixed) -> int:
    """AFT samples: a multiple of lcm over the stages of N / gcd(N, EO) (both travelling
    waves stay cyclic in the sampling), at least 64."""
    eo = m.spec.eo
    step = math.lcm(m.n1 // math.gcd(m.n1, eo), m.n2 // math.gcd(m.n2, eo))
    return int(step * math.ceil(64 / step))


def deck_text(m: Mixed, rom: str, sets: dict, band, beta: float, indices=None) -> str:
    """A deck of the paper_flange template (pf.DECK): ``rom1`` without interface modes,
    else the MS reduction with ``indices`` on both faces (sectors: gcd(N1, N2), which
    only groups the NZ equally spaced segments)."""
    s = m.spec
    ms = "" if indices is None else (
        f"\n[reduction.interface_modes]\nmethod = \"ms\"\nsectors = {m.gcd}\n"
        f"harmonic_indices = {list(indices)}\n")
    return pf.DECK.format(
        label=f"{ROMS[rom]}, {m.n1} + {m.n2} sectors", f0=pf.F0_DECK,
        modes=2 * s.n_modes, rom=rom, ms=ms, kt=s.kt, kn=s.kn, mu=s.mu, n0=s.n0,
        mn0=-s.n0, beta=beta, eo=s.eo,
        dofs1=json.dumps([f"{n}:z" for n in sets["ACTIVE1"]]),
        dofs2=json.dumps([f"{n}:z" for n in sets["ACTIVE2"]]),
        clock=-np.degrees(s.clocking), h=H, samples=_samples(m), f1=band[0], f2=band[1],
        out1=sets["ACTIVE1"][0], out2=sets["ACTIVE2"][0], stability=pf.NO_STABILITY)


def stage1_frequencies(d, sets: dict) -> tuple[float, float]:
    """Stage 1's EO resonance [Hz], stuck and free (pf.linear_frequencies with stage 2's
    load removed): the band and the damping follow stage 1's EO mode, as in the 50 + 50
    case, whose stage 2 answers through the flange. With different sector counts the two
    stages' EO modes lie apart (stage 2 has shorter blades), and the largest participation
    of both loads together may pick stage 2's stuck mode and stage 1's free one."""
    lab = d.reduced
    rows = [lab.dof_index(f"N{n}:UZ") for n in sets["ACTIVE2"]]
    F = d.F.copy()
    F[rows, 1:] = 0.0
    return pf.linear_frequencies(dataclasses.replace(d, F=F))


def make(work: Path, quick: bool, log=print, sectors=None) -> dict:
    """ccx model, ROM_I (for the band and the damping) and the decks of every ROM.
    Returns the info dict (also saved as work/case.json; a rerun with the same model reads
    it)."""
    from frirom.deck import load_deck
    from frirom.io import read_ccx_eigenvalues
    import scipy.linalg as sl
    m = spec_of(quick, sectors)
    work.mkdir(parents=True, exist_ok=True)
    info_path = work / "case.json"
    if info_path.exists():
        info = json.loads(info_path.read_text())
        if info.get("key") == m.key():
            return info
    t0 = time.perf_counter()
    n_ref = 20 if quick else 60
    inp = flange.write_assembly_deck(work / "flange.inp", m.spec, n_ref_modes=n_ref,
                                     sectors2=m.n2)
    flange.run_ccx(inp, expect=(".sti", ".mas", ".dof", ".dat"))
    t_ccx = time.perf_counter() - t0
    log(f"paper_flange_mixed: ccx wrote the {m.n1} + {m.n2} sector assembly in "
        f"{t_ccx:.1f} s")
    _, _, _, sets = flange.assembly_mesh(m.spec, sectors2=m.n2)
    sets = {k: [int(v) for v in vals] for k, vals in sets.items()}
    (work / "rom1.toml").write_text(deck_text(m, "rom1", sets, (1, 2), 0.0))
    t1 = time.perf_counter()
    d = load_deck(work / "rom1.toml")
    t_rom1 = time.perf_counter() - t1
    f_stuck, f_free = stage1_frequencies(d, sets)
    beta = 2 * pf.BETA_ZETA / (2 * np.pi * f_stuck)
    band = (0.97 * f_free, 1.03 * f_stuck)
    mod = d.model()
    lam = sl.eigh(pf._dense(mod.K), pf._dense(mod.M), eigvals_only=True)[:n_ref]
    ref = read_ccx_eigenvalues(work / "flange.dat")[:n_ref]
    cb_err = float(np.max(np.abs(np.sqrt(lam / ref) - 1)))
    log(f"paper_flange_mixed: EO {m.spec.eo} resonance {f_stuck:.2f} Hz stuck, "
        f"{f_free:.2f} Hz free; CB within {100 * cb_err:.3f} % of ccx's lowest {n_ref}")
    idx = index_sets(m)
    for rom in ROMS:
        (work / f"{rom}.toml").write_text(deck_text(m, rom, sets, band, beta, idx.get(rom)))
    info = dict(key=m.key(), quick=quick, f_stuck=f_stuck, f_free=f_free, beta=beta,
                band=band, t_ccx=t_ccx, t_rom1=t_rom1, cb_err=cb_err, n_ref=n_ref,
                sets=sets, fe_dofs=int(d.reduced.T.shape[0]))
    info_path.write_text(json.dumps(info))
    return info


def roms(work: Path, m: Mixed) -> dict:
    """ROM_I from its deck, every ROM_II derived from it (pf.derived: the deck's per-face
    MS reduction applied to ROM_I's Craig-Bampton matrices, without a second CB run; its
    'rom2' keeps [spec.eo], so a namespace whose eo is the index list names the set)."""
    d1, _ = pf.load(work, "rom1")
    idx = index_sets(m)
    out = {"rom1": d1}
    for rom in ROMS:
        if rom != "rom1":
            out[rom] = pf.derived(d1, "rom2", types.SimpleNamespace(eo=idx[rom],
                                                                     sectors=m.gcd))
    return out


# --------------------------------------------------------------------------------------------
# comparison
# --------------------------------------------------------------------------------------------

def compare(decks: dict, f0s, log=print, descending: bool = False) -> dict:
    """FRF of every ROM at each F0: {rom: {f0: pf.sweep result}} (peaks of both stages);
    descending: from the band's end to its start (another way past a fold)."""
    res = {}
    for rom, d in decks.items():
        res[rom] = {}
        band = (d.omega_end, d.omega_start) if descending else None
        for f0 in f0s:
            res[rom][f0] = r = pf.sweep(d, f0, band)
            log(f"  {ROMS[rom]:<15} F0 {f0:g} N: {r['seconds']:.1f} s{pf.stopped(r)}")
    return res


def errors(r: dict, r1: dict) -> tuple[float, float, bool]:
    """Largest relative error over the two stages' peaks (amplitude, frequency) and whether
    both FRFs reached the end of the band."""
    ea = max(abs(r["peak_amp"][k] / r1["peak_amp"][k] - 1) for k in range(2))
    ef = max(abs(r["peak_f"][k] / r1["peak_f"][k] - 1) for k in range(2))
    return ea, ef, bool(r["complete"] and r1["complete"])


def report(m: Mixed, info: dict, decks: dict, res: dict) -> list:
    """Print Table 1 and the peak table; returns the rows (rom, f0, amp err, freq err,
    flag)."""
    print(f"\nTable 1 ({m.n1} + {m.n2} sectors, NZ = {m.nz}, {info['fe_dofs']} FE DoFs; "
          f"CB within {100 * info['cb_err']:.3f} % of ccx over {info['n_ref']} modes)")
    print(f"  {'ROM':<15} {'interface':>9} {'active':>7} {'CB modal':>9} {'total':>6} "
          f"{'nonlinear':>9} {'reduction s':>11}")
    for rom, d in decks.items():
        s = pf.sizes(d)
        t = info["t_rom1"] if rom == "rom1" else d.reduced.build_seconds
        print(f"  {ROMS[rom]:<15} {s['interface']:9d} {s['active']:7d} {s['modal']:9d} "
              f"{s['total']:6d} {s['nonlinear']:9d} {t:11.2f}")
    print("  (ROM_I: ccx's matrices read and Craig-Bampton; ROM_II: the MS step on ROM_I)")
    print("\nPeaks, stage 1 | stage 2, and ROM_II against ROM_I (largest error of the two "
          f"stages; targets {100 * pf.TARGET_AMP:g} % / {100 * pf.TARGET_FREQ:g} %)")
    rows = []
    for f0 in sorted(next(iter(res.values()))):
        r1 = res["rom1"][f0]
        for rom in decks:
            r = res[rom][f0]
            line = (f"  F0 {f0:5g} N {ROMS[rom]:<15} {r['peak_amp'][0]:.4e} m "
                    f"{r['peak_f'][0]:9.3f} Hz | {r['peak_amp'][1]:.4e} m "
                    f"{r['peak_f'][1]:9.3f} Hz {r['seconds']:6.1f} s slip {r['slip']:.2f} "
                    f"lift {r['lift']:.2f}{pf.stopped(r)}")
            if rom != "rom1":
                ea, ef, done = errors(r, r1)
                flag = pf.row_flag(ea, ef, done)
                rows.append((rom, f0, ea, ef, flag))
                line += (f"  err {100 * ea:.3f} % / {100 * ef:.4f} % {flag} "
                         f"(x{r1['seconds'] / max(r['seconds'], 1e-9):.0f})")
            print(line)
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the coarse mesh (20 + 30 sectors "
                    "unless --sectors)")
    ap.add_argument("--sectors", type=int, nargs=2, metavar=("N1", "N2"), default=None,
                    help="sector counts of stages 1 and 2 (default 50 60; --quick 20 30)")
    ap.add_argument("--work", default=None, help="folder of the model, decks and results "
                    "(default results/paper_flange_mixed[_quick])")
    ap.add_argument("--f0", type=float, nargs="+", default=[F0_STUCK, F0_SLIP],
                    help="excitation levels F0 [N per blade] (default: stuck and slipping)")
    ap.add_argument("--descending", action="store_true",
                    help="sweep from the band's end down to its start")
    ap.add_argument("--spectrum", action="store_true",
                    help="also print ROM_I's flange energy per spatial index at the "
                         "largest F0's peak (a load continuation: minutes at paper size)")
    a = ap.parse_args(argv)
    m = spec_of(a.quick, a.sectors)
    work = Path(a.work or f"results/paper_flange_mixed_{m.n1}_{m.n2}"
                          f"{'_quick' if a.quick else ''}").resolve()
    t0 = time.perf_counter()
    info = make(work, a.quick, sectors=a.sectors)
    sets = index_sets(m)
    print_reasoning(m, sets)
    decks = roms(work, m)
    res = compare(decks, a.f0, descending=a.descending)
    report(m, info, decks, res)
    if a.spectrum:
        f0 = max(a.f0)
        f_hz = res["rom1"][f0]["peak_f"][0]
        sp_ = pf.spectrum(decks["rom1"], f0, f_hz, types.SimpleNamespace(sectors=m.gcd))
        print()
        keep = pf.print_spectrum(sp_, f0, f_hz)
        print(f"    indices above 1e-6 of a stage's energy: {_short(keep, 16)}")
    name = "compare" + "_".join([""] + [f"{f:g}" for f in a.f0]) + \
        ("_down" if a.descending else "")
    (work / f"{name}.json").write_text(json.dumps(
        {rom: {f"{f0:g}": {k: r[k] for k in ("peak_amp", "peak_f", "seconds", "complete",
                                              "slip", "lift")} for f0, r in v.items()}
         for rom, v in res.items()}))
    print(f"total {time.perf_counter() - t0:.0f} s; decks in {work} (frirom run "
          f"{work / 'rom2.toml'})")


if __name__ == "__main__":
    main()
