"""Peer run: frirom's nonlinear-mode backbone (EPMC) against tmdsimpy's EPMC on the same
model, at the same truncation (harmonics 0..H, N AFT samples a period).

tmdsimpy (Porter & Brake, github.com/tmd-lab/tmdsimpy, MIT) is run from its public
source in its own environment, never imported into frirom's: this script starts the
peer's Python on itself (``--as-peer``) and exchanges arrays through a temporary .npz.
Install the peer outside the repository, e.g.

    git clone https://github.com/tmd-lab/tmdsimpy /work/peers/tmdsimpy
    python3 -m venv /work/peers/venv && /work/peers/venv/bin/pip install numpy scipy
    python cases/bench/peer_tmdsimpy.py --peer /work/peers/tmdsimpy \\
        --peer-python /work/peers/venv/bin/python

(or the environment variables FRIROM_PEER_TMDSIMPY and FRIROM_PEER_PYTHON). Without the
peer the script says so and exits 0.

The model both codes take exactly: three masses in a chain fixed at one end, two
Jenkins elements (elastic Coulomb, constant slip force: frirom's ``jenkins`` law with
slip force mu fn0, tmdsimpy's ``JenkinsForce`` with Fs), one from the first mass to
ground and one between the second and third masses, Rayleigh damping as a matrix. Both
solve the same EPMC equations (Krack 2015): harmonic 1 mass-normalised, the modal
amplitude a its scale, the phase fixed by (M phi)^T Xs_1 = 0, the artificial damping
xi M, damping ratio xi / (2 omega). frirom continues in log10 a (its one driver);
tmdsimpy's residual ``VibrationSystem.epmc_res`` is solved by its own ``NonlinearSolver``
(scipy's hybr with its analytical Jacobian) at each of frirom's amplitudes, started from
its own previous point (the first from the stuck linear mode), so the two meet at equal
a and their differences are the solvers' and the AFTs'. Writes
cases/bench/results/peer_tmdsimpy.json (the table, the peer's commit) and prints, per
truncation, the largest relative frequency and damping differences.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

#: the chain: masses [kg], springs ground-1, 1-2, 2-3 [N/m]
MASSES = (1.0, 0.8, 0.5)
SPRINGS = (4.0e4, 2.0e4, 1.0e4)
#: Jenkins elements: (coupling row over the 3 DoFs, kt [N/m], slip force [N])
JENKINS = (((1.0, 0.0, 0.0), 2.0e4, 1.0), ((0.0, 1.0, -1.0), 1.0e4, 0.5))
#: Rayleigh damping C = ALPHA M + BETA K (K without the Jenkins elements)
ALPHA, BETA = 0.5, 2.0e-6
#: the truncations compared: (H, N); modal amplitudes from stuck to gross slip
TRUNCATIONS = ((1, 128), (3, 128), (5, 256))
AMPLITUDES = (1.0e-5, 3.0e-3)


def matrices():
    m = np.diag(MASSES)
    k1, k2, k3 = SPRINGS
    k = np.array([[k1 + k2, -k2, 0.0], [-k2, k2 + k3, -k3], [0.0, -k3, k3]])
    return m, k, ALPHA * m + BETA * k


def frirom_backbone(H, N):
    import frirom
    from frirom.model import ContactGroup, Damping, Model
    m, k, c = matrices()
    groups = [ContactGroup(law="jenkins", G=np.array([row]), params=np.array([[kt, 0.5,
                                                                               2 * fs]]),
                           name=f"j{i}") for i, (row, kt, fs) in enumerate(JENKINS)]
    model = Model(m, k, Damping.matrix(c), groups)
    opts = frirom.SolverOptions(harmonics=H, samples=N, formulation="banded",
                                tol_residual=1e-12, tol_update=1e-12, ds_max=0.05,
                                history=False)
    t0 = time.perf_counter()
    bb = frirom.nonlinear_mode(model, 0, AMPLITUDES, "stuck", opts)
    sec = time.perf_counter() - t0
    if bb.status != "done":
        raise RuntimeError(f"frirom stopped early at H = {H}, N = {N}: {bb.message}")
    from frirom.nonlinear_modes import linear_mode
    phi = linear_mode(model, 0, "stuck")[0]
    return bb, phi, sec


def peer_main(path_in, path_out):
    """Runs in the peer's environment: tmdsimpy's EPMC at the amplitudes given."""
    from tmdsimpy.nlforces.jenkins_element import JenkinsForce
    from tmdsimpy.solvers import NonlinearSolver
    from tmdsimpy.vibration_system import VibrationSystem
    d = np.load(path_in)
    m, k, c = d["M"], d["K"], d["C"]
    H, N = int(d["H"]), int(d["N"])
    vib = VibrationSystem(m, k, C=c)
    for row, kt, fs in zip(d["rows"], d["kt"], d["fs"]):
        q = row.reshape(1, -1)
        vib.add_nl_force(JenkinsForce(q, q.T.copy(), kt, fs))
    n = m.shape[0]
    h = np.arange(H + 1)
    nhc = 2 * H + 1
    fl = np.zeros(nhc * n)
    fl[2 * n:3 * n] = m @ d["phi"]              # (M phi)^T Xs_1 = 0
    x = np.zeros(nhc * n + 2)
    x[n:2 * n] = d["phi"]
    x[-2] = d["w0"]
    x[-1] = d["phi"] @ c @ d["phi"]             # xi of the linear mode
    solver = NonlinearSolver()
    out, t0 = [], time.perf_counter()
    for la in np.log10(d["amplitude"]):
        def fun(u, la=la):
            r = vib.epmc_res(np.r_[u, la], fl, h, Nt=N)
            return r[0], r[1]
        x, r, _, sol = solver.nsolve(fun, x, verbose=False, xtol=1e-13)
        out.append((x[-2], x[-1], np.abs(r).max(), bool(sol["success"])))
    np.save(path_out, np.array(out, float))
    return time.perf_counter() - t0


def peer_commit(src: Path) -> str:
    try:
        return subprocess.run(["git", "-C", str(src), "rev-parse", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--peer", type=Path, default=os.environ.get("FRIROM_PEER_TMDSIMPY"),
                    help="tmdsimpy's source folder (the one holding tmdsimpy/)")
    ap.add_argument("--peer-python", default=os.environ.get("FRIROM_PEER_PYTHON",
                                                            sys.executable),
                    help="the Python of the peer's environment (numpy, scipy)")
    ap.add_argument("--quick", action="store_true", help="H = 1 only")
    a = ap.parse_args(argv)
    if a.peer is None or not (Path(a.peer) / "tmdsimpy" / "vibration_system.py").exists():
        print("peer_tmdsimpy: skipped: tmdsimpy is not installed (give its source folder "
              "with --peer or FRIROM_PEER_TMDSIMPY; see this script's docstring)")
        return 0
    src = Path(a.peer).resolve()
    from _results import add
    rows, table = [], []
    print(f"peer: tmdsimpy {peer_commit(src)[:12]} at {src}, run by {a.peer_python}")
    print("model: 3 masses in a chain, 2 Jenkins elements, Rayleigh damping; EPMC from the "
          f"stuck first mode, modal amplitude {AMPLITUDES[0]:g} .. {AMPLITUDES[1]:g}")
    print(f"{'H':>2s}  {'N':>4s}  {'points':>6s}  {'frirom s':>8s}  {'peer s':>7s}  "
          f"{'max |df/f|':>10s}  {'max |dD|/D':>10s}  {'peer max|R|':>11s}")
    m, k, c = matrices()
    for H, N in TRUNCATIONS[:1] if a.quick else TRUNCATIONS:
        bb, phi, sec = frirom_backbone(H, N)
        with tempfile.TemporaryDirectory() as tmp:
            fin, fout = Path(tmp) / "in.npz", Path(tmp) / "out.npy"
            np.savez(fin, M=m, K=k, C=c, H=H, N=N, phi=phi, w0=bb.omega0,
                     amplitude=bb.amplitude, rows=np.array([j[0] for j in JENKINS]),
                     kt=np.array([j[1] for j in JENKINS]),
                     fs=np.array([j[2] for j in JENKINS]))
            env = dict(os.environ, PYTHONPATH=str(src))
            p = subprocess.run([a.peer_python, str(Path(__file__).resolve()), "--as-peer",
                                str(fin), str(fout)], env=env, capture_output=True,
                               text=True)
            if p.returncode != 0:
                print(p.stdout + p.stderr)
                raise RuntimeError("peer_tmdsimpy: the peer's run failed (above)")
            peer_sec = float(p.stdout.strip().splitlines()[-1])
            res = np.load(fout)
        w_p, xi_p, r_p, ok = res.T
        f, D = bb.omega / (2 * np.pi), bb.damping_ratio
        f_p, D_p = w_p / (2 * np.pi), xi_p / (2 * w_p)
        df = np.abs(f_p / f - 1)
        dD = np.abs(D_p - D) / np.abs(D)
        print(f"{H:>2d}  {N:>4d}  {len(bb):>6d}  {sec:>8.2f}  {peer_sec:>7.2f}  "
              f"{df.max():>10.2e}  {dD.max():>10.2e}  {r_p.max():>11.1e}"
              + ("" if ok.all() else f"  ({int((~ok.astype(bool)).sum())} peer solves "
                                     "unconverged)"))
        pick = np.unique(np.searchsorted(bb.amplitude, np.geomspace(*AMPLITUDES, 7)
                                         .clip(max=bb.amplitude[-1])))
        for i in pick:
            table.append((H, N, bb.amplitude[i], f[i], f_p[i], D[i], D_p[i]))
        rows.append({"H": H, "N": N, "points": len(bb), "frirom_s": sec, "peer_s": peer_sec,
                     "max_rel_df": float(df.max()), "max_rel_dD": float(dD.max()),
                     "peer_max_residual": float(r_p.max()), "peer_all_converged":
                     bool(ok.all()), "amplitude": bb.amplitude.tolist(),
                     "f_frirom": f.tolist(), "f_peer": f_p.tolist(),
                     "D_frirom": D.tolist(), "D_peer": D_p.tolist()})
    print(f"{'H':>2s}  {'N':>4s}  {'a':>9s}  {'f frirom Hz':>13s}  {'f tmdsimpy Hz':>13s}  "
          f"{'D frirom %':>11s}  {'D tmdsimpy %':>12s}")
    for H, N, amp, f, fp, D, Dp in table:
        print(f"{H:>2d}  {N:>4d}  {amp:>9.3e}  {f:>13.8f}  {fp:>13.8f}  {100 * D:>11.7f}  "
              f"{100 * Dp:>12.7f}")
    add(peer={"name": "tmdsimpy", "commit": peer_commit(src)}, truncations=rows)
    print("peer tmdsimpy: " + "; ".join(
        f"H = {r['H']}, N = {r['N']}: max |df/f| {r['max_rel_df']:.1e}, max |dD|/D "
        f"{r['max_rel_dD']:.1e} over {r['points']} points" for r in rows))
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "--as-peer":
        print(peer_main(sys.argv[2], sys.argv[3]))
        sys.exit(0)
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _results import record
    sys.exit(record("peer_tmdsimpy", main))
