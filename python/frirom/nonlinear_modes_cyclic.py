"""Nonlinear modes of a tuned cyclic sector (frirom.model.CyclicModel): the backbone of one
nodal diameter k, the rotor vibrating as a travelling wave, by the EPMC of
:mod:`frirom.nonlinear_modes` in the one continuation driver (frirom_run mode 3, the
condensed system of frirom_hbm_epmc_cyclic.f90).

Sector s moves as sector 0 delayed by s k / N of a period: time harmonic h of that motion
lives on nodal diameter k_h = sign h k mod N (the model's sign, as for an engine order k),
so each harmonic's receptance comes from k_h's modes (psi^H M_k psi = I over the sector)
and a contact to the next sector sees sector 0's motion phase-shifted by exp(i k_h 2 pi /
N), exactly as in a forced response under engine order k. The unknowns are the contact
DoFs' harmonics of sector 0, the frequency and the artificial damping; harmonic 1 is
mass-normalised over the sector (a is the sector's modal amplitude: the whole rotor's is
sqrt(N) a) and its phase fixed against the linear travelling wave it starts from
(Im(c^H q_1) = 0, c that wave's modal coordinates).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ._errors import ParameterError
from .model import CyclicModel, Excitation
from .reduction.cyclic import contact_rows

__all__ = ["cyclic_linear_mode", "open_cyclic"]

#: largest sector whose every DoF is an output of the run (Backbone.harmonics); above, the
#: run reports the contact DoFs and the outputs, and the energy per cycle comes from the
#: contact forces (_modal_from_forces)
_ALL_OUTPUTS = 400


def _with_diameter(model: CyclicModel, nodal_diameter) -> CyclicModel:
    """The model with its engine order set to the nodal diameter k of the mode."""
    if nodal_diameter is None:
        return model
    k = nodal_diameter
    if not (isinstance(k, (int, np.integer)) and 0 <= k < model.n_sectors):
        raise ParameterError(f"nodal_diameter: expected an integer 0..{model.n_sectors - 1},"
                             f" got {k!r}")
    return dataclasses.replace(model, engine_order=int(k))


def cyclic_linear_mode(model: CyclicModel, mode: int = 0, start: str = "stuck",
                       nodal_diameter: int | None = None):
    """The linear travelling wave a cyclic nonlinear mode starts from, in the modal
    coordinates of harmonic 1's nodal diameter k_1 = sign k mod N: (q0 (nm,) complex,
    unit norm, omega0 rad/s, k_1). 'free': mode `mode` of k_1 (q0 a unit vector); 'stuck':
    of diag(omega_r^2) + (G_k Psi)^H Ks (G_k Psi), every contact element a linear spring
    of its law's stick stiffness (within the model's modes of k_1)."""
    if not isinstance(model, CyclicModel):
        raise ParameterError("model: expected a frirom.model.CyclicModel")
    if start not in ("stuck", "free"):
        raise ParameterError("start: expected 'stuck' or 'free'")
    model = _with_diameter(model, nodal_diameter)
    k1 = model.harmonic_index(1)
    m = model.modes_of(k1)
    nm = m.omega.size
    if not (isinstance(mode, (int, np.integer)) and 0 <= mode < nm):
        raise ParameterError(f"mode: expected an index 0..{nm - 1} (the modes of nodal "
                             f"diameter {k1} the model has)")
    A = np.diag(m.omega.astype(complex) ** 2)
    if start == "stuck":
        Gk, ks = contact_rows(model.n_dof, model.n_sectors, model.contacts, k1)
        P = Gk @ m.psi
        A = A + P.conj().T @ (ks[:, None] * P)
    lam, V = np.linalg.eigh(0.5 * (A + A.conj().T))
    q0 = V[:, mode]
    j = int(np.argmax(np.abs(q0)))
    q0 = q0 * (abs(q0[j]) / q0[j])          # the largest coordinate real and positive
    return q0, float(np.sqrt(lam[mode])), k1


def open_cyclic(model: CyclicModel, mode, start, opts, outputs=None, static=None,
                nodal_diameter=None):
    """The packed sector, a cyclic mode run (frirom._run.Run) on it, the linear mode's
    frequency w0 and the rest that a Backbone of the run's points needs
    (frirom.nonlinear_modes._backbone_from's keywords n_out, energy_viscous,
    nodal_diameter): (packed, run, w0, keywords)."""
    from ._pack import _output_map, pack
    from ._run import Run
    model = _with_diameter(model, nodal_diameter)
    if opts.modes:
        raise ParameterError("options.modes: a cyclic model brings its own modes per nodal "
                             "diameter (frirom.reduction.cyclic.cyclic_model)")
    q0, w0, k1 = cyclic_linear_mode(model, mode, start)
    n, H = model.n_dof, opts.harmonics
    F = np.zeros((n, 1))
    if static is not None:
        st = np.asarray(static, float).ravel()
        if st.size != n or not np.all(np.isfinite(st)):
            raise ParameterError(f"static: {n} finite values expected")
        F[:, 0] = st
    out, P = _output_map(outputs, n)
    # the run reports every sector DoF (up to _ALL_OUTPUTS), else the contact DoFs and the
    # outputs asked for
    run_out = (np.arange(n) if n <= _ALL_OUTPUTS else
               np.unique(np.r_[model.nonlinear_dofs(),
                               np.asarray(out if out is not None else [], int)]))
    if P is not None:
        if n > _ALL_OUTPUTS:
            raise ParameterError(f"outputs: a combination matrix needs a sector of at most "
                                 f"{_ALL_OUTPUTS} DoFs; give DoF indices")
    else:
        sel = (np.asarray(out, int) if out is not None
               else run_out if n <= 100 else model.nonlinear_dofs())
        P = np.zeros((sel.size, run_out.size))
        pos = {int(d): i for i, d in enumerate(run_out)}
        P[np.arange(sel.size), [pos[int(d)] for d in sel]] = 1.0
        out = sel
    o = dataclasses.replace(opts, formulation="condensed", modes=None)
    packed = pack(model, Excitation(F), o, run_out)
    packed.select = P if P.shape[1] == run_out.size else P[:, run_out]
    packed.select_dofs = np.asarray(out) if out is not None else np.zeros(0, int)
    nm = packed.modes.hmodes
    qp = np.zeros(nm, complex)
    qp[:q0.size] = q0
    run = Run(packed, cyclic_mode=(qp, w0))
    packed.mode_ny = run.ny
    # each harmonic's modes on the run's outputs: modal coordinates of the reported motion
    pers = [model.modes_of(model.harmonic_index(h)) for h in range(H + 1)]
    full = run_out.size == n

    done = {"y": np.zeros((0, 3)), "e": np.zeros(0), "xv": np.zeros(0)}

    def energy_viscous(omega, xi, a, Xp):
        """Energy per cycle (per sector) and the viscous part of xi from the modal
        coordinates of every harmonic: from every DoF's harmonics when the run reports
        them all, else from the contact forces (_modal_from_forces). The Backbone is made
        again after every segment from all its points: the points computed before are
        kept (the same amplitude, omega and xi) and only the new ones computed."""
        y = np.column_stack([a, omega, xi])
        k = done["y"].shape[0]
        if not (k <= y.shape[0] and np.array_equal(y[:k], done["y"])):
            k = 0
            done.update(y=y[:0], e=np.zeros(0), xv=np.zeros(0))
        new = slice(k, None)
        if y.shape[0] > k:
            if full:
                qs = [np.linalg.lstsq(pers[h].psi, (Xp[new, :, 2 * h - 1]
                                                    - 1j * Xp[new, :, 2 * h]).T,
                                      rcond=None)[0] for h in range(1, H + 1)]
            else:
                qs = _modal_from_forces(model, pers, run_out, o.n_samples, omega[new],
                                        xi[new], Xp[new])
            e = sum(h ** 2 * (np.abs(q) ** 2).sum(axis=0) for h, q in enumerate(qs, 1))
            c = 2 * pers[1].zeta * pers[1].omega
            xv = ((c[:, None] * np.abs(qs[0]) ** 2).sum(axis=0)
                  / np.maximum(a[new], 1e-300) ** 2)
            done.update(y=y, e=np.r_[done["e"][:k], np.pi * xi[new] * omega[new] * e],
                        xv=np.r_[done["xv"][:k], xv])
        return done["e"].copy(), done["xv"].copy()

    return packed, run, w0, {"n_out": run_out.size, "energy_viscous": energy_viscous,
                             "nodal_diameter": k1,
                             "harmonic_dofs": None if full else run_out}


def _modal_from_forces(model: CyclicModel, pers, rows, n_samples, omega, xi, Xp):
    """Modal coordinates q_h (nm_h, npt) of harmonics h = 1..H of a cyclic mode's points
    from the harmonics Xp (npt, rows.size, 2H+1) of the DoFs `rows` (every contact DoF
    among them), as the condensed run defines them (frirom_hbm_epmc_modal epmd_outputs):
    q_h = -psi_ext^H f_h / (w_r^2 - W^2 + i W (2 zeta_r w_r - xi)), W = h omega, f_h the
    contact forces' harmonic h on sector 0 and the next sector (G^T f), psi_ext harmonic
    h's modes on both (the next sector's times exp(i k_h 2 pi / N)). The forces come from
    the AFT of the contact displacements of every point at once with n_samples samples
    (the run's); harmonics >= 1 of a closed cycle do not depend on where its sliders
    start, so the law's initial sliders serve."""
    from .contact import LAWS, aft
    from .show import _next_sector
    n, npt = model.n_dof, omega.size
    nc = Xp.shape[2]
    H = (nc - 1) // 2
    x = np.zeros((npt, n, nc))
    x[:, rows] = Xp
    xx = np.concatenate([x, np.stack([_next_sector(model, x[p]) for p in range(npt)])],
                        axis=1)                                       # (npt, 2n, nc)
    gf = np.zeros((npt, 2 * n, nc))
    for g in model.contacts:
        law = LAWS[g.law]
        ne, nd = g.n_elem, law.n_dir
        m = g.G.shape[1]
        u = np.stack([np.asarray(g.G @ xx[p, :m]) for p in range(npt)])   # (npt, ne nd, nc)
        par = np.broadcast_to(np.asarray(g.params, float), (ne, len(law.parameters)))
        w0 = (None if not law.n_slider or g.w0 is None else
              np.tile(np.broadcast_to(np.asarray(g.w0, float), (ne, law.n_slider)), (npt, 1)))
        f = aft(law, u.reshape(npt * ne, nd, nc), np.tile(par, (npt, 1)), n_samples,
                w0=w0, jacobian=False).forces.reshape(npt, ne * nd, nc)
        for p in range(npt):
            gf[p, :m] += np.asarray(g.G.T @ f[p])
    alpha = 2 * np.pi / model.n_sectors
    qs = []
    for h in range(1, H + 1):
        m = pers[h]
        psi = np.vstack([m.psi, m.psi * np.exp(1j * m.k * alpha)])        # (2n, nm)
        fh = gf[:, :, 2 * h - 1] - 1j * gf[:, :, 2 * h]                  # (npt, 2n)
        W = h * omega[None, :]
        den = (m.omega[:, None] ** 2 - W ** 2
               + 1j * W * (2 * m.zeta[:, None] * m.omega[:, None] - xi[None, :]))
        qs.append(-(psi.conj().T @ fh.T) / den)
    return qs
