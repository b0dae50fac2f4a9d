"""Reference models with known answers, for tests and benchmarks (importable by worker processes)."""
from __future__ import annotations

import numpy as np

from .model import STATUS_OK, Model, Quantity

STATUS_REFUSED = 7


class FlakyModel(Model):
    """``y = x0 + 2·x1``, but rows with ``x0 > threshold`` fail with status 7 (like a solver that diverges)."""

    status_reasons = {**Model.status_reasons, STATUS_REFUSED: "x0 above threshold: solver refused"}

    def __init__(self, threshold: float):
        self.threshold = threshold
        self.inputs = ("x0", "x1")
        self.input_units = ("mm", "mm")
        self.outputs = (Quantity("y", "mm", "um"),)

    def evaluate(self, X):
        return self.evaluate_with_status(X)[0]

    def evaluate_with_status(self, X):
        X = self.check_input(X)
        y = (X[:, 0] + 2.0 * X[:, 1])[:, None]
        status = np.where(X[:, 0] > self.threshold, STATUS_REFUSED, STATUS_OK).astype(np.int16)
        y[status != STATUS_OK] = np.nan
        return y, status


class CpuBoundModel(Model):
    """A deliberately expensive smooth model (``work`` inner iterations per sample), for speed-up benchmarks.

    ``y = Σ_j sin(x·c_j)`` over ``work`` terms, computed row by row.
    """

    def __init__(self, k: int = 3, work: int = 2000):
        self.work = work
        self.inputs = tuple(f"x{i}" for i in range(k))
        self.input_units = ("1",) * k
        self.outputs = (Quantity("y"),)
        self._c = np.linspace(0.1, 1.0, work)

    def evaluate(self, X):
        X = self.check_input(X)
        s = X.sum(axis=1)
        return np.array([np.sin(v * self._c).sum() for v in s])[:, None]


class TrivialModel(Model):
    """``y = x0`` — measures the engine's own overhead."""

    def __init__(self, k: int = 3):
        self.inputs = tuple(f"x{i}" for i in range(k))
        self.input_units = ("1",) * k
        self.outputs = (Quantity("y"),)

    def evaluate(self, X):
        return self.check_input(X)[:, :1].copy()


#: how many :class:`UnpickleCountingModel` objects this process has unpickled
UNPICKLED = {"count": 0}


class UnpickleCountingModel(Model):
    """``y = `` how many of these models the evaluating process had unpickled when it evaluated the row:
    tells whether a worker unpacks a model once or with every chunk."""

    def __init__(self, tag: int = 0):
        self.tag = tag                   # models that differ in content are different models to a worker
        self.inputs = ("x",)
        self.input_units = ("1",)
        self.outputs = (Quantity("unpickled"),)

    def __setstate__(self, state):
        self.__dict__.update(state)
        UNPICKLED["count"] += 1

    def evaluate(self, X):
        X = self.check_input(X)
        return np.full((len(X), 1), float(UNPICKLED["count"]))
