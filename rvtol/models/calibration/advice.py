"""What the calibration says about measuring: which measurement tells each parameter apart from the others, and
why a group of parameters looks alike to the measured curves — sentences :mod:`.parameters` attaches to its
parameters and :func:`.parameters.separation_advice` fills (``str.format`` fields named after its values).

A leaf module (no imports): the fit writes these into its diagnostics while it runs.
"""

#: what measurement tells each element family (compliance scale) apart from the others
FAMILY_SEPARATED_BY = {
    "sun_support": "a radial stiffness test of the input shaft's support",
    "sun_planet_mesh": "a first-stage mesh stiffness test (sun and one planet on a fixture)",
    "turning_arm_bearings": "a load–deflection test of one needle bearing, or a TE curve under load fitted with the "
                            "part errors (studies/calibration.md)",
    "crank_support_bearings": "a load–deflection test of the crank support bearings in the carrier",
    "cycloid_pin": "a pin-contact load–deflection test, or a TE curve under load fitted with the part errors "
                   "(studies/calibration.md)",
    "carrier_housing_bearing": "a radial/tilt stiffness test of the main bearing",
    "crank_bending": "a bending test of one crankshaft between its bearings",
    "crank_torsion": "a torsion test of one crankshaft",
    "carrier": "a torsion test of the carrier alone (flange against end plate)",
    "pin_groove": "a pin-in-groove load–deflection test",
    "disc_web": "a torsion test of one disc between its crank holes and its tooth ring",
    "input_shaft": "a torsion test of the input shaft",
}
#: a family without its own entry; every family at once
FAMILY_DEFAULT = "a component test of that element"
ALL_FAMILIES_SEPARATED_BY = "component tests of each family"

#: what measurement tells each effective clearance apart
CLEARANCE_SEPARATED_BY = {
    "crank_bearing": "a radial-clearance gauge reading of the needle bearings",
    "crank_support": "a radial-play reading of the crank support bearings",
    "carrier_housing": "a radial-play reading of the main bearing",
    "pin": "pin-diameter and pin-circle measurements",
}
FRICTION_SEPARATED_BY = ("the loop's width away from zero torque, both branches measured over a wide torque range "
                         "(friction widens it in proportion to the torque; a clearance opens it at zero torque only)")
FACTOR_SEPARATED_BY = "a direct measurement of that part error"
#: what tells a measurement's angle offset apart, by whether it is a torsion curve (else a TE curve)
OFFSET_SEPARATED_BY = {True: "measuring both torque directions",
                       False: "an absolute zero of the TE encoders (a known reference position)"}

#: why a group of parameters looks alike, by the reason separation_advice finds
LOOK_ALIKE = {
    "same_path": ("their deflections add along the same torque path with nearly the same load law, so the curve "
                  "measures little more than a weighted sum of their compliances"),
    "play": "both open play at zero torque, so the torsion curve measures their combined backlash",
    "offset": ("a clearance raises the positive-torque branch and lowers the negative one; with torques of one sign "
               "that is an offset"),
    "shift_and_scale": ("a clearance shifts each branch by a constant where a compliance scales the elastic angle; "
                        "they separate only as far as the curve covers a wide torque range in both directions"),
    "proportional": "their effects on this measurement are nearly proportional",
}
SEPARATION = ("{why}. To separate them: {measurements}; or hold all but one at a known value (leave it out of the "
              "parameters).")
SEPARATED_BY_ONE = "{name} — {measurement}"
