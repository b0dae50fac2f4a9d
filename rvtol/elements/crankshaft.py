"""Crankshaft as a Timoshenko beam on two supports (bending + shear) and a twisted shaft.

Each crank rests on two support bearings (``z = 0`` input side, ``z = L``
output side) and carries the turning-arm bearing loads of the two discs
(``0 < z_1 < z_2 < L``) and the planet-gear force on an overhang
(``z = -c``).  Deflections come from the unit-load (Mohr) integrals of a
beam on two simple supports::

    α_jk = ∫ m_j m_k / (E I) dz + ∫ v_j v_k / (κ G A) dz

where ``m_j``, ``v_j`` are the bending moment and shear force due to a unit
load at ``z_j``; they are piecewise linear/constant, and Simpson's rule on
every piece between breakpoints integrates them exactly.  For points inside
the span this is Roark's simply supported beam under a point load plus the
Timoshenko shear term (the tests check the closed form).  ``κ = 6(1+ν)/(7+6ν)``
(Cowper, solid circle).  The crank torque enters at the eccentrics and leaves
at the planet gear, twisting each segment by ``φ = M ℓ / (G J)``.
"""
from __future__ import annotations

import numpy as np


def cowper_circle(nu: float) -> float:
    return 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu)


def _unit_load_diagrams(z_load: float, x: np.ndarray, L: float):
    """Bending moment and shear at ``x`` (beam on supports at 0 and ``L``, unit load at ``z_load``).

    Both are sums over the forces left of ``x``: ``m = Σ F_p (x - p)``, ``v = Σ F_p``.
    """
    forces = ((0.0, (L - z_load) / L), (L, z_load / L), (z_load, -1.0))
    m = sum(F * np.where(x > p, x - p, 0.0) for p, F in forces)
    v = sum(F * (x > p) for p, F in forces)
    return m, v


def influence_matrix(z, L: float, d: float, E: float, nu: float) -> np.ndarray:
    """``α[j, k]``: deflection at ``z[j]`` per unit load at ``z[k]`` (mm/N), solid shaft of diameter ``d``."""
    z = np.asarray(z, dtype=float)
    G = E / (2.0 * (1.0 + nu))
    EI = E * np.pi * d ** 4 / 64.0
    kGA = cowper_circle(nu) * G * np.pi * d ** 2 / 4.0
    knots = np.unique(np.concatenate([z, [0.0, L]]))
    a, b = knots[:-1], knots[1:]
    mid = 0.5 * (a + b)
    h = b - a
    diag = [tuple(_unit_load_diagrams(zk, x, L) for x in (a + 1e-12 * h, mid, b - 1e-12 * h)) for zk in z]
    n = len(z)
    out = np.empty((n, n))
    for j in range(n):
        for k in range(n):
            (mj0, vj0), (mjm, vjm), (mj1, vj1) = diag[j]
            (mk0, vk0), (mkm, vkm), (mk1, vk1) = diag[k]
            bend = h / 6.0 * (mj0 * mk0 + 4.0 * mjm * mkm + mj1 * mk1)
            shear = h / 6.0 * (vj0 * vk0 + 4.0 * vjm * vkm + vj1 * vk1)
            out[j, k] = bend.sum() / EI + shear.sum() / kGA
    return out


def support_reactions(z, L: float) -> np.ndarray:
    """``r[s, k]``: reaction at support ``s`` (0: z = 0, 1: z = L) per unit load at ``z[k]``."""
    z = np.asarray(z, dtype=float)
    return np.stack([(L - z) / L, z / L])


def torsional_compliance(d: float, E: float, nu: float) -> float:
    """``1/(G J)`` of a solid shaft (rad per N·mm per mm of length)."""
    G = E / (2.0 * (1.0 + nu))
    return 1.0 / (G * np.pi * d ** 4 / 32.0)
