"""Study analyses of the transmission-error model (``[[analysis]] kind = ...``).

``transmission_error_curve`` — one reducer in full (:func:`.curve.reducer_curve`): TE curve over one
output revolution, its order spectrum with the error families expected at each large order
(:mod:`.orders`), forces.  ``configuration`` = "nominal" (the spec's nominal values; default),
"median" or "worst" (the Monte Carlo sample with the median / largest Δθ_er) or "values" (with
``[analysis.values]`` = {factor = value in the factor's unit}, others nominal); ``newmark`` (true: also
run the Newmark-β solver and overlay it); ``orders`` (listed in the order table whatever their size, with
what gives them: e.g. ``[3, 81, 162]``).

``transmission_error_sensitivity`` — doc 000 §3–4 (:func:`.sensitivity.te_sensitivity`): five-point
sensitivities of Δθ_er to each error factor of Table 3 (one at a time, magnitude e, the others zero)
across e, and their ranking.  It builds its own model over those factors (same reducer and solver
options as the study's model), so it does not depend on the study's spec.

``rvtol kinds KIND`` lists every key; the layouts are in :mod:`.texts`.
"""
from __future__ import annotations

from dataclasses import dataclass

from ... import units
from ...analysis import Analysis, CommonOptions, ModelTarget, target_model
from ...options import option
from . import texts
from .curve import CONFIGURATIONS, chosen_reducer, reducer_curve
from ..reducer_20dof.factors import TABLE3_GROUPS
from .model import TransmissionErrorModel
from .sensitivity import DEFAULT_MAGNITUDES, table3_spec, te_sensitivity


@dataclass
class TEOptions(CommonOptions):
    """The keys of an analysis of the transmission-error model."""

    model: str | None = option(None, "composed study: the transmission-error stage (default: the only one)")


@dataclass(frozen=True)
class TEPlan:
    """The transmission-error model an analysis reads: the study's, or a stage of a composed study."""

    target: ModelTarget


def te_plan(o: TEOptions, study, error) -> TEPlan:
    return TEPlan(target_model(study, TransmissionErrorModel, "transmission_error", o.model, error))


def shown_units(model_units) -> list[str]:
    """The units a stage's inputs are listed in (µm, arcsec)."""
    return ["um" if u == "mm" else "arcsec" if u == "rad" else u for u in model_units]


class TECurve(Analysis):
    """One reducer over one output revolution (see module docstring)."""

    kind, title = "transmission_error_curve", "Transmission error over one output revolution"
    layout = texts.curve

    @dataclass
    class Options(TEOptions):
        configuration: str = option("nominal", "the reducer: the spec's nominal values, the Monte Carlo sample with "
                                               "the median or largest Δθ_er, or the values given", choices=CONFIGURATIONS)
        values: dict[str, float] = option({}, "{factor = value in its unit} (configuration = \"values\"; the others "
                                              "nominal)", names="factors")
        newmark: bool = option(False, "also run the Newmark-β solver and overlay it")
        orders: list[int] = option([], "orders (per output revolution) the order table lists whatever their size, "
                                       "with what gives them (e.g. 3 and the input orders i, 2·i a measured "
                                       "spectrum shows)", min=1)

        def complete(self, study, error):
            self.values = {n: float(units.to_base(v, study.spec.factor(n).unit)) for n, v in self.values.items()}
            if self.values and self.configuration != "values":
                raise error("values", 'values are used only with configuration = "values"')

    def prepare(self, o, study, error) -> TEPlan:
        return te_plan(o, study, error)

    def compute(self, ctx):
        o, t = self.options, self.plan.target
        x, how = chosen_reducer(o.configuration, ctx.spec, ctx.mc, t.output("te_pp"), o.values)
        if t.stage is None:
            names, shown = ctx.spec.names, [f.unit for f in ctx.spec.factors]
        else:                       # a stage of a composed study: its inputs as the mapping gives them
            names, shown = t.model.inputs, shown_units(t.model.input_units)
        return reducer_curve(t.model, t.inputs(x)[0], how, names, shown, t.stage, o.newmark, ctx.evaluator,
                             orders=o.orders)


@dataclass
class TESensitivityOptions(TEOptions):
    factors: list[str] = option(list(TABLE3_GROUPS), "the error factors (default: the Table 3 groups)", min_length=1)
    magnitudes: list[float] = option(list(DEFAULT_MAGNITUDES), "µm: the magnitudes e", positive=True, min_length=1)
    percent: float = option(10.0, "the five points span ±percent % of e", positive=True, max=50.0)


@dataclass(frozen=True)
class TESensitivityPlan(TEPlan):
    """And the model over the chosen error factors (same reducer and solver options) with their spec."""

    te_model: object
    spec: object


def te_sensitivity_plan(o: TESensitivityOptions, study, error) -> TESensitivityPlan:
    target = te_plan(o, study, error).target
    try:
        te_model = target.model.variant(inputs=o.factors)
    except Exception as exc:  # unknown factor names: say where
        raise error("factors", getattr(exc, "reason", str(exc))) from None
    if any(u != "mm" for u in te_model.input_units):
        raise error("factors", "only magnitude factors (lengths) have an S-versus-e curve")
    return TESensitivityPlan(target, te_model, table3_spec(o.factors, o.magnitudes))


class TESensitivity(Analysis):
    """Doc 000 §3–4: five-point sensitivity of Δθ_er to the Table 3 factors across e."""

    kind = "transmission_error_sensitivity"
    title = "Sensitivity of the transmission error to the error factors (doc 000 §3–4)"
    layout = texts.te_sensitivity
    Options = TESensitivityOptions

    def prepare(self, o, study, error) -> TESensitivityPlan:
        return te_sensitivity_plan(o, study, error)

    def compute(self, ctx):
        o, p = self.options, self.plan
        return te_sensitivity(p.te_model, p.spec, o.factors, o.magnitudes, o.percent, ctx.evaluator)
