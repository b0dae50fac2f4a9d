"""The sentences of the sign-off digest (:mod:`rvtol.signoff`): what to change to make a requirement pass and the
fixes it proposes, as templates the digest fills with its numbers (``str.format`` fields named after them).

A leaf module (no imports): the digest, a computation, formats these while it runs (they are recorded in
summary.json); the report's layout of the digest is :mod:`rvtol.report.signoff`.
"""

# what_to_change: one sentence per case of the first-order tightening (rvtol.signoff.tightening)
NOTHING_EVALUATED = "No sample could be evaluated: nothing to estimate from."
MEAN_BEYOND = ("The mean {mean:.4g} {unit} itself lies at or beyond the limit: tightening tolerances cannot fix it — "
               "the nominal design (or a mean shift of its largest drivers) must change.")
CONSTANT = ("The output is constant ({mean:.6g} {unit} in every evaluated sample, σ = 0): no tolerance of the spec "
            "moves it, so no tightening changes it.")
CONSTANT_CPK = " Its Cpk is undefined (σ = 0): state the requirement as a min_yield."
NO_DRIVER = "The spread must fall from σ = {sigma:.3g} to {target:.3g} {unit}; no driver could be estimated."
ONLY_CONFIDENCE = ("The point estimate already meets the requirement: the confidence bound does not — more samples "
                   "(a larger n) would demonstrate it, or a small tightening of the drivers below.")
SEVERAL = ("The spread must fall from σ = {sigma:.3g} to {target:.3g} {unit} ({need:.0f} % of the variance), more than "
           "the largest drivers explain to first order ({names}: {explained:.0f} %): tighten several tolerances (an "
           "allocation analysis finds which, at the least cost).")
SCALE = ("The spread must fall from σ = {sigma:.3g} to {target:.3g} {unit}: scaling {names} to {f:.0f} % of {their} "
         "present tolerance would do it to first order (S1 = {explained:.2f}). An estimate: an allocation analysis "
         "gives cost-optimal tolerances checked by Monte Carlo.")

# first_order_fixes: (action, reason) of each kind of fix
MORE_SAMPLES = ("run n = {n:,} samples",
                "the estimate already meets the requirement; this n would demonstrate it if the figures hold")
MORE_PARTS = ("measure about {parts}",
              "the fitted laws of the measured factors are too uncertain to demonstrate it — more Monte Carlo samples "
              "cannot; these would, if the fitted laws held (the fit's deviation shrinks as 1/√parts)")
FAILURES = ("find what makes {share:.3g} % of the samples fail to evaluate — {why} — and tighten or re-centre the "
            "factors that drive it (each sample's status is in samples.parquet)",
            "they count as failing the requirement, which allows {allowed:.3g} %; the evaluated units are a selection "
            "(those that could be evaluated), so no fix is read from their mean and σ alone — a nominal inside the "
            "limits is not ruled out")
FAILURES_ALONE = ("{share:.3g} % of the samples could not be evaluated — {why} — and count as failing: more than the "
                  "{allowed:.3g} % the requirement allows; the evaluated units meet it ({outside:.3g} % of all samples "
                  "outside the limits).")
FAILURES_AND_SPREAD = ("{share:.3g} % of the samples could not be evaluated — {why} — and count as failing, beside "
                       "{outside:.3g} % of all samples evaluated outside the limits (the requirement allows "
                       "{allowed:.3g} %): together they fail it.")
REDESIGN = ("move the mean ({mean:.4g} {unit}) {side} the limit {limit:g} {unit}: a nominal of the design",
            "tightening cannot help: as tolerances shrink, every unit approaches the nominal one")
RECENTRE = ("move the mean from {mean:.4g} to {mid:.4g} {unit} (shift {shift:+.3g} {unit}: a nominal, no tolerance "
            "changes)",
            "the present spread σ = {sigma:.3g} {unit} fits the band when centred (needs σ ≤ {centred:.3g}); to first "
            "order, at the point estimate")
TIGHTEN = ("scale {names} to {f:.0f} % of {their} present tolerance",
           "σ from {sigma:.3g} to {target:.3g} {unit}: to first order, at the point estimate (S1 = {explained:.2f} "
           "from the Monte Carlo samples)")
TIGHTEN_SEVERAL = ("tighten several tolerances",
                   "σ from {sigma:.3g} to {target:.3g} {unit}: more than the largest drivers explain to first order "
                   "({explained:.0f} %)")


# a population statistic's band (rvtol.verdict.judge_statistic): tolerances do not move a central value
STATISTIC_OUTSIDE = ("The {statistic} {value:.4g} {unit} lies outside the band [{lower}, {upper}] {unit}: a central "
                     "value is the nominal design's (and the model's), not the tolerances' — tightening cannot move it.")
STATISTIC_UNDECIDED = ("The {statistic}'s interval reaches both sides of a limit of the band: more samples decide it; "
                       "tolerances do not move a central value.")
MORE_SAMPLES_STATISTIC = ("run n = {n:,} samples",
                          "the {statistic}'s interval straddles a limit; this n would decide it if the estimate held")
REDESIGN_STATISTIC = ("move the {statistic} ({value:.4g} {unit}) into the band [{lower}, {upper}] {unit}: the nominal "
                      "design, or the model, must change",
                      "a central value: tightening tolerances narrows the units about it, it does not move it")


def their(n: int) -> str:
    """The possessive for ``n`` tolerances."""
    return "its" if n == 1 else "their"
