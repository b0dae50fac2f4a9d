"""Rule #1, the envelope requirement: a feature of size's form stays within its size's departure from MMC.

ASME Y14.5-2018 §5.8 (Rule #1, the default for features of size) and ISO 8015's envelope Ⓔ: a shaft's surface may
not cross a perfect cylinder at its maximum material size, so its form deviation f (straightness, flatness,
circularity, cylindricity) is at most the size's departure from MMC — at MMC the form must be perfect::

    external (a shaft: MMC the largest size d_max)    0 ≤ f ≤ min(t_f, d_max − d)
    internal (a hole: MMC the smallest size D_min)    0 ≤ f ≤ min(t_f, D − D_min)

A spec writes it on the form factor (``tolerance = "⌭0.01"``, ``envelope = "shaft.d"``, ``feature_type =
"external"``).  What it changes:

- **the worst case**: the drawing admits the size and the form together only in that polygon, not in the box of
  their two bands — a linear output a·d + b·f reaches its extremes at the polygon's corners (d_max, 0), (d_min, 0),
  (d_min, m) and (d_max − m, m) with m = min(t_f, d_max − d_min) (internal: mirrored).  The mating size of a shaft,
  d + f, is then at most d_max, as Rule #1 intends: a fit's minimum clearance is MMC hole − MMC shaft whatever the
  form tolerances (:func:`extreme`; the stack-up's ``worst case (GD&T domains)`` row);
- **the Monte Carlo** describes the parts as produced — size and form drawn independently — so some of them break
  the envelope; the stack-up notes say how many (:func:`violations`), the parts an inspection to the drawing would
  reject.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import units


@dataclass(frozen=True)
class Envelope:
    """A form factor bound by its size's departure from MMC (indices in the spec; limits in base units)."""

    form: int
    size: int
    external: bool
    size_limits: tuple[float, float]
    form_limit: float                  # t_f

    def corners(self) -> np.ndarray:
        """The polygon of (size, form) the drawing admits, its corners (base units)."""
        lo, hi = self.size_limits
        m = min(self.form_limit, hi - lo)
        if self.external:
            return np.array([[lo, 0.0], [hi, 0.0], [lo, m], [hi - m, m]])
        return np.array([[lo, 0.0], [hi, 0.0], [hi, m], [lo + m, m]])

    def mmc_departure(self, size: np.ndarray) -> np.ndarray:
        lo, hi = self.size_limits
        return hi - size if self.external else size - lo


def envelopes(spec) -> list[Envelope]:
    """The spec's envelopes (each form factor with ``envelope``)."""
    out = []
    for i, f in enumerate(spec.factors):
        if f.envelope:
            j = spec.index(f.envelope)
            s = spec.factors[j]
            size = tuple(float(units.to_base(v, s.unit)) for v in s.band)
            out.append(Envelope(i, j, f.feature_type == "external", size,
                                float(units.to_base(f.band[1], f.unit))))
    return out


def extreme(env: Envelope, a_size: float, a_form: float, centre: tuple[float, float]) -> tuple[float, float]:
    """How much the envelope moves a linear output's worst case, against the box of the two bands that the
    arithmetic worst case takes: ``(change of the low end, change of the high end)`` in the output's base unit —
    the polygon's lowest and highest value of a_size·(d − c_d) + a_form·(f − c_f) less the box's (≥ 0 and ≤ 0)."""
    v = (env.corners() - np.asarray(centre)) @ np.array([a_size, a_form])
    lo, hi = env.size_limits
    box = abs(a_size) * 0.5 * (hi - lo) + abs(a_form) * 0.5 * env.form_limit
    return float(v.min() + box), float(v.max() - box)


def violations(env: Envelope, X: np.ndarray) -> int:
    """The sampled parts (rows of ``X``, base units) whose form exceeds their size's departure from MMC."""
    X = np.asarray(X, dtype=float)
    return int(np.count_nonzero(X[:, env.form] > np.maximum(env.mmc_departure(X[:, env.size]), 0.0)))
