"""Per-unit prediction: each kitted reducer from its measured parts, with an interval and a verdict.

For reducer ``i`` with measured factor values ``m`` (standard uncertainty ``u``) the prediction
draws ``n`` samples of its factors:

* a **measured** factor is its measured value plus the measurement error, ``x = m + u·z`` with
  ``z`` a standard normal score (GUM: the measurand is known as ``m`` with standard uncertainty
  ``u``; ``u = 0`` fixes it exactly);
* an **unmeasured** factor is drawn from the spec — conditionally on the measured ones where the
  spec correlates them (the Gaussian copula's conditional normal: ``z_U = A z_M + L ε`` with
  ``A = C_UM C_MM⁻¹`` and ``L Lᵀ = C_UU − A C_MU``), so a measured disc tells what its
  stack-ground twin is likely to be.

The uniform design behind every unit is the same (one design from the sub-stream ``per_unit`` of
the study seed: common random numbers), so two units differ only by what was measured on them.
All units are evaluated in one call of the study's :class:`~rvtol.mc.Evaluator`.

Per unit and output: median, mean, standard deviation and the central prediction interval
(``interval``, 95 % by default: the 2.5 % and 97.5 % points of the ``n`` samples).  Per unit and
requirement: the probability ``P`` that the unit conforms (the fraction of its samples within the
limits; samples the model cannot evaluate count as non-conforming) with its lower and upper
confidence bounds (one-sided at the requirement's bound level, :func:`rvtol.verdict.bound_level`),
and the verdict of :func:`rvtol.verdict.judge_unit`: conforms / does not conform / undecided.

Per unit and requirement also the **ISO 14253-1 decision rule** (ISO 14253-1:2017, *Decision rules for
verifying conformity or nonconformity with specifications*, §5, the default rule of "proving
conformance/non-conformance" with guard bands of the expanded uncertainty): the unit's predicted value y (the
mean of its samples, GUM's best estimate) with standard uncertainty u (their standard deviation, ddof = 1)
and expanded uncertainty U = k·u (``coverage_factor`` k, 2 by default) is

* **conformance proven** when y lies in the tolerance zone reduced by U on each side:
  L + U ≤ y ≤ H − U (a one-sided requirement: only its limit; the zone is closed);
* **non-conformance proven** when y lies outside the zone enlarged by U: y < L − U or y > H + U;
* **undecided** otherwise (and when fewer than two samples could be evaluated: no u to read).

:func:`guard_banded` is the rule.  How it relates to the probability verdict: for a normal prediction,
conformance proven means every limit is at least k·u from y, so P(conforms) ≥ 2Φ(k) − 1 (0.9545 at k = 2;
Φ(k) = 0.9772 for one limit), and non-conformance proven means P ≤ Φ(−k) (0.0228).  The two agree whenever the
probability a unit must show is at most 2Φ(k) − 1; with a stricter one (0.9973) a unit may be "conformance
proven" by the guard band yet "undecided" on P — the guard band at k = 2 asks less than 3σ.  The P verdict
also sees a skewed or bounded prediction as it is; the guard band reads only its mean and spread.

For a linear model ``y = c + Σ a_i x_i`` the prediction is normal-equivalent with variance
``Σ_measured (a_i u_i)² + Σ_unmeasured a_j² σ_j²`` (independent factors) — the closed form the
tests hold this module to.  :func:`samples_to_demonstrate` gives the ``n`` at which a unit can be
shown to conform at all.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import pandas as pd
from scipy import stats

from .. import stats as st
from .. import units
from ..mc import result_of
from ..model import STATUS_OK, Model, Quantity
from ..sampling import SampleSet, substream_seed, uniform_design
from ..spec import YIELD_INTERVALS, Requirement, ToleranceSpec
from ..verdict import CONFORMS, DOES_NOT_CONFORM, UNDECIDED, judge_unit, samples_for_unit, unit_probability_required
from .measured_parts import MeasuredUnits

#: the order of the unit verdicts, worst last (a unit's overall verdict is its worst requirement's)
STATES = (CONFORMS, UNDECIDED, DOES_NOT_CONFORM)
_U_EPS = 2.0 ** -53
#: the three outcomes of the ISO 14253-1 decision rule (module docstring)
CONFORMANCE_PROVEN, NONCONFORMANCE_PROVEN, NOT_PROVEN = "conformance proven", "non-conformance proven", "undecided"
COVERAGE_FACTOR = 2.0


def guard_banded(y: float, u: float, lower: float | None, upper: float | None, k: float = COVERAGE_FACTOR) -> str:
    """The ISO 14253-1 decision for a value ``y`` with standard uncertainty ``u`` against the limits
    (``None``: no limit on that side): conformance proven when ``lower + k·u ≤ y ≤ upper − k·u``,
    non-conformance proven when ``y < lower − k·u`` or ``y > upper + k·u``, else undecided (module docstring)."""
    if not (np.isfinite(y) and np.isfinite(u)):
        return NOT_PROVEN
    U = k * u
    if (lower is None or y >= lower + U) and (upper is None or y <= upper - U):
        return CONFORMANCE_PROVEN
    if (lower is not None and y < lower - U) or (upper is not None and y > upper + U):
        return NONCONFORMANCE_PROVEN
    return NOT_PROVEN


def samples_to_demonstrate(requirements, probability: float | None = None) -> int:
    """The smallest ``n`` at which a unit with every sample conforming is judged to conform on every
    requirement (:func:`rvtol.verdict.samples_for_unit`: the lower bound of ``n/n`` reaching each
    requirement's own probability, or ``probability``); e.g. 1109 for 0.9973 and 59 for 0.95 at a 95 %
    one-sided Clopper–Pearson bound (``(1 − c)^(1/n) ≥ p``).  1 without requirements."""
    need = 1
    for r in requirements:
        m = samples_for_unit(r, probability)
        if m is None:
            p = probability if probability is not None else unit_probability_required(r)
            raise ValueError(f"requirement {r.label!r}: no sample size demonstrates P = {p:g} of one unit")
        need = max(need, m)
    return need


def unit_design(spec: ToleranceSpec, measured: MeasuredUnits, n: int, method: str = "lhs",
                seed: int | None = None) -> np.ndarray:
    """``[units·n, k]`` factor values (base units); rows ``i·n … (i+1)·n − 1`` are unit ``i`` (module doc)."""
    u = unit_uniforms(spec, measured, n, method, seed)
    cache: dict[bytes, tuple] = {}
    return np.concatenate([unit_values(spec, measured, i, u, cache) for i in range(len(measured))]) \
        if len(measured) else np.empty((0, len(spec)))


def unit_uniforms(spec: ToleranceSpec, measured: MeasuredUnits, n: int, method: str = "lhs",
                  seed: int | None = None) -> np.ndarray:
    """The ``[n, k]`` uniform design every unit shares (sub-stream ``per_unit`` of ``seed``: common random
    numbers); :func:`unit_values` turns it into one unit's factor values."""
    if tuple(measured.names) != tuple(spec.names):
        raise ValueError("the measured units were read against another spec")
    return uniform_design(n, len(spec), method, substream_seed(seed, "per_unit"))


def unit_values(spec: ToleranceSpec, measured: MeasuredUnits, i: int, u: np.ndarray,
                cache: dict | None = None) -> np.ndarray:
    """Unit ``i``'s ``[n, k]`` factor values (base units) at the uniform coordinates ``u[n, k]``: a measured
    factor ``m + u·Φ⁻¹(u_j)``, an unmeasured one from the spec, conditionally on the measured ones where the
    spec correlates them (module doc).  Every factor is a function of its own independent coordinate, so a
    coordinate's posterior (:mod:`rvtol.production.per_serial`) maps to values the same way."""
    n, k = u.shape
    z = stats.norm.ppf(u)
    C = spec.correlation
    m = measured.measured[i]
    x = np.empty((n, k))
    x[:, m] = measured.value[i, m] + measured.uncertainty[i, m] * z[:, m]
    un = np.flatnonzero(~m)
    if C is None:
        for j in un:
            x[:, j] = spec.factors[j].ppf_base(u[:, j])
        return x
    cache = {} if cache is None else cache
    key = m.tobytes()
    if key not in cache:
        cache[key] = _conditional(C, m)
    A, L = cache[key]
    zm = np.column_stack([_score(spec.factors[j], x[:, j]) for j in np.flatnonzero(m)]) if m.any() \
        else np.zeros((n, 0))
    zu = zm @ A.T + z[:, un] @ L.T
    uu = np.clip(stats.norm.cdf(zu), _U_EPS, 1.0 - _U_EPS)
    for c, j in enumerate(un):
        x[:, j] = spec.factors[j].ppf_base(uu[:, c])
    return x


def _score(f, x_base: np.ndarray) -> np.ndarray:
    """The normal score of a value (base units) under the factor's distribution."""
    p = f.dist.cdf(units.from_base(x_base, f.unit))
    return stats.norm.ppf(np.clip(p, _U_EPS, 1.0 - _U_EPS))


def _conditional(C: np.ndarray, measured: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(A, L)`` of the conditional normal scores of the unmeasured given the measured factors."""
    M, U = np.flatnonzero(measured), np.flatnonzero(~measured)
    Cuu = C[np.ix_(U, U)]
    if M.size == 0:
        return np.zeros((U.size, 0)), np.linalg.cholesky(Cuu)
    Cum, Cmm = C[np.ix_(U, M)], C[np.ix_(M, M)]
    A = np.linalg.solve(Cmm, Cum.T).T
    S = Cuu - A @ Cum.T
    return A, np.linalg.cholesky(0.5 * (S + S.T))


@dataclass
class UnitPredictions:
    """Every unit's samples of every output (display units) and what follows from them."""

    units: tuple[str, ...]
    outputs: tuple[Quantity, ...]
    Y: np.ndarray                      # [units, n, outputs], display units, NaN where failed
    status: np.ndarray                 # [units, n]
    requirements: tuple[Requirement, ...]   # limits in display units
    interval: float
    measured: np.ndarray               # [units] number of measured factors
    status_reasons: dict
    probability: float | None = None   # the probability of conformance a unit must show (None: each requirement's)
    coverage_factor: float = COVERAGE_FACTOR   # k of the ISO 14253-1 guard band U = k·u
    #: unit -> why its verdicts are withheld (every requirement's verdict and decision undecided: the per-serial
    #: update's prior conflict or unconverged sampler, :mod:`rvtol.production.per_serial`)
    withheld: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        return self.Y.shape[1]

    def to_frame(self) -> pd.DataFrame:
        """One row per reducer: :meth:`unit_frame` (verdict, per requirement P and verdict, per output median and
        interval)."""
        return self.unit_frame()

    def output_frame(self) -> pd.DataFrame:
        """One row per unit and output: median, mean, std, the prediction interval, failed samples."""
        return self._outputs.copy()

    @cached_property
    def _outputs(self) -> pd.DataFrame:
        a = (1.0 - self.interval) / 2.0
        rows = []
        for i, unit in enumerate(self.units):
            ok = self.status[i] == STATUS_OK
            for j, q in enumerate(self.outputs):
                y = self.Y[i, ok, j]
                row = {"reducer": unit, "output": q.name, "unit": q.shown_unit, "failed": int((~ok).sum())}
                if y.size:
                    lo, med, hi = np.quantile(y, [a, 0.5, 1.0 - a])
                    row.update(median=med, mean=float(y.mean()), std=float(y.std(ddof=1)) if y.size > 1 else 0.0,
                               lo=lo, hi=hi)
                rows.append(row)
        return pd.DataFrame(rows, columns=["reducer", "output", "unit", "median", "mean", "std", "lo", "hi",
                                           "failed"])

    def requirement_frame(self) -> pd.DataFrame:
        """One row per unit and requirement: P(conforms) with its interval, the required P, the verdict."""
        return self._requirements.copy()

    @cached_property
    def _requirements(self) -> pd.DataFrame:
        rows = []
        names = [q.name for q in self.outputs]
        for i, unit in enumerate(self.units):
            ok = self.status[i] == STATUS_OK
            for r in self.requirements:
                y = self.Y[i, :, names.index(r.output)]
                yr = st.yield_of(y, ok, r.lower, r.upper, r.confidence, YIELD_INTERVALS[r.interval])
                j = judge_unit(r, conforming=yr.conforming, n=yr.n, n_failed=int((~ok).sum()),
                               required=self.probability)
                ok_y = y[ok]
                est = float(ok_y.mean()) if ok_y.size else np.nan
                u = float(ok_y.std(ddof=1)) if ok_y.size > 1 else np.nan     # one sample has no spread to read
                why = self.withheld.get(unit)
                rows.append({"reducer": unit, "requirement": r.label, "output": r.output, "P": j.p,
                             "P_lo": j.p_lo, "P_hi": j.p_hi, "required": j.required,
                             "verdict": UNDECIDED if why else j.state,
                             "reasons": "; ".join([*j.reasons, *([f"withheld: {why}"] if why else [])]),
                             "y": est, "u": u, "U": self.coverage_factor * u,
                             "ISO 14253-1": NOT_PROVEN if why else guard_banded(est, u, r.lower, r.upper,
                                                                                self.coverage_factor)})
        return pd.DataFrame(rows, columns=["reducer", "requirement", "output", "P", "P_lo", "P_hi", "required",
                                           "verdict", "reasons", "y", "u", "U", "ISO 14253-1"])

    def verdicts(self) -> dict[str, str]:
        """Reducer -> its overall verdict: the worst of its requirements' (conforms without requirements; undecided
        where :attr:`withheld`)."""
        req = self._requirements
        out = {}
        for u in self.units:
            states = req.loc[req["reducer"] == u, "verdict"].tolist()
            out[u] = UNDECIDED if u in self.withheld else max(states, key=STATES.index) if states else CONFORMS
        return out

    def unit_frame(self) -> pd.DataFrame:
        """One row per reducer (the CI-friendly table): verdict, per requirement P and verdict, per
        output median and interval — flat columns, display units in the names."""
        outs, req, verdicts = self._outputs, self._requirements, self.verdicts()
        rows = []
        for i, u in enumerate(self.units):
            row = {"reducer": u, "verdict": verdicts[u], "measured_factors": int(self.measured[i]), "n": self.n}
            for _, r in req[req["reducer"] == u].iterrows():
                row[f"{r['requirement']}: P"] = r["P"]
                row[f"{r['requirement']}: P_lo"] = r["P_lo"]
                row[f"{r['requirement']}: verdict"] = r["verdict"]
                row[f"{r['requirement']}: ISO 14253-1 (k={self.coverage_factor:g})"] = r["ISO 14253-1"]
            for _, o in outs[outs["reducer"] == u].iterrows():
                pct = f"{100 * self.interval:g}%"
                row[f"{o['output']} median [{o['unit']}]"] = o["median"]
                row[f"{o['output']} {pct} lo [{o['unit']}]"] = o["lo"]
                row[f"{o['output']} {pct} hi [{o['unit']}]"] = o["hi"]
            rows.append(row)
        return pd.DataFrame(rows)

    def counts(self) -> dict[str, int]:
        v = list(self.verdicts().values())
        return {s: v.count(s) for s in STATES}

    def verdict_table(self) -> pd.DataFrame:
        """One row per reducer: its verdict and, per requirement, ``P [lo, hi]``."""
        req, verdicts = self._requirements, self.verdicts()
        table = pd.DataFrame({"reducer": list(verdicts), "verdict": list(verdicts.values())})
        for r in self.requirements:
            sub = req[req["requirement"] == r.label].set_index("reducer")
            table[f"{r.label}: P [CI]"] = [f"{sub.loc[u, 'P']:.4f} [{sub.loc[u, 'P_lo']:.4f}, {sub.loc[u, 'P_hi']:.4f}]"
                                           for u in table["reducer"]]
            table[f"{r.label}: ISO 14253-1 (y ± U, k={self.coverage_factor:g})"] = [
                f"{sub.loc[u, 'ISO 14253-1']} ({sub.loc[u, 'y']:.4g} ± {sub.loc[u, 'U']:.3g})" for u in table["reducer"]]
        return table

    def plot(self, output: str, ax=None):
        """Every unit's median and prediction interval of ``output``, coloured by its verdict on the output's
        requirement(s)."""
        from ..plotting.production import plot_unit_intervals

        req, outs = self._requirements, self._outputs
        rs = [r for r in self.requirements if r.output == output]
        sub = outs[outs["output"] == output].set_index("reducer").reindex(self.units)
        vs = []
        for u in self.units:
            states = req.loc[(req["reducer"] == u) & (req["output"] == output), "verdict"].tolist()
            vs.append(max(states, key=STATES.index) if states else "")
        return plot_unit_intervals(list(self.units), sub["median"].to_numpy(float), sub["lo"].to_numpy(float),
                                   sub["hi"].to_numpy(float), vs, output=output, unit=sub["unit"].iloc[0],
                                   lower=next((r.lower for r in rs if r.lower is not None), None),
                                   upper=next((r.upper for r in rs if r.upper is not None), None),
                                   interval=self.interval, ax=ax)

    def summary(self) -> dict:
        """n, the interval, the verdict counts and, per unit, its verdict, requirements and outputs."""
        req, outs, verdicts = self._requirements, self._outputs, self.verdicts()
        units_ = []
        for u in self.units:
            rq = req[req["reducer"] == u]
            ou = outs[outs["reducer"] == u]
            units_.append({
                "reducer": u, "verdict": verdicts[u],
                "requirements": [{"requirement": r["requirement"], "P": r["P"], "P_ci": [r["P_lo"], r["P_hi"]],
                                  "required": r["required"], "verdict": r["verdict"],
                                  "iso14253": {"decision": r["ISO 14253-1"], "y": r["y"], "u": r["u"], "U": r["U"]}}
                                 for _, r in rq.iterrows()],
                "outputs": {o["output"]: {"unit": o["unit"], "median": o["median"], "interval": [o["lo"], o["hi"]],
                                          "failed": o["failed"]} for _, o in ou.iterrows()},
            })
        return {"n": self.n, "interval": self.interval, "counts": self.counts(),
                "conformance_probability": self.probability, "coverage_factor": self.coverage_factor, "units": units_}


def predict_units(model: Model, spec: ToleranceSpec, measured: MeasuredUnits, n: int, *, evaluator,
                  requirements=(), method: str = "lhs", seed: int | None = None,
                  interval: float = 0.95, probability: float | None = None,
                  coverage_factor: float = COVERAGE_FACTOR) -> UnitPredictions:
    """Predict every unit of ``measured`` (module docstring); ``evaluator``: an :class:`rvtol.mc.Evaluator`;
    ``probability``: the probability of conformance a unit must show (default: each requirement's own,
    :func:`rvtol.verdict.unit_probability_required`); ``coverage_factor``: k of the ISO 14253-1 guard band."""
    if not 0.0 < interval < 1.0:
        raise ValueError(f"interval must lie in (0, 1), got {interval}")
    if not coverage_factor > 0:
        raise ValueError(f"coverage_factor must be > 0, got {coverage_factor}")
    X = unit_design(spec, measured, n, method, seed)
    return evaluate_units(model, spec, measured, X, evaluator=evaluator, requirements=requirements, method=method,
                          seed=seed, interval=interval, probability=probability, coverage_factor=coverage_factor)


def evaluate_units(model: Model, spec: ToleranceSpec, measured: MeasuredUnits, X: np.ndarray, *, evaluator,
                   requirements=(), method: str = "lhs", seed: int | None = None, interval: float = 0.95,
                   probability: float | None = None, coverage_factor: float = COVERAGE_FACTOR,
                   what: str = "per-unit prediction") -> UnitPredictions:
    """The :class:`UnitPredictions` of the factor values ``X[units·n, k]`` (rows ``i·n … (i+1)·n − 1``: unit
    ``i``), all units in one call of ``evaluator``."""
    U = len(measured)
    n = X.shape[0] // U
    ev = evaluator(model, X, what)
    res = result_of(model, SampleSet(X, spec.names, spec.units, method, seed), ev)
    reqs = tuple(r.in_unit(model.output(r.output).shown_unit) for r in requirements)
    return UnitPredictions(tuple(measured.units), tuple(model.outputs), res.Y.reshape(U, n, -1),
                           res.status.reshape(U, n), reqs, float(interval), measured.measured.sum(axis=1),
                           dict(model.status_reasons), probability, float(coverage_factor))
