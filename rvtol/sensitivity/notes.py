"""The notes the sensitivity computations write into their results (:mod:`.surrogate`, :mod:`.given_data`,
:mod:`.global_`): templates they fill with their numbers (``str.format`` fields named after them).

A leaf module (no imports): the computations format these while they run (the notes are recorded in
summary.json and some are raised as warnings); the layout of the results is :mod:`.texts`.
"""

CONSTANT_OUTPUT = "{output}: the output does not vary; its indices are 0."

# ---------------------------------------------------------------- polynomial chaos (surrogate/monte_carlo.py)
PCE_DEPENDENT = ("The inputs are dependent: {pairs}. PCE Sobol indices assume independent factors: these are the "
                 "indices of a surrogate fitted on the dependent sample and read with independent margins, not a valid "
                 "variance decomposition. The delta index (moment-independent, computed on the dependent sample) is "
                 "the valid measure here.")
PCE_POOR_FIT = ("{output}: the polynomial chaos surrogate is not accurate enough (Q² LOO = {q2_loo:.3f}, hold-out = "
                "{q2_holdout:.3f} < {min_q2:g}); its indices could be off by up to {bias:.2f} beyond their intervals")
#: what follows PCE_POOR_FIT, by the on_poor_fit policy
PCE_POOR_FIT_THEN = {
    "raise": ". Use the Saltelli route (sobol) or more samples.",
    "withhold": ". They are withheld (NaN; the surrogate's values are in `raw`): use the Saltelli route (sobol) or "
                "more samples.",
    "warn": ". Read them as indicative only.",
}
PCE_INTERVALS = ("Intervals ({ci}, {resamples} resamples) cover the sampling of the {n} Monte Carlo points given the "
                 "selected terms, not the surrogate's truncation error (see bias_bound).")

# ---------------------------------------------------------------- given data (given_data.py)
GIVEN_DEPENDENT = ("The inputs are dependent ({pairs}): each S1 is the share of variance explained by the factor "
                   "including what it carries of the factors correlated with it; the indices need not sum to ≤ 1. The "
                   "delta index is the moment-independent alternative.")
GIVEN_INTERVALS = ("Intervals (bootstrap, {resamples} resamples) cover the sampling of the {n} points, not the small "
                   "discretisation bias of the classes.")

# ---------------------------------------------------------------- eFAST (global_.py)
FAST_INTERVALS = ("eFAST confidence intervals come from a bootstrap that SALib flags as unreliable for this method "
                  "(SALib issue 649): read them as indicative.")
