"""What the production sections say: their prose and the layout of each result as report blocks.

``per_unit`` lays out a :class:`~rvtol.production.per_unit.UnitPredictions` (the per-unit prediction from
measured parts) with the analysis' options and plan (``per_unit(result, options, plan)``: the measured units, the
samples per unit, the outputs shown; ``per_serial`` likewise), ``selective`` a
:class:`~rvtol.production.grading.Grading` (selective assembly); the analyses (:mod:`rvtol.production.analyses`)
name them.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..blocks import Figure, Table, Text, figure_png
from .per_serial import CONFLICT_Z, ESS_MIN, R_HAT_MAX

# --------------------------------------------------------------------------- per-unit prediction
PER_UNIT = ("{units} reducers from the kit list {kits}; measured part families: {families}. Per reducer, {n} samples: "
            "each measured factor at its measured value plus a normal measurement error of its stated standard "
            "uncertainty, each unmeasured factor drawn from the spec (conditionally on the measured ones where the "
            "spec correlates them), one design for every reducer (sub-stream 'per_unit' of the study seed).\n\n"
            "Verdict per requirement (rvtol.verdict.judge_unit): the unit conforms when the probability that it "
            "meets the requirement reaches {probability} (on its lower confidence bound unless the requirement's "
            "basis is the estimate), does not conform when even the upper bound stays below, and is undecided in "
            "between; the unit's verdict is its worst. Result: {conforms} conform, {not_conform} do not conform, "
            "{undecided} undecided. ISO 14253-1 decision per requirement: the unit's predicted value y (mean of its "
            "samples) against the tolerance zone reduced (conformance proven) or enlarged (non-conformance proven) "
            "by U = {k:g}·u, u the samples' standard deviation; undecided in between. One row per reducer: {file} "
            "in the report folder.")
GAUGES = ("Gauge studies (crossed gauge R&R, ANOVA method, AIAG MSA 4th ed.; rvtol.production.msa): the features' "
          "standard uncertainty u = √(σ_GRR² + u_cal²), in the study's unit; interaction pooled into repeatability "
          "when its p-value exceeds the study's interaction_alpha; AIAG: %GRR < 10 % acceptable, 10–30 % "
          "conditionally, > 30 % unacceptable (of the tolerance when one is given); ndc = ⌊1.41·PV/GRR⌋")
POPULATION = "the yield the requirement asks of the population"
ONE_UNIT = "{p:g} (the study's conformance probability for one unit)"
TOO_FEW = ("Note: with n = {n} samples per unit no unit can be shown to conform on every requirement (that needs n ≥ "
           "{needed} with every sample conforming): the verdicts can only be 'does not conform' or 'undecided'.")
KITS = "Kits: the part serial in every slot ('-': not measured) and the number of measured factors"
VERDICTS = "Per-unit verdicts: probability of conformance P with its {confidence:.0%} interval"
PREDICTIONS = ("Per-unit predictions: median, mean, std and the {interval:.0%} prediction interval [lo, hi] (display "
               "units); failed: samples the model could not evaluate")
UNIT_PLOT = ("{output}: per-unit median and {interval:.0%} prediction interval, coloured by the unit's verdict on this "
             "output's requirement(s)")


def per_unit(res, o, p) -> list:
    units = p.units
    fams = ", ".join(f"{f.name} ({len(f.serials)} parts, {len(f.columns)} features, slots {', '.join(f.slots)})"
                     for f in units.families)
    counts = res.counts()
    blocks = [Text(PER_UNIT.format(
        units=len(units), kits=Path(units.kit_file).name, families=fams, n=p.n,
        probability=POPULATION if o.conformance_probability is None else ONE_UNIT.format(p=o.conformance_probability),
        conforms=counts["conforms"], not_conform=counts["does not conform"], undecided=counts["undecided"],
        k=res.coverage_factor, file=p.file))]
    if p.n < p.needed:
        blocks.append(Text(TOO_FEW.format(n=p.n, needed=p.needed)))
    outs = res.output_frame()
    outs = outs[outs["output"].isin(p.outputs)]
    gauges = units.gauge_frame()
    if gauges is not None:
        blocks.append(Table(gauges, GAUGES))
    blocks += [Table(units.to_frame(), KITS),
               Table(res.verdict_table(), VERDICTS.format(
                   confidence=res.requirements[0].confidence if res.requirements else 0.95)),
               Table(outs, PREDICTIONS.format(interval=o.interval))]
    blocks += [Figure(figure_png(res.plot(out)), UNIT_PLOT.format(output=out, interval=o.interval))
               for out in p.outputs]
    return blocks


# --------------------------------------------------------------------------- per-serial update
PER_SERIAL = ("{units} reducers from the kit list {kits} ({families}); {updated} with an end-of-line record in {eol} "
              "(read: {read}). The prior of each reducer is its per-unit prediction from its measured parts ({n} "
              "samples, as in the per-unit prediction); its end-of-line readings update it by Bayes' rule "
              "(rvtol.production.per_serial){method}\n\n"
              "Verdicts after the test (the probability of conformance as in the per-unit prediction; ISO 14253-1 "
              "guard bands at k = {k:g}): {conforms} conform, {not_conform} do not conform, {undecided} undecided "
              "(before the test: {before}). One row per reducer: {file} in the report folder.")
BY_FACTORS = (": the coordinates inferred are the {hidden} factors with the largest share "
              "of the readings' variance and the directions along which all the other factors move the readings "
              "(estimated on the batch's prior samples); a quadratic surrogate of each unit's readings in them, fitted "
              "on its prior samples, carries its cross-validated error into the likelihood beside the readings' own "
              "uncertainty; emcee's ensemble sampler ({chains} ensembles of {walkers} walkers, {steps} "
              "steps, the first half discarded). The posterior prediction is the study's model itself at {n} "
              "posterior draws (the other factors as in the prior: common random numbers). A unit is converged when "
              "every split-R̂ ≤ {r_hat} and every effective sample size ≥ {ess}; a unit that is not is undecided.")
BY_OUTPUTS = (", in the model's own outputs: each reducer's prior samples are moved by the ensemble Kalman analysis "
              "on its readings (y' = y + K(y_obs + ε − d), K = C_yd (C_dd + R)⁻¹ from its samples, ε ~ N(0, R) with "
              "the readings' uncertainty) — no factor-level surrogate and no sampler; exact for jointly normal "
              "outputs, their linear-Gaussian approximation otherwise. The factors are moved the same way (the table "
              "of the factors each test narrowed most).")
UPDATES = ("Per updated reducer: the readings, the surrogate's cross-validated residual s against the reading's "
           "uncertainty u_obs (the likelihood's σ = √(u_obs² + s²)) and its R², the sampler's diagnostics and time")
FACTORS = ("The factors each test narrowed most: the prior and the posterior median and {interval:.0%} interval (the "
           "factor's unit) and the ratio of the interval widths")
CONFLICT = ("Readings the reducer's prior cannot produce — more than {k:g} standard deviations of its prior prediction "
            "(the prior samples' spread and the reading's uncertainty together) from its mean: {units}. Such a reducer is not what its measured parts and the spec say (a part "
            "mis-measured, a serial mixed up, a fault the model does not have); its verdict is undecided.")
WEAK_SURROGATE = ("Note: the surrogate explains at most {r2:.0%} of a reading's variance within a unit (cross-validated "
                  "R², median over the readings and units {median:.0%}): the readings depend on more factors, or less "
                  "smoothly, than a quadratic in {d} coordinates follows, so the test narrows the prediction little — "
                  "the surrogate's error is in the likelihood, so the posterior stays calibrated, not sharp. The "
                  "readings themselves (the 'measured' column) are the unit's best figures for what was read.")
SERIAL_OUTPUTS = ("Per reducer and output: the end-of-line reading, the prior and the posterior median and "
                  "{interval:.0%} prediction interval (display units), the ratio of the interval widths")
SERIAL_PLOT = ("{output}: per reducer the prior interval (from its measured parts), the interval after its end-of-line "
               "test and the reading")


def per_serial(res, o, p) -> list:
    units = p.units
    fams = ", ".join(f"{f.name}: {len(f.serials)} parts" for f in units.families)
    counts, before = res.counts(), res.prior.counts()
    method = BY_OUTPUTS if o.update == "outputs" else BY_FACTORS.format(
        n=p.n, hidden=o.hidden, chains=o.chains, walkers=o.walkers, steps=o.steps, r_hat=R_HAT_MAX, ess=ESS_MIN)
    blocks = [Text(PER_SERIAL.format(
        units=len(units), kits=Path(units.kit_file).name, families=fams, updated=len(res.updates),
        eol=Path(res.eol.file).name, read=", ".join(f"{q} [{u}] ± {s:.3g}" for q, u, s in
                                                    zip(res.eol.outputs, res.eol.units, res.eol.uncertainty)),
        n=p.n, method=method, k=res.posterior.coverage_factor, conforms=counts["conforms"], not_conform=counts["does not conform"],
        undecided=counts["undecided"], before=", ".join(f"{v} {k}" for k, v in before.items()), file=p.file))]
    if p.n < p.needed:
        blocks.append(Text(TOO_FEW.format(n=p.n, needed=p.needed)))
    conflicts = [f"{u} ({', '.join(up.conflict)})" for u, up in res.updates.items() if up.conflict]
    if conflicts:
        blocks.append(Text(CONFLICT.format(units="; ".join(conflicts), k=CONFLICT_Z)))
    r2 = [r for up in res.updates.values() for r in up.surrogate_r2]      # (none with update = "outputs")
    if r2 and max(r2) < 0.5:
        blocks.append(Text(WEAK_SURROGATE.format(r2=max(r2), median=float(np.median(r2)),
                                                 d=len(next(iter(res.updates.values())).hidden))))
    blocks += [Table(res.update_frame(), UPDATES),
               Table(res.factor_frame(), FACTORS.format(interval=o.interval)),
               Table(res.posterior.verdict_table(), VERDICTS.format(
                   confidence=res.posterior.requirements[0].confidence if res.posterior.requirements else 0.95)),
               Table(res.output_frame(), SERIAL_OUTPUTS.format(interval=o.interval))]
    blocks += [Figure(figure_png(res.plot(out)), SERIAL_PLOT.format(output=out)) for out in p.outputs]
    return blocks


# --------------------------------------------------------------------------- selective assembly
SETUP = ("Graded: {factors} (one part per factor and reducer). Supply before grading: {supply}{other}. Matching rule: "
         "{rule}. Simulated inside the Monte Carlo on the study's {n} samples (common random numbers: only the "
         "graded factor changes); evaluated: {outputs}{stages}. {stock}")
OTHER_SUPPLY = (" ({source}; the spec's own distribution is {own}, the case 'as drawn'; 'no grading' picks parts at "
                "random from this supply)")
UNLIMITED = "Unlimited supply: each part is drawn from the supply within its class."
FINITE = ("Finite stock: a graded batch of {ratio:g} parts per part used (sub-stream 'selective_stock'); a reducer "
          "whose class is empty takes the class whose centre is nearest its target, and the parts left over are "
          "counted per class.")
CASES = ("Assembly cases: yield of every requirement and of all together with its {confidence:.0%} interval, verdict "
         "(rvtol.verdict.judge), output statistics")
CLASSES = "Classes of the case '{label}' (limits in {unit}; the outer ones at the supply's support)"
STOCK = ("Stock balance of '{label}': parts made per class, wanted by the rule, used, left over ({substituted} "
         "substituted)")
AGAINST_CLASSES = ("The number of classes against the gain: yield of all requirements together, with its interval")
OPTIMISED = ("Optimised limits of {k} classes: Nelder–Mead over the classes' cumulative probabilities from equal "
             "probabilities, on a design of {n} samples of its own (sub-stream 'selective_optimise', unlimited "
             "supply), maximising the yield of all requirements with the indicator smoothed by a normal kernel "
             "(Silverman bandwidth of the ungraded outputs): {start:.4f} at equal probabilities → {best:.4f} after "
             "{evaluations} evaluations ({message}). The row 'optimised limits' above checks them on the study's "
             "samples.")


def selective(res, o) -> list:
    supply = res.part.supply
    other = "" if res.same_supply else OTHER_SUPPLY.format(source=supply.factor.source or "given in the study",
                                                           own=res.own)
    stages = f" (the stages {', '.join(res.stages)})" if res.stages is not None else ""
    stock = UNLIMITED if res.stock_ratio is None else FINITE.format(ratio=res.stock_ratio)
    chosen = res.chosen
    blocks = [Text(SETUP.format(factors=", ".join(res.part.factors), supply=supply.factor.describe(), other=other,
                                rule=res.rule, n=res.n, outputs=", ".join(res.model_outputs), stages=stages,
                                stock=stock)),
              Table(res.to_frame(), CASES.format(confidence=res.confidence)),
              Table(chosen.classes.describe(res.unit, supply), CLASSES.format(label=chosen.label, unit=res.unit))]
    asm = chosen.assembly
    if asm is not None and asm.stock is not None:
        blocks += [Table(asm.stock.to_frame(), STOCK.format(label=chosen.label, substituted=asm.stock.substituted)),
                   Figure(figure_png(res.plot("stock")), f"Stock balance of '{chosen.label}'")]
    blocks += [Figure(figure_png(res.plot("distributions", out)), f"{out}: without grading and with '{chosen.label}'")
               for out in res.outputs]
    if res.has_requirements:
        blocks.append(Figure(figure_png(res.plot("classes")), AGAINST_CLASSES))
    opt = res.optimised
    if opt is not None:
        blocks.append(Text(OPTIMISED.format(k=opt.classes.k, n=res.optimise_n, start=opt.start, best=opt.best,
                                            evaluations=opt.evaluations, message=opt.message)))
    return blocks
