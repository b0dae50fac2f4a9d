"""Order-of-magnitude compliance breakdown of an RV-80E-sized reducer with the elements of rvtol.elements.

Run:  PYTHONPATH=. python studies/compliance_elements_rv80e.py

Loads come from the doc 004 torsion-angle model (rvtol.models.stiffness) at the rated output torque
784 N·m, input locked: pin forces, turning-arm bearing forces, the loads on each crank (two eccentrics
and the planet gear) and the torque the cranks put on the input-side end plate.  Each new element is
then evaluated under its share of those loads and its contribution to the output rotation is found by
virtual work, θ_e = Σ f_e·δ_e / T (rvtol.elements.chain).  Dimensions not in the design files are the
ASSUMED values below (see studies/compliance_elements.md).  Nothing here is fitted to a published figure.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from rvtol.design import load_design
from rvtol.elements import carrier_structure as cs
from rvtol.elements import chain, disc_web, pin_groove, shafts
from rvtol.elements.rolling_bearings import BearingPair, NeedleRollerBearing, TaperedRollerBearing
from rvtol.models.stiffness.torsion_angle import ReducerStiffness

ROOT = Path(__file__).resolve().parents[1]
T = 784.0e3                                     # N·mm, rated torque (REFERENCE)

# ---- ASSUMED dimensions (not in data/designs/rv80e_stiffness.toml) ----------------------------------
# crank support bearing: a 32004 X-sized tapered roller bearing (d 20, D 42, T 15, B 15, C 12, e ≈ 0.37);
# internal geometry estimated: 16 rollers of mean diameter 5 mm on d_m = 31 mm, effective length 10 mm
TRB = dict(rollers=16, alpha=math.atan(0.37 / 1.5), length=10.0, pitch_diameter=31.0,
           alpha_inner=math.atan(0.37 / 1.5) - math.radians(4.0))
PRELOADS = (0.0, 1000.0, 2000.0)                # N axial preload of the X pair (1 kN taken as nominal)
# crankshaft: journals Ø20 under the bearings and to the gear, eccentrics Ø26 (needle inner race)
CRANK = dict(stations=(-10.0, 7.5, 30.5, 38.0), d_outer=(20.0, 26.0, 20.0), d_inner=(0.0, 0.0, 0.0))
# pin in housing groove: radial clearance r_g − r_p, groove length carrying one disc's load
GROOVE_CLEARANCES = (0.005, 0.010, 0.020)       # mm
GROOVE_LENGTH = 10.0                            # mm (= disc width b)
# disc web: from the outer edge of the crank holes (a_0 + 17 mm, needle bearing bore Ø34) to the root circle
HOLE_RADIUS = 17.0
# carrier flanges: thickness of the input-side end plate and of the output flange, clamp radius around
# a pillar root
END_PLATE_T, OUTPUT_FLANGE_T, CLAMP_RADIUS = 10.0, 14.0, 20.0
# input shaft between the locked motor brake and the sun gear
INPUT_SHAFT = dict(d=15.0, length=60.0)


def main() -> list[tuple]:
    d = load_design(ROOT / "data/designs/rv80e_stiffness.toml")
    rs = ReducerStiffness.from_design(d)
    E, nu = rs.pins.E, rs.pins.nu
    G = E / (2 * (1 + nu))
    mods = (d["cycloid.equidistance_modification"], d["cycloid.moved_distance_modification"])
    ta = rs.evaluate(T, nominal_mods=mods)
    contact = ta.contacts[0][1]
    loads = rs.crank_loads(contact)
    rows = []

    def add(name, theta, local, note="", nominal=False):
        rows.append((name, float(chain.arcsec(theta)), float(T / theta / 1e3 * math.pi / 10800.0) if theta else
                     math.inf, local, note, nominal))

    # existing doc 004 elements, for context
    for name, th in zip(("involute stage (existing θ1)", "cycloid–pin contact (existing θ2)",
                         "turning-arm bearings, Stribeck closed form (existing θ3)",
                         "crankshafts Ø22 uniform (existing θ4)", "carrier pillars, rigid flanges (existing θ5)"),
                        ta.theta[0]):
        add(name, th, "", "rvtol.models.stiffness", nominal=name.startswith(("involute", "cycloid")))

    # 1. crank support bearings: X pair per crank, loads of the three points of each crank
    z = loads.z                                                       # gear, disc 1, disc 2
    P = loads.loads[0]                                                # (3 cranks, 3 points, 2)
    brg = TaperedRollerBearing(**TRB)
    for pre in PRELOADS:
        pair = BearingPair(brg, brg, (0.0, rs.support_span), "X")
        if pre > 0:
            pair = pair.with_preload_force(pre)
        work = 0.0
        for i in range(3):
            f = np.array([P[i, :, 0].sum(), P[i, :, 1].sum(), 0.0, -(z * P[i, :, 1]).sum(), (z * P[i, :, 0]).sum()])
            sol = pair.solve(f)
            q = sol.q[0]
            u = np.stack([q[0] + q[4] * z, q[1] - q[3] * z], axis=1)  # crank displacement at the points
            work += float((P[i] * u).sum())
        kr = pair.radial_stiffness([1000.0, 6000.0], 0.5 * rs.support_span)
        add(f"crank support bearings, X pair, preload {pre / 1e3:g} kN", work / T,
            f"pair, mid-span, tangent: {kr[0] / 1e3:.0f} N/µm at 1 kN, {kr[1] / 1e3:.0f} N/µm at 6 kN"
            + (f"; Δ = {pair.interference * 1e3:.1f} µm" if pre else ""), "new", nominal=pre == 1000.0)

    # 2. crankshaft, stepped (bending + shear, rigid supports) and torsion
    sh = shafts.SteppedShaft(CRANK["stations"], CRANK["d_outer"], CRANK["d_inner"], E, nu)
    C = sh.flexibility(z, supports=(0.0, rs.support_span))
    bend = sum(float(np.einsum("pd,pq,qd->", P[i], C, P[i])) for i in range(3))
    add("crankshafts, stepped Ø20/Ø26 (bending + shear)", bend / T,
        f"{1 / C[1, 1] / 1e3:.0f} N/µm at an eccentric", "new", nominal=True)
    t1, t2 = loads.torque                                             # (1, 3) each
    tw = 0.0
    for i in range(3):
        a, b = float((t1 + t2)[0, i]), float(t2[0, i])
        tw += a * a * sh.torsional_compliance(z[0], z[1]) + b * b * sh.torsional_compliance(z[1], z[2])
    add("crankshafts, torsion gear → eccentrics", tw / T, f"GJ(Ø20) = {G * math.pi * 20 ** 4 / 32 / 1e6:.0f} N·m²",
        "new", nominal=True)

    # 3. turning-arm needle bearings with load distribution (zero clearance)
    nb = NeedleRollerBearing(rollers=rs.bearing_rollers, length=rs.bearing_length)
    F = loads.bearing_force[0]
    work = sum(float(Fi * nb.solve(Fi).u[0, 0]) for Fi in F)
    add("turning-arm needle bearings, load distribution", work / T,
        f"secant {F.max() / nb.solve(F.max()).u[0, 0] / 1e3:.0f} N/µm at {F.max():.0f} N", "new", nominal=True)

    # 4. pin in housing groove, in series with the disc–pin contact (both discs)
    Fk = contact.force[0][contact.force[0] > 0]
    for c in GROOVE_CLEARANCES:
        w = pin_groove.groove_approach(Fk, GROOVE_LENGTH, rs.pins.r_p, rs.pins.r_p + c, E, nu)
        ang = pin_groove.groove_half_angle(Fk.max(), GROOVE_LENGTH, rs.pins.r_p, rs.pins.r_p + c, E, nu)
        add(f"pin–groove contact, clearance {c * 1e3:g} µm", 2 * float((Fk * w).sum()) / T,
            f"secant {Fk.max() / w.max() / 1e3:.0f} N/µm at {Fk.max():.0f} N; half-angle {math.degrees(ang):.0f}°",
            "new" + ("" if ang < 0.3 else " (contact arc > 0.3 rad: indicative)"), nominal=c == 0.010)

    # 5. disc web
    ri = rs.crank_radius + HOLE_RADIUS
    ro = rs.pins.R_p - rs.pins.r_p - rs.pins.a
    Kw = disc_web.annular_web_stiffness(ri, ro, rs.pins.b, G)
    add("disc webs (two discs)", rs.i_b ** 2 * T / (2 * Kw), f"K_web = {Kw / 1e3 * math.pi / 10800:.0f} N·m/arcmin",
        "new", nominal=True)

    # 6. carrier: pillars with Cowper κ and twist, flexible flanges at the roots
    sec = cs.rectangle(rs.pillar_width, rs.pillar_thickness, nu)
    b0 = cs.equivalent_boss_radius(sec)
    kphi = (cs.boss_rotational_stiffness(b0, CLAMP_RADIUS, END_PLATE_T, E, nu),
            cs.boss_rotational_stiffness(b0, CLAMP_RADIUS, OUTPUT_FLANGE_T, E, nu))
    TB = float(abs(loads.support_torque(rs.crank_radius, rs.support_span)[0, 0]))
    for label, ends in (("rigid flanges", (math.inf, math.inf)), ("flexible flanges", kphi)):
        k = cs.pillar_stiffness(sec, rs.pillar_length, E, nu, ends)
        K = cs.carrier_torsional_stiffness(rs.pillars, rs.pillar_radius, k, section=sec, length=rs.pillar_length, G=G)
        add(f"carrier pillars + twist, {label}", TB * TB / K / T, f"k_pillar = {k / 1e3:.0f} N/µm; T_B = {TB / 1e3:.0f} N·m"
            + (f"; k_φ = {kphi[0] / 1e9:.1f}/{kphi[1] / 1e9:.1f} kN·m/mrad" if label.startswith("flex") else ""),
            "new", nominal=label.startswith("flex"))

    # 7. input shaft twist, input locked at the motor
    Kin = G * math.pi * INPUT_SHAFT["d"] ** 4 / 32 / INPUT_SHAFT["length"]
    add("input shaft twist (reflected by i²)", T / chain.reflected_to_output(Kin, rs.ratio),
        f"K_in = {Kin / 1e3:.0f} N·m/rad, i = {rs.ratio:g}", "new", nominal=True)
    return rows


if __name__ == "__main__":
    rows = main()
    print("| element | θ at 784 N·m (arcsec) | T/θ (N·m/arcmin) | local stiffness | | nominal chain |")
    print("|---|---|---|---|---|---|")
    for name, arc, K, local, note, nom in rows:
        print(f"| {name} | {arc:.3g} | {K:.3g} | {local} | {note} | {'x' if nom else ''} |")
    tot = sum(r[1] for r in rows if r[5])
    print(f"| **nominal chain, all in series** | **{tot:.3g}** | **{784.0 / tot * 60:.3g}** | | | |")
