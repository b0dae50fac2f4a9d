"""Study analysis of the lost-motion model: stage breakdown (analytic vs Monte Carlo).

``[[analysis]] kind = "lost_motion_breakdown"``: geometry, each stage's mean ± T/2 by the document's
formulas (document mode) and mean ± 3σ of the linear model beside the Monte Carlo (mean and σ with
CIs, 95 % and ±3σ-coverage intervals), the histogram of the total against its limit and the
contributions chart (:func:`.breakdown.stage_breakdown`, laid out by :mod:`.texts`).

The screening estimate beside the maker's lost motion on the 20-DOF torsion curve is the
``lost_motion_screening`` analysis of :mod:`rvtol.models.screening`.
"""
from __future__ import annotations

from dataclasses import dataclass

from ...analysis import Analysis, CommonOptions
from . import texts
from .breakdown import stage_breakdown
from .model import LostMotionModel


@dataclass
class LostMotionOptions(CommonOptions):
    """The keys of an analysis of the lost-motion model (the study's model must be one)."""

    def complete(self, study, error):
        if not isinstance(study.model, LostMotionModel):
            raise error("kind", "this analysis needs the lost-motion model ([model] kind = \"lost_motion\")")


class LostMotionBreakdown(Analysis):
    kind, title = "lost_motion_breakdown", "Geometric lost motion: stages, analytic and Monte Carlo"
    layout = texts.breakdown
    Options = LostMotionOptions

    def compute(self, ctx):
        return stage_breakdown(ctx.model, ctx.spec, ctx.mc)
