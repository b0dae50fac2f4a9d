"""The prose of a validation report: what was compared, how to read the verdicts, where the model misses."""
from __future__ import annotations

import numpy as np


def introduction(result, reducer: str) -> str:
    i = 100.0 * result.interval
    return (f"Each published figure of an {reducer} is predicted by the model as it is — its nominal point and "
            f"a Monte Carlo sample of {result.n} reducers of the tolerance spec — before any calibration. A "
            f"measured value (a TE peak-to-peak from its printed extremes, …) is one unit the maker built: it is "
            f"judged against the predicted spread — predicted median / measured, the measured value's percentile "
            f"among the predicted units, and whether it lies inside the central {i:.0f} % of them (its reading "
            f"uncertainty allowed for). A catalogue bound holds for every shipped unit: 'consistent' when the "
            f"central {i:.0f} % of the predicted units meet it, 'partly' when only the median does, 'contradicts' "
            f"when the median does not. The median's interval is distribution-free (two order statistics). "
            f"A figure of another reducer, or of a quantity no model output is mapped to, is listed with the "
            f"reason it is not predicted; sources that were found but could not be read are listed at the end.")


def calibration(fit) -> str:
    if fit is None:
        return "No calibration was asked for."
    if not fit.success:
        return f"Calibration on {fit.on} failed: {fit.message}."
    return (f"Calibration on one figure, {fit.on} ({fit.measured:.4g} {fit.unit}): the published figures read are "
            f"scalars, so one parameter is fitted — the tolerance scale s that multiplies every tolerance of the "
            f"spec about its middle (the measured units' parts made to s × the drawing's bands), on the same "
            f"uniform design for every s. s = {fit.value:.4g} brings the predicted median to the measured "
            f"value ({fit.message}). Every other figure is then predicted with it (hold-out). A scale far from 1 "
            f"says the drawing's tolerances do not explain the measurement; a hold-out that the calibrated model "
            f"misses says the fitted parameter is not what differs.")


def misses(result) -> str:
    """One sentence per figure the model does not agree with, in each stage."""
    lines = []
    for _, r in result.misses().iterrows():
        if "order [1/rev]" in r and np.isfinite(r.get("order [1/rev]", np.nan)):
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
