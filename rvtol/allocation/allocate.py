"""The allocation a study asks for: the problem from its keys, every optimiser, the checks — one result.

:func:`allocation_problem` builds the :class:`~rvtol.allocation.problem.AllocationProblem` a study's
``[[analysis]] kind = "allocation"`` describes (which factors, their cost curves, which requirements);
:func:`allocate` runs what the :class:`Plan` asks for and returns an :class:`Allocation`:

* a requirement the NOMINAL design misses cannot be met by any tolerance: it is set aside (with its
  design levers, :func:`rvtol.allocation.problem.design_levers`, the top one checked by a Monte Carlo
  run of the shifted design) and the tolerances are allocated against the others;
* a requirement whose first-order spread at the nominal differs from the study's Monte Carlo spread
  by more than a factor of 2 (a magnitude such as a tilt or a radial offset, a max − min: zero or
  undefined derivative at the nominal) makes the linearised methods unavailable — the Monte Carlo
  constraint (GA, uniform scale) remains;
* the uniform baseline, the convex optimum of the linearised problem, the GA; every allocation checked
  by an independent Monte Carlo run (its own seed stream), the cheapest verified one optionally
  against every requirement of the study; the minimum cost against the requirement scale (Pareto).

A composed model is evaluated only as far as the allocation's requirements need
(:meth:`CompositeModel.restricted`: a GA over stack-up requirements does not run the 20-DOF stages).
Seeds come from the study seed through separate streams (GA design, GA operators, verification,
levers), so the result is reproducible and the check independent of the optimisation.
"""
from __future__ import annotations

import fnmatch
import math
from dataclasses import dataclass, field, replace
from typing import Callable, Sequence

import numpy as np
import pandas as pd

from .. import units
from ..mc import run_monte_carlo
from ..model import dependencies
from ..records import frame_records
from ..sampling import substream_seed
from ..stats import rss
from ..verdict import yield_bound
from .baseline import uniform_baseline, verify
from .convex import solve_convex
from .cost import CostTable
from .ga import GASettings, solve_ga
from .problem import (AllocationProblem, LinearisedConstraint, MonteCarloConstraint, design_levers,
                      expand_requirements, linearise, requirements_frame, shifted_spec)
from .results import AllocationResult, ParetoCurve, Verification, component_axis_table


# --------------------------------------------------------------------------- the problem from a study's keys
def matching_factors(spec, key: str) -> list[str]:
    """The spec's factors a ``factors`` entry or an ``assign`` key names: a factor name, a family template
    (``pins[k].diameter_in_lot``: all its copies) or a shell pattern (``crank_*.cam_*.position.*``; ``[``
    opens a character class, so a pattern over per-pin names writes ``[[]`` for a literal bracket)."""
    if key in spec.names:
        return [key]
    fam = [f.name for f in spec.factors if f.family == key]
    if fam:
        return fam
    return [n for n in spec.names if fnmatch.fnmatchcase(n, key)]


def assign_curves(spec, names: list[str], assign: dict[str, str], table: CostTable, error: Callable) -> list:
    """The cost curve of each allocated factor: by factor name, family or pattern (the first key in the
    table's order that matches), then group, then ``"*"``.  ``error(key, reason)``: the located error of a
    key of the ``assign`` table (``None``: the table)."""
    keys = list(assign)
    groups = {f.group for f in spec.factors}
    matched = {k: set(matching_factors(spec, k)) for k in keys if k != "*" and k not in groups}
    curves = []
    for n in names:
        g = spec.factor(n).group
        k = next((k for k in matched if n in matched[k]), None) or (g if g in keys else ("*" if "*" in keys else None))
        if k is None:
            raise error(None, f"no cost curve for factor {n!r} (group {g!r}); add it or a \"*\" entry")
        cname = assign[k]
        if cname not in table.curves:
            raise error(k, f"unknown cost curve {cname!r} (known: {', '.join(table.curves)})")
        curves.append(table.curves[cname])
    for k in keys:
        if k != "*" and k not in groups and not matched[k]:
            raise error(k, f"{k!r} is neither a factor, a family, a pattern of factor names nor a group of the spec")
    return curves


def allocated_factors(spec, factors: list[str] | None, groups: list[str] | None, error: Callable) -> list[str]:
    """The factors ``factors`` (names, family templates, shell patterns) or ``groups`` name (default: every
    factor of the spec); ``error(key, reason)``: the located error of the ``factors`` or ``groups`` key."""
    if factors is not None:
        names = []
        for key in factors:
            found = matching_factors(spec, key)
            if not found:
                raise error("factors", f"{key!r} names no factor of the spec (a name, a family template with [k] "
                                       "or a shell pattern)")
            names += [n for n in found if n not in names]
        return names
    if groups is not None:
        known = {f.group for f in spec.factors}
        for g in groups:
            if g not in known:
                raise error("groups", f"unknown group {g!r} (spec groups: {', '.join(sorted(known))})")
        return [f.name for f in spec.factors if f.group in groups]
    return list(spec.names)


def allocation_problem(model, spec, names: list[str] | None, requirements, outputs: list[str] | None,
                       assign: dict[str, str], table: CostTable, tie: str, error: Callable) -> AllocationProblem:
    """The problem of allocating ``names`` (None: every factor a required output depends on) against
    ``requirements`` (output patterns expanded; only those on ``outputs`` patterns when given), with the cost
    curves ``assign`` names; ``tie = "drawing"`` ties the factors of one drawing callout."""
    reqs = expand_requirements(requirements, model)
    if outputs is not None:
        reqs = [r for r in reqs if any(fnmatch.fnmatchcase(r.output, pat) for pat in outputs)]
        if not reqs:
            raise error("outputs", f"no requirement is on an output matching {outputs}")
    central = [r for r in reqs if not r.per_unit]
    if central:
        raise error("outputs", f"{central[0].label!r} judges the {central[0].statistic} of its output: a central value "
                               "is the nominal design's, which tolerances do not move — allocate for the per-unit "
                               "requirements only (outputs = [...] without it; verify.all_requirements still checks it)")
    if names is None:
        deps = dependencies(model)
        if deps is None:
            raise error("factors", "\"dependencies\" needs a model that declares what each output depends on (a "
                                   "composed or linear model); list the factors")
        need = set().union(*(deps.get(r.output, set()) for r in reqs))
        names = [n for n in spec.names if n in need]
        if not names:
            raise error("factors", "the requirements' outputs depend on no factor of the spec")
    curves = assign_curves(spec, names, assign, table, lambda k, why: error("assign" if k is None else f"assign.{k}",
                                                                            why))
    return AllocationProblem(model, spec, names, curves, reqs, drawing_ties(spec, names) if tie == "drawing" else ())


def drawing_ties(spec, names: list[str]) -> tuple[tuple[str, ...], ...]:
    """The allocated factors that stand for one drawing tolerance (:func:`rvtol.callouts.callout_of`:
    the coordinates of one position zone, the copies of a per-part family), as groups to tie: a drawing
    gives one ±t per callout, not one per coordinate or per pin."""
    from ..callouts import callout_of

    groups: dict[str, list[str]] = {}
    for n in names:
        groups.setdefault(callout_of(spec.factor(n)), []).append(n)
    return tuple(tuple(g) for g in groups.values() if len(g) > 1)


def zero_failure_n(r) -> int | None:
    """The fewest samples whose yield bound (the requirement's own interval and level) reaches ``r.min_yield``
    with no failing sample (the success-run size; 1109 for 0.9973 at 95 %); None when the requirement does
    not judge a yield on a bound."""
    if r.min_yield is None or r.basis != "lower_bound":
        return None
    if yield_bound(r, 1 << 40, 1 << 40) < r.min_yield:
        return None
    lo, hi = 1, 1
    while yield_bound(r, hi, hi) < r.min_yield:
        lo, hi = hi, 2 * hi
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if yield_bound(r, mid, mid) < r.min_yield else (lo, mid)
    return hi


def evaluated_problem(p: AllocationProblem) -> AllocationProblem:
    """``p`` with its model evaluated only as far as its requirements need (a composed model restricted to
    their outputs: a GA over stack-up requirements does not run the 20-DOF stages)."""
    if not hasattr(p.model, "restricted"):
        return p
    outs = list(dict.fromkeys(r.output for r in p.requirements))
    return replace(p, model=p.model.restricted(outs))


# --------------------------------------------------------------------------- what to run
@dataclass(frozen=True)
class Plan:
    """What :func:`allocate` runs: ``convex`` (rss | worst_case | none), the GA's constraint (monte_carlo |
    linearised | none), its design (``ga_n`` samples by ``ga_method``), whether it confirms its winner on a
    second design, its settings; the independent check's ``verify_n`` and whether the cheapest verified
    allocation is also checked against every study requirement (``verify_all``, ``verify_all_n`` samples,
    0: the study's n); the Pareto scales and whether the GA runs at each."""

    convex: str = "rss"
    ga_constraint: str = "monte_carlo"
    ga_n: int = 2000
    ga_method: str = "lhs"
    ga_confirm: bool = False
    ga: GASettings = field(default_factory=lambda: GASettings(seed=0))
    verify_n: int = 20000
    verify_all: bool = False
    verify_all_n: int = 0
    pareto_scales: tuple[float, ...] = (0.5, 0.75, 1.0, 1.5, 2.0)
    pareto_ga: bool = False

    @property
    def linearised_mode(self) -> str:
        return "rss" if self.convex == "none" else self.convex


# --------------------------------------------------------------------------- the result
@dataclass
class AllCheck:
    """The cheapest verified allocation against every requirement of the study (None frame: none verified)."""

    method: str | None = None
    n: int = 0
    frame: pd.DataFrame | None = None
    lowered: list[str] = field(default_factory=list)
    labels: list[str] = field(default_factory=list)     # the requirement of each row of ``frame``


@dataclass
class Levers:
    """Where the requirements the nominal misses stand, their design levers and the top ones checked."""

    measured_from_mc: bool
    stand: pd.DataFrame
    levers: dict[str, pd.DataFrame]
    checked: pd.DataFrame
    describe: str


@dataclass
class Allocation:
    """An allocation study's outcome: the problem allocated (``problem``; ``full``: with the set-aside
    requirements), each method's result, their independent checks, the Pareto curve, the linearised
    spread beside the Monte Carlo, the check against every requirement and the design levers."""

    problem: AllocationProblem
    full: AllocationProblem
    model_label: str
    costs: CostTable
    plan: Plan
    results: list[AllocationResult]
    checks: dict[str, Verification]
    pareto: ParetoCurve | None
    linearised: str                         # the linearised constraint, described
    constraint: str                         # the uniform baseline's constraint, described
    ga_constraint: str | None               # the GA's constraint, described (None: no GA)
    set_aside: list = field(default_factory=list)
    spread: pd.DataFrame | None = None
    all_check: AllCheck | None = None
    levers: Levers | None = None

    @property
    def by_method(self) -> dict[str, AllocationResult]:
        return {r.method: r for r in self.results}

    @property
    def cost_unit(self) -> str:
        return self.costs.cost_unit

    @property
    def curves(self) -> list:
        """The cost curves the allocated factors use (each once)."""
        return list({c.name: c for c in self.problem.curves}.values())

    def curves_frame(self) -> pd.DataFrame:
        rows = []
        u = self.cost_unit
        for c in self.curves:
            rows.append({"curve": c.name, "kind": c.kind, f"C(t) [{u}], t in {c.unit}": c.formula(),
                         "points": len(c.fit.tolerance) if c.fit else 0,
                         "fitted": "a, b" + ("" if c.fit and c.fit.fixed_c else ", c") if c.fit else "given",
                         f"RMSE [{u}]": c.fit.rmse if c.fit else math.nan,
                         "R²": c.fit.r2 if c.fit else math.nan, "t_min": c.t_min, "t_max": c.t_max})
        return pd.DataFrame(rows)

    def to_frame(self) -> pd.DataFrame:
        """Allocated tolerances ±t per factor, one column per method (factor units)."""
        frame = self.results[0].to_frame().drop(columns=["t uniform (±)"])
        for r in self.results:
            frame[f"t {r.method} (±)"] = r.display_t() if r.t is not None else np.nan
        return frame.drop(columns=["cost"])

    def methods_frame(self) -> pd.DataFrame:
        """Total cost of each method against the uniform baseline and its independent check."""
        base = self.results[0].total_cost
        return pd.DataFrame([{"method": r.method, "status": r.status, "constraint": r.constraint,
                              f"total cost [{self.cost_unit}]": r.total_cost,
                              "vs uniform [%]": 100.0 * (r.total_cost / base - 1.0) if r.t is not None else np.nan,
                              "independent MC": ("pass" if self.checks[r.method].passed else "FAIL")
                              if r.method in self.checks else "n/a"} for r in self.results])

    def component_axis(self) -> pd.DataFrame | None:
        best = self.results[-1]
        return component_axis_table(best) if best.t is not None else None

    def requirements_frame(self) -> pd.DataFrame:
        return requirements_frame(self.problem.requirements)

    def checks_frame(self) -> pd.DataFrame:
        return pd.DataFrame([v.summary_row() for v in self.checks.values()])

    @property
    def failed_checks(self) -> list[str]:
        return [m for m, v in self.checks.items() if not v.passed]

    def plot(self, which: str = "tolerances"):
        """``tolerances`` (against the uniform baseline), ``ga`` (its convergence), ``costs`` (the curves)."""
        from ..plotting.allocation import cost_curves, ga_history, tolerance_bars

        if which == "costs":
            return cost_curves(self.curves, self.cost_unit)
        if which == "ga":
            return ga_history(self.by_method["GA"], self.by_method.get(f"convex {self.plan.linearised_mode}"))
        return tolerance_bars([r for r in self.results if r.t is not None])

    def fixes(self, key: str) -> list:
        """Checked ways to pass the study's requirements (:class:`rvtol.signoff.Fix`, for the first page): the
        cheapest verified allocation where its independent Monte Carlo on the study's model demonstrates a
        requirement ("tighten"), and each design lever whose shifted design a Monte Carlo run passed
        ("redesign")."""
        from ..signoff import Fix

        out = []
        a = self.all_check
        if a is not None and a.frame is not None:
            r = self.by_method.get(a.method)
            cost = f" (total cost {r.total_cost:.4g} {self.cost_unit})" if r is not None and r.t is not None else ""
            for label, row in zip(a.labels, a.frame.to_dict("records")):
                if row["passed"]:
                    out.append(Fix(label, "tighten", f"the {a.method} allocation's tolerances{cost}",
                                   f"yield {row['yield']:.5f} (bound {row['yield_lo']:.5f}) in an independent "
                                   f"Monte Carlo run of the study's model (n = {a.n})", key, checked=True))
        if self.levers is not None:
            for row in self.levers.checked.to_dict("records"):
                if row["passed"]:
                    out.append(Fix(row["requirement"], "redesign",
                                   f"shift the nominal of {row['lever']} by {row['shift']:+.4g} {row['unit']}",
                                   f"yield {row['yield after']:.5f} (bound {row['yield bound']:.5f}) in a Monte "
                                   f"Carlo run of the shifted design (n = {row['n']})", key, checked=True))
        return out

    def costs_summary(self) -> dict:
        return {"curves": frame_records(self.curves_frame())}

    def summary(self) -> dict:
        p = self.problem
        out = {"factors": p.factors, "ties": [list(g) for g in p.ties], "methods": frame_records(self.methods_frame()),
               "tolerances": frame_records(self.to_frame()),
               "verification": {m: frame_records(v.to_frame()) for m, v in self.checks.items()},
               "pareto": frame_records(self.pareto.to_frame()) if self.pareto is not None else []}
        if self.all_check is not None and self.all_check.frame is not None:
            a = self.all_check
            out["all_requirements"] = {"method": a.method, "n": a.n, "rows": frame_records(a.frame),
                                       "lowered": a.lowered}
        if self.set_aside:
            out["set_aside"] = [r.label for r in self.set_aside]
        if self.levers is not None:
            out["design_levers"] = {label: frame_records(f) for label, f in self.levers.levers.items()}
            out["design_levers_checked"] = frame_records(self.levers.checked)
        return out


# --------------------------------------------------------------------------- the computation
def allocate(full: AllocationProblem, plan: Plan, costs: CostTable, evaluate, executor, seed, mc=None,
             study_problem: AllocationProblem | None = None) -> Allocation:
    """Allocate the tolerances of ``full`` by what ``plan`` asks for (module docstring).  ``mc``: the study's
    Monte Carlo result, ``study_problem``: the same allocation with every requirement of the study, when the
    allocation runs on the study's own model and spec (the linearised spread, the check against every
    requirement and the levers are measured against it)."""
    on_study = study_problem is not None and mc is not None
    lin_full = linearise(full, evaluate)
    missed = [r for j, r in enumerate(full.requirements) if lin_full.margin[j] <= 0]
    kept = [r for r in full.requirements if r not in missed]
    p = full.with_requirements(kept) if missed and kept else full
    lin = linearise(p, evaluate) if p is not full else lin_full     # the same rows: the study's cache answers
    lin_con = LinearisedConstraint(p, lin, plan.linearised_mode)
    spread = linear_spread(p, lin, mc) if on_study else None
    unfit = [] if spread is None else [r for r, ratio in zip(p.requirements, spread["first order / MC"])
                                       if not 0.5 <= ratio <= 2.0]
    pe = evaluated_problem(p)
    ga_con = None
    if plan.ga_constraint == "monte_carlo":
        ga_con = MonteCarloConstraint(pe, plan.ga_n, plan.ga_method, substream_seed(seed, "allocation_ga_design"),
                                      evaluate)
    elif plan.ga_constraint == "linearised" and not unfit:
        ga_con = lin_con
    why = ("not linearisable at the nominal: " + "; ".join(f"{r.label} ({r.output})" for r in unfit)) if unfit else ""
    results: list[AllocationResult] = []
    if ga_con is not None or not unfit:
        results.append(uniform_baseline(pe if ga_con is not None and ga_con is not lin_con else p, ga_con or lin_con))
    else:
        results.append(AllocationResult("uniform", p, None, "not linearisable", False, lin_con.describe(), notes=[why]))
    if plan.convex != "none":
        results.append(solve_convex(p, lin_con) if not unfit else AllocationResult(
            f"convex {lin_con.mode}", p, None, "not linearisable", False, lin_con.describe(), notes=[why]))
    if ga_con is not None:
        settings = replace(plan.ga, seed=substream_seed(seed, "allocation_ga"))
        seed_t = results[0].t if results[0].feasible and results[0].t is not None else None   # uniform seeds the GA
        confirm = (MonteCarloConstraint(pe, plan.ga_n, plan.ga_method, substream_seed(seed, "allocation_ga_confirm"),
                                        evaluate) if plan.ga_confirm else None)
        results.append(solve_ga(pe if ga_con is not lin_con else p, ga_con, settings, initial=seed_t, confirm=confirm))
    vseed = substream_seed(seed, "allocation_verify")
    checks = {r.method: verify(replace(r, problem=pe), plan.verify_n, vseed, executor) for r in results if r.feasible}
    pareto = pareto_curve(p, lin, ga_con, plan, costs.cost_unit, seed) if not unfit else None
    out = Allocation(p, full, type(full.model).__name__, costs, plan, results, checks, pareto, lin_con.describe(),
                     (ga_con or lin_con).describe(), ga_con.describe() if ga_con is not None else None,
                     missed if p is not full else [], spread)
    if plan.verify_all:
        out.all_check = check_all([r for r in results if r.feasible and r.t is not None], checks, study_problem,
                                  plan, mc, executor, seed)
    out.levers = levers(full, lin_full, LinearisedConstraint(full, lin_full, lin_con.mode),
                        study_reference(full, mc) if on_study else {}, mc, plan, executor, seed)
    return out


def study_reference(full: AllocationProblem, mc) -> dict[int, tuple[float, float]]:
    """Each requirement's Monte Carlo mean and standard deviation at the spec's tolerances (base units of
    the output), from the study's own run."""
    out = {}
    for j, r in enumerate(full.requirements):
        q = full.model.output(r.output)
        y = mc.column(r.output)
        out[j] = (units.convert(float(np.nanmean(y)), q.shown_unit, q.unit),
                  units.convert(float(np.nanstd(y, ddof=1)), q.shown_unit, q.unit))
    return out


def linear_spread(p: AllocationProblem, lin, mc) -> pd.DataFrame:
    """Each requirement's first-order standard deviation at the nominal, √Σ (S_k σ_k)² at the spec's
    tolerances, against the study's Monte Carlo standard deviation of that output."""
    sd = p.spec.std_base()
    rows = []
    for j, r in enumerate(p.requirements):
        q = p.model.output(r.output)
        lin_sd = float(q.to_display(rss(lin.S[j] * sd, skip_nan=True)))
        mc_sd = float(np.nanstd(mc.column(r.output), ddof=1))
        rows.append({"requirement": r.label, "output": r.output, "unit": q.shown_unit,
                     "first-order σ": lin_sd, "Monte Carlo σ": mc_sd,
                     "first order / MC": lin_sd / mc_sd if mc_sd > 0 else (1.0 if lin_sd == 0 else np.inf)})
    return pd.DataFrame(rows)


def pareto_curve(p: AllocationProblem, lin, ga_con, plan: Plan, cost_unit: str, seed) -> ParetoCurve:
    """The minimum cost of each method against the requirement limits × f about the nominal output."""
    rows = []
    for f in plan.pareto_scales:
        lf = replace(lin, margin=lin.margin * f)
        con = LinearisedConstraint(p.scaled_requirements(f), lf, plan.linearised_mode)
        pf = con.problem
        row = {"requirement scale [1]": f}
        row["uniform (linearised)"] = _cost(uniform_baseline(pf, con))
        if plan.convex != "none":
            row[f"convex {con.mode}"] = _cost(solve_convex(pf, con))
        if plan.pareto_ga and ga_con is not None:
            gc = (MonteCarloConstraint(pf, plan.ga_n, plan.ga_method, ga_con.seed, ga_con.evaluate)
                  if isinstance(ga_con, MonteCarloConstraint) else con)
            settings = replace(plan.ga, seed=substream_seed(seed, "allocation_ga"))
            row["GA (Monte Carlo)" if isinstance(gc, MonteCarloConstraint) else "GA (linearised)"] = _cost(
                solve_ga(pf, gc, settings))
        rows.append(row)
    return ParetoCurve(pd.DataFrame(rows), cost_unit)


def check_all(results: list[AllocationResult], checks: dict[str, Verification], study_problem, plan: Plan, mc,
              executor, seed) -> AllCheck:
    """The cheapest allocation that passed its own independent check, against every requirement of the study
    on the study's model — beside each requirement's yield at the spec's present tolerances (the study's Monte
    Carlo), so what the allocation costs the requirements it did not optimise for shows."""
    verified = [r for r in results if r.method in checks and checks[r.method].passed]
    if not verified:
        return AllCheck()
    best = min(verified, key=lambda r: r.total_cost)
    n = plan.verify_all_n or (mc.n if mc is not None else plan.verify_n)
    v = verify(replace(best, problem=study_problem), n, substream_seed(seed, "allocation_verify"), executor)
    frame = v.to_frame().copy()
    worse = []
    if mc is not None:
        now = {d["output"]: d["yield"] for d in (x.to_dict() for x in mc.verdicts())}
        frame.insert(frame.columns.get_loc("yield"), "yield at the spec", [now.get(o, np.nan) for o in frame["output"]])
        worse = [f"{o} {a:.3f} → {b:.3f}" for o, a, b in zip(frame["output"], frame["yield at the spec"], frame["yield"])
                 if np.isfinite(a) and b < a - 2.0 * np.sqrt(max(a * (1 - a), 1e-12) * (1 / v.n + 1 / mc.n))]
    return AllCheck(best.method, v.n, frame, worse, [r.label for r in study_problem.requirements])


def levers(full: AllocationProblem, lin_full, lin_con: LinearisedConstraint, ref: dict, mc, plan: Plan, executor,
           seed) -> Levers | None:
    """What the nominal design must change where no tolerance can meet a requirement: where each such
    requirement stands (nominal, Monte Carlo mean and σ), its first-order levers, and the top lever checked
    by a Monte Carlo run of the shifted design (None: every requirement's nominal lies inside its limits)."""
    found = design_levers(full, lin_full, reference=ref)
    if not found:
        return None
    stand, checks = [], []
    for j, r in enumerate(full.requirements):
        if r.label not in found:
            continue
        q = full.model.output(r.output)
        row = {"requirement": r.label, "output": r.output, "unit": q.shown_unit,
               "nominal": float(q.to_display(lin_full.y0[j]))}
        if j in ref:
            row["Monte Carlo mean"] = float(q.to_display(ref[j][0]))
            row["Monte Carlo σ"] = float(q.to_display(ref[j][1]))
        stand.append(row)
        checks.append(check_lever(full, r, found[r.label].iloc[0], mc, plan, executor, seed))
    return Levers(bool(ref), pd.DataFrame(stand), found, pd.DataFrame(checks), lin_con.describe())


def check_lever(full: AllocationProblem, r, top, mc, plan: Plan, executor, seed) -> dict:
    """One Monte Carlo run of the spec with the lever's nominal shifted by its 'shift needed alone'."""
    p1 = evaluated_problem(full.with_requirements([r]))
    n = mc.n if mc is not None else plan.verify_n
    spec = shifted_spec(p1.spec, top["lever (mean shift of)"], float(top["shift needed alone"]))
    res = run_monte_carlo(p1.model, spec, n, "random", substream_seed(seed, "allocation_levers"), p1.requirements,
                          executor, progress=False)
    d = res.verdicts()[0].to_dict()
    y = res.column(r.output)
    return {"requirement": r.label, "lever": top["lever (mean shift of)"], "shift": float(top["shift needed alone"]),
            "unit": top["unit"], "n": n, "mean after": float(np.nanmean(y)), "σ after": float(np.nanstd(y, ddof=1)),
            "yield after": d["yield"], "yield bound": d["yield_bound"], "passed": d["passed"]}


def _cost(r: AllocationResult) -> float:
    return r.total_cost if r.t is not None and r.feasible else math.nan


def check_requirements_demonstrable(reqs: Sequence, n: int, error: Callable) -> None:
    """A Monte Carlo constraint of ``n`` samples must be able to demonstrate every requirement's yield with no
    failing sample; ``error(reason)``: the located error of the sample count."""
    for r in reqs:
        need = zero_failure_n(r)
        if need is not None and n < need:
            raise error(f"n = {n} cannot demonstrate {r.label} even with no failing sample (the {r.label!r} "
                        f"judges yield ≥ {r.min_yield:g} on its lower confidence bound): use n ≥ {need}")

