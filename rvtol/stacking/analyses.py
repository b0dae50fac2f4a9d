"""Study analyses of the stack-up conventions (``[[analysis]] kind = ...``), for any model.

Thin adapters (:mod:`rvtol.analysis`): their options, one call of
:func:`rvtol.stacking.beside_monte_carlo.compare_conventions` or
:func:`rvtol.stacking.beside_monte_carlo.tail_probabilities`, the layout in :mod:`rvtol.stacking.texts`.
``rvtol kinds stack_conventions`` (``tail_probability``) lists every key with its default and meaning.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..analysis import Analysis, CommonOptions
from ..options import option
from . import texts
from .beside_monte_carlo import compare_conventions, tail_probabilities
from .conventions import SIX_SIGMA_CP, SIX_SIGMA_SHIFT
from .tail import APPROXIMATIONS, METHODS


@dataclass
class SixSigmaOptions:
    cp: float = option(SIX_SIGMA_CP, "the process capability every band is read as", positive=True)
    shift: float = option(SIX_SIGMA_SHIFT, "the mean shift in σ", nonnegative=True)

    def complete(self, study, error):
        if not self.shift < 3.0 * self.cp:
            raise error("shift", f"a shift of {self.shift:g}σ leaves no Cpk at Cp {self.cp:g} (it must be < 3·Cp)")


@dataclass
class StackOptions(CommonOptions):
    outputs: list[str] | None = option(None, 'the outputs (or "all"; default: those the requirements name)',
                                       names="outputs", all_ok=True, min_length=1)


class StackConventionsAnalysis(Analysis):
    """Worst case, RSS, MRSS, 6σ and the true worst case beside the Monte Carlo (:mod:`rvtol.stacking`)."""

    kind, title = "stack_conventions", "Stack-up conventions beside the Monte Carlo"
    layout = texts.conventions

    @dataclass
    class Options(StackOptions):
        sigma_levels: list[float] = option([3.0], "the ±zσ of the statistical rows", min_length=1, positive=True)
        percentiles: list[float] = option([0.135, 99.865], "Monte Carlo percentiles (in %) with intervals",
                                          min_length=1)
        mrss_factor: float | None = option(None, "a given MRSS factor (a row of its own)", positive=True)
        six_sigma: SixSigmaOptions | None = option(SixSigmaOptions, "the 1.5σ-shift convention's row (false: "
                                                                    "none)")
        true_worst_case: bool = option(True, "the true extreme of the model over the bands (corners, differential "
                                             "evolution, L-BFGS-B)")
        second_order: bool = option(True, "mean shift, skewness and kurtosis by the method of moments, Pearson tails")
        starts: int = option(4, "starts of the worst-case search", min=2)
        max_evaluations: int = option(5000, "model evaluations of the worst-case search", min=100)
        gradient: str = option("auto", "auto: the model's analytic gradient if it has one, else five-point",
                               choices=("auto", "five_point"))
        percent: float = option(10.0, "the five-point derivatives span ±percent % of the nominal", positive=True)

        def complete(self, study, error):
            if self.outputs is None:
                self.outputs = (list(dict.fromkeys(r.output for r in study.requirements))
                                or [study.model.outputs[0].name])
            for p in self.percentiles:
                if not 0.0 < p < 100.0:
                    raise error("percentiles", f"percentiles lie in (0, 100), got {p:g}")

    def compute(self, ctx):
        o = self.options
        six = None if o.six_sigma is None else (o.six_sigma.cp, o.six_sigma.shift)
        return compare_conventions(ctx.model, ctx.spec, o.outputs, ctx.mc, ctx.evaluator, sigma_levels=o.sigma_levels,
                                   percentiles=o.percentiles, mrss_factor=o.mrss_factor, six_sigma=six,
                                   true_wc=o.true_worst_case, second_order=o.second_order, starts=o.starts,
                                   max_evaluations=o.max_evaluations, gradient=o.gradient, percent=o.percent)


class TailProbabilityAnalysis(Analysis):
    """Tail probabilities beyond each requirement limit by OpenTURNS' reliability methods (:mod:`rvtol.stacking.tail`)."""

    kind = "tail_probability"
    title = "Tail probabilities beyond the limits (FORM, SORM, importance, subset and directional sampling)"
    layout = texts.tails

    @dataclass
    class Options(StackOptions):
        samples: int = option(4000, "model runs per sampling method and limit (0: the approximations only)", min=0,
                              zero_or_min=100)
        methods: list[str] = option(list(METHODS), "the reliability methods", choices=METHODS, min_length=1)
        design_points: int = option(4, "the most design points multi-FORM looks for", min=2)
        seed: int | None = option(None, "seed of the importance samples (default: the study's)", min=0)

        def complete(self, study, error):
            if self.outputs is None:
                self.outputs = list(dict.fromkeys(r.output for r in study.requirements))
                if not self.outputs:
                    raise error("outputs", "tail probabilities need requirement limits: this study has no "
                                           "[[requirement]]")
            for o in self.outputs:
                if not any(r.output == o for r in study.requirements):
                    raise error("outputs", f"output {o!r} has no requirement (no limit to estimate a tail beyond)")
            if not self.samples:
                self.methods = [m for m in self.methods if m in APPROXIMATIONS]

    def compute(self, ctx):
        o = self.options
        return tail_probabilities(ctx.model, ctx.spec, ctx.mc, o.outputs, ctx.evaluator, samples=o.samples,
                                  methods=tuple(o.methods), design_points=o.design_points,
                                  seed=ctx.seed if o.seed is None else o.seed)
