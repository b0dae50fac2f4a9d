"""Results of the adjustment studies: one assembly at several Q, and the Q sweep.

* :func:`example_runs` simulates one assembly (given part errors) for each
  accuracy weight Q, with and without adjustment;
* :func:`accuracy_sweep` evaluates the final error and the effort against Q,
  for one assembly and (optionally) for a Monte Carlo batch through
  :func:`rvtol.mc.evaluate`, showing the diminishing returns of a larger Q.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ... import units
from ...mc import Evaluator
from .adjuster import AssemblyRun
from .model import AdjustedAssemblyModel


@dataclass
class ExampleRuns:
    """One assembly (part errors ``w``, rad) simulated at each Q, plus the unadjusted assembly."""

    weights: list[float]
    runs: list[AssemblyRun]
    unadjusted: AssemblyRun
    output_names: list[str]
    unit: str = "mrad"

    def to_frame(self) -> pd.DataFrame:
        rows = []
        for q, r in zip(self.weights, self.runs):
            row = {"Q": units.number_label(q)}
            for j, n in enumerate(self.output_names):
                row[f"{n} [{self.unit}]"] = self._shown(r.final[0, j])
            row[f"final_error [{self.unit}]"] = self._shown(np.linalg.norm(r.final[0]))
            row[f"effort [{self.unit}]"] = self._shown(r.effort[0])
            rows.append(row)
        return pd.DataFrame(rows)

    def _shown(self, v: float) -> float:
        """In display units; round-off below 1e-12 of the part errors (the exact zeros of Q = ∞) shown as 0."""
        scale = float(np.max(np.abs(self.unadjusted.x_installed)))
        return 0.0 if abs(v) <= 1e-12 * scale else float(units.from_base(v, self.unit))

    def plot(self, fig=None):
        from ...plotting.adjustment import example_steps

        return example_steps(self, fig=fig)


@dataclass
class AccuracySweep:
    """Final error and effort against Q: one assembly, and Monte Carlo batch statistics."""

    Q: np.ndarray
    final_error: np.ndarray  # one assembly (rad)
    effort: np.ndarray
    batch_rms_final: np.ndarray | None = None  # RMS over the batch of the final error norm (rad)
    batch_mean_effort: np.ndarray | None = None
    batch_n: int = 0
    unit: str = "mrad"
    unadjusted_final: float = math.nan
    unadjusted_batch_rms: float = math.nan
    notes: list[str] = field(default_factory=list)

    def to_frame(self) -> pd.DataFrame:
        u = self.unit
        df = pd.DataFrame({"Q": self.Q,
                           f"final error, example [{u}]": units.from_base(self.final_error, u),
                           f"effort, example [{u}]": units.from_base(self.effort, u)})
        if self.batch_rms_final is not None:
            df[f"RMS final error, MC [{u}]"] = units.from_base(self.batch_rms_final, u)
            df[f"mean effort, MC [{u}]"] = units.from_base(self.batch_mean_effort, u)
        return df

    def plot(self, fig=None):
        from ...plotting.adjustment import accuracy_sweep

        return accuracy_sweep(self, fig=fig)


def example_runs(model: AdjustedAssemblyModel, w: np.ndarray, weights) -> ExampleRuns:
    """Simulate the assembly with part errors ``w`` (rad, step order) at each Q."""
    w = np.atleast_2d(np.asarray(w, float))
    runs = [model.with_accuracy(q).adjuster.simulate(w) for q in weights]
    unadj = model.adjuster.simulate(w, adjust=False)
    return ExampleRuns(list(weights), runs, unadj, model.description.observation_names())


def accuracy_sweep(model: AdjustedAssemblyModel, w: np.ndarray, Q: np.ndarray, X_batch: np.ndarray | None = None,
                   evaluate=None) -> AccuracySweep:
    """Final error and effort vs ``Q`` for one assembly ``w`` and for a batch ``X_batch`` (spec columns, base).

    ``evaluate`` (an :class:`rvtol.mc.Evaluator`) runs the batch (default: serial).
    """
    evaluate = evaluate or Evaluator()
    w = np.atleast_2d(np.asarray(w, float))
    i_err, i_eff = model.output_index("final_error"), model.output_index("effort")
    fe, ef, rms, me = [], [], [], []
    for q in Q:
        mq = model.with_accuracy(float(q))
        r = mq.adjuster.simulate(w)
        fe.append(float(np.linalg.norm(r.final[0])))
        ef.append(float(r.effort[0]))
        if X_batch is not None:
            Y = evaluate(mq, X_batch, "adjustment sweep").Y
            rms.append(float(np.sqrt(np.nanmean(Y[:, i_err] ** 2))))
            me.append(float(np.nanmean(Y[:, i_eff])))
    unadj = model.with_accuracy(0.0, adjust=False)
    res = AccuracySweep(np.asarray(Q, float), np.array(fe), np.array(ef),
                        np.array(rms) if X_batch is not None else None,
                        np.array(me) if X_batch is not None else None,
                        0 if X_batch is None else len(X_batch))
    res.unadjusted_final = float(np.linalg.norm(unadj.adjuster.simulate(w, adjust=False).final[0]))
    if X_batch is not None:
        Y0 = evaluate(unadj, X_batch, "adjustment sweep").Y
        res.unadjusted_batch_rms = float(np.sqrt(np.nanmean(Y0[:, i_err] ** 2)))
    return res


@dataclass
class StepStatistics:
    """RMS over a Monte Carlo batch of each KC's error after every step, with and without adjustment."""

    state_names: list[str]
    adjusted: np.ndarray  # [N, n_state] RMS after the adjustment of step k (rad)
    unadjusted: np.ndarray  # [N, n_state] RMS after installing step k without any adjustment
    accuracy: float
    n: int
    unit: str = "mrad"

    def to_frame(self) -> pd.DataFrame:
        rows = []
        for k in range(self.adjusted.shape[0]):
            for i, nm in enumerate(self.state_names):
                rows.append({"step": k + 1, "KC": nm,
                             f"RMS unadjusted [{self.unit}]": float(units.from_base(self.unadjusted[k, i], self.unit)),
                             f"RMS adjusted [{self.unit}]": float(units.from_base(self.adjusted[k, i], self.unit))})
        return pd.DataFrame(rows)

    def plot(self, ax=None):
        from ...plotting.adjustment import step_statistics

        return step_statistics(self, ax=ax)


def step_statistics(model: AdjustedAssemblyModel, X: np.ndarray) -> StepStatistics:
    """Per-step RMS KC errors of the batch ``X`` (spec columns, base units)."""
    run = model.simulate(X)
    w, v = model.split(X)
    free = model.adjuster.simulate(w, v, adjust=False)
    rms = lambda a: np.sqrt(np.mean(a ** 2, axis=0))  # noqa: E731
    return StepStatistics(list(model.adjuster.state_names), rms(run.x_adjusted), rms(free.x_installed),
                          model.accuracy, len(X))
