"""The uncertainty of a law fitted to measured parts, carried into a requirement's verdict.

A factor with ``dist = "measured"`` and ``method = "fit"`` (:func:`rvtol.inputs.measured.parametric.fit`) is sampled
from the law fitted to its n measured values, θ̂.  Treated as known, that law would let a Monte Carlo of any
size "demonstrate" a yield the data cannot support: fitted to 250 parts a lognormal's 99.2 % point is known
only to within a factor of about 1.5 in ppm, and the requirement's limit may lie beyond every measured value,
where only the fitted tail speaks.  This module measures how much the figures a requirement judges (yield,
Cpk) move over the laws the data allow, so that :mod:`rvtol.verdict` judges a bound that carries it.

**The laws the data allow** (:func:`law_draws`).  B parametric bootstrap samples of n values are drawn from
θ̂ (with the gauge's normal error added and removed again when the factor has a ``measurement_sigma``:
the whole estimation is repeated) and the same family is refitted to each (θ_b, the same maximum
likelihood as the fit itself, the location of a positive family fixed as there).  They become draws θ*
of the parameter's distribution given the data:

* *location–scale families* — normal, Gumbel, uniform, and lognormal, Weibull (location fixed: the
  normal and smallest-extreme-value laws of ln(x − x₀)) and Rayleigh (a scale family) — have pivots:
  with (a, b) the location and scale in those coordinates and an equivariant estimator (the MLE),
  (â − a)/b̂ and b̂/b are distributed as (a_b − â)/b_b and b_b/b̂ whatever the true (a, b).  Inverting
  them draw by draw, b* = b̂²/b_b and a* = â − b̂ (a_b − â)/b_b, gives the fiducial distribution —
  Fisher's, equal here to the Bayesian posterior under the right-Haar prior 1/b (D. A. S. Fraser,
  *The Structure of Inference*, Wiley 1968).  For one normal factor and a limit U its lower quantile
  of Φ((U − a*)/b*) is the exact confidence bound of the yield P(X ≤ U), the one the noncentral t
  gives from (x̄, s, n) (D. B. Owen, "A survey of properties and applications of the noncentral
  t-distribution", Technometrics 10 (1968) 445–478; the one-sided tolerance bound) — the test oracle
  of this module.  The plain percentile bootstrap (the refits θ_b themselves) covers 91 % where 95 % is
  claimed in that case at n = 250: it is not used;
* other families (gamma, beta, Johnson, Pearson III, positive families with a fitted location) have no
  pivot; their draws are the refits reflected about θ̂ — the basic bootstrap, θ* = 2θ̂ − θ_b, on the
  log scale for positive parameters (A. C. Davison, D. V. Hinkley, *Bootstrap Methods and their
  Application*, Cambridge 1997, §5.2) — which is the fiducial draw above to first order.

The draws are conditional on the family the fit chose (AIC): a family's own tail is taken as given, and the
report's Anderson–Darling test and Q–Q plot are what judge it.  The copies of a family (``multiplicity``)
drawn from one set of measured values share one unknown law: one set of draws moves them together.

**Their effect on the Monte Carlo** (:func:`effects`).  The samples of the study were drawn from θ̂; the
same samples, weighted by the likelihood ratio w = f_θ*(x)/f_θ̂(x) of the measured factors (times the ratio
of the Gaussian copula densities when the spec correlates a measured factor), estimate every figure under
θ* without a single new model evaluation (importance sampling: E_θ̂[w·g] = E_θ*[g]).  The yield under θ*
is 1 − Σ_out w/N over the samples outside the limits (or Σ_in w/N when fewer are in) — exact in
expectation, and needing weights only where the requirement's tail is — less the probability θ* puts
outside θ̂'s support, where no sample was drawn (counted as non-conforming: a bounded law whose refit is
wider).  Cpk (normal theory: weighted mean and σ; percentile: weighted 0.135/50/99.865 % points) is
estimated on a fixed subsample of at most :data:`SUBSAMPLE` samples, on which its unweighted value is the
centre, so the sampling noise the draws share cancels in the difference (the Cpk's own sampling error is
Bissell's, from all the samples).  Kish's effective sample size
(Σw)²/Σw² of each draw on that subsample says whether the weights can be trusted (a note below 25 %: the
reweighted figures' Monte Carlo error twice the unweighted one's).

**The bound judged** (:mod:`rvtol.verdict`).  At the requirement's one-sided level ℓ the fit's deviation
is d_fit = p̂ − (the 1 − ℓ quantile of the yield over the draws) (and likewise for Cpk), combined with the
Monte Carlo's own deviation (Clopper–Pearson/Wilson, Bissell) as independent errors
(:func:`rvtol.stats.combined_lower_bound`).  A requirement the estimate meets but whose bound the fit's
deviation alone keeps below it cannot be demonstrated by more samples: the verdict gives the measured parts
that would (d_fit shrinks as 1/√n).

**Where the data end**.  The share of the non-conforming samples whose value of a measured factor lies
beyond every measured value (above the largest, or below the smallest) says how much of the yield is the
fitted law's extrapolated tail; from :data:`EXTRAPOLATED` on, the requirement's notes say that the limit
lies beyond the data.

Only ``method = "fit"`` is carried this way; a factor resampled (``empirical``) or smoothed (``kde``) from
its values has no parameter to draw and no tail beyond its data: a requirement that depends on one gets a
note saying that its bound does not carry the data's own uncertainty.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from .errors import InputError
from .inputs.measured import FAMILIES, deconvolve, fit_family
from .units import label as unit_label

#: parameter draws per measured factor
DRAWS = 400
#: the most samples the Cpk under each draw is estimated on (and the weights' effective sample size, on
#: :data:`ESS_SUBSAMPLE` when no Cpk is asked for)
SUBSAMPLE = 10_000
ESS_SUBSAMPLE = 1_000
#: the share of the non-conforming samples beyond the measured values from which a note says so
EXTRAPOLATED = 0.5
#: a draw's effective sample size (fraction of the samples) below which the notes warn: the reweighted figures'
#: Monte Carlo error is then more than twice the unweighted one's
LOW_ESS = 0.25
#: points × draws per block of weights (memory: 8 bytes each)
_BLOCK = 1 << 21

#: location-scale coordinates (a, b) of a family's scipy parameters, and back — the families with a pivot
_PIVOTAL = {
    "normal": (lambda p: (p["loc"], p["scale"]), lambda a, b, p: {"loc": a, "scale": b}),
    "gumbel": (lambda p: (p["loc"], p["scale"]), lambda a, b, p: {"loc": a, "scale": b}),
    "uniform": (lambda p: (p["loc"], p["scale"]), lambda a, b, p: {"loc": a, "scale": b}),
    "lognormal": (lambda p: (math.log(p["scale"]), p["s"]),
                  lambda a, b, p: {"s": b, "loc": p["loc"], "scale": np.exp(a)}),
    "weibull": (lambda p: (math.log(p["scale"]), 1.0 / p["c"]),
                lambda a, b, p: {"c": 1.0 / b, "loc": p["loc"], "scale": np.exp(a)}),
    "rayleigh": (lambda p: (0.0, p["scale"]), lambda a, b, p: {"loc": p["loc"], "scale": b}),
}
#: the positive families: pivotal only with their location fixed
_POSITIVE_PIVOTAL = ("lognormal", "weibull", "rayleigh")
#: shape parameters that may be negative (reflected on their own scale, not the log one)
_REAL_SHAPES = {"johnsonsu": ("a",), "johnsonsb": ("a",), "pearson3": ("skew",)}


@dataclass
class Laws:
    """The law fitted to one measured factor and ``draws`` laws its data allow (module docstring)."""

    factor: str
    family: str
    fitted: dict                  # θ̂, scipy's parameter names
    draws: dict                   # parameter -> array of the draws' values
    method: str                   # "pivotal" or "reflected bootstrap"
    parts: int                    # the measured values the law was fitted to
    data_range: tuple[float, float]   # the smallest and largest measured value (as read)
    failed: int = 0               # bootstrap refits that failed (left out)
    unit: str = ""                # the factor's unit (of its values and of data_range)

    @property
    def dist(self):
        return FAMILIES[self.family][0]

    @property
    def n_draws(self) -> int:
        return int(next(iter(self.draws.values())).size)

    def log_ratio(self, x: np.ndarray) -> np.ndarray:
        """``[len(x), draws]``: ln f_θ*(x) − ln f_θ̂(x) (−∞ where a draw's density is 0)."""
        x = np.asarray(x, dtype=float)
        with np.errstate(all="ignore"):
            fitted = self.dist.logpdf(x, **self.fitted)
            return self.dist.logpdf(x[:, None], **{k: v[None, :] for k, v in self.draws.items()}) - fitted[:, None]

    def normal_scores(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(ẑ [len(x)], z* [len(x), draws])``: Φ⁻¹ of the fitted and the drawn CDFs at ``x`` (the copula's scores)."""
        x = np.asarray(x, dtype=float)
        clip = lambda u: np.clip(u, 2.0 ** -53, 1.0 - 2.0 ** -53)  # noqa: E731
        z = stats.norm.ppf(clip(self.dist.cdf(x, **self.fitted)))
        zs = stats.norm.ppf(clip(self.dist.cdf(x[:, None], **{k: v[None, :] for k, v in self.draws.items()})))
        return z, zs

    def outside_support(self) -> np.ndarray:
        """Per draw, the probability it puts outside the fitted law's support (where no sample was drawn)."""
        lo, hi = self.dist.support(**self.fitted)
        d = {k: v for k, v in self.draws.items()}
        out = np.zeros(self.n_draws)
        if math.isfinite(lo):
            out += self.dist.cdf(lo, **d)
        if math.isfinite(hi):
            out += self.dist.sf(hi, **d)
        return out


def law_draws(factor: str, measured, draws: int = DRAWS, rng: np.random.Generator | None = None) -> Laws:
    """The :class:`Laws` of a measured factor fitted by family (``measured``: its
    :class:`rvtol.inputs.measured.factor.Measured` record, ``method = "fit"``), from ``draws`` parametric bootstrap
    refits."""
    rep = measured.fit
    c = rep.candidate(measured.family)
    family, fitted = c.family, dict(c.params)
    dist, positive = FAMILIES[family]
    n = int(rep.data.size)
    g = rng if rng is not None else np.random.default_rng()
    u = measured.measurement_sigma
    sims = c.frozen.rvs(size=(draws, n), random_state=g)
    if u:
        sims = sims + g.normal(0.0, u, size=sims.shape)
    failed = 0
    refits = None if u else _closed_form_refits(sims, family, rep.location)
    if refits is None:
        refits = []
        for x in sims:
            try:
                if u:
                    x = deconvolve(x, u)[0]
                refits.append(_refit(x, family, rep.location, fitted))
            except InputError:    # a resample the family cannot be fitted to (or the gauge cannot resolve)
                failed += 1
    if len(refits) < draws // 2:
        raise InputError(f"factor {factor!r}: its {family} law could be refitted to only {len(refits)} of {draws} "
                         "bootstrap samples: its uncertainty cannot be estimated")
    pivotal = family in _PIVOTAL and (family not in _POSITIVE_PIVOTAL or rep.location is not None)
    if pivotal:
        to_ab, from_ab = _PIVOTAL[family]
        a0, b0 = to_ab(fitted)
        ab = np.array([to_ab(p) for p in refits])
        b = b0 * b0 / ab[:, 1]
        a = a0 - b0 * (ab[:, 0] - a0) / ab[:, 1]
        new = from_ab(a, b, fitted)
        params = {k: np.broadcast_to(np.asarray(new[k], dtype=float), (len(refits),)).copy() for k in fitted}
        method = "pivotal"
    else:
        fixed = {"loc"} if positive and rep.location is not None else set()
        real = set(_REAL_SHAPES.get(family, ())) | {"loc"}
        params = {}
        for k, v0 in fitted.items():
            v = np.array([p[k] for p in refits])
            if k in fixed:
                params[k] = np.full(len(refits), v0)
            elif k in real:
                params[k] = 2.0 * v0 - v
            else:
                params[k] = np.exp(2.0 * math.log(v0) - np.log(v))
        method = "reflected bootstrap"
    values = np.asarray(measured.values, dtype=float)
    return Laws(factor, family, fitted, params, method, n, (float(values.min()), float(values.max())), failed)


def _closed_form_refits(sims: np.ndarray, family: str, location: float | None) -> list[dict] | None:
    """The maximum-likelihood refits of every bootstrap sample (rows of ``sims``) at once where the MLE has a closed
    form — normal: (x̄, √(Σ(x − x̄)²/n)); lognormal with its location x₀ fixed: the same of ln(x − x₀) — as
    ``scipy.stats`` ``fit`` computes them (:func:`rvtol.inputs.measured.parametric.fit_family`); None for other families."""
    if family == "normal":
        return [{"loc": float(m), "scale": float(s)} for m, s in zip(sims.mean(axis=1), sims.std(axis=1))]
    if family == "lognormal" and location is not None and np.all(sims > location):
        t = np.log(sims - location)
        return [{"s": float(s), "loc": float(location), "scale": float(math.exp(m))}
                for m, s in zip(t.mean(axis=1), t.std(axis=1))]
    return None


def _refit(x: np.ndarray, family: str, location: float | None, start: dict) -> dict:
    """The fit's own maximum likelihood (:func:`rvtol.inputs.measured.parametric.fit_family`) on a bootstrap sample — for a
    Weibull with its location fixed, as the smallest-extreme-value law of ln(x − x₀) (``scipy.stats.gumbel_l``:
    the two likelihoods differ by the Jacobian Σ ln(x − x₀), free of the parameters, so the maxima coincide; ten
    times faster than scipy's Weibull fit)."""
    if family != "weibull" or location is None:
        return fit_family(x, family, location, start=start)[0]
    if not np.all(x > location):
        raise InputError(f"needs every value above its location {location:g}")
    with np.errstate(all="ignore"):
        a, b = stats.gumbel_l.fit(np.log(x - location), loc=math.log(start["scale"]), scale=1.0 / start["c"])
    if not (math.isfinite(a) and math.isfinite(b) and b > 0):
        raise InputError("fit failed")
    return {"c": 1.0 / b, "loc": float(location), "scale": math.exp(a)}


# ----------------------------------------------------------------------------- the study's measured factors
@dataclass
class MeasuredFactors:
    """The measured factors of a Monte Carlo: those fitted by family (their column and unit), the others by method,
    which outputs depend on which (None: every output on every factor), and the spec (its correlation)."""

    fitted: list[tuple[int, str, str, object, str]]  # (column, name, unit, Measured, label: a family's template)
    unfitted: list[tuple[str, str, int, str]]        # (name, method, measured values, label)
    dependencies: dict | None
    spec: object

    @classmethod
    def of(cls, spec, model=None) -> "MeasuredFactors | None":
        """The measured factors of ``spec`` (None when it has none); a fitted factor whose distribution is no longer
        its fitted law (a scaled copy) counts as not fitted."""
        from .model import dependencies

        fitted, unfitted = [], []
        for j, f in enumerate(spec.factors):
            m = f.measured
            if m is None:
                continue
            if m.fit is not None and _is_fitted_law(f.dist, m):
                fitted.append((j, f.name, f.unit, m, f.family or f.name))
            else:
                unfitted.append((f.name, m.method if m.fit is None else "fit, rescaled", m.n, f.family or f.name))
        if not fitted and not unfitted:
            return None
        return cls(fitted, unfitted, dependencies(model) if model is not None else None, spec)

    def used_by(self, output: str) -> tuple[list, list]:
        """The fitted factors ``output`` can depend on, and the other measured ones as ``(label, method, values)``
        (a family once)."""
        deps = None if self.dependencies is None else self.dependencies.get(output)
        keep = (lambda name: True) if deps is None else (lambda name: name in deps)
        other = {f[3]: (f[3], f[1], f[2]) for f in self.unfitted if keep(f[0])}
        return [f for f in self.fitted if keep(f[1])], list(other.values())


def _is_fitted_law(dist, m) -> bool:
    """Whether ``dist`` is the law ``m``'s fit chose (not, e.g., an allocation's scaled copy of it)."""
    c = m.fit.candidate(m.family)
    q = np.quantile(m.fit.data, [0.1, 0.5, 0.9])
    try:
        return bool(np.allclose(np.asarray(dist.cdf(q), dtype=float), c.frozen.cdf(q), rtol=1e-9, atol=1e-12))
    except Exception:   # a distribution without a cdf cannot be the fitted one
        return False


# ----------------------------------------------------------------------------- one requirement's figures
@dataclass
class FitEffect:
    """What the measured factors' fitted laws leave uncertain in one requirement (module docstring): the yield and the
    judged Cpk under each drawn law, the fit's one-sided deviations at the requirement's level, the share of the
    non-conformance beyond each factor's measured values, and the notes the verdict carries."""

    laws: list[Laws]
    level: float                                   # the one-sided level of the requirement's bound
    yield_estimate: float
    yield_draws: np.ndarray
    cpk_centre: float | None = None                # the judged Cpk on the subsample, unweighted
    cpk_draws: np.ndarray | None = None
    ess_draws: np.ndarray | None = None            # each draw's effective sample size (fraction of the subsample)
    beyond: dict = field(default_factory=dict)     # factor -> (share beyond its data, "above"/"below", the limit value)
    out: int = 0                                   # samples outside the limits (failed ones included)
    unfitted: list = field(default_factory=list)   # (name, method, n) of measured factors not carried
    unavailable: list = field(default_factory=list)    # (name, why) of fitted factors whose draws failed
    notes: list[str] = field(default_factory=list)

    @property
    def ess(self) -> float:
        """The smallest effective sample size over the draws (a fraction of the samples it is estimated on)."""
        return 1.0 if self.ess_draws is None or not self.ess_draws.size else float(np.min(self.ess_draws))

    @property
    def parts(self) -> dict[str, int]:
        return {law.factor: law.parts for law in self.laws}

    @property
    def yield_dev(self) -> float:
        """The fit's one-sided deviation of the yield at the bound's level: p̂ − the (1 − ℓ) quantile over the draws."""
        if not self.laws:
            return 0.0
        return max(0.0, self.yield_estimate - float(np.quantile(self.yield_draws, 1.0 - self.level)))

    @property
    def cpk_dev(self) -> float:
        if self.cpk_draws is None or self.cpk_centre is None or not np.isfinite(self.cpk_draws).any():
            return 0.0
        return max(0.0, self.cpk_centre - float(np.nanquantile(self.cpk_draws, 1.0 - self.level)))

    def yield_interval(self, confidence: float) -> tuple[float, float]:
        a = 0.5 * (1.0 - confidence)
        return float(np.quantile(self.yield_draws, a)), float(np.quantile(self.yield_draws, 1.0 - a))

    def cpk_interval(self, confidence: float) -> tuple[float | None, float | None]:
        if self.cpk_draws is None or not np.isfinite(self.cpk_draws).any():
            return None, None
        a = 0.5 * (1.0 - confidence)
        return float(np.nanquantile(self.cpk_draws, a)), float(np.nanquantile(self.cpk_draws, 1.0 - a))

    def describe(self, confidence: float, yield_bound: float | None, mc_bound: float | None) -> None:
        """Fill :attr:`notes`: the fit's interval beside the bound judged, where the data end, the weights' quality."""
        self.notes = []
        if self.laws:
            names = ", ".join(f"{law.factor} ({law.family}, {law.parts} parts)" for law in self.laws)
            lo, hi = self.yield_interval(confidence)
            self.notes.append(
                f"fitted to measured parts: {names}; under the laws these data allow ({self.laws[0].n_draws} draws) "
                f"the yield spans [{lo:.5f}, {hi:.5f}] ({100 * confidence:.4g} % two-sided: "
                f"{(1 - hi) * 1e6:,.0f}–{(1 - lo) * 1e6:,.0f} ppm out) — the yield bound judged, {_f(yield_bound)}, "
                f"carries it (the Monte Carlo's alone: {_f(mc_bound)})")
            for law in self.laws:
                share, side, edge = self.beyond.get(law.factor, (0.0, "", None))
                if share >= EXTRAPOLATED:
                    self.notes.append(
                        f"the limit lies beyond the measured data: {100 * share:.0f} % of the non-conforming samples "
                        f"have {law.factor} {side} {edge:.6g} {unit_label(law.unit)}, the "
                        f"{'largest' if side == 'above' else 'smallest'} of its "
                        f"{law.parts} measured values — there the yield is the fitted {law.family} tail, extrapolated")
            if self.out == 0:
                self.notes.append("no sample lies outside the limits: how the fitted laws' uncertainty moves the yield "
                                  "cannot be seen in these samples (it is not in the bound)")
            if self.ess < LOW_ESS:
                self.notes.append(f"the draws' weights are uneven (effective sample size down to {100 * self.ess:.0f} "
                                  "% of the samples): the fit's spread is itself uncertain")
        for name, method, n in self.unfitted:
            self.notes.append(f"{name} is taken from {n} measured values by {method}: the uncertainty of so few parts, "
                              "and any tail beyond them, is not in the bound")


def _f(v) -> str:
    return "n/a" if v is None else f"{v:.5f}"


def effects(mf: MeasuredFactors, values: np.ndarray, Y: np.ndarray, ok: np.ndarray, output_names, requirements,
            levels, seed: int | None) -> dict:
    """Requirement label -> :class:`FitEffect` (None for a requirement no measured factor moves).

    ``values``: the samples (base units, one column per factor of ``mf.spec``); ``Y`` the outputs in the
    requirements' units with ``ok`` the evaluated rows; ``levels``: each requirement's one-sided level."""
    from . import units
    from .sampling import substream

    N = len(ok)
    laws: dict[str, Laws] = {}
    columns: dict[str, np.ndarray] = {}
    unavailable: dict[str, str] = {}
    drawn: dict[int, Laws | str] = {}     # one set of laws per measured data set: a family's copies share it
    for i, (j, name, unit, m, label) in enumerate(mf.fitted):
        if id(m) not in drawn:
            try:
                drawn[id(m)] = law_draws(label, m, DRAWS, substream(seed, "fit_uncertainty", 0, i))
                drawn[id(m)].unit = unit
            except InputError as exc:   # its uncertainty cannot be estimated: the verdict says so, nothing passes on it
                drawn[id(m)] = exc.reason
        if isinstance(drawn[id(m)], str):
            unavailable[name] = drawn[id(m)]
        else:
            laws[name] = drawn[id(m)]
        columns[name] = np.asarray(units.from_base(values[:, j], unit), dtype=float)
    size = SUBSAMPLE if any(r.min_cpk is not None for r in requirements) else ESS_SUBSAMPLE
    sub = np.arange(N) if N <= size else np.sort(substream(seed, "fit_uncertainty", 1).choice(N, size, replace=False))
    weights = _Weights(mf, laws, columns, values)
    out = {}
    for r, level in zip(requirements, levels):
        used, unfitted = mf.used_by(r.output)
        if not used and not unfitted:
            out[r.label] = None
            continue
        missing = list({f[4]: (f[4], unavailable[f[1]]) for f in used if f[1] in unavailable}.values())
        names = [f[1] for f in used if f[1] not in unavailable]
        if not names:
            out[r.label] = FitEffect([], level, math.nan, np.array([]), unfitted=unfitted, unavailable=missing)
            continue
        y = Y[:, list(output_names).index(r.output)]
        inside = ok.copy()
        if r.lower is not None:
            inside &= np.nan_to_num(y, nan=-np.inf) >= r.lower
        if r.upper is not None:
            inside &= np.nan_to_num(y, nan=np.inf) <= r.upper
        n_out = int(N - inside.sum())
        miss = 1.0 - np.prod([1.0 - laws[n].outside_support() for n in names], axis=0)
        if n_out <= N // 2:
            yields = 1.0 - miss - weights.sum(names, np.flatnonzero(~inside)) / N
        else:
            yields = weights.sum(names, np.flatnonzero(inside)) / N
        distinct = list({id(laws[n]): laws[n] for n in names}.values())
        e = FitEffect(distinct, level, float(inside.sum()) / N, yields, out=n_out, unfitted=unfitted,
                      unavailable=missing)
        w = weights.at(names, sub)
        e.ess_draws = w.sum(axis=0) ** 2 / np.maximum((w * w).sum(axis=0), 1e-300) / len(sub)
        if r.min_cpk is not None:
            good = ok[sub]
            e.cpk_centre, e.cpk_draws = _cpk_draws(r, y[sub][good], w[good])
        for n in names:                 # a family: its copy most often beyond the data
            x = columns[n][~inside]
            lo, hi = laws[n].data_range
            above, below = (float(np.mean(x > hi)), float(np.mean(x < lo))) if x.size else (0.0, 0.0)
            share = (above, "above", hi) if above >= below else (below, "below", lo)
            if share[0] >= e.beyond.get(laws[n].factor, (-1.0,))[0]:
                e.beyond[laws[n].factor] = share
        out[r.label] = e
    return out


class _Weights:
    """The likelihood ratios of the drawn laws at chosen samples (module docstring), in blocks of points."""

    def __init__(self, mf: MeasuredFactors, laws: dict, columns: dict, values: np.ndarray):
        self.laws, self.columns, self.values, self.spec = laws, columns, values, mf.spec
        self.index = {name: j for j, name, *_ in mf.fitted}

    def _log(self, names: list[str], rows: np.ndarray) -> np.ndarray:
        lw = sum(self.laws[n].log_ratio(self.columns[n][rows]) for n in names)
        R = self.spec.correlation
        if R is not None:
            lw = lw + self._copula(names, rows, np.asarray(R, dtype=float))
        return lw

    def _copula(self, names: list[str], rows: np.ndarray, R: np.ndarray) -> np.ndarray:
        """ln c(u*) − ln c(û) of the Gaussian copula: −½ (2 δᵀQẑ + δᵀQδ), Q = R⁻¹ − I, δ = z* − ẑ on the measured
        factors' scores (the others' do not change)."""
        from . import units

        Q = np.linalg.inv(R) - np.eye(len(R))
        m = [self.index[n] for n in names]
        if not np.any(np.abs(Q[m]) > 1e-12):
            return 0.0
        J = np.flatnonzero(np.any(np.abs(Q[m]) > 1e-12, axis=0))
        zhat = np.zeros((len(rows), len(R)))
        for j in J:
            f = self.spec.factors[j]
            if j in m:
                continue
            u = np.asarray(f.dist.cdf(units.from_base(self.values[rows, j], f.unit)), dtype=float)
            zhat[:, j] = stats.norm.ppf(np.clip(u, 2.0 ** -53, 1.0 - 2.0 ** -53))
        deltas = {}
        for n, j in zip(names, m):
            zhat[:, j], zs = self.laws[n].normal_scores(self.columns[n][rows])
            deltas[j] = zs - zhat[:, j][:, None]
        Qz = zhat @ Q.T                                     # [rows, k]
        out = 0.0
        for j, d in deltas.items():
            out = out + 2.0 * d * Qz[:, j][:, None]
            for j2, d2 in deltas.items():
                out = out + d * Q[j, j2] * d2
        return -0.5 * out

    def at(self, names: list[str], rows: np.ndarray) -> np.ndarray:
        """The weights p*(x)/p̂(x) of ``rows`` under each draw. Every sample was drawn from the fitted law, so p̂(x) > 0
        and a draw whose support misses x gives exactly 0 (ln 0 − ln p̂ = −inf); a NaN or +inf can only come from a
        sample on the fitted law's support boundary where its density rounds to 0 (−inf − −inf, finite − −inf) —
        a point that law cannot draw, weighted 0 like one outside."""
        with np.errstate(all="ignore"):
            return np.nan_to_num(np.exp(self._log(names, rows)), nan=0.0, posinf=0.0)

    def sum(self, names: list[str], rows: np.ndarray) -> np.ndarray:
        """Per draw, Σ w over ``rows``, a block at a time."""
        draws = self.laws[names[0]].n_draws
        total = np.zeros(draws)
        step = max(1, _BLOCK // draws)
        for a in range(0, len(rows), step):
            total += self.at(names, rows[a:a + step]).sum(axis=0)
        return total


def _cpk_draws(r, y: np.ndarray, w: np.ndarray) -> tuple[float | None, np.ndarray | None]:
    """The judged Cpk of ``r`` on the evaluated subsample ``y``: unweighted, and under each draw's weights ``w``."""
    from .stats import CPK_QUANTILES, _cpk_from_quantiles

    if y.size < 2 or not np.ptp(y) > 0:
        return None, None
    ones = np.ones((y.size, 1))
    if r.cpk_method == "percentile":
        order = np.argsort(y)
        ys = y[order]

        def cpk(wt):
            cum = np.cumsum(wt[order], axis=0)
            cum /= cum[-1]
            q = [ys[np.minimum(np.argmax(cum >= p, axis=0), ys.size - 1)] for p in CPK_QUANTILES]
            return _cpk_from_quantiles(*q, r.lower, r.upper)
    else:
        def cpk(wt):
            tot = wt.sum(axis=0)
            mu = (wt * y[:, None]).sum(axis=0) / tot
            sd = np.sqrt(np.maximum((wt * (y[:, None] - mu) ** 2).sum(axis=0) / tot, 0.0))
            sides = [(r.upper - mu) / (3 * sd)] if r.upper is not None else []
            sides += [(mu - r.lower) / (3 * sd)] if r.lower is not None else []
            with np.errstate(all="ignore"):
                return np.min(sides, axis=0)
    centre = float(cpk(ones)[0])
    return (centre if math.isfinite(centre) else None), np.asarray(cpk(w), dtype=float)


def to_record(e: FitEffect, confidence: float, mc_yield_bound: float | None, mc_cpk_bound: float | None) -> dict:
    """summary.json's record of a requirement's fit uncertainty."""
    lo, hi = e.yield_interval(confidence) if e.laws else (None, None)
    clo, chi = e.cpk_interval(confidence)
    return {
        "factors": {law.factor: {"family": law.family, "parts": law.parts, "draws": law.n_draws, "method": law.method,
                                 "failed_refits": law.failed, "measured_range": list(law.data_range),
                                 "beyond_data": e.beyond.get(law.factor, (0.0,))[0]} for law in e.laws},
        "not_carried": [{"factor": n, "method": m, "values": k} for n, m, k in e.unfitted],
        "unavailable": [{"factor": n, "reason": why} for n, why in e.unavailable],
        "confidence": confidence,
        "yield_interval": [lo, hi], "ppm_interval": [None if hi is None else (1 - hi) * 1e6,
                                                     None if lo is None else (1 - lo) * 1e6],
        "yield_deviation": e.yield_dev if e.laws else None, "yield_bound_monte_carlo": mc_yield_bound,
        "cpk_interval": [clo, chi], "cpk_deviation": e.cpk_dev if e.cpk_draws is not None else None,
        "cpk_bound_monte_carlo": mc_cpk_bound,
        "effective_sample_size": e.ess if e.laws else None,
    }

