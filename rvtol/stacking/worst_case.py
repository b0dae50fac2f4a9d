"""The worst case that is the true extreme of a non-linear model, over the tolerance bands.

:func:`true_worst_case` finds the minimum and maximum of an output over the factors' bands
(:attr:`rvtol.spec.Factor.band`; a circular position zone as its disc, not the square) by bounded
optimisation: L-BFGS-B (scipy) from several starts — the band centres, the linearised worst-case
corner and Halton points — with gradients analytic (a model with ``gradient``) or by central
differences in one batch of model evaluations per iterate; with few factors every corner of the
box is evaluated too and polished.  It is a local method with several starts: it finds the true
extreme of a monotone or mildly non-linear output (for a monotone one the extreme is a corner, which
the corner search finds exactly) and says which starts and corners it tried.  The linearised worst
case (:mod:`rvtol.stacking.conventions`) stands beside it: where they differ, the output is not
linear over the bands.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize
from scipy.stats import qmc

from .. import units
from ..mc import Evaluator
from ..model import Model
from ..spec import ToleranceSpec
from .conventions import contributors


@dataclass
class WorstCase:
    """The extreme values of an output over the tolerance bands (display units), where they are, how found."""

    output: str
    unit: str
    low: float
    high: float
    x_low: dict            # factor -> value (its unit) at the minimum
    x_high: dict
    evaluations: int
    how: str
    notes: list[str] = field(default_factory=list)


class _Box:
    """The bands as a box of normalised variables v: [0, 1] per factor; a position zone as (ρ ∈ [0, 1], φ ∈ [−1, 1])."""

    def __init__(self, spec: ToleranceSpec):
        con = contributors(spec, np.zeros(len(spec)))
        self.lo, self.hi, self.k = con.lo, con.hi, len(spec)
        self.plain = [i for i, z in enumerate(con.zone) if not z]
        self.zones = []   # (i_x, i_y, radius)
        for z in dict.fromkeys(z for z in con.zone if z):
            i, j = [m for m, zz in enumerate(con.zone) if zz == z]
            self.zones.append((i, j, float(con.t[i])))
        self.dim = len(self.plain) + 2 * len(self.zones)
        self.bounds = [(0.0, 1.0)] * len(self.plain) + [b for _ in self.zones for b in ((0.0, 1.0), (-1.0, 1.0))]

    def to_x(self, V: np.ndarray) -> np.ndarray:
        V = np.atleast_2d(V)
        X = np.empty((V.shape[0], self.k))
        p = len(self.plain)
        X[:, self.plain] = self.lo[self.plain] + V[:, :p] * (self.hi[self.plain] - self.lo[self.plain])
        for q, (i, j, r) in enumerate(self.zones):
            rho, phi = V[:, p + 2 * q], V[:, p + 2 * q + 1]
            cx, cy = 0.5 * (self.lo[i] + self.hi[i]), 0.5 * (self.lo[j] + self.hi[j])
            X[:, i] = cx + r * rho * np.cos(np.pi * phi)
            X[:, j] = cy + r * rho * np.sin(np.pi * phi)
        return X

    def corner(self, a: np.ndarray, sign: float) -> np.ndarray:
        """The linearised extreme for the gradient ``a`` (``sign`` +1: maximum, −1: minimum)."""
        v = [1.0 if sign * a[i] > 0 else 0.0 for i in self.plain]
        for i, j, _ in self.zones:
            ax, ay = sign * a[i], sign * a[j]
            v += [1.0, math.atan2(ay, ax) / math.pi] if (ax or ay) else [0.0, 0.0]
        return np.array(v)

    def corners(self, a: np.ndarray, sign: float, limit: int = 12) -> np.ndarray | None:
        """Every corner of the plain factors (zones at their linearised extreme), or None beyond ``limit`` factors."""
        p = len(self.plain)
        if p > limit:
            return None
        base = self.corner(a, sign)
        grid = ((np.arange(2 ** p)[:, None] >> np.arange(p)) & 1).astype(float)
        out = np.repeat(base[None], len(grid), axis=0)
        out[:, :p] = grid
        return out


def true_worst_case(model: Model, spec: ToleranceSpec, output: str, evaluate: Evaluator | None = None, *,
                    starts: int = 4, corner_limit: int = 10, max_evaluations: int = 5000,
                    gradient: np.ndarray | None = None) -> WorstCase:
    """The minimum and maximum of ``output`` over the factors' bands (module docstring).

    ``gradient`` (base units, at the nominal point) orients the linearised corner start; without it a
    central difference at the band centres does.  ``max_evaluations`` caps the
    model evaluations of the search (the best point found so far is reported, and the cap noted).
    """
    evaluate = evaluate or Evaluator()
    q = model.output(output)
    j = model.output_index(output)
    box = _Box(spec)
    analytic = hasattr(model, "gradient")
    count = [0]
    notes: list[str] = []
    h = 1e-5

    def values(V) -> np.ndarray:
        X = box.to_x(V)
        count[0] += len(X)
        ev = evaluate(model, X, "true worst case")
        return np.where(ev.ok, ev.Y[:, j], np.nan)

    def value_and_grad(v, sign):
        """(sign·y, sign·∂y/∂v) at v: one batch of 2·dim + 1 rows (central differences, one-sided at bounds)."""
        if analytic:
            X = box.to_x(v)
            y = float(values(v)[0])
            G = np.asarray(model.gradient(X), float)[0, j]
            Jv = np.empty(box.dim)
            for m in range(box.dim):   # chain rule through the box map, by differences of the (cheap) map
                e = np.zeros(box.dim)
                e[m] = h
                lo_v, hi_v = _clip(v - e, box.bounds), _clip(v + e, box.bounds)
                Jv[m] = G @ ((box.to_x(hi_v) - box.to_x(lo_v))[0]) / max(hi_v[m] - lo_v[m], 1e-300)
            return sign * y, sign * Jv
        pts = [v]
        for m in range(box.dim):
            e = np.zeros(box.dim)
            e[m] = h
            pts += [_clip(v + e, box.bounds), _clip(v - e, box.bounds)]
        y = values(np.array(pts))
        g = np.array([(y[1 + 2 * m] - y[2 + 2 * m]) / max(pts[1 + 2 * m][m] - pts[2 + 2 * m][m], 1e-300)
                      for m in range(box.dim)])
        return sign * y[0], sign * g

    centre = np.array([0.5] * len(box.plain) + [0.0, 0.0] * len(box.zones))
    if gradient is None:   # orient the corner by the box-variable gradient at the centre (same signs)
        _, g0 = value_and_grad(centre, 1.0)
        a = np.zeros(box.k)
        a[box.plain] = g0[:len(box.plain)]
    else:
        a = np.nan_to_num(np.asarray(gradient, float))
    halton = qmc.Halton(d=box.dim, scramble=False).random(max(starts - 2, 0) + 1)[1:]   # skip the origin
    lo_b = np.array([b[0] for b in box.bounds])
    hi_b = np.array([b[1] for b in box.bounds])
    result = {}
    hows = []
    for sign, key in ((-1.0, "high"), (1.0, "low")):
        sgn = -sign   # minimise sign·y: sign −1 finds the maximum
        cands = [centre, box.corner(a, sgn)] + [lo_b + u * (hi_b - lo_b) for u in halton]
        best_v, best_y = None, math.inf
        cs = box.corners(a, sgn, corner_limit)
        if cs is not None:
            ys = sign * values(cs)
            if np.any(np.isfinite(ys)):
                m = int(np.nanargmin(ys))
                best_v, best_y = cs[m], float(ys[m])
                cands.insert(0, cs[m])
        for v0 in cands:
            if count[0] >= max_evaluations:
                notes.append(f"stopped at the evaluation budget ({max_evaluations})")
                break
            per_call = 1 if analytic else 2 * box.dim + 1
            try:
                res = optimize.minimize(lambda v: _finite(value_and_grad(v, sign)), v0, jac=True, method="L-BFGS-B",
                                        bounds=box.bounds,
                                        options={"maxiter": 200, "ftol": 1e-13, "gtol": 1e-12,
                                                 "maxfun": max(2, (max_evaluations - count[0]) // per_call)})
            except _Failed:
                notes.append("the model could not be evaluated at some points inside the bands; those starts "
                             "were abandoned")
                continue
            if res.fun < best_y:
                best_v, best_y = res.x, float(res.fun)
        if best_v is None:
            result[key] = (math.nan, {})
            continue
        x = box.to_x(best_v)[0]
        result[key] = (sign * best_y, {f.name: float(units.from_base(x[i], f.unit)) for i, f in enumerate(spec.factors)})
    hows.append(f"L-BFGS-B over the bands from {len(halton) + 2} starts (centre, linearised corner, Halton)"
                + (", every corner of the box" if box.corners(a, 1.0, corner_limit) is not None else "")
                + ("; analytic gradient" if analytic else "; central differences"))
    disp = lambda v: float(q.to_display(np.array([v]))[0]) if math.isfinite(v) else math.nan  # noqa: E731
    lo, hi = disp(result["low"][0]), disp(result["high"][0])
    return WorstCase(output, q.shown_unit, lo, hi, result["low"][1], result["high"][1], count[0], "; ".join(hows),
                     list(dict.fromkeys(notes)))


class _Failed(Exception):
    pass


def _finite(fg):
    f, g = fg
    if not (np.isfinite(f) and np.all(np.isfinite(g))):
        raise _Failed
    return float(f), g


def _clip(v, bounds):
    return np.array([min(max(x, b[0]), b[1]) for x, b in zip(v, bounds)])
