"""Direct computation of the RV-80E mapping (data/products/rv80e/mapping.md), independent of rvtol's
stack-up and expression code: the reference the sign-off study's composed model is tested against.

Written straight from mapping.md §0–§3 with NumPy (first order: axes as straight lines through their end
points, offsets added as vectors). Values in the drawing's units — µm and deg — as in mapping.md; the
functions take ``v``: {factor name: (n,) array in its own unit} (``values(sample_set)``).
Kept from the retired review script studies/product_rv80e_mapping_check.py.
"""
from __future__ import annotations

import math

import numpy as np

ZB = 40
PHI = np.radians([0.0, 120.0, 240.0])          # crank i at 120°(i−1)
THK = 2 * np.pi * np.arange(ZB) / ZB           # pin k at θ_k = 2π(k−1)/z_b
Z_DISC = {1: +6.0, 2: -6.0}                    # disc mid-planes
L_SPAN = 42.0                                  # support-bearing span, main-bearing span
Z_GEAR = -21.0 - 12.0                          # planet-gear plane


def values(ss) -> dict[str, np.ndarray]:
    """{factor name: (n,) array in the factor's unit} from a SampleSet."""
    X = ss.display_values()
    return {n: X[:, j] for j, n in enumerate(ss.names)}


def c1(design) -> float:
    """√(1 − K1²), K1 = z_b e / R_p."""
    k1 = ZB * design.value("cycloid.eccentricity", "mm") / design.value("pin.circle_radius", "mm")
    return math.sqrt(1 - k1 ** 2)


def rot(v, ang):
    """Rotate 2-vectors (..., 2) by ``ang`` (rad)."""
    c, s = math.cos(ang), math.sin(ang)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def axis_at(v, pre, z, z0=0.0, L=L_SPAN):
    """Offset (n, 2) at z of an axis with end points pre.x1, y1 (z0 + L/2) and pre.x2, y2 (z0 − L/2)."""
    p1 = np.stack([v[pre + ".x1"], v[pre + ".y1"]], -1)
    p2 = np.stack([v[pre + ".x2"], v[pre + ".y2"]], -1)
    return 0.5 * (p1 + p2) + (p1 - p2) * (z - z0) / L


def vec(v, pre):
    return np.stack([v[pre + ".x"], v[pre + ".y"]], -1)


def interp_AB(a, b, z):
    """Between support bearing A (z = −21) and B (z = +21)."""
    return a + (b - a) * (z + 21.0) / 42.0


def unit(deg):
    r = np.radians(deg)
    return np.stack([np.cos(r), np.sin(r)], -1)


# ----------------------------------------------------------------------------- mapping.md §1
def n0(v, design, j):
    return v[f"disc_{j}.profile.equidistance_mod"] - c1(design) * v[f"disc_{j}.profile.moved_distance_mod"]


def pin_gap(v):
    """g_k (n, 40): normal clearance added by pin k in its groove."""
    w = np.stack([v[f"pins[{k}].diameter_in_lot"] for k in range(1, ZB + 1)], -1)
    return v["housing.pin_groove.diameter"][:, None] / 2 - (v["pins.diameter_lot"][:, None] + w)


def ceff(v, j, i):
    return v[f"needles.disc_{j}.crank_{i}.clearance"] - v[f"disc_{j}.crank_hole_{i}.form"] - v[f"crank_{i}.cam_{j}.form"]


def q(v, i, z):
    """Crank i's rotation axis relative to its journal axis at z (crank axes)."""
    return interp_AB(vec(v, f"crank_{i}.bearing_A.inner_runout"), vec(v, f"crank_{i}.bearing_B.inner_runout"), z)


def a(v, i, z):
    """a_i(z): crank i's rotation axis relative to the carrier's rotation axis (carrier axes)."""
    o = interp_AB(vec(v, f"crank_{i}.bearing_A.outer_runout"), vec(v, f"crank_{i}.bearing_B.outer_runout"), z)
    return axis_at(v, f"carrier.crank_bore_{i}.position", z) + o - axis_at(v, "carrier.main_raceways.runout", z)


def cam(v, i, j):
    """c_ij: cam j of crank i relative to the crank's rotation axis at z_j (crank axes)."""
    z = Z_DISC[j]
    return axis_at(v, f"crank_{i}.cam_{j}.position", z, z0=z, L=12.0) - q(v, i, z)


def hole(v, j, i):
    z = Z_DISC[j]
    return axis_at(v, f"disc_{j}.crank_hole_{i}.position", z, z0=z, L=12.0)


def planet(v, i):
    """Planet gear i's centre relative to crank i's rotation axis (crank axes)."""
    return 0.5 * v[f"crank_{i}.planet_gear.runout"][:, None] * unit(v[f"crank_{i}.planet_gear.runout_phase"]) \
        - q(v, i, Z_GEAR)


def stackup_kcs(v) -> dict[str, np.ndarray]:
    """The body-relative KCs of data/products/rv80e/assembly.toml, (n, 2) in µm, by the direct formulas."""
    out = {"carrier_axis": axis_at(v, "housing.main_raceways.coaxiality", 0.0)}
    for i in (1, 2, 3):
        out[f"crank_{i}_in_carrier"] = a(v, i, 0.0)
        out[f"crank_{i}_at_gear"] = a(v, i, Z_GEAR)
        out[f"crank_{i}_planet"] = planet(v, i)
        for j in (1, 2):
            out[f"crank_{i}_at_disc_{j}"] = a(v, i, Z_DISC[j])
            out[f"crank_{i}_cam_{j}"] = cam(v, i, j)
            out[f"disc_{j}_hole_{i}"] = hole(v, j, i)
    return out


# ----------------------------------------------------------------------------- mapping.md §2
def lm_inputs(v, design) -> dict[str, np.ndarray]:
    """Doc 001 inputs in µm."""
    planets = (1, 2, 3)
    alpha = design["sun.pressure_angle"]
    esn_p = np.mean([v[f"crank_{i}.planet_gear.tooth_thickness"] for i in planets], axis=0)
    fr_p = np.mean([v[f"crank_{i}.planet_gear.runout"] for i in planets], axis=0)
    da = np.mean([np.sum(a(v, i, Z_GEAR) * unit(120.0 * (i - 1)), -1) for i in planets], axis=0)
    per_disc = [np.mean([np.maximum(ceff(v, j, i), 0.0) for i in planets], axis=0) for j in (1, 2)]
    return {
        "E_w": math.cos(alpha) * (v["sun.tooth_thickness"] + esn_p),
        "Delta_a": da,
        "Delta_F_r": v["sun.runout"] + fr_p,
        "Delta_r_c": np.minimum(n0(v, design, 1), n0(v, design, 2)),
        "Delta_r_p": v["housing.pin_circle.radius"],
        "xi_pin": pin_gap(v).mean(axis=1),
        "Delta_b": np.minimum(*per_disc),
    }


# ----------------------------------------------------------------------------- mapping.md §3
def te_state(v, design, row: int, te: bool = False):
    """The 20-DOF ErrorState (mm, rad) of sample ``row``, mapping.md §3 as written: the pin positions (circle
    radius + 2-lobe pattern + residual) and the pin-in-groove clearance g_k common to both discs; each disc its
    own profile modification (Δr_j, ΔR_j: the kernel's n_j(φ)) and its own 2-lobe profile patterns; each crank's
    phase from its planet's clocking, φ_i = −c_i/(m z_p/2) (issue 39), and (``te``: the TE stage, which drives one
    way) each planet's tooth thickness on its driving flank, s_i."""
    from rvtol.models.reducer_20dof import layout as L
    from rvtol.models.reducer_20dof.factors import ErrorState

    s = ErrorState.zero(ZB)
    e = s.err
    um = 1e-3

    def put(mag, ang, u):
        e[mag], e[ang] = math.hypot(*u) * um, math.atan2(u[1], u[0])

    def at(name):
        return v[name][row]

    e[L.E_S], e[L.BETA_S] = at("sun.runout") / 2 * um, math.radians(at("sun.runout_phase"))
    put(L.A_C, L.GAMMA_C, axis_at(v, "housing.main_raceways.coaxiality", 0.0)[row])
    r_ref = design["sun.module"] * design["planet.teeth"] / 2
    for i in (1, 2, 3):
        e[L.PHI_P + i - 1] = -at(f"crank_{i}.planet_gear.clocking") * um / r_ref
        if te:
            e[L.S_P + i - 1] = at(f"crank_{i}.planet_gear.tooth_thickness") * um
        put(L.E_P + i - 1, L.BETA_P + i - 1, planet(v, i)[row])
        put(L.E_CA + i - 1, L.BETA_CA + i - 1, rot(a(v, i, 0.0)[row], -PHI[i - 1]))
        for j in (1, 2):
            k = 3 * (j - 1) + i - 1
            put(L.E_C + k, L.BETA_C + k, (1.0 if j == 1 else -1.0) * cam(v, i, j)[row])
            put(L.E_H + k, L.BETA_H + k, rot(hole(v, j, i)[row], -PHI[i - 1]))
            e[L.DELTA_B + k] = max(ceff(v, j, i)[row], 0.0) / 2 * um
    for j in (1, 2):
        e[L.MOD_EQ + j - 1] = at(f"disc_{j}.profile.equidistance_mod") * um
        e[L.MOD_MOVED + j - 1] = at(f"disc_{j}.profile.moved_distance_mod") * um
    residual = {c: np.array([at(f"housing.pin_groove[{k}].{c}_residual") for k in range(1, ZB + 1)])
                for c in ("radial", "tangential")}
    radial = (at("housing.pin_circle.radius") + residual["radial"] + at("housing.pin_grooves.radial_harmonic")
              * np.sin(2 * THK + math.radians(at("housing.pin_grooves.radial_harmonic_phase"))))
    tangential = (residual["tangential"] + at("housing.pin_grooves.cumulative_pitch")
                  * np.sin(2 * THK + math.radians(at("housing.pin_grooves.cumulative_pitch_phase"))))
    g = pin_gap(v)[row]
    for j in (1, 2):
        s.pin_err[L.PIN_R, j - 1] = radial * um
        s.pin_err[L.PIN_AP, j - 1] = tangential * um
        s.pin_err[L.PIN_GAP, j - 1] = g * um
        for field, amp in ((L.DISC_R, "form"), (L.DISC_AP, "cumulative_pitch")):
            A, ph = at(f"disc_{j}.profile.{amp}") * um, math.radians(at(f"disc_{j}.profile.{amp}_phase"))
            s.disc_h[j - 1, field, 2] = [A * math.sin(ph), A * math.cos(ph)]      # A·sin(2θ_d + ph)
    return s
