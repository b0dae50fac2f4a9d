"""Study analyses for sensitivity (``[[analysis]] kind = ...``), for any model.

Each is a thin adapter (:mod:`rvtol.analysis`): its options, one call of a
:mod:`rvtol.sensitivity` function, the layout in :mod:`rvtol.sensitivity.texts`.
``rvtol kinds KIND`` lists every key with its default and meaning.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..analysis import Analysis, CommonOptions
from ..options import REQUIRED, option
from . import global_ as gs
from . import texts
from .given_data import DELTA_DEFAULT_N, delta_given, given_data
from .linearisation import linearised_contributions
from .local import five_point, sensitivity_curve
from .matrix import sensitivity_matrix
from .surrogate import CI_METHODS, MIN_Q2, POOR_FIT, pce_given
from .surrogate import METHODS as FIT_METHODS


@dataclass
class SensitivityOptions(CommonOptions):
    """The keys every sensitivity analysis takes."""

    outputs: list[str] | None = option(None, 'the outputs to analyse (or "all"; default: the model\'s first output)',
                                       names="outputs", all_ok=True, min_length=1)
    factors: list[str] | None = option(None, "the factors to vary (default: every factor)", names="factors",
                                       min_length=1)
    seed: int | None = option(None, "seed of this analysis' random numbers (default: the study's seed)", min=0)
    confidence: float | None = option(None, "confidence level of the intervals (default: the report's)", min=0.5,
                                      max=0.999999)


@dataclass(frozen=True)
class SensitivityPlan:
    """The outputs a sensitivity analysis works on: the table's, else its default from the study's model."""

    outputs: list[str]


class _Sensitivity(Analysis):
    """The study-dependent defaults every sensitivity analysis shares; its layouts read the plan
    (``layout(result, options, plan)``)."""

    def prepare(self, o, study, error) -> SensitivityPlan:
        return SensitivityPlan(o.outputs if o.outputs is not None else self.default_outputs(study))

    @staticmethod
    def default_outputs(study) -> list[str]:
        """The outputs when the table names none: the model's first."""
        return [study.model.outputs[0].name]

    def blocks(self, result) -> list:
        return list(type(self).layout(result, self.options, self.plan))

    def seed(self, ctx):
        return ctx.seed if self.options.seed is None else self.options.seed

    def confidence(self, ctx):
        return self.options.confidence or ctx.options.confidence


# --------------------------------------------------------------------------- local
class LocalSensitivity(_Sensitivity):
    kind, title = "local_sensitivity", "Local sensitivity (five-point)"
    layout = texts.local

    @dataclass
    class Options(SensitivityOptions):
        percent: float = option(10.0, "the five points span ±percent % of the nominal", positive=True)
        abs_step: dict[str, float] = option({}, "{factor = ± value in its unit}: the step of a factor with a zero "
                                                "nominal (default: ±percent % of the tolerance half-band)",
                                            positive=True, names="factors")

    def compute(self, ctx):
        o = self.options
        return five_point(ctx.model, ctx.spec, factors=o.factors, outputs=self.plan.outputs, percent=o.percent,
                          abs_step=o.abs_step or None, evaluate=ctx.evaluator)


class SensitivityCurve(_Sensitivity):
    kind, title = "sensitivity_curve", "Sensitivity against error magnitude"
    layout = texts.curve

    @dataclass
    class Options(SensitivityOptions):
        magnitudes: list[float] = option(REQUIRED, "the error magnitudes e (in `unit`, else each factor's unit); "
                                                   "non-zero", min_length=1)
        unit: str | None = option(None, "the unit of the magnitudes")
        percent: float = option(10.0, "the five points span ±percent % of e", positive=True)
        together: bool = option(False, "set every listed factor to e at once (else one at a time)")

        def complete(self, study, error):
            if self.factors is None:
                raise error("factors", "missing required key (the factors whose curve to draw)")
            if any(m == 0 for m in self.magnitudes):
                raise error("magnitudes", "magnitudes must be non-zero (the points span ±percent % of e)")
            if self.unit is not None:
                from ..units import canonical, dimension

                try:
                    self.unit = canonical(self.unit)
                except Exception as exc:   # an unknown unit: the loader's one-line message
                    raise error("unit", getattr(exc, "reason", str(exc))) from None
                for f in self.factors:
                    fu = study.spec.factor(f).unit
                    if dimension(fu) != dimension(self.unit):
                        raise error("unit", f"unit {self.unit!r} does not fit factor {f!r} ({fu})")

    def compute(self, ctx):
        o = self.options
        return sensitivity_curve(ctx.model, ctx.spec, factors=o.factors, magnitudes=o.magnitudes, unit=o.unit,
                                 outputs=self.plan.outputs, percent=o.percent, together=o.together,
                                 evaluate=ctx.evaluator)


class Contributions(_Sensitivity):
    kind, title = "contributions", "Contributions to variance (linearisation) and high/low table"
    layout = texts.contributions

    @dataclass
    class Options(SensitivityOptions):
        percent: float = option(10.0, "the five-point derivatives span ±percent % of the nominal", positive=True)

    def compute(self, ctx):
        o = self.options
        return linearised_contributions(ctx.model, ctx.spec, outputs=self.plan.outputs, factors=o.factors,
                                        percent=o.percent, evaluate=ctx.evaluator, mc_statistics=ctx.mc.statistics())


# --------------------------------------------------------------------------- global
class Sobol(_Sensitivity):
    kind, title = "sobol", "Global sensitivity: Sobol indices"
    layout = texts.global_indices

    @dataclass
    class Options(SensitivityOptions):
        n: int = option(1024, "base samples N (Saltelli: N·(k + 2) model runs, N·(2k + 2) with S2)", min=2,
                        power_of_two=True)
        second_order: bool = option(True, "also the second-order indices S2")
        num_resamples: int = option(100, "bootstrap resamples of the intervals", min=10)

    def compute(self, ctx):
        o = self.options
        return gs.sobol(ctx.model, ctx.spec, n=o.n, factors=o.factors, outputs=self.plan.outputs,
                        second_order=o.second_order, seed=self.seed(ctx), num_resamples=o.num_resamples,
                        confidence=self.confidence(ctx), evaluate=ctx.evaluator)


class Morris(_Sensitivity):
    kind, title = "morris", "Global screening: Morris elementary effects"
    layout = texts.global_indices

    @dataclass
    class Options(SensitivityOptions):
        trajectories: int = option(20, "Morris trajectories", min=2)
        levels: int = option(4, "grid levels of each factor's band", min=2, even=True)
        num_resamples: int = option(1000, "bootstrap resamples of μ*'s interval", min=10)

    def compute(self, ctx):
        o = self.options
        return gs.morris(ctx.model, ctx.spec, trajectories=o.trajectories, levels=o.levels, factors=o.factors,
                         outputs=self.plan.outputs, seed=self.seed(ctx), num_resamples=o.num_resamples,
                         confidence=self.confidence(ctx), evaluate=ctx.evaluator)


class Fast(_Sensitivity):
    kind, title = "fast", "Global sensitivity: FAST"
    layout = texts.global_indices

    @dataclass
    class Options(SensitivityOptions):
        method: str = option("efast", "efast (search curves, S1 and ST) or rbd (RBD-FAST, S1)",
                             choices=("efast", "rbd"))
        samples: str = option("monte_carlo", "rbd: the Monte Carlo samples or fresh ones",
                              choices=("monte_carlo", "fresh"))
        M: int | None = option(None, "interference factor (default: 4 for efast, 10 for rbd)", min=1)
        n: int | None = option(None, "samples per factor (efast, default 1024; > 4·M²) or in all (rbd, default 2048)",
                               min=2)
        num_resamples: int = option(100, "bootstrap resamples of the intervals", min=10)

        def complete(self, study, error):
            efast = self.method == "efast"
            self.M = self.M if self.M is not None else (4 if efast else 10)
            self.n = self.n if self.n is not None else (1024 if efast else 2048)
            if efast and self.n <= 4 * self.M ** 2:
                raise error("n", f"must be > 4·M² = {4 * self.M ** 2}, got {self.n}")

    def compute(self, ctx):
        o = self.options
        args = dict(n=o.n, M=o.M, factors=o.factors, outputs=self.plan.outputs, seed=self.seed(ctx),
                    num_resamples=o.num_resamples, confidence=self.confidence(ctx), evaluate=ctx.evaluator)
        if o.method == "efast":
            return gs.fast(ctx.model, ctx.spec, **args)
        given = o.samples == "monte_carlo"
        return gs.rbd_fast(ctx.model, ctx.spec, samples=ctx.mc.samples if given else None,
                           Y=ctx.mc.Y if given else None, **args)


class Delta(_Sensitivity):
    kind, title = "delta", "Global sensitivity: delta (moment-independent)"
    layout = texts.global_indices

    @dataclass
    class Options(SensitivityOptions):
        samples: str = option("monte_carlo", "a random subsample of the study's Monte Carlo sample (correlation "
                                             "included) or fresh model runs", choices=("monte_carlo", "fresh"))
        n: int | None = option(None, f"monte_carlo: rows of the subsample (default {DELTA_DEFAULT_N}, 0: every "
                                     "sample; its density estimates cost ~n² per factor); fresh: model runs "
                                     "(default 2048, >= 100)", min=0)
        num_resamples: int = option(50, "bootstrap resamples of the intervals", min=10)

        def complete(self, study, error):
            given = self.samples == "monte_carlo"
            if self.n is None:
                self.n = DELTA_DEFAULT_N if given else 2048
            elif given and 0 < self.n < 100:
                raise error("n", f"must be 0 (every sample) or >= 100, got {self.n}")
            elif not given and self.n < 100:
                raise error("n", f"must be >= 100, got {self.n}")

    def compute(self, ctx):
        o = self.options
        args = dict(factors=o.factors, outputs=self.plan.outputs, seed=self.seed(ctx), num_resamples=o.num_resamples,
                    confidence=self.confidence(ctx), evaluate=ctx.evaluator, executor=ctx.executor)
        if o.samples == "fresh":
            return gs.delta(ctx.model, ctx.spec, o.n, **args)
        return delta_given(ctx.model, ctx.spec, ctx.mc.samples, ctx.mc.Y, o.n or None, **args)


class GivenData(_Sensitivity):
    kind, title = "given_data", "Global sensitivity: first-order indices from the Monte Carlo sample"
    layout = texts.global_indices

    @dataclass
    class Options(SensitivityOptions):
        classes: int | None = option(None, "equal-count classes of each factor (default ⌊√n⌋ in [8, 200])", min=2)
        num_resamples: int = option(200, "bootstrap resamples of the intervals", min=10)

    def compute(self, ctx):
        o = self.options
        return given_data(ctx.model, ctx.spec, ctx.mc.samples, ctx.mc.Y, factors=o.factors, outputs=self.plan.outputs,
                          seed=self.seed(ctx), classes=o.classes, num_resamples=o.num_resamples,
                          confidence=self.confidence(ctx))


class PCE(_Sensitivity):
    kind, title = "pce", "Global sensitivity: Sobol indices from a polynomial chaos surrogate"
    layout = texts.pce

    @dataclass
    class Options(SensitivityOptions):
        germs: str = option("auto", "the polynomial families (auto: from each factor's distribution)",
                            choices=("auto", "legendre", "hermite"))
        holdout: float = option(0.2, "share of the samples held out to validate the fit", min=0.0, max=0.49)
        ci: str = option("bootstrap", "how the intervals are computed", choices=CI_METHODS)
        num_resamples: int = option(100, "bootstrap resamples of the intervals", min=10)
        min_q2: float = option(MIN_Q2, "below this Q² the indices are withheld", min=0.0, max=1.0)
        on_poor_fit: str = option("withhold", "what a fit below min_q2 does", choices=POOR_FIT)
        second_order: bool = option(True, "also the second-order indices S2")
        n: int = option(0, "fit on a random subsample of n Monte Carlo rows (0: every sample)", min=0,
                        zero_or_min=100)
        max_degree: int | None = option(None, "the largest total degree of the expansion", min=1)
        q: float | None = option(None, "hyperbolic truncation q of the candidate terms", positive=True, max=1.0)
        max_interaction: int | None = option(None, "the most factors one term may couple", min=1)
        method: str | None = option(None, "the sparse regression", choices=FIT_METHODS)

    def compute(self, ctx):
        o = self.options
        fit = {k: getattr(o, k) for k in ("max_degree", "q", "max_interaction", "method") if getattr(o, k) is not None}
        fit.update(map=ctx.evaluator.map, workers=ctx.evaluator.workers)     # the degrees side by side
        return pce_given(ctx.model, ctx.spec, ctx.mc.samples, ctx.mc.Y, n=o.n or None, factors=o.factors,
                         outputs=self.plan.outputs, seed=self.seed(ctx), germs=o.germs, holdout=o.holdout, ci=o.ci, num_resamples=o.num_resamples,
                         confidence=self.confidence(ctx), min_q2=o.min_q2, on_poor_fit=o.on_poor_fit,
                         second_order=o.second_order, **fit)


# --------------------------------------------------------------------------- cross-model matrix
class SensitivityMatrix(_Sensitivity):
    """Drawing tolerance × output: five-point variance shares of all, Sobol total indices of the top ones
    (:mod:`rvtol.sensitivity.matrix`)."""

    kind, title = "sensitivity_matrix", "Sensitivity matrix: drawing tolerances × outputs"
    layout = texts.matrix

    @dataclass
    class Options(SensitivityOptions):
        outputs: list[str] | None = option(None, 'the outputs (or "all"; default: every output a requirement names)',
                                           names="outputs", all_ok=True, min_length=1)
        percent: float = option(10.0, "the five-point derivatives span ±percent % of the nominal", positive=True)
        top: int = option(10, "the tolerances with a Sobol total index of their own (the others: one group)", min=1)
        n: int = option(64, "Sobol base samples", min=2, power_of_two=True)
        num_resamples: int = option(100, "bootstrap resamples of the intervals", min=10)

    @staticmethod
    def default_outputs(study) -> list[str]:
        """Every output a requirement names, else every output."""
        return list(dict.fromkeys(r.output for r in study.requirements)) or list(study.model.output_names)

    def compute(self, ctx):
        o = self.options
        return sensitivity_matrix(ctx.model, ctx.spec, outputs=self.plan.outputs, factors=o.factors, percent=o.percent,
                                  top=o.top, n=o.n, seed=self.seed(ctx), num_resamples=o.num_resamples,
                                  confidence=self.confidence(ctx), evaluate=ctx.evaluator, mc=ctx.mc)
