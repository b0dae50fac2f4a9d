"""Helpers shared by local and global sensitivity: evaluation, name checks, units.

Every function that evaluates a model takes ``evaluate``, an
:class:`rvtol.mc.Evaluator` (``evaluate(model, X, desc) -> Evaluation``, base
units in and out); analyses pass ``ctx.evaluator`` so every model evaluation
runs on the study's executor; the default is a serial ``Evaluator()``.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Sequence

import numpy as np

from .. import units
from ..errors import InputError
from ..model import Model
from ..spec import ToleranceSpec

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd


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


def model_gradient(model: Model, x0: np.ndarray) -> np.ndarray | None:
    """The model's own exact ∂Y/∂X at ``x0`` (outputs × inputs, base units) when it has one (``gradient(X)``:
    the formula model), else None — the linearised analyses then take five-point derivatives."""
    g = getattr(model, "gradient", None)
    if g is None:
        return None
    return np.asarray(g(np.atleast_2d(np.asarray(x0, dtype=float))), dtype=float)[0]


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


def correlation_note(spec: ToleranceSpec, method: str) -> str:
    """A note when ``method`` (which assumes independent inputs) meets a correlated spec."""
    if spec.correlation is None:
        return ""
    return (f"The spec correlates some factors; {method} assumes independent inputs, so it was computed "
            "with each factor's own distribution but without the correlation. The delta index "
            "(moment-independent, computed on correlated samples) is the valid measure here.")
