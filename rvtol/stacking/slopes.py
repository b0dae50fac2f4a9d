"""One-sided slopes of a model's output at the nominal point: where a single derivative cannot be trusted.

A linearised stack-up reads each contributor's effect from one derivative.  That fails silently where the
output has a kink at the nominal point — a norm of a centred position zone (``hypot(x, y)``: every
direction increases it, its "derivative" is the whole unit disc), an ``abs``, a ``min``/``max`` at a tie —
and where the derivative is undefined (NaN, ∞).  :func:`one_sided_slopes` asks the model itself:

* per plain factor i, the one-sided directional derivatives D⁺ᵢ = (y(x₀ + h eᵢ) − y₀)/h and
  D⁻ᵢ = (y(x₀ − h eᵢ) − y₀)/h (h = ``step`` × the half band): a smooth output has D⁻ = −D⁺, a kink
  does not (|x| at 0: D⁺ = D⁻ = 1);
* per circular position zone, the directional derivative along a ring of directions u_φ,
  D(φ) = (y(x₀ + h u_φ) − y₀)/h, and its extremes (each polished by a bounded scalar search in φ):
  a smooth output has max D = −min D = |∇_zone y|; a cone (−|p₁ − p₂| of a floating fastener) has
  max D = min D = −1: every direction lowers it;
* per datum-feature shift (:func:`rvtol.spec.datum_shifts`), the same ring with every zone it locates moved by
  the same vector — the pattern translated as a whole (the distance between two of its features: D = 0).

A contributor is *kinked* when the two sides disagree by more than ``kink_tolerance`` of their size and
(for a factor) its one-sided slopes stay as the step doubles — a smooth extremum's double with it.
The linearised worst case then takes the side that hurts (:mod:`rvtol.stacking.conventions`): a factor
adds t·max(0, D⁺, D⁻) above and t·max(0, −D⁺, −D⁻) below; a zone of radius r adds r·max(0, max D)
above and r·max(0, −min D) below — the handbooks' "a position tolerance ⌀t contributes t/2 in the
direction that hurts" (Drake 1999 ch. 9; Fischer, *Mechanical Tolerance Stackup and Analysis*, 2011,
ch. 9), here with the direction and the size of the effect measured on the model.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize

from ..mc import Evaluator
from ..model import Model
from ..spec import ToleranceSpec, datum_shifts

#: relative step (of the half band / zone radius) of the one-sided differences
STEP = 1e-4
#: the two sides of a smooth contributor agree to this fraction of their size
KINK_TOLERANCE = 0.2
#: ring directions of a zone (then polished)
DIRECTIONS = 36


@dataclass
class Slopes:
    """One-sided slopes of one output at ``x0`` (output base unit per factor base unit)."""

    up: np.ndarray                   # D⁺ per factor (NaN for zone coordinates)
    down: np.ndarray                 # D⁻ per factor: change of y per unit step toward lower values
    zone_max: dict = field(default_factory=dict)   # zone -> max over directions of D(φ)
    zone_min: dict = field(default_factory=dict)   # zone -> min over directions of D(φ)
    zone_grad: dict = field(default_factory=dict)  # zone -> (D_x, D_y) by central differences
    pattern_max: dict = field(default_factory=dict)  # datum feature -> max D(φ) of its zones moved together
    pattern_min: dict = field(default_factory=dict)  # datum feature -> min D(φ)
    kinked: list = field(default_factory=list)     # factor and zone names with a kink at x0
    undefined: list = field(default_factory=list)  # names whose slopes the model could not give
    evaluations: int = 0

    def central(self, i: int) -> float:
        """(D⁺ − D⁻)/2: the central difference of factor i."""
        return 0.5 * (self.up[i] - self.down[i])


def _kink(a: float, b: float, tol: float) -> bool:
    """True when a smooth contributor's two sides (a, −b expected equal) disagree."""
    scale = abs(a) + abs(b)
    return bool(scale > 0 and abs(a + b) > tol * scale)


def _stationary(up: float, down: float, up2: float, down2: float) -> bool:
    """True when both one-sided slopes double with the step: a smooth extremum (y ≈ y₀ + ½ y'' h²), not a kink
    (whose one-sided slopes stay as the step grows)."""
    return all(abs(b - 2 * a) <= 0.1 * abs(2 * a) for a, b in ((up, up2), (down, down2)) if a != 0.0) and \
        (up != 0.0 or down != 0.0)


def one_sided_slopes(model: Model, spec: ToleranceSpec, output: str, x0: np.ndarray | None = None,
                     evaluate: Evaluator | None = None, *, step: float = STEP,
                     kink_tolerance: float = KINK_TOLERANCE, directions: int = DIRECTIONS) -> Slopes:
    """The one-sided slopes of ``output`` at ``x0`` (default the nominal point; module docstring)."""
    evaluate = evaluate or Evaluator()
    j = model.output_index(output)
    x0 = spec.nominal_base() if x0 is None else np.asarray(x0, dtype=float)
    from .conventions import contributors   # the bands in base units (one definition)

    con = contributors(spec, np.zeros(len(spec)))
    k = len(spec)
    plain = [i for i in range(k) if not con.zone[i]]
    zones = {}
    for z in dict.fromkeys(z for z in con.zone if z):
        zones[z] = [m for m in range(k) if con.zone[m] == z]
    # a datum-feature shift moves every zone it locates by one vector: its ring moves them together
    rings = {z: [tuple(p)] for z, p in zones.items()}
    patterns = {d.label: [tuple(zones[z]) for z in d.zones] for d in datum_shifts(spec)}
    count = [0]

    def y(X) -> np.ndarray:
        X = np.atleast_2d(X)
        count[0] += len(X)
        ev = evaluate(model, X, "one-sided slopes")
        return np.where(ev.ok, ev.Y[:, j], np.nan)

    h = {i: step * max(float(con.t[i]), 1e-300) for i in range(k)}
    phis = 2 * np.pi * np.arange(directions) / directions

    def moved(pairs, p):
        x = x0.copy()
        for ix, iy in pairs:
            x[ix] += h[pairs[0][0]] * math.cos(p)
            x[iy] += h[pairs[0][0]] * math.sin(p)
        return x

    rows = [x0]
    for i in plain:
        for s in (1.0, -1.0, 2.0, -2.0):   # the doubled steps tell a kink (slopes that stay) from a smooth extremum
            x = x0.copy()
            x[i] += s * h[i]
            rows.append(x)
    for pairs in list(rings.values()) + list(patterns.values()):
        rows += [moved(pairs, p) for p in phis]
    v = y(np.array(rows))
    y0 = v[0]
    up = np.full(k, np.nan)
    down = np.full(k, np.nan)
    out = Slopes(up, down)
    r = 1
    for i in plain:
        up[i], down[i] = (v[r] - y0) / h[i], (v[r + 1] - y0) / h[i]
        up2, down2 = (v[r + 2] - y0) / (2 * h[i]), (v[r + 3] - y0) / (2 * h[i])
        r += 4
        if not (np.isfinite(up[i]) and np.isfinite(down[i])):
            out.undefined.append(spec.names[i])
        elif _kink(up[i], down[i], kink_tolerance) and not _stationary(up[i], down[i], up2, down2):
            out.kinked.append(spec.names[i])
    for name, pairs, pattern in [(z, p, False) for z, p in rings.items()] + [(d, p, True) for d, p in patterns.items()]:
        d = (v[r:r + directions] - y0) / h[pairs[0][0]]
        r += directions
        if not np.all(np.isfinite(d)):
            if not pattern:       # a pattern the model cannot shift: absent from pattern_max (the caller says so)
                out.undefined.append(name)
            continue

        def dphi(p, pairs=pairs):
            return float((y(moved(pairs, p))[0] - y0) / h[pairs[0][0]])

        ext = []
        for sign in (1.0, -1.0):   # polish the best ring direction within its neighbours
            m = int(np.argmax(sign * d))
            w = 2 * np.pi / directions
            res = optimize.minimize_scalar(lambda p: -sign * dphi(p), bounds=(phis[m] - w, phis[m] + w),
                                           method="bounded", options={"xatol": 1e-4})
            best = float(sign * d[m])
            if np.isfinite(res.fun) and -res.fun > best:
                best = float(-res.fun)
            ext.append(sign * best)
        if pattern:
            out.pattern_max[name], out.pattern_min[name] = ext
            continue
        out.zone_max[name], out.zone_min[name] = ext
        # the gradient of a smooth zone: D(0) = D_x, D(π/2) = D_y (central over the ring's opposite points)
        q = directions // 4
        out.zone_grad[name] = (0.5 * (d[0] - d[2 * q]), 0.5 * (d[q] - d[3 * q]))
        if _kink(out.zone_max[name], out.zone_min[name], kink_tolerance):
            out.kinked.append(name)
    out.evaluations = count[0]
    return out
