"""``[[analysis]] kind = "epistemic_band"``: the prediction over what is not known of the design (:mod:`rvtol.epistemic`).

A thin adapter (:mod:`rvtol.analysis`): its options, one call of :func:`rvtol.epistemic.epistemic_band`, the layout in
:mod:`rvtol.epistemic.texts`.  ``rvtol kinds epistemic_band`` lists every key.  The design must state ranges
(``range``, ``basis``); each sampled design rebuilds the study's models on a variant of the design
(:class:`rvtol.epistemic.StudyVariants`) and runs on the study's executor, one design per task.  The design as
written's tolerance band is the study's own Monte Carlo.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..analysis import Analysis, CommonOptions
from ..errors import InputError
from ..options import REQUIRED, option
from . import texts
from .band import SENSITIVITY_METHODS, design_inputs, study_band


@dataclass
class EpistemicOptions(CommonOptions):
    outputs: list[str] = option(REQUIRED, "the outputs whose band is computed", names="outputs", min_length=1)
    n: int = option(32, "designs sampled over the estimated numbers' ranges (each rebuilds the study's models: "
                        "seconds to a minute each)", min=4)
    method: str = option("lhs", "how the designs are drawn", choices=("lhs", "sobol", "random"))
    keys: list[str] | None = option(None, "the design numbers to sample (default: every number with a range that "
                                          "is no formula)", min_length=1)
    tolerance_samples: int = option(0, "units of the tolerance spec each design is also evaluated on (the same "
                                       "units for every design): the designs × units band; 0: nominal tolerances "
                                       "only", min=0)
    interval: float = option(0.95, "central band of the designs (and of the units) reported", min=0.5, max=0.999)
    sensitivity: str = option("given_data", "how the estimated numbers' first-order indices are estimated from the "
                                            "designs: given_data (correlation ratio) or pce", choices=SENSITIVITY_METHODS)
    top: int = option(3, "estimated numbers listed per output as its largest drivers", min=1)
    seed: int | None = option(None, "seed of the designs (default: the study's)")

    def complete(self, study, error):
        if study.design is None:
            raise error("kind", "the epistemic band needs the study's design ([study] design) with ranges")
        try:
            design_inputs(study.design, self.keys)
        except InputError as exc:                # a key that is no uncertain number of the design
            raise error("keys", exc.reason) from None


class EpistemicBand(Analysis):
    kind, title = "epistemic_band", "The prediction over the design's estimated numbers (epistemic band)"
    layout = texts.layout
    Options = EpistemicOptions

    def compute(self, ctx):
        o = self.options
        return study_band(ctx, o.outputs, n=o.n, method=o.method, keys=o.keys, tolerance_samples=o.tolerance_samples,
                          interval=o.interval, sensitivity=o.sensitivity,
                          **({"seed": o.seed} if o.seed is not None else {}))
