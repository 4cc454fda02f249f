"""Benchmark: Monte Carlo of a mistuned 24-blade disk with a friction shroud per blade.

Model: the lattice bladed disk of tests/_mistuned.py (tests/_lattices.py's tuned rotor on
linear supports, a two-node blade per sector, a Jenkins shroud contact from each blade tip
to the next: one friction interface per blade). The tuned sector is reduced once by
Craig-Bampton (masters: both cyclic boundaries, the blade tip) and expanded to the annulus
(no FE annulus is assembled); every sample scatters the clamped-blade modal stiffnesses
(component mode mistuning, frirom.reduction.mistuning). Engine order 3 on the blade tips,
harmonics 0..3.

Measures: the sizes (FE sector and annulus, reduced sector and annulus, contact unknowns),
the seconds of one tuned and one mistuned FRF with friction, the throughput of the friction
study in samples per minute serially and on frirom's LocalCluster of two worker processes
(frirom.mistuning.local_cluster), back to back, three times (min and median speed-up, the
load average before each, CPU seconds per sample serially and in a worker, each worker's
import seconds and memory), the amplification factor's statistics with friction, stuck and
free; writes cases/bench/results/mistuning.json and the figures
cases/bench/results/mistuning_*.png (copied into docs/_static by --docs). Last line: seconds
per mistuned FRF and the Dask speed-up.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python cases/bench/mistuning.py [--quick] [--docs]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics as stat
import sys
import time
from pathlib import Path

# before numpy: one BLAS thread here as in every worker, so that serial and two workers
# compare one core with two
for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")
import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from _mistuned import disk  # noqa: E402

from frirom.mistuning import (MistunedDisk, local_cluster, monte_carlo,  # noqa: E402
                              sample_deviations)
from frirom.mistuning_plots import (plot_amplification, plot_blade_amplitudes,  # noqa: E402
                                    plot_envelopes)
from frirom.model import Damping  # noqa: E402
from frirom.reduction.cyclic import CyclicSector, cyclic_model  # noqa: E402
from frirom.reduction.mistuning import mistuning_sector  # noqa: E402

N, EO, H = 24, 3, 3
STD = 0.03                  # blade stiffness scatter (standard deviation, fraction)
N_MODES = 8                 # fixed-interface modes of the sector
N_BLADE_MODES = 2           # clamped-blade modes that carry the scatter (383 and 669 Hz)


def build() -> tuple[MistunedDisk, dict]:
    d = disk(N, ground=False)
    ms = mistuning_sector(d["sector"], d["Ks"], d["Ms"], N_MODES, d["blade"], keep=d["keep"],
                          n_blade_modes=N_BLADE_MODES)
    contacts = ms.reduce_contacts(d["contacts"])
    sec = CyclicSector(n_dof=ms.n_reduced, n_sectors=N, left=ms.left, right=ms.right,
                       axis=ms.axis, origin=np.zeros(3))
    cm = cyclic_model(sec, ms.K, ms.M, contacts, EO, H, damping=Damping.rayleigh(2.0, 2e-6))
    w1 = cm.modes_of((-EO) % N).omega[0]       # free interfaces, first ND-EO mode
    md = MistunedDisk(ms, contacts, ms.T.T @ d["F"], EO, int(ms.reduced(d["tip"][0])[0]),
                      (0.9 * w1, 1.25 * w1), Damping.rayleigh(2.0, 2e-6),
                      options=dict(harmonics=H, samples=8 * N), n_linear=401)
    n_elem = sum(g.n_elem * g.n_dir for g in md.contacts) * N
    sizes = {"blades": N, "fe_sector_dofs": int(d["Ks"].shape[0]),
             "fe_annulus_dofs": int(d["K"].shape[0]), "reduced_sector": ms.n_reduced,
             "reduced_annulus": ms.n_annulus, "blade_modes": ms.n_blade_modes,
             "contact_unknowns": int(n_elem * (2 * H + 1)), "harmonics": H,
             "fixed_interface_modes": N_MODES}
    return md, sizes


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true",
                    help="4 friction samples, 40 linear (else 100)")
    ap.add_argument("--samples", type=int, default=None, help="friction samples (default 20)")
    ap.add_argument("--docs", action="store_true", help="copy the figures to docs/_static")
    a = ap.parse_args(argv)
    n_fr = a.samples or (4 if a.quick else 20)
    n_lin = 40 if a.quick else 100
    out = HERE / "results"
    out.mkdir(exist_ok=True)
    md, sizes = build()
    print("sizes:", ", ".join(f"{k} {v}" for k, v in sizes.items()))
    tuned = md.response(None, "friction")
    one = md.response(sample_deviations(N, STD, 0, 0), "friction")
    print(f"one FRF with friction: tuned {tuned.seconds:.2f} s ({tuned.omega.size} points), "
          f"mistuned {one.seconds:.2f} s ({one.omega.size} points)")
    speed = _speedup(md, tuned, n_per=4 if a.quick else 8, reps=2 if a.quick else 3)
    t0 = time.perf_counter()
    serial = monte_carlo(md, n_fr, STD, seed=1, tuned=tuned)
    t_serial = time.perf_counter() - t0
    rate_s = 60 * n_fr / t_serial
    print(f"friction study, {n_fr} samples serially: {rate_s:.1f} samples/min, so 200 "
          f"samples in {200 / rate_s:.1f} min")
    t0 = time.perf_counter()
    lin = {st: monte_carlo(md, n_lin, STD, seed=1, interfaces=st) for st in ("stuck", "free")}
    t_lin = (time.perf_counter() - t0) / (2 * n_lin)
    stats = {"friction": serial["stats"], **{k: v["stats"] for k, v in lin.items()}}
    for k, st in stats.items():
        p = {r["percentile"]: r for r in st["percentiles"]}
        print(f"amplification, {k:8s} n {st['n']:4d}: mean {st['mean']:.3f}, max "
              f"{st['max']:.3f}, P95 {p[95]['value']:.3f} [{p[95]['low']:.3f}, "
              f"{p[95]['high']:.3f}]")
    worst = serial["samples"][int(np.argmax(serial["af"]))]
    worst_resp = md.response(worst["deviations"], "friction")
    figs = {"mistuning_blades.png": plot_blade_amplitudes(worst_resp, tuned,
                                                          "Worst friction sample: blade "
                                                          "amplitudes at its peak"),
            "mistuning_af.png": plot_amplification({"friction": serial["af"],
                                                    "stuck": lin["stuck"]["af"],
                                                    "free": lin["free"]["af"]}, N),
            "mistuning_envelope.png": plot_envelopes(serial["samples"], tuned)}
    for name, fig in figs.items():
        fig.savefig(out / name, dpi=110)
        if a.docs:
            shutil.copy(out / name, ROOT / "docs" / "_static" / name)
    res = {"sizes": sizes, "std": STD, "engine_order": EO,
           "seconds_tuned_frf": tuned.seconds, "seconds_mistuned_frf": one.seconds,
           "points_mistuned_frf": int(one.omega.size),
           "friction_samples": n_fr, "serial_samples_per_min": rate_s,
           "dask2_samples_per_min": speed["dask_rate_median"],
           "dask_speedup": speed["speedup_median"], "dask": speed,
           "worker_memory_mb": speed["worker_memory_mb"], "linear_samples": n_lin,
           "seconds_per_linear_sample": t_lin, "statistics": stats,
           "cpu_count": os.cpu_count()}
    (out / "mistuning.json").write_text(json.dumps(res, indent=1))
    print(f"seconds per mistuned FRF {one.seconds:.2f}, Dask speed-up "
          f"{speed['speedup_median']:.2f} (median of {len(speed['speedup'])}, min "
          f"{speed['speedup_min']:.2f}; load average {speed['load_median']:.1f})")


def _speedup(md, tuned, n_per: int, reps: int) -> dict:
    """Serial and two LocalCluster workers back to back, ``reps`` times, ``n_per`` friction
    samples each (the same samples): samples per minute, speed-up, CPU seconds per sample
    (serial and in the workers) and the load average (1 min) before each run. The cluster
    is started and frirom imported in its workers (one at a time: warm_workers) before
    any clock (frirom.mistuning.local_cluster); the seconds of that import are
    reported."""
    out = {"n_per_run": n_per, "serial_rate": [], "dask_rate": [], "speedup": [],
           "load": [], "cpu_serial": [], "cpu_worker": [], "wall_worker": [],
           "process_cpu_serial": [], "process_cpu_worker": []}
    c, cl, imp = local_cluster(2)      # workers up and frirom imported, one at a time
    with c, cl:
        out["worker_import_seconds"] = sorted(round(v, 2) for v in imp.values())
        out["worker_memory_mb"] = sorted(round(v, 1) for v in cl.run(_rss).values())
        for r in range(reps):
            seed = 100 + r                            # fresh samples each repetition
            out["load"].append(os.getloadavg()[0])
            t0 = time.perf_counter()
            s = monte_carlo(md, n_per, STD, seed=seed, tuned=tuned)
            ts = time.perf_counter() - t0
            t0 = time.perf_counter()
            d = monte_carlo(md, n_per, STD, seed=seed, tuned=tuned, scheduler=cl)
            td = time.perf_counter() - t0
            assert np.allclose(d["af"], s["af"], rtol=1e-10), "Dask and serial differ"
            out["serial_rate"].append(60 * n_per / ts)
            out["dask_rate"].append(60 * n_per / td)
            out["speedup"].append(ts / td)
            out["cpu_serial"].append(float(np.mean([x["cpu_seconds"] for x in s["samples"]])))
            out["cpu_worker"].append(float(np.mean([x["cpu_seconds"] for x in d["samples"]])))
            out["wall_worker"].append(float(np.mean([x["seconds"] for x in d["samples"]])))
            out["process_cpu_serial"].append(float(np.mean([x["process_cpu_seconds"]
                                                            for x in s["samples"]])))
            out["process_cpu_worker"].append(float(np.mean([x["process_cpu_seconds"]
                                                            for x in d["samples"]])))
            print(f"  run {r + 1}/{reps} (load average {out['load'][-1]:.1f}): serial "
                  f"{out['serial_rate'][-1]:.1f}/min, two workers {out['dask_rate'][-1]:.1f}"
                  f"/min, speed-up {out['speedup'][-1]:.2f}; CPU s per sample serial "
                  f"{out['cpu_serial'][-1]:.2f}, in a worker {out['cpu_worker'][-1]:.2f} "
                  f"(whole process {out['process_cpu_serial'][-1]:.2f}, "
                  f"{out['process_cpu_worker'][-1]:.2f}; wall in a worker "
                  f"{out['wall_worker'][-1]:.2f})", flush=True)
    out.update(speedup_min=min(out["speedup"]), speedup_median=stat.median(out["speedup"]),
               dask_rate_median=stat.median(out["dask_rate"]),
               load_median=stat.median(out["load"]))
    print(f"Dask speed-up, two workers over serial: min {out['speedup_min']:.2f}, median "
          f"{out['speedup_median']:.2f} (load average {min(out['load']):.1f}.."
          f"{max(out['load']):.1f}); worker import {out['worker_import_seconds']} s, "
          f"memory {out['worker_memory_mb']} MB")
    return out


def _rss() -> float:
    """Resident memory [MB] of this process (a worker, after loading frirom)."""
    import psutil
    return psutil.Process().memory_info().rss / 2**20


if __name__ == "__main__":
    main()
