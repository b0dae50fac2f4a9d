"""Sub-ppm tail probabilities where Monte Carlo cannot demonstrate them, by OpenTURNS' reliability methods.

A Monte Carlo run of n samples that sees no part beyond a limit only bounds the probability (below
≈ 3/n at 95 %); a requirement of 1 ppm needs millions of samples to be *shown*.  Reliability
methods estimate the tail itself.  rvtol hands them to OpenTURNS (the field's library), on the
study's own probability model: the factors are written as functions of independent standard normals
u through the study's sampling transform (Gaussian copula: x_i = F_i⁻¹(Φ((L u)_i)), L the Cholesky
factor of the spec's correlation, :func:`rvtol.sampling.from_normal_scores`), so the standard space
OpenTURNS works in is exactly the one the Monte Carlo draws from, for every distribution kind.  The
event is y > limit (``side="upper"``) or y < limit.

=================  ===========================================================================  ===========
method             what it gives                                                                error
=================  ===========================================================================  ===========
FORM               the most probable failure point u* (nearest point of the limit state to the   none stated
                   origin; ``ot.AbdoRackwitz``, or ``ot.Cobyla`` — derivative-free — where the
                   gradient vanishes, e.g. a radius at a centred zone), β = |u*|, P ≈ Φ(−β):
                   exact for a linear output of normal factors
SORM               FORM corrected by the limit state's curvatures at u* (Breitung 1984; Tvedt    none stated
                   and Hohenbichler in the record): undefined where a curvature is ≤ −1/β (a
                   circle around the origin: every direction fails alike)
multi-FORM         several design points found one after another (``ot.MultiFORM``, deflation),  none stated
                   the probability of their union of half-spaces: a failure domain with
                   several directions of failure
importance         N samples of N(u*, I) weighted by φ(u)/φ(u − u*) (``ot.ImportanceSampling-   s.e.
sampling           Experiment``): unbiased, but its error estimate is blind to failure regions
                   far from u*
subset             Au & Beck (2001): a chain of conditional levels p₀ = 0.1 by Markov chain     s.e. (c.o.v.)
simulation         Monte Carlo (``ot.SubsetSampling``): any shape, any number of design points
directional        random directions in u-space, the failure distance on each by root finding,  s.e.
sampling           χ² tail along it (Bjerager 1988; ``ot.DirectionalSampling``): exact for a
                   failure domain outside a sphere about the origin
=================  ===========================================================================  ===========

An estimate that is no estimate is shown as "not estimated: <why>" and enters no comparison: a method that
could not run or found no design point; a probability outside [0, 1]; a sampling estimate whose standard
error is negative, NaN or 0 (OpenTURNS' directional sampling returns 0 ± −1 when no direction reaches the
limit; a weighted estimate with no spread has no error to state), that saw no failure (0 bounds P, it does
not estimate it), or whose coefficient of variation exceeds ``MAX_COV`` = 1/3 (its ±3 standard errors, the
rule the estimates are compared by, reach 0: it cannot tell P from 0); and a SORM or multi-FORM value above
P(χ²ₖ > β²), the probability of the whole space beyond the sphere of radius β about the origin — a failure
domain whose nearest point lies at β holds no more (Breitung's formula blows up as a curvature nears −1/β;
a curvature ≤ −1/β leaves it undefined).

The estimates are compared: two sampling estimates **disagree** when they differ by more than three
of their combined standard errors; FORM / SORM / multi-FORM (approximations without an error) when
they lie outside three standard errors of the reference.  Of two disagreeing sampling estimates the
less robust one is suspect — importance sampling about one design point, whose standard error cannot
see failure regions far from it, before subset or directional simulation, which explore the whole
space (two of those disagreeing: both).  The **reference** — the tail's best estimate — is the
sampling estimate with the smallest coefficient of variation that is not suspect; each disagreement
is listed.  All of them are *estimates* from the
distributions (their tails extrapolated, not measured): **the verdict stays the Monte Carlo's** (unless the study
asks the tails to decide what it leaves undecided, cross-checked against it: :mod:`rvtol.tail_decision`)
(:mod:`rvtol.verdict`), which the report says beside them.

Samples the model cannot evaluate count as failures (as in the yield) and are reported.
Distributions with bounded support (uniform, triangular, truncated normal) cannot reach a limit
beyond their worst case: then no point of the limit state exists, β = ∞ and P = 0 — decided on the
corners of the supports, u = ±``REACH`` (Φ(−8.3) = 5·10⁻¹⁷: every bounded margin at its end to
double precision), not on a wider or narrower box.

References.  A. M. Hasofer and N. C. Lind, J. Eng. Mech. Div. ASCE 100 (1974) 111–121 (FORM);
K. Breitung, "Asymptotic approximations for multinormal integrals", J. Eng. Mech. 110 (1984) 357–366
(SORM); S.-K. Au and J. L. Beck, "Estimation of small failure probabilities in high dimensions by
subset simulation", Prob. Eng. Mech. 16 (2001) 263–277; P. Bjerager, "Probability integration by
directional simulation", J. Eng. Mech. 114 (1988) 1285–1302; R. E. Melchers, "Importance sampling in
structural systems", Structural Safety 6 (1989) 3–10; M. Baudin et al., "OpenTURNS: an industrial
software for uncertainty quantification in simulation", Handbook of Uncertainty Quantification,
Springer 2017.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from .. import units
from ..mc import Evaluator
from ..model import STATUS_OK, Model
from ..sampling import from_normal_scores, substream_seed
from ..spec import ToleranceSpec
from . import notes as N

METHODS = ("FORM", "SORM", "multi-FORM", "importance sampling", "subset", "directional")
#: the approximations (no error of their own)
APPROXIMATIONS = ("FORM", "SORM", "multi-FORM")
#: two estimates disagree beyond this many combined standard errors
DISAGREE_SE = 3.0
#: which of two disagreeing sampling estimates is the suspect: importance sampling about one design point is
#: blind to failure regions far from it (its standard error does not see them); subset and directional
#: simulation explore the whole space
ROBUSTNESS = {"importance sampling": 0, "directional": 1, "subset": 1}
#: the largest coefficient of variation of a sampling estimate: beyond it the estimate's ±DISAGREE_SE standard
#: errors reach 0 (it cannot tell P from 0 by the rule the estimates are compared by)
MAX_COV = 1.0 / DISAGREE_SE
#: the normal score of a bounded support's end for the out-of-reach test: Φ(−REACH) = 5e-17, below the last bit
#: of 1 in double precision, so every bounded margin's inverse CDF is at its end
REACH = 8.3


@dataclass
class Estimate:
    """One method's estimate of the tail probability."""

    method: str
    pf: float | None
    se: float | None = None          # standard error (sampling methods)
    evaluations: int = 0
    note: str = ""
    beta: float | None = None        # the nearest design point's distance (multi-FORM's; None: FORM's)

    @property
    def cov(self) -> float | None:
        if self.se is None or not self.pf:
            return None
        return self.se / self.pf

    def to_dict(self) -> dict:
        return {"method": self.method, "pf": self.pf, "ppm": None if self.pf is None else 1e6 * self.pf,
                "se": self.se, "ppm_se": None if self.se is None else 1e6 * self.se, "cov": self.cov,
                "evaluations": self.evaluations, "note": self.note}


@dataclass
class TailEstimate:
    """Every method's estimate of P(output beyond one limit), their agreement and the reference."""

    output: str
    unit: str                 # display unit of the limit
    side: str                 # "upper" | "lower"
    limit: float              # display units
    estimates: list = field(default_factory=list)
    beta: float | None = None
    converged: bool = False
    x_star: dict = field(default_factory=dict)        # factor -> value (its unit) at the most probable failure point
    design_points: list = field(default_factory=list)  # multi-FORM: [{factor: value}, ...]
    reference: str | None = None
    disagreements: list = field(default_factory=list)
    failed_samples: int = 0
    evaluations: int = 0
    notes: list[str] = field(default_factory=list)

    def get(self, method: str) -> Estimate | None:
        return next((e for e in self.estimates if e.method == method), None)

    def _pf(self, method):
        e = self.get(method)
        return None if e is None else e.pf

    @property
    def pf_form(self) -> float | None:
        return self._pf("FORM")

    @property
    def ppm_form(self) -> float | None:
        return None if self.pf_form is None else 1e6 * self.pf_form

    @property
    def pf_reference(self) -> float | None:
        return None if self.reference is None else self._pf(self.reference)

    def to_dict(self) -> dict:
        imp = self.get("importance sampling")
        return {"output": self.output, "unit": self.unit, "side": self.side, "limit": self.limit, "beta": self.beta,
                "pf_form": self.pf_form, "ppm_form": self.ppm_form, "form_converged": self.converged,
                "most_probable_failure_point": self.x_star, "design_points": self.design_points,
                "pf_importance_sampling": None if imp is None else imp.pf,
                "pf_importance_sampling_se": None if imp is None else imp.se,
                "estimates": [e.to_dict() for e in self.estimates], "reference": self.reference,
                "pf_reference": self.pf_reference, "disagreements": self.disagreements,
                "failed_samples": self.failed_samples, "evaluations": self.evaluations, "notes": self.notes}


class _Limit:
    """The output as a function of standard normals u (OpenTURNS function), evaluated in batches."""

    def __init__(self, model: Model, spec: ToleranceSpec, output: str, limit_base: float, side: str, evaluate):
        self.model, self.spec, self.side, self.limit = model, spec, side, limit_base
        self.j = model.output_index(output)
        self.evaluate = evaluate
        # a serial evaluator without a store or a cache: the model is called once per batch — the evaluator's
        # chunks, progress bar and clock cost more than the reliability methods' small batches of a cheap model
        self.direct = (getattr(evaluate, "workers", 0) == 1 and getattr(evaluate, "store", True) is None
                       and getattr(evaluate, "cache", True) is None)
        self.count = 0
        self.failed = 0
        # a value that lies beyond the limit: failed evaluations count as failures
        self.beyond = limit_base + (1.0 if side == "upper" else -1.0) * (abs(limit_base) + 1.0)

    def y(self, U) -> np.ndarray:
        U = np.atleast_2d(np.asarray(U, dtype=float))
        self.count += len(U)
        X = from_normal_scores(self.spec, U)
        if self.direct:
            Y, status = self.model.evaluate_with_status(self.model.check_input(X))
            ok = np.asarray(status) == STATUS_OK
        else:
            ev = self.evaluate(self.model, X, "tail estimate")
            Y, ok = ev.Y, ev.ok
        y = np.where(ok, np.asarray(Y, dtype=float)[:, self.j], np.nan)
        bad = ~np.isfinite(y)
        self.failed += int(bad.sum())
        return np.where(bad, self.beyond, y)

    def event(self):
        import openturns as ot

        k = len(self.spec)
        f = ot.PythonFunction(k, 1, func_sample=lambda U: self.y(U)[:, None])
        vec = ot.CompositeRandomVector(f, ot.RandomVector(ot.Normal(k)))
        return ot.ThresholdEvent(vec, ot.Greater() if self.side == "upper" else ot.Less(), self.limit)


def tail_probability(model: Model, spec: ToleranceSpec, output: str, limit: float, side: str = "upper",
                     evaluate: Evaluator | None = None, *, samples: int = 4000, seed: int | None = None,
                     key: int = 0, methods=METHODS, design_points: int = 4) -> TailEstimate:
    """P(``output`` > ``limit``) (``side="upper"``) or P(output < limit) by the ``methods`` of the module docstring;
    ``limit`` in the output's display unit.  ``samples``: the model evaluations of each sampling method (importance
    sampling: N; subset simulation: about N per level; directional sampling: N/20 directions); ``seed``, ``key``:
    OpenTURNS' generator is seeded per method from the named sub-stream ``stacking_tail`` of ``seed`` (key: the method) (the result
    is the same for a seed); ``design_points``: the most multi-FORM looks for."""
    import openturns as ot

    ot.Log.Show(ot.Log.NONE)
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise ValueError(f"unknown tail methods {unknown} (known: {', '.join(METHODS)})")
    evaluate = evaluate or Evaluator()
    q = model.output(output)
    lim = float(units.convert(limit, q.shown_unit, q.unit))
    ls = _Limit(model, spec, output, lim, side, evaluate)
    est = TailEstimate(output, q.shown_unit, side, float(limit))
    k = len(spec)
    event = ls.event()
    beyond = (lambda y: y > lim) if side == "upper" else (lambda y: y < lim)  # noqa: E731
    y0 = ls.y(np.zeros((1, k)))[0]
    u_star = None

    def counted(method, fn):
        c0 = ls.count
        try:
            e = fn()
        except Exception as exc:   # OpenTURNS reports a method that cannot run as an exception: say why
            e = Estimate(method, None, note=_reason(exc))
        why = None if e.pf is None else _not_an_estimate(e, k, est.beta)
        if why is not None:
            e = Estimate(method, None, note=why)
        if e.pf is None:
            e.note = N.NOT_ESTIMATED.format(why=e.note or "no result")
        e.evaluations = ls.count - c0
        est.estimates.append(e)
        return e

    def seed_for(i):
        ot.RandomGenerator.SetSeed(substream_seed(seed, "stacking_tail", key, i))

    # FORM: Abdo-Rackwitz (gradient), Cobyla where the gradient vanishes or the solver fails
    form_result = None
    if any(m in methods for m in APPROXIMATIONS + ("importance sampling",)):
        def run_form():
            nonlocal form_result, u_star
            if beyond(y0):
                est.notes.append(N.NOMINAL_FAILS)
            # where the gradient vanishes at the origin (a radius at a centred zone), Abdo-Rackwitz from a point off
            # it, then Cobyla, which stops on a constraint tolerance of its own (1e-4 of the limit)
            for solver, start in ((ot.AbdoRackwitz(), [0.0] * k), (ot.AbdoRackwitz(), [0.1] * k),
                                  (ot.Cobyla(), [0.0] * k), (ot.Cobyla(), [0.1] * k)):
                try:
                    algo = ot.FORM(solver, event, start)
                    algo.run()
                except Exception:
                    continue
                r = algo.getResult()
                u = np.array(r.getStandardSpaceDesignPoint())
                g = ls.y(u[None])[0]
                if abs(g - lim) <= 1e-6 * (abs(lim) + abs(y0 - lim)) + 1e-12:
                    form_result, u_star = r, u
                    note = "" if isinstance(solver, ot.AbdoRackwitz) else N.FORM_COBYLA
                    est.converged = True
                    beta = float(np.linalg.norm(u)) * (-1.0 if beyond(y0) else 1.0)
                    est.beta = beta
                    return Estimate("FORM", float(r.getEventProbability()), note=note)
            if _out_of_reach(spec, ls, beyond):
                est.beta = math.inf
                return Estimate("FORM", 0.0, note=N.FORM_OUT_OF_REACH)
            return Estimate("FORM", None, note=N.FORM_NONE)
        if "FORM" in methods or "SORM" in methods or "importance sampling" in methods:
            counted("FORM", run_form) if "FORM" in methods else run_form()
    if u_star is not None:
        xs = from_normal_scores(spec, u_star[None])[0]
        est.x_star = {f.name: float(units.from_base(xs[i], f.unit)) for i, f in enumerate(spec.factors)}
    reachable = u_star is not None
    if "SORM" in methods and reachable:
        counted("SORM", lambda: _sorm(ot, event, u_star, est.beta))
    if "multi-FORM" in methods and reachable:
        counted("multi-FORM", lambda: _multi_form(ot, event, u_star, spec, design_points, est))
    block = 100
    outer = max(1, samples // block)
    if "importance sampling" in methods:
        counted("importance sampling", lambda: _importance(ot, event, u_star if reachable else None, k, outer, block,
                                                           lambda: seed_for(1)))
    if "subset" in methods:
        counted("subset", lambda: _subset(ot, event, samples, block, lambda: seed_for(2)))
    if "directional" in methods:
        counted("directional", lambda: _directional(ot, event, samples, block, lambda: seed_for(3)))
    _compare(est)
    est.failed_samples = ls.failed
    est.evaluations = ls.count
    if ls.failed:
        est.notes.append(N.FAILED_EVALUATIONS.format(n=ls.failed))
    return est


def _sorm(ot, event, u_star: np.ndarray, beta_form: float) -> Estimate:
    """SORM (Breitung) from the FORM design point ``u_star`` (Hasofer-Lind index ``beta_form``), Tvedt's and
    Hohenbichler's beside it."""
    # from the FORM design point, by Abdo–Rackwitz (one step: u* is already the point), Cobyla where it
    # fails; Cobyla alone wanders off the point in many dimensions (50 factors: no result)
    r = None
    for solver in (ot.AbdoRackwitz(), ot.Cobyla()):
        try:
            algo = ot.SORM(solver, event, list(u_star))
            algo.run()
        except Exception as exc:
            error = exc
            continue
        r = algo.getResult()
        if np.allclose(np.array(r.getStandardSpaceDesignPoint()), u_star, rtol=1e-4,
                       atol=1e-4 * max(1.0, abs(beta_form))):
            break
    if r is None:
        raise error
    pb = float(r.getEventProbabilityBreitung())
    beta = float(r.getHasoferReliabilityIndex())
    if not math.isfinite(pb) or any(1.0 + beta * float(c) <= 0.0 for c in r.getSortedCurvatures()):
        return Estimate("SORM", None, note=N.SORM_UNDEFINED)
    extra = []
    for name, get in (("Tvedt", r.getEventProbabilityTvedt), ("Hohenbichler", r.getEventProbabilityHohenbichler)):
        try:
            extra.append(N.SORM_OTHER.format(name=name, ppm=1e6 * float(get())))
        except Exception:
            extra.append(N.SORM_OTHER_UNDEFINED.format(name=name))
    return Estimate("SORM", pb, note=N.SORM.format(others=", ".join(extra)))


def _multi_form(ot, event, u_star: np.ndarray, spec: ToleranceSpec, design_points: int,
                est: TailEstimate) -> Estimate:
    """Multi-FORM from ``u_star``: up to ``design_points`` design points (recorded in ``est``)."""
    algo = ot.MultiFORM(ot.Cobyla(), event, list(u_star))
    algo.setMaximumDesignPointsNumber(design_points)
    algo.run()
    r = algo.getResult()
    pts = [np.array(x.getStandardSpaceDesignPoint()) for x in r.getFORMResultCollection()]
    pf = float(r.getEventProbability())
    if not (0.0 <= pf <= 1.0) or len(pts) < 2:
        return Estimate("multi-FORM", None, note=N.MULTI_FORM_ONE.format(n=len(pts)))
    X = from_normal_scores(spec, np.array(pts))
    est.design_points = [{f.name: float(units.from_base(x[i], f.unit)) for i, f in enumerate(spec.factors)}
                         for x in X]
    return Estimate("multi-FORM", pf, beta=min(float(np.linalg.norm(p)) for p in pts),
                    note=N.MULTI_FORM.format(n=len(pts), betas=", ".join(f"{np.linalg.norm(p):.4g}" for p in pts)))


def _importance(ot, event, u_star, k: int, outer: int, block: int, seed) -> Estimate:
    """Importance sampling about the FORM design point ``u_star`` (None: none found), ``outer`` blocks of
    ``block``; ``seed()`` seeds OpenTURNS' generator."""
    if u_star is None:
        return Estimate("importance sampling", None, note=N.IS_NO_POINT)
    seed()
    exp = ot.ImportanceSamplingExperiment(ot.Normal(list(u_star), [1.0] * k, ot.CorrelationMatrix(k)))
    algo = ot.ProbabilitySimulationAlgorithm(event, exp)
    algo.setMaximumOuterSampling(outer)
    algo.setBlockSize(block)
    algo.setMaximumCoefficientOfVariation(-1.0)
    algo.run()
    r = algo.getResult()
    return Estimate("importance sampling", float(r.getProbabilityEstimate()), float(r.getStandardDeviation()),
                    note=N.IS.format(n=outer * block))


def _subset(ot, event, samples: int, block: int, seed) -> Estimate:
    """Subset simulation, about ``samples`` evaluations per level."""
    seed()
    algo = ot.SubsetSampling(event)
    n_level = max(block, samples)
    algo.setMaximumOuterSampling(max(1, n_level // block))
    algo.setBlockSize(block)
    algo.setConditionalProbability(0.1)
    algo.run()
    r = algo.getResult()
    levels = algo.getStepsNumber() if hasattr(algo, "getStepsNumber") else None
    return Estimate("subset", float(r.getProbabilityEstimate()), float(r.getStandardDeviation()),
                    note=N.SUBSET.format(n=n_level, levels=N.SUBSET_LEVELS.format(levels=levels) if levels else ""))


def _directional(ot, event, samples: int, block: int, seed) -> Estimate:
    """Directional sampling, ``samples``/20 directions."""
    seed()
    algo = ot.DirectionalSampling(event)
    n_dir = max(block // 2, samples // 20)
    algo.setBlockSize(50)
    algo.setMaximumOuterSampling(max(1, n_dir // 50))
    algo.setMaximumCoefficientOfVariation(-1.0)
    algo.run()
    r = algo.getResult()
    return Estimate("directional", float(r.getProbabilityEstimate()), float(r.getStandardDeviation()),
                    note=N.DIRECTIONAL.format(n=max(1, n_dir // 50) * 50))


def _out_of_reach(spec: ToleranceSpec, ls: _Limit, beyond) -> bool:
    """True when every factor's support is bounded and none of the supports' corners (u = ±``REACH``, Φ = 1 − 5e-17;
    at most 2¹² of them) lies beyond the limit."""
    k = len(spec)
    if k > 12:
        return False
    for f in spec.factors:
        lo, hi = (float(v) for v in f.dist.frozen.support())
        if not (math.isfinite(lo) and math.isfinite(hi)):
            return False
    corners = REACH * (2.0 * ((np.arange(2 ** k)[:, None] >> np.arange(k)) & 1) - 1.0)
    return not np.any(beyond(ls.y(corners)))


def _not_an_estimate(e: Estimate, k: int, beta: float | None) -> str | None:
    """Why ``e`` (a number) is no estimate of the probability (module docstring), or None: ``k`` the dimension of
    u-space, ``beta`` FORM's reliability index."""
    pf, se, cov = e.pf, e.se, e.cov
    shown = f"{1e6 * pf:.3g}" + ("" if se is None else f" ± {1e6 * se:.3g}") + " ppm"
    if not (math.isfinite(pf) and 0.0 <= pf <= 1.0):
        return N.NOT_A_PROBABILITY.format(shown=shown)
    if e.method in APPROXIMATIONS:
        b = e.beta if e.beta is not None else beta
        if e.method != "FORM" and b is not None and math.isfinite(b) and b > 0:
            ball = float(stats.chi2.sf(b * b, k))
            if pf > ball * (1 + 1e-9):
                return N.ABOVE_THE_BALL.format(shown=shown, beta=b, k=k, ball=1e6 * ball)
        return None
    if se is None or not math.isfinite(se) or se < 0:
        return N.SE_UNDEFINED.format(shown=shown)
    if pf == 0.0:
        return N.NO_FAILURE_SEEN.format(shown=shown)
    if se == 0.0:
        return N.SE_ZERO.format(shown=shown)
    if cov > MAX_COV:
        return N.COV_TOO_LARGE.format(shown=shown, cov=cov, max=MAX_COV, k=DISAGREE_SE)
    return None


def _reason(exc: Exception) -> str:
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    return N.COULD_NOT_RUN.format(why=text[:200])


def _compare(est: TailEstimate) -> None:
    """The reference estimate and the disagreements (module docstring)."""
    sampled = [e for e in est.estimates if e.method not in APPROXIMATIONS and e.pf is not None and e.se is not None]

    def agree(a: Estimate, b: Estimate) -> bool:
        err = math.hypot(a.se, b.se)
        return abs(a.pf - b.pf) <= DISAGREE_SE * err + 1e-3 * max(a.pf, b.pf) * (err == 0)

    if sampled:
        suspect = set()
        for i, a in enumerate(sampled):
            for b in sampled[i + 1:]:
                if not agree(a, b):
                    ra, rb = ROBUSTNESS.get(a.method, 0), ROBUSTNESS.get(b.method, 0)
                    suspect |= {a.method} if ra < rb else {b.method} if rb < ra else {a.method, b.method}
                    est.disagreements.append(N.DISAGREE.format(a=a.method, a_ppm=1e6 * a.pf, a_se=1e6 * a.se,
                                                               b=b.method, b_ppm=1e6 * b.pf, b_se=1e6 * b.se,
                                                               k=DISAGREE_SE))
        trusted = [e for e in sampled if e.method not in suspect] or \
            [max(sampled, key=lambda e: ROBUSTNESS.get(e.method, 0))]
        ref = min(trusted, key=lambda e: (e.cov if e.cov is not None else math.inf, -ROBUSTNESS.get(e.method, 0)))
        est.reference = ref.method
        for e in est.estimates:
            if e.method in APPROXIMATIONS and e.pf is not None:
                err = DISAGREE_SE * ref.se if ref.se else 1e-3 * ref.pf
                if abs(e.pf - ref.pf) > err:
                    est.disagreements.append(N.OUTSIDE_REFERENCE.format(method=e.method, ppm=1e6 * e.pf, k=DISAGREE_SE,
                                                                        ref=ref.method, ref_ppm=1e6 * ref.pf,
                                                                        ref_se=1e6 * ref.se))
    elif est.get("FORM") is not None and est.get("FORM").pf is not None:
        est.reference = "FORM"
