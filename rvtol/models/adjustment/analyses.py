"""Study analysis ``adjustment``: the optimal adjustment of an assembly, step by step and against Q.

::

    [[analysis]]
    kind = "adjustment"
    part_errors = "example.part_errors"   # a design parameter, or numbers (step order) with `unit`
    accuracy_weights = [0, 5, 10, "inf"]  # Q values of the example ("inf": terminal constraint)
    sweep = [0.01, 10000]                 # Q range of the sweep (log spaced)
    sweep_points = 41
    batch = true                          # also sweep the study's Monte Carlo samples

The study's model must be ``adjusted_assembly``.  The section shows the
state-space matrices, the example assembly at each Q with and without
adjustment, the per-step RMS KC errors of the Monte Carlo batch, the final
error and effort against Q, and the linear map from part errors to the
final KC errors at the study's Q.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ...analysis import Analysis
from ... import units
from ...report.sections import Section, frame_records
from .description import weight_value
from .model import AdjustedAssemblyModel
from .sweep import accuracy_sweep, example_runs, step_statistics


def require_adjusted_model(study, params) -> AdjustedAssemblyModel:
    if not isinstance(study.model, AdjustedAssemblyModel):
        raise params.error("kind", f"needs the study model kind 'adjusted_assembly', got {type(study.model).__name__}")
    return study.model


def part_errors(params, study, model: AdjustedAssemblyModel, key: str = "part_errors") -> np.ndarray:
    """Part errors (rad, step order) from a design parameter name or from numbers with ``unit``."""
    raw = params.raw(key)
    n = len(model.w_names)
    if isinstance(raw, str):
        if study.design is None:
            raise params.error(key, "names a design parameter but the study has no design")
        if raw not in study.design:
            raise params.error(key, f"design has no parameter {raw!r}")
        vals = np.atleast_1d(np.asarray(study.design[raw], float))
        if units.dimension(study.design.param(raw).unit) != "angle":
            raise params.error(key, f"design parameter {raw!r} is not an angle")
    else:
        unit = params.unit("unit", "mrad", dimension="angle")
        vals = units.to_base(np.asarray(params.floats(key), float), unit)
    if len(vals) != n:
        raise params.error(key, f"expected {n} part errors ({', '.join(model.w_names)}), got {len(vals)}")
    return vals


def accuracy_weights(params, key: str = "accuracy_weights", default=(0, 5, 10, "inf")) -> list[float]:
    raw = params.raw(key, list(default))
    if not isinstance(raw, list) or not raw:
        raise params.error(key, "expected a non-empty array of weights (numbers or \"inf\")")
    from ...params import Params

    p = Params({str(i): v for i, v in enumerate(raw)}, file=params.file, key=params.path(key))
    return [weight_value(p, str(i), allow_inf=True) for i in range(len(raw))]


class AdjustmentAnalysis(Analysis):
    def setup(self, params, study):
        self.model = require_adjusted_model(study, params)
        self.w = part_errors(params, study, self.model)
        self.weights = accuracy_weights(params)
        lo, hi = params.floats("sweep", [0.01, 1e4], length=2, positive=True)
        if not lo < hi:
            raise params.error("sweep", f"expected [low, high] with low < high, got [{lo}, {hi}]")
        self.sweep = np.geomspace(lo, hi, params.int("sweep_points", 41, min=3))
        self.batch = params.bool("batch", True)
        self.title = params.str("title", "Assembly adjustment (state space, finite-horizon LQR)")
        params.finish()

    def run(self, ctx) -> Section:
        m = self.model
        d = m.description
        sec = Section("adjustment", self.title)
        sec.add_text(describe(m))
        sec.add_table(frame_of(d.F_full(), d.state_names(), d.part_error_names()),
                      "F: part errors (columns, in installation order) to KC errors δ (rows) [rad/rad]",
                      float_format="{:.3g}", index=True)
        sec.add_table(d.to_frame(), f"Assembly steps; every other KC has effort weight R = {d.effort_locked:g}")

        ex = example_runs(m, self.w, self.weights)
        ex_df = ex.to_frame()
        sec.add_table(ex_df, "Example assembly (part errors "
                      + ", ".join(f"{n} = {units.from_base(v, 'mrad'):g}" for n, v in zip(m.w_names, self.w))
                      + " mrad): final KC errors and adjustment effort per accuracy weight Q", "{:.4g}")
        sec.add_figure(ex.plot(), "Example assembly: KC errors after each step with the optimal adjustment "
                       "(solid) and without adjustment (dashed)")

        X = ctx.mc.samples.values if self.batch else None
        if X is not None:
            st = step_statistics(m, X)
            sec.add_figure(st.plot(), f"Monte Carlo batch of the study's spec: RMS KC error after each step, "
                           f"Q = {units.number_label(m.accuracy)}")
            sec.add_table(st.to_frame(), "Monte Carlo batch: RMS KC error after each step", "{:.3g}")
        sw = accuracy_sweep(m, self.w, self.sweep, X, ctx.evaluator)
        sec.add_figure(sw.plot(), "Final KC error (RSS of the final observations) and adjustment effort against "
                       "the accuracy weight Q: the gain per unit of Q falls as Q grows (diminishing returns). The "
                       "Monte Carlo batch includes the spec's measurement noise, which the adjustment cannot remove: "
                       "it sets the floor of its RMS final error at large Q")
        marg = marginal_table(sw)
        sec.add_table(marg, "Diminishing returns: final error reduction per decade of Q", "{:.3g}")

        M_w, _ = m.adjuster.linear_map()
        lm = frame_of(M_w, [f"delta_{n}" for n in d.observation_names()], list(m.w_names))
        sec.add_table(lm, f"Linear map at Q = {units.number_label(m.accuracy)}: final KC error per unit part error [rad/rad]",
                      float_format="{:.4f}", index=True)
        sec.summary = {
            "accuracy_weight": None if math.isinf(m.accuracy) else m.accuracy,
            "example": frame_records(ex_df),
            "sweep": frame_records(sw.to_frame()),
            "linear_map": {r: {c: float(lm.loc[r, c]) for c in lm.columns} for r in lm.index},
        }
        return sec


def describe(m: AdjustedAssemblyModel) -> str:
    d = m.description
    return (f"{d.title}. State x = KC angular errors ({', '.join(d.state_names())}) relative to the datum; "
            f"x(k+1) = A x(k) + B u(k) + F(k) w(k), A = I (rigid), B = F (an adjustment acts like the part's error), "
            f"y(k) = C(k) x(k) + v(k) measures the KC installed at step k. Adjustments u(k) = −K(k) x̂(k) are applied "
            f"after the part of step k is installed and measured (x̂: Kalman estimate; exact without noise). "
            f"K(k) from the backward Riccati recursion with P(N) = Q(N) = Q·C(N)ᵀC(N), no stage cost; "
            f"R(k) = {d.effort_adjustable:g} on adjustable KCs and {d.effort_locked:g} elsewhere; "
            f"Q → ∞ is computed exactly as the terminal constraint C(N) x(N) = 0 with least effort. "
            f"Study model: Q = {units.number_label(m.accuracy)}{'' if m.adjust else ', adjustment switched off'}.")


def frame_of(M: np.ndarray, rows, cols) -> pd.DataFrame:
    df = pd.DataFrame(M, index=list(rows), columns=list(cols))
    df.index.name = "output"
    return df


def marginal_table(sw) -> pd.DataFrame:
    """Final-error reduction and effort added per decade of Q (example assembly): diminishing returns."""
    logq = np.log10(sw.Q)
    decades = np.arange(math.ceil(logq[0]), math.floor(logq[-1]) + 1)
    fe = np.exp(np.interp(decades, logq, np.log(np.maximum(sw.final_error, 1e-300))))
    ef = np.interp(decades, logq, sw.effort)
    mr = lambda v: float(units.from_base(v, "mrad"))  # noqa: E731
    return pd.DataFrame([{"Q from [1]": 10.0 ** decades[i - 1], "Q to [1]": 10.0 ** decades[i],
                          "final error at Q to [mrad]": mr(fe[i]),
                          "final error reduction [mrad]": mr(fe[i - 1] - fe[i]),
                          "effort added [mrad]": mr(ef[i] - ef[i - 1])} for i in range(1, len(decades))])
