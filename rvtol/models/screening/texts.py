"""What the screening section says: its prose and the layout of a
:class:`.beside_torsion_curve.ScreeningComparison`.

``layout(result, options) -> list of blocks`` (:mod:`rvtol.blocks`), named by
:mod:`rvtol.models.screening.analyses`.
"""
from __future__ import annotations

from ...blocks import Figure, Table, Text, figure_png

INTRO = ("What a sign-off judges is the maker's lost motion: the angle between the mid-points of the hysteresis width "
         "at ±{p:g} % of rated torque, input locked, elastic deflection included (REFERENCE), here from the 20-DOF "
         "torsion curve. Doc 001's formula is a screening estimate of the geometric (zero-load) part only. Both on the "
         "same reducers — {where}: screening estimate (consistent mode) mean {consistent:.3f}′, doc 001 as printed "
         "{document:.3f}′; torsion curve backlash {backlash:.3f}′ and lost motion {lost_motion:.3f}′, of which "
         "{elastic:.3f}′ is elastic deflection within ±{p:g} %. The 20-DOF sun–planet mesh has no backlash, so the "
         "involute-stage play (Δφ12/i, mean {involute:.4f}′) is added to the torsion-curve figures in series (exact "
         "at zero load: plays in series add).")

EVERY_SAMPLE = "every Monte Carlo sample (the study's torsion-curve outputs)"
SUBSAMPLE = "{n} reducers drawn from the Monte Carlo sample (sub-stream screening_subsample)"

COMPOSED = ("One drawing sample drives both: the screening stage {lm!r} reads its seven inputs through the declared "
            "mapping, the torsion stage {tc!r} the full 20-DOF error state. The screening sums its stages' plays; the "
            "20-DOF finds the smallest play of the disc's three degrees of freedom together (a disc that translates "
            "within its needle clearances closes its pins sooner), so with clearances in the pins AND the needle sets "
            "the screening's sum lies above the torsion curve's backlash — a conservative screen.")

UNSEEN_BY_TC = "Not seen by the torsion curve (no 20-DOF counterpart): {names}."
UNSEEN_BY_LM = "Not in doc 001's formula (the screening estimate ignores them; the torsion curve sees them): {names}."
FAILED = ("{bad} of {n} reducers could not be evaluated (e.g. a negative clearance) and are left out of the "
          "comparison.")

RATES = ("Rates at the output per factor: doc 001 as printed, consistent mode, and the 20-DOF torsion curve (central "
         "differences of the backlash and of the lost motion around 2 µm of clearance on the crank bearings and pins)")


def screening(res, o) -> list:
    m = res.means
    every = res.source in ("torsion_curve", "composed")
    where = EVERY_SAMPLE if every else SUBSAMPLE.format(n=res.n_drawn)
    blocks = [Text(INTRO.format(p=res.percent, where=where, **{c: m[c] for c in res.labels}))]
    if res.source == "composed":
        blocks.append(Text(COMPOSED.format(tc=res.stages[0], lm=res.stages[1])))
    if res.unseen_by_tc:
        blocks.append(Text(UNSEEN_BY_TC.format(names=", ".join(res.unseen_by_tc))))
    if res.unseen_by_lm:
        blocks.append(Text(UNSEEN_BY_LM.format(names=", ".join(res.unseen_by_lm))))
    if res.failed:
        blocks.append(Text(FAILED.format(bad=res.failed, n=res.n_evaluated)))
    return blocks + [
        Table(res.statistics, f"Screening estimate and maker's figures on the same {len(res.frame)} reducers (arcmin)"),
        Table(res.rates, RATES),
        Table(res.quantiles, "Reducers at quantiles of the screening estimate"),
        Figure(figure_png(res.plot()), "Per reducer: screening estimate against the torsion-curve lost motion"),
    ]
