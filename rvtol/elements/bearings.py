"""Roller bearing radial deflection: Palmgren's empirical line-contact formula.

The turning-arm (crank) bearing is a needle roller bearing running on the
eccentric.  rvtol uses the standard empirical formula of Palmgren (1959),
as given by Harris & Kotzalas (*Rolling Bearing Analysis*, chapter on contact deformation)
for one roller–raceway line contact of steel::

    δ = 3.84e-5 · Q^0.9 / l^0.8        (mm, with Q in N and l in mm)

with the most loaded roller carrying Stribeck's ``Q_max = 4.08 F_r / Z``
(line contact, zero clearance) and its two contacts (eccentric and cycloid
bore) in series, so the bearing's radial deflection is
``δ_r = 2 · 3.84e-5 · Q_max^0.9 / l^0.8``.
"""
from __future__ import annotations

import numpy as np

PALMGREN_LINE = 3.84e-5   # mm · N^-0.9 · mm^0.8, one line contact, steel on steel
STRIBECK_LINE = 4.08      # Q_max Z / F_r for line contact and zero clearance


def radial_deflection(F_r, rollers: int, length: float):
    """Radial deflection (mm) of a roller bearing under radial load ``F_r`` (N)."""
    q = STRIBECK_LINE * np.abs(np.asarray(F_r, dtype=float)) / rollers
    return 2.0 * PALMGREN_LINE * q ** 0.9 / length ** 0.8
