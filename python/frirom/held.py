"""What a point's solution left to the free-body pin, and contacts that slide off their
patch (issue 29 item 1).

A body held only by its contacts (an under-platform damper) has directions its equations
leave free once it slips: the solver holds each contact's mean relative displacement
(harmonic 0) by a weak spring, ``FREE_PIN`` times the contact's stuck stiffness, anchored
at the assembled position (``fortran/frirom_hbm_free.f90``). :func:`held_directions`
reports, per contact group at one point, which of those means the pin alone decided:

* the **tangential** mean of an element that does not stick all cycle (it slips or
  opens some of the period): its slider follows any shift of the mean, so its force does
  not fix the mean and only the pin does (a body is indeterminate when every contact
  holding it is so);
* the **normal** mean of an element open all cycle (a law with a normal direction).

and the pin's force on each element's means, ``FREE_PIN ks_d |mean(u_d)|``: at a held
mean this is the force the true equations leave undetermined (zero at the picked member
of the family, round-off in practice); at a stuck or partly slipping element it is the
bias the pin adds, to be compared with the contact's own forces.

:func:`patch_warnings` flags elements whose relative tangential displacement leaves the
contact patch: ``max_t |u_t(t)|`` over the period, in any tangential direction d, larger
than the patch's extent along d (a node pair slid by more than the patch is long cannot
be in contact as the model assumes). The extent is the ``[[contacts]]`` key ``patch`` [m],
or, for node-set contacts of an ``[fe_model]``, the extent of side a's nodes along each
tangent (``frirom.deck.build``), else not checked.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .contact import LAWS, stuck_stiffness

#: fortran/frirom_hbm.fypp's FREE_PIN (tests/test_held.py reads it there)
FREE_PIN = 1.0e-2


@dataclass
class Held:
    """One contact group at a point. tangential, normal: element indices whose
    tangential / normal mean the pin alone decided; pin_force (n_elem,): the largest pin
    force on an element's means [N]; contact_force (n_elem,): the element's largest
    contact force over the period [N], the scale of pin_force."""

    group: str
    tangential: np.ndarray
    normal: np.ndarray
    pin_force: np.ndarray
    contact_force: np.ndarray


def _tangential(law) -> list:
    return [d for d, name in enumerate(LAWS[law].directions) if name != "v"]


def held_directions(model, fields) -> list:
    """Held per contact group of ``model`` for the ContactField list ``fields``
    (:func:`frirom.show.contact_fields` of one point); [] when the model has no free body
    (the pin is off: nothing is held)."""
    if not model.free_bodies():
        return []
    out = []
    for g, c in zip(model.contacts, fields):
        ks = stuck_stiffness(g.law, g.params).reshape(c.n_elem, -1)
        mean = c.u.mean(axis=2)                             # harmonic 0 of each direction
        pin = 0.0 if g.law == "cubic" else FREE_PIN
        pin_force = (pin * ks * np.abs(mean)).max(axis=1)
        stick, liftoff = c.states[:, 0], c.states[:, 2]
        tangential = np.flatnonzero(stick < 1.0) if pin else np.zeros(0, int)
        has_normal = "v" in c.directions
        normal = (np.flatnonzero(liftoff == 1.0) if pin and has_normal
                  else np.zeros(0, int))
        out.append(Held(c.name, tangential, normal, pin_force,
                        np.abs(c.f).max(axis=(1, 2))))
    return out


def held_lines(held: list) -> list:
    """One line per group: what the pin held and its largest force against the contact
    forces."""
    lines = []
    for h in held:
        n = h.pin_force.size
        e = int(np.argmax(h.pin_force)) if n else 0
        scale = float(h.contact_force.max()) if n else 0.0
        rel = f" ({h.pin_force[e] / scale:.2g} of the largest contact force)" if scale else ""
        lines.append(f"free body: contact {h.group}: tangential mean held by the pin at "
                     f"{h.tangential.size} of {n} elements (slipping or open), normal mean at "
                     f"{h.normal.size} (open all cycle); largest pin force "
                     f"{h.pin_force[e] if n else 0.0:.3g} N at element {e}{rel}")
    return lines


def patch_warnings(model, fields) -> list:
    """Warnings for elements whose relative tangential displacement over the period
    exceeds the group's patch extent (``ContactGroup.patch``: a number, the same along
    every tangent, or one per tangential direction; None: not checked)."""
    out = []
    for g, c in zip(model.contacts, fields):
        patch = getattr(g, "patch", None)
        if patch is None:
            continue
        td = _tangential(g.law)
        ext = np.broadcast_to(np.asarray(patch, float).ravel(), (len(td),))
        reach = np.abs(c.u[:, td, :]).max(axis=2)            # (n_elem, n_tangential)
        over = reach > ext[None, :]
        if not over.any():
            continue
        e, d = np.unravel_index(int(np.argmax(reach / ext[None, :])), reach.shape)
        out.append(f"contact {c.name}: the relative displacement {c.directions[td[d]]} of "
                   f"{int(over.any(axis=1).sum())} of {c.n_elem} elements exceeds the "
                   f"contact patch (largest {reach[e, d] * 1e3:.4g} mm at element {e}, "
                   f"patch {ext[d] * 1e3:.4g} mm): a pair slides off the patch the model "
                   "assumes (a heavier load sticks it; [[contacts]] patch gives the extent)")
    return out
