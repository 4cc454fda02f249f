"""Forced response of mistuned bladed disks and Monte Carlo studies of their amplification.

:class:`MistunedDisk` holds the tuned sector's reduction (a
:class:`frirom.reduction.mistuning.MistuningSector`), its contacts, the engine-order load
and the output DoF of every blade; :meth:`MistunedDisk.response` gives every blade's
response against frequency for one set of blade deviations with the interfaces in friction
(harmonic balance on the annulus, the ordinary solver), stuck or free (linear, solved per
frequency). The amplification factor of a sample is its largest blade peak over the tuned
disk's peak in the same interface state.

:func:`monte_carlo` runs n samples (deviations normal with a standard deviation, sample i
seeded from (seed, i) so that any subset is reproducible), serially or on a Dask cluster
(a ``distributed`` scheduler address, or a LocalCluster of ``workers`` processes). Every
finished sample is written to ``out/sample_<i>.npz`` as it arrives: a run that dies (or
loses a worker, which Dask reschedules) keeps what finished and a rerun only computes the
rest. :func:`statistics` gives percentiles with distribution-free confidence intervals
(order statistics, binomial coverage), identical however the samples were computed.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.stats import binom

from ._cluster import local_workers
from ._errors import InputError, ParameterError
from .model import Damping
from .reduction.mistuning import (MistuningSector, deviations, stick_stiffnesses,
                                  whitehead_bound)

__all__ = ["MistunedDisk", "Response", "monte_carlo", "statistics", "sample_deviations",
           "local_cluster", "warm_workers", "whitehead_bound"]


@dataclass
class Response:
    """omega (n_w,) rad/s; amplitude (n_w, N) every blade's output amplitude (largest over
    the period for friction, the harmonic's modulus for the linear states)."""

    omega: np.ndarray
    amplitude: np.ndarray
    seconds: float = 0.0

    @property
    def envelope(self) -> np.ndarray:
        return self.amplitude.max(axis=1)

    @property
    def peak(self) -> float:
        return float(self.amplitude.max())

    @property
    def blade_peaks(self) -> np.ndarray:
        """(N,) each blade's amplitude at the frequency of the largest blade peak."""
        return self.amplitude[int(np.argmax(self.envelope))]


@dataclass
class MistunedDisk:
    """A bladed disk to mistune: sector reduction, reduced contacts (n_r or 2 n_r columns),
    sector 0's reduced load F (n_r, H+1), engine order, output reduced coordinate of the
    blade (its direction: a row of reduced coordinates, or one index), damping and the
    frequency band [rad/s]."""

    sector: MistuningSector
    contacts: list
    F: np.ndarray
    engine_order: int
    output: int
    band: tuple
    damping: Damping = field(default_factory=lambda: Damping.rayleigh(0.0, 0.0))
    options: dict = field(default_factory=dict)
    n_linear: int = 301

    @property
    def n_blades(self) -> int:
        return self.sector.n_sectors

    def outputs(self) -> np.ndarray:
        return np.array([self.sector.position(self.output, s) for s in range(self.n_blades)])

    def model(self, delta=None, interfaces: str = "friction"):
        return self.sector.model(delta, self.damping, self.contacts, interfaces)

    def excitation(self):
        return self.sector.excitation(self.F, self.engine_order)

    def linear(self, delta=None, interfaces: str = "stuck") -> "LinearAnnulus":
        """The annulus with stuck or free interfaces in its structural modes."""
        if self.damping.kind != "rayleigh":
            raise ParameterError("MistunedDisk: the linear states take Rayleigh damping")
        K = self.sector.stiffness(delta)
        groups = self.sector.contacts(self.contacts) if interfaces == "stuck" else []
        return LinearAnnulus(K, self.sector.mass(), self.damping.alpha, self.damping.beta,
                             groups)

    def response(self, delta=None, interfaces: str = "friction") -> Response:
        """Every blade's response over the band for deviations ``delta`` (None: tuned)."""
        t0 = time.perf_counter()
        ex = self.excitation()
        out = self.outputs()
        if interfaces == "friction":
            from .solver import SolverOptions, frf
            model = self.model(delta, interfaces)
            r = frf(model, ex, self.band[0], self.band[1], SolverOptions(**self.options),
                    outputs=out)
            if not r.complete:
                raise ParameterError(f"mistuned FRF stopped: {r.message}")
            res = Response(np.asarray(r.omega), np.asarray(r.amp_max))
        else:
            w = np.linspace(self.band[0], self.band[1], self.n_linear)
            lin = self.linear(delta, interfaces)
            amp = np.abs(lin.solve(ex.F[:, 1], w, out))
            w, amp = _refine_peak(lin, ex.F[:, 1], w, amp, out)
            res = Response(w, amp)
        res.seconds = time.perf_counter() - t0
        return res


def linear_response(model, f, omegas, outputs, modes=None) -> np.ndarray:
    """(n_w, n_out) complex harmonic response (K - w^2 M + i w C) x = f at the outputs.

    Rayleigh damping and up to 4000 DoFs: through the modes of (K, M) (``modes`` = (lam,
    phi) if already known, see :func:`linear_modes`; False: never); otherwise one sparse LU
    per frequency."""
    K, M, C = model.K.tocsc(), model.M.tocsc(), model.C.tocsc()
    omegas = np.asarray(omegas, dtype=float)
    d = model.damping
    if modes is None:
        modes = linear_modes(model)
    if modes is not None and modes is not False:
        # modal: C = alpha M + beta K is diagonal in the modes of (K, M)
        lam, phi = modes
        g = phi.T @ np.asarray(f, complex)
        den = (lam[None, :] - omegas[:, None] ** 2
               + 1j * omegas[:, None] * (d.alpha + d.beta * lam[None, :]))
        return (g[None, :] / den) @ phi[np.asarray(outputs)].T
    out = np.empty((len(omegas), len(outputs)), complex)
    for i, w in enumerate(omegas):
        A = (K - w * w * M + 1j * w * C).tocsc()
        out[i] = spla.splu(A).solve(np.asarray(f, complex))[outputs]
    return out


def linear_modes(model):
    """(lam, phi) of (K, M) when the damping is Rayleigh and the model small enough for a
    dense eigen-solve (<= 4000 DoFs), else None."""
    if model.damping.kind != "rayleigh" or model.K.shape[0] > 4000:
        return None
    return sla.eigh(model.K.toarray(), model.M.toarray())


class LinearAnnulus:
    """(K + G^T k G - w^2 M + i w (alpha M + beta K)) x = f through the modes of (K, M):
    the stick stiffness of the contacts (rank r, not damped) enters by the Woodbury
    identity, an r x r solve per frequency."""

    def __init__(self, K, M, alpha, beta, groups=()):
        self.lam, self.phi = sla.eigh(K.toarray(), M.toarray())
        self.alpha, self.beta = alpha, beta
        if groups:
            G = sp.vstack([g.G for g in groups]).tocsr()
            self.k = np.concatenate([stick_stiffnesses(g) for g in groups])
            self.V = np.asarray((G @ self.phi))          # (r, n_modes) = G Phi
        else:
            self.k, self.V = np.zeros(0), np.zeros((0, self.lam.size))

    def solve(self, f, omegas, outputs) -> np.ndarray:
        g = self.phi.T @ np.asarray(f, complex)
        P = self.phi[np.asarray(outputs)]
        out = np.empty((len(omegas), len(outputs)), complex)
        for i, w in enumerate(np.asarray(omegas, float)):
            dinv = 1.0 / (self.lam - w * w + 1j * w * (self.alpha + self.beta * self.lam))
            q = dinv * g
            if self.k.size:
                # (D + V^T k V)^-1 = D^-1 - D^-1 V^T (k^-1 + V D^-1 V^T)^-1 V D^-1
                S = np.diag(1.0 / self.k) + (self.V * dinv) @ self.V.T
                q = q - dinv * (self.V.T @ np.linalg.solve(S, self.V @ q))
            out[i] = P @ q
        return out


def _refine_peak(lin, f, w, amp, out, rounds: int = 3):
    """Add points around the largest blade peak until the grid step there is 1e-3 of the
    band's, so that the peak is found to ~1e-6 relative."""
    for _ in range(rounds):
        i = int(np.argmax(amp.max(axis=1)))
        lo, hi = w[max(i - 1, 0)], w[min(i + 1, w.size - 1)]
        wn = np.linspace(lo, hi, 21)[1:-1]
        an = np.abs(lin.solve(f, wn, out))
        w = np.concatenate([w, wn])
        amp = np.concatenate([amp, an])
        order = np.argsort(w)
        w, amp = w[order], amp[order]
    return w, amp


def sample_deviations(n_blades: int, std: float, seed: int, index: int) -> np.ndarray:
    """Deviations of sample ``index`` of a study seeded ``seed``: its own stream, so any
    sample is reproducible alone (numpy SeedSequence (seed, index))."""
    ss = np.random.SeedSequence([int(seed), int(index)])
    return deviations(n_blades, std, seed=np.random.default_rng(ss).integers(2**63))


def _one(disk: MistunedDisk, std: float, seed: int, index: int, interfaces: str,
         tuned_peak: float) -> dict:
    c0, p0 = time.thread_time(), time.process_time()
    d = sample_deviations(disk.n_blades, std, seed, index)
    r = disk.response(d, interfaces)
    return {"index": index, "deviations": d, "peak": r.peak, "af": r.peak / tuned_peak,
            "blade_peaks": r.blade_peaks, "omega": r.omega, "envelope": r.envelope,
            "seconds": r.seconds, "cpu_seconds": time.thread_time() - c0,
            "process_cpu_seconds": time.process_time() - p0}


def _save(out: Path, tag: str, res: dict) -> None:
    tmp = out / f".{tag}_{res['index']:05d}.npz"
    np.savez(tmp, **res)
    tmp.replace(out / f"{tag}_{res['index']:05d}.npz")


def monte_carlo(disk: MistunedDisk, n_samples: int, std: float, seed: int = 0,
                interfaces: str = "friction", out=None, scheduler: str | None = None,
                workers: int | None = None, progress=None, tuned: Response | None = None
                ) -> dict:
    """Amplification factors of ``n_samples`` mistuning samples.

    out: folder of per-sample files (resumable; default none); scheduler: address of a
    running ``distributed`` scheduler, a ``distributed.Client`` (kept open: one cluster for
    several studies), or 'local' for a LocalCluster of ``workers`` processes (made and
    closed here), or None (serial); progress: callable(done, total, partial_af) after every
    sample; tuned: the tuned disk's Response in the same interface state if already known.
    Returns {'tuned': Response, 'af': (n,), 'samples': [dict], 'stats': ...}.
    """
    if interfaces not in ("friction", "stuck", "free"):
        raise ParameterError(f"interfaces: expected 'friction', 'stuck' or 'free', got "
                             f"{interfaces!r}")
    n = int(n_samples)
    if n < 1:
        raise ParameterError(f"n_samples: expected >= 1, got {n_samples}")
    if tuned is None:
        tuned = disk.response(None, interfaces)
    tag = f"sample_{interfaces}"
    done = {}
    if out is not None:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        meta = {"n_blades": disk.n_blades, "std": std, "seed": seed, "interfaces": interfaces}
        mfile = out / f"study_{interfaces}.json"
        if mfile.exists() and json.loads(mfile.read_text()) != meta:
            raise InputError(f"{mfile}: written by a different study ({mfile.read_text()}); "
                             "use another folder")
        mfile.write_text(json.dumps(meta))
        for i in range(n):
            p = out / f"{tag}_{i:05d}.npz"
            if p.exists():
                with np.load(p) as z:
                    done[i] = {k: z[k] for k in z.files}
    todo = [i for i in range(n) if i not in done]

    def finish(res):
        done[int(res["index"])] = res
        if out is not None:
            _save(out, tag, res)
        if progress is not None:
            progress(len(done), n, np.array([float(v["af"]) for v in done.values()]))

    tp = tuned.peak
    if scheduler is None:
        for i in todo:
            finish(_one(disk, std, seed, i, interfaces, tp))
    else:
        _distributed(disk, std, seed, todo, interfaces, tp, scheduler, workers, finish)
    samples = [done[i] for i in range(n)]
    af = np.array([float(s["af"]) for s in samples])
    return {"tuned": tuned, "af": af, "samples": samples, "stats": statistics(af)}


def _warm() -> float:
    """Run on a worker: import what a sample needs (the import itself happens when this
    function is unpickled there); returns the worker's pid for the caller's bookkeeping."""
    from . import solver  # noqa: F401
    import os
    return os.getpid()


def warm_workers(client) -> dict:
    """Import frirom on every worker of ``client`` that has not yet done so, ONE WORKER AT
    A TIME, before any task runs; returns {worker address: seconds}. An editable install
    (meson-python) checks and rebuilds its extension on the first import in every
    process: workers that import at once race on the same build folder (and a stale build
    fails in all of them); one after the other, the first rebuilds, the rest find it up to
    date. The seconds are each worker's import cost, kept out of the samples' clock."""
    out = {}
    for w in sorted(client.scheduler_info()["workers"]):
        t0 = time.perf_counter()
        client.run(_warm, workers=[w], wait=True)
        out[w] = time.perf_counter() - t0
    return out


def _own_session() -> str:
    """Run on a LocalCluster worker: make it a session of its own (os.setsid)."""
    import os
    try:
        os.setsid()
    except OSError as exc:          # already a session or group leader
        return f"not moved ({exc})"
    return "own session"


def local_cluster(n_workers: int = 2):
    """A LocalCluster of ``n_workers`` one-thread worker processes set up for Monte Carlo
    samples: (cluster, client, {worker: seconds of its frirom import}); close the client
    and the cluster (pass the client to :func:`monte_carlo` for several studies). What
    keeps two workers near twice one on a shared machine:

    - the workers of :func:`frirom._cluster.local_workers` (one BLAS thread, glibc's
      allocator as in a serial run, Dask's profiler and monitors quiet);
    - every worker a session of its own: Linux (``sched_autogroup``) shares the CPU
      between sessions, not processes, and the workers would otherwise share the session
      of the process that started them, so that on a loaded machine two workers got the
      CPU time of one (0.8-1.0x serial at load average 8-14; 1.5-1.8x in their own
      sessions; on an idle machine both ways get a core each);
    - frirom imported in each worker before any task, one worker at a time
      (:func:`warm_workers`).
    """
    from dask.distributed import Client
    cluster = local_workers(n_workers)
    client = Client(cluster)
    try:
        seconds = warm_workers(client)        # first: unpickling imports frirom
        client.run(_own_session)
    except Exception:
        client.close()
        cluster.close()
        raise
    return cluster, client, seconds


def _distributed(disk, std, seed, todo, interfaces, tp, scheduler, workers, finish):
    from dask.distributed import Client, as_completed
    cluster = None
    own = not hasattr(scheduler, "submit")          # a Client of the caller's: keep it
    if not own:
        client = scheduler
    elif scheduler == "local":
        cluster, client, _ = local_cluster(workers or 2)
    else:
        client = Client(scheduler)
    try:
        warm_workers(client)
        # the disk goes to every worker once; each task names it by its key
        fut_disk = client.scatter(disk, broadcast=True, hash=False)
        futs = [client.submit(_one, fut_disk, std, seed, i, interfaces, tp, pure=False,
                              retries=3, key=f"mistuning-{interfaces}-{seed}-{i}")
                for i in todo]
        for f in as_completed(futs):
            finish(f.result())
            f.release()
        fut_disk.release()
    finally:
        if own:
            client.close()
            if cluster is not None:
                cluster.close()


def statistics(af, percentiles=(50, 90, 95, 99), confidence: float = 0.95) -> dict:
    """Mean, max and percentiles of the amplification factors with distribution-free
    confidence intervals: the order statistics x_(l) <= q_p <= x_(u) chosen so that the
    binomial(n, p) probability of l <= #{x < q_p} < u is at least ``confidence``."""
    x = np.sort(np.asarray(af, dtype=float))
    n = x.size
    rows = []
    for p in percentiles:
        q = p / 100.0
        est = float(np.quantile(x, q))
        a = (1 - confidence) / 2
        lo = int(binom.ppf(a, n, q))            # x_(lo) with lo 1-based -> index lo - 1
        hi = int(binom.ppf(1 - a, n, q)) + 1
        rows.append({"percentile": p, "value": est,
                     "low": float(x[lo - 1]) if lo >= 1 else float("nan"),
                     "high": float(x[hi - 1]) if hi <= n else float("nan")})
    return {"n": n, "mean": float(x.mean()), "std": float(x.std(ddof=1)) if n > 1 else 0.0,
            "max": float(x.max()), "percentiles": rows}
