"""``[[analysis]] kind = "validation"``: the study's model against published measurements (:mod:`rvtol.validation`).

A thin adapter (:mod:`rvtol.analysis`): its options, one call of :func:`rvtol.validation.validate`, the layout
in :mod:`rvtol.validation.texts`.  ``rvtol kinds validation`` lists every key.  The published files are read
and checked when the study loads; the prediction reuses the study's Monte Carlo sample (same ``n``, method and
seed); the calibration draws the same uniform design with the spec's tolerances scaled.
"""
from __future__ import annotations

import glob
from dataclasses import dataclass
from pathlib import Path

from ..analysis import Analysis, CommonOptions, ModelTarget
from ..epistemic import study_band
from ..errors import InputError
from ..options import REQUIRED, option
from . import texts
from .published import load_published_files
from .validate import PARAMETERS, validate


@dataclass
class ValidationOptions(CommonOptions):
    published: list[str] = option(REQUIRED, "published-data files or glob patterns, relative to the study "
                                            "(data/measurements/published/*.toml)", min_length=1)
    reducer: str = option(REQUIRED, "the reducer the study's design is (e.g. RV-80E): figures of other reducers are "
                                    "listed, not predicted")
    stands_for: list[str] = option([], "other reducer names whose figures the design predicts (e.g. the \"RV-E "
                                       "series\" of a catalogue bound)")
    sensitivity_outputs: dict = option({}, "{published quantity = [other model outputs]}: the same figure against "
                                           "each, beside the prediction and not judged (e.g. the TE an assumed test "
                                           "rig reads, te.te_pp_rig)")
    shape_of: list[str] = option([], "<source id>:<quantity id> of measured spectra (order_amplitudes) of another "
                                     "reducer with the design's pins and ratio, compared in shape")
    reference_order: int | None = option(None, "the order a spectrum's shape is relative to (default: the pin "
                                               "count, the mesh order)", min=1)
    spectrum_on_rig: bool = option(False, "predicted spectra of the TE the TE stage's test rig reads (default: the "
                                          "reducer's own TE)")
    outputs: dict = option({}, "{published quantity = model output}: the output that predicts each quantity "
                               "(e.g. transmission_error_pp = \"te.te_pp\")")
    te_model: str | None = option(None, "the TE model (a stage of a composed study) whose curves give the predicted "
                                        "order spectrum, for measured TE orders", names="stages")
    interval: float = option(0.95, "central predicted interval a measured value is judged against", min=0.5,
                             max=0.999)
    confidence: float = option(0.95, "confidence of the predicted median's interval", min=0.5, max=0.999)
    order_threshold: float = option(0.10, "a measured strong order is 'present' in the prediction at this share of "
                                          "the largest predicted order", min=0.0, max=1.0)
    spectrum_samples: int = option(16, "predicted reducers whose TE spectrum is computed", min=1)
    calibrate_on: str | None = option(None, "<source id>:<quantity id> of the measured value to fit the parameter "
                                            "to (the others are then predicted: hold-out); default: no calibration")
    parameter: str = option("tolerance_scale", "the fitted parameter: tolerance_scale multiplies every tolerance "
                                               "of the spec about its middle", choices=PARAMETERS)
    bounds: list[float] = option([0.25, 10.0], "[low, high] of the fitted parameter", positive=True)
    epistemic_n: int = option(0, "designs sampled over the design's estimated numbers (their ranges, rvtol.epistemic) "
                                 "to put the epistemic band beside each prediction; 0: none", min=0)
    epistemic_units: int = option(0, "units of the tolerance spec each of those designs is also evaluated on (the "
                                     "designs × units band)", min=0)
    epistemic_outputs: list[str] = option([], "further outputs banded beside the mapped ones (e.g. the rigidity under "
                                              "each reading)", names="outputs")
    epistemic_sensitivity: str = option("given_data", "how the estimated numbers' indices are estimated (given_data "
                                                      "or pce)", choices=("given_data", "pce"))

    def complete(self, study, error):
        for name, out in self.outputs.items():
            if not isinstance(out, str):
                raise error("outputs", f"{name}: expected the name of a model output (a string), got {out!r}")
            try:
                study.model.output(out)
            except InputError as exc:
                raise error("outputs", f"{name}: {exc.reason}") from None
        for name, outs in self.sensitivity_outputs.items():
            if not isinstance(outs, list) or not all(isinstance(o, str) for o in outs):
                raise error("sensitivity_outputs", f"{name}: expected a list of model output names, got {outs!r}")
            if name not in self.outputs:
                raise error("sensitivity_outputs", f"{name}: not a quantity of outputs (its prediction comes first)")
            for out in outs:
                try:
                    study.model.output(out)
                except InputError as exc:
                    raise error("sensitivity_outputs", f"{name}: {exc.reason}") from None
        if len(self.bounds) != 2 or not self.bounds[0] < self.bounds[1]:
            raise error("bounds", f"expected [low, high] with low < high, got {self.bounds}")
        if self.epistemic_n:
            if self.epistemic_n < 4:
                raise error("epistemic_n", f"must be 0 (no band) or >= 4 designs, got {self.epistemic_n}")
            if study.design is None or not study.design.uncertain():
                raise error("epistemic_n", "the study's design states no range for any number (range, basis)")


@dataclass(frozen=True)
class ValidationPlan:
    """The published sources read (:func:`.published.load_published_files`) and the TE stage whose curves give the
    predicted spectra (None: no ``te_model``)."""

    sources: list
    te: ModelTarget | None


def validation_plan(o: ValidationOptions, study, error) -> ValidationPlan:
    """The published files ``o.published`` names, read, and the TE stage; the keys that name a published figure
    (``shape_of``, ``calibrate_on``) checked against them."""
    paths = []
    for pattern in o.published:
        hits = sorted(glob.glob(pattern if Path(pattern).is_absolute() else str(study.base_dir / pattern)))
        if not hits:
            raise error("published", f"{pattern!r} matches no file")
        paths += [h for h in hits if h not in paths]
    sources = load_published_files(paths)
    te = _te_target(study, o.te_model, error) if o.te_model is not None else None
    known_shapes = {q.key for s in sources if s.status == "read" for q in s.quantities if q.kind == "order_amplitudes"}
    for key in o.shape_of:
        if key not in known_shapes:
            raise error("shape_of", f"unknown measured spectrum {key!r} (order_amplitudes figures: "
                                    f"{', '.join(sorted(known_shapes)) or 'none'})")
    if o.shape_of and te is None:
        raise error("shape_of", "a spectrum's shape needs the study's TE model (te_model)")
    if o.calibrate_on is not None:
        known = {q.key: q for s in sources if s.status == "read" for q in s.quantities}
        q = known.get(o.calibrate_on)
        if q is None:
            raise error("calibrate_on", f"unknown published figure {o.calibrate_on!r} (known: "
                                        f"{', '.join(known) or 'none'})")
        if q.reducer != o.reducer or q.kind not in ("value", "range") or q.quantity not in o.outputs:
            raise error("calibrate_on", f"{o.calibrate_on!r} cannot be calibrated on: a measured value (kind "
                                        f"value or range) of the {o.reducer} whose quantity {q.quantity!r} "
                                        "outputs maps to a model output")
    return ValidationPlan(sources, te)


def _te_target(study, name: str, error) -> ModelTarget:
    stage = next(s for s in study.model.stages if s.name == name)
    if not callable(getattr(stage.model, "run", None)) or "te_pp" not in stage.model.output_names:
        raise error("te_model", f"model {name!r} is not a transmission_error model")
    return ModelTarget(study.model, stage.model, name)


def te_spectra(target: ModelTarget, rig: bool = False):
    """``X -> [TE amplitude per order of one output revolution (arcsec), or None where the solver failed]``: each
    row's TE curve by the TE stage's own ``run`` and its order spectrum (``TEResult.spectrum``) — the reducer's own
    TE, or (``rig``) the TE its test rig reads where the stage has one."""
    def spectra(X):
        return [r.spectrum(rig=rig)["amplitude [arcsec]"].to_numpy() if r.ok else None
                for r in (target.model.run(x) for x in target.inputs(X))]
    return spectra


class ValidationAnalysis(Analysis):
    kind, title = "validation", "The model against published measurements"
    layout = texts.layout
    Options = ValidationOptions

    def prepare(self, o, study, error) -> ValidationPlan:
        return validation_plan(o, study, error)

    def compute(self, ctx):
        o, p, mc = self.options, self.plan, ctx.mc
        outs = set(o.outputs.values()) | {x for v in o.sensitivity_outputs.values() for x in v}
        known = (mc.samples.values, {out: mc.column(out) for out in outs}, mc.ok)
        g = getattr(p.te.model, "geometry", None) if p.te is not None else None
        return validate(ctx.model, ctx.spec, p.sources, o.outputs, reducer=o.reducer, n=len(mc.samples),
                        method=mc.samples.method, seed=mc.samples.seed, evaluator=ctx.evaluator, known=known,
                        te_spectra=te_spectra(p.te, o.spectrum_on_rig) if p.te is not None else None,
                        calibrate_on=o.calibrate_on, parameter=o.parameter, bounds=tuple(o.bounds),
                        interval=o.interval, confidence=o.confidence, order_threshold=o.order_threshold,
                        spectrum_samples=o.spectrum_samples, stands_for=tuple(o.stands_for),
                        sensitivity_outputs=o.sensitivity_outputs, shape_of=tuple(o.shape_of),
                        lattice=(g.z_b, g.ratio) if g is not None else None, reference_order=o.reference_order,
                        epistemic=_epistemic_band(ctx, o))


def _epistemic_band(ctx, o):
    """The estimated design's band of the mapped outputs and the extra ones (``epistemic_n`` designs), or None."""
    if not o.epistemic_n:
        return None
    return study_band(ctx, list(dict.fromkeys([*o.outputs.values(), *o.epistemic_outputs])), n=o.epistemic_n,
                      tolerance_samples=o.epistemic_units, interval=o.interval, sensitivity=o.epistemic_sensitivity)
