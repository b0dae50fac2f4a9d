"""What the allocation sections say: their prose and the layout of an :class:`~rvtol.allocation.allocate.Allocation`
as report blocks (:mod:`rvtol.blocks`: Text, Table, Figure).

``costs`` lays out the cost–tolerance models section, ``allocation`` the allocation itself; the analysis
(:mod:`rvtol.allocation.analyses`) names them.
"""
from __future__ import annotations

from ..blocks import Figure, Table, Text, figure_png

INTRO = ("Minimise Σ C_i(t_i) over {n} tolerances ±t_i of model {model} subject to the requirements below and the "
         "cost curves' ranges t_min ≤ t ≤ t_max. Changing t_i rescales factor i's distribution about its centre. "
         "Uniform: the spec's tolerances times the largest common factor that meets the constraint ({constraint}). ")
CONVEX = "Convex: cvxpy global optimum of the {linearised} (five-point gradient at nominal). "
GA = "GA: pygad, {population} × {generations} generations, {handling} rules, constraint {constraint}. "
CHECK = ("Every allocation is checked by an independent Monte Carlo run (n = {n}, plain random sampling, its own "
         "seed).")

TIES = ("One ±t per drawing tolerance: {callouts} callouts stand for {factors} factors (coordinates of a position "
        "zone, copies of a per-part family) and share their tolerance, so {free} tolerances are optimised for "
        "{all} factors.")

NOT_CONFIRMED = ("Not confirmed by the independent Monte Carlo run: {methods}. An allocation that sits exactly on its "
                 "constraint passes a fresh sample only about half the time on the estimate and rarely on a lower "
                 "confidence bound; the linearised RSS constraint also assumes a normal output centred on its "
                 "nominal value (one-sided factors whose mean moves with their tolerance, skewed or bounded "
                 "distributions and non-linear models break that). The GA's Monte Carlo constraint uses the "
                 "requirement's own basis, so its allocation carries the sampling margin.")

CHECKS = ("Independent Monte Carlo check (n = {n}, plain random, seed {seed}): requirements met, and the worst output "
          "(full tables in summary.json)")

SPREAD = ("First-order spread at the nominal against the study's Monte Carlo (the linearised methods need a ratio "
          "within [0.5, 2])")

NONE_VERIFIED = ("No allocation passed its own independent Monte Carlo check, so none is checked against every "
                 "requirement of the study.")

ALL = ("{method} (the cheapest allocation its own check passed) against every requirement of the study (the study's "
       "model, n = {n}): what the allocation did not optimise for, and the set-aside requirements; 'yield at the "
       "spec' is the study's Monte Carlo at the present tolerances. On the requirements it allocated for, the "
       "independent check above (its own n) decides: a smaller n here may leave a yield undemonstrated by a single "
       "failing sample")

LOWERED = ("The {method} allocation LOWERS the yield of requirements it was not asked to meet (by more than two "
           "standard errors of the difference): {which}. It changes tolerances these outputs also depend on: "
           "loosening one widens their spread, and where the nominal lies outside a limit even tightening lowers "
           "the yield (the units move toward the nominal). Adopt it only together with those requirements' own fix "
           "(their design levers).")

SET_ASIDE = ("Set aside (the NOMINAL design misses them, so no tolerance can meet them; their design levers follow): "
             "{which}. The tolerances above are allocated against the other requirements.")

LEVERS = ("Where the NOMINAL design already lies on or outside a requirement's limit, scaling tolerances cannot help: "
          "as every tolerance shrinks, every reducer approaches the nominal one (where the Monte Carlo mean lies on "
          "the passing side of a limit the nominal misses, the present yield comes from the spread itself and "
          "tightening lowers it). The tables below give the design levers to first order: the shift of one drawing "
          "nominal (every copy of a family alike) that alone moves the output from {base} to the limit minus z·σ "
          "({constraint}), ranked by the output change of a shift by one tolerance half-band t; the slope is the "
          "five-point derivative at the nominal. A direction and a size for a design change: the top lever of each "
          "is checked below by a Monte Carlo run of the shifted design, where a linear step can miss.")
FROM_MC = "the Monte Carlo mean and σ of the study"
FROM_NOMINAL = "the nominal output and the linearised σ"
LEVERS_CHECKED = ("The top lever of each, checked: a Monte Carlo run of the study's spec with that one drawing nominal "
                  "shifted (every other tolerance as it is)")


def costs(res, o) -> list:
    t = res.costs
    return [
        Text(f"Cost data: {t.file} — {t.description}. {t.source}. Sources: "
             + "; ".join(f"{c.name}: {c.source}" for c in res.curves) + "."),
        Table(res.curves_frame(), "Cost–tolerance curves used (t: tolerance half-band ±t)", "{:.4g}"),
        Figure(figure_png(res.plot("costs")), "Cost–tolerance curves and their data"),
    ]


def allocation(res, o) -> list:
    p, plan = res.problem, res.plan
    intro = INTRO.format(n=len(p.factors), model=res.model_label, constraint=res.constraint)
    if plan.convex != "none":
        intro += CONVEX.format(linearised=res.linearised)
    if res.ga_constraint is not None:
        intro += GA.format(population=plan.ga.population, generations=plan.ga.generations, handling=plan.ga.handling,
                           constraint=res.ga_constraint)
    blocks = [Text(intro + CHECK.format(n=plan.verify_n)),
              Table(res.requirements_frame(), "Requirements on the model outputs", "{:.4g}")]
    if p.ties:
        blocks.append(Text(TIES.format(callouts=len(p.ties), factors=sum(len(g) for g in p.ties), free=len(p.free),
                                       all=len(p.factors))))
    blocks.append(Table(res.to_frame(), "Allocated tolerances ±t per factor (factor units)", "{:.4g}"))
    cax = res.component_axis()
    if cax is not None:
        blocks.append(Table(cax, f"{res.results[-1].method}: tolerance per component and axis", "{:.3g}"))
    blocks.append(Table(res.methods_frame(), "Total cost against the uniform-tolerance baseline", "{:.4g}"))
    blocks += [Text(f"{r.method}: {note}") for r in res.results for note in r.notes]
    if res.failed_checks:
        blocks.append(Text(NOT_CONFIRMED.format(methods=", ".join(res.failed_checks))))
    if res.checks:
        v0 = next(iter(res.checks.values()))
        blocks.append(Table(res.checks_frame(), CHECKS.format(n=v0.n, seed=v0.seed), "{:.4g}"))
    blocks.append(Figure(figure_png(res.plot("tolerances")), "Allocated tolerances against the uniform baseline"))
    ga = res.by_method.get("GA")
    if ga is not None and ga.history:
        blocks.append(Figure(figure_png(res.plot("ga")), "GA convergence"))
    if res.pareto is not None:
        blocks += [Table(res.pareto.to_frame(), f"Minimum total cost [{res.cost_unit}] against the requirement "
                                                "(limits × scale about the nominal output)", "{:.4g}"),
                   Figure(figure_png(res.pareto.plot()), "Cost against requirement (Pareto front)")]
    if res.spread is not None:
        blocks.append(Table(res.spread, SPREAD, "{:.4g}"))
    a = res.all_check
    if a is not None:
        if a.frame is None:
            blocks.append(Text(NONE_VERIFIED))
        else:
            blocks.append(Table(a.frame, ALL.format(method=a.method, n=a.n), "{:.4g}"))
            if a.lowered:
                blocks.append(Text(LOWERED.format(method=a.method, which="; ".join(a.lowered))))
    if res.set_aside:
        blocks.append(Text(SET_ASIDE.format(which="; ".join(f"{r.label} ({r.output})" for r in res.set_aside))))
    if res.levers is not None:
        blocks += levers(res.levers)
    return blocks


def levers(lv) -> list:
    base = FROM_MC if lv.measured_from_mc else FROM_NOMINAL
    return [Text(LEVERS.format(base=base, constraint=lv.describe)),
            Table(lv.stand, f"Where the requirements the nominal misses stand (the levers are measured from {base})",
                  "{:.4g}"),
            *[Table(frame, f"Design levers for: {label}", "{:.4g}") for label, frame in lv.levers.items()],
            Table(lv.checked, LEVERS_CHECKED, "{:.4g}")]

