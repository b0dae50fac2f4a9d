"""The worst case that is the true extreme of a non-linear model, over the tolerance bands.

:func:`true_worst_case` finds the minimum and maximum of an output over the factors' bands
(:attr:`rvtol.spec.Factor.band`; a circular position zone as its disc, not the square; a zone at MMC or
LMC as the disc whose radius grows with its feature's size, :func:`rvtol.spec.zone_bonus`; a datum-feature
shift as one more disc, of radius (the datum's departure from MMB)/2, that moves every zone of its pattern by
the same vector, :func:`rvtol.spec.datum_shifts`).  The
output may be non-smooth (a norm of centred zones, ``abs``, ``min``/``max``), so no single method is
trusted:

1. **corners**: with few factors every corner of the box (each plain factor at an end of its band)
   with every zone on its boundary circle at ``zone_directions`` angles — the extreme of an output
   that is monotone in each factor (checked: the sign of each factor's effect on a Halton sample of the
   box, ``monotone`` in the result; evidence, not a proof);
2. **differential evolution** (scipy, derivative-free global search, the population evaluated in one batch
   per generation), which needs no derivative and does not stop at a kink;
3. **L-BFGS-B** from several starts — the band centres, the linearised worst-case corner, Halton points
   and the best points of 1–2 — with gradients analytic (a model with ``gradient``; where it is undefined,
   central differences) or by central differences in one batch per iterate.

The reported extreme is the best of all.  It is **guaranteed** only for a model that is linear in its
factors (the corner/disc is then the extreme, ``guaranteed = True``); otherwise the result says which
methods reached the reported value (within 1e-9 of the output's range) and that the extreme of a
non-convex output over a box is not guaranteed by any finite search.  The linearised worst case
(:mod:`rvtol.stacking.conventions`) stands beside it: where they differ, the output is not linear over
the bands.
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
from ..model import LinearModel
from ..spec import ToleranceSpec, datum_shifts, zone_bonus
from . import notes as N
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
    guaranteed: bool = False          # True only where the extreme is provably the corner/disc (a linear model)
    monotone: bool | None = None      # each factor's effect of one sign over the sampled box (None: not checked)
    methods: dict = field(default_factory=dict)   # "low"/"high" -> {method: best value (display)}


class _Box:
    """The bands as a box of normalised variables v: [0, 1] per factor; a position zone as (ρ ∈ [0, 1], φ ∈ [−1, 1]),
    its radius t/2 plus the bonus of its size (at the size of the same point); a datum-feature shift as one more
    (ρ, φ), radius κ (x_d − reference), added to every zone of its pattern."""

    def __init__(self, spec: ToleranceSpec):
        con = contributors(spec, np.zeros(len(spec)))
        self.lo, self.hi, self.k = con.lo, con.hi, len(spec)
        self.plain = [i for i, z in enumerate(con.zone) if not z]
        self.zones = []   # (i_x, i_y, radius, [(size index, κ, reference)])
        for z in dict.fromkeys(z for z in con.zone if z):
            i, j = [m for m, zz in enumerate(con.zone) if zz == z]
            self.zones.append((i, j, float(con.t[i]), zone_bonus(spec, z)))
        pair = {con.zone[i]: (i, j) for i, j, _, _ in self.zones}
        self.datums = datum_shifts(spec)
        self.shifts = [(ds.index, ds.kappa, ds.reference, [pair[z] for z in ds.zones]) for ds in self.datums]
        self.discs = len(self.zones) + len(self.shifts)
        self.dim = len(self.plain) + 2 * self.discs
        self.bounds = [(0.0, 1.0)] * len(self.plain) + [b for _ in range(self.discs) for b in ((0.0, 1.0), (-1.0, 1.0))]

    def to_x(self, V: np.ndarray) -> np.ndarray:
        V = np.atleast_2d(V)
        X = np.empty((V.shape[0], self.k))
        p = len(self.plain)
        X[:, self.plain] = self.lo[self.plain] + V[:, :p] * (self.hi[self.plain] - self.lo[self.plain])
        for q, (i, j, r, bonus) in enumerate(self.zones):
            rho, phi = V[:, p + 2 * q], V[:, p + 2 * q + 1]
            R = r + sum(kap * (X[:, m] - ref) for m, kap, ref in bonus)
            cx, cy = 0.5 * (self.lo[i] + self.hi[i]), 0.5 * (self.lo[j] + self.hi[j])
            X[:, i] = cx + R * rho * np.cos(np.pi * phi)
            X[:, j] = cy + R * rho * np.sin(np.pi * phi)
        for q, (m, kap, ref, pairs) in enumerate(self.shifts, start=len(self.zones)):
            rho, phi = V[:, p + 2 * q], V[:, p + 2 * q + 1]
            R = kap * (X[:, m] - ref)
            for i, j in pairs:
                X[:, i] += R * rho * np.cos(np.pi * phi)
                X[:, j] += R * rho * np.sin(np.pi * phi)
        return X

    def corner(self, a: np.ndarray, sign: float) -> np.ndarray:
        """The linearised extreme for the gradient ``a`` (``sign`` +1: maximum, −1: minimum); a size the output does
        not read directly at the end where the zones or shifts it enlarges are largest."""
        grows = {m: kap for _, _, _, bonus in self.zones for m, kap, _ in bonus}
        grows.update({m: kap for m, kap, _, _ in self.shifts})
        v = [1.0 if sign * a[i] > 0 or (a[i] == 0 and grows.get(i, 0.0) > 0) else 0.0 for i in self.plain]
        directions = [[(i, j)] for i, j, _, _ in self.zones] + [pairs for _, _, _, pairs in self.shifts]
        for pairs in directions:
            ax, ay = (sign * sum(a[i] for i, _ in pairs), sign * sum(a[j] for _, j in pairs))
            v += [1.0, math.atan2(ay, ax) / math.pi] if (ax or ay) else [0.0, 0.0]
        return np.array(v)

    def corners(self, directions: int, limit: int) -> np.ndarray | None:
        """Every corner of the plain factors × every zone on its boundary at ``directions`` angles (and at its
        centre), or None beyond ``limit`` points."""
        p, nz = len(self.plain), self.discs
        count = 2 ** p * (directions + 1) ** nz
        if count > limit:
            return None
        grid = ((np.arange(2 ** p)[:, None] >> np.arange(p)) & 1).astype(float)
        ring = [(0.0, 0.0)] + [(1.0, -1.0 + 2.0 * m / directions) for m in range(directions)]
        out = grid
        for _ in range(nz):
            out = np.array([np.concatenate([row, pt]) for row in out for pt in ring])
        return out


class _Search:
    """The evaluations of one worst-case search: ``output`` of ``model`` at points ``v`` of the box's variables,
    counted (:attr:`count`), and their derivatives — the model's own where it has them (chain rule through the
    box map), else central differences."""

    H = 1e-5

    def __init__(self, model: Model, box: _Box, j: int, evaluate: Evaluator):
        self.model, self.box, self.j, self.evaluate = model, box, j, evaluate
        self.analytic = hasattr(model, "gradient")
        self.count = 0
        self.undefined_grad = False

    def values(self, V) -> np.ndarray:
        X = self.box.to_x(V)
        self.count += len(X)
        ev = self.evaluate(self.model, X, "true worst case")
        return np.where(ev.ok, ev.Y[:, self.j], np.nan)

    def differences(self, v, sign):
        box, h = self.box, self.H
        pts = [v]
        for m in range(box.dim):
            e = np.zeros(box.dim)
            e[m] = h
            pts += [_clip(v + e, box.bounds), _clip(v - e, box.bounds)]
        y = self.values(np.array(pts))
        g = np.array([(y[1 + 2 * m] - y[2 + 2 * m]) / max(pts[1 + 2 * m][m] - pts[2 + 2 * m][m], 1e-300)
                      for m in range(box.dim)])
        return sign * y[0], sign * g

    def value_and_grad(self, v, sign):
        """(sign·y, sign·∂y/∂v) at v: analytic where the model's gradient is defined, else central differences."""
        box, h = self.box, self.H
        if self.analytic:
            X = box.to_x(v)
            y = float(self.values(v)[0])
            G = np.asarray(self.model.gradient(X), float)[0, self.j]
            if np.isfinite(y) and np.all(np.isfinite(G)):
                Jv = np.empty(box.dim)
                for m in range(box.dim):   # chain rule through the box map, by differences of the (cheap) map
                    e = np.zeros(box.dim)
                    e[m] = h
                    lo_v, hi_v = _clip(v - e, box.bounds), _clip(v + e, box.bounds)
                    Jv[m] = G @ ((box.to_x(hi_v) - box.to_x(lo_v))[0]) / max(hi_v[m] - lo_v[m], 1e-300)
                return sign * y, sign * Jv
            self.undefined_grad = True
        return self.differences(v, sign)

    def evolve(self, sign: float, budget: int, seed: int, notes: list[str]):
        """Differential evolution — derivative-free, global, the population in one batch per generation — of
        sign·y within ``budget`` evaluations: ``(sign·y, v)`` of its best point, or None (not run, or nothing
        finite)."""
        box = self.box
        pop = max(5, min(15, budget // (2 * max(box.dim, 1) * 20)))
        if not budget > 4 * pop * box.dim:
            return None

        def batch(V):
            y = self.values(np.asarray(V).T)
            return np.where(np.isfinite(y), sign * y, np.inf)

        gens = max(1, (budget // 2) // (pop * box.dim) - 1)
        init = "sobol" if box.dim > 1 else "latinhypercube"
        try:
            de = optimize.differential_evolution(batch, box.bounds, popsize=pop, maxiter=gens, tol=0.0, atol=0.0,
                                                 seed=seed, polish=False, vectorized=True, updating="deferred",
                                                 init=init)
        except ValueError as exc:       # scipy refuses the box (e.g. a degenerate bound): said, not hidden
            notes.append(f"differential evolution not run ({exc}): corners and L-BFGS-B starts only")
            return None
        return (float(de.fun), de.x) if np.isfinite(de.fun) else None

    def polish(self, cands, sign: float, found: dict, max_evaluations: int, notes: list[str]) -> None:
        """L-BFGS-B from each candidate start ``(origin, v0)`` while the budget lasts; each origin's best into
        ``found``."""
        for origin, v0 in cands:
            if self.count >= max_evaluations:
                notes.append(f"stopped at the evaluation budget ({max_evaluations})")
                break
            per_call = 1 if self.analytic else 2 * self.box.dim + 1
            try:
                res = optimize.minimize(lambda v: _finite(self.value_and_grad(v, sign)), v0, jac=True,
                                        method="L-BFGS-B", bounds=self.box.bounds,
                                        options={"maxiter": 200, "ftol": 1e-13, "gtol": 1e-12,
                                                 "maxfun": max(2, (max_evaluations - self.count) // per_call)})
            except _Failed:
                notes.append("the model could not be evaluated at some points inside the bands (NaN): those "
                             "L-BFGS-B starts were abandoned")
                continue
            if origin not in found or res.fun < found[origin][0]:
                found[origin] = (float(res.fun), res.x)


def true_worst_case(model: Model, spec: ToleranceSpec, output: str, evaluate: Evaluator | None = None, *,
                    starts: int = 4, corner_limit: int = 4096, max_evaluations: int = 5000,
                    gradient: np.ndarray | None = None, zone_directions: int = 16, seed: int = 0,
                    monotone_samples: int = 16) -> WorstCase:
    """The minimum and maximum of ``output`` over the factors' bands (module docstring).

    ``gradient`` (base units, at the nominal point) orients the linearised corner start; without it a
    central difference at the band centres does.  ``max_evaluations`` caps the model evaluations of the
    searches (the best point found so far is reported, and the cap noted); ``corner_limit`` the corners
    enumerated; ``seed`` the differential evolution (the result is deterministic for a seed).
    """
    q = model.output(output)
    box = _Box(spec)
    search = _Search(model, box, model.output_index(output), evaluate or Evaluator())
    lo_b = np.array([b[0] for b in box.bounds])
    hi_b = np.array([b[1] for b in box.bounds])
    notes = [(N.PATTERN_SHIFT_SEPARATE if ds.separate else N.PATTERN_SHIFT).format(datum=ds.label,
                                                                                    zones=", ".join(ds.zones))
             for ds in box.datums]
    centre = np.array([0.5] * len(box.plain) + [0.0, 0.0] * box.discs)
    if gradient is None or not np.all(np.isfinite(gradient)):   # orient the corner by the box-variable gradient
        _, g0 = search.differences(centre, 1.0)
        a = np.zeros(box.k)
        a[box.plain] = g0[:len(box.plain)]
    else:
        a = np.asarray(gradient, float)
    linear = isinstance(model, LinearModel)
    monotone = None
    if box.plain and monotone_samples:
        monotone = _monotone(search.values, box, monotone_samples, seed)
    cs = box.corners(zone_directions, corner_limit)
    ys_corner = search.values(cs) if cs is not None else None
    halton = qmc.Halton(d=box.dim, scramble=False).random(max(starts - 2, 0) + 1)[1:]   # skip the origin
    result, methods = {}, {}
    for sign, key in ((-1.0, "high"), (1.0, "low")):
        sgn = -sign   # minimise sign·y: sign −1 finds the maximum
        found: dict[str, tuple[float, np.ndarray]] = {}
        if ys_corner is not None and np.any(np.isfinite(ys_corner)):
            m = int(np.nanargmin(sign * ys_corner))
            found["corners"] = (float(sign * ys_corner[m]), cs[m])
        de = search.evolve(sign, max_evaluations - search.count, seed, notes)
        if de is not None:
            found["differential evolution"] = de
        # the linearised corner first (exact for a linear output: the budget never runs out before it), then the best
        # points found, then the other starts
        cands = [("L-BFGS-B", box.corner(a, sgn))]
        cands += [(m + " → L-BFGS-B", v) for m, (_, v) in sorted(found.items(), key=lambda t: t[1][0])]
        cands += [("L-BFGS-B", v) for v in [centre] + [lo_b + u * (hi_b - lo_b) for u in halton]]
        search.polish(cands, sign, found, max_evaluations, notes)
        if not found:
            result[key] = (math.nan, {})
            methods[key] = {}
            continue
        best_y, best_v = min(found.values(), key=lambda t: t[0])
        x = box.to_x(best_v)[0]
        result[key] = (sign * best_y, {f.name: float(units.from_base(x[i], f.unit)) for i, f in enumerate(spec.factors)})
        methods[key] = {m: sign * v for m, (v, _) in found.items()}
    disp = lambda v: float(q.to_display(np.array([v]))[0]) if math.isfinite(v) else math.nan  # noqa: E731
    lo, hi = disp(result["low"][0]), disp(result["high"][0])
    span = abs(hi - lo) if math.isfinite(hi - lo) else 0.0
    agree = {}
    for key, val in (("low", lo), ("high", hi)):
        ms = {m: disp(v) for m, v in methods.get(key, {}).items()}
        methods[key] = ms
        agree[key] = [m for m, v in ms.items() if abs(v - val) <= 1e-9 * max(span, abs(val), 1e-300)]
    how = _how(zone_directions, cs, len(halton), search, agree, linear, monotone)
    return WorstCase(output, q.shown_unit, lo, hi, result["low"][1], result["high"][1], search.count, how,
                     list(dict.fromkeys(notes)), guaranteed=linear, monotone=monotone, methods=methods)


def _how(zone_directions: int, cs, halton: int, search: _Search, agree: dict, linear: bool, monotone) -> str:
    """How the extremes were found, which methods reached them, and whether they are guaranteed."""
    how = (f"best of: every corner × zone boundary at {zone_directions} angles"
           + (f" ({len(cs)} points)" if cs is not None else " (skipped: too many)")
           + ", differential evolution (scipy, derivative-free), L-BFGS-B from their best points and from "
           + f"{halton + 2} starts (centre, linearised corner, Halton)"
           + ("; analytic gradient" if search.analytic else "; central differences")
           + (" (central differences where it is undefined)" if search.undefined_grad else ""))
    how += f"; low reached by {', '.join(agree['low']) or '—'}, high by {', '.join(agree['high']) or '—'}"
    if linear:
        return how + "; a linear model: the extreme is the corner/disc (guaranteed)"
    return how + ("; not guaranteed (a global search over a non-linear output)"
                  + ("; the output is monotone in each plain factor over a sampled box (evidence, not proof): its "
                     "extreme lies on the corners enumerated" if monotone else ""))


def _monotone(values, box: _Box, n: int, seed: int) -> bool:
    """True when every plain factor's effect keeps one sign at ``n`` Halton points of the box (zones at random
    points of their discs): a corner is then the extreme (for a model that is monotone everywhere)."""
    U = qmc.Halton(d=box.dim, scramble=True, seed=seed).random(n)
    lo_b = np.array([b[0] for b in box.bounds])
    hi_b = np.array([b[1] for b in box.bounds])
    V = lo_b + U * (hi_b - lo_b)
    p = len(box.plain)
    rows = []
    for v in V:   # each factor's local effect (±0.02 of its band) and its effect end to end, at every point
        for m in range(p):
            for lo_, hi_ in ((max(v[m] - 0.02, 0.0), min(v[m] + 0.02, 1.0)), (0.0, 1.0)):
                a, b = v.copy(), v.copy()
                a[m], b[m] = lo_, hi_
                rows += [a, b]
    y = values(np.array(rows)).reshape(n, p * 2, 2)
    dy = y[:, :, 1] - y[:, :, 0]
    if not np.all(np.isfinite(dy)):
        return False
    scale = np.abs(dy).max(initial=0.0)
    tol = 1e-12 * max(scale, 1e-300)
    dy = dy.reshape(n, p, 2).transpose(1, 0, 2).reshape(p, -1)   # per factor: every local and end-to-end effect
    return bool(np.all((dy >= -tol).all(axis=1) | (dy <= tol).all(axis=1)))


class _Failed(Exception):
    pass


def _finite(fg):
    f, g = fg
    if not (np.isfinite(f) and np.all(np.isfinite(g))):
        raise _Failed
    return float(f), g


def _clip(v, bounds):
    return np.array([min(max(x, b[0]), b[1]) for x, b in zip(v, bounds)])
