"""meson test and tests/test_capi_cyclic.py: a cyclic sector's nonlinear mode from C
(examples/cyclic_mode.c through frirom.h) and from a Fortran program (examples/
cyclic_mode.f90 through the frirom_run module) reproduces frirom.nonlinear_mode's backbone.

The model is tests/_rotor.py's lattice rotor (N = 7 sectors, preloaded normal1d ground
contacts, a Jenkins damper between neighbouring blade tips, Rayleigh damping), nodal
diameter 2 at H = 3 (harmonics on diameters 0, 5, 3, 1), from stick to gross slip. Python
makes the sector's data as its own run gets it (frirom.nonlinear_modes_cyclic.open_cyclic:
the contact, output and loaded rows, G on them, each harmonic's modes, the linear
travelling wave q0 and the settings) and writes them to a text file (write_case: its
layout); each program reads the file, runs the backbone and prints one line per point,
"amplitude omega xi xo...", then "status S NPTS" (the C program also restores the run
from a checkpoint after its first batch and exits 1 unless the restored run makes the
same points bit for bit). Tolerance: the same points, and
amplitude, omega, xi and the output harmonics within 1e-10 of their largest value (both
run the same driver on the same numbers).

Usage: python capi_cyclic.py PROGRAM [PROGRAM ...]
"""

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
TOL = 1e-10
AMPLITUDES = (1e-6, 1e-1)


def case():
    """(cyclic model, SolverOptions) of the rotor's sector at nodal diameter 2, H = 3."""
    sys.path.insert(0, str(HERE))
    import frirom
    from _rotor import ALPHA, BETA, N, rotor, rotor_sector, sector_contacts
    from frirom.model import Damping
    from frirom.reduction.cyclic import cyclic_model
    r, K, Ks, glob = rotor()
    n_s = Ks.shape[0]
    cm = cyclic_model(rotor_sector(r, N), Ks, r["sector"]["M"],
                      sector_contacts(r, glob, n_s), 2, 3,
                      damping=Damping.rayleigh(ALPHA, BETA))
    opts = frirom.SolverOptions(harmonics=3, samples=16 * N, tol_residual=1e-11,
                                tol_update=1e-11, max_iter=40)
    return cm, opts


def reference_and_data(cm, opts):
    """Python's backbone, and the packed sector its run was opened on, with the run's
    settings and linear mode (open_cyclic captured while nonlinear_mode runs)."""
    import frirom.nonlinear_modes_cyclic as nmc
    from frirom import nonlinear_mode
    seen = {}
    real_open = nmc.open_cyclic

    def spy(model, mode, start, o, *args, **kw):
        out = real_open(model, mode, start, o, *args, **kw)
        seen.update(model=model, mode=mode, start=start, packed=out[0], w0=out[2])
        return out
    nmc.open_cyclic = spy
    try:
        bb = nonlinear_mode(cm, 0, AMPLITUDES, "stuck", opts)
    finally:
        nmc.open_cyclic = real_open
    q0, w0, _ = nmc.cyclic_linear_mode(seen["model"], seen["mode"], seen["start"])
    assert w0 == seen["w0"]
    return bb, seen["packed"], q0


def _line(f, values, fmt="{:.17g}"):
    f.write(" ".join(fmt.format(v) for v in np.ravel(values, order="F")) + "\n")


def write_case(path, packed, q0, omega0):
    """The sector's data as whitespace-separated numbers, 0-based indices, column-major:
    n H samples ngroup ng npar nw nout nmodes / max_points max_iter batch reuse_jacobian
    history / tol_residual tol_update tol_stall ds ds_min ds_max / omega0 a_start a_end /
    ginfo (3, ngroup) / gr gc (ng) / gv (ng) / params (npar) / w0 (nw) / fe (n, 2H+1) /
    outdofs (nout) / q0 (nmodes complex: re im) / psi (n, nmodes, H+1 complex) / omega /
    zeta (nmodes, H+1)."""
    from frirom._run import _setting
    o, m = packed.opts, packed.modes
    G = packed.G
    gp, gi, gx = G
    rows = np.repeat(np.arange(gp.size - 1), np.diff(gp))
    nm = m.psi.shape[1]
    q = np.zeros(nm, complex)
    q[:q0.size] = q0
    fe = packed.fe0
    with open(path, "w") as f:
        _line(f, [packed.n_dof, packed.H, _setting(o, "samples"), packed.ginfo.shape[1],
                  gx.size, packed.params.size, packed.nw, packed.out_f.size, nm], "{:d}")
        _line(f, [_setting(o, k) for k in ("max_points", "max_iter", "batch",
                                           "reuse_jacobian", "history")], "{:d}")
        _line(f, [_setting(o, k) for k in ("tol_residual", "tol_update", "tol_stall", "ds",
                                           "ds_min", "ds_max")])
        _line(f, [omega0, *AMPLITUDES])
        _line(f, packed.ginfo, "{:d}")
        _line(f, rows, "{:d}")
        _line(f, gi - 1, "{:d}")
        _line(f, gx)
        _line(f, packed.params)
        _line(f, packed.w0[:packed.nw] if packed.nw else [])
        _line(f, fe)
        _line(f, packed.out_f, "{:d}")
        _line(f, np.column_stack([q.real, q.imag]).T)
        _line(f, np.stack([m.psi.real, m.psi.imag]))
        _line(f, m.omega_h)
        _line(f, m.zeta_h)


def run(program, path):
    out = subprocess.run([program, str(path)], capture_output=True, text=True)
    if out.returncode:
        raise RuntimeError(f"{program}: exit {out.returncode}\n{out.stdout[-2000:]}"
                           f"{out.stderr[-2000:]}")
    rows, status = [], None
    for line in out.stdout.splitlines():
        words = line.split()
        if words and words[0] == "status":
            status = (int(words[1]), int(words[2]))
        elif words and words[0] != "restored":
            rows.append([float(w) for w in words])
    return np.array(rows), status


def compare(rows, status, bb):
    """Largest relative errors (amplitude, omega, xi, outputs) of a program's points
    against the backbone bb; None when the points differ in number or status."""
    n = len(bb)
    if status is None or status[1] != n or rows.shape[0] != n or bb.status != "done":
        return None
    xo = rows[:, 3:].reshape(n, bb.harmonics.shape[2], bb.harmonics.shape[1])
    xo = xo.transpose(0, 2, 1)                      # (npt, nout, 2H+1), column-major rows
    return (np.abs(rows[:, 0] / bb.amplitude - 1).max(),
            np.abs(rows[:, 1] - bb.omega).max() / bb.omega.max(),
            np.abs(rows[:, 2] - bb.xi).max() / bb.xi.max(),
            np.abs(xo - bb.harmonics).max() / np.abs(bb.harmonics).max())


def main(programs, tol: float = TOL):
    """0 when every program reproduces Python's backbone within tol."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    cm, opts = case()
    bb, packed, q0 = reference_and_data(cm, opts)
    bad = 0
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "sector.txt"
        write_case(path, packed, q0, bb.omega0)
        for prog in programs:
            rows, status = run(prog, path)
            err = compare(rows, status, bb)
            name = Path(prog).name
            if err is None:
                print(f"{name}: status {status}, {rows.shape[0]} points; Python "
                      f"{bb.status} {len(bb)} points FAILED")
                bad += 1
                continue
            ok = max(err) <= tol
            bad += not ok
            print(f"{name}: {len(bb)} points; relative error amplitude {err[0]:.1e}, omega "
                  f"{err[1]:.1e}, xi {err[2]:.1e}, outputs {err[3]:.1e} (tolerance {tol:g}) "
                  f"{'ok' if ok else 'FAILED'}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
