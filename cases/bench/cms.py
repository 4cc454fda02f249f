"""Craig-Bampton reduction time and peak memory: frirom (Fortran: ARPACK shift-invert on a
MUMPS sparse LDL^T) against scipy (eigsh shift-invert on one SuperLU factor, reused for the
constraint modes), on the same CalculiX-exported matrices in the same run.

    .venv/bin/python cases/bench/cms.py [--work results/bench_cms] [--sizes 10k 50k 150k]

Models: the clamped steel block of cases/models/block.py (C3D8), meshed at three sizes,
exported by ccx (cached in --work). Masters: the IFACE patch on the free end + ACTIVE.
Each (size, modes, solver) runs in its own process, so the peak resident memory of that
process is the peak of that reduction (matrices included); results are appended to
--work/results.jsonl as they come and reused on a rerun (delete the file to remeasure).
The last line is the frirom/scipy time ratio at the largest size and the most modes.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
SIZES = {"10k": (36, 9, 9), "50k": (60, 15, 15), "150k": (90, 22, 22)}


def prepare(work: Path, size: str) -> Path:
    """Deck -> ccx -> matrices -> npz cache (K, M, masters); returns the npz path."""
    npz = work / f"block_{size}.npz"
    if npz.exists():
        return npz
    sys.path.insert(0, str(ROOT / "cases" / "models"))
    import block
    import scipy.sparse as sp

    from frirom.io import read_calculix

    d = work / f"block_{size}"
    deck = block.write_block_deck(d / "block.inp", *SIZES[size], n_ref_modes=0)
    job = block.run_ccx(deck)
    m = read_calculix(job)
    masters = m.dof_indices(["IFACE", "ACTIVE"])
    K, M = sp.csr_matrix(m.K), sp.csr_matrix(m.M)
    np.savez(npz, Kdata=K.data, Kind=K.indices, Kptr=K.indptr, Mdata=M.data,
             Mind=M.indices, Mptr=M.indptr, masters=masters)
    for ext in (".sti", ".mas"):          # big text files, no longer needed
        job.with_suffix(ext).unlink()
    return npz


def one(npz: str, n_modes: int, solver: str) -> None:
    """Child process: one reduction; prints a JSON line."""
    import scipy.sparse as sp

    from frirom.reduction.cb import craig_bampton

    z = np.load(npz)
    n = z["Kptr"].size - 1
    K = sp.csr_matrix((z["Kdata"], z["Kind"], z["Kptr"]), shape=(n, n))
    M = sp.csr_matrix((z["Mdata"], z["Mind"], z["Mptr"]), shape=(n, n))
    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    t0 = time.perf_counter()
    cb = craig_bampton((K, M), n_modes, masters=z["masters"], solver=solver)
    dt = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    w = np.linalg.eigvalsh(np.linalg.solve(np.linalg.cholesky(cb.M),
                                           np.linalg.solve(np.linalg.cholesky(cb.M),
                                                           cb.K).T))
    print(json.dumps(dict(n_dof=n, n_masters=int(cb.n_masters), time=dt, peak_mb=peak,
                          base_mb=base, eig=cb.eigenvalues.tolist(),
                          rom_f1=float(np.sqrt(w[0]) / 2 / np.pi))))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", default=str(ROOT / "results" / "bench_cms"))
    ap.add_argument("--sizes", nargs="+", default=list(SIZES), choices=list(SIZES))
    ap.add_argument("--modes", nargs="+", type=int, default=[50, 200])
    ap.add_argument("--one", nargs=3, metavar=("NPZ", "MODES", "SOLVER"),
                    help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.one:
        one(a.one[0], int(a.one[1]), a.one[2])
        return
    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    store = work / "results.jsonl"
    done = {}
    if store.exists():
        for line in store.read_text().splitlines():
            r = json.loads(line)
            done[(r["size"], r["modes"], r["solver"])] = r
    for size in a.sizes:
        npz = prepare(work, size)
        for modes in a.modes:
            for solver in ("frirom", "scipy"):
                key = (size, modes, solver)
                if key in done:
                    continue
                res = subprocess.run([sys.executable, __file__, "--one", str(npz), str(modes),
                                      solver], capture_output=True, text=True)
                if res.returncode != 0:
                    raise RuntimeError(f"{key} failed:\n{res.stderr[-3000:]}")
                r = json.loads(res.stdout.strip().splitlines()[-1])
                r.update(size=size, modes=modes, solver=solver)
                done[key] = r
                with open(store, "a") as fh:
                    fh.write(json.dumps(r) + "\n")
                print(f"  {size:>5} {modes:4d} modes {solver:7s} {r['time']:9.2f} s "
                      f"{r['peak_mb']:8.0f} MB", flush=True)
    print(f"\nCraig-Bampton reduction, clamped C3D8 block (ccx matrices); "
          f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', 'default')}")
    print(f"{'DoFs':>8} {'masters':>7} {'modes':>5} {'frirom s':>9} {'scipy s':>9} "
          f"{'ratio':>6} {'frirom MB':>9} {'scipy MB':>9} {'max eig diff':>12}")
    last = None
    for size in a.sizes:
        for modes in a.modes:
            f, s = done.get((size, modes, "frirom")), done.get((size, modes, "scipy"))
            if not f or not s:
                continue
            diff = np.max(np.abs(np.array(f["eig"]) / np.array(s["eig"]) - 1))
            ratio = f["time"] / s["time"]
            print(f"{f['n_dof']:8d} {f['n_masters']:7d} {modes:5d} {f['time']:9.2f} "
                  f"{s['time']:9.2f} {ratio:6.2f} {f['peak_mb']:9.0f} {s['peak_mb']:9.0f} "
                  f"{diff:12.1e}")
            last = (f["n_dof"], modes, ratio)
    if last:
        print(f"frirom/scipy time ratio at {last[0]} DoFs, {last[1]} modes: {last[2]:.2f}")


if __name__ == "__main__":
    from _results import record
    record("cms", main)
