"""Accuracy and cost of the AFT sample count N against H: the basis of the default
SolverOptions.n_samples.

For each case and H, the response at its resonance frequency is solved with N samples
(Newton started from the converged answer) and compared with the converged answer (N =
2^14): relative error of the first-harmonic amplitude at the output DoF (at the peak the
response is flat in frequency, so this is the error of the peak amplitude). Prints, per
case, the error table over H x N with the smallest N whose error stays below the target
from there on and the error of the default N; then the cost against N (CPU time of the
AFT + Jacobian of 1000 contact elements, the part of a Newton iteration that grows with
N, minimum of repeats, ratio to N = 256); the last lines check the default rule.

Cases: the Jenkins SDOF of tests/test_verification.py (90 % slip at the peak), its 3-DoF
1-D normal-load model with lift-off, and the bundled cases/joint/joint.toml (lumped blade
with a Jenkins platform damper).

    OPENBLAS_NUM_THREADS=1 python cases/bench/samples.py [--quick] [--target 1e-4]
"""

from __future__ import annotations

import argparse
import os
import time
import warnings
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from aft import make_inputs  # noqa: E402  (cases/bench/aft.py)
from frirom import contact  # noqa: E402
from frirom.deck import load_deck  # noqa: E402
from frirom.model import ContactGroup, Damping, Excitation, Model  # noqa: E402
from frirom.solver import SolverOptions, frf, solve_point  # noqa: E402

N_REF = 2 ** 14
HERE = Path(__file__).resolve().parent


def _model(M, C, K, law, G, params):
    group = ContactGroup(law=law, G=np.asarray(G, float), params=np.atleast_2d(params))
    return Model(M, K, Damping.matrix(C), [group])


def cases():
    """name -> (model, excitation, frequency range, output DoF)."""
    out = {}
    out["jenkins SDOF"] = (_model(np.eye(1), 0.02 * np.eye(1), np.eye(1), "jenkins", [[1.0]],
                                  [2.0, 0.2, 1.0]),
                           Excitation(np.array([[0.0, 0.3]], complex)), (0.8, 1.4), 0)
    mn = np.diag([1.0, 1.0, 0.5])
    kn = np.array([[3.0, 0.0, -1.0], [0.0, 4.0, 0.0], [-1.0, 0.0, 1.0]])
    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    out["normal1d lift-off"] = (_model(mn, 0.01 * kn + 0.01 * mn, kn, "normal1d",
                                       [[c, s, 0.0], [-s, c, 0.0]], [2.0, 2.0, 0.3, 0.7]),
                                Excitation(np.array([[0, 0], [0, 0], [0, 0.1]], complex)),
                                (0.8, 1.3), 2)
    deck = load_deck(HERE.parent / "joint" / "joint.toml")
    out["joint.toml"] = (deck.model(), Excitation(deck.F[:, :2]),
                         (2 * np.pi * 400.0, 2 * np.pi * 520.0), 0)
    return out


def peak_frequency(model, exc, band, out):
    """Resonance frequency from a coarse FRF (H = 5, N = 512)."""
    r = frf(model, exc, band[0], band[1], SolverOptions(harmonics=5, samples=512),
            outputs=[out])
    a1 = np.hypot(r.X[:, 0, 1], r.X[:, 0, 2])
    return float(r.omega[int(np.argmax(a1))])


def amplitude(point):
    return float(np.hypot(point.X[0, 1], point.X[0, 2]))


def study(model, exc, omega, out, hs, ns):
    """errors[h][n] at frequency omega; n = 0 is the default N."""
    errors = {}
    for h in hs:
        ref = solve_point(model, exc, omega, SolverOptions(harmonics=h, samples=N_REF),
                          outputs=[out])
        a_ref = amplitude(ref)
        start = {"unknowns": ref.unknowns, "slider": ref.slider}
        errors[h] = {}
        for n in (0,) + tuple(ns):
            if 0 < n < 2 * h + 1:
                continue
            p = solve_point(model, exc, omega, SolverOptions(harmonics=h, samples=n or None),
                            outputs=[out], start=start)
            errors[h][n] = abs(amplitude(p) / a_ref - 1)
    return errors


def aft_cost(h, n, repeat):
    """CPU seconds of one AFT + Jacobian of 1000 normal1d elements (the inputs of
    cases/bench/aft.py), minimum of repeats: the part of a Newton iteration that grows
    with N (the linear algebra does not depend on N)."""
    rng = np.random.default_rng(0)
    x, kt, kn, mu, n0 = make_inputs(1000, h, rng)
    p = np.stack([kt, kn, mu, n0], axis=1)
    contact.aft("normal1d", x, p, n)
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()
        contact.aft("normal1d", x, p, n)
        best = min(best, time.process_time() - t0)
    return best


def needed(err_row, target):
    """Smallest N of the row from which the error stays below target."""
    ns = sorted(n for n in err_row if n)
    ok = None
    for n in reversed(ns):
        if err_row[n] > target:
            break
        ok = n
    return ok


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="H = 1, 3, 7 only")
    ap.add_argument("--target", type=float, default=1e-4, help="relative error target")
    args = ap.parse_args()
    hs = (1, 3, 7) if args.quick else tuple(range(1, 16))
    ns = (32, 64, 128, 256, 512, 1024, 2048, 4096)
    warnings.simplefilter("ignore", RuntimeWarning)
    summary = {}
    for name, (model, exc, band, out) in cases().items():
        omega = peak_frequency(model, exc, band, out)
        errors = study(model, exc, omega, out, hs, ns)
        print(f"\n{name}: relative error of the first-harmonic amplitude at the resonance "
              f"(omega = {omega:.6g} rad/s) against N = {N_REF}")
        print(f"{'H':>3} " + " ".join(f"{n:>9d}" for n in ns) + f"  {'N(err<=target)':>15}"
              f" {'default':>8} {'err(default)':>12}")
        for h in hs:
            row = errors[h]
            nd = SolverOptions(harmonics=h).n_samples
            err_d = row[0]
            summary.setdefault(name, []).append((h, needed(row, args.target), nd, err_d))
            print(f"{h:3d} " + " ".join(f"{row[n]:9.1e}" if n in row else f"{'-':>9}"
                                        for n in ns)
                  + f"  {needed(row, args.target) or '>max':>15} {nd:8d} {err_d:12.1e}")
    print("\ncost: ms of CPU for one AFT + Jacobian of 1000 normal1d elements (ratio to N = 256)")
    print(f"{'H':>3} " + " ".join(f"{n:>14d}" for n in ns))
    for h in sorted({hs[0], hs[len(hs) // 2], hs[-1]}):
        t = {n: aft_cost(h, n, 5 if args.quick else 15) for n in ns if n >= 2 * h + 1}
        print(f"{h:3d} " + " ".join(f"{t[n] * 1e3:7.2f} ({t[n] / t[256]:4.2f})" if n in t
                                    else f"{'-':>14}" for n in ns))
    print(f"\ndefault rule check (target {args.target:g}):")
    worst = max(e for rows in summary.values() for (_, _, _, e) in rows)
    for name, rows in summary.items():
        print(f"  {name}: largest error with the default N: "
              f"{max(e for (_, _, _, e) in rows):.1e}")
    print(f"largest error of the default over all cases and H: {worst:.1e}")


if __name__ == "__main__":
    from _results import record
    record("samples", main)
