"""``[[analysis]] kind = "lost_motion_screening"``: doc 001's screening estimate beside the maker's figures.

::

    [[analysis]]
    kind = "lost_motion_screening"
    samples = 1000      # torsion curves on a random subsample of the Monte Carlo (all if fewer)
    percent = 3.0       # lost motion within ±percent % of rated torque (REFERENCE; others use 5)
    design = "..."      # 20-DOF design of the torsion curve (default: the study's design)
    limit = 1.0         # arcmin (default: the study's requirement on lost_motion, else the
                        # design's reducer.lost_motion_limit)
    model = "torsion"   # composed study: the torsion-curve stage (default: the only one)
    screening = "screening"   # composed study: the lost-motion stage (default: the only one)

Which models it works on: :mod:`.beside_torsion_curve`; what it computes:
:func:`.beside_torsion_curve.screening_comparison`
(per-factor rates, the two screening modes beside the torsion-curve lost motion, backlash and elastic
part on the same reducers, reducers at quantiles of the screening estimate, a scatter plot), laid
out by :mod:`.texts`.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ...analysis import Analysis, CommonOptions, target_model
from ...errors import InputError
from ...options import option
from ..lost_motion.model import LostMotionModel
from ..torsion_curve.model import TorsionCurveModel
from . import texts
from .beside_torsion_curve import ScreeningPlan, screening_comparison, screening_plan


class LostMotionScreening(Analysis):
    kind, title = "lost_motion_screening", "Screening estimate (doc 001) beside the maker's lost motion (torsion curve)"
    layout = texts.screening

    @dataclass
    class Options(CommonOptions):
        samples: int = option(1000, "torsion curves on a random subsample of the Monte Carlo (all if fewer)", min=10)
        percent: float | None = option(None, "lost motion within ±percent % of rated torque (default: the study's "
                                             "torsion-curve model's, else 3)", min=0.01, max=50.0)
        design: str | None = option(None, "the 20-DOF design of the torsion curve (default: the study's design)")
        limit: float | None = option(None, "the lost-motion limit (default: the study's requirement on lost_motion, "
                                           "else the design's reducer.lost_motion_limit)", unit="arcmin", positive=True)
        model: str | None = option(None, "composed study: the torsion-curve stage (default: the only one)")
        screening: str | None = option(None, "composed study: the lost-motion stage (default: the only one)")

    def prepare(self, o, study, error) -> ScreeningPlan:
        """Where both sides come from (:func:`.comparison.screening_plan`): the study's stages or model, the
        20-DOF design of the torsion curve (``design``, else the study's)."""
        from ...design import load_design

        m, tc, lm = study.model, None, None
        if getattr(m, "stages", None):              # a composed study: its torsion-curve and screening stages
            source = "composed"
            tc = target_model(study, TorsionCurveModel, "torsion_curve", o.model, error)
            lm = target_model(study, LostMotionModel, "lost_motion", o.screening, error, key="screening")
        elif isinstance(m, LostMotionModel):
            source = "lost_motion"
        elif isinstance(m, TorsionCurveModel):
            source = "torsion_curve"
        elif hasattr(m, "screening_inputs"):
            source = "own"
        else:
            raise error("kind", "this analysis needs the lost-motion or the torsion-curve model, or a model with "
                                "screening_inputs(X) (rvtol.models.screening.bridge)")
        design20 = load_design(Path(study.base_dir) / o.design) if o.design is not None else study.design
        if design20 is None:
            raise error("design", "the torsion curve needs a 20-DOF design ([study] design or design = ...)")
        try:
            return screening_plan(study, design20, source, tc, lm, design_given=o.design is not None,
                                  percent=o.percent, samples=o.samples, limit=o.limit)
        except InputError as exc:
            if exc.file is not None:                # located already (e.g. a key the 20-DOF design lacks)
                raise
            raise error(exc.key, exc.reason) from None

    def compute(self, ctx):
        return screening_comparison(self.plan, ctx.model, ctx.spec, ctx.mc, seed=ctx.seed, evaluate=ctx.evaluator)
