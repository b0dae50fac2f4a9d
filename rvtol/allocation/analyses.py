"""Study analysis ``allocation``: cost-optimal tolerances that still meet the requirements.

A thin adapter (:mod:`rvtol.analysis`): its options, one call of :func:`rvtol.allocation.allocate.allocate`,
the layout in :mod:`rvtol.allocation.texts`.  ``rvtol kinds allocation`` lists every key with its default
and meaning; an example::

    [[analysis]]
    kind = "allocation"
    costs = "../data/costs/bx40e_angular.toml"
    assign = { "*" = "ground_axis" }       # factor name, family, pattern or group, or "*" -> cost curve
    groups = ["Crankshaft 1", "..."]       # or factors = [...] (names, family templates, shell patterns) or
                                           # factors = "dependencies" (what a required output depends on)
    convex = "rss"                         # rss | worst_case | none
    [analysis.model]                       # optional: another model than the study's ([model] format)
    kind = "adjusted_assembly"
    [[analysis.requirement]]               # optional: else the study's requirements
    output = "delta_*"                     # a pattern expands to every matching output
    upper = 1.0
    [analysis.ga]
    n = 2000
    [analysis.verify]
    n = 20000
    [analysis.pareto]
    scales = [0.5, 0.75, 1.0, 1.5, 2.0]
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..analysis import Analysis, CommonOptions
from ..errors import InputError
from ..options import REQUIRED, option
from ..params import Params
from ..sampling import METHODS
from ..spec.requirements import RequirementTable, requirement_of
from . import texts
from .allocate import Plan, allocate, allocated_factors, allocation_problem, check_requirements_demonstrable
from .cost import load_costs
from .ga import HANDLING, GASettings


@dataclass
class GAOptions:
    constraint: str = option("monte_carlo", "the GA's constraint (none: no GA)",
                             choices=("monte_carlo", "linearised", "none"))
    n: int = option(2000, "Monte Carlo samples per candidate (one fixed design: common random numbers)", min=50)
    method: str = option("lhs", "sampling of that design", choices=METHODS)
    confirm: bool = option(False, "the cheapest candidate that also meets the requirements on a second, fresh design")
    population: int = option(40, "candidates per generation", min=4)
    generations: int = option(150, "generations", min=1)
    parents: int = option(20, "parents mating per generation", min=2)
    elitism: int = option(2, "best candidates kept as they are", min=0)
    mutation_probability: float = option(0.15, "probability of mutating a gene", min=0.0, max=1.0)
    handling: str = option("feasibility", "constraint handling (Deb's rules or a penalty)", choices=HANDLING)
    penalty: float = option(10.0, "penalty factor (handling = penalty)", positive=True)

    def complete(self, study, error):
        if self.confirm and self.constraint != "monte_carlo":
            raise error("confirm", "a confirmation sample needs the Monte Carlo constraint (constraint = \"monte_carlo\")")
        try:
            ga_settings(self)                       # GASettings checks the keys against each other
        except InputError as exc:
            raise error(exc.key, exc.reason) from None


def ga_settings(g: GAOptions) -> GASettings:
    """The GA's settings of the ``[analysis.ga]`` table (seed 0: :func:`.allocate.allocate` seeds each run)."""
    return GASettings(population=g.population, generations=g.generations, parents=g.parents, elitism=g.elitism,
                      mutation_probability=g.mutation_probability, handling=g.handling, penalty=g.penalty, seed=0)


@dataclass
class VerifyOptions:
    n: int = option(20000, "samples of the independent Monte Carlo check of each allocation", min=100)
    all_requirements: bool = option(False, "also check the cheapest verified allocation against every requirement "
                                           "of the study on the study's model")
    all_requirements_n: int = option(0, "its sample count (0: the study's n)", min=0)


@dataclass
class ParetoOptions:
    scales: list[float] = option([0.5, 0.75, 1.0, 1.5, 2.0], "requirement limits × f about the nominal output",
                                 positive=True)
    ga: bool = option(False, "also run the GA at each scale (expensive)")


@dataclass(frozen=True)
class AllocationPlan:
    """What an allocation analysis allocates: the problem (``study_problem``: the same with every requirement of the
    study, when it runs on the study's own model and spec; else None), what :func:`.allocate.allocate` runs
    (``methods``) and the cost–tolerance curves (``costs``)."""

    problem: object
    study_problem: object
    methods: Plan
    costs: object


def allocation_plan(o, study, error) -> AllocationPlan:
    """The cost curves, the model and spec (the study's or the table's own), the allocated factors and the
    requirements of an ``allocation`` table ``o``, made into the allocation problem."""
    table = load_costs(o.costs)
    spec, model = _model(o, study)
    names = None if o.factors == "dependencies" else allocated_factors(spec, o.factors, o.groups, error)
    reqs = _requirements(o.requirement, error) or list(study.requirements)
    if not reqs:
        raise error("requirement", "no requirement: give [[analysis.requirement]] or study requirements")
    try:
        problem = allocation_problem(model, spec, names, reqs, o.outputs, o.assign, table, o.tie, error)
        study_problem = (problem.with_requirements(list(study.requirements))
                         if model is study.model and spec is study.spec and study.requirements else None)
    except InputError as exc:     # a requirement's error carries its full key; the problem's get ours
        if exc.key and "[" in exc.key:
            raise
        raise error(exc.key, exc.reason) from None
    g, v = o.ga, o.verify
    if g.constraint == "monte_carlo":
        check_requirements_demonstrable(problem.requirements, g.n, lambda why: error("ga.n", why))
    if v.all_requirements and study_problem is None:
        raise error("verify.all_requirements", "needs the study's own model, spec and requirements")
    methods = Plan(o.convex, g.constraint, g.n, g.method, g.confirm, ga_settings(g), v.n, v.all_requirements,
                   v.all_requirements_n, tuple(o.pareto.scales), o.pareto.ga)
    return AllocationPlan(problem, study_problem, methods, table)


def _requirements(tables, error) -> list:
    """The requirements of the ``[[analysis.requirement]]`` tables (read by :class:`RequirementTable`), each
    located at its table: ``analysis[i].requirement[j]`` (the key the located error of ``requirement`` names)."""
    if not tables:
        return []
    where = error("requirement", "")
    return [requirement_of(t, where.file, f"{where.key}[{j}]") for j, t in enumerate(tables)]


def _model(o, study):
    """The spec and model the allocation works on: the study's, or the table's own ([analysis.model], spec)."""
    from ..registry import model_factory
    from ..spec import load_spec

    spec = load_spec(o.spec) if o.spec is not None else study.spec
    if o.model is None:
        return spec, study.model
    mp = o.model
    model = model_factory(mp.str("kind"), mp.file)(mp, study.design, spec)
    mp.finish()
    model.check_spec(spec)
    return spec, model


class AllocationAnalysis(Analysis):
    kind, title = "allocation", "Cost-optimal tolerance allocation"
    layout = texts.allocation

    @dataclass
    class Options(CommonOptions):
        costs: Path = option(REQUIRED, "the cost–tolerance curves (a TOML file of [[curve]] tables)")
        assign: dict[str, str] = option(REQUIRED, "factor name, family, shell pattern or group, or \"*\" -> the "
                                                  "name of its cost curve")
        spec: Path | None = option(None, "another spec than the study's (needs [analysis.model])")
        model: Params | None = option(None, "another model than the study's (a [model] table)")
        factors: list[str] | str | None = option(None, "the allocated factors: names, family templates (pins[k].d) "
                                                       "or shell patterns, or \"dependencies\" (every factor a "
                                                       "required output depends on); default: every factor")
        groups: list[str] | None = option(None, "or the factors of these spec groups", min_length=1)
        requirement: list[RequirementTable] = option([], "[[analysis.requirement]] tables (default: the study's "
                                                         "requirements)")
        outputs: list[str] | None = option(None, "only the requirements on outputs matching these patterns",
                                           min_length=1)
        convex: str = option("rss", "the linearised global optimum (cvxpy)", choices=("rss", "worst_case", "none"))
        tie: str = option("none", "drawing: one ±t per drawing callout (a position zone's coordinates, a per-pin "
                                  "family's copies)", choices=("none", "drawing"))
        ga: GAOptions = option(GAOptions, "the general optimiser (pygad)")
        verify: VerifyOptions = option(VerifyOptions, "the independent Monte Carlo check")
        pareto: ParetoOptions = option(ParetoOptions, "minimum cost against the requirement scale")

        def complete(self, study, error):
            if self.spec is not None and self.model is None:
                raise error("spec", "a spec of its own needs a model of its own ([analysis.model])")
            f = self.factors
            if f is not None and f != "dependencies":
                if not (isinstance(f, list) and all(isinstance(x, str) for x in f)):
                    raise error("factors", "expected an array of strings (or \"dependencies\")")
                if not f:
                    raise error("factors", "expected at least 1 strings, got 0")
            if self.convex == "none" and self.ga.constraint == "none":
                raise error("convex", "both optimisers are switched off")

    def prepare(self, o, study, error) -> AllocationPlan:
        return allocation_plan(o, study, error)

    def compute(self, ctx):
        """The :class:`~rvtol.allocation.Allocation` of this study (its ``by_method``: method ->
        :class:`~rvtol.allocation.AllocationResult`; an analysis that ``requires`` this one reads it from
        ``ctx.results``)."""
        p = self.plan
        return allocate(p.problem, plan=p.methods, costs=p.costs, evaluate=ctx.evaluator, executor=ctx.executor,
                        seed=ctx.seed, mc=ctx.mc, study_problem=p.study_problem)

    def report(self, result):
        from ..blocks import Section

        costs = Section(f"{self.key}_costs", f"{self.title}: cost–tolerance models", texts.costs(result, self.options),
                        result.costs_summary())
        return [costs, super().report(result)]

