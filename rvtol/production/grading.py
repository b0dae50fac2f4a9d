"""A study's selective assembly: every assembly case on the study's own Monte Carlo samples, one result.

:func:`compare_grading` runs, on the study's samples (common random numbers: only the graded factor
changes), the cases a study asks for: the factor as the spec drew it (when the supply is another
distribution), no grading (parts at random from the supply), ``k`` equal-probability classes for each
``k``, a proposed grading and the optimised limits (:func:`rvtol.production.selective.optimise_limits`,
searched on a separate design, sub-stream ``selective_optimise``, then checked on the study's samples).
Per case: the yield of every requirement and of all of them together with intervals, the verdict
(:func:`rvtol.verdict.judge`), the outputs' mean, spread and 99.865 % point, and with a finite stock the
substitutions and the parts left over per class.  The ungraded case is the study's result itself when
the supply is the factor's distribution.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .. import stats as st
from .. import units
from ..mc import result_of
from ..sampling import SampleSet, sample, substream_seed
from ..spec import YIELD_INTERVALS
from .selective import (Classes, GradedPart, LimitOptimisation, assemble, bandwidths, named_values, optimise_limits,
                        smoothed_yield, stock_batch, stock_size, ungraded)

#: cases that are not a number of equal-probability classes (left out of the yield-against-classes curve)
NOT_ON_THE_CURVE = ("proposed limits", "optimised limits", "as drawn (spec)")


@dataclass
class Case:
    """One assembly case: its label, number of classes, the classes (None: no grading), its Monte Carlo
    result and the assembly (None without grading)."""

    label: str
    k: int
    classes: Classes | None
    mc: object
    assembly: object = None

    def joint(self) -> st.YieldResult:
        """Yield of all the result's requirements together (a sample conforms when it meets every one)."""
        mc = self.mc
        inside = mc.ok.copy()
        names = [q.name for q in mc.outputs]
        for r in (r for r in mc.requirements if r.per_unit):     # a statistic's band judges no unit
            y = mc.Y[:, names.index(r.output)]
            if r.lower is not None:
                inside &= np.nan_to_num(y, nan=-np.inf) >= r.lower
            if r.upper is not None:
                inside &= np.nan_to_num(y, nan=np.inf) <= r.upper
        r0 = mc.requirements[0]
        k, n = int(inside.sum()), mc.n
        lo, hi = st.proportion_ci(k, n, r0.confidence, YIELD_INTERVALS[r0.interval])
        return st.YieldResult(n, k, k / n, lo, hi)

    def row(self, outputs) -> dict:
        mc = self.mc
        row = {"case": self.label, "classes": self.k, "failed": int(mc.n - mc.ok.sum())}
        for v in mc.verdicts():
            y = v.yield_
            row[f"{v.requirement.label}: yield"] = y.estimate
            row[f"{v.requirement.label}: CI"] = f"[{y.lo:.4f}, {y.hi:.4f}]"
            row[f"{v.requirement.label}: verdict"] = "PASS" if v.passed else "FAIL"
        if mc.requirements:
            j = self.joint()
            row.update({"all requirements: yield": j.estimate, "all requirements: CI": f"[{j.lo:.4f}, {j.hi:.4f}]"})
        stats_df = mc.statistics()
        for o in outputs:
            r = stats_df.loc[o]
            unit = r["unit"]
            row[f"{o} mean [{unit}]"] = r.get("mean")
            row[f"{o} std [{unit}]"] = r.get("std")
            row[f"{o} P99.865 [{unit}]"] = r.get("P99.865")
        asm = self.assembly
        if asm is not None:
            row["substituted"] = asm.substituted
            if asm.stock is not None:
                row["left over"] = int(asm.stock.leftover.sum())
        return row

    def summary(self, unit: str) -> dict:
        mc = self.mc
        out = {"case": self.label, "classes": self.k, "failed": int(mc.n - mc.ok.sum()),
               "requirements": [{"requirement": v.requirement.label, "yield": v.yield_.estimate,
                                 "yield_ci": [v.yield_.lo, v.yield_.hi], "passed": v.passed} for v in mc.verdicts()]}
        if mc.requirements:
            j = self.joint()
            out["joint_yield"] = j.estimate
            out["joint_yield_ci"] = [j.lo, j.hi]
        if self.classes is not None:
            out["limits"] = [float(v) for v in units.from_base(self.classes.edges[1:-1], unit)]
            out["limits_unit"] = unit
        asm = self.assembly
        if asm is not None:
            out["substituted"] = asm.substituted
            if asm.stock is not None:
                out["stock"] = {k: v.tolist() for k, v in (("made", asm.stock.made), ("wanted", asm.stock.wanted),
                                                           ("used", asm.stock.used), ("left_over", asm.stock.leftover))}
        return out


@dataclass
class Grading:
    """The assembly cases of a selective assembly (the last is the one shown in detail), the optimised limits
    (None unless searched) and what the report says of the setup."""

    part: GradedPart
    cases: list[Case]
    outputs: list[str]
    same_supply: bool                    # the supply is the graded factor's own distribution
    own: str                             # the spec's own distribution of the (first) graded factor
    model_outputs: tuple[str, ...]       # what each case evaluates
    stages: tuple[str, ...] | None       # the composed study's stages evaluated (None: one model)
    n: int                               # the study's samples
    confidence: float
    stock_ratio: float | None
    optimised: LimitOptimisation | None = None
    optimise_n: int | None = None
    has_requirements: bool = False
    notes: list[str] = field(default_factory=list)

    @property
    def chosen(self) -> Case:
        return self.cases[-1]

    @property
    def unit(self) -> str:
        return self.part.supply.factor.unit

    @property
    def rule(self) -> str:
        return "; ".join(f"{f}: {r.describe()}" for f, r in zip(self.part.factors, self.part.rules))

    def to_frame(self) -> pd.DataFrame:
        """One row per case: the yields with their intervals, verdicts, output statistics, stock."""
        return pd.DataFrame([c.row(self.outputs) for c in self.cases])

    def plot(self, which: str = "distributions", output: str | None = None):
        """``distributions`` of ``output`` without grading and with the chosen case, ``stock`` (the chosen
        case's balance), ``classes`` (the joint yield against the number of classes)."""
        from ..plotting.production import plot_graded_distributions, plot_stock_balance, plot_yield_against_classes

        chosen = self.chosen
        if which == "stock":
            s = chosen.assembly.stock
            return plot_stock_balance(np.arange(1, chosen.classes.k + 1), s.made, s.used, s.leftover)
        if which == "classes":
            ks, ests, los, his = [], [], [], []
            for c in self.cases:
                if c.label in NOT_ON_THE_CURVE:
                    continue
                j = c.joint()
                ks.append(c.k), ests.append(j.estimate), los.append(j.lo), his.append(j.hi)
            o_pt = None
            if self.optimised is not None:
                j = chosen.joint()
                o_pt = (chosen.k, j.estimate, j.lo, j.hi)
            return plot_yield_against_classes(ks, ests, los, his, optimised=o_pt,
                                              title="yield of all requirements together")
        first = self.cases[0].mc
        rs = [r for r in first.requirements if r.output == output]
        series = {c.label: c.mc.column(output) for c in self.cases if c.classes is None}
        series[chosen.label] = chosen.mc.column(output)
        return plot_graded_distributions(series, output=output, unit=first.unit_of(output),
                                         lower=next((r.lower for r in rs if r.lower is not None), None),
                                         upper=next((r.upper for r in rs if r.upper is not None), None))

    def summary(self) -> dict:
        return {"factors": list(self.part.factors), "supply": self.part.supply.factor.describe(), "rule": self.rule,
                "stock_ratio": self.stock_ratio, "cases": [c.summary(self.unit) for c in self.cases]}


def compare_grading(study_model, model, spec, part: GradedPart, classes, mc, evaluator, seed, *, outputs,
                    requirements, constants: dict | None = None, limits: Classes | None = None,
                    stock_ratio: float | None = None, optimise: dict | None = None) -> Grading:
    """The assembly cases (module docstring) of ``part`` on the study's samples ``mc.samples``.

    ``study_model``: the study's model (whose result ``mc`` is); ``model``: what each case evaluates (the
    study's model restricted to ``outputs``) with ``requirements`` on them; ``classes``: the numbers of
    equal-probability classes; ``constants``: design numbers a target reads; ``optimise``: ``{classes, n,
    max_evaluations}`` of the limit search, or None.
    """
    X = mc.samples.values
    env = {**named_values(model, spec, X), **(constants or {})}
    supply = part.supply
    same = all(supply.same_as(spec.factor(f)) for f in part.factors)

    def case(cls, label, k, as_drawn=False) -> Case:
        stock = None
        if cls is None:
            Xg = X if as_drawn else ungraded(X, spec, part)
            asm = None
        else:
            if stock_ratio is not None:
                stock = stock_batch(supply, stock_size(stock_ratio, len(X) * len(part.factors)), seed)
            asm = assemble(X, spec, part, cls, env, stock)
            Xg = asm.X
        if model is study_model and cls is None and np.array_equal(Xg, X):
            res = mc                                       # the study's own result: nothing to evaluate
        else:
            ev = evaluator(model, Xg, f"selective assembly: {label}")
            res = result_of(model, SampleSet(Xg, spec.names, spec.units, mc.samples.method, seed), ev, requirements,
                            mc.confidence)
        return Case(label, k, cls, res, asm)

    cases = [] if same else [case(None, "as drawn (spec)", 1, as_drawn=True)]
    cases.append(case(None, "no grading", 1))
    for k in classes:
        if k != 1:
            cases.append(case(Classes.equal_probability(supply, k), f"{k} equal-probability classes", k))
    if limits is not None:
        cases.append(case(limits, "proposed limits", limits.k))
    opt = None
    if optimise is not None:
        opt = search_limits(model, spec, part, constants or {}, requirements, mc.samples.method, evaluator, seed,
                            **optimise)
        cases.append(case(opt.classes, "optimised limits", opt.classes.k))
    return Grading(part, cases, list(outputs), same, spec.factor(part.factors[0]).describe(), model.output_names,
                   tuple(s.name for s in model.stages) if hasattr(model, "stages") else None, mc.n, mc.confidence, stock_ratio, opt,
                   optimise["n"] if optimise else None, bool(requirements))


def search_limits(model, spec, part: GradedPart, constants: dict, requirements, method: str, evaluator, seed, *,
                  classes: int, n: int, max_evaluations: int) -> LimitOptimisation:
    """The limits of ``classes`` classes that maximise the smoothed yield of all requirements on a design of
    ``n`` samples of its own (sub-stream ``selective_optimise``, unlimited supply)."""
    Xo = sample(spec, n, method, substream_seed(seed, "selective_optimise")).values
    env = {**named_values(model, spec, Xo), **constants}
    reqs = [r.in_unit(model.output(r.output).shown_unit) for r in requirements]
    outs = model.output_names
    base = result_of(model, SampleSet(Xo, spec.names, spec.units, "lhs", seed),
                     evaluator(model, ungraded(Xo, spec, part), "class limits: ungraded"))
    h = bandwidths(base.Y, base.ok, reqs, outs)

    def objective(cls: Classes) -> float:
        asm = assemble(Xo, spec, part, cls, env)
        r = result_of(model, SampleSet(asm.X, spec.names, spec.units, "lhs", seed),
                      evaluator(model, asm.X, "class limits"))
        return smoothed_yield(r.Y, r.ok, reqs, outs, h)

    return optimise_limits(objective, part.supply, classes, max_evaluations=max_evaluations)
