"""The optimal adjustment of an assembly, step by step and against the accuracy weight Q.

:func:`adjustment_assessment` returns an :class:`AdjustmentAssessment`: the state-space matrices, an
example assembly at each Q with and without adjustment, the per-step RMS KC errors of a Monte Carlo
batch, the final error and effort against Q (with the error reduction per decade of Q: diminishing
returns), and the linear map from part errors to the final KC errors at the model's Q.
:func:`part_errors_from` reads the example's part errors from a design parameter or from numbers.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ... import units
from ...errors import InputError
from ...records import frame_records
from .model import AdjustedAssemblyModel
from .sweep import AccuracySweep, ExampleRuns, StepStatistics, accuracy_sweep, example_runs, step_statistics


def part_errors_from(raw, unit: str, design, model: AdjustedAssemblyModel) -> np.ndarray:
    """Part errors (rad, step order) from a design parameter name ``raw`` or from numbers in ``unit``;
    raises :class:`InputError` (the reason only: the caller knows the key)."""
    n = len(model.w_names)
    if isinstance(raw, str):
        if design is None:
            raise InputError("names a design parameter but the study has no design")
        if raw not in design:
            raise InputError(f"design has no parameter {raw!r}")
        vals = np.atleast_1d(np.asarray(design[raw], float))
        if units.dimension(design.param(raw).unit) != "angle":
            raise InputError(f"design parameter {raw!r} is not an angle")
    else:
        if not isinstance(raw, list) or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in raw):
            raise InputError("expected a design parameter name or an array of numbers")
        vals = units.to_base(np.asarray([float(v) for v in raw], float), unit)
    if len(vals) != n:
        raise InputError(f"expected {n} part errors ({', '.join(model.w_names)}), got {len(vals)}")
    return vals


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


@dataclass
class AdjustmentAssessment:
    """``F``: part errors to KC errors; ``steps``: the assembly steps; ``example``: the example assembly per
    Q; ``batch``: the Monte Carlo batch step by step (None without one); ``sweep``: final error and effort
    against Q; ``marginal``: per decade of Q; ``linear_map``: final KC error per unit part error at the
    model's Q."""

    model: AdjustedAssemblyModel
    part_errors: np.ndarray
    F: pd.DataFrame
    steps: pd.DataFrame
    example: ExampleRuns
    sweep: AccuracySweep
    marginal: pd.DataFrame
    linear_map: pd.DataFrame
    batch: StepStatistics | None = None

    def to_frame(self) -> pd.DataFrame:
        return self.sweep.to_frame()

    def plot(self, which: str = "example"):
        """The report's figure of ``which``: ``example`` (the example assembly's KC errors after each step),
        ``batch`` (the Monte Carlo batch's RMS KC error step by step; an error without a batch) or ``sweep``
        (final error and effort against Q)."""
        if which == "batch" and self.batch is None:
            raise ValueError("no Monte Carlo batch was assessed: no batch figure")
        parts = {"example": self.example, "batch": self.batch, "sweep": self.sweep}
        if which not in parts:
            raise ValueError(f"unknown figure {which!r} (expected example, batch or sweep)")
        return parts[which].plot()

    def summary(self) -> dict:
        m, lm = self.model, self.linear_map
        return {"accuracy_weight": None if math.isinf(m.accuracy) else m.accuracy,
                "example": frame_records(self.example.to_frame()), "sweep": frame_records(self.sweep.to_frame()),
                "linear_map": {r: {c: float(lm.loc[r, c]) for c in lm.columns} for r in lm.index}}


def adjustment_assessment(m: AdjustedAssemblyModel, w: np.ndarray, weights, Q: np.ndarray, X=None,
                          evaluate=None) -> AdjustmentAssessment:
    """``m``'s adjustment of the example assembly with part errors ``w`` at the accuracy ``weights``, swept
    over ``Q``; ``X``: a Monte Carlo batch of part errors (None: none), evaluated with ``evaluate``."""
    d = m.description
    F = frame_of(d.F_full(), d.state_names(), d.part_error_names())
    ex = example_runs(m, w, weights)
    batch = step_statistics(m, X) if X is not None else None
    sw = accuracy_sweep(m, w, Q, X, evaluate)
    M_w, _ = m.adjuster.linear_map()
    lm = frame_of(M_w, [f"delta_{n}" for n in d.observation_names()], list(m.w_names))
    return AdjustmentAssessment(m, w, F, d.to_frame(), ex, sw, marginal_table(sw), lm, batch)
