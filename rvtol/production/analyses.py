"""Study analyses ``per_unit_prediction`` and ``selective_assembly``.

::

    [[analysis]]
    kind = "per_unit_prediction"
    name = ""                       # optional: section key per_unit_prediction_<name>, file per_unit_<name>.csv
    kits = "measured/kits.csv"      # the kit list (rvtol.production.measured_parts)
    n = 1109                        # samples per unit (default: the n at which a unit can be shown to
                                    # conform on every requirement, rvtol.production.per_unit.samples_to_demonstrate)
    interval = 0.95                 # central prediction interval shown per output
    outputs = ["torsion.lost_motion"]   # outputs in the tables and plots (default: those of the requirements)

    [[analysis.parts]]              # one table per part family
    file = "measured/crankshafts.csv"
    slots = ["crank_1", "crank_2", "crank_3"]   # the places its parts take; factor = "<slot>.<column>"
    name = "crankshaft"             # optional (default: the file's stem)

Sections: the kits; per reducer its verdict (conforms / does not conform / undecided) and, per
requirement, the probability that it conforms with its interval; per output the median and the
prediction interval; a plot per requirement's output.  The report folder gets ``per_unit.csv``
(one row per reducer, flat columns: the CI-friendly output) and ``summary.json`` an entry per unit
under ``analyses.per_unit_prediction.units``.

::

    [[analysis]]
    kind = "selective_assembly"
    name = "pins"                   # optional: section key selective_assembly_<name>
    factor = "pins.diameter_lot"    # the graded part's size (or factors = [...]: one part per factor)
    target = "..."                  # matching rule: the target size, an expression of factors, mapped quantities and
                                    # design numbers design.<key>, base units (or targets = [...], one per factor)
    # match = "hole.size"           # or: class to class with the mating part (or match = [...])
    classes = [2, 3, 4]             # numbers of equal-probability classes compared with no grading
    limits = [-3.0, -2.0, -1.0]     # optional: inner limits of a proposed grading (unit of the supply)
    stock_ratio = 1.1               # optional: graded parts made per part used (finite stock); default unlimited
    outputs = ["torsion.lost_motion"]   # outputs whose distributions are shown (default: the requirements')
    [analysis.supply]               # optional: the parts' size before grading, as a [[factor]] (no name);
    unit = "um"                     # default: the graded factor's own distribution
    dist = "uniform"
    lower = -4.0
    upper = 2.0
    source = "..."
    [analysis.optimise]             # optional: search the limits of `classes` classes
    classes = 3
    n = 300                         # size of the search's own design (sub-stream selective_optimise)
    max_evaluations = 40

The comparison runs on the study's own Monte Carlo samples (common random numbers): the
ungraded case is the study's result itself when the supply is the factor's distribution.  Per
case: the yield of every requirement and of all of them together with intervals, the verdict by
:func:`rvtol.verdict.judge`, the outputs' mean, spread and 99.865 % point, and with a finite stock
the substitutions and the parts left over per class.  The optimised limits are found on a separate
design and checked on the study's samples.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from .. import stats as st
from ..analysis import Analysis
from ..errors import InputError
from ..expressions import Expression
from ..mc import result_of
from ..params import Params
from ..report.sections import Section
from ..sampling import SampleSet, sample, substream_seed
from ..spec import YIELD_INTERVALS, factor_from_params
from .measured_parts import FamilySource, load_measured_units
from .per_unit import STATES, predict_units, samples_to_demonstrate
from .selective import (Classes, ClassToClassRule, GradedPart, Supply, TargetRule, assemble, bandwidths,
                        design_numbers, known_names, named_values, optimise_limits, smoothed_yield, stock_batch,
                        stock_size, ungraded)


def _key(kind: str, name: str) -> str:
    return f"{kind}_{name}" if name else kind


def _unique_key(params: Params, study, key: str) -> None:
    if any(getattr(a, "key", None) == key for a in study.analyses):
        raise params.error("name", f"two analyses with the key {key!r}: give each a name")


def _outputs(params: Params, study) -> list[str]:
    names = study.model.output_names
    default = list(dict.fromkeys(r.output for r in study.requirements)) or list(names)
    outs = params.strs("outputs", default, min_length=1)
    for o in outs:
        if o not in names:
            raise params.error("outputs", f"unknown output {o!r} (the model has: {', '.join(names)})")
    return outs


def _evaluated(study, outputs: list[str]):
    """``(model, requirements)``: the study's model restricted to ``outputs`` (a composed study evaluates only
    the stages they need) and the study's requirements on them."""
    model = study.model
    if hasattr(model, "restricted") and set(outputs) != set(model.output_names):
        model = model.restricted(outputs)
    return model, [r for r in study.requirements if r.output in outputs]


def _no_build(params, study, why: str) -> None:
    """A study with a build (``[study] build``) chooses its fitted parts per sample: this analysis would be overruled."""
    if getattr(study, "build", None) is not None:
        raise params.error("kind", f"this analysis {why}; the study's build would choose those parts again: give "
                                   "[study] build = false")


# --------------------------------------------------------------------------- per-unit prediction
class PerUnitPrediction(Analysis):
    def setup(self, params, study):
        _no_build(params, study, "predicts units that are built already (their fitted parts are measured)")
        self.name = params.str("name", "")
        self.key = _key("per_unit_prediction", self.name)
        _unique_key(params, study, self.key)
        kits = params.path_value("kits", study.base_dir)
        sources = []
        tables = params.tables("parts")
        if not tables:
            raise params.error("parts", "give at least one [[analysis.parts]] table (file, slots)")
        for t in tables:
            sources.append(FamilySource(t.path_value("file", study.base_dir), tuple(t.strs("slots", min_length=1)),
                                        t.str("name", None)))
            t.finish()
        self.units = load_measured_units(study.spec, kits, sources)
        study.inputs.update({f"{self.key}:{k}": v for k, v in self.units.files().items()})
        self.outputs = _outputs(params, study)
        self.model, self.requirements = _evaluated(study, self.outputs)
        self.probability = params.float("conformance_probability", None, min=0.5, max=0.999999)
        try:
            self.needed = samples_to_demonstrate(self.requirements, self.probability)
        except ValueError as exc:       # a requirement that asks for P = 1 of one unit
            raise params.error("conformance_probability", f"{exc}: give a conformance_probability < 1") from None
        self.n = params.int("n", self.needed, min=2)
        self.interval = params.float("interval", 0.95, min=0.5, max=0.9999)
        self.file = f"per_unit_{self.name}.csv" if self.name else "per_unit.csv"
        params.finish()

    def run(self, ctx) -> Section:
        from ..plotting.production import plot_unit_intervals

        pred = predict_units(self.model, ctx.spec, self.units, self.n, evaluator=ctx.evaluator,
                             requirements=self.requirements, method=ctx.options.method, seed=ctx.seed,
                             interval=self.interval, probability=self.probability)
        s = Section(self.key, "Per-unit prediction from measured parts" + (f": {self.name}" if self.name else ""))
        fams = ", ".join(f"{f.name} ({len(f.serials)} parts, {len(f.columns)} features, slots "
                         f"{', '.join(f.slots)})" for f in self.units.families)
        counts = pred.counts()
        s.add_text(
            f"{len(self.units)} reducers from the kit list {Path(self.units.kit_file).name}; measured part families: "
            f"{fams}. Per reducer, {self.n} samples: each measured factor at its measured value plus a normal "
            "measurement error of its stated standard uncertainty, each unmeasured factor drawn from the spec "
            "(conditionally on the measured ones where the spec correlates them), one design for every reducer "
            "(sub-stream 'per_unit' of the study seed).\n\n"
            "Verdict per requirement (rvtol.verdict.judge_unit): the unit conforms when the probability that it "
            "meets the requirement reaches "
            + ("the yield the requirement asks of the population" if self.probability is None else
               f"{self.probability:g} (the study's conformance probability for one unit)")
            + " (on its lower confidence bound unless the requirement's basis is the estimate), does not conform "
            "when even the upper bound stays below, and is undecided in between; the unit's verdict is its worst. "
            f"Result: {counts['conforms']} conform, {counts['does not conform']} do not conform, "
            f"{counts['undecided']} undecided. One row per reducer: {self.file} in the report folder.")
        if self.n < self.needed:
            s.add_text(f"Note: with n = {self.n} samples per unit no unit can be shown to conform on every "
                       f"requirement (that needs n ≥ {self.needed} with every sample conforming): the verdicts "
                       "can only be 'does not conform' or 'undecided'.")
        s.add_table(self.units.to_frame(), "Kits: the part serial in every slot ('-': not measured) and the "
                                           "number of measured factors")
        req = pred.requirement_frame()
        verdicts = pred.verdicts()
        table = pd.DataFrame({"reducer": list(verdicts), "verdict": list(verdicts.values())})
        for r in pred.requirements:
            sub = req[req["requirement"] == r.label].set_index("reducer")
            table[f"{r.label}: P [CI]"] = [f"{sub.loc[u, 'P']:.4f} [{sub.loc[u, 'P_lo']:.4f}, {sub.loc[u, 'P_hi']:.4f}]"
                                           for u in table["reducer"]]
        s.add_table(table, f"Per-unit verdicts: probability of conformance P with its "
                           f"{pred.requirements[0].confidence if pred.requirements else 0.95:.0%} interval")
        outs = pred.output_frame()
        outs = outs[outs["output"].isin(self.outputs)]
        s.add_table(outs, f"Per-unit predictions: median, mean, std and the {self.interval:.0%} prediction "
                          "interval [lo, hi] (display units); failed: samples the model could not evaluate")
        for o in self.outputs:
            rs = [r for r in pred.requirements if r.output == o]
            sub = outs[outs["output"] == o].set_index("reducer").reindex(pred.units)
            vs = []
            for u in pred.units:
                states = req.loc[(req["reducer"] == u) & (req["output"] == o), "verdict"].tolist()
                vs.append(max(states, key=STATES.index) if states else "")
            fig = plot_unit_intervals(list(pred.units), sub["median"].to_numpy(float), sub["lo"].to_numpy(float),
                                      sub["hi"].to_numpy(float), vs, output=o, unit=sub["unit"].iloc[0],
                                      lower=next((r.lower for r in rs if r.lower is not None), None),
                                      upper=next((r.upper for r in rs if r.upper is not None), None),
                                      interval=self.interval)
            s.add_figure(fig, f"{o}: per-unit median and {self.interval:.0%} prediction interval, coloured by the "
                              "unit's verdict on this output's requirement(s)")
        s.add_file(self.file, pred.unit_frame().to_csv(index=False))
        s.summary = {"n": self.n, "n_to_demonstrate": self.needed, "interval": self.interval, "counts": counts,
                     "conformance_probability": self.probability,
                     "file": self.file, "units": _unit_summary(pred, req, verdicts)}
        return s


def _unit_summary(pred, req: pd.DataFrame, verdicts: dict) -> list[dict]:
    outs = pred.output_frame()
    out = []
    for u in pred.units:
        rq = req[req["reducer"] == u]
        ou = outs[outs["reducer"] == u]
        out.append({
            "reducer": u, "verdict": verdicts[u],
            "requirements": [{"requirement": r["requirement"], "P": r["P"], "P_ci": [r["P_lo"], r["P_hi"]],
                              "required": r["required"], "verdict": r["verdict"]} for _, r in rq.iterrows()],
            "outputs": {o["output"]: {"unit": o["unit"], "median": o["median"], "interval": [o["lo"], o["hi"]],
                                      "failed": o["failed"]} for _, o in ou.iterrows()},
        })
    return out


# --------------------------------------------------------------------------- selective assembly
def _listed(params: Params, one: str, many: str, default=None) -> list[str] | None:
    if one in params and many in params:
        raise params.error(many, f"give {one!r} or {many!r}, not both")
    if one in params:
        return [params.str(one)]
    if many in params:
        return params.strs(many, min_length=1)
    return default


class SelectiveAssembly(Analysis):
    def setup(self, params, study):
        _no_build(params, study, "grades and fits the parts itself")
        spec, model = study.spec, study.model
        self.name = params.str("name", "")
        self.key = _key("selective_assembly", self.name)
        _unique_key(params, study, self.key)
        factors = _listed(params, "factor", "factors")
        if not factors:
            raise params.error("factor", "missing required key (the graded part's size: a factor of the spec)")
        for f in factors:
            if f not in spec.names:
                raise params.error("factors" if "factors" in params else "factor", f"unknown factor {f!r}")
        if len(set(factors)) != len(factors):
            raise params.error("factors", "a factor is named twice")
        graded = spec.factor(factors[0])
        if "supply" in params:
            sp = params.sub("supply")
            sp.data.setdefault("name", factors[0])
            supply = Supply(factor_from_params(sp))
        else:
            supply = Supply(graded)
        from .. import units

        for f in factors:
            if units.dimension(spec.factor(f).unit) != units.dimension(supply.factor.unit):
                raise params.error("supply", f"the supply's unit {supply.factor.unit!r} does not fit factor {f!r}")
        targets = _listed(params, "target", "targets")
        match = _listed(params, "match", "match_factors")
        if (targets is None) == (match is None):
            raise params.error("target", "give the matching rule: target (a target size) or match (class to class)")
        rules = []
        known = known_names(model, spec)
        self.constants: dict[str, float] = {}
        if targets is not None:
            key = "targets" if "targets" in params else "target"
            if len(targets) != len(factors):
                raise params.error(key, f"{len(targets)} targets for {len(factors)} graded factors")
            for t in targets:
                try:
                    e = Expression.parse(t)
                    self.constants.update(design_numbers([m for m in e.names if m not in known], study.design))
                except InputError as exc:
                    raise params.error(key, exc.reason) from None
                bad = [m for m in e.names if m not in known and m not in self.constants]
                if bad:
                    raise params.error(key, f"unknown name {bad[0]!r} in {t!r} (a factor of the spec, a mapped "
                                            "quantity or a design number design.<key>)")
                rules.append(TargetRule(e))
        else:
            key = "match_factors" if "match_factors" in params else "match"
            if len(match) != len(factors):
                raise params.error(key, f"{len(match)} mating parts for {len(factors)} graded factors")
            for m in match:
                if m not in spec.names:
                    raise params.error(key, f"unknown factor {m!r}")
                rules.append(ClassToClassRule(m, Supply(spec.factor(m))))
        try:
            self.part = GradedPart(tuple(factors), supply, tuple(rules))
        except ValueError as exc:
            raise params.error("target" if targets is not None else "match", str(exc)) from None
        ks = params.raw("classes", [2, 3, 4])
        if not isinstance(ks, list) or not ks or not all(isinstance(k, int) and not isinstance(k, bool) and 1 <= k <= 50
                                                         for k in ks):
            raise params.error("classes", f"expected a list of numbers of classes (integers 1…50), got {ks!r}")
        self.classes = sorted(set(ks))
        self.limits = None
        if "limits" in params:
            lim = params.floats("limits", min_length=1)
            try:
                self.limits = Classes.from_limits(units.to_base(np.asarray(lim), supply.factor.unit))
            except ValueError:
                raise params.error("limits", f"class limits must increase strictly, got {lim}") from None
            p = self.limits.probabilities(supply)
            if np.any(p <= 0):
                raise params.error("limits", f"class {int(np.argmin(p)) + 1} holds no part of the supply "
                                             f"({supply.factor.describe()})")
        self.stock_ratio = params.float("stock_ratio", None, min=1.0)
        self.outputs = _outputs(params, study)
        self.model, self.requirements = _evaluated(study, self.outputs)
        self.optimise = None
        if "optimise" in params:
            op = params.sub("optimise")
            self.optimise = {"classes": op.int("classes", 3, min=2, max=20), "n": op.int("n", 300, min=20),
                             "max_evaluations": op.int("max_evaluations", 40, min=2)}
            op.finish()
            if not self.requirements:
                raise params.error("optimise", "optimising the class limits needs requirements on the outputs "
                                               "(the yield)")
        params.finish()

    # ------------------------------------------------------------------
    def _case(self, ctx, X, env, classes: Classes | None, label: str, k: int, as_drawn: bool = False) -> dict:
        """Evaluate one assembly case on the samples ``X``; ``classes`` None: no grading (parts at random from
        the supply, or with ``as_drawn`` the samples as the spec drew them)."""
        spec, model = ctx.spec, self.model
        stock = None
        if classes is None:
            Xg = X if as_drawn else ungraded(X, spec, self.part)
            asm = None
        else:
            if self.stock_ratio is not None:
                size = stock_size(self.stock_ratio, len(X) * len(self.part.factors))
                stock = stock_batch(self.part.supply, size, ctx.seed)
            asm = assemble(X, spec, self.part, classes, env, stock)
            Xg = asm.X
        if model is ctx.model and classes is None and np.array_equal(Xg, ctx.mc.samples.values):
            mc = ctx.mc                                   # the study's own result: nothing to evaluate
        else:
            ev = ctx.evaluator(model, Xg, f"selective assembly: {label}")
            s = SampleSet(Xg, spec.names, spec.units, ctx.mc.samples.method, ctx.seed)
            mc = result_of(model, s, ev, self.requirements, ctx.mc.confidence)
        return {"label": label, "k": k, "classes": classes, "mc": mc, "assembly": asm}

    def _row(self, case: dict) -> dict:
        mc = case["mc"]
        row = {"case": case["label"], "classes": case["k"], "failed": int(mc.n - mc.ok.sum())}
        for v in mc.verdicts():
            y = v.yield_
            row[f"{v.requirement.label}: yield"] = y.estimate
            row[f"{v.requirement.label}: CI"] = f"[{y.lo:.4f}, {y.hi:.4f}]"
            row[f"{v.requirement.label}: verdict"] = "PASS" if v.passed else "FAIL"
        if mc.requirements:
            j = _joint(mc)
            row.update({"all requirements: yield": j.estimate, "all requirements: CI": f"[{j.lo:.4f}, {j.hi:.4f}]"})
        stats_df = mc.statistics()
        for o in self.outputs:
            r = stats_df.loc[o]
            unit = r["unit"]
            row[f"{o} mean [{unit}]"] = r.get("mean")
            row[f"{o} std [{unit}]"] = r.get("std")
            row[f"{o} P99.865 [{unit}]"] = r.get("P99.865")
        asm = case["assembly"]
        if asm is not None:
            row["substituted"] = asm.substituted
            if asm.stock is not None:
                row["left over"] = int(asm.stock.leftover.sum())
        return row

    def run(self, ctx) -> list[Section]:
        from ..plotting.production import plot_graded_distributions, plot_stock_balance, plot_yield_against_classes

        spec, model = ctx.spec, self.model
        X = ctx.mc.samples.values
        env = {**named_values(model, spec, X), **self.constants}
        supply = self.part.supply
        same = all(supply.same_as(spec.factor(f)) for f in self.part.factors)
        cases = [] if same else [self._case(ctx, X, env, None, "as drawn (spec)", 1, as_drawn=True)]
        cases.append(self._case(ctx, X, env, None, "no grading", 1))
        for k in self.classes:
            if k == 1:
                continue
            cases.append(self._case(ctx, X, env, Classes.equal_probability(supply, k), f"{k} equal-probability "
                                                                                          "classes", k))
        if self.limits is not None:
            cases.append(self._case(ctx, X, env, self.limits, "proposed limits", self.limits.k))
        opt = None
        if self.optimise is not None:
            opt = self._optimise(ctx)
            cases.append(self._case(ctx, X, env, opt.classes, "optimised limits", opt.classes.k))
        chosen = cases[-1]
        s = Section(self.key, "Selective assembly" + (f": {self.name}" if self.name else ""))
        unit = supply.factor.unit
        rule = "; ".join(f"{f}: {r.describe()}" for f, r in zip(self.part.factors, self.part.rules))
        own = spec.factor(self.part.factors[0]).describe()
        s.add_text(
            f"Graded: {', '.join(self.part.factors)} (one part per factor and reducer). Supply before grading: "
            f"{supply.factor.describe()}" + ("" if same else f" ({supply.factor.source or 'given in the study'}; the "
                                             f"spec's own distribution is {own}, the case 'as drawn'; 'no "
                                             "grading' picks parts at random from this supply)")
            + f". Matching rule: {rule}. Simulated inside the Monte Carlo on the study's {ctx.mc.n} samples "
            "(common random numbers: only the graded factor changes); evaluated: "
            + ", ".join(model.output_names)
            + (f" (the stages {', '.join(st.name for st in model.stages)})" if hasattr(model, "stages") else "")
            + ". "
            + ("Unlimited supply: each part is drawn from the supply within its class."
               if self.stock_ratio is None else
               f"Finite stock: a graded batch of {self.stock_ratio:g} parts per part used (sub-stream "
               "'selective_stock'); a reducer whose class is empty takes the class whose centre is nearest its "
               "target, and the parts left over are counted per class."))
        rows = pd.DataFrame([self._row(c) for c in cases])
        s.add_table(rows, "Assembly cases: yield of every requirement and of all together with its "
                          f"{ctx.mc.confidence:.0%} interval, verdict (rvtol.verdict.judge), output statistics")
        s.add_table(chosen["classes"].describe(unit, supply),
                    f"Classes of the case '{chosen['label']}' (limits in {unit}; the outer ones at the supply's "
                    "support)")
        asm = chosen["assembly"]
        if asm is not None and asm.stock is not None:
            s.add_table(asm.stock.to_frame(), f"Stock balance of '{chosen['label']}': parts made per class, wanted "
                                              f"by the rule, used, left over ({asm.stock.substituted} substituted)")
            cl = np.arange(1, chosen["classes"].k + 1)
            s.add_figure(plot_stock_balance(cl, asm.stock.made, asm.stock.used, asm.stock.leftover),
                         f"Stock balance of '{chosen['label']}'")
        for o in self.outputs:
            rs = [r for r in cases[0]["mc"].requirements if r.output == o]
            series = {c["label"]: c["mc"].column(o) for c in cases if c["classes"] is None}
            series[chosen["label"]] = chosen["mc"].column(o)
            s.add_figure(plot_graded_distributions(series, output=o, unit=cases[0]["mc"].unit_of(o),
                                                   lower=next((r.lower for r in rs if r.lower is not None), None),
                                                   upper=next((r.upper for r in rs if r.upper is not None), None)),
                         f"{o}: without grading and with '{chosen['label']}'")
        if self.requirements:
            ks, ests, los, his = [], [], [], []
            for c in cases:
                if c["label"] in ("proposed limits", "optimised limits", "as drawn (spec)"):
                    continue
                j = _joint(c["mc"])
                ks.append(c["k"]), ests.append(j.estimate), los.append(j.lo), his.append(j.hi)
            o_pt = None
            if opt is not None:
                j = _joint(cases[-1]["mc"])
                o_pt = (cases[-1]["k"], j.estimate, j.lo, j.hi)
            s.add_figure(plot_yield_against_classes(ks, ests, los, his, optimised=o_pt,
                                                    title="yield of all requirements together"),
                         "The number of classes against the gain: yield of all requirements together, with its "
                         "interval")
        if opt is not None:
            s.add_text(f"Optimised limits of {opt.classes.k} classes: Nelder–Mead over the classes' cumulative "
                       f"probabilities from equal probabilities, on a design of {self.optimise['n']} samples of its "
                       "own (sub-stream 'selective_optimise', unlimited supply), maximising the yield of all "
                       "requirements with the indicator smoothed by a normal kernel (Silverman bandwidth of the "
                       f"ungraded outputs): {opt.start:.4f} at equal probabilities → {opt.best:.4f} after "
                       f"{opt.evaluations} evaluations ({opt.message}). The row 'optimised limits' above checks them "
                       "on the study's samples.")
        s.summary = {
            "factors": list(self.part.factors), "supply": supply.factor.describe(), "rule": rule,
            "stock_ratio": self.stock_ratio,
            "cases": [_case_summary(c, unit) for c in cases],
        }
        return s

    def _optimise(self, ctx):
        spec, model = ctx.spec, self.model
        o = self.optimise
        Xo = sample(spec, o["n"], ctx.mc.samples.method, substream_seed(ctx.seed, "selective_optimise")).values
        env = {**named_values(model, spec, Xo), **self.constants}
        reqs = [r.in_unit(model.output(r.output).shown_unit) for r in self.requirements]
        outs = model.output_names
        base = result_of(model, SampleSet(Xo, spec.names, spec.units, "lhs", ctx.seed),
                         ctx.evaluator(model, ungraded(Xo, spec, self.part), "class limits: ungraded"))
        h = bandwidths(base.Y, base.ok, reqs, outs)

        def objective(classes: Classes) -> float:
            asm = assemble(Xo, spec, self.part, classes, env)
            r = result_of(model, SampleSet(asm.X, spec.names, spec.units, "lhs", ctx.seed),
                          ctx.evaluator(model, asm.X, "class limits"))
            return smoothed_yield(r.Y, r.ok, reqs, outs, h)

        return optimise_limits(objective, self.part.supply, o["classes"], max_evaluations=o["max_evaluations"])


def _joint(mc) -> st.YieldResult:
    """Yield of all the result's requirements together (a sample conforms when it meets every one)."""
    inside = mc.ok.copy()
    names = [q.name for q in mc.outputs]
    for r in mc.requirements:
        y = mc.Y[:, names.index(r.output)]
        if r.lower is not None:
            inside &= np.nan_to_num(y, nan=-np.inf) >= r.lower
        if r.upper is not None:
            inside &= np.nan_to_num(y, nan=np.inf) <= r.upper
    r0 = mc.requirements[0]
    k, n = int(inside.sum()), mc.n
    lo, hi = st.proportion_ci(k, n, r0.confidence, YIELD_INTERVALS[r0.interval])
    return st.YieldResult(n, k, k / n, lo, hi)


def _case_summary(c: dict, unit: str) -> dict:
    from .. import units

    mc = c["mc"]
    out = {"case": c["label"], "classes": c["k"], "failed": int(mc.n - mc.ok.sum()),
           "requirements": [{"requirement": v.requirement.label, "yield": v.yield_.estimate,
                             "yield_ci": [v.yield_.lo, v.yield_.hi], "passed": v.passed} for v in mc.verdicts()]}
    if mc.requirements:
        j = _joint(mc)
        out["joint_yield"] = j.estimate
        out["joint_yield_ci"] = [j.lo, j.hi]
    if c["classes"] is not None:
        out["limits"] = [float(v) for v in units.from_base(c["classes"].edges[1:-1], unit)]
        out["limits_unit"] = unit
    asm = c["assembly"]
    if asm is not None:
        out["substituted"] = asm.substituted
        if asm.stock is not None:
            out["stock"] = {k: v.tolist() for k, v in (("made", asm.stock.made), ("wanted", asm.stock.wanted),
                                                       ("used", asm.stock.used), ("left_over", asm.stock.leftover))}
    return out

