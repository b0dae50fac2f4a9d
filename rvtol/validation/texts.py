"""What a validation section says: its prose and the layout of a :class:`.validate.ValidationResult` as report
blocks (:mod:`rvtol.blocks`); the analysis (:mod:`.analyses`) names :func:`layout`."""
from __future__ import annotations

import numpy as np

from ..blocks import Figure, Table, Text, figure_png
from .validate import EPISTEMIC_COLUMNS

INTRODUCTION = (
    "Each published figure of an {reducer} is predicted by the model as it is — its nominal point and a Monte Carlo "
    "sample of {n} reducers of the tolerance spec — before any calibration. A measured value (a TE peak-to-peak from "
    "its printed extremes, …) is one unit the maker built: it is judged against the predicted spread — predicted "
    "median / measured, the measured value's percentile among the predicted units, and whether it lies inside the "
    "central {i:.0f} % of them (its reading uncertainty allowed for). A catalogue bound holds for every shipped unit: "
    "'consistent' when the central {i:.0f} % of the predicted units meet it, 'partly' when only the median does, "
    "'contradicts' when the median does not. The median's interval is distribution-free (two order statistics). "
    "Measured strong orders of a TE spectrum are compared in shape only (their amplitudes are not known): 'present' "
    "when the predicted order reaches {t:.0f} % of the largest predicted order. A measured spectrum with amplitudes "
    "is compared in shape — each order's amplitude over the reference order's, against the predicted units' same "
    "ratio — which also holds for another reducer of the same order lattice (pins, ratio). Rows with a role "
    "'sensitivity' (the same figure against another output, e.g. with an assumed test rig) or 'published model "
    "result' (the authors' own simulation) stand beside the prediction and are not judged. A figure of another "
    "reducer, or of a quantity no model output is mapped to, is listed with the reason it is not predicted; sources "
    "found but not read are listed at the end.")

CALIBRATED = (
    "Calibration on one figure, {on} ({measured:.4g} {unit}): the published figures read are scalars, so one "
    "parameter is fitted — the tolerance scale s that multiplies every tolerance of the spec about its middle (the "
    "measured units' parts made to s × the drawing's bands), on the same uniform design for every s. s = {s:.4g} "
    "brings the predicted median to the measured value ({message}). Every other figure is then predicted with it "
    "(hold-out). A scale far from 1 says the drawing's tolerances do not explain the measurement; a hold-out the "
    "calibrated model misses says the fitted parameter is not what differs. Another unit of the same design and "
    "quantity is predicted by the same distribution the calibration centred, so its ratio is the two "
    "measurements' ratio by construction: it is listed as 'not a hold-out'.")

EPISTEMIC = (
    "Beside the tolerance band, the estimated design's own band: {n} designs drawn over the ranges of its {k} estimated "
    "numbers (design file: range, basis), each rebuilt into the whole model ({ok} gave a prediction) and evaluated at "
    "nominal tolerances{u_text} — 'epistemic min/max' over the designs, 'designs × units' the central band of the "
    "designs' units. 'With the estimates' says whether a measured figure lies within what the estimates admit and by "
    "how much it misses otherwise; the estimated numbers with the largest first-order index on the output are the ones "
    "that could explain a miss. Nothing is fitted: the ranges are the design file's.")

COLUMNS = ["source", "quantity", "unit under test", "kind", "measured", "± reading", "unit", "nominal", "median",
           "median CI low", "median CI high", "P low", "P high", "predicted / measured", "measured percentile [%]",
           "yield [%]", "failed", "verdict"]


def calibration(fit) -> str:
    if fit is None:
        return "No calibration was asked for."
    if not fit.success:
        return f"Calibration on {fit.on} failed: {fit.message}."
    return CALIBRATED.format(on=fit.on, measured=fit.measured, unit=fit.unit, s=fit.value, message=fit.message)


def misses(result) -> str:
    """One sentence per figure the model does not agree with, in each stage."""
    lines = []
    for _, r in result.misses().iterrows():
        if isinstance(r.get("measured reducer"), str):           # a measured spectrum's shape
            ratio = next(k for k in r.index if k.startswith("measured / order") and np.isfinite(r[k]))
            pred = "predicted / order" + ratio[len("measured / order"):]
            lines.append(f"{r['stage']}: order {int(r['order [1/rev]'])} of {r['source']}:{r['quantity']} "
                         f"({r['measured reducer']}) is {r[ratio]:.3g} × the reference order's in the measurement "
                         f"(±{r['± ratio [%]']:.0f} %), {r[pred]:.3g} in the prediction: {r['verdict']}.")
            continue
        if np.isfinite(r.get("order [1/rev]", np.nan)):
            lines.append(f"{r['stage']}: order {int(r['order [1/rev]'])} of {r['source']}:{r['quantity']} is strong "
                         f"in the measurement; the model gives it {r['predicted amplitude [arcsec]']:.3g}″, "
                         f"{r['of the largest predicted order [%]']:.2g} % of its largest order.")
            continue
        what = f"{r['source']}:{r['quantity']} ({r['what']}, {r['unit under test']})"
        if r["kind"] in ("value", "range"):
            lines.append(f"{r['stage']}: {what} measured {r['measured']:.4g} {r['unit']}, predicted median "
                         f"{r['median']:.4g} (central interval {r['P low']:.4g}–{r['P high']:.4g}; ratio "
                         f"{r['predicted / measured']:.3g}): {r['verdict']}, the measured value at the "
                         f"{r['measured percentile [%]']:.3g}th percentile of the predicted units.")
        else:
            lines.append(f"{r['stage']}: {what} {r['kind'].replace('_', ' ')} {r['measured']:.4g} {r['unit']}, "
                         f"predicted median {r['median']:.4g} (central interval {r['P low']:.4g}–"
                         f"{r['P high']:.4g}), {r['yield [%]']:.3g} % of the predicted units within: {r['verdict']}.")
    if not lines:
        return "The model agrees with every figure it predicts."
    return "Where the model misses: " + " ".join(lines)


def layout(res, o) -> list:
    blocks = [Text(INTRODUCTION.format(reducer=o.reducer, n=res.n, i=100 * res.interval, t=100 * o.order_threshold)),
              Table(res.sources_frame().drop(columns=["file"]), "Published sources")]
    lo, hi = 50 * (1 - res.interval), 50 * (1 + res.interval)
    names = {"P low": f"P{lo:g}", "P high": f"P{hi:g}"}
    for stage in dict.fromkeys(res.comparison["stage"]):
        frame = res.stage(stage)
        cols = COLUMNS + (["role"] if frame["role"].any() else [])
        if "with the estimates" in frame and (frame["with the estimates"] != "").any():
            cols += [c for c in EPISTEMIC_COLUMNS if c in frame and frame[c].notna().any() and (frame[c] != "").any()]
        blocks.append(Table(frame[cols].rename(columns=names), f"{stage[0].upper()}{stage[1:]}: published figures "
                                                                "against the model"))
    if len(res.orders):
        blocks.append(Table(res.orders, "Orders the measured TE spectrum shows as strong, against the predicted "
                                        "spectrum (median over the predicted reducers)"))
    if len(res.shape):
        blocks.append(Table(res.shape.rename(columns=names), "Measured order amplitudes against the predicted "
                                                            "spectra, in shape (relative to the reference order)"))
        for stage, top in res.largest.items():
            blocks.append(Text(f"Largest predicted TE orders, {stage}: "
                               + ", ".join(f"{k} ({a:.3g}″)" for k, a in top) + "."))
    first = res.stage(res.comparison["stage"].iloc[0])
    est = first[first["estimated for this reducer"] != ""].drop_duplicates("source")
    if len(est):
        blocks.append(Table(est[["source", "estimated for this reducer"]],
                            "Reducer data rvtol had to estimate to predict each source's figures"))
    blocks.append(Text(calibration(res.calibration)))
    if res.calibration is not None:
        blocks.append(Table(res.calibration.to_frame(), "Calibration: the tolerance scales evaluated"))
    if np.isfinite(res.comparison["predicted / measured"].astype(float)).any():
        blocks.append(Figure(figure_png(res.plot()), "Predicted / measured per published figure (log scale)"))
    if res.epistemic is not None:
        e = res.epistemic
        units = e.settings.get("tolerance_samples", 0)
        blocks.append(Text(EPISTEMIC.format(n=e.n, k=len(e.inputs), ok=int(e.ok.sum()),
                                            u_text=f" and over {units} units of the tolerance spec each" if units else "")))
        blocks.append(Table(e.to_frame(), "The estimated design's band of each mapped output"))
    blocks.append(Text(misses(res)))
    if len(res.missing):
        blocks.append(Table(res.missing, "Looked for and not found, or found and not read"))
    return blocks
