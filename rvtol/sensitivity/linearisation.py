"""The linearisation view: % contribution to variance, RSS and worst case, high/low/median.

With the five-point gradient S (base units) at the nominal point x0 and each
factor's mean μ_i, standard deviation σ_i and tolerance band [lo_i, hi_i]:

* first-order mean:   y0 + Σ S_i (μ_i − x0_i)
* RSS standard deviation (:func:`rvtol.stats.rss`): σ_y = √(Sᵀ C S), C_ij = ρ_ij σ_i σ_j (ρ: the Pearson correlation the
  spec's Gaussian copula gives the margins, :func:`rvtol.sampling.factor_correlation` — the normal-score
  correlation itself for two normal factors, smaller in size for others);
* % contribution to variance (independent factors): 100·(S_i σ_i)² / Σ_j (S_j σ_j)²;
* worst case: y0 + Σ min/max(S_i (lo_i − x0_i), S_i (hi_i − x0_i)).

:func:`linear_prediction` works on any gradient (the stack-up and
allocation helpers reuse it); :func:`contributions` runs the five-point
derivatives first.  :func:`high_low_table` is *not* linearised: it
evaluates the model with one factor at a time at its low limit, median and
high limit (the classic one-at-a-time "swing" table behind a tornado chart).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import pandas as pd

from .. import units
from ..model import Model
from ..spec import ToleranceSpec
from ..mc import Evaluator
from ..records import frame_records
from ..sampling import factor_correlation
from ..stats import rss
from .common import (derivative_to_display, factor_indices, model_gradient, output_indices,
                     ratio_unit)
from .local import LocalSensitivityResult, five_point


@dataclass
class LinearPrediction:
    """What the linearisation predicts for one output (display units) and the per-factor table."""

    output: str
    unit: str
    y0: float
    mean: float
    std: float
    worst_low: float
    worst_high: float
    frame: pd.DataFrame  # factor, S, S_unit, sigma, S_sigma, variance_pct, worst_case_share
    sigma_level: float = 3.0
    notes: list[str] = field(default_factory=list)

    def to_frame(self) -> pd.DataFrame:
        return self.frame

    def summary(self) -> dict:
        k = self.sigma_level
        return {"output": self.output, "unit": self.unit, "y_nominal": self.y0, "mean_first_order": self.mean,
                "std_rss": self.std, f"rss_low_{k:g}sigma": self.mean - k * self.std,
                f"rss_high_{k:g}sigma": self.mean + k * self.std,
                "worst_case_low": self.worst_low, "worst_case_high": self.worst_high}

    def plot(self, ax=None):
        from ..plotting.sensitivity import contribution_bars

        return contribution_bars(self, ax=ax)


def linear_prediction(spec: ToleranceSpec, gradient: np.ndarray, y0: float, x0: np.ndarray | None = None,
                      output: str = "y", out_unit: str = "1", out_base_unit: str | None = None,
                      sigma_level: float = 3.0) -> LinearPrediction:
    """Linearised mean, RSS σ, worst case and % contributions from a base-unit ``gradient``.

    ``gradient[k]`` is ∂y/∂x_k in output base unit per factor base unit (NaN
    or 0 for factors that do not act); ``y0`` is the output at ``x0`` (base
    units; default the spec's nominal point).  Results are in ``out_unit``.
    """
    g = np.nan_to_num(np.asarray(gradient, dtype=float), nan=0.0)
    x0 = spec.nominal_base() if x0 is None else np.asarray(x0, dtype=float)
    mu, sd = spec.mean_base(), spec.std_base()
    lims = np.array([[units.to_base(v, f.unit) for v in f.band] for f in spec.factors])
    dlo, dhi = g * (lims[:, 0] - x0), g * (lims[:, 1] - x0)
    contrib = g * sd
    corr = factor_correlation(spec)          # the copula's Pearson correlation of the margins (None: independent)
    sd_y = rss(contrib, np.eye(len(spec)) if corr is None else corr)
    var_indep = float(rss(contrib, squared=True))
    ob = out_base_unit or units.base_unit(out_unit)
    disp = lambda v: float(units.convert(v, ob, out_unit))  # noqa: E731
    frame = pd.DataFrame({
        "factor": spec.names,
        "S": [float(derivative_to_display(v, out_unit, f.unit)) * units.factor(ob) for v, f in zip(g, spec.factors)],
        "S_unit": [ratio_unit(out_unit, f.unit) for f in spec.factors],
        "sigma": [f.dist.std for f in spec.factors],
        "factor_unit": spec.units,
        "S_sigma": [disp(c) for c in contrib],
        "variance_pct": 100.0 * contrib**2 / var_indep if var_indep > 0 else np.zeros(len(spec)),
        "dy_low": [disp(v) for v in dlo],
        "dy_high": [disp(v) for v in dhi],
    })
    notes = []
    if spec.correlation is not None:
        shown = f"{disp(rss(contrib)):.4g} {units.label(out_unit)}"
        notes.append(f"RSS σ includes the correlation (σ without it: {shown}); "
                     "% contributions are those of the independent factors.")
    return LinearPrediction(
        output, out_unit, disp(y0), disp(y0 + float(g @ (mu - x0))), disp(sd_y),
        disp(y0 + float(np.minimum(dlo, dhi).sum())), disp(y0 + float(np.maximum(dlo, dhi).sum())),
        frame, sigma_level, notes)


def contributions(model: Model, spec: ToleranceSpec, output: str | None = None,
                  local: LocalSensitivityResult | None = None, percent: float = 10.0,
                  evaluate: Evaluator | None = None) -> LinearPrediction:
    """The gradient of ``output`` at the nominal point — the model's exact one when it has ``gradient`` and
    no ``local`` result is given, else five-point — then :func:`linear_prediction`."""
    q = model.outputs[output_indices(model, [output] if output else None)[0]]
    G = model_gradient(model, spec.nominal_base()) if local is None else None
    if G is not None:   # the model's exact derivatives
        x0 = spec.nominal_base()
        y0 = float((evaluate or Evaluator())(model, x0[None], "nominal point").Y[0, model.output_index(q.name)])
        pred = linear_prediction(spec, G[model.output_index(q.name)], y0, output=q.name, out_unit=q.shown_unit,
                                 out_base_unit=q.unit)
        pred.notes.append("derivatives: the model's own (exact), not five-point differences")
        return pred
    if local is None:
        local = five_point(model, spec, outputs=[q.name], percent=percent, evaluate=evaluate)
    g = local.gradient(q.name, spec.names)
    y0 = float(local.for_output(q.name)["y0"].iloc[0])
    pred = linear_prediction(spec, g, units.convert(y0, q.shown_unit, q.unit), output=q.name,
                             out_unit=q.shown_unit, out_base_unit=q.unit)
    pred.notes.extend(local.notes)
    return pred


# --------------------------------------------------------------------------- high / low / median
@dataclass
class HighLowResult:
    """One-at-a-time outputs with one factor at its low limit, median and high limit."""

    frame: pd.DataFrame  # output, factor, low, median, high (factor unit), y_low, y_median, y_high, swing

    def to_frame(self) -> pd.DataFrame:
        return self.frame

    def plot(self, output: str, ax=None):
        from ..plotting.sensitivity import swing_tornado

        return swing_tornado(self, output, ax=ax)


def high_low_table(model: Model, spec: ToleranceSpec, factors: Sequence[str] | None = None,
                   outputs: Sequence[str] | None = None, evaluate: Evaluator | None = None) -> HighLowResult:
    """Evaluate the model with each factor in turn at its low limit, median and high limit.

    The other factors stay at nominal; limits are :attr:`rvtol.spec.Factor.band`.
    """
    model.check_spec(spec)
    evaluate = evaluate or Evaluator()
    idx = factor_indices(spec, factors)
    oidx = output_indices(model, outputs)
    x0 = spec.nominal_base()
    X = [x0.copy()]
    levels = []
    for i in idx:
        f = spec.factors[i]
        lo, hi = f.band
        med = float(f.dist.ppf(0.5))
        levels.append((lo, med, hi))
        for v in (lo, med, hi):
            x = x0.copy()
            x[i] = units.to_base(v, f.unit)
            X.append(x)
    ev = evaluate(model, np.array(X), "high/low/median")
    rows = []
    for j in oidx:
        q = model.outputs[j]
        y = q.to_display(ev.Y[:, j])
        for c, i in enumerate(idx):
            lo, med, hi = levels[c]
            ylo, ymed, yhi = (float(v) for v in y[1 + 3 * c: 4 + 3 * c])
            rows.append({"output": q.name, "output_unit": q.shown_unit, "factor": spec.names[i],
                         "factor_unit": spec.factors[i].unit, "low": lo, "median": med, "high": hi,
                         "y_nominal": float(y[0]), "y_low": ylo, "y_median": ymed, "y_high": yhi,
                         "swing": abs(yhi - ylo)})
    return HighLowResult(pd.DataFrame(rows))


# --------------------------------------------------------------------------- the contributions study
@dataclass
class ContributionsResult:
    """Per output: the linearised prediction (:func:`contributions`) beside the Monte Carlo's statistics, and
    the one-at-a-time high/low/median table."""

    outputs: list[str]
    percent: float
    predictions: dict[str, LinearPrediction]
    high_low: HighLowResult
    mc_statistics: pd.DataFrame | None = None     # the study's Monte Carlo statistics (rows: outputs)

    def to_frame(self) -> pd.DataFrame:
        return pd.concat([p.frame.assign(output=o) for o, p in self.predictions.items()], ignore_index=True)

    def plot(self, output: str | None = None, which: str = "variance", ax=None):
        """The report's figure of ``output`` (default: the first): ``variance`` (% contribution to variance of the
        linearised prediction) or ``swing`` (the one-at-a-time high/low swing)."""
        out = output or self.outputs[0]
        if out not in self.predictions:
            raise ValueError(f"no output {out!r} (outputs: {', '.join(self.outputs)})")
        if which == "variance":
            return self.predictions[out].plot(ax=ax)
        if which == "swing":
            return self.high_low.plot(out, ax=ax)
        raise ValueError(f"unknown figure {which!r} (expected variance or swing)")

    def summary(self) -> dict:
        hl = self.high_low.frame
        return {o: {"prediction": p.summary(), "contributions": frame_records(p.frame),
                    "high_low": frame_records(hl[hl["output"] == o])} for o, p in self.predictions.items()}


def linearised_contributions(model: Model, spec: ToleranceSpec, outputs: Sequence[str],
                             factors: Sequence[str] | None = None, percent: float = 10.0,
                             evaluate: Evaluator | None = None, mc_statistics: pd.DataFrame | None = None
                             ) -> ContributionsResult:
    """Five-point derivatives of every factor, the linearised prediction of each output, and the high/low/median
    table of ``factors`` (all when None)."""
    local = five_point(model, spec, None, outputs, percent, None, evaluate)
    hl = high_low_table(model, spec, factors, outputs, evaluate)
    preds = {o: contributions(model, spec, o, local) for o in outputs}
    return ContributionsResult(list(outputs), percent, preds, hl, mc_statistics)
