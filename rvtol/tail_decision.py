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
* per estimator — importance sampling and subset simulation, each a valid estimate (coefficient of variation at
  most 1/3) beyond every limit — the non-conformance p̂ = Σ p̂_side with its standard error s = √(Σ s_side²) and
  the interval [p̂ − z s, p̂ + z s], z = Φ⁻¹(ℓ) at the requirement's one-sided level ℓ; a limit beyond the
  bounded supports' reach contributes exactly 0 (FORM's corner test);
* a **cross-check with the Monte Carlo**: the Monte Carlo's own count k of n beyond the limits gives the two-sided
  99 % Clopper–Pearson interval of the non-conformance; an estimator's interval that does not overlap it means the
  two disagree (a failure region the estimators missed, a model that fails where they look): no decision;
* the verdict: **PASS** when *both* estimators put the yield's lower end 1 − (p̂ + z s) at or above min_yield,
  **FAIL** when both put its upper end 1 − max(0, p̂ − z s) below it, else UNDECIDED — with the estimators, their
  runs and intervals in the requirement's notes and reasons, and the yield bound judged the less favourable one's.
  Both must agree because each can be wrong alone: importance sampling about one design point is blind to a
  second failure region (a radius, hypot(x, y), fails in every direction: it sees a fifth of the tail), and subset
  simulation's standard error ignores the correlation of its chains (its 95 % bound under-covers, about 15 % in
  the tests); a wrong PASS needs both to err the same way.

Not used for a Cpk requirement, a population statistic, factors fitted to measured parts (their laws' own
uncertainty is not in the tail estimators) or a sequential run (its rule decides).  Failed model evaluations
count as non-conforming, as in the yield.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from scipy import stats

from .stacking.beside_monte_carlo import search_evaluator
from .stacking.tail import tail_probability
from .stats import proportion_ci
from .verdict import _pct, bound_level

#: the tail methods run (FORM gives importance sampling its centre, and says when a limit is out of reach)
METHODS = ("FORM", "importance sampling", "subset")
#: the estimators that must agree on a decision
SAMPLERS = ("importance sampling", "subset")
#: the confidence of the Monte Carlo's interval the tail estimate is cross-checked against
CROSS_CHECK = 0.99
#: model runs per sampling method and limit
DEFAULT_SAMPLES = 2000


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
    methods: list[str] = field(default_factory=list)   # per limit: each estimator's figure
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
        if eligible(r, v, measured):
            out[r.label] = _decide_one(key, r, v, model, spec, evaluator, seed, samples)
    return out


def _decide_one(key, r, v, model, spec, evaluator, seed, samples) -> TailDecision:
    sub = model.restricted([r.output]) if hasattr(model, "restricted") else model
    search = search_evaluator(sub, spec, evaluator)
    n = int(v.yield_.n)
    k = n - int(v.yield_.conforming)
    mc_ci = tuple(float(x) for x in proportion_ci(k, n, CROSS_CHECK))
    per = {m: [0.0, 0.0] for m in SAMPLERS}          # estimator -> [p, variance] summed over the limits
    runs, notes = 0, []
    for side, lim in (("lower", r.lower), ("upper", r.upper)):
        if lim is None:
            continue
        est = tail_probability(sub, spec, r.output, lim, side, search, samples=samples, seed=seed,
                               key=1000 + 2 * key + (side == "upper"), methods=METHODS)
        runs += est.evaluations
        form = est.get("FORM")
        if form is not None and form.pf == 0.0 and est.beta == math.inf:
            notes.append(f"{side}: out of reach (the bounded supports' corners)")
            continue                                  # P = 0 exactly: every estimator's share is 0
        for m in SAMPLERS:
            e = est.get(m)
            if e is None or e.pf is None or e.se is None:
                why = (f"beyond the {side} limit {m} gives no estimate ({e.note if e is not None else 'not run'}): "
                       "both importance sampling and subset simulation are needed to decide")
                return TailDecision(r.label, "UNDECIDED", None, None, None, mc_ci, runs, notes, why)
            per[m][0] += e.pf
            per[m][1] += e.se ** 2
        notes += [f"{side}: " + ", ".join(f"{m} {_ppm(est.get(m).pf)} ± {_ppm(est.get(m).se)}" for m in SAMPLERS)]
    z = float(stats.norm.ppf(bound_level(r)))
    ivs = {m: (max(0.0, p - z * math.sqrt(var)), min(1.0, p + z * math.sqrt(var))) for m, (p, var) in per.items()}
    binding = max(SAMPLERS, key=lambda m: ivs[m][1])  # the estimator whose interval reaches furthest
    p, se, iv = per[binding][0], math.sqrt(per[binding][1]), ivs[binding]
    what = (f"the tails' non-conformance ({'; '.join(notes)}; {runs:,} model runs), {_pct(bound_level(r))} intervals "
            + ", ".join(f"{m} [{_ppm(a)}, {_ppm(b)}]" for m, (a, b) in ivs.items()))
    off = [m for m, (a, b) in ivs.items() if a > mc_ci[1] or b < mc_ci[0]]
    if off:
        why = (f"{what}: {' and '.join(off)} disagree{'s' if len(off) == 1 else ''} with the Monte Carlo's {k} of "
               f"{n:,} ({_pct(CROSS_CHECK)} interval [{_ppm(mc_ci[0])}, {_ppm(mc_ci[1])}]): not used")
        return TailDecision(r.label, "UNDECIDED", p, se, iv, mc_ci, runs, notes, why)
    if all(1.0 - b >= r.min_yield for _, b in ivs.values()):
        return TailDecision(r.label, "PASS", p, se, iv, mc_ci, runs, notes,
                            f"decided by the tails: {what}; the yield ≥ {1 - iv[1]:.6g} ≥ {r.min_yield:g} by both")
    if all(1.0 - a < r.min_yield for a, _ in ivs.values()):
        low = min(ivs.values(), key=lambda ab: ab[0])
        return TailDecision(r.label, "FAIL", p, se, low, mc_ci, runs, notes,
                            f"decided by the tails: {what}; the yield ≤ {1 - low[0]:.6g} < {r.min_yield:g} by both")
    return TailDecision(r.label, "UNDECIDED", p, se, iv, mc_ci, runs, notes,
                        f"{what}: they do not both put the yield on one side of {r.min_yield:g}")


def _ppm(p: float) -> str:
    return f"{1e6 * p:.4g} ppm"
