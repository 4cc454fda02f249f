"""A mistuning Monte Carlo on a real multi-process Dask cluster: a ``dask scheduler`` and
two ``dask worker`` processes started here; one worker is killed mid-study. Nothing that
finished is lost (its sample file stays and is not recomputed), the study completes on the
surviving worker, and the amplification factors and statistics equal the serial run's."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from _mistuned import lumped_disk
from frirom.mistuning import MistunedDisk, local_cluster, monte_carlo
from frirom.model import Damping
from frirom.reduction.mistuning import mistuning_sector

pytestmark = pytest.mark.slow

N, EO = 24, 3


def _disk():
    d = lumped_disk(N)
    ms = mistuning_sector(d["sector"], d["Ks"], d["Ms"], None, d["blade"], keep=d["tip"])
    wb = np.sqrt(1e6 / 0.1)
    return MistunedDisk(ms, [], ms.T.T @ d["F"], EO, int(ms.reduced(d["tip"])[0]),
                        (0.85 * wb, 1.15 * wb), Damping.rayleigh(0.0, 2e-3 / wb),
                        n_linear=1501)


def _wait(cond, what, timeout=60.0):
    t0 = time.time()
    while not cond():
        if time.time() - t0 > timeout:
            raise TimeoutError(what)
        time.sleep(0.2)


def test_killed_worker_loses_nothing(tmp_path):
    dask = str(Path(sys.executable).with_name("dask"))
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "PYTHONPATH": os.pathsep.join(sys.path)}
    sfile = tmp_path / "scheduler.json"
    procs = []
    try:
        procs.append(subprocess.Popen([dask, "scheduler", "--scheduler-file", str(sfile),
                                       "--no-dashboard", "--port", "0"], env=env,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        _wait(sfile.exists, "scheduler file")
        for _ in range(2):
            procs.append(subprocess.Popen([dask, "worker", "--scheduler-file", str(sfile),
                                           "--nthreads", "1", "--no-nanny",
                                           "--no-dashboard"], env=env,
                                          stdout=subprocess.DEVNULL,
                                          stderr=subprocess.DEVNULL))
        address = json.loads(sfile.read_text())["address"]
        from dask.distributed import Client
        with Client(address) as c:
            _wait(lambda: len(c.scheduler_info()["workers"]) == 2, "two workers")
        disk = _disk()
        killed = {}

        def progress(done, total, af):
            if done == 6 and not killed:
                procs[1].kill()
                procs[1].wait()
                killed["at"] = done
                killed["files"] = {p.name: p.stat().st_mtime_ns
                                   for p in (tmp_path / "out").glob("sample_*.npz")}

        n = 40
        res = monte_carlo(disk, n, 0.02, seed=5, interfaces="stuck", out=tmp_path / "out",
                          scheduler=address, progress=progress)
        assert killed and len(killed["files"]) == 6
        for name, mtime in killed["files"].items():      # not recomputed after the kill
            assert (tmp_path / "out" / name).stat().st_mtime_ns == mtime
        assert len(list((tmp_path / "out").glob("sample_*.npz"))) == n
        serial = monte_carlo(disk, n, 0.02, seed=5, interfaces="stuck")
        assert np.allclose(res["af"], serial["af"], rtol=1e-12, atol=0)
        for a, b in zip(res["stats"]["percentiles"], serial["stats"]["percentiles"]):
            assert a == pytest.approx(b, rel=1e-12, nan_ok=True)
        # a rerun finds every sample on disk and computes none
        again = monte_carlo(disk, n, 0.02, seed=5, interfaces="stuck", out=tmp_path / "out",
                            scheduler=None, progress=lambda *a: pytest.fail("recomputed"))
        assert np.array_equal(again["af"], res["af"])
    finally:
        for p in procs[::-1]:
            if p.poll() is None:
                p.terminate()
                try:
                    p.wait(10)
                except subprocess.TimeoutExpired:
                    p.kill()


def test_local_cluster_workers():
    """frirom's LocalCluster: each worker a session of its own (the kernel shares the CPU
    between sessions), one BLAS thread, glibc's allocator without Dask's
    MALLOC_TRIM_THRESHOLD_ (it freezes the mmap threshold: 16-24 % more CPU per sample),
    Dask's profiler off, frirom imported before any task; a client reused for two studies
    gives the serial results."""
    cluster, client, seconds = local_cluster(2)
    try:
        info = client.run(lambda: (os.getsid(0), os.environ.get("OPENBLAS_NUM_THREADS"),
                                   __import__("dask").config.get(
                                       "distributed.worker.profile.enabled"),
                                   "frirom.solver" in sys.modules,
                                   os.environ.get("MALLOC_TRIM_THRESHOLD_")))
        assert sorted(seconds) == sorted(info) and len(info) == 2
        sids = {v[0] for v in info.values()}
        assert len(sids) == 2 and os.getsid(0) not in sids
        assert all(v[1:] == ("1", False, True, None) for v in info.values())
        disk = _disk()
        for state in ("stuck", "free"):
            res = monte_carlo(disk, 6, 0.02, seed=2, interfaces=state, scheduler=client)
            ref = monte_carlo(disk, 6, 0.02, seed=2, interfaces=state)
            assert np.array_equal(res["af"], ref["af"])
        assert client.status == "running"            # the caller's client stays open
    finally:
        client.close()
        cluster.close()
