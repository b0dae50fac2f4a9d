"""Does a rigid cycloid disc fit its pin ring? The per-pin fit margin, a one-variable linear programme.

A disc displaced from its ideal place and free to turn about its centre (it turns as it enters the ring:
the cranks and the carrier are free before the planet gears are fitted) meets pin k along that contact's
normal.  To first order in the displacement (micrometres against a 76.5-mm pin circle) the normal approach at
pin k is

    δ_k = n_k · d + ρ_k ψ

with d the disc centre's offset (mm, in the disc's eccentric frame), ψ its turn (rad), n_k the contact
normal and ρ_k its moment arm about the disc centre — the 20-DOF model's own contact geometry
(:func:`rvtol.models.reducer_20dof.contacts.pin_contacts`: n_k = (cos α_k, sin α_k) from the pitch point P to
the pin centre, ρ_k = R_d sin α_k, doc 000 §1.3 contact 4).  Pin k lets the disc in while δ_k ≤ c_k, its
normal clearance (the profile modification's n(φ_k), the pin's clearance in its groove, the pin's position
errors and the disc's profile errors, as the kernel writes them).  A disc whose axis is tilted has a
different offset at each face; the approach is linear along the pin, so the two faces are the extremes and
both must fit, with one ψ (a rigid disc).

The **fit margin** is the largest uniform normal clearance the best turn leaves at every pin::

    m = max_ψ min_{k, faces f} (c_k − n_k · d_f − ρ_k ψ)

m ≥ 0: the disc goes in and no pin touches it (m is the gap left at the tightest pin); m < 0: some pin
interferes by |m| whatever the turn.  With a_k = c_k − max_f n_k · d_f (ρ_k is the same at both faces),
m = max_ψ f(ψ), f(ψ) = min_k (a_k − ρ_k ψ): concave and piecewise linear in ψ.  Closed form
(:func:`turn_free_margin`): for a pin i with ρ_i > 0 (a falling line) and a pin j with ρ_j < 0 (a rising
one), max_ψ min(a_i − ρ_i ψ, a_j − ρ_j ψ) is their crossing,

    v_ij = (a_i |ρ_j| + a_j ρ_i) / (ρ_i + |ρ_j|),

and f ≤ both lines, so max f ≤ v_ij for every pair and ≤ a_k for every pin with ρ_k = 0; at the maximiser
a falling and a rising line (or a flat one) are active, so the bound is reached:

    m = min( min_{ρ_k = 0} a_k ,  min_{ρ_i > 0 > ρ_j} v_ij )

(the LP's dual: a convex combination of the constraints with Σ λ_k ρ_k = 0, whose vertices are these pairs
and flat pins).  Nothing bounds ψ if every arm has one sign: m = +inf (not a pin ring).

Two consequences the tests hold: every normal passes through P, so a disc offset across the eccentric
(d along y, both faces alike) is taken up by the turn ψ = −d_y / R_d — the disc rolls about P, the conjugate
motion, and the margin does not change; with radial normals (ρ = 0) and one clearance c the margin is
c − max_k n_k · d, i.e. c − |d| for a dense ring: the isotropic reading this replaces.
"""
from __future__ import annotations

import numpy as np

#: rows per block in :func:`turn_free_margin` (the pair table is rows × pins × pins)
BLOCK = 2048


def turn_free_margin(a: np.ndarray, arm: np.ndarray) -> np.ndarray:
    """``max_ψ min_k (a[:, k] − arm[k]·ψ)`` for every row of ``a`` (closed form, module docstring).

    ``a[n, m]``: each row's clearances left at the m constraints before the turn (mm); ``arm[m]``: each
    constraint's moment arm (mm per rad), the same for every row.  Returns ``m[n]`` (+inf where nothing bounds
    the turn).
    """
    a = np.atleast_2d(np.asarray(a, dtype=float))
    arm = np.asarray(arm, dtype=float)
    if a.shape[1] != arm.size:
        raise ValueError(f"{a.shape[1]} constraints but {arm.size} arms")
    flat = arm == 0.0
    up, down = np.flatnonzero(arm > 0.0), np.flatnonzero(arm < 0.0)
    out = np.full(a.shape[0], np.inf)
    if flat.any():
        out = np.minimum(out, a[:, flat].min(axis=1))
    if up.size and down.size:
        ri, rj = arm[up][:, None], -arm[down][None, :]          # ρ_i > 0, |ρ_j| > 0
        wi, wj = rj / (ri + rj), ri / (ri + rj)                  # the pair's convex weights (sum 1)
        for s in range(0, a.shape[0], BLOCK):
            ai, aj = a[s:s + BLOCK, up][:, :, None], a[s:s + BLOCK, down][:, None, :]
            v = (ai * wi + aj * wj).reshape(ai.shape[0], -1)
            out[s:s + BLOCK] = np.minimum(out[s:s + BLOCK], v.min(axis=1))
    return out


def disc_fit_margin(clearance: np.ndarray, normal: np.ndarray, arm: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """The fit margin of one disc per row (module docstring).

    ``clearance[n, z_b]`` (or ``[z_b]``, the same for every row): each pin's normal clearance c_k (mm);
    ``normal[z_b, 2]``, ``arm[z_b]``: the contact normals and moment arms in the disc's eccentric frame;
    ``faces[n, F, 2]``: the disc centre's offset from its ideal place at each of its F faces (mm, eccentric
    frame).  Returns the margin ``m[n]`` (mm).
    """
    faces = np.asarray(faces, dtype=float)
    approach = np.einsum("nfx,kx->nfk", faces, np.asarray(normal, dtype=float)).max(axis=1)   # max_f n_k·d_f
    a = np.broadcast_to(np.asarray(clearance, dtype=float), approach.shape) - approach
    return turn_free_margin(a, arm)
