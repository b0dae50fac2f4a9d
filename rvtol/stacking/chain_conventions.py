"""The stack-up conventions of a deviation chain's key characteristics: worst case, RSS and loop-method signs of the
linearised chain, beside the Monte Carlo.

The conventions of :mod:`rvtol.stacking.conventions` read one output through its gradient; the outputs of a 6-DOF
deviation chain (doc 003, :class:`rvtol.models.stackup.model.StackupModel`) come in forms that a gradient alone does
not carry — a component of a key characteristic (KC), the norm of a pair of them, a weighted magnitude of all six —
so their worst case and RSS are taken here from the chain itself.  The chain is any model that gives its KCs'
Jacobians and deviations and the form of each output: ``jacobian(x0) -> {kc: J}``, ``kc_deviations(X) -> {kc: E}``,
``linear_form(output) -> (form, kc, selection)``, ``output(name)`` and ``nonlinear_floats()`` (the stack-up model's
methods; nothing here imports a model).

The chain's Jacobian ``J = ∂E_kc/∂x`` comes from
:meth:`rvtol.models.stackup.model.StackupModel.jacobian` (small-displacement
torsor adjoints, analytic, about the zero-deviation nominal; central
differences if the spec's nominal values deviate).  For each output:

* **signed component** (u, v, w, α, β, γ of a KC): first-order mean, RSS σ
  and worst case by :func:`rvtol.sensitivity.linearisation.linear_prediction`;
  the **loop-method sign** of each contributor is the sign of its
  derivative — doc 003's positive accumulator (pushes the KC up, "opposes the
  closed-loop direction"), negative accumulator (compensates) or
  uncorrelated (zero);
* **magnitude of a pair** (radial = √(u²+v²), tilt = √(α²+β²)): the norm is
  not differentiable at zero, so the pair ``z = M·(x − x0)`` is linearised
  instead.  Worst case: the largest norm over the box of tolerance bands,
  exactly (the image of a box is a zonotope; its farthest point is a vertex,
  found by sweeping the support direction).  RSS: ``z ~ N(M(μ−x0), M Σ Mᵀ)``;
  its norm's 99.73 % quantile and mean by one-dimensional quadrature;
* **weighted magnitude** (‖e‖, ‖ε‖): worst-case *bound* √Σ w_i WC_i² and
  RSS root-mean-square √Σ w_i (m_i² + C_ii);
* the assembly **margin** of a closing fit is not linearisable (a max of
  norms): Monte Carlo only.

Factor bands are :attr:`rvtol.distributions.Distribution.band`; the
covariance uses the Pearson correlation the spec's Gaussian copula gives the margins
(:func:`rvtol.sampling.factor_correlation`: the normal-score ρ itself for normal factors).  The clearance float enters through its
derivative at the nominal (centred) position, where it acts like a square
[-1, 1]² scaled by c/2 — the disc's circumscribed square — so linear worst
cases of floats are conservative by up to √2 and the float's size terms
(c × position) vanish; the Monte Carlo shows both.

:func:`linear_stackup` (the ``stackup_linear`` analysis of :mod:`rvtol.models.stackup.analyses`) returns a
:class:`LinearStackup`: per output the worst-case and RSS figures of its form, the Monte Carlo's beside them, and the
contributors with their loop-method signs.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import optimize
from scipy.special import ndtr

from .. import units
from ..errors import InputError
from ..records import frame_records
from ..sampling import factor_correlation
from ..sensitivity.linearisation import linear_prediction
from ..stats import percentile_ci, rss
from ..units import label

COVERAGE = 0.9973  # one-sided coverage of magnitudes (as ±3σ)


# --------------------------------------------------------------------------- geometry of the linear map
def zonotope_max_norm(centre, generators) -> float:
    """``max ‖c + Σ t_j g_j‖`` over ``t ∈ [-1, 1]^k`` for 2-D ``c`` and generators ``g[2, k]``.

    The maximum of a convex function over a zonotope sits at a vertex; the
    vertex in direction ``d`` is ``c + Σ sign(d·g_j) g_j`` and the sign
    pattern changes only where ``d ⟂ g_j``, so one direction inside each arc
    between those critical angles visits every vertex.
    """
    c = np.asarray(centre, float)
    G = np.asarray(generators, float)
    G = G[:, np.hypot(G[0], G[1]) > 0]
    if G.shape[1] == 0:
        return float(np.hypot(*c))
    crit = np.mod(np.arctan2(G[1], G[0]) + np.pi / 2, np.pi)
    crit = np.sort(np.concatenate([crit, crit + np.pi]))
    mids = 0.5 * (crit + np.roll(crit, -1))
    mids[-1] = 0.5 * (crit[-1] + crit[0] + 2 * np.pi)
    D = np.stack([np.cos(mids), np.sin(mids)], axis=1)
    V = c + np.sign(D @ G) @ G.T
    return float(np.hypot(V[:, 0], V[:, 1]).max())


_GL_X, _GL_W = np.polynomial.legendre.leggauss(256)


def _principal(mean, cov):
    w, V = np.linalg.eigh(np.asarray(cov, float))
    return V.T @ np.asarray(mean, float), np.sqrt(np.clip(w, 0.0, None))


def norm_cdf_2d(r, mean, cov) -> np.ndarray:
    """``P(‖z‖ ≤ r)`` for ``z ~ N(mean, cov)`` in 2-D, vectorised over ``r``.

    In the principal axes, ``P = ∫ φ(x; m₁, s₁)·[Φ((h−m₂)/s₂) − Φ((−h−m₂)/s₂)] dx`` with
    ``h = √(r² − x²)``; substituting ``x = r·sin θ`` makes the integrand smooth, and 256-point
    Gauss–Legendre over the part of θ within ±9 s₁ of m₁ gives ~1e-12 accuracy.
    """
    r = np.atleast_1d(np.asarray(r, float))
    m, s = _principal(mean, cov)
    out = np.zeros_like(r)
    pos = r > 0
    if s[1] == 0:  # deterministic
        out[pos] = (np.hypot(*m) <= r[pos]).astype(float)
        return out
    rr = r[pos][:, None]
    if s[0] == 0:  # all spread on the major axis
        h = np.sqrt(np.clip(rr[:, 0] ** 2 - m[0] ** 2, 0.0, None))
        val = ndtr((h - m[1]) / s[1]) - ndtr((-h - m[1]) / s[1])
        out[pos] = np.where(np.abs(m[0]) <= rr[:, 0], val, 0.0)
        return out
    lo = np.arcsin(np.clip((m[0] - 9 * s[0]) / rr, -1.0, 1.0))
    hi = np.arcsin(np.clip((m[0] + 9 * s[0]) / rr, -1.0, 1.0))
    th = 0.5 * (hi + lo) + 0.5 * (hi - lo) * _GL_X
    x, h = rr * np.sin(th), rr * np.cos(th)
    f = (np.exp(-0.5 * ((x - m[0]) / s[0]) ** 2) / (s[0] * np.sqrt(2 * np.pi))
         * (ndtr((h - m[1]) / s[1]) - ndtr((-h - m[1]) / s[1])) * h)
    out[pos] = 0.5 * (hi - lo)[:, 0] * (f @ _GL_W)
    return out


def _top(mean, cov) -> float:
    return float(np.hypot(*np.asarray(mean, float)) + 12 * np.sqrt(max(np.trace(np.asarray(cov, float)), 0.0)))


def norm_quantile_2d(p: float, mean, cov) -> float:
    top = _top(mean, cov)
    if top == 0:
        return 0.0
    return float(optimize.brentq(lambda r: norm_cdf_2d(r, mean, cov)[0] - p, 0.0, top, xtol=1e-14 * top,
                                 rtol=1e-12))


def norm_mean_2d(mean, cov) -> float:
    """``E‖z‖ = ∫₀^∞ (1 − F(r)) dr`` (Gauss–Legendre on [0, |m| + 12σ])."""
    top = _top(mean, cov)
    if top == 0:
        return 0.0
    r = 0.5 * top * (1.0 + _GL_X)
    return float(0.5 * top * ((1.0 - norm_cdf_2d(r, mean, cov)) @ _GL_W))


# --------------------------------------------------------------------------- the linearisation
@dataclass
class Factors:
    """Per-factor bands and moments in base units."""

    x0: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    mu: np.ndarray
    cov: np.ndarray

    @classmethod
    def of(cls, spec) -> "Factors":
        lims = np.array([[units.to_base(v, f.unit) for v in f.band] for f in spec.factors])
        sd = spec.std_base()
        corr = factor_correlation(spec)      # the copula's Pearson correlation of the margins (None: independent)
        corr = np.eye(len(spec)) if corr is None else corr
        return cls(spec.nominal_base(), lims[:, 0], lims[:, 1], spec.mean_base(), corr * np.outer(sd, sd))

    @property
    def centre(self):
        return 0.5 * (self.lo + self.hi)

    @property
    def half(self):
        return 0.5 * (self.hi - self.lo)


def loop_sign(g, rel: float = 1e-9) -> list[str]:
    """Doc 003's loop method: '+' positive accumulator, '−' negative accumulator, '0' uncorrelated."""
    g = np.asarray(g, float)
    tol = rel * (np.abs(g).max() if g.size else 0.0)
    return ["+" if v > tol else "−" if v < -tol else "0" for v in g]


@dataclass
class OutputLinearisation:
    output: str
    unit: str  # display
    form: str
    figures: dict  # name -> value (display units)
    contributions: pd.DataFrame
    notes: list[str] = field(default_factory=list)


def linearise_output(model, spec, name: str, J: dict, fx: Factors,
                     E0: dict | None = None) -> OutputLinearisation:
    """Linear predictions of one output from the KC Jacobians ``J`` and KC deviations ``E0`` at ``fx.x0``."""
    q = model.output(name)
    form, kc, sel = model.linear_form(name)
    disp = lambda v: float(q.to_display(v))  # noqa: E731
    e0 = (model.kc_deviations(fx.x0[None])[0] if E0 is None else E0)[kc].reshape(6)
    Jk = J[kc].copy()
    Jk[np.abs(Jk) < 1e-12 * max(np.abs(Jk).max(), 1e-300)] = 0.0  # cos(π/2)-sized noise of the transport
    if form == "dof":
        g = Jk[sel]
        pred = linear_prediction(spec, g, float(e0[sel]), fx.x0, name, q.shown_unit, q.unit)
        wc = np.abs(g) * fx.half
        fr = pd.DataFrame({"factor": spec.names, "derivative": pred.frame["S"], "unit": pred.frame["S_unit"],
                           "sign": loop_sign(g),
                           "accumulator": [{"+": "positive", "−": "negative", "0": "uncorrelated"}[s]
                                           for s in loop_sign(g)],
                           "worst-case share %": _pct(wc), "variance share %": pred.frame["variance_pct"]})
        figs = {"WC low": pred.worst_low, "WC high": pred.worst_high, "RSS mean": pred.mean, "RSS σ": pred.std,
                "RSS low": pred.mean - 3 * pred.std, "RSS high": pred.mean + 3 * pred.std}
        return OutputLinearisation(name, q.shown_unit, form, figs, fr, list(pred.notes))
    if form == "norm":
        M = Jk[list(sel)]
        centre = e0[list(sel)] + M @ (fx.centre - fx.x0)
        wc = zonotope_max_norm(centre, M * fx.half)
        m, C = e0[list(sel)] + M @ (fx.mu - fx.x0), M @ fx.cov @ M.T
        share_var = np.einsum("ij,ij->j", M, M) * np.diag(fx.cov)
        fr = pd.DataFrame({"factor": spec.names,
                           "derivative": [_pair(M[:, j], q, f.unit) for j, f in enumerate(spec.factors)],
                           "unit": [f"{label(q.shown_unit)}/{label(f.unit)}" for f in spec.factors],
                           "sign": [f"({a}, {b})" for a, b in zip(loop_sign(M[0]), loop_sign(M[1]))],
                           "accumulator": "—",
                           "worst-case share %": _pct(np.hypot(M[0], M[1]) * fx.half),
                           "variance share %": _pct(share_var)})
        figs = {"WC high": disp(wc), "RSS mean": disp(norm_mean_2d(m, C)),
                "RSS high": disp(norm_quantile_2d(COVERAGE, m, C))}
        return OutputLinearisation(name, q.shown_unit, form, figs, fr)
    if form == "weighted":
        w = sel
        lin = e0 + Jk @ (fx.centre - fx.x0)
        wc_dof = np.abs(lin) + np.abs(Jk) @ fx.half
        m, C = e0 + Jk @ (fx.mu - fx.x0), Jk @ fx.cov @ Jk.T
        contrib = (w[:, None] * Jk**2).sum(axis=0) * np.diag(fx.cov)
        fr = pd.DataFrame({"factor": spec.names, "derivative": np.nan, "unit": "", "sign": "",
                           "accumulator": "—",
                           "worst-case share %": _pct((np.sqrt(w)[:, None] * np.abs(Jk)).sum(0) * fx.half),
                           "variance share %": _pct(contrib)})
        figs = {"WC high": disp(rss(wc_dof, weights=w)),
                "RSS high": disp(rss(m, weights=w, variances=np.diag(C)))}
        return OutputLinearisation(name, q.shown_unit, form, figs, fr,
                                   ["worst case is an upper bound √Σ w_i WC_i² (each DOF at its own worst)"])
    return OutputLinearisation(name, q.shown_unit, form, {}, pd.DataFrame(),
                               ["not linearisable (larger of two end-point norms): Monte Carlo only"])


def _pct(v) -> np.ndarray:
    v = np.asarray(v, float)
    s = v.sum()
    return 100.0 * v / s if s > 0 else np.zeros_like(v)


def _pair(col, q, funit) -> str:
    f = units.factor(funit) / units.factor(q.shown_unit) * units.factor(q.unit)
    return f"({col[0] * f:.4g}, {col[1] * f:.4g})"


# --------------------------------------------------------------------------- beside the Monte Carlo
#: what the WC / RSS / MC columns hold, per kind of output
BASIS = {
    "dof": "signed: WC = arithmetic worst case; RSS = mean ± 3σ; MC = P0.135 / P99.865",
    "norm": "magnitude: WC high = max over the tolerance box; RSS high = P99.73 of the linearised pair's norm; "
            "MC high = P99.73",
    "weighted": "‖e‖/‖ε‖: WC high = upper bound; RSS high = rms; MC high = rms",
    "none": "margin: Monte Carlo only (MC low = P0.27, MC high = P99.73)",
}
COLUMNS = ["output", "unit", "kind", "WC low", "WC high", "RSS mean", "RSS σ", "RSS low", "RSS high", "MC mean", "MC σ",
           "MC low", "MC high", "MC max"]


def check_linearisable(model) -> None:
    """Raise :class:`InputError` if a fit of ``model`` floats in a worst-case mode (not differentiable)."""
    worst = model.nonlinear_floats()
    if worst:
        raise InputError(f"fit {worst[0]!r} floats in a worst-case mode, which is not differentiable in its "
                         "direction; linearise a model with uniform (or centred) floats")


def mc_figures(mc, name: str, form: str) -> dict:
    """The Monte Carlo figures of output ``name`` that match the linearised ones of its ``form``."""
    y = mc.column(name)
    y = np.sort(y[np.isfinite(y)])
    if len(y) == 0:
        return {}
    out = {"MC mean": float(y.mean()), "MC σ": float(y.std(ddof=1)) if len(y) > 1 else float("nan")}
    if form == "dof":
        out["MC low"] = percentile_ci(y, 0.00135)[0]
        out["MC high"] = percentile_ci(y, 0.99865)[0]
    elif form == "weighted":
        out["MC high"] = float(np.sqrt(np.mean(y**2)))
    else:
        if form == "none":
            out["MC low"] = percentile_ci(y, 1 - COVERAGE)[0]
        out["MC high"] = percentile_ci(y, COVERAGE)[0]
    out["MC min"], out["MC max"] = float(y[0]), float(y[-1])
    return out


@dataclass
class OutputFigures:
    """One output: its linearisation, the Monte Carlo figures and its largest contributors (``top``)."""

    name: str
    linear: OutputLinearisation
    mc: dict
    top: pd.DataFrame | None = None

    def plot(self, top: int = 12):
        from ..plotting.stackup import contribution_bars

        return contribution_bars(self.linear, top=top)

    def summary(self) -> dict:
        lin = self.linear
        out = {"form": lin.form, "linear": lin.figures, "monte_carlo": self.mc, "notes": lin.notes}
        if not lin.contributions.empty:
            out["contributions"] = frame_records(lin.contributions)
        return out


@dataclass
class LinearStackup:
    outputs: list[OutputFigures]
    top: int
    figures: list[str] = field(default_factory=list)     # outputs that get a contribution chart

    def to_frame(self) -> pd.DataFrame:
        """One row per output: worst case, RSS and Monte Carlo figures (display units)."""
        rows = [{"output": o.name, "unit": label(o.linear.unit), "kind": o.linear.form, **o.linear.figures, **o.mc}
                for o in self.outputs]
        return pd.DataFrame(rows).reindex(columns=COLUMNS)

    def summary(self) -> dict:
        return {"outputs": {o.name: o.summary() for o in self.outputs}}

    def plot(self, output: str | None = None):
        """The contribution chart of ``output`` (default: the first the study charts, else the first output) with
        its ``top`` contributors — the report's figure."""
        name = output or (self.figures[0] if self.figures else self.outputs[0].name)
        for o in self.outputs:
            if o.name == name:
                return o.plot(self.top)
        raise ValueError(f"no output {name!r} (outputs: {', '.join(o.name for o in self.outputs)})")


def linear_stackup(model, spec, mc, outputs, top: int = 12, figures=()) -> LinearStackup:
    """Worst case and RSS of the linearised chain of each of ``outputs`` beside the Monte Carlo ``mc``;
    ``top`` contributors per output; ``figures``: the outputs whose contributions are charted."""
    fx = Factors.of(spec)
    J = model.jacobian(fx.x0)
    E0 = model.kc_deviations(fx.x0[None])[0]
    out = []
    for name in outputs:
        lin = linearise_output(model, spec, name, J, fx, E0)
        o = OutputFigures(name, lin, mc_figures(mc, name, lin.form))
        if not lin.contributions.empty:
            o.top = lin.contributions.sort_values("variance share %", ascending=False).head(top)
        out.append(o)
    return LinearStackup(out, top, list(figures))
