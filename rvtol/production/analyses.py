"""Study analyses ``per_unit_prediction``, ``per_serial_update`` and ``selective_assembly``.

Thin adapters (:mod:`rvtol.analysis`): their options, one call of
:func:`rvtol.production.per_unit.predict_units` or :func:`rvtol.production.grading.compare_grading`, the
layout in :mod:`rvtol.production.texts`.  ``rvtol kinds KIND`` lists every key with its default and
meaning; examples::

    [[analysis]]
    kind = "per_unit_prediction"
    kits = "measured/kits.csv"      # the kit list (rvtol.production.measured_parts)
    [[analysis.parts]]              # one table per part family
    file = "measured/crankshafts.csv"
    slots = ["crank_1", "crank_2", "crank_3"]
    [[analysis.parts.gauge]]        # optional: a feature's uncertainty from a gauge R&R study (rvtol.production.msa)
    file = "measured/cmm_grr.csv"
    features = ["cam_1.form"]
    [[analysis.parts]]              # or the inspection room's QIF 3.0 / DFQ file with a mapping
    file = "measured/discs.qif"
    mapping = "measured/discs_map.csv"
    slots = ["disc_1", "disc_2"]

    [[analysis]]
    kind = "per_serial_update"      # the same keys, and each reducer's end-of-line test (rvtol.production.per_serial)
    end_of_line = "measured/end_of_line.csv"

    [[analysis]]
    kind = "selective_assembly"
    factor = "pins.diameter_lot"    # the graded part's size (or factors = [...])
    target = "..."                  # the matching rule: a target size (or match = "hole.size": class to class)
    classes = [2, 3, 4]
    [analysis.supply]               # optional: the parts' size before grading, as a [[factor]] (no name)
    [analysis.optimise]             # optional: search the limits of `classes` classes
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import units
from ..analysis import Analysis, CommonOptions
from ..design import design_numbers
from ..errors import InputError
from ..expressions import Expression
from ..options import REQUIRED, option
from ..registry import curve_reader
from ..params import Params
from ..spec import factor_from_params
from . import texts
from .grading import compare_grading
from .measured_parts import FamilySource, load_measured_units
from .msa import INTERACTION_ALPHA, Gauge, read_gauge_study
from .per_serial import (CHAINS, HIDDEN, STEPS, UPDATES, WALKERS, check_serials, min_samples, posterior_draws,
                         read_end_of_line,
                         read_end_of_line_curves, update_serials)
from .per_unit import predict_units, samples_to_demonstrate
from .selective import Classes, ClassToClassRule, GradedPart, Supply, TargetRule, known_names


@dataclass
class ProductionOptions(CommonOptions):
    """The keys both analyses take: a name (two of a kind) and the outputs shown."""

    name: str = option("", "section key <kind>_<name> (give one to run the kind twice)")
    outputs: list[str] | None = option(None, "the outputs shown (default: those the requirements name, else all)",
                                       names="outputs", min_length=1)

    def complete(self, study, error):
        kind = self.KIND
        if getattr(study, "build", None) is not None:    # the build would choose the fitted parts again per sample
            raise error("kind", f"this analysis {self.BUILT}; the study's build would choose those parts again: give "
                                "[study] build = false")
        self.key = self.key or (f"{kind}_{self.name}" if self.name else kind)
        if any(getattr(a, "key", None) == self.key for a in study.analyses):
            raise error("name", f"two analyses with the key {self.key!r}: give each a name")


@dataclass(frozen=True)
class ProductionPlan:
    """The outputs shown (the table's, else those the requirements name, else all), the study's model restricted to
    them (a composed study evaluates only the stages they need) and the requirements on them that judge a single
    unit (a population statistic's band, a catalogue's typical value, judges none)."""

    outputs: list[str]
    model: object
    requirements: list


def _shown(o: ProductionOptions, study) -> tuple[list[str], object, list]:
    """:class:`ProductionPlan`'s fields for the table ``o``."""
    outputs = o.outputs or list(dict.fromkeys(r.output for r in study.requirements)) or list(study.model.output_names)
    model = study.model
    if hasattr(model, "restricted") and set(outputs) != set(model.output_names):
        model = model.restricted(outputs)
    return outputs, model, [r for r in study.requirements if r.output in outputs and r.per_unit]


@dataclass
class GaugeOptions:
    file: Path = option(REQUIRED, "the gauge R&R study (part, appraiser, [trial,] value [unit]: one reading per row)")
    features: list[str] = option(REQUIRED, "the part family's feature columns it measures (their u = σ_GRR)",
                                 min_length=1)
    calibration_u: float = option(0.0, "standard uncertainty (k = 1) of the gauge's calibration, in the gauge "
                                       "study's unit: u = √(σ²_GRR + calibration_u²)", nonnegative=True)
    tolerance: float | None = option(None, "the features' tolerance width USL − LSL in the gauge study's unit "
                                           "(%GRR of the tolerance)", positive=True)
    interaction_alpha: float = option(INTERACTION_ALPHA, "the part × appraiser interaction is pooled into "
                                                         "repeatability when its p-value exceeds this", min=0.001,
                                      max=0.999)


def gauge_of(g: GaugeOptions) -> Gauge:
    """The gauge a ``[[analysis.parts.gauge]]`` table names: its gauge R&R study read and analysed."""
    return Gauge(read_gauge_study(g.file, tolerance=g.tolerance, interaction_alpha=g.interaction_alpha),
                 tuple(g.features), g.calibration_u)


@dataclass
class PartsOptions:
    file: Path = option(REQUIRED, "the part family's file (one row per serial number)")
    slots: list[str] = option(REQUIRED, "the places its parts take (factor = <slot>.<column>)", min_length=1)
    name: str | None = option(None, "the family's name (default: the file's stem)")
    mapping: Path | None = option(None, "a QIF (.qif, .xml) or DFQ (.dfq) file's mapping: characteristic -> feature, "
                                        "reading, unit, u (rvtol.inputs.inspection)")
    gauge: list[GaugeOptions] | None = option(None, "[[analysis.parts.gauge]]: gauge studies giving features' "
                                                    "measurement uncertainty", min_length=1)


# --------------------------------------------------------------------------- per-unit prediction
@dataclass(frozen=True)
class PerUnitPlan(ProductionPlan):
    """And the measured units (kits and part families read), the samples per unit that can show a unit conforms
    (``needed``) and those drawn (``n``: the table's, else ``needed``), the file of one row per unit and the files
    read (``inputs``, recorded in summary.json)."""

    units: object
    needed: int
    n: int
    file: str
    inputs: dict


def per_unit_plan(o, study, error) -> PerUnitPlan:
    """The :class:`PerUnitPlan` of a ``per_unit_prediction`` table ``o``."""
    outputs, model, requirements = _shown(o, study)
    units = load_measured_units(study.spec, o.kits, [
        FamilySource(p.file, tuple(p.slots), p.name, tuple(gauge_of(g) for g in p.gauge or ()), p.mapping)
        for p in o.parts])
    try:
        needed = samples_to_demonstrate(requirements, o.conformance_probability)
    except ValueError as exc:       # a requirement that asks for P = 1 of one unit
        raise error("conformance_probability", f"{exc}: give a conformance_probability < 1") from None
    return PerUnitPlan(outputs, model, requirements, units, needed, o.n if o.n is not None else needed,
                       f"per_unit_{o.name}.csv" if o.name else "per_unit.csv",
                       {f"{o.key}:{k}": v for k, v in units.files().items()})


class PerUnitPrediction(Analysis):
    kind, title = "per_unit_prediction", "Per-unit prediction from measured parts"
    layout = texts.per_unit

    @dataclass
    class Options(ProductionOptions):
        KIND = "per_unit_prediction"
        BUILT = "predicts units that are built already (their fitted parts are measured)"
        kits: Path = option(REQUIRED, "the kit list: which serial parts form which reducer")
        parts: list[PartsOptions] = option(REQUIRED, "[[analysis.parts]]: one table per measured part family",
                                           min_length=1)
        conformance_probability: float | None = option(None, "the probability of conformance a unit must show "
                                                             "(default: each requirement's yield)", min=0.5,
                                                       max=0.999999)
        n: int | None = option(None, "samples per unit (default: the n at which a unit can be shown to conform)",
                               min=2)
        interval: float = option(0.95, "central prediction interval shown per output", min=0.5, max=0.9999)
        coverage_factor: float = option(2.0, "k of the expanded uncertainty U = k·u of the ISO 14253-1 decision "
                                             "per unit (conformance / non-conformance proven / undecided)",
                                        min=1.0, max=6.0)

        def complete(self, study, error):
            super().complete(study, error)
            self.title = self.title or (f"{PerUnitPrediction.title}: {self.name}" if self.name else None)

    def prepare(self, o, study, error) -> PerUnitPlan:
        return per_unit_plan(o, study, error)

    def compute(self, ctx):
        o, p = self.options, self.plan
        return predict_units(p.model, ctx.spec, p.units, p.n, evaluator=ctx.evaluator, requirements=p.requirements,
                             method=ctx.options.method, seed=ctx.seed, interval=o.interval,
                             probability=o.conformance_probability, coverage_factor=o.coverage_factor)

    def blocks(self, result) -> list:
        return type(self).layout(result, self.options, self.plan)

    def summary(self, result):
        p = self.plan
        gauges = [{"family": f.name, "features": list(g.features), "u": g.u, "calibration_u": g.calibration_u,
                   **g.result.summary()} for f in p.units.families for g in f.gauges]
        return {**result.summary(), "n_to_demonstrate": p.needed, "file": p.file,
                **({"gauges": gauges} if gauges else {})}

    def files(self, result):
        return {self.plan.file: result.unit_frame().to_csv(index=False)}


# --------------------------------------------------------------------------- per-serial update
@dataclass(frozen=True)
class PerSerialPlan(PerUnitPlan):
    """And the end-of-line records read (its outputs are among ``outputs``: the readings' outputs are evaluated
    too)."""

    eol: object


def per_serial_plan(o, study, error) -> PerSerialPlan:
    """The :class:`PerSerialPlan` of a ``per_serial_update`` table ``o``: the per-unit plan, the end-of-line
    records (a table or a folder of curves) checked against the units, and the samples per unit the update needs."""
    unit = per_unit_plan(o, study, error)
    if o.curves is not None:
        try:
            eol = read_end_of_line_curves(o.curves, o.curve_outputs, study.model, o.percent, figures=curve_reader())
        except InputError as exc:
            if exc.file is not None:        # a curve file's own error names that file
                raise
            raise error(exc.key, exc.reason) from None      # a key of this analysis: located as such
    else:
        eol = read_end_of_line(o.end_of_line, study.model)
    check_serials(eol, unit.units)
    outputs, model = unit.outputs, unit.model
    extra = [out for out in eol.outputs if out not in outputs]
    if extra:                                   # the readings' outputs are evaluated too
        outputs = outputs + extra
        model = study.model.restricted(outputs) if hasattr(study.model, "restricted") else study.model
    d = min(o.hidden, len(study.spec)) + len(eol.outputs)
    need = min_samples(d) if o.update == "factors" else len(eol.outputs) + 2
    if o.n is not None and o.n < need:
        raise error("n", f"{o.n} samples per unit: the surrogate in {d} coordinates ({o.hidden} hidden "
                         f"factors, {len(eol.outputs)} readings' directions) is fitted on the prior samples "
                         f"and needs n >= {need}")
    n = max(unit.n, need)
    if o.update == "factors" and posterior_draws(o.walkers, o.steps, o.chains) < n:
        raise error("n", f"{n} posterior draws per unit, the sampler keeps "
                         f"{posterior_draws(o.walkers, o.steps, o.chains)} (chains · walkers · "
                         "steps/2): give more steps or walkers, or a smaller n")
    inputs = {**unit.inputs, f"{o.key}:end_of_line": {"path": eol.file, "sha256": eol.sha256}}
    return PerSerialPlan(outputs, model, unit.requirements, unit.units, unit.needed, n, unit.file, inputs, eol)


class PerSerialUpdate(PerUnitPrediction):
    kind, title = "per_serial_update", "Per-serial update from the end-of-line test"
    layout = texts.per_serial

    @dataclass
    class Options(PerUnitPrediction.Options):
        KIND = "per_serial_update"
        end_of_line: Path | None = option(None, "the end-of-line test records: reducer, <output> [unit], ...; a row "
                                                "'uncertainty' (rvtol.production.per_serial.read_end_of_line)")
        curves: Path | None = option(None, "or a folder of hysteresis curves, <reducer>.csv (torque, angle, sigma; "
                                           "0 → +T → −T → 0), read by the maker's definitions")
        curve_outputs: dict[str, str] | None = option(None, "with curves: figure (lost_motion, backlash, rigidity, "
                                                            "rigidity_50_100) -> the study output it is")
        percent: float = option(3.0, "with curves: the lost motion's torque, % of the curve's largest", min=0.1,
                                max=50.0)
        update: str = option("factors", "how the test updates a unit: 'factors' infers its factors (surrogate and "
                                        "emcee; the model at the posterior draws), 'outputs' the ensemble Kalman update "
                                        "of its prior samples on the readings (no surrogate; linear-Gaussian)",
                             choices=UPDATES)
        hidden: int = option(HIDDEN, "factors inferred one by one (the largest share of the readings' variance); the "
                                     "others through the directions the readings see (rvtol.production.per_serial)",
                             min=0, max=8)
        walkers: int = option(WALKERS, "walkers of each emcee ensemble (at least 2·hidden + 2)", min=4)
        steps: int = option(STEPS, "steps of each ensemble; the first half is discarded", min=100)
        chains: int = option(CHAINS, "independent ensembles (the split-R̂ compares them)", min=2, max=16)

        def complete(self, study, error):
            self.title = self.title or (f"{PerSerialUpdate.title}: {self.name}" if self.name else None)
            super().complete(study, error)          # after: the prediction's own default title would come first
            if (self.end_of_line is None) == (self.curves is None):
                raise error("end_of_line", "give end_of_line (a table of readings) or curves (a folder of curves)")
            if self.curves is not None and not self.curve_outputs:
                raise error("curve_outputs", "curves need curve_outputs: the study output of each figure")

    def prepare(self, o, study, error) -> PerSerialPlan:
        return per_serial_plan(o, study, error)

    def compute(self, ctx):
        o, p = self.options, self.plan
        return update_serials(p.model, ctx.spec, p.units, p.eol, p.n, evaluator=ctx.evaluator,
                              requirements=p.requirements, method=ctx.options.method, seed=ctx.seed,
                              interval=o.interval, probability=o.conformance_probability,
                              coverage_factor=o.coverage_factor, update=o.update, hidden=o.hidden,
                              walkers=o.walkers, steps=o.steps,
                              chains=o.chains, progress=ctx.evaluator.progress)


# --------------------------------------------------------------------------- selective assembly
@dataclass
class OptimiseOptions:
    classes: int = option(3, "the number of classes whose limits are searched", min=2, max=20)
    n: int = option(300, "size of the search's own design (sub-stream selective_optimise)", min=20)
    max_evaluations: int = option(40, "model evaluations of the search (Nelder–Mead)", min=2)


@dataclass(frozen=True)
class SelectivePlan(ProductionPlan):
    """And the graded part (factors, supply, matching rules), the design numbers its target expressions name
    (``constants``) and the proposed grading of ``limits`` (None: none)."""

    part: GradedPart
    constants: dict
    grading: Classes | None


def selective_plan(o, study, error) -> SelectivePlan:
    """The :class:`SelectivePlan` of a ``selective_assembly`` table ``o`` (its keys checked by ``complete``)."""
    outputs, model, requirements = _shown(o, study)
    spec = study.spec
    names = _one_or_many(o.factor, o.factors, "factor", "factors", error)
    supply = Supply(spec.factor(names[0]))
    if o.supply is not None:
        o.supply.data.setdefault("name", names[0])
        supply = Supply(factor_from_params(o.supply))
    for f in names:
        if units.dimension(spec.factor(f).unit) != units.dimension(supply.factor.unit):
            raise error("supply", f"the supply's unit {supply.factor.unit!r} does not fit factor {f!r}")
    targets = _one_or_many(o.target, o.targets, "target", "targets", error)
    constants = {}
    if targets is not None:
        rules = _target_rules(o, study, names, targets, constants, error)
    else:
        rules = _match_rules(o, spec, names, _one_or_many(o.match, o.match_factors, "match", "match_factors", error),
                             error)
    try:
        part = GradedPart(tuple(names), supply, tuple(rules))
    except ValueError as exc:
        raise error("target" if targets is not None else "match", str(exc)) from None
    grading = None
    if o.limits is not None:
        try:
            grading = Classes.from_limits(units.to_base(np.asarray(o.limits), supply.factor.unit))
        except ValueError:
            raise error("limits", f"class limits must increase strictly, got {o.limits}") from None
        p = grading.probabilities(supply)
        if np.any(p <= 0):
            raise error("limits", f"class {int(np.argmin(p)) + 1} holds no part of the supply "
                                  f"({supply.factor.describe()})")
    if o.optimise is not None and not requirements:
        raise error("optimise", "optimising the class limits needs requirements on the outputs (the yield)")
    return SelectivePlan(outputs, model, requirements, part, constants, grading)


def _target_rules(o, study, names, targets, constants: dict, error) -> list:
    """The target rule of each graded factor; the design numbers the expressions name go into ``constants``."""
    key = "targets" if o.targets is not None else "target"
    if len(targets) != len(names):
        raise error(key, f"{len(targets)} targets for {len(names)} graded factors")
    known = known_names(study.model, study.spec)
    rules = []
    for t in targets:
        try:
            e = Expression.parse(t)
            constants.update(design_numbers([m for m in e.names if m not in known], study.design))
        except InputError as exc:
            raise error(key, exc.reason) from None
        bad = [m for m in e.names if m not in known and m not in constants]
        if bad:
            raise error(key, f"unknown name {bad[0]!r} in {t!r} (a factor of the spec, a mapped quantity or "
                             "a design number design.<key>)")
        rules.append(TargetRule(e))
    return rules


def _match_rules(o, spec, names, match, error) -> list:
    """The class-to-class rule of each graded factor with its mating part."""
    key = "match_factors" if o.match_factors is not None else "match"
    if len(match) != len(names):
        raise error(key, f"{len(match)} mating parts for {len(names)} graded factors")
    for m in match:
        if m not in spec.names:
            raise error(key, f"unknown factor {m!r}")
    return [ClassToClassRule(m, Supply(spec.factor(m))) for m in match]


class SelectiveAssembly(Analysis):
    kind, title = "selective_assembly", "Selective assembly"
    layout = texts.selective

    @dataclass
    class Options(ProductionOptions):
        KIND = "selective_assembly"
        BUILT = "grades and fits the parts itself"
        factor: str | None = option(None, "the graded part's size: a factor of the spec", names="factors")
        factors: list[str] | None = option(None, "or several factors (one part per factor)", names="factors",
                                           min_length=1)
        target: str | None = option(None, "matching rule: the target size, an expression of factors, mapped "
                                          "quantities and design numbers design.<key> (base units)")
        targets: list[str] | None = option(None, "or one target per factor", min_length=1)
        match: str | None = option(None, "or: class to class with the mating part (a factor)")
        match_factors: list[str] | None = option(None, "or one mating part per factor", min_length=1)
        classes: list[int] = option([2, 3, 4], "numbers of equal-probability classes compared with no grading",
                                    min_length=1, min=1, max=50)
        limits: list[float] | None = option(None, "inner limits of a proposed grading (unit of the supply)",
                                            min_length=1)
        stock_ratio: float | None = option(None, "graded parts made per part used (finite stock; default "
                                                 "unlimited)", min=1.0)
        supply: Params | None = option(None, "the parts' size before grading, as a [[factor]] table without a name "
                                             "(default: the graded factor's own distribution)")
        optimise: OptimiseOptions | None = option(None, "search the limits of a number of classes")

        def complete(self, study, error):
            super().complete(study, error)
            self.title = self.title or (f"{SelectiveAssembly.title}: {self.name}" if self.name else None)
            names = _one_or_many(self.factor, self.factors, "factor", "factors", error)
            if not names:
                raise error("factor", "missing required key (the graded part's size: a factor of the spec)")
            if len(set(names)) != len(names):
                raise error("factors", "a factor is named twice")
            targets = _one_or_many(self.target, self.targets, "target", "targets", error)
            match = _one_or_many(self.match, self.match_factors, "match", "match_factors", error)
            if (targets is None) == (match is None):
                raise error("target", "give the matching rule: target (a target size) or match (class to class)")
            self.classes = sorted(set(self.classes))

    def prepare(self, o, study, error) -> SelectivePlan:
        return selective_plan(o, study, error)

    def compute(self, ctx):
        o, p = self.options, self.plan
        opt = None if o.optimise is None else vars(o.optimise)
        return compare_grading(ctx.model, model=p.model, spec=ctx.spec, part=p.part, classes=o.classes, mc=ctx.mc,
                               evaluator=ctx.evaluator, seed=ctx.seed, outputs=p.outputs, requirements=p.requirements,
                               constants=p.constants, limits=p.grading, stock_ratio=o.stock_ratio, optimise=opt)


def _one_or_many(one, many, one_key: str, many_key: str, error) -> list[str] | None:
    """``[one]``, ``many`` or None; both given is an error."""
    if one is not None and many is not None:
        raise error(many_key, f"give {one_key!r} or {many_key!r}, not both")
    return [one] if one is not None else many

