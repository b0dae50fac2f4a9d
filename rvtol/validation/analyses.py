"""``[[analysis]] kind = "validation"``: the study's model against published measurements (:mod:`rvtol.validation`).

::

    [[analysis]]
    kind = "validation"
    published = ["../data/measurements/published/*.toml"]   # files or glob patterns, relative to the study
    reducer = "RV-80E"                 # the reducer the study's design is: figures of others are listed, not predicted
    te_model = "te"                    # optional: the TE model (a stage of a composed study) for measured TE orders
    interval = 0.95                    # central predicted interval a measured value is judged against
    confidence = 0.95                  # of the predicted median's interval
    order_threshold = 0.10             # a measured strong order is "present" at ≥ this share of the largest predicted
    spectrum_samples = 16              # predicted reducers whose TE spectrum is computed
    [analysis.outputs]                 # published quantity name -> the model output that predicts it
    transmission_error_pp = "te.te_pp"
    lost_motion = "reducer.lost_motion"
    [analysis.calibration]             # optional: fit one parameter to one figure, predict the others
    on = "yang2021_mmt:te_pp_prototype_1"
    parameter = "tolerance_scale"
    bounds = [0.25, 10.0]

The prediction reuses the study's Monte Carlo sample (same ``n``, method and seed); the calibration draws the
same uniform design with the spec's tolerances scaled.  Everything is read and checked when the study loads
(the published files included).
"""
from __future__ import annotations

import glob
from pathlib import Path

import numpy as np

from ..analysis import Analysis, target_model
from ..errors import InputError
from ..report.sections import Section
from . import text
from .published import load_published_files
from .validate import PARAMETERS, validate


class ValidationAnalysis(Analysis):
    def setup(self, params, study):
        self.key = params.str("key", "validation")
        self.title = params.str("title", "The model against published measurements")
        paths = []
        for pattern in params.strs("published", min_length=1):
            full = pattern if Path(pattern).is_absolute() else str(study.base_dir / pattern)
            hits = sorted(glob.glob(full))
            if not hits:
                raise params.error("published", f"{pattern!r} matches no file")
            paths += [h for h in hits if h not in paths]
        self.sources = load_published_files(paths)
        self.reducer = params.str("reducer")
        outs = params.sub("outputs", {})
        self.outputs = {}
        for name in list(outs.keys()):
            out = outs.str(name)
            try:
                study.model.output(out)
            except InputError as exc:
                raise outs.error(name, exc.reason) from None
            self.outputs[name] = out
        outs.finish()
        self.te = None
        if "te_model" in params:
            from ..models.transmission.model import TransmissionErrorModel

            self.te = target_model(params, study, TransmissionErrorModel, "transmission_error", key="te_model")
        self.interval = params.float("interval", 0.95, min=0.5, max=0.999)
        self.confidence = params.float("confidence", 0.95, min=0.5, max=0.999)
        self.threshold = params.float("order_threshold", 0.10, min=0.0, max=1.0)
        self.spectrum_samples = params.int("spectrum_samples", 16, min=1)
        cal = params.sub("calibration", None)
        self.calibrate_on = None
        self.parameter, self.bounds = "tolerance_scale", (0.25, 10.0)
        if cal is not None and len(cal.keys()):
            self.calibrate_on = cal.str("on")
            self.parameter = cal.str("parameter", "tolerance_scale", choices=PARAMETERS)
            lo, hi = cal.floats("bounds", [0.25, 10.0], length=2, positive=True)
            if not lo < hi:
                raise cal.error("bounds", f"expected [low, high] with low < high, got [{lo:g}, {hi:g}]")
            self.bounds = (lo, hi)
            known = {q.key: (s, q) for s in self.sources if s.status == "read" for q in s.quantities}
            if self.calibrate_on not in known:
                raise cal.error("on", f"unknown published figure {self.calibrate_on!r} (known: {', '.join(known)})")
            src, q = known[self.calibrate_on]
            if q.reducer != self.reducer or q.kind not in ("value", "range") or q.quantity not in self.outputs:
                raise cal.error("on", f"{self.calibrate_on!r} cannot be calibrated on: it must be a measured value "
                                      f"(kind value or range) of the {self.reducer} whose quantity "
                                      f"{q.quantity!r} [analysis.outputs] maps to a model output")
            cal.finish()
        params.finish()

    def _te_curves(self, X):
        out = []
        for x in self.te.inputs(X):
            r = self.te.model.run(x)
            out.append(r.te if r.ok else None)
        return out

    def run(self, ctx):
        mc = ctx.mc
        known = (mc.samples.values, {o: mc.column(o) for o in set(self.outputs.values())}, mc.ok)
        res = validate(ctx.model, ctx.spec, self.sources, self.outputs, reducer=self.reducer, n=len(mc.samples),
                       method=mc.samples.method, seed=mc.samples.seed, evaluator=ctx.evaluator, known=known,
                       te_curves=self._te_curves if self.te is not None else None, calibrate_on=self.calibrate_on,
                       parameter=self.parameter, bounds=self.bounds, interval=self.interval,
                       confidence=self.confidence, order_threshold=self.threshold,
                       spectrum_samples=self.spectrum_samples)
        sec = Section(self.key, self.title)
        sec.add_text(text.introduction(res, self.reducer))
        sec.add_table(res.sources_frame().drop(columns=["file"]), caption="Published sources")
        lo, hi = 50 * (1 - self.interval), 50 * (1 + self.interval)
        cols = ["source", "quantity", "unit under test", "kind", "measured", "± reading", "unit", "nominal", "median",
                "median CI low", "median CI high", "P low", "P high", "predicted / measured",
                "measured percentile [%]", "yield [%]", "failed", "verdict"]
        names = {"P low": f"P{lo:g}", "P high": f"P{hi:g}"}
        for stage in dict.fromkeys(res.comparison["stage"]):
            frame = res.stage(stage)
            sec.add_table(frame[cols + (["role"] if frame["role"].any() else [])].rename(columns=names),
                          caption=f"{stage[0].upper()}{stage[1:]}: published figures against the model")
        if len(res.orders):
            sec.add_table(res.orders, caption="Orders the measured TE spectrum shows as strong, against the "
                                              "predicted spectrum (median over the predicted reducers)")
            for stage, top in res.largest.items():
                sec.add_text(f"Largest predicted TE orders, {stage}: " + ", ".join(
                    f"{o} ({a:.3g}″)" for o, a in top) + ".")
        est = res.stage(res.comparison["stage"].iloc[0])[["source", "quantity", "estimated for this reducer"]]
        est = est[est["estimated for this reducer"] != ""].drop_duplicates("source")
        if len(est):
            sec.add_table(est[["source", "estimated for this reducer"]],
                          caption="Reducer data rvtol had to estimate to predict each source's figures")
        sec.add_text(text.calibration(res.calibration))
        if res.calibration is not None:
            sec.add_table(res.calibration.to_frame(), caption="Calibration: the tolerance scales evaluated")
        if np.isfinite(res.comparison["predicted / measured"].astype(float)).any():
            sec.add_figure(res.plot(), caption="Predicted / measured per published figure (log scale)")
        sec.add_text(text.misses(res))
        if len(res.missing):
            sec.add_table(res.missing, caption="Looked for and not found, or found and not read")
        sec.summary = res.summary()
        return sec
