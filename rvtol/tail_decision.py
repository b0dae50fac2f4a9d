"""Requirements the Monte Carlo left undecided, decided by the tail's own estimators at a fraction of the samples.

A yield requirement near its bound — 99.73 % demonstrated at 95 % when the true yield is 99.8 % — needs tens of
thousands of plain Monte Carlo samples: the bound tightens as 1/√n.  The non-conformance it is about is a tail
probability, which subset simulation (Au & Beck 2001) and importance sampling estimate with a standard error
that shrinks much faster per model run when the probability is small.  With ``[sampling] tails = true``
(``rvtol run --tails``), after the Monte Carlo every per-unit yield requirement it left UNDECIDED gets:

* beyond each of its limits, the tail estimates of :func:`rvtol.stacking.tail.tail_probability` on the model
  restricted to the requirement's output (a composed study evaluates only the stages that reach it): FORM (the
  design point), importance sampling about it and subset simulation, ``tail_samples`` model runs each; the
  reference estimate is the one :mod:`rvtol.stacking.tail` names (the sampling estimate with the smallest
  coefficient of variation that no other contradicts, each at most 1/3);
* the non-conformance p̂ = Σ p̂_side with its standard error s = √(Σ s_side²), and the interval
  [p̂ − z s, p̂ + z s], z = Φ⁻¹(ℓ) at the requirement's one-sided level ℓ (the normal approximation of the
  estimator, which its coefficient of variation ≤ 1/3 keeps above zero: its 3 s reach 0 at most);
* a **cross-check with the Monte Carlo**: the Monte Carlo's own count k of n beyond the limits gives the two-sided
  99 % Clopper–Pearson interval of the non-conformance; a tail interval that does not overlap it is not used
  (the two disagree — a design point the estimators missed, a model that fails where they look — and the
  requirement stays UNDECIDED with both figures in its reasons);
* the verdict: **PASS** when 1 − (p̂ + z s) ≥ min_yield, **FAIL** when 1 − max(0, p̂ − z s) < min_yield,
  else UNDECIDED — with the estimator, its runs and its interval in the requirement's notes and reasons, and the
  yield bound judged the tail's.

Not used for a Cpk requirement, a population statistic, factors fitted to measured parts (their laws' own
uncertainty is not in the tail estimators) or a sequential run (its rule decides).  Failed model evaluations
count as non-conforming, as in the yield.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from scipy import stats

from .stacking.compare import search_evaluator
from .stacking.tail import tail_probability
from .stats import proportion_ci
from .verdict import bound_level

#: the tail methods run (FORM gives importance sampling its centre)
METHODS = ("FORM", "importance sampling", "subset")
#: the confidence of the Monte Carlo's interval the tail estimate is cross-checked against
CROSS_CHECK = 0.99
#: model runs per sampling method and limit
DEFAULT_SAMPLES = 1000


@dataclass
class TailDecision:
    """One requirement judged by its tail estimates (module docstring)."""

    label: str
    state: str                          # PASS, FAIL or UNDECIDED
    p: float | None                     # the non-conformance estimate
    se: float | None
    interval: tuple[float, float] | None  # of the non-conformance, at the requirement's one-sided level
    mc_interval: tuple[float, float]    # the Monte Carlo's, two-sided at CROSS_CHECK
    evaluations: int
    methods: list[str] = field(default_factory=list)   # per side: the reference estimator
    why: str = ""

    @property
    def yield_bound(self) -> float | None:
        return None if self.interval is None else 1.0 - self.interval[1]

    def to_dict(self) -> dict:
        return {"state": self.state, "nonconformance": self.p, "se": self.se,
                "interval": None if self.interval is None else list(self.interval),
                "monte_carlo_interval": list(self.mc_interval), "evaluations": self.evaluations,
                "estimators": self.methods, "why": self.why}


def eligible(r, v, measured: bool) -> bool:
    """Whether requirement ``r`` (its verdict ``v``) is one the tails may decide."""
    return (v.undecided and r.per_unit and r.min_cpk is None and r.min_yield is not None and not measured
            and r.basis != "estimate")


def decide(mc, model, spec, evaluator, *, seed: int | None, samples: int = DEFAULT_SAMPLES) -> dict[str, TailDecision]:
    """Label -> :class:`TailDecision` of every requirement of ``mc`` the tails may decide (:func:`eligible`)."""
    measured = any(f.measured is not None for f in spec.factors)
    out: dict[str, TailDecision] = {}
    for key, v in enumerate(mc.verdicts()):
        r = v.requirement
        if not eligible(r, v, measured):
            continue
        sub = model.restricted([r.output]) if hasattr(model, "restricted") else model
        search = search_evaluator(sub, spec, evaluator)
        n = int(v.yield_.n)
        k = n - int(v.yield_.conforming)
        mc_ci = tuple(float(x) for x in proportion_ci(k, n, CROSS_CHECK))
        ps, ses, methods, runs = [], [], [], 0
        for side, lim in (("lower", r.lower), ("upper", r.upper)):
            if lim is None:
                continue
            est = tail_probability(sub, spec, r.output, lim, side, search, samples=samples, seed=seed,
                                   key=1000 + 2 * key + (side == "upper"), methods=METHODS)
            runs += est.evaluations
            ref = est.get(est.reference) if est.reference else None
            if ref is None or ref.pf is None or ref.se is None:
                why = (f"beyond the {side} limit no tail estimate holds ("
                       + "; ".join(f"{e.method}: {e.note}" for e in est.estimates if e.pf is None) + ")")
                out[r.label] = TailDecision(r.label, "UNDECIDED", None, None, None, mc_ci, runs, methods, why)
                break
            ps.append(ref.pf)
            ses.append(ref.se)
            methods.append(f"{side}: {ref.method}")
        else:
            p, se = math.fsum(ps), math.sqrt(math.fsum(s * s for s in ses))
            z = float(stats.norm.ppf(bound_level(r)))
            iv = (max(0.0, p - z * se), min(1.0, p + z * se))
            what = (f"the tails' non-conformance {_ppm(p)} ± {_ppm(se)} (s.e.; {', '.join(methods)}; {runs:,} model "
                    f"runs), {_pct(bound_level(r))} interval [{_ppm(iv[0])}, {_ppm(iv[1])}]")
            if iv[0] > mc_ci[1] or iv[1] < mc_ci[0]:
                state = "UNDECIDED"
                why = (f"{what} disagrees with the Monte Carlo's {k} of {n:,} ({_pct(CROSS_CHECK)} interval "
                       f"[{_ppm(mc_ci[0])}, {_ppm(mc_ci[1])}]): not used")
            elif 1.0 - iv[1] >= r.min_yield:
                state, why = "PASS", f"decided by the tails: {what}, yield ≥ {1 - iv[1]:.6g} ≥ {r.min_yield:g}"
            elif 1.0 - iv[0] < r.min_yield:
                state, why = "FAIL", f"decided by the tails: {what}, yield ≤ {1 - iv[0]:.6g} < {r.min_yield:g}"
            else:
                state, why = "UNDECIDED", f"{what}: the yield's interval [{1 - iv[1]:.6g}, {1 - iv[0]:.6g}] holds " \
                                          f"{r.min_yield:g}"
            out[r.label] = TailDecision(r.label, state, p, se, iv, mc_ci, runs, methods, why)
    return out


def apply(v, d: TailDecision):
    """Verdict ``v`` as the tail decision ``d`` judges it (:meth:`rvtol.mc.MonteCarloResult.verdicts`)."""
    if d.state == "PASS":
        return replace(v, passed=True, undecided=False, yield_bound=d.yield_bound, n_to_demonstrate=None,
                       parts_to_demonstrate=None, reasons=[], notes=[d.why, *v.notes])
    if d.state == "FAIL":
        return replace(v, passed=False, undecided=False, yield_bound=d.yield_bound, n_to_demonstrate=None,
                       parts_to_demonstrate=None, reasons=[d.why, *v.reasons])
    return replace(v, reasons=[*v.reasons, d.why])


def _ppm(p: float) -> str:
    return f"{1e6 * p:.4g} ppm"


def _pct(x: float) -> str:
    return f"{100 * x:g} %"
