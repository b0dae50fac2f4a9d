"""What the stack-up sections say: their prose and the layout of each result as report blocks.

``conventions`` lays out a :class:`~rvtol.stacking.beside_monte_carlo.ConventionsComparison`, ``tails`` a
:class:`~rvtol.stacking.beside_monte_carlo.TailProbabilities`; the analyses (:mod:`rvtol.stacking.analyses`) name them.
"""
from __future__ import annotations

from ..blocks import Figure, Table, Text, figure_png
from ..units import label

CONVENTIONS = ("The conventions engineers and peer tools quote, beside this study's Monte Carlo. Linearised rows use the "
               "output's gradient at the nominal point and each factor's band (its drawing limits where written in "
               "drawing notation); the true worst case is the extreme of the model itself over the bands (bounded "
               "optimisation). RSS reads every band as ±3σ of a centred normal; MRSS inflates it (Bender's 1.5; the "
               "handbook's C_f = 1 + ½(T_wc − T_rss)/(T_rss(√n − 1))); the statistical rows use each factor's own "
               "distribution; the 6σ rows treat mean shifts arithmetically (static) or as a wider σ (dynamic, "
               "σ/(1 − k)), and the 1.5σ-shift convention reads every band as a ±6σ process shifted 1.5σ. Every row "
               "that adds variances takes the spec's correlation (of the normals a band is read as, or Pearson's of "
               "the distributions under the copula), and each row's note says what it leaves out. Only the Monte "
               "Carlo enters the verdict.")
CONTRIBUTORS = ("{output}: contributors (a: sensitivity; k = |μ − band centre|/t; Cp, Cpk of each factor's distribution "
                "against its band; shares of the worst case and of the RSS)")
PERCENTILES = "{output}: Monte Carlo percentiles of the study's choice with {confidence:.0%} order-statistic intervals"
INTERVALS = "{output}: each convention's interval (Monte Carlo rows in orange), limits dashed"

TAILS = ("Estimates, not demonstrations, by OpenTURNS in the study's own standard-normal space: FORM (the most "
         "probable failure point u*, β = |u*|, P ≈ Φ(−β): exact for a linear output of normal factors), SORM "
         "(FORM corrected by the curvatures at u*), multi-FORM (several design points), importance sampling "
         "about u*, subset simulation and directional sampling (any shape of failure domain), each sampling "
         "estimate with its standard error. A result that is no estimate — a method that could not run, a "
         "standard error negative, NaN or 0, no sample beyond the limit, a coefficient of variation above 1/3 (its "
         "±3 standard errors reach 0), a SORM value above the probability of the whole space beyond its β — is "
         "shown as \"not estimated\" with its reason and compared with nothing. Estimates that disagree beyond "
         "three standard errors are flagged; "
         "the reference is the most precise sampling estimate not under suspicion (importance sampling about "
         "one point is blind to failure regions far from it). All rest on the factors' distributions (their "
         "tails extrapolated, not measured) and none enters the verdict, which is the Monte Carlo's: where it "
         "sees no failure it only bounds the ppm.")
TAIL_TABLE = ("Probability beyond each limit: the Monte Carlo (counted; the verdict uses it) and OpenTURNS' estimates "
              "from the distributions, the reference marked ({confidence:.0%} interval of the Monte Carlo)")
FAILURE_POINTS = ("The most probable failure points (each factor in its unit): the combination of deviations most likely "
                  "to reach the limit")


def conventions(res, o) -> list:
    blocks = [Text(CONVENTIONS)]
    for out, oc in res.outputs.items():
        sc = oc.conventions
        u = label(sc.unit)
        frame = oc.table().rename(columns={"low": f"low [{u}]", "high": f"high [{u}]", "half_width": f"± [{u}]",
                                           "centre": f"centre [{u}]", "sigma": f"σ [{u}]"})
        blocks += [Table(frame, f"{out}: stack-up conventions (gradient: {oc.gradient}; y at the band centres "
                                f"{sc.y_centre:.6g} {u})"),
                   Table(sc.factors, CONTRIBUTORS.format(output=out)),
                   Table(oc.percentiles, PERCENTILES.format(output=out, confidence=res.confidence)),
                   Figure(figure_png(res.plot(out)), INTERVALS.format(output=out)),
                   *[Text("Note: " + n) for n in sc.notes]]
    return blocks


def tails(res, o) -> list:
    blocks = [Text(TAILS), Table(res.to_frame(), TAIL_TABLE.format(confidence=res.confidence))]
    blocks += [Text("Disagreement: " + f) for f in res.disagreements()]
    pts = res.failure_points()
    if len(pts):
        blocks.append(Table(pts, FAILURE_POINTS))
    return blocks
