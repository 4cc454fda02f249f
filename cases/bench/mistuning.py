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
study in samples per minute serially and on a LocalCluster of two worker processes (and
its memory per worker), the amplification factor's statistics with friction, stuck and
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
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(ROOT / "tests"))
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
from _mistuned import disk  # noqa: E402

from frirom.mistuning import MistunedDisk, monte_carlo, sample_deviations  # noqa: E402
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
    t0 = time.perf_counter()
    serial = monte_carlo(md, n_fr, STD, seed=1, tuned=tuned)
    t_serial = time.perf_counter() - t0

    def progress(done, total, af):
        print(f"  dask: {done}/{total} samples, amplification so far mean {af.mean():.3f} "
              f"max {af.max():.3f}", flush=True)

    from dask.distributed import Client, LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None) as c:
        with Client(c) as cl:        # workers up and frirom imported before the clock
            cl.run(lambda: __import__("frirom.mistuning"))
            mem = {k: round(v, 1) for k, v in cl.run(_rss).items()}
        t0 = time.perf_counter()
        dist = monte_carlo(md, n_fr, STD, seed=1, scheduler=c.scheduler_address,
                           progress=progress, tuned=tuned)
        t_dask = time.perf_counter() - t0
    assert np.allclose(dist["af"], serial["af"], rtol=1e-10), "Dask and serial differ"
    rate_s = 60 * n_fr / t_serial
    rate_d = 60 * n_fr / t_dask
    print(f"friction study, {n_fr} samples: serial {rate_s:.1f} samples/min, two workers "
          f"{rate_d:.1f} samples/min (speed-up {rate_d / rate_s:.2f}); worker memory {mem} MB")
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
           "dask2_samples_per_min": rate_d, "dask_speedup": rate_d / rate_s,
           "worker_memory_mb": mem, "linear_samples": n_lin,
           "seconds_per_linear_sample": t_lin, "statistics": stats,
           "cpu_count": os.cpu_count()}
    (out / "mistuning.json").write_text(json.dumps(res, indent=1))
    print(f"seconds per mistuned FRF {one.seconds:.2f}, Dask speed-up "
          f"{rate_d / rate_s:.2f}")


def _rss() -> float:
    """Resident memory [MB] of this process (a worker, after loading frirom)."""
    import psutil
    return psutil.Process().memory_info().rss / 2**20


if __name__ == "__main__":
    main()
