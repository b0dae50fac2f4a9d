"""Sequential sign-off: decide a requirement from samples looked at batch after batch, at its confidence.

A fixed-n bound (Clopper–Pearson, :func:`rvtol.stats.proportion_lower_bound`) holds at the one n it was
planned for.  A run that looks after every batch and stops the first time that bound crosses the
requirement makes a wrong PASS far more often than 1 − c (``studies/sequential.md``: 5 % becomes 20–30 %
over 20 looks).  The rule here holds at every n at once, so the run may look as often as it likes and stop
whenever it likes:

**Evidence for a proportion above p₀** (a yield above the required one; a share of the units below a
median's limit above ½).  With x₁, x₂, … ∈ {0, 1}, S successes and F failures in n, the mixture
likelihood ratio of the alternatives q > p₀ against p₀ is

    M_n(p₀) = ∫_{p₀}^1 (q/p₀)^S ((1 − q)/(1 − p₀))^F π(q) dq / ∫_{p₀}^1 π(q) dq,

π the Beta(a, b) density.  Each integrand is a nonnegative supermartingale with initial value 1 under
any true p ≤ p₀ (one step multiplies it by p q/p₀ + (1 − p)(1 − q)/(1 − p₀), which is 1 at p = p₀ and
increases with p when q > p₀), so their fixed mixture M_n is one too, and by Ville's inequality

    P(M_n(p₀) ≥ 1/α for some n) ≤ α        whenever p ≤ p₀

(J. Ville, *Étude critique de la notion de collectif*, 1939; the mixture martingale of H. Robbins,
"Statistical methods related to the law of the iterated logarithm", Ann. Math. Stat. 41 (1970)
1397–1409; S. R. Howard, A. Ramdas, J. McAuliffe, J. Sekhon, "Time-uniform, nonparametric,
nonasymptotic confidence sequences", Ann. Stat. 49 (2021) 1055–1080, §3 — their one-sided
conjugate mixtures are this construction).  "M_n ≥ 1/α" is the sequential test of H₀: p ≤ p₀ at
level α whatever the stopping rule, the number of looks or the batch sizes.  Conjugacy gives the
closed form (B the beta function, I_x the regularised incomplete beta function):

    M_n(p₀) = B(a + S, b + F)/B(a, b) · [1 − I_{p₀}(a + S, b + F)] / [1 − I_{p₀}(a, b)] / (p₀^S (1 − p₀)^F).

The mixing prior decides *where* the rule is efficient, not whether it is valid.  It is the conjugate
prior centred on p₀ with ``tune_n`` pseudo-observations, Beta(p₀ m, (1 − p₀) m), m = ``tune_n``: its
spread above p₀ is the standard error of a proportion at n = m, so the alternatives it weighs are
those the run can resolve near m samples (Howard et al. 2021, §3.5, tune the mixture to the sample size
where the boundary should be tightest).  A run tunes it to the study's ``n``.

The decisions of :func:`judge_yield` and :func:`judge_median` use this one function, :func:`judge_mean` a second mixture:

* yield ≥ p₀: PASS when the evidence that the conforming share exceeds p₀ reaches 1/α, FAIL when the
  evidence that the non-conforming share exceeds 1 − p₀ does (a sample the model could not evaluate
  counts as non-conforming, as in :func:`rvtol.verdict.judge`), CONTINUE otherwise;
* mean in [L, U] (a normal output, as the fixed-n verdict's Student t assumes): the scale-invariant mixture
  Bayes factor of the one-sample t-test, δ = (μ − μ₀)/σ ~ N(0, g) against δ = 0 and σ under the right-Haar prior
  dσ/σ on both, is a function of t alone (ν = n − 1),

      BF_n(μ₀) = (1 + n g)^(−1/2) · [(1 + t²/ν) / (1 + t²/(ν(1 + n g)))]^(n/2),   t = √n (ȳ − μ₀)/s,

  (J. N. Rouder et al., Psychon. Bull. Rev. 16 (2009) 225, eq. 1 at a fixed g) and a nonnegative martingale under
  μ = μ₀ in the filtration of the scale-invariant statistics (T. L. Lai, "On confidence sequences", Ann. Stat. 4
  (1976) 265–280; H. Wang & A. Ramdas, "Anytime-valid t-tests and confidence sequences for Gaussian means with
  unknown variance", Sequential Analysis 2025), so {μ₀ : BF_n(μ₀) < 1/α} covers μ at every n at once with
  probability ≥ 1 − α.  Solving BF_n = 1/α for t² gives the interval ȳ ± s √(ν u / n), u = (R − 1)/(1 − R/(1 + n g)),
  R = (√(1 + n g)/α)^(2/n) (unbounded while R ≥ 1 + n g).  PASS when it lies inside the band, FAIL when it lies
  wholly outside; g = x/m with x the root of x = 2 ln(1/α) + ln(1 + x), which makes the interval narrowest at n = m;
  a sample the model could not evaluate leaves the mean unbounded (as in :func:`rvtol.verdict.statistic_interval`);
* median in [L, U]: median ≤ U is demonstrated by evidence that P(Y ≤ U) > ½, median > U by evidence that
  P(Y > U) > ½ (and likewise at L); a sample the model could not evaluate is counted against the claim
  being made (it may lie anywhere), so each claim's error stays ≤ α.  PASS needs every limit's claim
  (the intersection–union principle, as :func:`rvtol.verdict.judge_statistic`), FAIL any one limit's
  opposite claim.

α = 1 − :func:`rvtol.verdict.bound_level`: the same level a fixed-n verdict of the requirement uses.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import special

#: the three outcomes of a look: demonstrated, demonstrated not to hold, not yet decided
PASS, FAIL, CONTINUE = "PASS", "FAIL", "CONTINUE"


def mixture_prior(p0: float, tune_n: float) -> tuple[float, float]:
    """The mixing prior Beta(a, b) = Beta(p₀ m, (1 − p₀) m) of the evidence for a proportion above ``p0``, tuned to
    ``m = tune_n`` samples (module docstring)."""
    if not 0.0 < p0 < 1.0:
        raise ValueError(f"p0 must lie in (0, 1), got {p0!r}")
    if not tune_n > 0:
        raise ValueError(f"tune_n must be > 0, got {tune_n!r}")
    return p0 * tune_n, (1.0 - p0) * tune_n


def log_evidence(successes, n, p0: float, tune_n: float):
    """ln M_n(p₀): the log mixture likelihood ratio for "the success probability exceeds ``p0``" after ``successes``
    in ``n`` trials (closed form of the module docstring; arrays broadcast).  Under any p ≤ p₀ the probability that
    it *ever* reaches ln(1/α) is at most α."""
    a, b = mixture_prior(p0, tune_n)
    s = np.asarray(successes, dtype=float)
    f = np.asarray(n, dtype=float) - s
    return (special.betaln(a + s, b + f) - special.betaln(a, b)
            + log_beta_sf(p0, a + s, b + f) - log_beta_sf(p0, a, b)
            - s * math.log(p0) - f * math.log1p(-p0))


#: below this, 1 − I_x(a, b) is taken from its series (:func:`log_beta_sf`): the regularised function loses digits
#: as it nears the smallest double (and is 0 beyond it)
_SF_SERIES_BELOW = 1e-250


def log_beta_sf(x: float, a, b):
    """ln(1 − I_x(a, b)), the log upper tail of Beta(a, b) at ``x`` (arrays ``a``, ``b`` broadcast), finite however
    far the tail.

    Where the tail is not tiny, the log of ``scipy.special.betaincc``; where it is (below 1e-250: then x lies far
    above the mean a/(a + b)), the hypergeometric series of the tail (Abramowitz & Stegun 26.5.23 with 15.1.1,
    written for the upper tail), summed in double precision:

        1 − I_x(a, b) = x^a (1 − x)^b / (b B(a, b)) · Σ_k t_k,   t_0 = 1,   t_{k+1} = t_k (a + b + k)(1 − x)/(b + 1 + k),

    whose ratio (a + b + k)(1 − x)/(b + 1 + k) stays below (a + b)(1 − x)/(b + 1) < 1 there: positive terms
    falling at least geometrically (no cancellation)."""
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    sf = special.betaincc(a, b, x)
    out = np.empty(a.shape)
    far = sf < _SF_SERIES_BELOW
    with np.errstate(divide="ignore"):
        out[~far] = np.log(sf[~far])
    if far.any():
        af, bf = a[far], b[far]
        z = 1.0 - x
        total, term, k = np.ones_like(af), np.ones_like(af), 0
        while True:
            term = term * (af + bf + k) * z / (bf + 1.0 + k)
            total += term
            k += 1
            if np.all(term <= 1e-17 * total):
                break
        out[far] = (af * math.log(x) + bf * math.log1p(-x) - np.log(bf) - special.betaln(af, bf) + np.log(total))
    return out if out.ndim else float(out)


def evidence_reached(successes, n, p0: float, alpha: float, tune_n: float):
    """True where the evidence for "success probability > ``p0``" has reached 1/``alpha`` (arrays broadcast)."""
    return log_evidence(successes, n, p0, tune_n) >= -math.log(alpha)


@dataclass
class Look:
    """One requirement at one look: its state (PASS / FAIL / CONTINUE), the sample size, and the evidence of each
    claim the rule weighs (the e-value M_n, to reach ``threshold`` = 1/α) — or, for a mean, its anytime-valid
    ``interval`` (None: not bounded yet)."""

    state: str
    n: int
    threshold: float
    evidence: dict[str, float] = field(default_factory=dict)
    interval: tuple[float, float] | None = None


#: the largest e-value recorded (a finite number for JSON; any e-value this large decides at any confidence)
EVIDENCE_CAP = 1e300


def _evidence(claims: dict[str, tuple[int, float]], n: int, alpha: float, tune_n: float) -> dict[str, float]:
    """Each claim's e-value (at most :data:`EVIDENCE_CAP`): ``claims`` maps its name to (successes, p₀)."""
    return {name: float(np.exp(min(float(log_evidence(k, n, p0, tune_n)), math.log(EVIDENCE_CAP))))
            for name, (k, p0) in claims.items()}


def judge_yield(conforming: int, n: int, min_yield: float, alpha: float, tune_n: float) -> Look:
    """PASS / FAIL / CONTINUE of "yield ≥ ``min_yield``" from ``conforming`` of ``n`` samples (a failed evaluation
    counts as non-conforming): PASS when the evidence for yield > p₀ reaches 1/α, FAIL when the evidence for
    non-conforming share > 1 − p₀ does (module docstring)."""
    claims = {"yield above": (conforming, min_yield), "yield below": (n - conforming, 1.0 - min_yield)}
    ev = _evidence(claims, n, alpha, tune_n)
    state = PASS if ev["yield above"] >= 1 / alpha else FAIL if ev["yield below"] >= 1 / alpha else CONTINUE
    return Look(state, n, 1.0 / alpha, ev)


def judge_median(y, ok, lower: float | None, upper: float | None, alpha: float, tune_n: float) -> Look:
    """PASS / FAIL / CONTINUE of "median in [``lower``, ``upper``]" from the outputs ``y`` (NaN allowed where ``ok``
    is False: a failed evaluation) — module docstring.  Distribution-free: it needs only that the samples are
    independent draws."""
    y = np.asarray(y, dtype=float)
    ok = np.asarray(ok, dtype=bool)
    n = int(y.size)
    claims = {}
    with np.errstate(invalid="ignore"):
        if upper is not None:
            claims["median ≤ upper"] = (int(np.sum(ok & (y <= upper))), 0.5)
            claims["median > upper"] = (int(np.sum(ok & (y > upper))), 0.5)
        if lower is not None:
            claims["median ≥ lower"] = (int(np.sum(ok & (y >= lower))), 0.5)
            claims["median < lower"] = (int(np.sum(ok & (y < lower))), 0.5)
    ev = _evidence(claims, n, alpha, tune_n)
    t = 1.0 / alpha
    inside = [k for k in ev if "≤" in k or "≥" in k]
    if all(ev[k] >= t for k in inside):
        return Look(PASS, n, t, ev)
    if any(ev[k] >= t for k in ev if k not in inside):
        return Look(FAIL, n, t, ev)
    return Look(CONTINUE, n, t, ev)


def effect_prior_variance(alpha: float, tune_n: float) -> float:
    """g of the mean's mixture (module docstring): x/m, x the root of x = 2 ln(1/α) + ln(1 + x) — at n = m the
    half-width ∝ √((1 + x)/x · (2 ln(1/α) + ln(1 + x))) is smallest there (its derivative in ln x vanishes)."""
    x = 2.0 * math.log(1.0 / alpha)
    for _ in range(60):
        x = 2.0 * math.log(1.0 / alpha) + math.log1p(x)
    return x / tune_n


def log_t_evidence(t2, n, g):
    """ln BF_n of the mean's mixture (module docstring) from t² and n ≥ 2 (arrays broadcast)."""
    n = np.asarray(n, dtype=float)
    nu = n - 1.0
    return -0.5 * np.log1p(n * g) + 0.5 * n * (np.log1p(t2 / nu) - np.log1p(t2 / (nu * (1.0 + n * g))))


def mean_halfwidth(s: float, n: int, alpha: float, tune_n: float) -> float | None:
    """Half-width of the anytime-valid interval ȳ ± h of a normal mean from the standard deviation ``s`` of ``n``
    values (module docstring); None while it is unbounded."""
    if n < 2:
        return None
    g = effect_prior_variance(alpha, tune_n)
    ng = n * g
    log_r = (2.0 / n) * (0.5 * math.log1p(ng) - math.log(alpha))
    if log_r >= math.log1p(ng):
        return None
    r = math.exp(log_r)
    u = (r - 1.0) / (1.0 - r / (1.0 + ng))
    return s * math.sqrt((n - 1) * u / n)


def judge_mean(y, ok, lower: float | None, upper: float | None, alpha: float, tune_n: float) -> Look:
    """PASS / FAIL / CONTINUE of "mean in [``lower``, ``upper``]" from the outputs ``y`` (``ok``: evaluated) — module
    docstring; a failed evaluation leaves the mean unbounded (CONTINUE)."""
    y = np.asarray(y, dtype=float)
    n = int(y.size)
    h = None if not np.all(ok) or n < 2 else mean_halfwidth(float(np.std(y, ddof=1)), n, alpha, tune_n)
    if h is None:
        return Look(CONTINUE, n, 1.0 / alpha)
    m = float(np.mean(y))
    lo, hi = m - h, m + h
    inside = (lower is None or lo >= lower) and (upper is None or hi <= upper)
    outside = (lower is not None and hi < lower) or (upper is not None and lo > upper)
    return Look(PASS if inside else FAIL if outside else CONTINUE, n, 1.0 / alpha, interval=(lo, hi))


# --------------------------------------------------------------------------- a requirement at a look, a run's stop
def unsupported(r) -> str | None:
    """Why the sequential rule cannot decide requirement ``r`` (None: it can) — a reason for an error line."""
    if r.min_cpk is not None:
        return ("a minimum Cpk has no anytime-valid bound here: ask the yield it stands for (min_yield; Cpk c of a "
                "normal output is the yield 2Φ(3c) − 1 between two limits), or run a fixed n")
    return None


def look_at(r, y, ok, tune_n: float) -> Look:
    """Requirement ``r`` (limits in the units of ``y``) at one look: its outputs ``y`` so far and which were evaluated
    (``ok``).  A yield or a median by the anytime-valid rule at α = 1 − :func:`rvtol.verdict.bound_level`; a yield
    with ``basis = "estimate"`` (no confidence claimed) by its estimate, decided at once."""
    from .stats import conforming
    from .verdict import bound_level

    alpha = 1.0 - bound_level(r)
    if r.statistic == "median":
        return judge_median(y, ok, r.lower, r.upper, alpha, tune_n)
    if r.statistic == "mean":
        return judge_mean(y, ok, r.lower, r.upper, alpha, tune_n)
    n = len(y)
    k = int(conforming(y, ok, r.lower, r.upper).sum())
    if r.basis == "estimate":
        return Look(PASS if k / n >= r.min_yield else FAIL, n, 1.0 / alpha, {})
    return judge_yield(k, n, r.min_yield, alpha, tune_n)


#: how the report names the rule
RULE = ("anytime-valid sequential rule (beta-mixture likelihood ratio ≥ 1/α, Ville's inequality: the error rate holds "
        "under any number of looks)")


@dataclass
class Stopping:
    """How a sequential run (:func:`rvtol.mc.run_until_decided`) went: batches of ``batch`` samples up to ``max_n``,
    the mixture tuned to ``tune_n``; the sample size at each look, each requirement's first decision (its look and
    :class:`Look`: a decision is kept once made — Ville's inequality bounds the chance it is *ever* wrong) and each
    requirement's last look."""

    batch: int
    max_n: int
    tune_n: float
    looks: list[int] = field(default_factory=list)
    decided: dict[str, tuple[int, Look]] = field(default_factory=dict)
    last: dict[str, Look] = field(default_factory=dict)

    def look(self, n: int, states: dict[str, Look]) -> None:
        """Record a look at ``n`` samples: each requirement label's :class:`Look`."""
        self.looks.append(n)
        self.last = dict(states)
        for label, lk in states.items():
            if label not in self.decided and lk.state != CONTINUE:
                self.decided[label] = (len(self.looks), lk)

    @property
    def n(self) -> int:
        return self.looks[-1] if self.looks else 0

    @property
    def all_decided(self) -> bool:
        return len(self.decided) == len(self.last)

    @property
    def finished(self) -> bool:
        return self.all_decided or self.n >= self.max_n

    def describe(self) -> str:
        """One sentence: when and why the run stopped."""
        how = ("every requirement decided" if self.all_decided else
               f"the budget max_n = {self.max_n:,} reached with {len(self.last) - len(self.decided)} requirement(s) "
               "undecided")
        return (f"sequential run: stopped at n = {self.n:,} after {len(self.looks)} look(s) (batches of "
                f"{self.batch:,}, budget {self.max_n:,}): {how} — {RULE}")

    def why(self, label: str) -> str:
        """A requirement's sequential verdict in words."""
        if label in self.decided:
            i, lk = self.decided[label]
            return (f"{'demonstrated' if lk.state == PASS else 'failure demonstrated'} at look {i} (n = {lk.n:,}) "
                    f"by the sequential rule: {_evidence_text(lk)}")
        lk = self.last[label]
        return (f"not decided within the budget max_n = {self.max_n:,} ({len(self.looks)} looks): "
                f"{_evidence_text(lk)} — a larger max_n would continue it")

    def to_dict(self) -> dict:
        return {"rule": RULE, "batch": self.batch, "max_n": self.max_n, "tune_n": self.tune_n, "n": self.n,
                "looks": list(self.looks), "stopped": "decided" if self.all_decided else "budget",
                "requirements": {label: {"state": (self.decided[label][1].state if label in self.decided
                                                   else CONTINUE),
                                         "look": self.decided[label][0] if label in self.decided else None,
                                         "n": self.decided[label][1].n if label in self.decided else None,
                                         "evidence": (self.decided.get(label, (0, lk))[1].evidence),
                                         "interval": _interval(self.decided.get(label, (0, lk))[1]),
                                         "threshold": lk.threshold}
                                 for label, lk in self.last.items()}}


def _interval(lk: Look) -> list[float] | None:
    return None if lk.interval is None else [float(v) for v in lk.interval]


def _evidence_text(lk: Look) -> str:
    if lk.interval is not None:
        return f"the mean's anytime-valid interval [{lk.interval[0]:.5g}, {lk.interval[1]:.5g}] (at 1/α = {lk.threshold:g})"
    if lk.threshold and not lk.evidence and lk.state == CONTINUE:
        return "the mean is not bounded yet (too few samples, or samples the model could not evaluate)"
    if not lk.evidence:
        return "judged on its estimate (basis = \"estimate\")"
    return ", ".join(f"evidence {k} {v:.3g}" for k, v in lk.evidence.items()) + f" (decides at 1/α = {lk.threshold:g})"
