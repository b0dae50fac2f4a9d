"""Involute (sun–planet) mesh stiffness after ISO 6336-1:2006, method B.

Doc 004 derives the mesh stiffness ``k_X`` "using elastic mechanics" without
giving the formula; rvtol uses the standard one:

* single stiffness ``c'_th = 1/q'`` with ``q'`` the ISO polynomial in the
  virtual teeth numbers and profile shifts (N/(mm·µm));
* ``c' = c'_th C_M C_R C_B cos β`` with ``C_M = 0.8``, ``C_R = 1`` (solid
  blanks), ``C_B = [1 + 0.5 (1.2 - h_fP/m)] [1 - 0.02 (20° - α)]``;
* below a specific load ``F_t/b`` of 100 N/mm, ``c'`` is scaled by
  ``(F_t/b)/100`` (ISO 6336-1 § 9);
* mesh stiffness ``c_γα = c' (0.75 ε_α + 0.25)``; per mesh ``k_X = c_γα b``
  (along the line of action), torsional ``K_X = k_X r_b²`` (doc 004).
"""
from __future__ import annotations

import numpy as np

_Q = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)


def single_stiffness_th(z1, z2, x1=0.0, x2=0.0) -> float:
    """``c'_th = 1/q'`` (N/(mm·µm)) for external spur gears."""
    C = _Q
    q = (C[0] + C[1] / z1 + C[2] / z2 + C[3] * x1 + C[4] * x1 / z1 + C[5] * x2 + C[6] * x2 / z2
         + C[7] * x1 ** 2 + C[8] * x2 ** 2)
    return 1.0 / q


def basic_rack_factor(alpha: float, dedendum_factor: float = 1.25) -> float:
    """``C_B`` for a basic rack with dedendum ``h_fP = dedendum_factor · m``, pressure angle in rad."""
    return (1.0 + 0.5 * (1.2 - dedendum_factor)) * (1.0 - 0.02 * (20.0 - np.degrees(alpha)))


def contact_ratio(z1, z2, m, alpha) -> float:
    """Transverse contact ratio ``ε_α`` of an unshifted standard external spur pair."""
    r1, r2 = m * z1 / 2.0, m * z2 / 2.0
    rb1, rb2 = r1 * np.cos(alpha), r2 * np.cos(alpha)
    path = np.sqrt((r1 + m) ** 2 - rb1 ** 2) + np.sqrt((r2 + m) ** 2 - rb2 ** 2) - (r1 + r2) * np.sin(alpha)
    return float(path / (np.pi * m * np.cos(alpha)))


def mesh_stiffness(z1, z2, m, alpha, b, F_t, x1=0.0, x2=0.0):
    """``k_X`` per mesh (N/mm along the line of action) at tangential force ``F_t`` (N, array OK)."""
    c_single = single_stiffness_th(z1, z2, x1, x2) * 0.8 * 1.0 * basic_rack_factor(alpha)
    load = np.clip(np.asarray(F_t, dtype=float) / b / 100.0, 0.0, 1.0)
    c_gamma = c_single * load * (0.75 * contact_ratio(z1, z2, m, alpha) + 0.25)
    return c_gamma * b * 1e3  # N/(mm·µm) · mm -> N/µm -> N/mm
