"""The tolerance allocation problem and its constraints.

Minimise ``Σ_i C_i(t_i)`` over the allocated factors' tolerances ``t_i``
(half-bands ±t: ``T/2`` of a two-sided factor, the coverage value of a
one-sided magnitude) subject to the requirements on the model's outputs and
``t_min,i ≤ t_i ≤ t_max,i`` (the cost curve's validity range).  Changing
``t_i`` rescales factor i's distribution about its centre
(:meth:`rvtol.spec.ToleranceSpec.scaled`), so its shape and σ/t ratio stay.

Two constraint evaluations:

* :class:`LinearisedConstraint` — the output's RSS σ from the model's
  five-point gradient at nominal, ``Σ_i (S_ji σ_i)² ≤ (m_j / z_j)²``, or the
  worst case ``Σ_i |S_ji| t_i ≤ m_j`` (m_j: distance of the nominal output
  to its nearer limit; z_j: 3·Cpk_min or the normal quantile of the yield);
  the convex problem of :mod:`rvtol.allocation.convex`;
* :class:`MonteCarloConstraint` — yield and/or Cpk of **any** Model from a
  Monte Carlo sample, evaluated through :func:`rvtol.mc.evaluate`, with a
  fixed uniform design (common random numbers) so the constraint is a
  deterministic function of the tolerances.

Both return a *violation* ≥ 0 per candidate (0 = feasible).
"""
from __future__ import annotations

import fnmatch
import math
from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np
import pandas as pd
from scipy import stats as sps

from .. import stats as st
from ..stats import rss
from .. import units
from ..errors import InputError
from ..executors import Shared
from ..mc import Evaluator, auto_chunk_size, evaluate, map_chunks
from ..model import Model
from ..sampling import apply_copula, to_factors, uniform_design
from ..spec import Requirement, ToleranceSpec
from ..verdict import cpk_figures, judge, other_cpk, percentile_cpk_confidence, yield_bound
from .cost import CostModel

def expand_requirements(reqs: Sequence[Requirement], model: Model) -> list[Requirement]:
    """Expand output patterns (``delta_*``) into one requirement per matching output."""
    out = []
    for r in reqs:
        if any(ch in r.output for ch in "*?["):
            names = [n for n in model.output_names if fnmatch.fnmatchcase(n, r.output)]
            if not names:
                raise InputError(f"output pattern {r.output!r} matches no output of the model "
                                 f"({', '.join(model.output_names)})", file=r.file, key=f"{r.key}.output")
            out += [replace(r, output=n) for n in names]
        else:
            model.output(r.output)
            out.append(r)
    return [r.in_unit(model.output(r.output).shown_unit) for r in out]


@dataclass
class AllocationProblem:
    """Model, spec, allocated factors with their cost curves, requirements (display-unit limits)."""

    model: Model
    spec: ToleranceSpec
    factors: list[str]
    curves: list[CostModel]
    requirements: list[Requirement]
    ties: tuple[tuple[str, ...], ...] = ()    # factors that share one tolerance (one drawing callout)

    def __post_init__(self):
        self.model.check_spec(self.spec)
        self.idx = [self.spec.index(n) for n in self.factors]
        if len(set(self.idx)) != len(self.idx) or not self.idx:
            raise InputError("allocated factors must be distinct and at least one", key="factors")
        # a tied factor follows its group's first (the lead) at the spec's ratio: t_k = t_lead · t0_k / t0_lead
        at = {n: k for k, n in enumerate(self.factors)}
        self.lead = np.arange(len(self.factors))
        for group in self.ties:
            if any(n not in at for n in group):
                raise InputError(f"tied factors {', '.join(n for n in group if n not in at)} are not allocated",
                                 key="tie")
            self.lead[[at[n] for n in group]] = at[group[0]]
        self.free = np.flatnonzero(self.lead == np.arange(len(self.factors)))   # one variable per tolerance
        t0 = self.t0
        self.ratio = t0 / t0[self.lead]
        if len(self.curves) != len(self.factors):
            raise InputError("one cost curve per allocated factor", key="assign")
        for n, c in zip(self.factors, self.curves):
            f = self.spec.factor(n)
            if units.dimension(f.unit) != units.dimension(c.unit):
                raise InputError(f"cost curve {c.name!r} is in {c.unit} but factor {n!r} is in {f.unit}",
                                 key="assign")
        if not self.requirements:
            raise InputError("an allocation needs at least one requirement", key="requirement")

    # -- tolerances (base units) -------------------------------------------------
    @property
    def t0(self) -> np.ndarray:
        """The spec's current tolerances ±t of the allocated factors (base units)."""
        return np.array([units.to_base(self.spec.factors[i].half_band, self.spec.factors[i].unit)
                         for i in self.idx])

    @property
    def lower(self) -> np.ndarray:
        return np.array([c.bounds_base[0] for c in self.curves])

    @property
    def upper(self) -> np.ndarray:
        return np.array([c.bounds_base[1] for c in self.curves])

    def cost(self, t) -> np.ndarray:
        """Total cost of tolerance vectors ``t[..., m]`` (base units)."""
        t = np.asarray(t, float)
        return sum(c.cost_base(t[..., i]) for i, c in enumerate(self.curves))

    def costs(self, t) -> np.ndarray:
        return np.array([c.cost_base(t[i]) for i, c in enumerate(self.curves)])

    def scales(self, t) -> dict[str, float]:
        return {n: float(v / v0) for n, v, v0 in zip(self.factors, t, self.t0)}

    def spec_at(self, t) -> ToleranceSpec:
        """The spec with the allocated factors' tolerances set to ``t`` (base units)."""
        return self.spec.scaled(self.scales(t))

    def tie(self, t) -> np.ndarray:
        """``t[..., m]`` with every tied factor set from its lead (clipped to its own bounds)."""
        t = np.asarray(t, float)
        if not self.ties:
            return t
        return np.clip(t[..., self.lead] * self.ratio, self.lower, self.upper)

    def with_requirements(self, reqs: list[Requirement]) -> "AllocationProblem":
        return replace(self, requirements=reqs)

    def scaled_requirements(self, f: float) -> "AllocationProblem":
        """The same problem with every limit's distance from the nominal output multiplied by ``f``."""
        y0 = nominal_outputs(self.model, self.spec)
        reqs = []
        for r in self.requirements:
            c = y0[r.output]
            sc = lambda v: None if v is None else c + f * (v - c)  # noqa: E731
            reqs.append(replace(r, lower=sc(r.lower), upper=sc(r.upper)))
        return self.with_requirements(reqs)


def nominal_outputs(model: Model, spec: ToleranceSpec, evaluate: Evaluator | None = None) -> dict[str, float]:
    """Outputs (display units) at the spec's nominal point."""
    Y = (evaluate or Evaluator())(model, spec.nominal_base()[None, :], "nominal").Y[0]
    return {q.name: float(q.to_display(Y[j])) for j, q in enumerate(model.outputs)}


def z_of(r: Requirement) -> float:
    """How many output σ must fit between the nominal output and the nearer limit."""
    z = 0.0
    if r.min_cpk is not None:
        z = max(z, 3.0 * r.min_cpk)
    if r.min_yield is not None:
        two = r.lower is not None and r.upper is not None
        p = 1.0 - (1.0 - r.min_yield) / 2.0 if two else r.min_yield
        z = max(z, float(sps.norm.ppf(p))) if p < 1.0 else math.inf
    return z


# --------------------------------------------------------------------------- linearised constraint
@dataclass
class Linearisation:
    """Five-point gradient ``S[j, k]`` (base units) at nominal, for every requirement row j and spec factor k."""

    S: np.ndarray
    y0: np.ndarray  # base units, per requirement
    margin: np.ndarray  # base units: distance from y0 to the nearer limit
    z: np.ndarray
    rho: np.ndarray  # σ_k / t_k per spec factor (shape constant)
    t_spec: np.ndarray  # current ±t of every spec factor (base units)


def linearise(problem: AllocationProblem, evaluate: Evaluator | None = None) -> Linearisation:
    """Five-point derivatives (:func:`rvtol.sensitivity.local.five_point`) of the required outputs."""
    from ..sensitivity.common import model_gradient
    from ..sensitivity.local import five_point

    spec, model = problem.spec, problem.model
    outs = list(dict.fromkeys(r.output for r in problem.requirements))
    x0 = spec.nominal_base()
    G = model_gradient(model, x0)   # the model's exact derivatives when it has them
    if G is None:
        loc = five_point(model, spec, outputs=outs, evaluate=evaluate)
    else:
        Y0 = (evaluate or Evaluator())(model, x0[None], "nominal point").Y[0]
    S, y0, margin, z = [], [], [], []
    for r in problem.requirements:
        q = model.output(r.output)
        if G is None:
            S.append(loc.gradient(r.output, spec.names))
            yd = float(loc.for_output(r.output)["y0"].iloc[0])  # display
        else:
            S.append(G[model.output_index(r.output)])
            yd = float(q.to_display(Y0[model.output_index(r.output)]))
        dists = [v for v in ((r.upper - yd) if r.upper is not None else None,
                             (yd - r.lower) if r.lower is not None else None) if v is not None]
        m = min(dists)
        y0.append(units.convert(yd, q.shown_unit, q.unit))
        margin.append(float(units.convert(m, q.shown_unit, q.unit)))
        z.append(z_of(r))
    t_spec = np.array([units.to_base(f.half_band, f.unit) for f in spec.factors])
    rho = spec.std_base() / t_spec
    # NaN stays NaN: a factor whose five points the model could not evaluate has no gradient (not a zero one)
    return Linearisation(np.array(S), np.array(y0), np.array(margin), np.array(z), rho, t_spec)


class LinearisedConstraint:
    """RSS (``mode="rss"``) or worst-case (``"worst_case"``) constraint from a :class:`Linearisation`."""

    def __init__(self, problem: AllocationProblem, lin: Linearisation, mode: str = "rss"):
        if mode not in ("rss", "worst_case"):
            raise InputError(f"unknown linearised constraint {mode!r} (rss | worst_case)", key="convex")
        self.problem, self.lin, self.mode = problem, lin, mode
        alloc = np.zeros(len(problem.spec), bool)
        alloc[problem.idx] = True
        # factors without a gradient (the model failed on their five points): the requirements that
        # depend on them cannot be linearised; those rows get no budget (infeasible), never S = 0
        missing = np.isnan(lin.S)
        self.unavailable = [problem.spec.names[k] for k in np.flatnonzero(missing.any(axis=0))]
        S = np.where(missing, 0.0, lin.S)
        if mode == "rss":
            self.coef = np.abs(S[:, problem.idx]) * lin.rho[problem.idx]  # per unit t: σ contribution
            fixed = rss(S[:, ~alloc] * lin.rho[~alloc] * lin.t_spec[~alloc], axis=1, squared=True)
            # a nominal output on or outside its limits (margin ≤ 0) leaves no budget: squaring a
            # negative margin would turn it into a positive one
            room = np.where(lin.margin > 0, lin.margin / lin.z, 0.0)
            self.budget = room ** 2 - fixed  # for Σ (coef t)²
        else:
            self.coef = np.abs(S[:, problem.idx])
            self.budget = lin.margin - (np.abs(S[:, ~alloc]) * lin.t_spec[~alloc]).sum(axis=1)  # for Σ coef t
        self.budget = np.where(missing.any(axis=1) | np.isnan(self.budget), -np.inf, self.budget)

    def load(self, T) -> np.ndarray:
        """``[p, j]`` used fraction of each requirement's budget (≤ 1 is feasible)."""
        T = np.atleast_2d(T)
        if self.mode == "rss":
            used = rss(T[:, None, :] * self.coef[None], axis=-1, squared=True)
        else:
            used = (T[:, None, :] * self.coef[None]).sum(-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.budget > 0, used / self.budget, np.inf)

    def violation(self, T) -> np.ndarray:
        L = self.load(T)
        if self.mode == "rss":
            L = np.sqrt(L)
        return np.maximum(L - 1.0, 0.0).sum(axis=1)

    def describe(self) -> str:
        return ("linearised RSS: Σ (S_i σ_i)² ≤ (margin/z)²" if self.mode == "rss"
                else "linearised worst case: Σ |S_i| t_i ≤ margin")

    def binding(self, t=None) -> list[str]:
        """Why the requirements that no allocation (or the tolerances ``t``, base units) can meet fail:
        one sentence each, naming the requirement (empty if every budget holds)."""
        out = []
        load = self.load(np.asarray(t, float))[0] if t is not None else None
        for j, r in enumerate(self.problem.requirements):
            q = self.problem.model.output(r.output)
            y0 = float(q.to_display(self.lin.y0[j]))
            where = f"{r.label} ({r.output})"
            if np.isnan(self.lin.S[j]).any():
                out.append(f"{where}: the model failed on the five points of a factor, no linearisation")
            elif self.lin.margin[j] <= 0:
                out.append(f"{where}: the NOMINAL design gives {y0:.4g} {units.label(q.shown_unit)}, on or outside "
                           "its limits — no tolerance can fix that; the nominal design must change")
            elif self.budget[j] <= 0:
                out.append(f"{where}: the nominal {y0:.4g} {units.label(q.shown_unit)} leaves a margin the factors "
                           "that are not allocated already use up")
            elif load is not None and load[j] > 1.0:
                out.append(f"{where}: {100 * (np.sqrt(load[j]) if self.mode == 'rss' else load[j]):.0f} % of its "
                           "budget at these tolerances")
        return out


def design_levers(problem: AllocationProblem, lin: Linearisation, top: int = 8,
                  reference: dict[int, tuple[float, float]] | None = None) -> dict[str, pd.DataFrame]:
    """For each requirement whose NOMINAL output lies on or outside its limits (no tolerance can fix it),
    the first-order design levers: the mean shift of one factor (or of every copy of a family alike) that
    moves the output to ``limit ∓ z·σ`` — z as the allocation's — ranked by the output change one
    tolerance half-band of shift gives.  The output is measured from ``reference[j] = (mean, σ)`` (base
    units: the study's Monte Carlo mean and standard deviation at the present tolerances) when given —
    an output that is a minimum or maximum over copies (backlash: the tightest of the pin clearances) or a
    clipped clearance is not centred on its nominal value — else from the nominal output with the
    linearised RSS σ.  The slope is the five-point derivative at the nominal: a direction and a size for
    the designer, to be confirmed by a study of the changed design.  Angles (phases) are not levers, nor
    error magnitudes (one-sided distributions: a form or position error's size is what the process
    achieves, not a nominal the designer sets)."""
    spec, out = problem.spec, {}
    sd = spec.std_base()
    for j, r in enumerate(problem.requirements):
        if lin.margin[j] > 0 or np.isnan(lin.S[j]).any():
            continue
        q = problem.model.output(r.output)
        y_ref, sigma = (reference[j] if reference and j in reference
                        else (lin.y0[j], rss(lin.S[j] * sd)))
        lower = units.convert(r.lower, q.shown_unit, q.unit) if r.lower is not None else None
        if lower is not None and (r.upper is None or lin.y0[j] <= lower):     # the limit the nominal misses
            target = lower + lin.z[j] * sigma
        else:
            target = units.convert(r.upper, q.shown_unit, q.unit) - lin.z[j] * sigma
        need = target - y_ref                                      # base units of the output
        levers: dict[str, list] = {}          # lever -> [Σ S over its copies, its first factor]
        for k, f in enumerate(spec.factors):
            if units.dimension(f.unit) == "angle" or f.dist.one_sided or lin.S[j, k] == 0.0:
                continue              # phases, and error magnitudes (Rayleigh, ...: set by the process, not a nominal)
            key = f.family or f.name
            entry = levers.setdefault(key, [0.0, f])
            entry[0] += lin.S[j, k]
        copies = {}
        for f in spec.factors:
            copies[f.family or f.name] = copies.get(f.family or f.name, 0) + 1
        rows = []
        for key, (S, f) in levers.items():
            t = units.to_base(f.half_band, f.unit)
            shift = need / S
            rows.append({"lever (mean shift of)": key, "copies shifted alike": copies[key],
                         "unit": f.unit, "now (mean)": f.dist.mean,
                         f"output change per +t [{q.shown_unit}]": float(q.to_display(S * t)),
                         "shift needed alone": float(units.from_base(shift, f.unit)),
                         "shift needed / t": float(shift / t) if t > 0 else np.nan,
                         "_rank": abs(S * t)})
        frame = pd.DataFrame(rows).sort_values("_rank", ascending=False).drop(columns="_rank").head(top)
        out[r.label] = frame.reset_index(drop=True)
    return out


def shifted_spec(spec, lever: str, shift: float) -> "ToleranceSpec":
    """``spec`` with every factor the lever names (a factor, or every copy of a family) shifted by ``shift``
    (the factor's unit): its distribution and its nominal move, its tolerance band keeps its width."""
    hit = [f.name for f in spec.factors if (f.family or f.name) == lever]
    if not hit:
        raise KeyError(lever)
    return spec.with_factors(
        replace(f, dist=replace(f.dist, shift=f.dist.shift + shift),
                nominal=None if f.nominal is None else f.nominal + shift,
                limits=None if f.limits is None else (f.limits[0] + shift, f.limits[1] + shift))
        if f.name in hit else f for f in spec.factors)


# --------------------------------------------------------------------------- Monte Carlo constraint
class MonteCarloConstraint:
    """Yield / Cpk of the requirements from ``n`` samples with a fixed uniform design (CRN).

    Scaling a factor's tolerance by f maps each sample value affinely about
    the distribution's centre (mean, mode, or the shift of a one-sided
    magnitude): ``x' = c + f (x − c)`` — that is what
    :meth:`rvtol.distributions.Distribution.scaled` does.  The centres are
    measured once through the spine's own ``scaled`` + ``to_factors`` path and
    the affinity is checked there, so candidates are mapped without
    re-freezing scipy distributions (a factor that does not scale affinely
    falls back to the spine path).
    """

    def __init__(self, problem: AllocationProblem, n: int, method: str = "lhs", seed: int | None = None,
                 evaluate: Evaluator | None = None):
        self.problem, self.n, self.method, self.seed = problem, int(n), method, seed
        self.evaluate = evaluate or Evaluator()
        self.U = apply_copula(uniform_design(self.n, len(problem.spec), method, seed), problem.spec.correlation)
        self.X0 = to_factors(problem.spec, self.U)
        self.centre = affine_centres(problem)
        self.evaluations = 0
        # the outputs the requirements judge: only these come back from the workers (the sign-off's model has 44
        # outputs, its allocation judges a few — the rest would cross the process boundary for nothing)
        self.columns = np.array(sorted({problem.model.output_index(r.output) for r in problem.requirements}), int)
        self._seen: dict[bytes, np.ndarray] = {}     # candidate (its tolerances' bytes) -> its judged outputs
        self.keep = max(1, int(2e8 // max(8 * self.n * len(self.columns), 1)))   # ≈ 200 MB of them
        self._chunks: tuple = (None, None, [])         # chunk size, the model and the chunks as Shared (_shared)

    def samples(self, t) -> np.ndarray:
        """The design's factor values (base units) with the allocated tolerances set to ``t``."""
        p = self.problem
        X = self.X0.copy()
        f = np.asarray(t, float) / p.t0
        for c, i in enumerate(p.idx):
            if np.isnan(self.centre[c]):
                X[:, i] = to_factors(p.spec_at(t), self.U)[:, i]
            else:
                X[:, i] = self.centre[c] + f[c] * (self.X0[:, i] - self.centre[c])
        return X

    def outputs(self, T) -> list[np.ndarray]:
        """The judged model outputs (base units; the columns :attr:`columns`) for each candidate of ``T[p, m]``
        (one batch through the executor).

        Where every allocated factor scales affinely, the workers build the candidates' samples themselves
        from chunks of the fixed design (:func:`_candidate_outputs`: the design travels once per batch, not
        once per candidate), and a candidate seen before is not evaluated again (common random numbers: the
        same tolerances give the same samples, so the same outputs)."""
        T = np.atleast_2d(np.asarray(T, float))
        self.evaluations += len(T) * self.n
        if np.isnan(self.centre).any():     # a factor that does not scale affinely: the spine's path, in the parent
            X = np.vstack([self.samples(t) for t in T])
            Y = self.evaluate(self.problem.model, X, "allocation").Y[:, self.columns]
            return [Y[i * self.n:(i + 1) * self.n] for i in range(len(T))]
        keys = [t.tobytes() for t in T]
        todo = list(dict.fromkeys(k for k in keys if k not in self._seen))
        if todo:
            Tn = np.array([np.frombuffer(k) for k in todo]).reshape(len(todo), T.shape[1])
            f = Tn / self.problem.t0
            workers = self.evaluate.workers if isinstance(self.evaluate, Evaluator) else 1
            # one chunk per worker: a batch's chunks cost the same (the same candidates on as many design rows), so
            # more chunks balance nothing and each is one more task to schedule — the RV-80E sign-off's 64 batches
            # of 8 chunks took 14.0 s on 2 pool workers and 18.7 s on a 2-worker LocalCluster, of 2 chunks 13.6
            # and 16.1 s (wall time inside the calls)
            cs = auto_chunk_size(self.n, workers, per_worker=1)
            model, chunks = self._shared(cs) if workers > 1 else (self.problem.model, [self.X0])
            tasks = [(model, X0, f, np.asarray(self.problem.idx), self.centre, self.columns) for X0 in chunks]
            mapper = self.evaluate.map if isinstance(self.evaluate, Evaluator) else map_chunks
            Y = np.concatenate(mapper(_candidate_outputs, tasks), axis=1)
            if len(self._seen) + len(todo) > self.keep:
                self._seen.clear()
            self._seen.update(zip(todo, Y))
        return [self._seen[k] for k in keys]

    def _shared(self, cs: int) -> tuple:
        """The model and the design's chunks of ``cs`` rows as :class:`rvtol.executors.Shared`: every batch passes
        them unchanged, so the workers receive them once (the RV-80E sign-off's 64 batches each sent its two 3.6 MB
        chunks and the model: about 20 ms a batch on two pool workers).  Kept for the constraint's life: a copy of
        the design and its pickle (2 × 3.6 MB per chunk for the sign-off), and as much on each worker."""
        if self._chunks[0] != cs:
            self._chunks = (cs, Shared(self.problem.model),
                            [Shared(self.X0[a:a + cs]) for a in range(0, self.n, cs)])
        return self._chunks[1], self._chunks[2]

    def measures(self, T) -> list[list[dict]]:
        """Per candidate, per requirement: yield and Cpk (estimates and lower confidence bounds).

        Only what a requirement asks for is computed; the bounds are the sign-off's
        (:func:`rvtol.verdict.yield_bound`, :func:`rvtol.verdict.cpk_bound`: the
        requirement's interval, one- or two-sided).
        """
        m = self.problem.model
        out = []
        where = {int(c): k for k, c in enumerate(self.columns)}     # model output index -> column of outputs()
        for Y in self.outputs(T):
            rows = []
            for r in self.problem.requirements:
                j = m.output_index(r.output)
                y = m.outputs[j].to_display(Y[:, where[j]])
                ok = np.isfinite(y)
                row = {}
                if r.min_yield is not None:
                    inside = ok.copy()
                    if r.lower is not None:
                        inside &= np.nan_to_num(y, nan=-np.inf) >= r.lower
                    if r.upper is not None:
                        inside &= np.nan_to_num(y, nan=np.inf) <= r.upper
                    k, n = int(inside.sum()), len(y)
                    row["yield"] = k / n
                    row["yield_lo"] = yield_bound(r, k, n)
                if r.min_cpk is not None:
                    good = y[ok]
                    cap = st.capability(good, r.lower, r.upper, r.confidence) if ok.sum() > 2 else {}
                    pci = (st.bootstrap_ci(good, lambda v: st.percentile_cpk(v, r.lower, r.upper),
                                           percentile_cpk_confidence(r))
                           if r.cpk_method == "percentile" and len(good) >= 100 else (None, None))
                    row["cpk"], row["cpk_lo"] = cpk_figures(r, cap, int(ok.sum()), pci)
                    if cap.get("cpk") is not None:       # the sign-off's non-normal rule (rvtol.verdict.judge)
                        row["shape"], row["other_cpk"] = other_cpk(r, good, cap, (row["cpk"], row["cpk_lo"]))
                row["n_failed"] = int((~ok).sum())
                rows.append(row)
            out.append(rows)
        return out

    def violation(self, T) -> np.ndarray:
        res = []
        for rows in self.measures(T):
            v = 0.0
            for r, mrow in zip(self.problem.requirements, rows):
                v += judge(r, yield_=mrow.get("yield"), yield_lo=mrow.get("yield_lo"), cpk=mrow.get("cpk"),
                           cpk_lo=mrow.get("cpk_lo"), n_failed=mrow["n_failed"], shape=mrow.get("shape"),
                           other_cpk=mrow.get("other_cpk")).violation
            res.append(v)
        return np.array(res)

    def describe(self) -> str:
        return f"Monte Carlo ({self.method}, n = {self.n}, fixed design: common random numbers)"


def _candidate_outputs(model: Model, X0: np.ndarray, f: np.ndarray, idx: np.ndarray, centre: np.ndarray,
                       columns: np.ndarray) -> np.ndarray:
    """``Y[candidate, row, output]`` (base units, NaN where the model failed; the outputs ``columns``) of the design
    rows ``X0`` with each allocated factor ``idx[c]`` scaled by ``f[candidate, c]`` about its centre (as
    :meth:`MonteCarloConstraint.samples`): one task of :meth:`MonteCarloConstraint.outputs`."""
    blocks = []
    for fc in f:
        X = X0.copy()
        for c, i in enumerate(idx):
            X[:, i] = centre[c] + fc[c] * (X0[:, i] - centre[c])
        blocks.append(X)
    Y = evaluate(model, np.vstack(blocks), progress=False).Y[:, columns]
    return Y.reshape(len(f), len(X0), -1)


def affine_centres(problem: AllocationProblem) -> np.ndarray:
    """Per allocated factor, the centre c with ``scaled(f) values = c + f·(values − c)`` (NaN if not affine)."""
    u = np.array([[0.05], [0.3], [0.5], [0.8], [0.97]])
    out = []
    for i in problem.idx:
        f = problem.spec.factors[i]
        x1 = f.ppf_base(u[:, 0])
        x2 = f.scaled(2.0).ppf_base(u[:, 0])
        x3 = f.scaled(0.5).ppf_base(u[:, 0])
        c = 2.0 * x1 - x2
        scale = max(float(np.max(np.abs(x1))), 1e-300)
        ok = np.allclose(c, c[0], rtol=0, atol=1e-12 * scale) and np.allclose(c[0] + 0.5 * (x1 - c[0]), x3, rtol=1e-12,
                                                                              atol=1e-12 * scale)
        out.append(float(c[0]) if ok else np.nan)
    return np.array(out)


def requirements_frame(reqs: Sequence[Requirement]) -> pd.DataFrame:
    """One row per distinct limit set; outputs sharing the same limits are listed together."""
    groups: dict[tuple, list[str]] = {}
    for r in reqs:
        groups.setdefault((r.lower, r.upper, r.unit, r.min_yield, r.min_cpk, r.basis), []).append(r.output)
    return pd.DataFrame([{"outputs": ", ".join(names), "lower": k[0], "upper": k[1], "unit": k[2],
                          "min yield": k[3], "min Cpk": k[4], "basis": k[5]} for k, names in groups.items()])
