"""Weighted nonlinear least squares with its uncertainty and an identifiability check.

Residuals ``r_i = w_i (f_i(θ) + o_g(i) − y_i)``: ``f`` the model's value at measured point ``i``
(a :class:`rvtol.model.Model` whose inputs are the physical parameters θ), ``o_g`` the angle offset
of the point's measurement (linear: its Jacobian column is the exact indicator, no model
evaluation), ``w_i = 1/σ_i`` with ``σ_i`` the measurement's stated uncertainty — or one display unit
(e.g. 1 arcsec) when none is given, which changes nothing but the size of the numbers.  Minimised by
:func:`scipy.optimize.least_squares` (trust-region reflective, bounded); the model Jacobian by
central differences (one-sided at a bound, step 10⁻³ of each parameter's typical size), all ``2k``
perturbed rows in one batch through the :class:`rvtol.mc.Evaluator`.

Uncertainty (the linearised theory of nonlinear regression: Seber & Wild, *Nonlinear Regression*,
Wiley 1989, §2.1 and §5.1; Bates & Watts, *Nonlinear Regression Analysis and Its Applications*,
Wiley 1988, §2.3 — what ``scipy.optimize.curve_fit`` computes with ``absolute_sigma=False``):

* degrees of freedom ``ν = n − p`` (``n`` points used, ``p`` parameters, offsets included);
* ``s² = Σ r_i² / ν`` — the residual variance, estimated from the fit even when σ is given
  (then ``s²`` is the reduced χ², ≈ 1 when the stated σ and the model are right);
* covariance ``C = s² (JᵀJ)⁻¹`` (``J = ∂r/∂θ`` at the estimate; by SVD, so a singular direction is
  found rather than inverted);
* confidence interval ``θ̂_j ± t_{(1+γ)/2, ν} √C_jj`` at confidence ``γ``; correlation
  ``ρ_jk = C_jk / √(C_jj C_kk)``.

The intervals are linearised: right when the model is close to linear in the parameters over the
interval and the residuals are independent with equal variance (after weighting) — both are shown in
the report (residual plot, reduced χ²).  An estimate on a bound has no symmetric interval: it is
flagged.

**Identifiability** (:class:`Identifiability`): named, with what would separate them
(:func:`.parameters.separation_advice`), are a parameter the measurement does not depend on (a zero
Jacobian column), parameters in a numerically singular direction, any pair of estimates with
``|ρ| > max_correlation`` (default 0.95), and groups that are collinear together although no pair
is: Belsley's diagnostics on the Jacobian with unit columns ``J̃`` (Belsley, Kuh & Welsch,
*Regression Diagnostics*, Wiley 1980, ch. 3) — condition indices ``η_k = s_max/s_k`` from the
singular values of ``J̃``, a component with ``η_k > 30`` ("moderate to strong" dependency in their
scale) and the parameters with a variance-decomposition proportion above 0.5 on it.  Each
parameter's multiple correlation with the others (``R_j² = 1 − 1/VIF_j``) is reported beside it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import optimize, stats

from ...errors import InputError, SolverError
from ...mc import Evaluator
from ...model import Model
from .parameters import Parameter, separation_advice

STEP = 1e-3          # finite-difference step, fraction of a parameter's typical size
RCOND = 1e-10        # singular values below RCOND × the largest: a direction the data do not determine


@dataclass
class Identifiability:
    """What the measurement cannot tell apart (names as the parameters'), and why."""

    condition: float                                   # cond(J̃ᵀJ̃) = η_max², J̃ with unit columns
    max_correlation: float
    unused: list[str] = field(default_factory=list)    # the measurement does not depend on it
    singular: list[list[str]] = field(default_factory=list)
    pairs: list[tuple[str, str, float]] = field(default_factory=list)
    collinear: list[tuple[list[str], float]] = field(default_factory=list)   # (group, condition index)
    multiple: dict[str, float] = field(default_factory=dict)   # multiple correlation R_j per parameter
    condition_indices: np.ndarray = field(default_factory=lambda: np.zeros(0))
    messages: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not (self.unused or self.singular or self.pairs or self.collinear)

    @property
    def flagged(self) -> set[str]:
        out = set(self.unused) | {n for g in self.singular for n in g} | {n for g, _ in self.collinear for n in g}
        return out | {n for a, b, _ in self.pairs for n in (a, b)}


@dataclass
class FitResult:
    """A finished fit (base units; ``parameters`` in the order of ``x``)."""

    parameters: tuple[Parameter, ...]
    x: np.ndarray
    se: np.ndarray
    ci: np.ndarray               # [p, 2]
    cov: np.ndarray
    corr: np.ndarray
    at_bound: np.ndarray
    confidence: float
    n: int
    dof: int
    s2: float                    # Σ r² / ν (weighted): the reduced χ² when σ was given
    weighted: bool               # σ given for every point
    y: np.ndarray                # measured values used (base)
    y_model: np.ndarray          # model + offset at the estimate (base)
    jac: np.ndarray              # ∂r/∂θ at the estimate
    t: float                     # the t quantile used
    nfev: int                    # residual evaluations of the optimiser
    evaluations: int             # 20-DOF model evaluations (rows), finite differences included
    success: bool
    message: str
    rejected: list[str]          # trial points where the model failed (rejected by the trust region)
    identifiability: Identifiability

    @property
    def names(self) -> list[str]:
        return [p.name for p in self.parameters]

    @property
    def residuals(self) -> np.ndarray:
        """Model − measurement at the points used (base units, unweighted)."""
        return self.y_model - self.y

    def value(self, name: str) -> float:
        return float(self.x[self.names.index(name)])

    def to_frame(self) -> pd.DataFrame:
        """One row per parameter, in display units."""
        rows = []
        for j, p in enumerate(self.parameters):
            d = p.display
            rows.append({"parameter": p.name, "acts on": p.acts_on(), "unit": p.unit, "start": d(p.start),
                         "lower": d(p.lower), "upper": d(p.upper), "estimate": d(self.x[j]),
                         "std. error": d(self.se[j]) if math.isfinite(self.se[j]) else math.inf,
                         f"{self.confidence:.0%} CI low": d(self.ci[j, 0]),
                         f"{self.confidence:.0%} CI high": d(self.ci[j, 1]),
                         "at bound": bool(self.at_bound[j]),
                         "multiple correlation": self.identifiability.multiple.get(p.name, math.nan),
                         "separable": p.name not in self.identifiability.flagged})
        return pd.DataFrame(rows)

    def correlation_frame(self) -> pd.DataFrame:
        return pd.DataFrame(self.corr, index=self.names, columns=self.names)

    @property
    def largest_correlation(self) -> float:
        """The largest |ρ| between two estimates (0 with one parameter)."""
        c = self.corr
        if c.shape[0] < 2:
            return 0.0
        off = np.abs(c[~np.eye(c.shape[0], dtype=bool)])
        return float(np.nanmax(off)) if np.isfinite(off).any() else float("nan")


def _differences(evaluator: Evaluator, model: Model, x: np.ndarray, f0: np.ndarray, lower, upper, typical):
    """Central-difference Jacobian of the model (one-sided at a bound); ``[n, k]``."""
    k = x.size
    h = STEP * typical
    plus = np.minimum(x + h, upper)
    minus = np.maximum(x - h, lower)
    X = np.repeat(x[None, :], 2 * k, axis=0)
    X[np.arange(k), np.arange(k)] = plus
    X[k + np.arange(k), np.arange(k)] = minus
    ev = evaluator(model, X, "calibration: Jacobian")
    J = np.empty((f0.size, k))
    for j in range(k):
        fp, fm = ev.Y[j], ev.Y[k + j]
        okp, okm = ev.status[j] == 0, ev.status[k + j] == 0
        if okp and okm and plus[j] > minus[j]:
            J[:, j] = (fp - fm) / (plus[j] - minus[j])
        elif okp and plus[j] > x[j]:
            J[:, j] = (fp - f0) / (plus[j] - x[j])
        elif okm and minus[j] < x[j]:
            J[:, j] = (f0 - fm) / (x[j] - minus[j])
        else:
            code = int(ev.status[j] or ev.status[k + j])
            raise SolverError(f"the model failed beside the estimate for {model.inputs[j]} "
                              f"({model.status_reasons.get(code, code)})")
    return J


def least_squares_fit(model: Model, physical: list[Parameter], offsets: list[tuple[Parameter, np.ndarray]],
                      y: np.ndarray, weight: np.ndarray, *, weighted: bool, evaluator: Evaluator | None = None,
                      confidence: float = 0.95, max_correlation: float = 0.95, max_condition_index: float = 30.0,
                      kinds=()) -> FitResult:
    """Fit ``physical`` (the model's inputs, in order) and ``offsets`` (``(parameter, mask of the points it
    shifts)``) to ``y`` with weights ``weight = 1/σ`` (see the module docstring)."""
    evaluator = evaluator or Evaluator()
    if tuple(p.name for p in physical) != tuple(model.inputs):
        raise InputError("the physical parameters must be the model's inputs, in order", key="parameter")
    params = tuple(physical) + tuple(p for p, _ in offsets)
    k, p_all = len(physical), len(params)
    n = y.size
    dof = n - p_all
    if dof < 1:
        raise InputError(f"{n} measured points for {p_all} parameters: need more points than parameters",
                         key="parameter")
    O = np.zeros((n, len(offsets)))
    for j, (_, mask) in enumerate(offsets):
        O[mask, j] = 1.0
    lower = np.array([p.lower for p in params])
    upper = np.array([p.upper for p in params])
    typical = np.array([p.typical for p in params])
    x0 = np.array([p.start for p in params])
    cache: dict[bytes, np.ndarray] = {}
    rejected: list[str] = []
    rows = [0]                       # model evaluations (rows), the Jacobian's included

    def count(ev_fn):
        def wrapped(m, X, desc):
            rows[0] += len(X)
            return ev_fn(m, X, desc)
        return wrapped

    evaluate = count(evaluator)

    def model_at(xp: np.ndarray, desc: str):
        key = xp.tobytes()
        if key not in cache:
            ev = evaluate(model, xp[None, :], desc)
            if ev.status[0] != 0:
                return None, int(ev.status[0])
            cache[key] = ev.Y[0]
        return cache[key], 0

    f_start, code = model_at(x0[:k], "calibration: start")
    if f_start is None:
        raise SolverError(f"the model fails at the start values ({model.status_reasons.get(code, code)})")
    penalty = 1e3 * max(1.0, float(np.max(np.abs(weight * (f_start + O @ x0[k:] - y)))))

    def residuals(xa):
        f, code = model_at(xa[:k], "calibration: step")
        if f is None:         # a trial point the solver cannot handle: rejected by the trust region
            rejected.append(model.status_reasons.get(code, str(code)))
            return np.full(n, penalty)
        return weight * (f + O @ xa[k:] - y)

    def jacobian(xa):
        f, _ = model_at(xa[:k], "calibration: step")
        Jm = _differences(evaluate, model, xa[:k], f, lower[:k], upper[:k], typical[:k]) if k else np.zeros((n, 0))
        return weight[:, None] * np.hstack([Jm, O])

    res = optimize.least_squares(residuals, x0, jac=jacobian, bounds=(lower, upper), x_scale=typical,
                                 method="trf", max_nfev=200 * p_all)
    x = res.x
    f, code = model_at(x[:k], "calibration: estimate")
    if f is None:
        raise SolverError(f"the model fails at the estimate ({model.status_reasons.get(code, code)})")
    r = weight * (f + O @ x[k:] - y)
    J = jacobian(x)
    s2 = float(r @ r / dof)
    cov, null = _covariance(J, typical, s2)
    se = np.sqrt(np.diag(cov))
    t = float(stats.t.ppf(0.5 * (1.0 + confidence), dof))
    ci = np.column_stack([x - t * se, x + t * se])
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    corr[~np.isfinite(corr)] = np.nan
    np.fill_diagonal(corr, 1.0)
    span = upper - lower
    at_bound = (x - lower <= 1e-6 * span) | (upper - x <= 1e-6 * span)
    ident = identifiability(J, corr, null, list(params), max_correlation, kinds, max_condition_index)
    return FitResult(params, x, se, ci, cov, corr, at_bound, confidence, n, dof, s2, weighted, y,
                     f + O @ x[k:], J, t, int(res.nfev), rows[0], bool(res.success), str(res.message), rejected, ident)


def _covariance(J: np.ndarray, typical: np.ndarray, s2: float) -> tuple[np.ndarray, list[np.ndarray]]:
    """``s² (JᵀJ)⁻¹`` by SVD of the column-scaled Jacobian; undetermined directions give infinite variance."""
    U, S, Vt = np.linalg.svd(J * typical, full_matrices=False)
    keep = S > RCOND * (S[0] if S.size and S[0] > 0 else 1.0)
    V = Vt.T
    cov_s = (V[:, keep] / S[keep] ** 2) @ V[:, keep].T * s2
    cov = cov_s * np.outer(typical, typical)
    null = [V[:, i] for i in np.flatnonzero(~keep)]
    for v in null:
        inf = np.abs(v) > 0.1
        cov[inf, :] = np.inf
        cov[:, inf] = np.inf
    return cov, null


def multiple_correlation(J: np.ndarray, names: list[str]) -> dict[str, float]:
    """``R_j``: multiple correlation of parameter ``j``'s Jacobian column with the others',
    ``R_j² = 1 − 1/VIF_j`` (uncentred; NaN where the columns are singular or zero)."""
    norms = np.linalg.norm(J, axis=0)
    out = {n: math.nan for n in names}
    if J.shape[1] < 2 or not np.all(norms > 0):
        return {n: (0.0 if J.shape[1] == 1 else math.nan) for n in names}
    Jn = J / norms
    G = Jn.T @ Jn
    if np.linalg.cond(G) > 1 / RCOND ** 2:
        return out
    vif = np.diag(np.linalg.inv(G))
    return {n: float(np.sqrt(max(0.0, 1.0 - 1.0 / v))) for n, v in zip(names, vif)}


def condition_indices(J: np.ndarray) -> np.ndarray:
    """Belsley's condition indices ``η_k = s_max / s_k`` of the Jacobian with unit columns (zero columns left out)."""
    norms = np.linalg.norm(J, axis=0)
    s = np.linalg.svd(J[:, norms > 0] / norms[norms > 0], compute_uv=False)
    return s[0] / np.where(s > 0, s, np.nan) if s.size else s


def collinear_groups(J: np.ndarray, names: list[str], max_index: float) -> list[tuple[float, list[str]]]:
    """``[(η_max, parameters)]`` when some condition index exceeds ``max_index``: the parameters whose
    variance-decomposition proportions, summed over all components above ``max_index``, exceed 0.5
    (Belsley, Kuh & Welsch 1980, §3.2; summing handles competing dependencies of similar η)."""
    norms = np.linalg.norm(J, axis=0)
    idx = np.flatnonzero(norms > 0)
    if idx.size < 2:
        return []
    _, s, Vt = np.linalg.svd(J[:, idx] / norms[idx], full_matrices=False)
    if not s[-1] > 0:
        return []
    eta = s[0] / s
    phi = (Vt.T / s) ** 2                          # [param, component]
    prop = phi / phi.sum(axis=1, keepdims=True)    # variance-decomposition proportions
    high = eta > max_index
    group = [names[idx[j]] for j in np.flatnonzero(prop[:, high].sum(axis=1) > 0.5)]
    return [(float(eta.max()), group)] if high.any() and len(group) > 1 else []


def identifiability(J: np.ndarray, corr: np.ndarray, null: list[np.ndarray], params: list[Parameter],
                    max_correlation: float, kinds=(), max_condition_index: float = 30.0) -> Identifiability:
    """Name the parameters this measurement cannot separate (module docstring)."""
    names = [p.name for p in params]
    norms = np.linalg.norm(J, axis=0)
    used = norms > 0
    Jn = J[:, used] / norms[used]
    G = Jn.T @ Jn
    ident = Identifiability(float(np.linalg.cond(G)) if used.any() else math.inf, max_correlation)
    ident.unused = [names[j] for j in np.flatnonzero(~used)]
    for v in null:
        group = [names[j] for j in np.flatnonzero(np.abs(v) > 0.1) if used[j]]
        if len(group) > 1:
            ident.singular.append(group)
    p = len(names)
    for a in range(p):
        for b in range(a + 1, p):
            rho = corr[a, b]
            if np.isfinite(rho) and abs(rho) > max_correlation:
                ident.pairs.append((names[a], names[b], float(rho)))
    paired = {n for a, b, _ in ident.pairs for n in (a, b)} | {n for g in ident.singular for n in g} | set(ident.unused)
    ident.multiple = multiple_correlation(J, names)
    ident.condition_indices = condition_indices(J)
    for eta, group in collinear_groups(J, names, max_condition_index):
        if len(set(group) - paired) > 1 or not set(group) & paired:   # not just a flagged pair plus one
            ident.collinear.append((group, eta))
    by_name = dict(zip(names, params))
    for n in ident.unused:
        ident.messages.append(f"{n}: this measurement does not depend on it (its Jacobian column is zero): "
                              f"{by_name[n].separated_by or 'measure something it changes'}, or drop it.")
    for g in ident.singular:
        ident.messages.append(f"{', '.join(g)}: not determined together (singular Jacobian): "
                              f"{separation_advice([by_name[n] for n in g], kinds)}")
    for a, b, rho in ident.pairs:
        ident.messages.append(f"{a} and {b} cannot be separated by this measurement (ρ = {rho:+.3f}): "
                              f"{separation_advice([by_name[a], by_name[b]], kinds)}")
    for group, eta in ident.collinear:
        ident.messages.append(f"{', '.join(group)} are nearly collinear together (condition index {eta:.3g} > "
                              f"{max_condition_index:g}): {separation_advice([by_name[k] for k in group], kinds)}")
    return ident
