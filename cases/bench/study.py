"""A 6-member family of the lap-joint case, serially and on a 2-worker LocalCluster.

The case's deck (cases/lap_joint/lap_joint.toml: CB 20 modes + GSI 20 free + 20 stick,
H = 3, N = 32, 700-1000 Hz) with a ``[study]`` over the shaker amplitude (6 values). The
reduced model is built once before both runs (the members read it from its cache file).
Both runs are :func:`frirom.study.run_study` in this process: first ``scheduler =
"serial"``, then on a LocalCluster of 2 single-threaded worker processes started here (its
address given as the scheduler, so the start-up is timed apart). Prints the wall times,
the speed-up, the largest difference between the two runs' curves, the overhead per task
(a task whose member is finished: it reads member.json and returns, i.e. Dask's round
trip) and the load average of the machine (shared machines make the speed-up noisy).

    OPENBLAS_NUM_THREADS=1 python cases/bench/study.py [--work DIR] [--size 0.008]

Measured (2 cores shared with eight other agents; 8 mm mesh, members of 16-25 s here
against about 8 s on an idle machine), three runs as the load fell:

    load (1 min)   serial s   2 workers s   speed-up   cores used serial / 2 workers
    16 -> 14          371.0         274.3       1.35      -
     9 -> 10          188.2         203.3       0.93      -
     8 -> 10          114.3         148.6       0.77      0.58 / 0.50

The last run's CPU accounting says why: on the LocalCluster 1.96 members ran at a time
(the tasks do overlap) but each had 0.26 of a core, so the two workers together had 0.50
cores, the serial run alone 0.58: with 8-16 runnable processes on 2 cores the study gets
about half a core however many processes it has. The curves are the same to the last bit,
the Dask overhead is 3-7 ms per task and the cluster starts in 3-8 s. The target of 1.7x
on 2 cores needs the cores free; it was not measurable today.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "cases" / "lap_joint"
AMPLITUDES = [5.0, 10.0, 15.0, 20.0, 25.0, 30.0]


def deck(work: Path) -> Path:
    """The case's deck next to the matrices in ``work`` (its job "lap" is then theirs),
    with the family study."""
    text = (CASE / "lap_joint.toml").read_text()
    text += ("\n[study]\nscheduler = \"serial\"\n[study.parameters]\n"
             f"\"excitation.load[0].amplitude\" = {AMPLITUDES}\n")
    path = work / "family.toml"
    path.write_text(text)
    return path


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", type=Path, default=ROOT / "results" / "bench_study")
    ap.add_argument("--size", type=float, default=0.008, help="element size [m]")
    a = ap.parse_args(argv)
    work = a.work.resolve()
    work.mkdir(parents=True, exist_ok=True)
    if not (work / "lap.sti").is_file():
        sys.path.insert(0, str(CASE))
        import make_lap_joint
        print(f"making the lap joint's matrices in {work} (gmsh + ccx)")
        make_lap_joint.make(work, size=a.size)

    from distributed import Client, LocalCluster

    from frirom.study import prepare_member, run_member, run_study
    path = deck(work)
    quiet = dict(quiet=True, log=lambda s: None)
    t = time.perf_counter()
    rom = prepare_member(path, {})
    print(f"reduced model: {'reused' if rom['reused'] else 'built'} "
          f"({rom['seconds']:.1f} s to build), {time.perf_counter() - t:.1f} s here")
    load0 = os.getloadavg()

    for d in ("serial", "dask"):
        for f in (work / d).glob("members/*/*"):
            f.unlink()
    t = time.perf_counter()
    ser = run_study(path, work / "serial", scheduler="serial", **quiet)
    t_ser = time.perf_counter() - t

    t = time.perf_counter()
    env = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=None, env=env)
    client = Client(cluster)
    client.run(lambda: __import__("frirom.solver"))      # workers import frirom once
    t_start = time.perf_counter() - t
    try:
        t = time.perf_counter()
        das = run_study(path, work / "dask", scheduler=cluster.scheduler_address, **quiet)
        t_das = time.perf_counter() - t
        # overhead per task: members already finished, so a task only reads member.json
        jobs = [(str(path), m["overrides"], str(work / "dask" / "members" / m["name"]),
                 False) for m in das["study"].members] * 10
        t = time.perf_counter()
        client.gather([client.submit(run_member, *j, pure=False) for j in jobs])
        t_task = (time.perf_counter() - t) / len(jobs)
    finally:
        client.close()
        cluster.close()
    load1 = os.getloadavg()

    def curves(res):
        import h5py
        with h5py.File(res["file"], "r") as f:
            return [f[f"members/{m}/amp_max"][()] for m in sorted(f["members"])]
    diff = max(float(np.abs(x - y).max() / np.abs(y).max()) if x.shape == y.shape
               else float("inf") for x, y in zip(curves(das), curves(ser)))
    frf_s = sum(s["seconds"] for s in ser["summaries"])
    print(f"\n6-member family of the lap joint (shaker amplitude {AMPLITUDES} N), "
          f"{os.cpu_count()} cores")
    print(f"{'run':<26s}{'wall s':>9s}{'ratio':>8s}")
    print(f"{'serial':<26s}{t_ser:9.1f}{1.0:8.2f}")
    print(f"{'LocalCluster, 2 workers':<26s}{t_das:9.1f}{t_ser / t_das:8.2f}   speed-up")
    print(f"{'  + cluster start':<26s}{t_das + t_start:9.1f}{t_ser / (t_das + t_start):8.2f}"
          f"   (start {t_start:.1f} s)")
    print(f"members' FRF time (serial): {frf_s:.1f} s; study overhead serial "
          f"{t_ser - frf_s:.1f} s")
    print(f"overhead per task (Dask round trip of a finished member): {1e3 * t_task:.0f} ms")
    for name, res, wall in (("serial", ser, t_ser), ("dask", das, t_das)):
        cpu = sum(s["cpu_seconds"] for s in res["summaries"])
        busy = sum(s["seconds"] for s in res["summaries"])
        print(f"{name}: members' CPU {cpu:.1f} s in {wall:.1f} s wall: {cpu / wall:.2f} "
              f"cores used; members ran {busy / wall:.2f} at a time, each on "
              f"{cpu / busy:.2f} of a core")
    print(f"largest difference dask vs serial (amp_max, relative): {diff:.1e}")
    print(f"load average before {load0[0]:.1f}, after {load1[0]:.1f} (1 min)")
    for m, s in zip(ser["study"].members, ser["summaries"]):
        w, amp = s["peaks"][0]
        print(f"  {m['name']} amplitude {m['values']['excitation.load[0].amplitude']:5.1f} N:"
              f" peak {amp:.4e} m at {w / 2 / np.pi:7.2f} Hz, {s['points']} points, "
              f"{s['seconds']:.1f} s")


if __name__ == "__main__":
    main()
