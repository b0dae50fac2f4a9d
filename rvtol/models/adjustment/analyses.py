"""Study analysis ``adjustment``: the optimal adjustment of an assembly, step by step and against Q.

::

    [[analysis]]
    kind = "adjustment"
    part_errors = "example.part_errors"   # a design parameter, or numbers (step order) with `unit`
    accuracy_weights = [0, 5, 10, "inf"]  # Q values of the example ("inf": terminal constraint)
    sweep = [0.01, 10000]                 # Q range of the sweep (log spaced)
    sweep_points = 41
    batch = true                          # also sweep the study's Monte Carlo samples

The study's model must be ``adjusted_assembly``.  The section
(:func:`.assessment.adjustment_assessment`, laid out by :mod:`.texts`) shows the state-space matrices,
the example assembly at each Q with and without adjustment, the per-step RMS KC errors of the Monte
Carlo batch, the final error and effort against Q, and the linear map from part errors to the final KC
errors at the study's Q.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ... import units
from ...analysis import Analysis, CommonOptions
from ...errors import InputError
from ...options import REQUIRED, option
from ...params import check_number
from . import texts
from .assessment import adjustment_assessment, part_errors_from
from .model import AdjustedAssemblyModel


def accuracy_weight(v, error, key: str) -> float:
    """A non-negative weight or ``"inf"`` (TOML ``inf``): the terminal constraint."""
    if v == "inf" or (isinstance(v, float) and v == math.inf):
        return math.inf
    if isinstance(v, str):
        raise error(key, f'expected a number or "inf", got the string {v!r}')
    return check_number(v, error, key, nonnegative=True)


@dataclass
class AdjustmentOptions(CommonOptions):
    """The keys of an analysis of the adjusted assembly (the study's model must be one)."""

    def complete(self, study, error):
        if not isinstance(study.model, AdjustedAssemblyModel):
            raise error("kind", f"needs the study model kind 'adjusted_assembly', got {type(study.model).__name__}")


@dataclass(frozen=True)
class AdjustmentPlan:
    """The example's part errors (rad, step order): the design parameter's or the numbers given."""

    part_errors: np.ndarray


class AdjustmentAnalysis(Analysis):
    kind, title = "adjustment", "Assembly adjustment (state space, finite-horizon LQR)"
    layout = texts.adjustment

    @dataclass
    class Options(AdjustmentOptions):
        part_errors: str | list = option(REQUIRED, "the example's part errors: a design parameter, or numbers (step "
                                                   "order) in `unit`")
        unit: str = option("mrad", "the unit of part_errors given as numbers (an angle)")
        accuracy_weights: list = option([0, 5, 10, "inf"], 'Q values of the example ("inf": terminal constraint)')
        sweep: list[float] = option([0.01, 1e4], "[low, high]: the Q range of the sweep (log spaced)", positive=True,
                                    min_length=2)
        sweep_points: int = option(41, "Q values of the sweep", min=3)
        batch: bool = option(True, "also sweep the study's Monte Carlo samples")

        def complete(self, study, error):
            super().complete(study, error)
            try:
                self.unit = units.canonical(self.unit)
                units.require_dimension(self.unit, "angle")
            except InputError as exc:
                raise error("unit", exc.reason) from None
            if not isinstance(self.accuracy_weights, list) or not self.accuracy_weights:
                raise error("accuracy_weights", "expected a non-empty array of weights (numbers or \"inf\")")
            self.accuracy_weights = [accuracy_weight(v, error, f"accuracy_weights.{i}")
                                     for i, v in enumerate(self.accuracy_weights)]
            lo, hi = self.sweep[:2]
            if len(self.sweep) != 2 or not lo < hi:
                raise error("sweep", f"expected [low, high] with low < high, got {self.sweep}")

    def prepare(self, o, study, error) -> AdjustmentPlan:
        try:
            return AdjustmentPlan(part_errors_from(o.part_errors, o.unit, study.design, study.model))
        except InputError as exc:
            raise error("part_errors", exc.reason) from None

    def compute(self, ctx):
        o = self.options
        X = ctx.mc.samples.values if o.batch else None
        Q = np.geomspace(o.sweep[0], o.sweep[1], o.sweep_points)
        return adjustment_assessment(ctx.model, w=self.plan.part_errors, weights=o.accuracy_weights, Q=Q, X=X,
                                     evaluate=ctx.evaluator)
