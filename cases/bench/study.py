"""A 6-member family of the lap-joint case, serially and on a 2-worker LocalCluster.

The case's deck (cases/lap_joint/lap_joint.toml: CB 20 modes + GSI 20 free + 20 stick,
700-1000 Hz) made heavier and even: H = 7, N = 128 and a continuation step a third of the
case's (about 230 points), with a ``[study]`` over the modal damping ratio (6 values,
0.0015-0.0025): every member has the same contact pattern and nearly the same number of
points, so six members on two workers are three even rounds (the shaker-amplitude family
of the case has members differing 2x in cost, and at H = 3 they take ~1 s each: too
short and too uneven to show a speed-up). The reduced model is built once before both
runs (the members read it from the content-keyed cache). Both runs are
:func:`frirom.study.run_study` in this process: first ``scheduler = "serial"``, then on a
LocalCluster of 2 single-threaded worker processes started here (its address given as the
scheduler, so the start-up is timed apart). Prints the wall times, the speed-up, the
largest difference between the two runs' curves, the overhead per task (a task whose
member is finished: it reads member.json and returns, i.e. Dask's round trip), and the
CPU accounting that makes a loaded machine visible: per run the members' CPU time, how
many ran at a time (mean and most), each worker's CPU time, and the machine's busy cores
(/proc/stat) of which how many were someone else's.

    OPENBLAS_NUM_THREADS=1 python cases/bench/study.py [--work DIR] [--size 0.008]

Measured: see the README ("Before a run, and many runs").
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
ZETAS = [0.0015, 0.0017, 0.0019, 0.0021, 0.0023, 0.0025]
#: the case's deck made heavier: (text, replacement)
HEAVIER = [("harmonics = 3", "harmonics = 7"), ("samples = 32", "samples = 128"),
           ("step = 0.05", "step = 0.015"), ("max_step = 0.1", "max_step = 0.03")]


def deck(work: Path) -> Path:
    """The case's deck next to the matrices in ``work`` (its job "lap" is then theirs),
    heavier (:data:`HEAVIER`), with the family study."""
    text = (CASE / "lap_joint.toml").read_text()
    for old, new in HEAVIER:
        if old not in text:
            raise ValueError(f"lap_joint.toml has no {old!r}")
        text = text.replace(old, new)
    text += ("\n[study]\nscheduler = \"serial\"\n[study.parameters]\n"
             f"\"damping.zeta\" = {ZETAS}\n")
    path = work / "family.toml"
    path.write_text(text)
    return path


def busy_jiffies() -> tuple:
    """(busy, total) clock ticks of every CPU so far (/proc/stat; (0, 0) elsewhere)."""
    try:
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:]]
    except (OSError, ValueError):
        return 0, 0
    idle = v[3] + (v[4] if len(v) > 4 else 0)
    return sum(v) - idle, sum(v)


def accounting(name: str, summaries: list, wall: float, jiffies: tuple) -> None:
    """Print how the members used the cores: CPU time, concurrency (from their FRF
    intervals), per worker process, and the machine's busy cores during the run."""
    cpu = sum(s["cpu_seconds"] for s in summaries)
    busy = sum(s["seconds"] for s in summaries)
    ev = sorted([(s["started"], 1) for s in summaries] + [(s["ended"], -1)
                                                          for s in summaries])
    most = run = 0
    for _, d in ev:
        run += d
        most = max(most, run)
    per = {}
    for s in summaries:
        per.setdefault(s["pid"], []).append(s)
    ncpu = os.cpu_count() or 1
    (b0, t0), (b1, t1) = jiffies
    machine = ncpu * (b1 - b0) / (t1 - t0) if t1 > t0 else float("nan")
    print(f"{name}: members' CPU {cpu:.1f} s in {wall:.1f} s wall = {cpu / wall:.2f} cores; "
          f"members ran {busy / wall:.2f} at a time on average, at most {most}; each on "
          f"{cpu / busy:.2f} of a core")
    for pid, ss in per.items():
        print(f"    process {pid}: {len(ss)} members, CPU {sum(x['cpu_seconds'] for x in ss):.1f}"
              f" s, FRF wall {sum(x['seconds'] for x in ss):.1f} s")
    print(f"    machine: {machine:.2f} of {ncpu} cores busy during the run, "
          f"{max(machine - cpu / wall, 0.0):.2f} of them not this study's")


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
    j0 = busy_jiffies()
    t = time.perf_counter()
    ser = run_study(path, work / "serial", scheduler="serial", **quiet)
    t_ser = time.perf_counter() - t
    j_ser = (j0, busy_jiffies())

    t = time.perf_counter()
    env = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=None, env=env)
    client = Client(cluster)
    client.run(lambda: __import__("frirom.solver"))      # workers import frirom once
    t_start = time.perf_counter() - t
    try:
        j0 = busy_jiffies()
        t = time.perf_counter()
        das = run_study(path, work / "dask", scheduler=cluster.scheduler_address, **quiet)
        t_das = time.perf_counter() - t
        j_das = (j0, busy_jiffies())
        # overhead per task: members already finished, so a task only reads member.json
        jobs = [(str(path), m["values"], str(work / "dask" / "members" / m["name"]),
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
    frf_s = sum(s["seconds"] for s in ser["summaries"])
    print(f"\n6-member family of the lap joint (H = 7, N = 128, damping.zeta {ZETAS}), "
          f"{os.cpu_count()} cores")
    print(f"{'run':<26s}{'wall s':>9s}{'ratio':>8s}")
    print(f"{'serial':<26s}{t_ser:9.1f}{1.0:8.2f}")
    print(f"{'LocalCluster, 2 workers':<26s}{t_das:9.1f}{t_ser / t_das:8.2f}   speed-up")
    print(f"{'  + cluster start':<26s}{t_das + t_start:9.1f}{t_ser / (t_das + t_start):8.2f}"
          f"   (start {t_start:.1f} s)")
    print(f"members' FRF time (serial): {frf_s:.1f} s; study overhead serial "
          f"{t_ser - frf_s:.1f} s")
    print(f"overhead per task (Dask round trip of a finished member): {1e3 * t_task:.0f} ms")
    accounting("serial", ser["summaries"], t_ser, j_ser)
    accounting("dask", das["summaries"], t_das, j_das)
    print(f"largest difference dask vs serial (amp_max, relative): {diff:.1e}")
    print(f"load average before {load0[0]:.1f}, after {load1[0]:.1f} (1 min)")
    for m, s in zip(ser["study"].members, ser["summaries"]):
        w, amp = s["peaks"][0]
        print(f"  {m['name']} zeta {m['values']['damping.zeta']:.4f}:"
              f" peak {amp:.4e} m at {w / 2 / np.pi:7.2f} Hz, {s['points']} points, "
              f"{s['seconds']:.1f} s, CPU {s['cpu_seconds']:.1f} s")


if __name__ == "__main__":
    from _results import record
    record("study", main)
