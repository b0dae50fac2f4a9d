"""What the reproduction sections say: their prose and the layout of each document's comparison.

``layout(result, options) -> list of blocks`` (:mod:`rvtol.blocks`), one per analysis of
:mod:`.analyses`; the library's layouts are reused where a section shows what the library computes.
"""
from __future__ import annotations

from rvtol.plugin import Figure, Table, Text, figure_png, stiffness_texts, transmission_texts

from .printed import RULE

#: the mapping in plain words, for the report
MAPPING = (
    "The RV-80E transmission-error model of doc 000 stands in for the BX40E (doc 002 gives no BX40E "
    "geometry). Doc 002's 2-D angles are read as tilts about the datum x axis, perpendicular to the reducer "
    "axis: a tilt δ moves an axis point at axial distance L from the tilt pivot by (0, −δ·L) in the carrier "
    "frame. Crankshaft KC1 / KC3 become carrier crank-hole position errors of RV-80E cranks 1 / 2 (E_ca, "
    "β_ca; crank 3 exact); cycloid gear KC2 / KC4 displace disc 1 / 2 relative to its cranks by the gear's "
    "own tilt relative to its crank, (δ_gear − δ_crank)·L, on all three crank holes (E_h, β_h). Every other "
    "error of the TE model is zero, so at Q = ∞ the reducer is error-free (doc 002's 12.5 arcsec floor comes "
    "from error sources it does not describe). TE is computed quasi-statically over one output revolution "
    "at 3 % of rated torque.")


# --------------------------------------------------------------------------- doc 000
PRINTED_TE = ("Printed sensitivities (doc 000 §4) against rvtol's over the same e range (reasons in "
              "studies/transmission_error.md)")


def transmission_error(res, o) -> list:
    blocks = transmission_texts.sensitivity(res.sensitivity, o, res.ranking, "the document's class")
    if len(res.printed):
        blocks.append(Table(res.printed, PRINTED_TE, "{:.4g}"))
    return blocks + transmission_texts.linearity_and_notes(res.sensitivity)


# --------------------------------------------------------------------------- doc 001
LOST_MOTION = ("rvtol evaluates the document's formulas with the document's printed inputs (design "
               "lost_motion_doc_example, spec lost_motion_doc_example: E_ws/E_wi = −0.05/−0.10 mm, Δa = 0.02 mm, ΔF_r "
               "= 0.01 mm, α = 20°, d1 = 50 mm; a = 10 mm, z_c = 40, K1 = 0.8, Δr_c = 0.005 ± 0.001 mm, Δr_p = 0.003 ± "
               "0.0005 mm; Δ = 0.02 ± 0.005 mm, K = 1.5, r = 30 mm; i = 100). Printed figures from {path}. "
               "'Reproduced' — {rule}")
NOT_DOC_DESIGN = ("Note: this study's design is not the document example ('{name}'); the reasons refer to the "
                  "document's inputs.")


def lost_motion(res, o) -> list:
    from .doc001_lost_motion import DOC_DESIGN_NAME

    blocks = [Text(LOST_MOTION.format(path=res.printed.path, rule=RULE))]
    if not res.doc_design:
        blocks.append(Text(NOT_DOC_DESIGN.format(name=DOC_DESIGN_NAME)))
    return blocks + [Table(res.table, "Printed figures of doc 001 against rvtol")]


# --------------------------------------------------------------------------- doc 002
READINGS = ("Readings rvtol uses where doc 002 is silent: C(k) measures the KC installed at step k; C(4) = I (each KC "
            "against the housing datum); Q(4) = Q·I on C(4)x; no stage cost (Q(k) = 0, k < 4); R(k) = 5 on every "
            "installed KC, 1000 on KCs not yet installed; B = F; the adjustment follows the installation and "
            "measurement of each part; effort = sqrt(Σ|u(k)|²). The 3-D case uses the same weights on x, y, z and "
            "W = I except crankshaft 2 (turned 180° about the reducer axis). Printed figures from {path}. "
            "'reproduced' — {rule}")
TE_MAPPING = ("TE of the example assembly — rvtol's mapping: {mapping} Lever arm L = {lever:g} mm: the disc mid-planes "
              "lie ±6 mm from the point midway between the two discs (face width 12 mm, doc 000 Table 1), taken as "
              "the tilt pivot; the opposite sign at the two discs is not represented. TE is proportional to L here, "
              "so only the reductions against Q = 0 are comparable with Table 4.")


def adjustment(res, o) -> list:
    blocks = [Text(READINGS.format(path=res.printed.path, rule=RULE)),
              Table(res.table, "Printed numbers of doc 002 and rvtol's values", "{:.4g}")]
    if res.te is not None:
        blocks += [Text(TE_MAPPING.format(mapping=MAPPING, lever=res.lever_arm)),
                   Table(res.te.drop(columns=["Q"]).rename(columns={"Q shown": "Q"}),
                         "TE of the example assembly at the Q of Table 4 (quasi-static, 3 % rated torque)", "{:.4g}"),
                   Figure(figure_png(res.plot()), "TE peak-to-peak of the example assembly against Q, beside doc "
                                                  "002's Table 4")]
    return blocks


# --------------------------------------------------------------------------- doc 003
SHAFT_HOLE = ("Fit {fit!r}: largest clearance over the size bands {cmax:.4g} mm, engagement {length:g} mm. WC = the "
              "model at that clearance with the shaft pushed to the wall (both ends one side, or opposite sides; the "
              "larger output). 'reproduced' is judged for each reading (the readings it holds for in brackets): "
              "{rule}")


def shaft_hole(res, o, p) -> list:
    blocks = [Text(SHAFT_HOLE.format(fit=res.fit.name, cmax=res.max_clearance, length=res.fit.length, rule=RULE)),
              Table(res.table, "Printed figures and what rvtol computes", "{:.4g}")]
    if res.planar is not None:
        name = p.zone_name
        blocks += [Table(res.planar.record, f"{name}: the document's printed planar-zone formulas against the "
                                            "derivation (lengths mm, angles rad)", "{:.4g}"),
                   Figure(figure_png(res.planar.plot()), f"{name}: uniform samples, exact domain, its box and the "
                                                         "printed box")]
    return blocks


# --------------------------------------------------------------------------- doc 004
NO_TORQUE = " Doc 004 does not state its torque."
STIFFNESS_TITLE = "Doc 004's printed figures against rvtol"
MODIFICATIONS = (" Table 3 keeps the radial clearance Δr_p − ΔR_p = 0.02 mm. rvtol's 'angular backlash' 2·n0/r_c' (rad) "
                 "with n0 = Δr_p − √(1−K1²)·ΔR_p the normal clearance at φ0 = arccos K1 is the quantity that matches "
                 "the document's j_C1 column (printed as mm); the clearance formula Δ(φ_k) itself is measured from "
                 "first contact and is nanometres at the first pin. Each sweep holds the other modification at zero.")
ERRORS = (" Errors swept over ±{range:g} µm in {step:g}-µm steps, the other error zero. Doc 004's Δ2 subtracts both "
          "errors from the clearance, so positive errors close it (more pins carry load, smaller θ).")
GEOMETRY = [("R_p", "pin circle radius R_p (Table 2, Table 4)"), ("a", "eccentricity a (Table 4)"),
            ("b", "cycloid width b (Table 4)")]


def stiffness_header(res) -> str:
    return stiffness_texts.header(res.breakdown.angles) + NO_TORQUE


def stiffness_angles(res, o) -> list:
    return stiffness_texts.angles(res.breakdown.angles, o, stiffness_header(res),
                                  "Torsion-angle components at the output: rvtol against doc 004's Table 5")


def stiffness_geometry(res, o) -> list:
    blocks = [Text(stiffness_header(res) + " k_b uses |T'| (see the model notes); K_B is summed over the pins loaded "
                                           "at T.")]
    for param, what in GEOMETRY:
        blocks += [Table(res.geometry.frames[param], f"Against the {what}", "{:.4g}"),
                   Figure(figure_png(res.geometry.plot(param, "force")),
                          f"Largest pin force and contact pairs against {param}"),
                   Figure(figure_png(res.geometry.plot(param, "theta")), f"θ_Σ, θ2 and K_B against {param}")]
    return blocks


def stiffness_modifications(res, o) -> list:
    m = res.modifications
    legend = "; ".join(f"{i + 1} {name.lower()}" for i, name in enumerate(m.combinations))
    return [Text(stiffness_header(res) + MODIFICATIONS),
            Table(m.clearances(), f"Doc 004 Table 3, clearances ({legend})", "{:.4g}"),
            Table(m.loads(), "Doc 004 Table 3 — largest pin force and contact pairs", "{:.4g}"),
            Table(m.pairs, "Contact pairs of the five combinations at fractions of the torque (doc 004 does not state "
                           "its torque)"),
            Table(m.sweep_equidistance, "θ against the equidistance modification Δr_p (ΔR_p = 0)", "{:.4g}"),
            Table(m.sweep_moved, "θ against the moved-distance modification ΔR_p (Δr_p = 0)", "{:.4g}"),
            Figure(figure_png(m.plot("equidistance")), "θ_Σ and θ2 against Δr_p (µm)"),
            Figure(figure_png(m.plot("moved_distance")), "θ_Σ and θ2 against ΔR_p (µm)")]


def stiffness_errors(res, o) -> list:
    e = res.errors
    step = 2 * e.error_range / (e.points - 1) * 1e3
    return [Text(stiffness_header(res) + ERRORS.format(range=e.error_range * 1e3, step=step)),
            Table(e.stats, "Sensitivity of the largest pin force and of θ_Σ to the pin errors", "{:.4g}"),
            Table(e.pin_circle, "Against δR_p", "{:.4g}"),
            Table(e.pin_radius, "Against δr_p", "{:.4g}"),
            Figure(figure_png(e.plot("force")), "Largest pin force against the pin errors"),
            Figure(figure_png(e.plot("theta")), "θ_Σ against the pin errors")]


def stiffness_reproduction(res, o) -> list:
    return [Text(f"One row per printed figure (printed figures from {res.printed.path}); the reason column says why. "
                 f"'reproduced' — {RULE}"),
            Table(res.reproduction, "Reproduction table", "{:.4g}")]


def stiffness_contact(res, o) -> list:
    return stiffness_texts.contact(res.breakdown.contact, o)


#: the sections of stiffness_reproduction before its own: key -> (title, layout)
STIFFNESS_SECTIONS = {
    "stiffness_breakdown": ("Elastic torsion angle θ_Σ = θ1 + … + θ5 (doc 004, Table 5)", stiffness_angles),
    "stiffness_contact": (stiffness_texts.CONTACT_TITLE, stiffness_contact),
    "stiffness_geometry": ("Geometry: pin circle radius, eccentricity, width (Tables 2 and 4)", stiffness_geometry),
    "stiffness_modifications": ("Profile modifications (Table 3 and the Δr_p, ΔR_p sweeps)", stiffness_modifications),
    "stiffness_errors": ("Pin circle radius and pin radius errors (δR_p, δr_p)", stiffness_errors),
}
