"""``validate``: the model's predictions of published measurements, before and after a calibration.

::

    from rvtol.validation import validate, load_published_files
    res = validate(model, spec, load_published_files(paths), {"transmission_error_pp": "te.te_pp"},
                   reducer="RV-80E", n=400, method="lhs", seed=1,
                   calibrate_on="yang2021_mmt:te_pp_prototype_1")
    res.to_frame()            # quantity, measured, predicted (nominal, median, interval), ratio, verdict, per stage
    res.orders                # measured strong TE orders against the predicted spectrum
    res.calibration           # the fitted tolerance scale

1. **Prediction, no calibration.**  Every published figure of the study's reducer whose quantity the study
   maps to a model output is predicted by the model as it is: its nominal point and a Monte Carlo sample of
   the tolerance spec (``n``, ``method``, ``seed``: the study's own sample when ``known`` is given), and
   compared (:mod:`.agreement`).  A figure of another reducer, or of a quantity no output is mapped to, is
   listed with the reason it is not predicted.
2. **Calibration on one figure, the others predicted (hold-out).**  The published figures read are
   scalars (a TE peak-to-peak, catalogue bounds), not curves: what one scalar can fix is one parameter.
   ``tolerance_scale`` ``s`` multiplies every tolerance of the spec about its middle
   (:meth:`rvtol.spec.ToleranceSpec.scaled`: the parts of the measured units made to ``s`` × the drawing's
   bands) and is fitted so that the predicted median equals the figure ``calibrate_on`` — on the same
   uniform design for every ``s`` (common random numbers: the median is a continuous function of ``s``),
   by Brent's method (:func:`scipy.optimize.brentq`) in ``bounds``.  Every other figure is then predicted
   with the fitted ``s``.
3. **The estimated design's own band** (``epistemic``: an :class:`rvtol.epistemic.EpistemicResult` of the mapped
   outputs): beside each prediction's tolerance band, the band over the designs the estimated numbers' ranges admit
   (at nominal tolerances, and designs × units where computed), whether the measured figure lies within the
   estimates' reach, by how much it misses otherwise, and the estimated numbers that drive it most (first-order
   index) — which of them could explain a miss.  Nothing is fitted by it.  A curve measurement (torsion or TE curve) would be calibrated with
   :mod:`rvtol.models.calibration` instead; none was readable in the published sources found.

   A hold-out must be able to fail.  A figure of the same reducer and quantity as the calibration figure
   (another unit of the same design, e.g. a second prototype) is predicted by the *same* distribution the
   calibration just centred on the first: its ratio is the ratio of the two measurements by construction, so
   it is listed with the role "same predicted distribution as the calibration figure: not a hold-out" and
   never counted as one.  Hold-outs are figures of other quantities, or bounds (a catalogue bound, the strong
   orders of the measured spectrum), each of which the calibrated model can miss.

Beside the prediction, never judged:

* ``sensitivity_outputs`` — ``{published quantity: [other model outputs]}``: the same figure against an
  alternative output (e.g. the TE an assumed test rig would read, ``te.te_pp_rig``, beside the reducer's
  own ``te.te_pp``), role "sensitivity";
* figures with ``origin = "model"`` — a published model's own result (e.g. the authors' simulation of
  their prototypes), role "published model result";
* ``shape_of`` — measured spectra (``order_amplitudes``) of another reducer with the same order lattice
  (``lattice`` = the design's pins and ratio), compared with the predicted spectra in shape
  (:func:`.agreement.compare_shape`, relative to ``reference_order``: default the pin count, the mesh order).

``stands_for``: other reducer names whose figures the study's design predicts (e.g. the "RV-E series" of a
catalogue bound).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import optimize

from ..errors import InputError
from ..mc import EvaluationCache, Evaluator
from ..records import frame_records
from ..sampling import sample
from .agreement import compare_limit, compare_orders, compare_shape, compare_value, largest_orders
from .published import PublishedQuantity, PublishedSource, display_value

PARAMETERS = ("tolerance_scale",)
BEFORE = "predicted (no calibration)"
HOLD_OUT, CALIBRATED_ON = "hold-out", "calibrated on"
SAME = "same predicted distribution as the calibration figure: not a hold-out"
SENSITIVITY = "sensitivity: {output} beside the prediction, not judged"
MODEL_RESULT = "published model result (not a measurement): beside the prediction, not judged"
#: roles whose rows are never misses of the model
NOT_JUDGED = ("sensitivity", "published model result")


@dataclass
class ScaleFit:
    """The fitted tolerance scale (``value`` None when no scale in ``bounds`` reproduces the figure)."""

    parameter: str
    on: str
    output: str
    measured: float
    unit: str
    bounds: tuple[float, float]
    value: float | None
    history: list[tuple[float, float]]       # (s, predicted median) in the order evaluated
    success: bool
    message: str

    @property
    def stage(self) -> str:
        return (f"after calibration ({self.parameter} = {self.value:.4g} fitted to {self.on})" if self.success
                else f"calibration on {self.on} failed")

    def to_frame(self) -> pd.DataFrame:
        return pd.DataFrame([{"tolerance scale": s, f"predicted median [{self.unit}]": m,
                              f"measured [{self.unit}]": self.measured} for s, m in sorted(self.history)])


@dataclass
class ValidationResult:
    """Comparisons (display units of the mapped outputs) per stage; sources and what was not read."""

    sources: tuple[PublishedSource, ...]
    comparison: pd.DataFrame
    orders: pd.DataFrame
    missing: pd.DataFrame
    calibration: ScaleFit | None
    n: int
    interval: float
    largest: dict = field(default_factory=dict)     # stage -> [(order, amplitude)] of the predicted TE
    shape: pd.DataFrame = field(default_factory=pd.DataFrame)   # measured spectra against the predicted, in shape
    epistemic: object = None                        # the estimated design's band (rvtol.epistemic), when computed

    def to_frame(self) -> pd.DataFrame:
        return self.comparison

    def sources_frame(self) -> pd.DataFrame:
        return pd.DataFrame([{"source": s.id, "citation": s.citation, "status": s.status, "read from": s.read_from,
                              "reducer": s.reducer, "how read": s.how_read, "accessed": s.accessed,
                              "figures": len(s.quantities), "file": s.file} for s in self.sources])

    def stage(self, name: str) -> pd.DataFrame:
        return self.comparison[self.comparison["stage"] == name].reset_index(drop=True)

    def misses(self) -> pd.DataFrame:
        """The predicted rows where the model does not agree with the publication (every stage; rows beside the
        prediction — sensitivities, published model results — are not judged)."""
        bad = self.comparison["verdict"].isin(["above the predicted interval", "below the predicted interval",
                                               "partly", "contradicts"])
        judged = ~self.comparison["role"].astype(str).str.startswith(NOT_JUDGED)
        rows = self.comparison[bad & judged]
        parts = [rows]
        if len(self.orders):
            parts.append(self.orders[self.orders["verdict"] == "absent"])
        if len(self.shape):
            parts.append(self.shape[self.shape["verdict"].str.startswith("misses")])
        parts = [p for p in parts if len(p)]
        return pd.concat(parts, ignore_index=True) if parts else rows.reset_index(drop=True)

    def plot(self, ax=None):
        from ..plotting.validation import ratio_chart

        return ratio_chart(self.comparison, ax=ax)

    def summary(self) -> dict:
        cal = None
        if self.calibration is not None:
            c = self.calibration
            cal = {"parameter": c.parameter, "on": c.on, "output": c.output, "measured": c.measured, "unit": c.unit,
                   "bounds": list(c.bounds), "value": c.value, "success": c.success, "message": c.message,
                   "history": [list(h) for h in c.history]}
        return {"n": self.n, "interval": self.interval,
                "sources": frame_records(self.sources_frame()),
                "comparison": frame_records(self.comparison), "orders": frame_records(self.orders),
                "shape": frame_records(self.shape),
                "missing": frame_records(self.missing), "calibration": cal,
                "largest_predicted_orders": {k: [list(x) for x in v] for k, v in self.largest.items()},
                "epistemic": self.epistemic.summary() if self.epistemic is not None else None}


def _estimated(src: PublishedSource) -> str:
    return "; ".join(f"{k}: {v}" for k, v in src.estimated.items())


def _not_predicted(src: PublishedSource, q: PublishedQuantity, reducer: str, outputs: dict, spectrum: bool,
                   stands_for=(), shape_of=(), lattice=None) -> str:
    if q.kind == "order_amplitudes" and (q.key in shape_of or q.reducer in (reducer, *stands_for)):
        if not spectrum:
            return "not compared: the study gives no TE model for the spectrum"
        if lattice is not None and (q.pins, q.ratio) != tuple(lattice):
            return (f"not compared: its order lattice (pins {q.pins}, ratio {q.ratio:g}) is not the design's (pins "
                    f"{lattice[0]}, ratio {lattice[1]:g})")
        return ""
    if q.reducer != reducer and q.reducer not in stands_for:
        why = src.estimated.get("design", f"a study whose design is an {q.reducer} predicts it")
        return f"not predicted: the study's design is an {reducer}; this figure's reducer: {q.reducer} ({why})"
    if q.kind == "orders":
        return "" if spectrum else "not predicted: the study gives no TE model for the spectrum"
    if q.quantity not in outputs:
        return f"not predicted: the study maps no model output to {q.quantity!r}"
    return ""


class _Predictor:
    """The model's outputs over the scaled spec's sample; every evaluation through one Evaluator."""

    def __init__(self, model, spec, n, method, seed, evaluator, known):
        self.model, self.spec, self.n, self.method, self.seed = model, spec, n, method, seed
        self.evaluator = evaluator or Evaluator(cache=EvaluationCache())
        self.known = known
        self._sub: dict[tuple, object] = {}

    def spec_at(self, s: float):
        return self.spec if s == 1.0 else self.spec.scaled({f: s for f in self.spec.names})

    def samples(self, s: float) -> np.ndarray:
        return sample(self.spec_at(s), self.n, self.method, self.seed).values

    def _restricted(self, outputs: tuple[str, ...]):
        if outputs not in self._sub:
            r = getattr(self.model, "restricted", None)
            self._sub[outputs] = r(list(outputs)) if r is not None else self.model
        return self._sub[outputs]

    def predict(self, s: float, outputs, desc: str) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray]:
        """``({output: display values, NaN where the sample failed}, X, ok)`` at scale ``s``."""
        outputs = tuple(outputs)
        X = self.samples(s)
        if s == 1.0 and self.known is not None:
            kX, kY, kok = self.known
            if kX.shape == X.shape and np.array_equal(kX, X) and all(o in kY for o in outputs):
                return {o: np.where(kok, kY[o], np.nan) for o in outputs}, X, kok.copy()
        sub = self._restricted(outputs)
        ev = self.evaluator(sub, X, desc)
        ok = ev.status == 0
        out = {}
        for o in outputs:
            j = [q.name for q in sub.outputs].index(o)
            out[o] = np.where(ok, sub.outputs[j].to_display(ev.Y[:, j]), np.nan)
        return out, X, ok

    def nominal(self, s: float, outputs) -> dict[str, float]:
        outputs = tuple(outputs)
        sub = self._restricted(outputs)
        ev = self.evaluator(sub, self.spec_at(s).nominal_base()[None, :], "validation: nominal")
        if ev.status[0] != 0:
            return {o: float("nan") for o in outputs}
        names = [q.name for q in sub.outputs]
        return {o: float(sub.outputs[names.index(o)].to_display(ev.Y[0, names.index(o)])) for o in outputs}


def _row(stage, src, q, measured, unc, unit, nominal, cmp, failed, role) -> dict:
    return {"stage": stage, "source": src.id, "quantity": q.id, "what": q.quantity, "reducer": q.reducer,
            "unit under test": q.unit_under_test, "kind": q.kind, "measured": measured, "± reading": unc,
            "unit": unit, "nominal": nominal, "median": cmp.get("median", np.nan),
            "median CI low": cmp.get("median_low", np.nan), "median CI high": cmp.get("median_high", np.nan),
            "P low": cmp.get("low", np.nan), "P high": cmp.get("high", np.nan),
            "predicted / measured": cmp.get("ratio", np.nan), "measured percentile [%]": cmp.get("percentile", np.nan),
            "yield [%]": cmp.get("yield", np.nan), "n": cmp.get("n", 0), "failed": failed,
            "verdict": cmp.get("verdict", ""), "role": role, "estimated for this reducer": _estimated(src)}


def validate(model, spec, sources, outputs: dict[str, str], *, reducer: str, n: int, method: str = "lhs",
             seed: int | None = None, evaluator: Evaluator | None = None, known=None, te_spectra=None,
             calibrate_on: str | None = None, parameter: str = "tolerance_scale",
             bounds: tuple[float, float] = (0.25, 10.0), interval: float = 0.95, confidence: float = 0.95,
             order_threshold: float = 0.10, spectrum_samples: int = 16, rtol: float = 0.02, stands_for=(),
             sensitivity_outputs: dict | None = None, shape_of=(), lattice=None,
             reference_order: int | None = None, epistemic=None) -> ValidationResult:
    """Predict every published figure of ``reducer`` (module docstring).

    ``outputs``: published quantity name -> the model output that predicts it; ``known``: ``(X, {output: display
    values}, ok)`` already evaluated on the unscaled sample (the study's Monte Carlo), used when ``X`` is that
    sample; ``te_spectra(X) -> [TE amplitude per order of one output revolution (arcsec; index = order) or None]``
    for the measured TE orders and spectra; ``lattice``: ``(pins, ratio)`` of the design, which a spectrum of
    another reducer must share to be compared in shape; ``reference_order``: the order a shape is relative to
    (default: the pins).
    """
    sources = tuple(sources)
    sens = {q: list(v) for q, v in (sensitivity_outputs or {}).items()}
    _check_arguments(model, outputs, sens, parameter, bounds)
    quantities = [(src, q) for src in sources if src.status == "read" for q in src.quantities]
    by_key = {q.key: (src, q) for src, q in quantities}
    spectra_known = [k for k, (_, q) in by_key.items() if q.kind == "order_amplitudes"]
    for key in shape_of:
        if key not in spectra_known:
            raise InputError(f"{key!r} is not a published order_amplitudes figure (known: "
                             f"{', '.join(spectra_known) or 'none'})", key="shape_of")
    spectrum = te_spectra is not None
    reason = {q.key: _not_predicted(src, q, reducer, outputs, spectrum, tuple(stands_for), tuple(shape_of), lattice)
              for src, q in quantities}
    numeric = [(src, q) for src, q in quantities if q.numeric and not reason[q.key]]
    order_qs = [(src, q) for src, q in quantities if q.kind == "orders" and not reason[q.key]]
    shape_qs = [(src, q) for src, q in quantities if q.kind == "order_amplitudes" and not reason[q.key]]
    needed = tuple(dict.fromkeys(outputs[q.quantity] for _, q in numeric))
    extra = tuple(dict.fromkeys(o for _, q in numeric for o in sens.get(q.quantity, ()) if o not in needed))
    target = None if calibrate_on is None else _calibration_target(calibrate_on, by_key, reason)
    pred = _Predictor(model, spec, n, method, seed, evaluator, known)
    rows, order_rows, shape_rows, largest = [], [], [], {}

    def role_of(stage: str, q: PublishedQuantity) -> str:
        if not q.measured:
            return MODEL_RESULT
        if target is None or stage == BEFORE:
            return ""
        t = target[1]
        if q.key == t.key:
            return CALIBRATED_ON
        if (q.reducer, q.quantity) == (t.reducer, t.quantity) and q.kind in ("value", "range"):
            return SAME         # another unit of the same distribution: its ratio is the two measurements' ratio
        return HOLD_OUT

    def compared(q, out, v, stage, s, nom, src, role):
        unit = model.output(out).shown_unit
        meas, unc = display_value(q, unit)
        if q.kind in ("value", "range"):
            cmp = compare_value(meas, unc, v, interval, confidence)
        else:
            cmp = compare_limit(meas, q.kind == "upper_limit", v, interval, confidence)
        return _row(stage, src, q, meas, unc, unit, nom.get(out, np.nan), cmp, int(np.sum(~np.isfinite(v))), role)

    def stage_rows(stage: str, s: float, values: dict, ok: np.ndarray, X: np.ndarray) -> None:
        nom = pred.nominal(s, needed + (extra if stage == BEFORE else ())) if needed else {}
        for src, q in numeric:
            out = outputs[q.quantity]
            rows.append(compared(q, out, values[out], stage, s, nom, src, role_of(stage, q)))
            if stage == BEFORE and q.measured:
                for alt in sens.get(q.quantity, ()):
                    rows.append(compared(q, alt, values[alt], stage, s, nom, src, SENSITIVITY.format(output=alt)))
        if order_qs or shape_qs:
            idx = np.flatnonzero(ok)[:spectrum_samples]
            spectra = te_spectra(X[idx]) if idx.size else []
            largest[stage] = largest_orders(spectra)
            role = "" if target is None or stage == BEFORE else HOLD_OUT
            order_rows.extend(_order_rows(stage, order_qs, spectra, order_threshold, role))
            for src, q in shape_qs:
                ref = reference_order if reference_order is not None else (lattice[0] if lattice else q.pins)
                shape_rows.extend(_shape_rows(stage, src, q, spectra, ref, interval))

    wanted = needed + extra
    values, X, ok = pred.predict(1.0, wanted, "validation: prediction") if wanted else ({}, pred.samples(1.0),
                                                                                     np.ones(n, bool))
    stage_rows(BEFORE, 1.0, values, ok, X)
    for src, q in quantities:
        if reason[q.key]:
            unit = q.unit
            rows.append(_row(BEFORE, src, q, q.value if q.numeric else np.nan,
                             q.reading_uncertainty if q.numeric else np.nan, unit, np.nan,
                             {"verdict": reason[q.key]}, 0, ""))
    fit = None
    if target is not None:
        src, q = target
        out = outputs[q.quantity]
        unit = model.output(out).shown_unit
        meas, _ = display_value(q, unit)
        fit = _fit_scale(pred, out, meas, unit, q.key, parameter, bounds, values[out], rtol)
        if fit.success:
            stage_rows(fit.stage, fit.value, *_predicted_after(pred, fit.value, out, needed))
    comparison = pd.DataFrame(rows)
    if epistemic is not None and len(comparison):
        comparison = _with_epistemic(comparison, epistemic, outputs)
    orders = pd.DataFrame(order_rows)
    return ValidationResult(sources, comparison, orders, _missing_frame(sources), fit, n, interval, largest,
                            pd.DataFrame(shape_rows), epistemic)


def _missing_frame(sources) -> pd.DataFrame:
    """What each source looked for and did not find or read."""
    return pd.DataFrame([{"source": s.id, "citation": s.citation, "source status": s.status, "what": m.what,
                          "status": m.status, "tried": m.tried} for s in sources for m in s.missing])


def _predicted_after(pred: _Predictor, s: float, fitted: str, needed: tuple[str, ...]):
    """``(values, ok, X)`` of the outputs ``needed`` at the fitted scale ``s``: the fitted output's sample was
    evaluated by the fit (the evaluator's cache has it), the rest now."""
    values, X, ok = pred.predict(s, (fitted,), "validation: after calibration")
    rest = tuple(o for o in needed if o != fitted)
    if rest:
        more, _, ok_more = pred.predict(s, rest, "validation: after calibration")
        values, ok = {**values, **more}, ok & ok_more
    return values, ok, X


def _check_arguments(model, outputs: dict, sens: dict, parameter: str, bounds) -> None:
    """Every mapped output is the model's (InputError naming it), the calibration's parameter and bounds are valid."""
    for out in list(outputs.values()) + [o for outs in sens.values() for o in outs]:
        model.output(out)
    if parameter not in PARAMETERS:
        raise InputError(f"unknown calibration parameter {parameter!r} (known: {', '.join(PARAMETERS)})",
                         key="calibration.parameter")
    if not (0 < bounds[0] < bounds[1]):
        raise InputError(f"bounds must satisfy 0 < low < high, got {list(bounds)}", key="calibration.bounds")


def _calibration_target(calibrate_on: str, by_key: dict, reason: dict):
    """``(source, figure)`` the calibration is fitted to: a measured value or range the study predicts."""
    if calibrate_on not in by_key:
        raise InputError(f"unknown published figure {calibrate_on!r}"
                         f" (known: {', '.join(by_key) or 'none'})", key="calibration.on")
    src, q = by_key[calibrate_on]
    if reason[q.key]:
        raise InputError(f"cannot calibrate on {calibrate_on!r}: {reason[q.key]}", key="calibration.on")
    if q.kind not in ("value", "range") or not q.measured:
        raise InputError(f"cannot calibrate on {calibrate_on!r}: a {q.kind} "
                         f"{'' if q.measured else 'of a published model '}is not a measured value",
                         key="calibration.on")
    return src, q


def _order_rows(stage: str, order_qs, spectra, threshold: float, role: str) -> list[dict]:
    """The measured strong orders of each figure against the predicted spectra (:func:`.agreement.compare_orders`)."""
    return [{"stage": stage, "source": src.id, "quantity": q.id, "reducer": q.reducer, "order [1/rev]": r["order"],
             "measured": "strong", "predicted amplitude [arcsec]": r["amplitude"],
             "of the largest predicted order [%]": 100.0 * r["share"],
             "reducers": len([a for a in spectra if a is not None]), "verdict": r["verdict"], "role": role}
            for src, q in order_qs for r in compare_orders(q.orders, spectra, threshold)]


def _shape_rows(stage: str, src, q, spectra, ref: int, interval: float) -> list[dict]:
    """A measured spectrum against the predicted ones in shape, relative to order ``ref``
    (:func:`.agreement.compare_shape`)."""
    unit = q.unit
    return [{"stage": stage, "source": src.id, "quantity": q.id, "measured reducer": q.reducer,
             "order [1/rev]": r["order"], f"measured [{unit}]": r["measured"],
             "± reading [%]": 100.0 * r["relative uncertainty"],
             f"measured / order {ref}": r["measured ratio"], "± ratio [%]": 100.0 * r["ratio uncertainty"],
             "predicted median [arcsec]": r["predicted"], f"predicted / order {ref}": r["predicted ratio"],
             "P low": r["low"], "P high": r["high"], "predicted / measured ratio": r["predicted / measured"],
             "reducers": r["n"], "verdict": r["verdict"]}
            for r in compare_shape(q.orders, q.amplitudes, q.relative_uncertainty, spectra, ref, interval)]


#: the columns the estimated design's band adds to the prediction's rows (module doc, item 3)
EPISTEMIC_COLUMNS = ["epistemic min", "epistemic max", "designs × units low", "designs × units high",
                     "with the estimates", "estimated drivers (S1)"]


def _with_epistemic(frame: pd.DataFrame, band, outputs: dict) -> pd.DataFrame:
    """The prediction rows (no calibration) of the mapped outputs with the epistemic band beside them."""
    names = [q.name for q in band.outputs]
    extra = {c: [] for c in EPISTEMIC_COLUMNS}
    for _, r in frame.iterrows():
        out = outputs.get(r["what"])
        if r["stage"] != BEFORE or out not in names or not r["n"]:
            for c in EPISTEMIC_COLUMNS:
                extra[c].append(np.nan if c not in ("with the estimates", "estimated drivers (S1)") else "")
            continue
        b = band.band(out)
        lo = b.get("combined low", b["epistemic min"])
        hi = b.get("combined high", b["epistemic max"])
        for c, v in zip(EPISTEMIC_COLUMNS[:4], (b["epistemic min"], b["epistemic max"], b.get("combined low", np.nan),
                                                b.get("combined high", np.nan))):
            extra[c].append(v)
        extra["with the estimates"].append(_reach(r, lo, hi, band.Y[band.ok, names.index(out)]))
        extra["estimated drivers (S1)"].append(band.drivers_text(out))
    return frame.assign(**extra)


def _reach(r, lo: float, hi: float, designs: np.ndarray) -> str:
    """Whether the measured figure lies within what the estimated numbers' ranges admit, and by how much it misses."""
    m, u = float(r["measured"]), float(r["± reading"]) if np.isfinite(r["± reading"]) else 0.0
    if r["kind"] in ("value", "range"):
        if m - u > hi:
            return f"misses: above every design by ×{m / hi:.3g} ({m - hi:.4g} {r['unit']})"
        if m + u < lo:
            return f"misses: below every design by ×{m / lo:.3g} ({lo - m:.4g} {r['unit']})"
        return "within the estimates' reach"
    meets = designs <= m if r["kind"] == "upper_limit" else designs >= m
    share = 100.0 * float(np.mean(meets)) if designs.size else np.nan
    if share == 100.0:
        return "every design meets it (nominal tolerances)"
    if share == 0.0:
        return "no design meets it (nominal tolerances)"
    return f"{share:.3g} % of the designs meet it (nominal tolerances)"


def _fit_scale(pred: _Predictor, output: str, measured: float, unit: str, key: str, parameter: str,
               bounds: tuple[float, float], at_one: np.ndarray, rtol: float) -> ScaleFit:
    """The tolerance scale whose predicted median of ``output`` equals ``measured`` (module docstring)."""
    lo, hi = bounds
    medians: dict[float, float] = {}
    history: list[tuple[float, float]] = []

    def median(s: float) -> float:
        if s not in medians:
            v = at_one if s == 1.0 else pred.predict(s, (output,), f"validation: tolerance scale {s:.4g}")[0][output]
            v = v[np.isfinite(v)]
            medians[s] = float(np.median(v)) if v.size else float("nan")
            history.append((s, medians[s]))
        return medians[s]

    def g(s: float) -> float:
        return median(s) - measured

    def result(value, success, message) -> ScaleFit:
        return ScaleFit(parameter, key, output, measured, unit, bounds, value, history, success, message)

    def clip(x: float) -> float:
        return min(max(x, lo), hi)

    a = clip(1.0)
    ga = g(a)
    if not np.isfinite(ga):
        return result(None, False, f"no successful prediction at tolerance scale {a:g}")
    if ga == 0:
        return result(a, True, "exact at the first evaluation")
    m0 = median(a)
    # first guess: the scale that makes the median proportional to the scale (errors acting linearly)
    b = clip(a * measured / m0) if m0 > 0 and measured > 0 else (hi if ga < 0 else lo)
    if b == a:
        b = hi if a < hi else lo
    gb = g(b)
    for _ in range(12):
        if not np.isfinite(gb) or np.sign(gb) != np.sign(ga):
            break
        # not bracketed: extrapolate the secant through the last two points by 1.5 × its step (the median is
        # concave in the scale where clearances saturate), at least a factor 1.25 from the last point
        slope = (gb - ga) / (b - a)
        if slope == 0 or not np.isfinite(slope):
            new = 2.0 * b if b > a else b / 2.0
        else:
            new = b - 1.5 * gb / slope
            new = max(new, 1.25 * b) if new > b else min(new, b / 1.25)
        new = clip(new)
        if new == b:
            break
        a, ga, b = b, gb, new
        gb = g(b)
    if not np.isfinite(gb):
        return result(None, False, f"no successful prediction at tolerance scale {b:g}")
    if np.sign(gb) == np.sign(ga):
        return result(None, False, f"no tolerance scale in [{lo:g}, {hi:g}] brings the predicted median to "
                                   f"{measured:.4g} {unit}: at {b:g} it is {median(b):.4g} {unit}")
    s, r = optimize.brentq(g, min(a, b), max(a, b), rtol=rtol, full_output=True, disp=False)
    return result(float(s), bool(r.converged), f"Brent's method: {r.function_calls} calls, {r.iterations} "
                                               f"iterations, relative tolerance {rtol:g}")
