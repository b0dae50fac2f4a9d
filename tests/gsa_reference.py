"""Analytic sensitivity test functions shared by ``tests/sensitivity/test_gsa_*.py`` (closed-form Sobol indices).

* Ishigami (a = 7, b = 0.1) on U(−π, π)³: S1 = (0.3139, 0.4424, 0), ST = (0.5576, 0.4424, 0.2437),
  S13 = 0.2437 (Ishigami & Homma 1990; Sobol' & Levitan 1999);
* Sobol' G on U(0, 1)⁶ with a = (0, 1, 4.5, 9, 99, 99): V_i = 1/(3(1+a_i)²), S1 = V_i/V,
  ST_i = V_i Π_{j≠i}(1+V_j)/V, V = Π(1+V_i) − 1 (Saltelli & Sobol' 1995);
* a linear model with five factors of different distributions: S1 = ST = (A_i σ_i)²/Σ(A_j σ_j)².

Tolerances.  An estimate passes when it lies within its own interval of the analytic value.  With
m comparisons in one test the interval is taken at 1 − 0.05/m (Bonferroni), so the whole test
has at most a 5 % false-alarm rate for calibrated intervals.  PCE intervals cover the sampling
of the design only; the surrogate's truncation error is bounded by ``bias_bound`` = 1 − Q²
(see rvtol.sensitivity.surrogate.indices), which the PCE comparisons add to the interval.
"""
from __future__ import annotations

import math

import numpy as np

from rvtol.model import FunctionModel, LinearModel, Quantity
from rvtol.spec import spec_from_table

A_ISH, B_ISH = 7.0, 0.1


def ishigami(X):
    return (np.sin(X[:, 0]) + A_ISH * np.sin(X[:, 1]) ** 2 + B_ISH * X[:, 2] ** 4 * np.sin(X[:, 0]))[:, None]


ISH_SPEC = spec_from_table({"factor": [{"name": f"x{i + 1}", "unit": "1", "dist": "uniform",
                                        "lower": -math.pi, "upper": math.pi} for i in range(3)]})
ISH = FunctionModel(ishigami, ISH_SPEC.names, ["y"])


def ishigami_indices():
    """``(S1, ST, S13)`` of the Ishigami function."""
    a, b, pi = A_ISH, B_ISH, math.pi
    V = a**2 / 8 + b * pi**4 / 5 + b**2 * pi**8 / 18 + 0.5
    V1 = 0.5 * (1 + b * pi**4 / 5) ** 2
    V2 = a**2 / 8
    V13 = b**2 * pi**8 * (1 / 18 - 1 / 50)
    return np.array([V1, V2, 0.0]) / V, np.array([V1 + V13, V2, V13]) / V, V13 / V


G_A = np.array([0.0, 1.0, 4.5, 9.0, 99.0, 99.0])


def g_function(X):
    return np.prod((np.abs(4 * X - 2) + G_A) / (1 + G_A), axis=1)[:, None]


G_SPEC = spec_from_table({"factor": [{"name": f"g{i}", "unit": "1", "dist": "uniform", "lower": 0, "upper": 1}
                                     for i in range(len(G_A))]})
G_MODEL = FunctionModel(g_function, G_SPEC.names, ["y"])


def g_indices():
    """``(S1, ST)`` of the Sobol' G function."""
    Vi = 1 / (3 * (1 + G_A) ** 2)
    V = np.prod(1 + Vi) - 1
    ST = Vi * np.array([np.prod(np.delete(1 + Vi, i)) for i in range(len(G_A))]) / V
    return Vi / V, ST


def linear_case():
    """``(model, spec, share)``: five factors (normal, uniform, triangular, normal inactive, Rayleigh)."""
    A = np.array([[1 / 50, -2 / 50, 0.5 / 50, 0.0, 3 / 50]])  # rad/mm
    spec = spec_from_table({"factor": [
        {"name": "p", "unit": "um", "dist": "normal", "mean": 3.0, "tolerance": 6.0},
        {"name": "q", "unit": "um", "dist": "uniform", "lower": -2.0, "upper": 4.0},
        {"name": "r", "unit": "um", "dist": "triangular", "lower": 0.0, "upper": 9.0},
        {"name": "s", "unit": "um", "dist": "normal", "mean": 0.0, "tolerance": 2.0},   # does not act
        {"name": "t", "unit": "um", "dist": "rayleigh", "tolerance": 1.5}]})
    model = LinearModel(spec.names, ["mm"] * 5, [Quantity("phi", "rad", "arcmin")], A)
    v = (A[0] * spec.std_base()) ** 2
    return model, spec, v / v.sum()


def bonferroni(m: int, family: float = 0.05) -> float:
    """Confidence level of each of ``m`` intervals for a family-wise error rate ``family``."""
    return 1.0 - family / m


def evaluate_display(model, samples):
    """Every output of ``model`` on ``samples``, in display units (as MonteCarloResult.Y)."""
    Y = model.evaluate(samples.values)
    return np.column_stack([q.to_display(Y[:, j]) for j, q in enumerate(model.outputs)])
