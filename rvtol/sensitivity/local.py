"""Five-point local sensitivity of any Model (doc 000, section 2).

For each factor x_i, the other factors are held at their nominal values and
x_i takes five equally spaced values spanning ±p % of its nominal (p = 10 by
default; where the nominal is zero, ±``abs_step`` or, by default, ±p % of the
factor's tolerance half-band T/2).  With spacing h the derivative is

* at the centre (fourth-order central stencil)::

      S = (f1 − 8 f2 + 8 f4 − f5) / (12 h)

* at the ends of the interval (fourth-order one-sided stencils)::

      S_low  = (−25 f1 + 48 f2 − 36 f3 + 16 f4 − 3 f5) / (12 h)
      S_high = ( 3 f1 − 16 f2 + 36 f3 − 48 f4 + 25 f5) / (12 h)

All three are exact for polynomials up to degree 4 and have an O(h⁴) error
on smooth functions (tests check both).  The spread between S_low, S and
S_high shows how non-linear the output is across the interval.

:func:`sensitivity_curve` repeats the central derivative across a range of
magnitudes e (the document's S-versus-e curves for e = 0.5…15 µm): the
factor's nominal is set to e and the five points span ±p % of e.

Every model evaluation goes through an evaluator (see
:mod:`rvtol.sensitivity.common`), so it runs on the study's executor.
Derivatives are reported in display units, e.g. ``arcsec/um``, with the sign.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from .. import units
from ..errors import InputError
from ..model import Model
from ..spec import ToleranceSpec
from ..mc import Evaluator
from ..records import frame_records
from .common import (FrameResult, derivative_to_display, factor_indices,
                     output_indices, ratio_unit)

#: weights (÷ 12h) of the five-point first derivative at each of the five nodes
WEIGHTS = np.array([
    [-25.0, 48.0, -36.0, 16.0, -3.0],   # at node 1 (forward, interval low end)
    [-3.0, -10.0, 18.0, -6.0, 1.0],     # at node 2
    [1.0, -8.0, 0.0, 8.0, -1.0],        # at node 3 (central)
    [-1.0, 6.0, -18.0, 10.0, 3.0],      # at node 4
    [3.0, -16.0, 36.0, -48.0, 25.0],    # at node 5 (backward, interval high end)
])
OFFSETS = np.arange(-2, 3)  # node positions in units of h around the centre


def _stencil(f, h, node: int):
    f = np.asarray(f, dtype=float)
    if f.shape[-1] != 5:
        raise ValueError(f"expected five function values on the last axis, got shape {f.shape}")
    return (f @ WEIGHTS[node]) / (12.0 * np.asarray(h, dtype=float))


def stencil_central(f, h):
    """Derivative at the middle of five equally spaced values ``f[..., 0:5]`` with spacing ``h``."""
    return _stencil(f, h, 2)


def stencil_forward(f, h):
    """Derivative at the first of five equally spaced values (one-sided, fourth order)."""
    return _stencil(f, h, 0)


def stencil_backward(f, h):
    """Derivative at the last of five equally spaced values (one-sided, fourth order)."""
    return _stencil(f, h, 4)


def stencil_all(f, h):
    """Derivatives at all five nodes, shape ``f.shape`` (fourth order everywhere)."""
    f = np.asarray(f, dtype=float)
    return np.stack([_stencil(f, h, j) for j in range(5)], axis=-1)


# --------------------------------------------------------------------------- evaluation core
def _evaluate_stencils(evaluate: Evaluator, model: Model, centres: np.ndarray, cols: Sequence[int], hs: Sequence[float],
                       desc: str) -> tuple[np.ndarray, np.ndarray]:
    """Evaluate five points per case (centre row, perturbed column, spacing h), each distinct row once.

    Returns ``(F[case, output, 5], ok[case])`` in base units.
    """
    rows = []
    for x0, j, h in zip(centres, cols, hs):
        block = np.repeat(x0[None, :], 5, axis=0)
        block[:, j] = x0[j] + OFFSETS * h
        rows.append(block)
    X = np.concatenate(rows)
    uniq, inverse = np.unique(X, axis=0, return_inverse=True)
    ev = evaluate(model, uniq, desc)
    Y = ev.Y[inverse.ravel()]
    ok = ev.ok[inverse.ravel()]
    n = len(cols)
    F = Y.reshape(n, 5, -1).transpose(0, 2, 1)
    return F, ok.reshape(n, 5).all(axis=1)


def _sign(s: float, scale: float) -> str:
    if not np.isfinite(s):
        return "n/a"
    if abs(s) <= 1e-12 * scale:
        return "0"
    return "+" if s > 0 else "−"


# --------------------------------------------------------------------------- five-point at nominal
@dataclass
class LocalSensitivityResult(FrameResult):
    """Five-point derivatives of outputs w.r.t. factors at the nominal point.

    ``frame`` has one row per (output, factor): ``S`` (central derivative),
    ``S_low_end``/``S_high_end`` (one-sided at the interval ends), all in
    ``S_unit`` (output display unit per factor unit); ``sign``; ``nominal``,
    ``half_range`` (the ± perturbation) and ``h`` in the factor's unit;
    ``S_base`` (base units, for linearisation); ``sigma`` (factor std, its
    unit), ``S_sigma`` (S·σ, output unit) and the linearised changes
    ``dy_low``/``dy_high`` when the factor moves to its tolerance limits.
    ``points`` holds the five (x, y) values behind each derivative.
    """

    frame: pd.DataFrame
    points: pd.DataFrame
    percent: float
    notes: list[str] = field(default_factory=list)

    def gradient(self, output: str, names: Sequence[str]) -> np.ndarray:
        """∂output/∂factor in base units, in the order of ``names`` (NaN where not computed)."""
        d = self.for_output(output).set_index("factor")["S_base"]
        return np.array([float(d.get(n, np.nan)) for n in names])

    def table(self, output: str) -> pd.DataFrame:
        """A report table for one output, with units in the column names."""
        d = self.for_output(output)
        out_u = d["output_unit"].iloc[0]
        return pd.DataFrame({
            "factor": d["factor"],
            "nominal": [f"{v:.4g} {units.label(u)}" for v, u in zip(d["nominal"], d["factor_unit"])],
            "± range": [f"{v:.3g} {units.label(u)}" for v, u in zip(d["half_range"], d["factor_unit"])],
            "S (centre)": d["S"],
            "S (low end)": d["S_low_end"],
            "S (high end)": d["S_high_end"],
            "unit of S": d["S_unit"],
            "sign": d["sign"],
            f"S·σ [{units.label(out_u)}]": d["S_sigma"],
        })

    def summary(self) -> dict:
        """What summary.json records: the span, the notes and every derivative (without the base-unit S)."""
        return {"percent": self.percent, "notes": self.notes,
                "derivatives": frame_records(self.frame.drop(columns=["S_base"]))}

    def plot(self, output: str | None = None, ax=None):
        from ..plotting.sensitivity import tornado

        return tornado(self, output or self.outputs[0], ax=ax)


def _half_range(spec: ToleranceSpec, i: int, x0: float, percent: float,
                abs_step: float | Mapping[str, float] | None) -> float:
    """The ± perturbation of factor ``i`` around ``x0`` (base units)."""
    f = spec.factors[i]
    given = abs_step.get(f.name) if isinstance(abs_step, Mapping) else abs_step
    if given is not None:
        if not given > 0:
            raise InputError(f"abs_step for {f.name!r} must be > 0, got {given}", key="abs_step")
        return float(units.to_base(given, f.unit))
    if x0 != 0.0:
        return abs(x0) * percent / 100.0
    lo, hi = f.band
    return float(units.to_base(0.5 * (hi - lo), f.unit)) * percent / 100.0


def five_point(model: Model, spec: ToleranceSpec, factors: Sequence[str] | None = None,
               outputs: Sequence[str] | None = None, percent: float = 10.0,
               abs_step: float | Mapping[str, float] | None = None, evaluate: Evaluator | None = None,
               x0: np.ndarray | None = None) -> LocalSensitivityResult:
    """Five-point derivatives of ``outputs`` w.r.t. ``factors`` at the nominal point.

    ``percent``: the five points span ±percent % of each nominal.  Factors
    with a zero nominal use ``abs_step`` (the ± perturbation in the factor's
    own unit; a number or ``{name: value}``; a given value overrides the
    percentage for that factor) or, if not given, ±percent % of the factor's
    tolerance half-band.  ``x0`` (base units) replaces the spec's nominal
    point.  ``evaluate`` (an :class:`rvtol.mc.Evaluator`) defaults to a serial one.
    """
    if not percent > 0:
        raise InputError(f"percent must be > 0, got {percent}", key="percent")
    model.check_spec(spec)
    evaluate = evaluate or Evaluator()
    idx = factor_indices(spec, factors)
    oidx = output_indices(model, outputs)
    centre = spec.nominal_base() if x0 is None else np.asarray(x0, dtype=float).copy()
    half = np.array([_half_range(spec, i, centre[i], percent, abs_step) for i in idx])
    hs = half / 2.0
    F, ok = _evaluate_stencils(evaluate, model, np.repeat(centre[None, :], len(idx), axis=0), idx, hs,
                               "five-point sensitivity")
    rows, pts, notes = [], [], []
    for c, i in enumerate(idx):
        f = spec.factors[i]
        lo, hi = (units.to_base(v, f.unit) for v in f.band)
        sigma = f.dist.std
        for j in oidx:
            q = model.outputs[j]
            fv = F[c, j] if ok[c] else np.full(5, np.nan)
            s_all = stencil_all(fv, hs[c])
            s_base = float(s_all[2])
            to_d = lambda s: float(derivative_to_display(s, q.shown_unit, f.unit))  # noqa: E731
            y0 = float(q.to_display(fv[2]))
            scale = max(np.nanmax(np.abs(q.to_display(fv))) if ok[c] else 0.0, 1e-300)
            s_disp = to_d(s_base)
            rows.append({
                "output": q.name, "output_unit": q.shown_unit, "factor": f.name, "factor_unit": f.unit,
                "nominal": float(units.from_base(centre[i], f.unit)),
                "half_range": float(units.from_base(half[c], f.unit)), "h": float(units.from_base(hs[c], f.unit)),
                "y0": y0, "S": s_disp, "S_low_end": to_d(s_all[0]), "S_high_end": to_d(s_all[4]),
                "S_unit": ratio_unit(q.shown_unit, f.unit),
                "sign": _sign(s_disp * float(units.from_base(half[c], f.unit)), scale),
                "S_base": s_base, "sigma": sigma, "S_sigma": s_disp * sigma,
                "dy_low": float(q.to_display(s_base * (lo - centre[i]))),
                "dy_high": float(q.to_display(s_base * (hi - centre[i]))),
            })
            for k in range(5):
                pts.append({"output": q.name, "factor": f.name,
                            "x": float(units.from_base(centre[i] + OFFSETS[k] * hs[c], f.unit)),
                            "y": float(q.to_display(fv[k]))})
        if not ok[c]:
            notes.append(f"factor {f.name!r}: the model failed on at least one of the five points; "
                         "its derivatives are not available (n/a).")
    return LocalSensitivityResult(pd.DataFrame(rows), pd.DataFrame(pts), float(percent), notes)


# --------------------------------------------------------------------------- S versus magnitude e
@dataclass
class SensitivityCurveResult(FrameResult):
    """Central derivative ``S`` (and end derivatives) against the magnitude e of each factor.

    ``frame``: one row per (output, factor, magnitude) with ``magnitude`` (in
    ``magnitude_unit``), ``S``, ``S_low_end``, ``S_high_end`` in ``S_unit``
    and the output value ``y`` at e.
    """

    frame: pd.DataFrame
    percent: float
    together: bool
    notes: list[str] = field(default_factory=list)

    def summary(self) -> dict:
        """What summary.json records: the span, one-at-a-time or together, and every point of the curves."""
        return {"percent": self.percent, "together": self.together, "curve": frame_records(self.frame)}

    def plot(self, output: str | None = None, ax=None):
        from ..plotting.sensitivity import curves

        return curves(self, output or self.outputs[0], ax=ax)


def sensitivity_curve(model: Model, spec: ToleranceSpec, factors: Sequence[str], magnitudes: Sequence[float],
                      unit: str | None = None, outputs: Sequence[str] | None = None, percent: float = 10.0,
                      together: bool = False, evaluate: Evaluator | None = None) -> SensitivityCurveResult:
    """The document's sensitivity-versus-magnitude curve.

    For each magnitude e (in ``unit``, default each factor's own unit) the
    factor's nominal is set to e (with ``together=True`` every listed factor
    is set to e at once, as when all errors have magnitude e; otherwise the
    others stay at their nominal) and the five points span ±percent % of e.
    """
    if not percent > 0:
        raise InputError(f"percent must be > 0, got {percent}", key="percent")
    mags = [float(m) for m in magnitudes]
    if not mags or any(m == 0.0 or not np.isfinite(m) for m in mags):
        raise InputError("magnitudes must be finite and non-zero (the points span ±percent % of e)",
                         key="magnitudes")
    model.check_spec(spec)
    evaluate = evaluate or Evaluator()
    idx = factor_indices(spec, factors)
    oidx = output_indices(model, outputs)
    nominal = spec.nominal_base()

    def base(e: float, i: int) -> float:
        f = spec.factors[i]
        if unit is not None and units.dimension(unit) != units.dimension(f.unit):
            raise InputError(f"unit {unit!r} does not fit factor {f.name!r} ({f.unit})", key="unit")
        return float(units.to_base(e, unit or f.unit))

    centres, cols, hs, cases = [], [], [], []
    for e in mags:
        for i in idx:
            x0 = nominal.copy()
            for m in (idx if together else [i]):
                x0[m] = base(e, m)
            centres.append(x0)
            cols.append(i)
            hs.append(abs(x0[i]) * percent / 100.0 / 2.0)
            cases.append((e, i))
    F, ok = _evaluate_stencils(evaluate, model, np.array(centres), cols, hs, "sensitivity curve")
    rows, failed = [], set()
    for c, (e, i) in enumerate(cases):
        f = spec.factors[i]
        if not ok[c]:
            failed.add(f.name)
        for j in oidx:
            q = model.outputs[j]
            fv = F[c, j] if ok[c] else np.full(5, np.nan)
            s_all = stencil_all(fv, hs[c])
            to_d = lambda s: float(derivative_to_display(s, q.shown_unit, f.unit))  # noqa: E731
            rows.append({"output": q.name, "output_unit": q.shown_unit, "factor": f.name,
                         "magnitude": e, "magnitude_unit": unit or f.unit,
                         "S": to_d(s_all[2]), "S_low_end": to_d(s_all[0]), "S_high_end": to_d(s_all[4]),
                         "S_unit": ratio_unit(q.shown_unit, f.unit), "y": float(q.to_display(fv[2]))})
    notes = [f"factor {n!r}: the model failed at some magnitudes (n/a there)." for n in sorted(failed)]
    return SensitivityCurveResult(pd.DataFrame(rows), float(percent), together, notes)
