"""Study analysis ``allocation``: cost-optimal tolerances that still meet the requirements.

::

    [[analysis]]
    kind = "allocation"
    title = "..."                          # optional
    key = "allocation"                     # optional: section key (summary.json analyses.<key>)
    costs = "../data/costs/bx40e_angular.toml"
    assign = { "*" = "ground_axis" }       # factor name, family, pattern, or group, or "*" -> cost curve
    groups = ["Crankshaft 1", "..."]       # optional: allocate these groups' factors
    factors = ["..."]                      # optional: or these factors (default: every factor): names,
                                           # family templates ("pins[k].diameter_in_lot") or shell
                                           # patterns ("crank_*.cam_*.position.*"); or "dependencies":
                                           # every factor a required output depends on (composed models)
    spec = "../data/specs/x.toml"          # optional: another spec than the study's
    convex = "rss"                         # rss | worst_case | none: the linearised global optimum
    tie = "none"                           # none | drawing: one ±t per drawing tolerance (the coordinates
                                           # of a position zone, the copies of a per-pin family tied)
    [analysis.model]                       # optional: another model than the study's ([model] format)
    kind = "adjusted_assembly"
    outputs = ["stackup.*"]                # optional: only the requirements on these outputs (patterns)
    [[analysis.requirement]]               # optional: else the study's requirements
    output = "delta_*"                     # a pattern expands to every matching output
    lower = -1.0
    upper = 1.0
    unit = "arcmin"
    min_cpk = 1.0
    [analysis.ga]                          # the general optimiser (pygad)
    constraint = "monte_carlo"             # monte_carlo | linearised | none (no GA)
    n = 2000                               # Monte Carlo samples per candidate (fixed design)
    method = "lhs"
    handling = "feasibility"               # feasibility | penalty
    confirm = false                        # the cheapest candidate that ALSO meets the requirements on a
                                           # second, fresh design (the fixed design flatters its own winner)
    population = 40
    generations = 150
    [analysis.verify]
    n = 20000                              # independent Monte Carlo check of each allocation
    all_requirements = false               # also check the cheapest verified allocation against EVERY study
                                           # requirement on the study's model (what the allocation left out)
    all_requirements_n = 0                 # its sample count (0: the study's n; the whole model is expensive)
    [analysis.pareto]
    scales = [0.5, 0.75, 1.0, 1.5, 2.0]    # requirement limits × f about the nominal output
    ga = false                             # also run the GA at each scale (expensive)

Seeds come from the study seed through separate streams (GA design, GA
operators, verification), so the analysis is reproducible and the check is
independent of the optimisation.

A composed model is evaluated only as far as the allocation's requirements need
(:meth:`CompositeModel.restricted`: a GA over stack-up requirements does not run the 20-DOF stages).
Two checks keep the linearised methods honest: a requirement the NOMINAL design misses is set aside
with its design levers (no tolerance can meet it), and a requirement whose first-order spread at
the nominal differs from the study's Monte Carlo spread by more than a factor of 2 (a magnitude such
as a tilt or a radial offset, a max − min: zero or undefined derivative at the nominal) makes the
linearised methods unavailable — the Monte Carlo constraint (GA, uniform scale) remains.
"""
from __future__ import annotations

import fnmatch
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from .. import units
from ..analysis import Analysis
from ..errors import InputError
from ..mc import run_monte_carlo
from ..model import dependencies
from ..params import Params
from ..registry import model_factory
from ..report.sections import Section, frame_records
from ..sampling import METHODS, substream_seed
from ..spec import load_spec, requirements_from_tables
from ..verdict import yield_bound
from .baseline import uniform_baseline, verify
from .convex import solve_convex
from .cost import CostTable, load_costs
from .ga import HANDLING, GASettings, solve_ga
from .problem import (AllocationProblem, LinearisedConstraint, MonteCarloConstraint, design_levers, shifted_spec,
                      expand_requirements, linearise, requirements_frame)
from .results import AllocationResult, ParetoCurve, component_axis_table



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


def assign_curves(spec, names: list[str], assign: Params, table: CostTable) -> list:
    """The cost curve of each allocated factor: by factor name, family or pattern (the first key in the
    table's order that matches), then group, then ``"*"``."""
    keys = list(assign.keys())
    groups = {f.group for f in spec.factors}
    matched = {k: set(matching_factors(spec, k)) for k in keys if k != "*" and k not in groups}
    curves = []
    for n in names:
        g = spec.factor(n).group
        k = next((k for k in matched if n in matched[k]), None) or (g if g in keys else ("*" if "*" in keys else None))
        if k is None:
            raise assign.error(None, f"no cost curve for factor {n!r} (group {g!r}); add it or a \"*\" entry")
        cname = assign.str(k)
        if cname not in table.curves:
            raise assign.error(k, f"unknown cost curve {cname!r} (known: {', '.join(table.curves)})")
        curves.append(table.curves[cname])
    for k in keys:
        assign.raw(k)
        if k != "*" and k not in groups and not matched[k]:
            raise assign.error(k, f"{k!r} is neither a factor, a family, a pattern of factor names nor a group of "
                                  "the spec")
    assign.finish()
    return curves


class AllocationAnalysis(Analysis):
    def setup(self, params: Params, study):
        base = Path(study.file).parent
        self.title = params.str("title", "Cost-optimal tolerance allocation")
        self.key = params.str("key", "allocation")
        self.table = load_costs(params.path_value("costs", base))
        spath = params.path_value("spec", base, None)
        spec = load_spec(spath) if spath is not None else study.spec
        if "model" in params:
            mp = params.sub("model")
            factory = model_factory(mp.str("kind"), params.file)
            model = factory(mp, study.design, spec)
            mp.finish()
            model.check_spec(spec)
        else:
            if spath is not None:
                raise params.error("spec", "a spec of its own needs a model of its own ([analysis.model])")
            model = study.model
        self.model_label = type(model).__name__
        # allocated factors
        by_dependency = "factors" in params and params.raw("factors") == "dependencies"
        if by_dependency:
            names = []                  # below, once the requirements are known
        elif "factors" in params:
            names = []
            for key in params.strs("factors", min_length=1):
                found = matching_factors(spec, key)
                if not found:
                    raise params.error("factors", f"{key!r} names no factor of the spec (a name, a family "
                                                  "template with [k] or a shell pattern)")
                names += [n for n in found if n not in names]
        elif "groups" in params:
            groups = params.strs("groups", min_length=1)
            known = {f.group for f in spec.factors}
            for g in groups:
                if g not in known:
                    raise params.error("groups", f"unknown group {g!r} (spec groups: {', '.join(sorted(known))})")
            names = [f.name for f in spec.factors if f.group in groups]
        else:
            names = list(spec.names)
        reqs = requirements_from_tables(params.tables("requirement")) or list(study.requirements)
        if not reqs:
            raise params.error("requirement", "no requirement: give [[analysis.requirement]] or study requirements")
        try:
            reqs = expand_requirements(reqs, model)
            if "outputs" in params:
                pats = params.strs("outputs", min_length=1)
                reqs = [r for r in reqs if any(fnmatch.fnmatchcase(r.output, pat) for pat in pats)]
                if not reqs:
                    raise params.error("outputs", f"no requirement is on an output matching {pats}")
            if by_dependency:
                deps = dependencies(model)
                if deps is None:
                    raise params.error("factors", "\"dependencies\" needs a model that declares what each output "
                                                  "depends on (a composed or linear model); list the factors")
                need = set().union(*(deps.get(r.output, set()) for r in reqs))
                names = [n for n in spec.names if n in need]
                if not names:
                    raise params.error("factors", "the requirements' outputs depend on no factor of the spec")
            curves = assign_curves(spec, names, params.sub("assign"), self.table)
            tie = params.str("tie", "none", choices=("none", "drawing"))
            self.problem = AllocationProblem(model, spec, names, curves, reqs,
                                             drawing_ties(spec, names) if tie == "drawing" else ())
            self.study_problem = (self.problem.with_requirements(list(study.requirements))
                                  if model is study.model and spec is study.spec and study.requirements else None)
        except InputError as exc:
            # requirement errors already carry their full key; problem-level ones get the analysis' key
            raise exc.located(file=params.file, key=None if exc.key and "[" in exc.key else params.key) from None
        self.convex = params.str("convex", "rss", choices=("rss", "worst_case", "none"))
        g = params.sub("ga", {})
        self.ga_constraint = g.str("constraint", "monte_carlo", choices=("monte_carlo", "linearised", "none"))
        self.ga_n = g.int("n", 2000, min=50)
        self.ga_method = g.str("method", "lhs", choices=METHODS)
        if self.ga_constraint == "monte_carlo":
            for r in self.problem.requirements:
                need = zero_failure_n(r)
                if need is not None and self.ga_n < need:
                    raise g.error("n", f"n = {self.ga_n} cannot demonstrate {r.label} even with no failing sample "
                                       f"(the {r.label!r} judges yield ≥ {r.min_yield:g} on its lower confidence "
                                       f"bound): use n ≥ {need}")
        self.ga_confirm = g.bool("confirm", False)
        if self.ga_confirm and self.ga_constraint != "monte_carlo":
            raise g.error("confirm", "a confirmation sample needs the Monte Carlo constraint (constraint = \"monte_carlo\")")
        kw = dict(population=g.int("population", 40, min=4), generations=g.int("generations", 150, min=1),
                  parents=g.int("parents", 20, min=2), elitism=g.int("elitism", 2, min=0),
                  mutation_probability=g.float("mutation_probability", 0.15, min=0.0, max=1.0),
                  handling=g.str("handling", "feasibility", choices=HANDLING),
                  penalty=g.float("penalty", 10.0, positive=True), seed=0)
        try:
            self.ga_settings = GASettings(**kw)
        except InputError as exc:
            raise g.error(exc.key, exc.reason) from None
        g.finish()
        v = params.sub("verify", {})
        self.verify_n = v.int("n", 20000, min=100)
        self.verify_all = v.bool("all_requirements", False)
        self.verify_all_n = v.int("all_requirements_n", 0, min=0)      # 0: the study's own sample count
        if self.verify_all and self.study_problem is None:
            raise v.error("all_requirements", "needs the study's own model, spec and requirements")
        v.finish()
        pp = params.sub("pareto", {})
        self.pareto_scales = pp.floats("scales", [0.5, 0.75, 1.0, 1.5, 2.0], positive=True)
        self.pareto_ga = pp.bool("ga", False)
        pp.finish()
        if self.convex == "none" and self.ga_constraint == "none":
            raise params.error("convex", "both optimisers are switched off")
        params.finish()
        self.result: dict[str, AllocationResult] = {}

    # -----------------------------------------------------------------------
    def run(self, ctx) -> list[Section]:
        evaluate = ctx.evaluator
        full = self.problem
        lin_full = linearise(full, evaluate)
        # a requirement the NOMINAL design misses cannot be met by any tolerance: it is set aside (with its
        # design levers below) and the tolerances are allocated against the requirements that can be met
        missed = [r for j, r in enumerate(full.requirements) if lin_full.margin[j] <= 0]
        kept = [r for r in full.requirements if r not in missed]
        p = full.with_requirements(kept) if missed and kept else full
        lin = linearise(p, evaluate) if p is not full else lin_full     # the same rows: the study's cache answers
        lin_con = LinearisedConstraint(p, lin, "rss" if self.convex == "none" else self.convex)
        spread = self.linear_spread(p, lin, ctx)
        unfit = [] if spread is None else [r for r, ratio in zip(p.requirements, spread["first order / MC"])
                                           if not 0.5 <= ratio <= 2.0]
        pe = evaluated_problem(p)
        results: list[AllocationResult] = []
        ga_con = None
        if self.ga_constraint == "monte_carlo":
            ga_con = MonteCarloConstraint(pe, self.ga_n, self.ga_method,
                                          substream_seed(ctx.seed, "allocation_ga_design"),
                                          evaluate)
        elif self.ga_constraint == "linearised" and not unfit:
            ga_con = lin_con
        why = ("not linearisable at the nominal: " + "; ".join(f"{r.label} ({r.output})" for r in unfit)) if unfit else ""
        if ga_con is not None or not unfit:
            results.append(uniform_baseline(pe if ga_con is not None and ga_con is not lin_con else p, ga_con or lin_con))
        else:
            results.append(AllocationResult("uniform", p, None, "not linearisable", False, lin_con.describe(), notes=[why]))
        if self.convex != "none":
            results.append(solve_convex(p, lin_con) if not unfit else AllocationResult(
                f"convex {lin_con.mode}", p, None, "not linearisable", False, lin_con.describe(), notes=[why]))
        if ga_con is not None:
            settings = replace(self.ga_settings, seed=substream_seed(ctx.seed, "allocation_ga"))
            seed_t = results[0].t if results[0].feasible and results[0].t is not None else None   # uniform seeds the GA
            confirm = (MonteCarloConstraint(pe, self.ga_n, self.ga_method,
                                            substream_seed(ctx.seed, "allocation_ga_confirm"), evaluate)
                       if self.ga_confirm else None)
            results.append(solve_ga(pe if ga_con is not lin_con else p, ga_con, settings, initial=seed_t,
                                    confirm=confirm))
        self.result = {r.method: r for r in results}
        vseed = substream_seed(ctx.seed, "allocation_verify")
        checks = {r.method: verify(replace(r, problem=pe), self.verify_n, vseed, ctx.executor)
                  for r in results if r.feasible}
        pareto = self.pareto(p, lin, ga_con, ctx) if not unfit else None
        sec = self.section(p, results, checks, pareto, lin_con, ga_con)
        if spread is not None:
            sec.add_table(spread, "First-order spread at the nominal against the study's Monte Carlo (the "
                                  "linearised methods need a ratio within [0.5, 2])", "{:.4g}")
        if self.verify_all:
            self.check_all(sec, [r for r in results if r.feasible and r.t is not None], checks, ctx)
        if p is not full:
            sec.add_text("Set aside (the NOMINAL design misses them, so no tolerance can meet them; their design "
                         "levers follow): " + "; ".join(f"{r.label} ({r.output})" for r in missed)
                         + ". The tolerances above are allocated against the other requirements.")
            sec.summary["set_aside"] = [r.label for r in missed]
        self.levers_tables(sec, full, lin_full, LinearisedConstraint(full, lin_full, lin_con.mode), ctx)
        return [self.cost_section(), sec]

    def study_reference(self, full, ctx) -> dict[int, tuple[float, float]]:
        """Each requirement's Monte Carlo mean and standard deviation at the spec's tolerances (base units of
        the output), from the study's own run; empty when the allocation does not run on the study's model."""
        if self.study_problem is None or ctx.mc is None:
            return {}
        out = {}
        for j, r in enumerate(full.requirements):
            q = full.model.output(r.output)
            y = ctx.mc.column(r.output)
            out[j] = (units.convert(float(np.nanmean(y)), q.shown_unit, q.unit),
                      units.convert(float(np.nanstd(y, ddof=1)), q.shown_unit, q.unit))
        return out

    def linear_spread(self, p, lin, ctx) -> pd.DataFrame | None:
        """Each requirement's first-order standard deviation at the nominal, Σ (S_k σ_k)² at the spec's
        tolerances, against the study's Monte Carlo standard deviation of that output (None when the
        allocation does not run on the study's model and spec)."""
        if self.study_problem is None or ctx.mc is None:
            return None
        sd = p.spec.std_base()
        rows = []
        for j, r in enumerate(p.requirements):
            q = p.model.output(r.output)
            lin_sd = float(q.to_display(float(np.sqrt(np.nansum((lin.S[j] * sd) ** 2)))))
            mc_sd = float(np.nanstd(ctx.mc.column(r.output), ddof=1))
            rows.append({"requirement": r.label, "output": r.output, "unit": q.shown_unit,
                         "first-order σ": lin_sd, "Monte Carlo σ": mc_sd,
                         "first order / MC": lin_sd / mc_sd if mc_sd > 0 else (1.0 if lin_sd == 0 else np.inf)})
        return pd.DataFrame(rows)

    def check_all(self, sec: Section, results, checks, ctx) -> None:
        """The cheapest allocation that passed its own independent check, against every requirement of the
        study on the study's model — beside each requirement's yield at the spec's present tolerances (the
        study's Monte Carlo), so what the allocation costs the requirements it did not optimise for shows."""
        verified = [r for r in results if r.method in checks and checks[r.method].passed]
        if not verified:
            sec.add_text("No allocation passed its own independent Monte Carlo check, so none is checked against "
                         "every requirement of the study.")
            return
        best = min(verified, key=lambda r: r.total_cost)
        n = self.verify_all_n or (ctx.mc.n if ctx.mc is not None else self.verify_n)
        v = verify(replace(best, problem=self.study_problem), n,
                   substream_seed(ctx.seed, "allocation_verify"), ctx.executor)
        frame = v.to_frame().copy()
        worse = []
        if ctx.mc is not None:
            now = {d["output"]: d["yield"] for d in (x.to_dict() for x in ctx.mc.verdicts())}
            frame.insert(frame.columns.get_loc("yield"), "yield at the spec", [now.get(o, np.nan) for o in frame["output"]])
            worse = [f"{o} {a:.3f} → {b:.3f}" for o, a, b in zip(frame["output"], frame["yield at the spec"], frame["yield"])
                     if np.isfinite(a) and b < a - 2.0 * np.sqrt(max(a * (1 - a), 1e-12) * (1 / v.n + 1 / ctx.mc.n))]
        sec.add_table(frame, f"{best.method} (the cheapest allocation its own check passed) against every requirement "
                      f"of the study (the study's model, n = {v.n}): what the allocation did not optimise for, and the "
                      "set-aside requirements; 'yield at the spec' is the study's Monte Carlo at the present tolerances. "
                      "On the requirements it allocated for, the independent check above (its own n) decides: a "
                      "smaller n here may leave a yield undemonstrated by a single failing sample",
                      "{:.4g}")
        if worse:
            sec.add_text(f"The {best.method} allocation LOWERS the yield of requirements it was not asked to meet "
                         "(by more than two standard errors of the difference): " + "; ".join(worse) + ". It changes "
                         "tolerances these outputs also depend on: loosening one widens their spread, and where the "
                         "nominal lies outside a limit even tightening lowers the yield (the units move toward the "
                         "nominal). Adopt it only together with those requirements' own fix (their design levers).")
        sec.summary["all_requirements"] = {"method": best.method, "n": v.n, "rows": frame_records(frame),
                                           "lowered": worse}

    def levers_tables(self, sec: Section, full, lin_full, lin_con, ctx) -> None:
        """What the nominal design must change where no tolerance can meet a requirement: where each such
        requirement stands (nominal, Monte Carlo mean and σ), its first-order levers, and the top lever
        checked by a Monte Carlo run of the shifted design."""
        ref = self.study_reference(full, ctx)
        levers = design_levers(full, lin_full, reference=ref)
        if not levers:
            return
        base = ("the Monte Carlo mean and σ of the study" if ref else "the nominal output and the linearised σ")
        sec.add_text("Where the NOMINAL design already lies on or outside a requirement's limit, scaling tolerances "
                     "cannot help: as every tolerance shrinks, every reducer approaches the nominal one (where the "
                     "Monte Carlo mean lies on the passing side of a limit the nominal misses, the present yield "
                     "comes from the spread itself and tightening lowers it). The tables below give the design "
                     "levers to first order: the shift of one drawing nominal (every copy of a family alike) that "
                     f"alone moves the output from {base} to the limit minus z·σ ({lin_con.describe()}), ranked "
                     "by the output change of a shift by one tolerance half-band t; the slope is the five-point "
                     "derivative at the nominal. A direction and a size for a design change: the top lever of each "
                     "is checked below by a Monte Carlo run of the shifted design, where a linear step can miss.")
        stand, checks = [], []
        for j, r in enumerate(full.requirements):
            if r.label not in levers:
                continue
            q = full.model.output(r.output)
            row = {"requirement": r.label, "output": r.output, "unit": q.shown_unit,
                   "nominal": float(q.to_display(lin_full.y0[j]))}
            if j in ref:
                row["Monte Carlo mean"] = float(q.to_display(ref[j][0]))
                row["Monte Carlo σ"] = float(q.to_display(ref[j][1]))
            stand.append(row)
            top = levers[r.label].iloc[0]
            checks.append(self.check_lever(full, r, top, ctx))
        sec.add_table(pd.DataFrame(stand), "Where the requirements the nominal misses stand (the levers are "
                      f"measured from {base})", "{:.4g}")
        for label, frame in levers.items():
            sec.add_table(frame, f"Design levers for: {label}", "{:.4g}")
        checked = pd.DataFrame(checks)
        sec.add_table(checked, "The top lever of each, checked: a Monte Carlo run of the study's spec with that "
                      "one drawing nominal shifted (every other tolerance as it is)", "{:.4g}")
        sec.summary["design_levers"] = {label: frame_records(f) for label, f in levers.items()}
        sec.summary["design_levers_checked"] = frame_records(checked)

    def check_lever(self, full, r, top, ctx) -> dict:
        """One Monte Carlo run of the spec with the lever's nominal shifted by its 'shift needed alone'."""
        p1 = evaluated_problem(full.with_requirements([r]))
        n = ctx.mc.n if ctx.mc is not None else self.verify_n
        spec = shifted_spec(p1.spec, top["lever (mean shift of)"], float(top["shift needed alone"]))
        mc = run_monte_carlo(p1.model, spec, n, "random", substream_seed(ctx.seed, "allocation_levers"),
                             p1.requirements, ctx.executor, progress=False)
        d = mc.verdicts()[0].to_dict()
        y = mc.column(r.output)
        return {"requirement": r.label, "lever": top["lever (mean shift of)"], "shift": float(top["shift needed alone"]),
                "unit": top["unit"], "n": n, "mean after": float(np.nanmean(y)), "σ after": float(np.nanstd(y, ddof=1)),
                "yield after": d["yield"], "yield bound": d["yield_bound"], "passed": d["passed"]}

    def pareto(self, p, lin, ga_con, ctx) -> ParetoCurve:
        rows = []
        for f in self.pareto_scales:
            lf = replace(lin, margin=lin.margin * f)
            con = LinearisedConstraint(p.scaled_requirements(f), lf, lin_con_mode(self.convex))
            pf = con.problem
            row = {"requirement scale [1]": f}
            row["uniform (linearised)"] = _cost(uniform_baseline(pf, con))
            if self.convex != "none":
                row[f"convex {con.mode}"] = _cost(solve_convex(pf, con))
            if self.pareto_ga and ga_con is not None:
                gc = (MonteCarloConstraint(pf, self.ga_n, self.ga_method, ga_con.seed, ga_con.evaluate)
                      if isinstance(ga_con, MonteCarloConstraint) else con)
                settings = replace(self.ga_settings, seed=substream_seed(ctx.seed, "allocation_ga"))
                row["GA (Monte Carlo)" if isinstance(gc, MonteCarloConstraint) else "GA (linearised)"] = _cost(
                    solve_ga(pf, gc, settings))
            rows.append(row)
        return ParetoCurve(pd.DataFrame(rows), self.table.cost_unit)

    # -----------------------------------------------------------------------
    def cost_section(self) -> Section:
        from ..plotting.allocation import cost_curves

        sec = Section(f"{self.key}_costs", f"{self.title}: cost–tolerance models")
        used = {c.name: c for c in self.problem.curves}
        rows = []
        for c in used.values():
            rows.append({"curve": c.name, "kind": c.kind, f"C(t) [{self.table.cost_unit}], t in {c.unit}": c.formula(),
                         "points": len(c.fit.tolerance) if c.fit else 0,
                         "fitted": "a, b" + ("" if c.fit and c.fit.fixed_c else ", c") if c.fit else "given",
                         f"RMSE [{self.table.cost_unit}]": c.fit.rmse if c.fit else math.nan,
                         "R²": c.fit.r2 if c.fit else math.nan, "t_min": c.t_min, "t_max": c.t_max})
        sec.add_text(f"Cost data: {self.table.file} — {self.table.description}. {self.table.source}. Sources: "
                     + "; ".join(f"{c.name}: {c.source}" for c in used.values()) + ".")
        sec.add_table(pd.DataFrame(rows), "Cost–tolerance curves used (t: tolerance half-band ±t)", "{:.4g}")
        sec.add_figure(cost_curves(list(used.values()), self.table.cost_unit), "Cost–tolerance curves and their data")
        sec.summary = {"curves": frame_records(pd.DataFrame(rows))}
        return sec

    def section(self, p, results, checks, pareto, lin_con, ga_con) -> Section:
        from ..plotting.allocation import ga_history, tolerance_bars

        sec = Section(self.key, self.title)
        sec.add_text(
            f"Minimise Σ C_i(t_i) over {len(p.factors)} tolerances ±t_i of model {self.model_label} "
            f"subject to the requirements below and the cost curves' ranges t_min ≤ t ≤ t_max. "
            f"Changing t_i rescales factor i's distribution about its centre. "
            f"Uniform: the spec's tolerances times the largest common factor that meets "
            f"the constraint ({(ga_con or lin_con).describe()}). "
            + (f"Convex: cvxpy global optimum of the {lin_con.describe()} (five-point gradient at nominal). "
               if self.convex != "none" else "")
            + (f"GA: pygad, {self.ga_settings.population} × {self.ga_settings.generations} generations, "
               f"{self.ga_settings.handling} rules, constraint {ga_con.describe()}. " if ga_con is not None else "")
            + f"Every allocation is checked by an independent Monte Carlo run (n = {self.verify_n}, plain random "
              f"sampling, its own seed).")
        sec.add_table(requirements_frame(p.requirements), "Requirements on the model outputs", "{:.4g}")
        frame = results[0].to_frame().drop(columns=["t uniform (±)"])
        for r in results:
            frame[f"t {r.method} (±)"] = r.display_t() if r.t is not None else np.nan
        frame = frame.drop(columns=["cost"])
        if p.ties:
            sec.add_text(f"One ±t per drawing tolerance: {len(p.ties)} callouts stand for "
                         f"{sum(len(g) for g in p.ties)} factors (coordinates of a position zone, copies of a "
                         f"per-part family) and share their tolerance, so {len(p.free)} tolerances are optimised "
                         f"for {len(p.factors)} factors.")
        sec.add_table(frame, "Allocated tolerances ±t per factor (factor units)", "{:.4g}")
        best = results[-1]
        cax = component_axis_table(best) if best.t is not None else None
        if cax is not None:
            sec.add_table(cax, f"{best.method}: tolerance per component and axis", "{:.3g}")
        base_cost = results[0].total_cost
        summ = pd.DataFrame([{"method": r.method, "status": r.status, "constraint": r.constraint,
                              f"total cost [{self.table.cost_unit}]": r.total_cost,
                              "vs uniform [%]": 100.0 * (r.total_cost / base_cost - 1.0) if r.t is not None else np.nan,
                              "independent MC": ("pass" if checks[r.method].passed else "FAIL")
                              if r.method in checks else "n/a"} for r in results])
        sec.add_table(summ, "Total cost against the uniform-tolerance baseline", "{:.4g}")
        for r in results:
            for note in r.notes:
                sec.add_text(f"{r.method}: {note}")
        failed = [m for m, v in checks.items() if not v.passed]
        if failed:
            sec.add_text(
                f"Not confirmed by the independent Monte Carlo run: {', '.join(failed)}. An allocation that sits "
                "exactly on its constraint passes a fresh sample only about half the time on the estimate and "
                "rarely on a lower confidence bound; the linearised RSS constraint also assumes a normal output "
                "centred on its nominal value (one-sided factors whose mean moves with their tolerance, skewed or "
                "bounded distributions and non-linear models break that). The GA's Monte Carlo constraint uses "
                "the requirement's own basis, so its allocation carries the sampling margin.")
        if checks:
            v0 = next(iter(checks.values()))
            sec.add_table(pd.DataFrame([v.summary_row() for v in checks.values()]),
                          f"Independent Monte Carlo check (n = {v0.n}, plain random, seed {v0.seed}): requirements met, "
                          "and the worst output (full tables in summary.json)", "{:.4g}")
        ok = [r for r in results if r.t is not None]
        sec.add_figure(tolerance_bars(ok), "Allocated tolerances against the uniform baseline")
        ga = self.result.get("GA")
        if ga is not None and ga.history:
            sec.add_figure(ga_history(ga, self.result.get(f"convex {lin_con.mode}")), "GA convergence")
        if pareto is not None:
            sec.add_table(pareto.to_frame(), f"Minimum total cost [{self.table.cost_unit}] against the requirement "
                          "(limits × scale about the nominal output)", "{:.4g}")
            sec.add_figure(pareto.plot(), "Cost against requirement (Pareto front)")
        sec.summary = {
            "factors": p.factors,
            "ties": [list(g) for g in p.ties],
            "methods": frame_records(summ),
            "tolerances": frame_records(frame),
            "verification": {m: frame_records(v.to_frame()) for m, v in checks.items()},
            "pareto": frame_records(pareto.to_frame()) if pareto is not None else [],
        }
        return sec


def drawing_ties(spec, names: list[str]) -> tuple[tuple[str, ...], ...]:
    """The allocated factors that stand for one drawing tolerance (:func:`rvtol.callouts.drawing_tolerance`:
    the coordinates of one position zone, the copies of a per-part family), as groups to tie: a drawing
    gives one ±t per callout, not one per coordinate or per pin."""
    from ..callouts import drawing_tolerance

    groups: dict[str, list[str]] = {}
    for n in names:
        groups.setdefault(drawing_tolerance(spec.factor(n)), []).append(n)
    return tuple(tuple(g) for g in groups.values() if len(g) > 1)


def evaluated_problem(p: AllocationProblem) -> AllocationProblem:
    """``p`` with its model evaluated only as far as its requirements need (a composed model restricted to
    their outputs: a GA over stack-up requirements does not run the 20-DOF stages)."""
    if not hasattr(p.model, "restricted"):
        return p
    outs = list(dict.fromkeys(r.output for r in p.requirements))
    return replace(p, model=p.model.restricted(outs))


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


def lin_con_mode(convex: str) -> str:
    return "rss" if convex == "none" else convex


def _cost(r: AllocationResult) -> float:
    return r.total_cost if r.t is not None and r.feasible else math.nan
