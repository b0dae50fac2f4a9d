"""RV-80E product: reference computation of data/products/rv80e/mapping.md (issue 11).

A review aid, not library code and not a study the CLI runs: it expands the per-pin families of
data/products/rv80e/tolerances.toml, samples the drawing tolerances, applies the declared mapping to
every model (doc 001 lost motion, doc 004 stiffness, the 20-DOF TE and torsion curve, the stack-up)
and prints the mapped inputs and a few model results; last it checks the mapping's frames and signs
against the 6-DOF stack-up (rv_crank_chain.toml adapted in memory to the product). The composed
product model of the integrator replaces it.

    PYTHONPATH=$PWD python studies/product_rv80e_mapping_check.py [--n 4000] [--te 60]

Light: about 6 s on one core with the defaults (plus the numba compilation on a first run).
"""
import math
import sys
import tomllib
from pathlib import Path

import numpy as np

from rvtol.design import load_design
from rvtol.sampling import sample
from rvtol.spec import spec_from_table

REPO = Path(__file__).resolve().parents[1]
ROOT = str(REPO / "data" / "products" / "rv80e") + "/"
D = load_design(ROOT + "design.toml")
ZB = 40
K1 = ZB * D["cycloid.eccentricity"] / D["pin.circle_radius"]
C1 = math.sqrt(1 - K1 ** 2)
ALPHA = D["sun.pressure_angle"]
PHI = np.radians([0.0, 120.0, 240.0])
THK = 2 * np.pi * np.arange(ZB) / ZB
Z_DISC = {1: +6.0, 2: -6.0}
L_SPAN = 42.0
Z_GEAR = -21.0 - 12.0

def expanded_spec():
    with open(ROOT + "tolerances.toml", "rb") as fh:
        data = tomllib.load(fh)
    out = []
    for f in data["factor"]:
        if "[k]" in f["name"]:
            for k in range(1, ZB + 1):
                out.append(dict(f, name=f["name"].replace("[k]", f"[{k}]")))
        else:
            out.append(f)
    data["factor"] = out
    return spec_from_table(data, file="expanded")

def rot(v, ang):
    """Rotate 2-vectors (..., 2) by ``ang`` (rad)."""
    c, s = math.cos(ang), math.sin(ang)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def axis_at(v, pre, z, z0=0.0, L=L_SPAN):
    """Offset (n, 2) at z of an axis with end points pre.x1, y1 (z0 + L/2) and pre.x2, y2 (z0 − L/2); µm."""
    p1 = np.stack([v[pre + ".x1"], v[pre + ".y1"]], -1)
    p2 = np.stack([v[pre + ".x2"], v[pre + ".y2"]], -1)
    return 0.5 * (p1 + p2) + (p1 - p2) * (z - z0) / L


def vec(v, pre):
    return np.stack([v[pre + ".x"], v[pre + ".y"]], -1)


def interp_AB(a, b, z):
    """Between support bearing A (z = −21) and B (z = +21)."""
    return a + (b - a) * (z + 21.0) / 42.0


def polar(u):
    return np.hypot(u[..., 0], u[..., 1]), np.arctan2(u[..., 1], u[..., 0])


def unit(deg):
    return np.array([math.cos(math.radians(deg)), math.sin(math.radians(deg))])


def product_values(ss):
    """{factor name: (n,) array in the factor's unit (µm or deg)} from a SampleSet."""
    X = ss.display_values()
    return {n: X[:, j] for j, n in enumerate(ss.names)}


# ----------------------------------------------------------------------------- derived quantities (mapping.md §1)
def derived(v):
    out = {"n0": {j: v[f"disc_{j}.profile.equidistance_mod"] - C1 * v[f"disc_{j}.profile.moved_distance_mod"]
                  for j in (1, 2)}}
    w = np.stack([v[f"pins[{k}].diameter_in_lot"] for k in range(1, ZB + 1)], -1)
    out["g"] = v["housing.pin_groove.diameter"][:, None] / 2 - (v["pins.diameter_lot"][:, None] + w)   # (n, 40)
    out["g_mean"] = out["g"].mean(axis=1)
    out["ceff"] = {(j, i): v[f"needles.disc_{j}.crank_{i}.clearance"] - v[f"disc_{j}.crank_hole_{i}.form"]
                   - v[f"crank_{i}.cam_{j}.form"] for j in (1, 2) for i in (1, 2, 3)}
    out["q"] = {i: (vec(v, f"crank_{i}.bearing_A.inner_runout"), vec(v, f"crank_{i}.bearing_B.inner_runout"))
                for i in (1, 2, 3)}

    def carrier_axis(i, z):
        """a_i(z): crank i's rotation axis relative to the carrier's rotation axis (carrier axes)."""
        o = interp_AB(vec(v, f"crank_{i}.bearing_A.outer_runout"), vec(v, f"crank_{i}.bearing_B.outer_runout"), z)
        return axis_at(v, f"carrier.crank_bore_{i}.position", z) + o - axis_at(v, "carrier.main_raceways.runout", z)

    out["carrier_axis"] = carrier_axis
    return out


# ----------------------------------------------------------------------------- model inputs (mapping.md §2, §5, §3)
def lm_inputs(v, d):
    """Doc 001 inputs in µm."""
    planets = (1, 2, 3)
    esn_p = np.mean([v[f"crank_{i}.planet_gear.tooth_thickness"] for i in planets], axis=0)
    fr_p = np.mean([v[f"crank_{i}.planet_gear.runout"] for i in planets], axis=0)
    da = np.mean([d["carrier_axis"](i, Z_GEAR) @ unit(120.0 * (i - 1)) for i in planets], axis=0)
    per_disc = [np.mean([np.maximum(d["ceff"][j, i], 0.0) for i in planets], axis=0) for j in (1, 2)]
    return {
        "E_w": math.cos(ALPHA) * (v["sun.tooth_thickness"] + esn_p),
        "Delta_a": da,
        "Delta_F_r": v["sun.runout"] + fr_p,
        "Delta_r_c": np.minimum(d["n0"][1], d["n0"][2]),
        "Delta_r_p": v["housing.pin_circle.radius"],
        "xi_pin": d["g_mean"],
        "Delta_b": np.minimum(*per_disc),
    }


def st_inputs(v, d):
    """Doc 004 inputs in µm."""
    return {
        "equidistance_mod": 0.5 * (v["disc_1.profile.equidistance_mod"] + v["disc_2.profile.equidistance_mod"]),
        "moved_distance_mod": 0.5 * (v["disc_1.profile.moved_distance_mod"] + v["disc_2.profile.moved_distance_mod"]),
        "pin_circle_error": -v["housing.pin_circle.radius"],
        "pin_radius_error": -d["g_mean"],
    }


def te_state(v, d, row):
    """ErrorState of the 20-DOF model for sample ``row`` (base units mm, rad)."""
    from rvtol.models.transmission import layout as L
    from rvtol.models.transmission.factors import ErrorState
    s = ErrorState.zero(ZB)
    e = s.err
    um = 1e-3

    def put(mag, ang, u):
        E, b = polar(u)
        e[mag], e[ang] = E * um, b

    def at(name):
        return v[name][row]

    e[L.E_S], e[L.BETA_S] = at("sun.runout") / 2 * um, math.radians(at("sun.runout_phase"))
    put(L.A_C, L.GAMMA_C, axis_at(v, "housing.main_raceways.coaxiality", 0.0)[row])          # H(0)
    for i in (1, 2, 3):
        qa, qb = (q[row] for q in d["q"][i])
        planet = 0.5 * at(f"crank_{i}.planet_gear.runout") * unit(at(f"crank_{i}.planet_gear.runout_phase"))
        put(L.E_P + i - 1, L.BETA_P + i - 1, planet - interp_AB(qa, qb, Z_GEAR))
        put(L.E_CA + i - 1, L.BETA_CA + i - 1, rot(d["carrier_axis"](i, 0.0)[row], -PHI[i - 1]))
        for j in (1, 2):
            z, k = Z_DISC[j], 3 * (j - 1) + i - 1
            cam = axis_at(v, f"crank_{i}.cam_{j}.position", z, z0=z, L=12.0)[row] - interp_AB(qa, qb, z)
            put(L.E_C + k, L.BETA_C + k, (1.0 if j == 1 else -1.0) * cam)
            hole = axis_at(v, f"disc_{j}.crank_hole_{i}.position", z, z0=z, L=12.0)[row]
            put(L.E_H + k, L.BETA_H + k, rot(hole, -PHI[i - 1]))
            e[L.DELTA_B + k] = max(d["ceff"][j, i][row], 0.0) / 2 * um
    residual = {c: np.array([at(f"housing.pin_groove[{k}].{c}_residual") for k in range(1, ZB + 1)])
                for c in ("radial", "tangential")}
    radial = (at("housing.pin_circle.radius") + residual["radial"] + at("housing.pin_grooves.radial_harmonic")
              * np.sin(2 * THK + math.radians(at("housing.pin_grooves.radial_harmonic_phase"))))
    tangential = (residual["tangential"] + at("housing.pin_grooves.cumulative_pitch")
                  * np.sin(2 * THK + math.radians(at("housing.pin_grooves.cumulative_pitch_phase"))))
    for j in (1, 2):
        s.pin_err[L.PIN_R, j - 1] = radial * um
        s.pin_err[L.PIN_AP, j - 1] = tangential * um
        s.pin_err[L.PIN_GAP, j - 1] = (d["n0"][j][row] + d["g"][row]) * um
        for field, amp in ((L.DISC_R, "form"), (L.DISC_AP, "cumulative_pitch")):
            a, ph = at(f"disc_{j}.profile.{amp}") * um, math.radians(at(f"disc_{j}.profile.{amp}_phase"))
            s.disc_h[j - 1, field, 2] = (a * math.sin(ph), a * math.cos(ph))     # a·sin(2θ_d + ph)
    return s


# ----------------------------------------------------------------------------- model runs
ARCMIN = 10800 / math.pi
ARCSEC = 648000 / math.pi
ALIASES = {"first_stage.module": "sun.module", "first_stage.pressure_angle": "sun.pressure_angle",
           "first_stage.face_width": "sun.face_width", "first_stage.profile_shift_sun": "sun.profile_shift",
           "first_stage.profile_shift_planet": "planet.profile_shift", "cycloid.width": "cycloid.face_width"}


def with_aliases(design):
    """The product design with the keys the stiffness model still reads (README: aliases)."""
    from dataclasses import replace
    from types import MappingProxyType
    p = dict(design.params)
    for a, k in ALIASES.items():
        p[a] = replace(design.params[k], name=a, source=f"alias of {k}")
    return replace(design, params=MappingProxyType(p))


def run_lm(li):
    from rvtol.models.lost_motion import LostMotionGeometry, LostMotionModel
    g = LostMotionGeometry.from_design(D)
    names = ["E_w", "Delta_a", "Delta_F_r", "Delta_r_c", "Delta_r_p", "xi_pin", "Delta_b"]
    lm = LostMotionModel(g, names, extra={"xi_pin": g.coefficients()["cycloid_stage"]["Delta_r_c"]})
    return lm.evaluate(np.column_stack([li[n] * 1e-3 for n in names]))


def run_st(si, m):
    from rvtol.models.stiffness.torsion_angle import ReducerStiffness
    rs = ReducerStiffness.from_design(with_aliases(D))
    return rs.evaluate(D["reducer.rated_torque"], *(si[k][:m] * 1e-3 for k in
                       ("equidistance_mod", "moved_distance_mod", "pin_circle_error", "pin_radius_error")))


def run_te_tc(v, d, rows):
    from rvtol.models.torsion_curve.model import TorsionCurveModel
    from rvtol.models.transmission.model import TransmissionErrorModel
    te, tc = TransmissionErrorModel(D), TorsionCurveModel(D)
    pp, lm, rg, bl, bad = [], [], [], [], 0
    for row in rows:
        st = te_state(v, d, row)
        r = te._sweep(st)
        if r.ok:
            pp.append((r.te.max() - r.te.min()) * ARCSEC)
        else:
            bad += 1
        tc.state = lambda x, st=st: st
        c = tc.curve()
        if c.ok:
            mt = c.metrics(D.value("reducer.lost_motion_torque_band", "%"))
            lm.append(mt.lost_motion * ARCMIN)
            rg.append(mt.rigidity * math.pi / 10800 / 1e3)
            bl.append(mt.backlash * ARCMIN)
        else:
            bad += 1
    return np.array(pp), np.array(lm), np.array(rg), np.array(bl), bad


# ----------------------------------------------------------------------------- stack-up check
def adapted_assembly():
    """rv_crank_chain.toml with the product's dimensions and KC components u, v (in memory)."""
    from rvtol.models.stackup.graph import assembly_from_table
    text = (REPO / "data" / "assemblies" / "rv_crank_chain.toml").read_text()
    data = tomllib.loads(text)
    dims = data["dimensions"]
    dims["crank_radius"] = {"design": "crank_bearing.centre_radius", "source": "product"}
    dims["disc_z"] = {"value": D.value("crank.disc_pitch", "mm") / 2, "unit": "mm", "source": "product"}
    dims["crank_bearing_span"] = {"design": "crank.support_span", "source": "product"}
    dims["main_bearing_span"] = {"design": "carrier.main_bearing_span", "source": "product"}
    dims["needle_clearance"] = {"value": 0.0, "unit": "mm", "source": "product: clearance through the hole size slot"}
    for part in data["part"]:
        for feat in part["feature"]:
            if part["name"].startswith("crank_") and feat["name"] == "eccentric":
                feat["form"] = f"{part['name']}.eccentric.form"
            for dev in feat.get("deviation", []):
                dev.pop("zone", None)          # zones change with the product; not checked here
    for kc in data["kc"]:
        if kc["name"] in ("cycloid_axis", "crank_axis"):
            kc["components"] = ["u", "v"]
    return assembly_from_table(data, file="rv_crank_chain.toml (product, in memory)", design=D)


def stackup_check(n=5, seed=3):
    from rvtol.models.stackup.model import StackupModel
    spec = expanded_spec()
    v = product_values(sample(spec, n, "random", seed=seed))
    d = derived(v)
    cols = {}
    for c in ("x1", "y1", "x2", "y2"):
        cols[f"housing.main_seats.coaxiality.{c}"] = v[f"housing.main_raceways.coaxiality.{c}"]
        cols[f"housing.main_seats.bearing_runout.{c}"] = -v[f"carrier.main_raceways.runout.{c}"]
        for i in (1, 2):
            cols[f"carrier.crank_hole_{i}.position.{c}"] = v[f"carrier.crank_bore_{i}.position.{c}"]
            cols[f"crank_{i}.eccentric.position.{c}"] = v[f"crank_{i}.cam_1.position.{c}"]
            cols[f"cycloid.crank_hole_{i}.position.{c}"] = v[f"disc_1.crank_hole_{i}.position.{c}"]
    for i in (1, 2):
        for end, (cx, cy) in (("B", ("x1", "y1")), ("A", ("x2", "y2"))):
            ov = vec(v, f"crank_{i}.bearing_{end}.outer_runout") - vec(v, f"crank_{i}.bearing_{end}.inner_runout")
            cols[f"carrier.crank_hole_{i}.bearing_runout.{cx}"] = ov[:, 0]
            cols[f"carrier.crank_hole_{i}.bearing_runout.{cy}"] = ov[:, 1]
        cols[f"cycloid.crank_hole_{i}.size"] = v[f"needles.disc_1.crank_{i}.clearance"]
        cols[f"cycloid.crank_hole_{i}.form"] = v[f"disc_1.crank_hole_{i}.form"]
        cols[f"crank_{i}.eccentric.form"] = v[f"crank_{i}.cam_1.form"]
    names = list(cols)
    model = StackupModel(adapted_assembly(), "carrier_first", names, floats={"needle_1": "centred"})
    Y = model.evaluate(np.column_stack([cols[k] for k in names]) * 1e-3) * 1e3
    out = [q.name for q in model.outputs]
    su_crank = Y[:, [out.index("crank_axis.u"), out.index("crank_axis.v")]]
    su_disc = Y[:, [out.index("cycloid_axis.u"), out.index("cycloid_axis.v")]]
    z = D.value("crank.disc_pitch", "mm") / 2

    def chain(zz):       # housing H + carrier-fixed a_1 − crank-fixed q_1 at zz (mapping.md §1)
        return axis_at(v, "housing.main_raceways.coaxiality", zz) + d["carrier_axis"](1, zz) - interp_AB(*d["q"][1], zz)

    direct_crank = chain(0.0)
    direct_disc = (chain(z) + axis_at(v, "crank_1.cam_1.position", z, z0=z, L=12.0)
                   - axis_at(v, "disc_1.crank_hole_1.position", z, z0=z, L=12.0))
    return np.abs(su_crank - direct_crank).max(), np.abs(su_disc - direct_disc).max()


def main(argv):
    n = int(argv[argv.index("--n") + 1]) if "--n" in argv else 4000
    n_te = int(argv[argv.index("--te") + 1]) if "--te" in argv else 60
    spec = expanded_spec()
    print(f"tolerances.toml: 159 factors -> {len(spec)} columns after expanding the per-pin families")
    v = product_values(sample(spec, n, "random", seed=11))
    d = derived(v)
    li, si = lm_inputs(v, d), st_inputs(v, d)
    for tag, inputs in (("LM", li), ("ST", si)):
        for k, x in inputs.items():
            print(f"{tag} {k:20s} mean {x.mean():8.3f} um   sd {x.std():6.3f}")
    c = np.stack(list(d["ceff"].values()))
    print(f"needle sets clipped to zero clearance: {100 * (c < 0).mean():.2f} %")
    Y = run_lm(li) * ARCMIN
    print(f"LM lost motion: mean {Y[:, 0].mean():.3f}', sd {Y[:, 0].std():.3f}', "
          f"P99.865 {np.quantile(Y[:, 0], 0.99865):.3f}'")
    m = min(n, 400)
    res = run_st(si, m)
    ok = res.extra["interference"] == 0
    theta, backlash = res.total[ok] * ARCSEC, res.pin_backlash[ok] * ARCMIN
    rigidity = res.rigidity[ok] * math.pi / 10800 / 1e3          # N·mm/rad -> N·m/arcmin
    print(f"ST at rated torque (n={m}, interfering {int((~ok).sum())}): theta_total {theta.mean():.2f}\" "
          f"sd {theta.std():.2f}\", rigidity {rigidity.mean():.1f} N m/arcmin, "
          f"pin backlash {backlash.mean():.3f}' sd {backlash.std():.3f}'")
    if n_te:
        pp, lm, rg, bl, bad = run_te_tc(v, d, range(min(n_te, n)))
        print(f"TE (n={len(pp)}): te_pp mean {pp.mean():.2f}\" sd {pp.std():.2f}\" max {pp.max():.2f}\"")
        print(f"TC (n={len(lm)}): lost motion mean {lm.mean():.3f}' sd {lm.std():.3f}' max {lm.max():.3f}', "
              f"backlash {bl.mean():.3f}', rigidity {rg.mean():.1f} N m/arcmin; failures {bad}")
    e1, e2 = stackup_check()
    print(f"stack-up vs direct mapping: crank_axis |diff| max {e1 * 1e3:.2f} nm, "
          f"cycloid_axis |diff| max {e2 * 1e3:.2f} nm")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
