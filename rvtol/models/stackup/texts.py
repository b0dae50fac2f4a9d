"""What the stack-up sections say: their prose and the layout of each result of the stack-up capabilities.

``layout(result, options) -> list of blocks`` (:mod:`rvtol.blocks`), named by
:mod:`rvtol.models.stackup.analyses`.
"""
from __future__ import annotations

import numpy as np

from ...blocks import Figure, Table, Text, figure_png
from ...units import label
from ...stacking.chain_conventions import BASIS

GRAPH = "{description}\n\nModel: {model}. Transform T = Trans × Rot ({rotation})."
EXACT, SMALL = "exact rotation Rz(γ)·Ry(β)·Rx(α)", "small-angle I + [ω]×"

SEQUENCES = ("Every sequence evaluates the Monte Carlo factor samples of this study (paired comparison). A sequence "
             "decides which fit locates each part; the fits left over close the loop and appear as '<fit>_misfit' "
             "outputs (radial and tilt misfit, and for clearance fits the assembly margin c⁺/2 − end-point offset: "
             "negative means the part cannot go in without force).\n\n{descriptions}")

DOMAINS = ("Mean vector and standard deviations derived in closed form (uniform in the domain; truncated normal: plane "
           "by quadrature, axis and clearance in closed form) beside the same moments of {n} samples drawn inside the "
           "domain. 'z' is (sampled − derived)/standard error of the sampled mean or σ (σ's from the sample fourth "
           "moment, valid for any distribution); |z| > 4 would contradict the derivation.")
FEW = ("{name}: only {few} of the {n} samples deviate from zero (e.g. a fit whose clearance is almost never positive). "
       "Moments resting on fewer than {min_moving} samples are ruled by a handful of rare values and their standard "
       "errors are unreliable, so no z is given.")
CLEARANCE = ("{name}: largest clearance {c:.4g} µm → worst radial offset {offset:.4g} µm, worst tilt {deg:.4g}° "
             "({mrad:.4g} mrad); E[c⁺²] = {ms:.4g} µm².")

LINEAR = ("The chain is linearised analytically at the nominal point (small-displacement torsors carried through the "
          "assembly program). Signed KC components get the first-order mean, RSS σ (±3σ) and the arithmetic worst "
          "case; radial offsets and tilts (norms of a pair) get the exact worst case of the linearised pair over the "
          "tolerance box and the 99.73 % quantile of its normal RSS distribution; ‖e‖/‖ε‖ get a worst-case bound and "
          "the RSS rms. Loop-method sign of a contributor: '+' positive accumulator (raises the KC), '−' negative "
          "accumulator (compensates), '0' uncorrelated. Clearance floats enter through their derivative at the "
          "centred position, i.e. as the disc's circumscribed square: linear worst cases of floats are conservative "
          "by up to √2, and clearance × position terms are absent from the linearisation (see the Monte Carlo).")
LINEAR_TABLE = ("Linearised worst case / RSS beside Monte Carlo (display units of each output; blank where a figure "
                "does not apply)")
CONTRIBUTORS = {"dof": "loop-method sign and accumulator from the derivative",
                "norm": "derivatives and signs of the pair's two components",
                "weighted": "shares of the weighted magnitude"}


def graph(res, o) -> list:
    m = res.model
    return [Text(GRAPH.format(description=m.assembly.description, model=m.describe(),
                              rotation=EXACT if m.rotation == "exact" else SMALL)),
            Figure(figure_png(res.plot()), "Parts (in placing order), features, fits and deviation flows"),
            Table(res.flows, "Deviation flows (doc 003 types f1–f5)"),
            Table(res.fits, "Fits: MDD/MgD/Mgg from the datum flags; clearance fits float (f4)"),
            *([Table(res.dimensions, "Dimensions and where each number comes from")] if not res.dimensions.empty
              else []),
            Table(res.sequences, "Assembly sequences")]


def sequences(res, o) -> list:
    text = SEQUENCES.format(descriptions="\n".join(f"{s}: {res.descriptions[s]}" for s in res.sequences))
    blocks = [Text(text),
              Table(res.to_frame(), "Output statistics per sequence (display units; P99.73 = 99.73 % quantile)"),
              Figure(figure_png(res.plot()), "Outputs both sequences share")]
    ok = res.assemblability()
    if len(ok):
        blocks.append(Table(ok, "Assemblability where a clearance fit closes the loop"))
    return blocks


def domain(dm_, n: int) -> list:
    """One domain's blocks (``dm_``: a :class:`.domain_check.DomainMoments`)."""
    from .domain_check import MIN_MOVING
    from .domains import ClearanceFit, ParallelPlaneZone

    d, name = dm_.domain, dm_.name
    blocks = [Table(dm_.moments, f"{name}: {dm_.description}", "{:.5g}")]
    if dm_.few:
        few = " and ".join(f"{v} ({k})" for k, v in dm_.few.items())
        blocks.append(Text(FEW.format(name=name, few=few, n=n, min_moving=MIN_MOVING)))
    if isinstance(d, ParallelPlaneZone):
        blocks.append(Figure(figure_png(dm_.plot()), f"{name}: uniform samples, exact domain and its box"))
    if isinstance(d, ClearanceFit):
        wc = dm_.worst_case
        blocks.append(Text(CLEARANCE.format(name=name, c=d.max_clearance() * 1e3, offset=wc["radial_offset"] * 1e3,
                                            deg=np.degrees(wc["tilt"]), mrad=wc["tilt"] * 1e3,
                                            ms=d.clearance_mean_square() * 1e6)))
    return blocks


def domains(res, o) -> list:
    return [Text(DOMAINS.format(n=res.n))] + [b for d in res.domains for b in domain(d, res.n)]


def linear(res, o) -> list:
    blocks = [Text(LINEAR), Table(res.to_frame(), LINEAR_TABLE, "{:.4g}"),
              Text("Columns by kind — " + "; ".join(f"{k}: {v}" for k, v in BASIS.items()) + ".")]
    for out in res.outputs:
        if out.top is None:
            continue
        lin = out.linear
        blocks.append(Table(out.top, f"{out.name}: largest contributors ({CONTRIBUTORS[lin.form]}; derivative in "
                                     f"{label(lin.unit)} per factor unit; worst-case and variance shares in %)",
                            "{:.4g}"))
        if out.name in res.figures:
            blocks.append(Figure(figure_png(out.plot(res.top)), f"{out.name}: contributions"))
    return blocks
