"""What the torsion-curve sections say: their prose and the layout of each result of
:mod:`.beside_analytical_models`.

``layout(result, options) -> list of blocks`` (:mod:`rvtol.blocks`), named by
:mod:`rvtol.models.torsion_curve.analyses`.
"""
from __future__ import annotations

from ... import units
from ...blocks import Figure, Table, Text, figure_png

CURVES = ("Carrier torque 0 → +{torque:g} → −… → 0 N·m in {points} steps per quarter, each equilibrium warm-started "
          "from the previous one (doc 000's 20-DOF model, quasi-static). Figures by the maker's definitions "
          "(REFERENCE): rigidity b/a between the rated-torque end points, lost motion between the mid-points at "
          "±{percent:g} % rated, backlash = width at zero torque. ")
FRICTION = ("Coulomb friction of the design's [friction] coefficients opens the loop (friction width at ±{percent:g} %, "
            "rvtol/models/reducer_20dof/friction.py): lost motion reads the mid-points, backlash the width at zero "
            "torque, free play and friction together.")
NO_FRICTION = ("The model has no friction, so the branches coincide away from zero (hysteresis width ~0) and the curve "
               "jumps across the clearances at zero torque.")

#: titles of the torsion_curve analysis' second and third sections
LOST_MOTION_TITLE = "Lost motion against clearances: 20-DOF beside the analytical model (doc 001)"
RIGIDITY_TITLE = "Rigidity: 20-DOF beside the elastic torsion-angle model (doc 004)"

LOST_MOTION = ("Clearances set on all six cycloid–crank bearings (δ_b, the radius of each bearing's free-play circle: "
               "radial internal clearance Δ = 2δ_b) and, separately, as a normal clearance δ at every pin (doc 001's "
               "per-side profile clearance Δr_c, an equidistant modification). The analytical columns add doc 001's "
               "geometric lost motion to the 20-DOF's clearance-free lost motion (the elastic part, which doc 001 "
               "ignores). As printed (K = {K:g}, Δr_c/(a z_c), no disc-to-output ratio) doc 001 predicts {share_b:.3f} "
               "of the 20-DOF's growth with δ_b and {share_c:.3f} with δ; its consistent mode (three bearings 120° "
               "apart give K = 1; flank to flank 2δ/(a z_c); the output turns i_b = {i_b:.4f} times the disc's "
               "rotation) gives the backlash rates. The lost-motion rate is a little higher than the backlash rate: "
               "with clearance, the soft low-load range of the Hertz-type bearing laws (doc 000: k = k0·P^0.1) is "
               "re-entered within ±{percent:g} % rated. The lost-motion rate is fitted from δ_b ≥ 2 µm (at zero "
               "clearance the bearings' zero-load stiffness vanishes).")

RIGIDITY = ("20-DOF, clearance-free: b/a = {rigidity:.1f} N·m/arcmin, secant at +rated T/θ = {secant:.1f} N·m/arcmin "
            "(θ = {theta:.2f} arcsec; virtual-work sum {theta:.2f} arcsec against the solver's {solver:.2f} arcsec).")
TORSION_ANGLE = ("Elastic torsion-angle model (doc 004, part 1) at the same torque: θ_Σ = {own:.2f} arcsec on its own "
                 "RV-80E ({own_rigidity:.1f} N·m/arcmin), {same:.2f} arcsec with doc 000's pin-gear and first-stage "
                 "geometry and no profile modification ({same_rigidity:.1f} N·m/arcmin).")
RIGID_CHAIN = ("Why they differ: the 20-DOF model treats cranks and carrier as rigid bodies (no θ4, θ5) but has the "
               "crank–carrier and carrier–housing bearings, which doc 004 leaves out; its contact laws are doc 000's "
               "k = k0·P^0.1 (force ∝ deflection^1.11) for pins and bearings, against doc 004's Hertz line contact "
               "with logarithmic terms and Palmgren's needle-bearing formula; its involute mesh is doc 000's constant "
               "1.58e5 N/mm against ISO 6336 at low load.")
WITH_CHAIN = ("Both models carry the design's compliance elements (crankshafts, crank support pair, carrier, pin "
              "grooves, disc webs, input shaft: kind compliance_breakdown compares them element by element); they "
              "differ in doc 000's contact laws k = k0·P^0.1 for pins and needle bearings against doc 004's Hertz line "
              "contact and Palmgren's needle-bearing formula, doc 000's constant mesh stiffness against ISO 6336, and "
              "in how the load is shared (the 20-DOF solves it, doc 004 takes it from statics).")

COMPLIANCE = ("Input locked, output torque {torque:g} N·m, clearance- and error-free reducer. Each element's share of "
              "the output angle by virtual work, θ_e = Σ f_e·δ_e / T (the actual forces as the virtual system; the "
              "shares add up to the angle). 20-DOF: doc 000's contact laws with the design's compliance elements in "
              "series with the contacts that carry their loads (table 2); doc 004's model: its components under its "
              "own statics with the same elements. NaN: the model has no such element. Differences between the two "
              "models come from their contact laws (doc 000's k = k0·P^0.1 against doc 004's Hertz/Palmgren/ISO 6336) "
              "and load sharing, not from the chain elements, which both take from rvtol.elements.")


def compliance_title(torque_Nm: float) -> str:
    return f"Compliance chain: output angle per element at {torque_Nm:g} N·m"


def curves(res, o) -> list:
    return [Text(CURVES.format(torque=units.from_base(res.torque, "N*m"), points=res.points, percent=res.percent)
                 + (FRICTION if res.friction else NO_FRICTION).format(percent=res.percent)),
            Table(res.metrics, "Maker's figures of the simulated curves", "{:.4g}"),
            Figure(figure_png(res.plot()), "Torsion curves (whole cycle)"),
            Figure(figure_png(res.plot(zoom=True)), "Torsion curves within ±10 % of rated torque")]


def lost_motion(res, o) -> list:
    return [Text(LOST_MOTION.format(K=res.K, share_b=res.document_share_b, share_c=res.document_share_c, i_b=res.i_b,
                                    percent=res.percent)),
            Table(res.rates, "First-order rates", "{:.4g}"),
            Table(res.crank_bearing, "Crank-bearing clearance", "{:.4g}"),
            Figure(figure_png(res.plot()), "Lost motion against δ_b"),
            Table(res.pins, "Pin clearance", "{:.4g}")]


def rigidity(res, o) -> list:
    asec = lambda v: float(units.from_base(v, "arcsec"))  # noqa: E731
    T = units.from_base(res.torque, "N*m")
    lines = [RIGIDITY.format(rigidity=units.from_base(res.rigidity, "N*m/arcmin"),
                             secant=units.from_base(res.torque / res.angle, "N*m/arcmin"), theta=asec(res.angle),
                             solver=asec(res.solver_angle))]
    comp = res.torsion_angle
    if comp is not None:
        own, same = comp["doc 004 RV-80E (arcsec)"].iloc[-1], comp["doc 000 geometry (arcsec)"].iloc[-1]
        lines.append(TORSION_ANGLE.format(own=own, own_rigidity=T / (own / 60), same=same, same_rigidity=T / (same / 60)))
    lines.append(WITH_CHAIN if res.chain else RIGID_CHAIN)
    blocks = [Text(" ".join(lines)),
              Table(res.breakdown, "20-DOF torsion angle at +rated split by virtual work (T θ = Σ f·d)", "{:.4g}")]
    if comp is not None:
        blocks.append(Table(comp, "Elastic torsion-angle model (doc 004) components at the same torque", "{:.4g}"))
    return blocks + [Table(res.readings_table(), "Rigidity under each reading of the maker's b/a (the Monte Carlo "
                                                 "reports each output)", "{:.4g}")]


def compliance(res, o) -> list:
    Tnm = units.from_base(res.torque, "N*m")
    blocks = [Text(COMPLIANCE.format(torque=Tnm)),
              Table(res.table, "Output angle per compliance family (arcsec)", "{:.3g}"),
              Figure(figure_png(res.plot()), f"Output angle per element at {Tnm:g} N·m")]
    if res.reductions is not None:
        blocks += [Table(res.reductions, "The compliance elements reduced to the 20-DOF contacts (module "
                                         "rvtol.models.reducer_20dof.compliance)", "{:.4g}"),
                   Table(res.sources, "Elements from the design")]
    return blocks

