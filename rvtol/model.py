"""The Model protocol: every physics in rvtol is a Model.

A model has ``inputs`` (factor names, with the base unit it expects for
each), ``outputs`` (:class:`Quantity`: name, base unit of the returned
values, unit to report in) and a vectorised ``evaluate(X[n, k]) -> Y[n, m]``
in base units.  Monte Carlo, five-point and global sensitivity and tolerance
allocation work on any Model without special cases.

A model may also offer ``gradient(X) -> (n, outputs, inputs)``, its exact derivatives in base units
(the formula model does); the linearised analyses then use it instead of five-point
differences (:func:`rvtol.sensitivity.common.model_gradient`).

Samples a model cannot evaluate (a solver that does not converge, contact
lost everywhere) are reported through :meth:`Model.evaluate_with_status`:
status 0 is success, any other code is a failure whose reason is
``model.status_reasons[code]``; those rows of ``Y`` are NaN and the engine
counts and reports them.  A model must be *row-deterministic*: the result for
one row must not depend on which other rows are evaluated with it, so chunked
and parallel evaluation are bit-identical to a serial run.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Callable, ClassVar, Sequence

import numpy as np

from . import units
from .errors import InputError, ModelError, did_you_mean

STATUS_OK = 0
STATUS_NONFINITE = 1


@dataclass(frozen=True)
class Quantity:
    """A named output: ``unit`` of the values ``evaluate`` returns, ``display_unit`` for reports."""

    name: str
    unit: str = "1"
    display_unit: str | None = None
    description: str = ""

    @property
    def shown_unit(self) -> str:
        return self.display_unit or self.unit

    def to_display(self, values):
        return units.convert(values, self.unit, self.shown_unit) if self.shown_unit != self.unit else values


class Model(ABC):
    """Base class of all models (see module docstring)."""

    #: reasons for non-zero status codes; subclasses extend this
    status_reasons: ClassVar[dict[int, str]] = {STATUS_NONFINITE: "model returned a non-finite value"}

    inputs: tuple[str, ...]
    input_units: tuple[str, ...]  # base unit expected per input ('mm', 'rad', '1', ...)
    outputs: tuple[Quantity, ...]

    @abstractmethod
    def evaluate(self, X: np.ndarray) -> np.ndarray:
        """``X[n, k]`` in base units -> ``Y[n, m]`` in base units."""

    def evaluate_with_status(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(Y, status)``; the default marks rows with a non-finite output as failed."""
        Y = np.asarray(self.evaluate(X), dtype=float)
        bad = ~np.all(np.isfinite(Y), axis=1)
        status = np.where(bad, STATUS_NONFINITE, STATUS_OK).astype(np.int16)
        return Y, status

    def dependencies(self) -> dict[str, frozenset[str]] | None:
        """Output name -> the inputs that move it, where the model knows its structure (each model says
        how it decides; :meth:`rvtol.models.composite.model.CompositeModel.depends_on` uses it);
        ``None``: every output depends on every input."""
        return None

    # -- conveniences ---------------------------------------------------------
    @property
    def output_names(self) -> tuple[str, ...]:
        return tuple(q.name for q in self.outputs)

    def output(self, name: str) -> Quantity:
        for q in self.outputs:
            if q.name == name:
                return q
        raise InputError(f"unknown output name {name!r}{did_you_mean(name, self.output_names)} "
                         f"(model has: {', '.join(self.output_names)})")

    def output_index(self, name: str) -> int:
        return self.output_names.index(self.output(name).name)

    def check_input(self, X) -> np.ndarray:
        X = np.asarray(X, dtype=float)
        if X.ndim != 2 or X.shape[1] != len(self.inputs):
            raise ModelError(f"{type(self).__name__} expects X of shape (n, {len(self.inputs)}), got {X.shape}")
        return X

    def check_spec(self, spec) -> None:
        """Check that ``spec`` supplies exactly this model's inputs with fitting units."""
        if tuple(spec.names) != tuple(self.inputs):
            missing = [n for n in self.inputs if n not in spec.names]
            extra = [n for n in spec.names if n not in self.inputs]
            what = (f"unknown factor name {extra[0]!r}{did_you_mean(extra[0], missing)}" if extra
                    else f"missing factor {missing[0]!r}")
            raise InputError(f"{what} for model {type(self).__name__}", file=spec.file, key="factor")
        for f, bu in zip(spec.factors, self.input_units):
            if units.dimension(f.unit) != units.dimension(bu):
                raise InputError(f"factor {f.name!r} has unit {f.unit!r} ({units.dimension(f.unit)}); "
                                 f"the model expects a {units.dimension(bu)}", file=spec.file, key="factor.unit")


class LinearModel(Model):
    """``Y = c + X·Aᵀ``: a linear stack-up, and the reference for the engine's tests.

    ``A[m, k]`` in (output base unit)/(input base unit).
    """

    def __init__(self, inputs: Sequence[str], input_units: Sequence[str], outputs: Sequence[Quantity],
                 coefficients, constant=None):
        self.inputs = tuple(inputs)
        self.input_units = tuple(input_units)
        self.outputs = tuple(outputs)
        self.A = np.asarray(coefficients, dtype=float).reshape(len(self.outputs), len(self.inputs))
        self.c = np.zeros(len(self.outputs)) if constant is None else np.asarray(constant, float).ravel()

    def evaluate(self, X):
        X = self.check_input(X)
        # row by row (no BLAS): the result of a row never depends on the chunk it is in
        return self.c + np.stack([(X * a).sum(axis=1) for a in self.A], axis=1)

    def dependencies(self) -> dict[str, frozenset[str]]:
        """Each output depends on the inputs with a non-zero coefficient."""
        return {q.name: frozenset(n for n, a in zip(self.inputs, row) if a != 0.0)
                for q, row in zip(self.outputs, self.A)}


class FunctionModel(Model):
    """Wrap a vectorised function ``f(X) -> Y`` (both base units) as a Model."""

    def __init__(self, f: Callable[[np.ndarray], np.ndarray], inputs: Sequence[str],
                 outputs: Sequence[Quantity | str], input_units: Sequence[str] | None = None):
        self.f = f
        self.inputs = tuple(inputs)
        self.input_units = tuple(input_units) if input_units is not None else ("1",) * len(self.inputs)
        self.outputs = tuple(q if isinstance(q, Quantity) else Quantity(q) for q in outputs)

    def evaluate(self, X):
        Y = np.asarray(self.f(self.check_input(X)), dtype=float)
        return Y.reshape(len(Y), -1)


def model_label(model: "Model") -> str:
    """The model as a report names it: its class, or what a wrapper says it is (``label``)."""
    return getattr(model, "label", None) or type(model).__name__


def dependencies(model: "Model") -> dict[str, set[str]] | None:
    """Output -> the model inputs it can depend on, where the model knows (a composed model through its
    declared mapping, a model through :meth:`Model.dependencies`); None: every output on every input."""
    if hasattr(model, "depends_on"):
        return {k: set(v) for k, v in model.depends_on().items()}
    own = model.dependencies()
    return None if own is None else {k: set(v) for k, v in own.items()}
