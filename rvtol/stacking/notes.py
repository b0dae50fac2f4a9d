"""The notes the stack-up computations write into their results (:mod:`.conventions`, :mod:`.tail`): templates
they fill with their numbers (``str.format`` fields named after them).

A leaf module (no imports): the computations format these while they run (the notes are recorded in
summary.json); the layout of the results is :mod:`.texts`.
"""

# ---------------------------------------------------------------- conventions: notes of the whole comparison
UNDEFINED_DERIVATIVE = ("the model's derivative is undefined (NaN/∞) for {names}: the central difference of its "
                        "one-sided slopes is used instead")
KINKED_FACTOR = ("{name}: the output has a kink at the nominal point (one-sided slopes D⁺ = {up:.4g}, D⁻ = {down:.4g} "
                 "per base unit): the worst case takes the side that hurts")
KINKED_ZONE = ("position zone {zone}: the output has a kink at the zone's centre (a norm: per unit radius it rises at "
               "most {hi:.4g} and falls at most {lo:.4g}); it is taken by its radius in the direction that hurts (worst "
               "case), as ±radius × the larger slope (RSS, statistical rows: an approximation of a one-sided effect)")
ZONE_BONUS = "position zone {zone} at {modifier}: radius {radius:.6g} at the sizes' band centres, growing with " \
             "the bonus of {sizes}"
DATUM_SHIFT = ("datum feature {datum} at MMB: its departure from MMB shifts {zones} together — one translation of the "
               "pattern (ASME Y14.5 simultaneous requirement; a zone marked separate, SEP REQT, shifts on its own), radius {radius:.6g} at its band "
               "centre growing with that departure, not a bonus of each zone (the distances within the pattern do not "
               "change with it); per unit of shift the output rises at most {hi:.4g} and falls at most {lo:.4g}; the "
               "worst-case rows take it, the Monte Carlo does not sample it (how the parts are made, not where they "
               "sit on the datum's simulator)")
PATTERN_SHIFT = ("datum feature {datum} at MMB shifts {zones} together: one translation of the pattern, anywhere within "
                 "half the datum's departure from MMB (ASME Y14.5 simultaneous requirement)")
DATUM_SHIFT_SEPARATE = ("datum feature {datum} at MMB, a separate requirement (SEP REQT) of {zones}: its departure from "
                        "MMB shifts that zone on its own, radius {radius:.6g} at its band centre; per unit of shift the "
                        "output rises at most {hi:.4g} and falls at most {lo:.4g}")
PATTERN_SHIFT_SEPARATE = ("datum feature {datum} at MMB shifts {zones} on its own (a separate requirement, SEP REQT), "
                          "anywhere within half the datum's departure from MMB")
MRSS_FEW = "MRSS (handbook) needs at least two contributors"
DYNAMIC_UNDEFINED = "a factor's mean lies outside its band (k ≥ 1): the dynamic RSS is undefined"

# ---------------------------------------------------------------- conventions: the note of each row
ZONES_AS_DISCS = " (position zones as discs)"
KINKED_ONE_SIDED = "; kinked contributors by the side that hurts (one-sided)"
ZONES_WITH_BONUS = "; zones at MMC/LMC with their bonus"
PATTERN_SHIFTS = "; each datum-feature shift as one translation of its pattern"
WORST_CASE = "every factor at the end of its band{zones}"
RSS = "every band read as ±3σ of a centred normal{sided}{correlation}"
RSS_SIDED = ("; kinked contributors, zones at MMC/LMC and datum-feature shifts as equal-bilateral ±(radius or half "
             "band) × the slope that hurts (handbook)")
MRSS = "C_f = {cf:.4g} × RSS{wider}"
MRSS_WIDER = " — wider than the worst case (few contributors)"
STATISTICAL = "mean and σ of each factor's own distribution{correlation}{kinked}"
CORRELATION_OF_NORMALS = "; the spec's correlation included (of the normals the bands are read as)"
CORRELATION_OF_DISTRIBUTIONS = ("; the spec's correlation included (Pearson's, of the distributions under the "
                                "Gaussian copula)")
CORRELATION_LEFT_OUT = " — except for the one-sided {names}, taken as independent (no sign to correlate)"
STATISTICAL_KINKED = "; kinked contributors as ±(largest one-sided slope)·σ, no mean shift (an approximation)"
SIX_SIGMA_STATIC = "the factors' mean shifts added arithmetically"
SIX_SIGMA_DYNAMIC = "each σ inflated by Cp/Cpk = 1/(1 − k)"
LINEARISED = ("; linearised at the nominal point: the output's curvature is left out (its mean shift {shift:+.4g} and "
              "skewness: the second-order rows)")
SIX_SIGMA_SHIFT = "every band a ±{width:g}σ process (Cp {cp:g}) shifted {shift:g}σ (Cpk {cpk:g})"

# ---------------------------------------------------------------- tail: the estimates' notes
NOMINAL_FAILS = "the nominal point itself fails: β < 0"
FORM_COBYLA = "Cobyla (derivative-free): Abdo-Rackwitz failed from the origin and from a point off it"
FORM_OUT_OF_REACH = ("no point of the limit state: every factor is bounded and no corner of their supports reaches the "
                     "limit — out of reach, P = 0")
FORM_NONE = ("Abdo-Rackwitz and Cobyla found no point of the limit state (a failure domain they cannot reach from the "
             "origin): no FORM estimate")
SORM_UNDEFINED = "Breitung's formula is undefined here (a curvature ≤ −1/β)"
SORM = "Breitung; {others}"
SORM_OTHER = "{name} {ppm:.4g} ppm"
SORM_OTHER_UNDEFINED = "{name} undefined"
MULTI_FORM_ONE = "{n} design point(s) found: nothing beyond FORM"
MULTI_FORM = "{n} design point(s), β = {betas}"
IS_NO_POINT = "no design point to sample about"
IS = "N = {n} about u*"
SUBSET = "{n} samples per level, p₀ = 0.1{levels}"
SUBSET_LEVELS = ", {levels} levels"
DIRECTIONAL = "{n} directions, root by Brent (safe and slow)"
FAILED_EVALUATIONS = "{n} evaluations could not be made and count as failures"
COULD_NOT_RUN = "could not run: {why}"
NOT_ESTIMATED = "not estimated: {why}"
NOT_A_PROBABILITY = "the method returned {shown}, not a probability"
ABOVE_THE_BALL = ("the method returned {shown}, more than the whole space beyond the sphere of radius β = {beta:.4g} "
                  "(P(χ²_{k} > β²) = {ball:.3g} ppm), which holds every failure domain whose nearest point lies at β")
SE_UNDEFINED = "the method returned {shown}: its standard error is undefined (negative or NaN)"
NO_FAILURE_SEEN = "no sample reached the limit ({shown}): that bounds the probability, it does not estimate it"
SE_ZERO = "the method returned {shown}: a standard error of 0 (degenerate weights: no spread to state an error from)"
COV_TOO_LARGE = ("the method returned {shown}: its coefficient of variation {cov:.2g} exceeds {max:.2g} (its ±{k:g} "
                 "standard errors reach 0: it cannot tell the probability from 0)")
DISAGREE = ("{a} {a_ppm:.4g} ± {a_se:.2g} ppm and {b} {b_ppm:.4g} ± {b_se:.2g} ppm differ by more than {k:g} combined "
            "standard errors")
OUTSIDE_REFERENCE = ("{method} {ppm:.4g} ppm lies outside {k:g} standard errors of the reference ({ref} {ref_ppm:.4g} ± "
                     "{ref_se:.2g} ppm)")
DOMAIN_ROW = ("the arithmetic worst case with the GD&T domains the drawing gives, not the box of the factors' bands: a "
              "composite frame's pattern over the frame itself (every feature in its ⌀T₁ zone and in a ⌀T₂ framework "
              "anywhere, not only s + e, |s| ≤ (T₁ − T₂)/2: rvtol.patterns), a form within its size's envelope "
              "(Rule #1: rvtol.envelopes); the other factors as in the arithmetic row — {parts} (the true extreme "
              "searches the bands)")
DOMAIN_SKIPPED = ("{domains}: taken by the bands only (a bonus, a datum shift or an undefined derivative on the same "
                  "factors) — a composite frame admits patterns its decomposition does not generate (up to ≈ 15 % more "
                  "in a worst case), an envelope fewer (sizes and forms it excludes)")
ENVELOPE_VIOLATED = ("{n} of {total} sampled parts break Rule #1 ({form} above {size}'s departure from MMC): the Monte "
                     "Carlo describes the parts as produced; an inspection to the drawing rejects these")
FRAMEWORK_ROTATES = ("pattern {pattern}'s feature-relating line references {datums}: its framework may also rotate about "
                     "the primary datum's axis, which rvtol does not model (a translation only) — every row "
                     "understates an output that turns with the pattern; give the line its secondary datum "
                     "(⌀T₂ A B) if the drawing has one, or each feature's basic position (basic = …) for the worst case "
                     "over the frame to include it")
FRAMEWORK_ROTATION_IN_ROW = ("pattern {pattern}'s feature-relating line references {datums}: its framework may also "
                             "rotate about the primary datum's axis — the worst case (GD&T domains) row includes a small "
                             "rotation about the pattern's centre (from the features' basic positions); the Monte Carlo "
                             "and the other rows translate it only")
