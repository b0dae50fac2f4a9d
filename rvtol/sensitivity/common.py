"""Helpers shared by local and global sensitivity: evaluation, name checks, units.

An *evaluator* is any callable ``evaluate(X, desc) -> Evaluation`` (base
units in and out, see :func:`rvtol.mc.evaluate`).  Analyses pass
``lambda X, desc: ctx.evaluate(X, desc=desc)`` so every model evaluation runs
on the study's executor; library users get :func:`default_evaluator`.
"""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

from .. import units
from ..errors import InputError
from ..executors import Executor
from ..mc import Evaluation, evaluate
from ..model import Model
from ..sampling import rng
from ..spec import ToleranceSpec

Evaluator = Callable[[np.ndarray, str], Evaluation]

#: sub-stream keys: each method draws from its own stream of the study seed
STREAMS = {"sobol": 1, "morris": 2, "fast": 3, "rbd_fast": 4, "delta": 5, "pce": 6, "given_data": 7,
           "delta_subsample": 8}


class FrameResult:
    """Mixin of results whose ``frame`` has one row per output (column ``output``) and more."""

    frame: "pd.DataFrame"

    def to_frame(self):
        return self.frame

    @property
    def outputs(self) -> list[str]:
        return list(dict.fromkeys(self.frame["output"]))

    def for_output(self, output: str):
        return self.frame[self.frame["output"] == output].reset_index(drop=True)


def default_evaluator(model: Model, executor: Executor | None = None, progress: bool = False) -> Evaluator:
    """Evaluate ``model`` through :func:`rvtol.mc.evaluate` (serial unless an executor is given)."""

    def run(X: np.ndarray, desc: str = "evaluating") -> Evaluation:
        return evaluate(model, X, executor, progress=progress, desc=desc)

    return run


def factor_indices(spec: ToleranceSpec, factors: Sequence[str] | None) -> list[int]:
    """Indices of ``factors`` in ``spec`` (all when None); unknown names raise InputError."""
    if factors is None:
        return list(range(len(spec)))
    idx = [spec.index(n) for n in factors]
    if len(set(idx)) != len(idx):
        raise InputError("a factor is named twice", key="factors")
    if not idx:
        raise InputError("no factors selected", key="factors")
    return idx


def output_indices(model: Model, outputs: Sequence[str] | None) -> list[int]:
    """Indices of ``outputs`` in ``model.outputs`` (all when None)."""
    if outputs is None:
        return list(range(len(model.outputs)))
    if not outputs:
        raise InputError("no outputs selected", key="outputs")
    return [model.output_index(n) for n in outputs]


def to_display(model: Model, Y: np.ndarray, out_idx: Sequence[int]) -> np.ndarray:
    """Columns ``out_idx`` of ``Y`` (base units) in each output's display unit."""
    return np.column_stack([model.outputs[j].to_display(Y[:, j]) for j in out_idx])


def ratio_unit(out_unit: str, in_unit: str) -> str:
    """The printed unit of a derivative, e.g. ``arcsec/µm`` (``1`` for dimensionless)."""
    def lab(u: str) -> str:
        return "1" if units.canonical(u) == "1" else units.label(u)

    return f"{lab(out_unit)}/{lab(in_unit)}"


def derivative_to_display(s_base, out_unit: str, in_unit: str):
    """A derivative in base units (output base per input base) -> ``out_unit`` per ``in_unit``."""
    return np.asarray(s_base) * units.factor(in_unit) / units.factor(out_unit)


def int_seed(seed: int | None, stream: str) -> int:
    """A positive int seed for SALib functions that only take ints, drawn from the study seed."""
    return int(rng(seed, STREAMS[stream]).integers(1, 2**31 - 1))


def generator(seed: int | None, stream: str) -> np.random.Generator:
    """The Generator of one method's sub-stream of the study seed."""
    return rng(seed, STREAMS[stream])


def correlation_note(spec: ToleranceSpec, method: str) -> str:
    """A note when ``method`` (which assumes independent inputs) meets a correlated spec."""
    if spec.correlation is None:
        return ""
    return (f"The spec correlates some factors; {method} assumes independent inputs, so it was computed "
            "with each factor's own distribution but without the correlation. The delta index "
            "(moment-independent, computed on correlated samples) is the valid measure here.")


def tolerance_limits(factor) -> tuple[float, float]:
    """The tolerance band ``(low, high)`` of a factor, in the factor's own unit.

    Bounded kinds (uniform, triangular, truncnorm): the support.  One-sided
    magnitudes (rayleigh, lognormal, weibull): from the lower end of the
    support to the coverage quantile (the factor's ``tolerance``).  Normal:
    the quantiles at ±``sigma_level``·σ, i.e. mean ± T/2.
    """
    from ..distributions import coverage

    d = factor.dist
    lo, hi = (float(v) for v in d.frozen.support())
    c = coverage(d.sigma_level)
    if d.one_sided:
        return lo, float(d.ppf(c))
    if np.isfinite(lo) and np.isfinite(hi):
        return lo, hi
    q = 0.5 * (1.0 - c)
    return float(d.ppf(q)), float(d.ppf(1.0 - q))
