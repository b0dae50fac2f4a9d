"""The compliance chain in the 20-DOF model (issue 12): each element's law in the model against the element's
closed form, the reductions to the contacts, and the whole chain against series/parallel combinations of the
element stiffnesses (linearised, clearance-free)."""
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import quad

from rvtol.design import load_design
from rvtol.elements import chain as springs
from rvtol.elements.reducer_chain import FAMILIES, ChainElements
from rvtol.errors import InputError, SpecError
from rvtol.models.torsion_curve.model import compliance_breakdown
from rvtol.models.reducer_20dof import _kernels as K
from rvtol.models.reducer_20dof import layout as L
from rvtol.models.reducer_20dof.compliance import (GROUPS, TABLE_RANGE, hermite_integrals, reduce_chain,
                                                  table_law)
from rvtol.models.reducer_20dof.contacts import pin_cos_sin, static_table
from rvtol.models.reducer_20dof.factors import ErrorState
from rvtol.models.reducer_20dof.geometry import geometry_from_design
from numpy_twin import ReferenceModel
from rvtol.models.reducer_20dof.quasistatic import QuasiStaticSolver

from conftest import ROOT

PRODUCT = load_design(ROOT / "data/products/rv80e/design.toml")
G = geometry_from_design(PRODUCT)
T = G.rated_torque
E, NU = PRODUCT["material.youngs_modulus"], PRODUCT["material.poisson_ratio"]
SHEAR = E / (2 * (1 + NU))


def kernel_law(g, c, s):
    """``(f, df/ds, energy)`` of contact row ``c`` at deflection ``s`` by the numba series law."""
    t = static_table(g, np.zeros(L.NERR))
    assert t.ser[c, L.S_ON] == 1.0
    return K.series_law(s, t.k0[c], t.pw[c], t.ser, c, t.tab)


def solve(g, torques, tol=1e-10):
    r = QuasiStaticSolver(g, tol_f=tol).torsion(torques)
    assert r.ok
    return r


def reduced(el, g):
    return reduce_chain(el, a_w=g.a_w, r_bs=g.r_bs, r_bp=g.r_bp, ratio=g.ratio, z_c=g.z_c, z_b=g.z_b, ecc=g.ecc,
                        rated_torque=g.rated_torque)


# ---------------------------------------------------------------------------------------------- the design
def test_only_designs_with_element_data_get_the_chain():
    te = geometry_from_design(load_design(ROOT / "data/designs/rv80e_te.toml"))
    assert te.chain is None and np.all(static_table(te, np.zeros(L.NERR)).ser == 0)
    assert geometry_from_design(PRODUCT, chain=False).chain is None
    assert set(G.chain.families) == {"input_shaft", "crank_torsion", "pin_groove", "disc_web", "crank_bending",
                                     "crank_support_bearings", "carrier", "housing_ring", "disc_seats",
                                     "carrier_seats", "carrier_joints", "contact_roughness", "edge_loading"}
    assert set(G.chain.families) | set(GROUPS.values()) == set(FAMILIES)


def test_compliance_scales_multiply_each_family(tmp_path):
    base = geometry_from_design(PRODUCT)
    d = PRODUCT.with_values()
    from rvtol.design import DesignParam
    from types import MappingProxyType
    params = dict(d.params)
    for fam, v in (("carrier", 2.0), ("cycloid_pin", 0.5), ("pin_groove", 3.0), ("crank_support_bearings", 1.5)):
        params[f"compliance_scale.{fam}"] = DesignParam(f"compliance_scale.{fam}", v, "1", "test")
    g = geometry_from_design(replace(d, params=MappingProxyType(params)))
    assert g.chain.crank["carrier"] == pytest.approx(2.0 * base.chain.crank["carrier"], rel=1e-14)
    assert g.k0_pin == pytest.approx(base.k0_pin / 0.5, rel=1e-14)        # δ = f^(1/p)/k0 halves
    np.testing.assert_allclose(g.chain.pin_table[1], 3.0 * base.chain.pin_table[1], rtol=1e-14)
    np.testing.assert_allclose(g.chain.crank_table[1], 1.5 * base.chain.crank_table[1], rtol=1e-14)
    assert g.chain.cam[0]["crank_support_bearings"] == pytest.approx(1.5 * base.chain.cam[0]["crank_support_bearings"])
    params["compliance_scale.bogus"] = DesignParam("compliance_scale.bogus", 1.0, "1", "test")
    with pytest.raises(InputError, match="unknown compliance family"):
        geometry_from_design(replace(d, params=MappingProxyType(params)))
    del params["compliance_scale.bogus"]
    params["compliance_scale.carrier"] = DesignParam("compliance_scale.carrier", 0.0, "1", "test")
    with pytest.raises(InputError, match="> 0") as e:
        geometry_from_design(replace(d, params=MappingProxyType(params)))
    assert e.value.key == "compliance_scale.carrier"


def test_bad_element_data_names_its_key():
    with pytest.raises(InputError) as e:
        geometry_from_design(PRODUCT.with_values(**{"pin.groove_radius": 2.999}))
    assert e.value.key == "pin.groove_radius" and e.value.file == PRODUCT.file
    with pytest.raises(InputError) as e:
        geometry_from_design(PRODUCT.with_values(**{"crank.disc_pitch": 40.0}))
    assert e.value.key == "crank.support_span"


# ---------------------------------------------------------------------------------------------- element laws
def test_pin_law_is_the_disc_pin_contact_in_series_with_the_groove_element():
    """Kernel force of a pin contact at the deflection of doc 000's law plus the groove element's tabulated
    approach plus the linear terms (housing ring, contact roughness) returns that force; tangent and energy follow.  The table
    itself is the conforming groove element (rvtol.elements.pin_groove) at its knots and within 0.2 % between."""
    gr = G.chain.elements.groove
    p = G.force_exponent
    ch = G.chain
    c_ring = sum(ch.pin.values())                       # housing ring + contact roughness (linear)
    knots = ch.pin_table[L.T_F]
    np.testing.assert_allclose(ch.pin_table[L.T_D][1:], gr.approach(knots[1:]), rtol=1e-12)
    mid = 0.5 * (knots[2:] + knots[1:-1])      # the first interval (to 0.2 N) is the secant: F ln F has no slope at 0
    np.testing.assert_allclose(table_law(ch.pin_table, mid)[0], gr.approach(mid), rtol=2e-3)

    def delta(F):
        return F ** (1 / p) / G.k0_pin + float(table_law(ch.pin_table, F)[0]) + c_ring * F

    for F in (0.5, 20.0, 400.0, 1500.0, 5000.0):
        s = delta(F)
        f, kt, energy = kernel_law(G, L.C_PIN + 7, s)
        assert f == pytest.approx(F, rel=1e-12)
        h = 1e-5 * F
        assert kt == pytest.approx(2 * h / (delta(F + h) - delta(F - h)), rel=1e-7)
        assert energy == pytest.approx(F * s - quad(delta, 0.0, F, epsabs=0, epsrel=1e-13, limit=200)[0], rel=1e-9)


def test_crank_support_law_is_the_preloaded_tapered_pair():
    """The crank–carrier law at the pair's translation u(R) (rvtol.elements.rolling_bearings, solved here)
    minus the tilt share plus the linear terms returns R: exactly at the table's knots, within the cubic
    Hermite's 0.15 % between them."""
    ch = G.chain
    pair = ch.elements.pair
    share = 0.25 * (ch.cam[0]["crank_support_bearings"] + ch.cam[1]["crank_support_bearings"])
    lin = sum(ch.crank.values())
    knots = ch.crank_table[L.T_F][[5, 40, 90, 127]]
    between = 0.5 * (ch.crank_table[L.T_F][1:] + ch.crank_table[L.T_F][:-1])[::9]
    for R, rel in [(r, 1e-10) for r in knots] + [(r, 1.5e-3) for r in between]:
        u = pair.solve(np.array([R, 0.0, 0.0, 0.0, 0.0]), tol=1e-9).q[0, 0]
        f, _, _ = kernel_law(G, L.C_CRANK + 1, u - share * R + lin * R)
        assert f == pytest.approx(R, rel=rel)
    # preload: at zero load the pair is stiff (all rollers loaded), the law's tangent is the pair's
    kr = pair.radial_stiffness(1e-6, 0.0)[0]
    _, kt, _ = kernel_law(G, L.C_CRANK, 1e-12)
    assert 1.0 / kt == pytest.approx(1.0 / kr - share + lin, rel=1e-6)
    # beyond the table: linear with the last tangent
    top = TABLE_RANGE * T / (3 * G.a_w)
    d0, m0, _ = table_law(ch.crank_table, top)
    f, kt, _ = kernel_law(G, L.C_CRANK, float(d0 + m0 * 1000.0 + lin * (top + 1000.0)))
    assert f == pytest.approx(top + 1000.0, rel=1e-12) and 1.0 / kt == pytest.approx(m0 + lin, rel=1e-12)


def test_star_terms_are_the_crank_flexibility_between_the_eccentrics():
    """Crank bending: mutual term on the crank resultant, own minus mutual on each cam (the star's exact
    reproduction of the 2×2 flexibility, beam of rigid supports); pair tilt likewise from the pair's
    tangent matrix at the rated crank load."""
    ch = G.chain
    cr = ch.elements.crank
    # bending: a uniform-⌀ check of the shaft the model builds (Roark: simply supported beam + shear)
    z = list(cr.eccentrics)
    Fb = cr.shaft.flexibility(z, supports=cr.support)
    assert ch.crank["crank_bending"] == pytest.approx(Fb[0, 1], rel=1e-14)
    for j in range(2):
        assert ch.cam[j]["crank_bending"] == pytest.approx(Fb[j, j] - Fb[0, 1], rel=1e-14)
    # the star reproduces the full matrix for any two eccentric loads
    rng = np.random.default_rng(1)
    for P in rng.normal(0, 1e3, (5, 2)):
        w_star = ch.crank["crank_bending"] * P.sum() + np.array([ch.cam[j]["crank_bending"] * P[j] for j in range(2)])
        np.testing.assert_allclose(w_star, Fb @ P, rtol=1e-12)
    # pair tilt: tangent of the pair at the rated symmetric crank load
    Rr = T / (3 * G.a_w)
    Kt = ch.elements.pair.solve(np.array([Rr, 0, 0, 0, 0.0]), tol=1e-9).stiffness[0]
    B = np.array([[1, 0, 0, 0, zj] for zj in z], float)
    Fp = B @ np.linalg.solve(Kt, B.T)
    for j in range(2):
        assert ch.cam[j]["crank_support_bearings"] == pytest.approx(Fp[j, j] - Fp[0, 1], rel=1e-6)


def test_reduced_crank_stores_what_the_full_beam_and_pair_store_under_the_rated_loads():
    """The star reduction against the full crank — stepped beam with the gear on its overhang and the
    nonlinear pair under all five load components — with the 20-DOF's own rated-torque crank loads.  The
    reduction lumps the planet-gear force (4 % of a crank's load) at the star centre and linearises the
    pair's tilt: stated tolerance 15 % on bending, 6 % on the pair, 6 % on the two together."""
    r = solve(G, [T], 1e-8)
    q = r.q[0]
    t = static_table(G, np.zeros(L.NERR))
    coef, off = np.zeros((t.n, 2, L.NZ)), np.zeros((t.n, 2))
    K.update_table(0.0, 0.0, G.prm(), np.zeros(L.NERR), np.zeros((3, 2, G.z_b)), np.zeros((2, 2, L.NH, 2)),
                   pin_cos_sin(G), coef, off)
    F, fc, kt = np.zeros(L.NDOF), np.zeros(t.n), np.zeros((t.n, 3))
    K.contact_forces(q, t.kind, t.idx, coef, off, t.k0, t.pw, t.gap, t.ser, t.tab, F, fc, kt)

    def direction(c):
        d = off[c] + np.array([sum(coef[c, a, m] * q[t.idx[c, a, m]] for m in range(L.NZ) if t.idx[c, a, m] >= 0)
                               for a in range(2)])
        return d / np.linalg.norm(d)

    el = G.chain.elements
    cr, pair = el.crank, el.pair
    z = np.array([cr.gear, *cr.eccentrics])
    Fb = cr.shaft.flexibility(z, supports=cr.support)
    bend = brg = 0.0
    for i in range(3):
        A = 2 * math.pi * i / 3 + math.pi / 2 - G.alpha_w          # mesh line of action at θ_c = 0
        P = np.stack([fc[L.C_MESH + i] * np.array([math.cos(A), math.sin(A)]),
                      -fc[L.C_CAM + i] * direction(L.C_CAM + i), -fc[L.C_CAM + 3 + i] * direction(L.C_CAM + 3 + i)])
        bend += sum(P[:, k] @ Fb @ P[:, k] for k in range(2))
        loads = np.array([P[:, 0].sum(), P[:, 1].sum(), 0.0, -(z * P[:, 1]).sum(), (z * P[:, 0]).sum()])
        qq = pair.solve(loads, tol=1e-9).q[0]
        brg += float((P * np.stack([qq[0] + qq[4] * z, qq[1] - qq[3] * z], axis=1)).sum())
    work = QuasiStaticSolver(G).contact_work(0.0, q)
    assert work["crank_bending"] == pytest.approx(bend, rel=0.15)
    assert work["crank_support_bearings"] == pytest.approx(brg, rel=0.06)
    assert work["crank_bending"] + work["crank_support_bearings"] == pytest.approx(bend + brg, rel=0.06)


# ---------------------------------------------------------------------------------------------- the chain
LINEAR = PRODUCT.with_values(**{"stiffness.hertz_exponent": 0.0})      # doc 000's laws made linear


def linearised(g):
    """The chain with its nonlinear laws linearised: the pair at its zero-load tangent (preloaded: all
    rollers loaded), the groove by its secant at 1 kN."""
    ch = g.chain
    m0 = ch.crank_table[L.T_M][0]
    f = np.array([0.0, 1e6])
    d, m = m0 * f, np.array([m0, m0])
    sec = float(ch.elements.groove.approach(1000.0)) / 1000.0
    return replace(g, chain=replace(ch, crank_table=np.stack([f, d, m, hermite_integrals(f, d, m)]), groove=None,
                                    pin_table=None, cam_table=None,
                                    pin={"pin_groove": sec, "housing_ring": ch.pin["housing_ring"],
                                         "contact_roughness": ch.pin["contact_roughness"]})), m0, sec


def test_linearised_chain_equals_the_series_parallel_combination_of_its_element_stiffnesses():
    """Clearance-free, linear laws: the 20-DOF output compliance equals the one of a stiffness matrix
    assembled here from the NumPy twin's contact Jacobians, each contact's stiffness the series
    combination (rvtol.elements.chain.series) of its own law and the element stiffnesses computed here from
    the design numbers (torque-path ones by hand); contacts and cranks, discs, pins in parallel through the
    assembly.  And the virtual-work parts sum to the solver's angle, each linear element's part f² c / T."""
    g0 = geometry_from_design(LINEAR)
    g, m0, sec = linearised(g0)
    ch, el = g.chain, g.chain.elements
    tau = 0.01 * T
    r = solve(g, [tau])
    # element stiffnesses from the design numbers
    d = LINEAR
    J = lambda dia: math.pi * dia ** 4 / 32                                        # noqa: E731
    K_in = SHEAR * J(d["input_shaft.diameter"]) / d["input_shaft.length"]
    ri = g.a_w + d["cycloid.crank_hole_diameter"] / 2
    ro = d["pin.circle_radius"] - d["pin.radius"] - d["cycloid.eccentricity"]
    K_web = 4 * math.pi * SHEAR * d["cycloid.face_width"] / (ri ** -2 - ro ** -2)
    L_span, w, pitch = d["crank.support_span"], d["cycloid.face_width"], d["crank.disc_pitch"]
    C_tw = ((L_span / 2 + d["crank.gear_overhang"]) - (pitch / 2 + w / 2)) / (SHEAR * J(d["crank.journal_diameter"])) \
        + w / 2 / (SHEAR * J(d["crank.eccentric_diameter"]))                         # gear → nearer eccentric
    ib = (1 - 1 / g.ratio) * g.z_c / g.z_b
    k_mesh = springs.series(g.k_sp, 1 / (g.r_bp ** 2 * C_tw), K_in / (3 * g.r_bs ** 2))
    # the finite-element seats and ring enter as the energy-equivalent compliances of the elements
    cA, cB = el.carrier_seat_compliance
    k_crank = springs.series(1 / m0, 1 / ch.crank["crank_bending"], el.carrier_stiffness / (3 * g.a_w ** 2 / 4),
                             2 * K_web / (3 * g.a_w ** 2 * ib ** 2), 1 / (0.25 * cA + 0.25 * cB),
                             1 / (3 * g.a_w ** 2 / 4 * el.carrier_joint_compliance))
    k_cam = [1 / (1 / g.k0_dc + ch.cam[j]["crank_bending"] + ch.cam[j]["crank_support_bearings"]
                  + el.disc_seat_compliance + ch.cam[j]["edge_loading"]) for j in range(2)]
    k_pin = springs.series(g.k0_pin, 1 / sec, 1 / el.housing_ring_compliance, 1 / el.roughness_compliance)
    ref = ReferenceModel(g)
    P = ref.linear_parts(0.0)
    loaded = ref.forces(0.0, r.q[0])[2]["pin"] > 0
    Km = g.k_s * P["sun"][0].T @ P["sun"][0] + k_mesh * P["mesh"][0].T @ P["mesh"][0] \
        + g.k0_ca * P["housing"][0].T @ P["housing"][0]
    for i in range(3):
        Km += k_crank * P["crank"][0][i].T @ P["crank"][0][i]
        for j in range(2):
            Km += k_cam[j] * P["cam"][0][j, i].T @ P["cam"][0][j, i]
    Gp = P["pin"][0][loaded]
    Km += k_pin * Gp.T @ Gp
    e = np.zeros(L.NDOF)
    e[L.THCA] = 1.0
    qref = np.linalg.solve(Km, tau * e)
    assert r.te[0] / tau == pytest.approx(qref[L.THCA] / tau, rel=1e-9)
    # the assumed set of loaded pins is the one of the reference solution (compressed) and no other
    d_pins = np.array([Gk @ qref for Gk in P["pin"][0].reshape(-1, L.NDOF)]).reshape(loaded.shape)
    assert np.all(d_pins[loaded] > 0) and np.all(d_pins[~loaded] <= 1e-15)
    # virtual work: the parts sum to the solver's angle; a linear element's part is c f² / T
    parts = compliance_breakdown(g, None, r.q[0], tau)
    assert sum(parts.values()) == pytest.approx(r.te[0], rel=1e-12)
    f_mesh = np.abs(P["mesh"][0] @ r.q[0]) * k_mesh
    assert parts["input_shaft"] == pytest.approx(3 * g.r_bs ** 2 / K_in * (f_mesh ** 2).sum() / tau, rel=1e-9)
    assert parts["crank_torsion"] == pytest.approx(g.r_bp ** 2 * C_tw * (f_mesh ** 2).sum() / tau, rel=1e-9)


@pytest.mark.parametrize("family", ["input_shaft", "crank_torsion", "carrier", "disc_web"])
def test_a_torque_path_element_adds_its_closed_form_to_the_output_compliance(family):
    """Linear laws, clearance-free: one torque-path element added to doc 000's rigid chain raises the output
    angle by its series closed form — input shaft T/(K_in i²), crank torsion r_bp² C_tw T/(3 i² r_bs²)
    (three meshes at T/(3 i r_bs)), carrier ρ_A² T/K_carrier (ρ_A = ½), disc webs i_b² T/(2 K_web).  Exact
    for the meshes; the carrier and web reductions assume tangential crank resultants (the planet gear's
    radial force tilts them by < 1 %): 1e-4."""
    g0 = geometry_from_design(LINEAR, chain=False)
    full = geometry_from_design(LINEAR)
    el = full.chain.elements
    keep = {"input_shaft": "input_shaft_stiffness", "carrier": "carrier_stiffness", "disc_web": "web_stiffness"}
    only = replace(el, pair=None, groove=None, needle=None, disc_seat_compliance=None, carrier_seat_compliance=None,
                   housing_ring_compliance=None, carrier_joint_compliance=None, roughness_compliance=None, **{k: None for f, k in keep.items() if f != family})
    ch = reduced(only, g0)
    ch = replace(ch, mesh={k: v for k, v in ch.mesh.items() if k == family},
                 cam=({}, {}), crank={k: v for k, v in ch.crank.items() if k == family})
    assert ch.families == (family,)
    tau = 0.01 * T
    d_theta = solve(replace(g0, chain=ch), [tau]).te[0] - solve(g0, [tau]).te[0]
    i, ib = g0.ratio, (1 - 1 / g0.ratio) * g0.z_c / g0.z_b
    closed = {"input_shaft": lambda: tau / (el.input_shaft_stiffness * i ** 2),
              "crank_torsion": lambda: full.chain.mesh["crank_torsion"] * tau / (3 * i ** 2 * g0.r_bs ** 2),
              "carrier": lambda: 0.25 * tau / el.carrier_stiffness,
              "disc_web": lambda: ib ** 2 * tau / (2 * el.web_stiffness)}[family]()
    assert d_theta == pytest.approx(closed, rel=1e-9 if family in ("input_shaft", "crank_torsion") else 1e-4)


def test_full_nonlinear_breakdown_sums_to_the_angle_at_every_torque():
    r = solve(G, [0.03 * T, 0.5 * T, T], 1e-9)
    for q, tau, theta in zip(r.q, r.torque, r.te):
        parts = compliance_breakdown(G, None, q, tau)
        assert set(parts) == set(FAMILIES)
        assert sum(parts.values()) == pytest.approx(theta, rel=1e-9)
        # every element stores energy except the needles' edge loading, which a tilt of a few 100 µrad
        # lets carry the same load at a slightly smaller middle approach (rvtol.elements.rolling_bearings)
        assert all(v >= -1e-12 * theta for f, v in parts.items() if f != "edge_loading")
        assert abs(parts["edge_loading"]) < 1e-3 * theta


def test_chain_elements_from_a_design_without_material_is_empty():
    el = ChainElements.from_design(load_design(ROOT / "data/designs/rv80e_te.toml"), 42.0)
    assert el.present == () and el.scale("carrier") == 1.0


# ---------------------------------------------------------------------------------------------- doc 004's model
from rvtol.models.stiffness.torsion_angle import COMPONENTS, ReducerStiffness   # noqa: E402

RS = ReducerStiffness.from_design(PRODUCT)
MODS = (PRODUCT["cycloid.equidistance_modification"], PRODUCT["cycloid.moved_distance_modification"])


def test_stiffness_model_reads_the_product_design_through_its_key_fallbacks():
    assert RS.module == PRODUCT["sun.module"] and RS.pressure_angle == PRODUCT["sun.pressure_angle"]
    assert RS.gear_width == PRODUCT["sun.face_width"] and RS.pins.b == PRODUCT["cycloid.face_width"]
    assert (RS.shift_sun, RS.shift_planet) == (PRODUCT["sun.profile_shift"], PRODUCT["planet.profile_shift"])
    assert RS.crank_radius == PRODUCT["crank_bearing.centre_radius"] == pytest.approx(G.a_w, rel=1e-4)
    assert RS.components == COMPONENTS + ("crank_support_bearings", "pin_groove", "disc_web", "input_shaft")
    doc = ReducerStiffness.from_design(load_design(ROOT / "data/designs/rv80e_stiffness.toml"))
    assert doc.components == COMPONENTS and doc.crank_radius == doc.module * (doc.z1 + doc.z2) / 2


def test_stiffness_model_extra_components_against_their_closed_forms():
    res = RS.evaluate([0.25 * T, T], *MODS)
    tau = res.torque
    d = PRODUCT
    K_in = SHEAR * math.pi * d["input_shaft.diameter"] ** 4 / 32 / d["input_shaft.length"]
    np.testing.assert_allclose(res.component("input_shaft"), tau / (K_in * RS.ratio ** 2), rtol=1e-12)
    ri = d["crank_bearing.centre_radius"] + d["cycloid.crank_hole_diameter"] / 2
    ro = d["pin.circle_radius"] - d["pin.radius"] - d["cycloid.eccentricity"]
    K_web = 4 * math.pi * SHEAR * d["cycloid.face_width"] / (ri ** -2 - ro ** -2)
    Tc = tau * (1 - 1 / RS.ratio) * RS.pins.z_c / (2 * RS.pins.z_p)
    np.testing.assert_allclose(res.component("disc_web"), 2 * Tc ** 2 / (K_web * tau), rtol=1e-12)
    # grooves: θ2 + θ_groove = i_b w(F_max)/r_c', split in the ratio of the two approaches at F_max
    cs = res.contacts[0][1]
    gr = RS.pins.groove
    w_g = gr.approach(cs.F_ref)
    both = res.component("cycloid_pin") + res.component("pin_groove")
    np.testing.assert_allclose(both, RS.i_b * cs.approach_ref / RS.pins.r_c, rtol=1e-12)
    np.testing.assert_allclose(res.component("pin_groove"), both * w_g / cs.approach_ref, rtol=1e-12)
    # support pair: each crank's loads on the pair, one by one
    pair = RS.chain.pair
    ld = RS.crank_loads(cs)
    z = ld.z - RS.support_span / 2
    for n in range(2):
        work = 0.0
        for i in range(3):
            P = ld.loads[n, i]
            f = [P[:, 0].sum(), P[:, 1].sum(), 0.0, -(z * P[:, 1]).sum(), (z * P[:, 0]).sum()]
            q = pair.solve(np.array(f), tol=1e-10).q[0]
            work += sum(P[k] @ np.array([q[0] + q[4] * z[k], q[1] - q[3] * z[k]]) for k in range(3))
        assert res.component("crank_support_bearings")[n] == pytest.approx(work / tau[n], rel=1e-6)
    # families: θ4 split into bending and torsion
    fam = res.families()
    np.testing.assert_allclose(fam["crank_bending"] + fam["crank_torsion"], res.component("crankshafts"), rtol=1e-12)
    assert sum(v[1] for v in fam.values()) == pytest.approx(res.total[1], rel=1e-12)


def test_a_groove_makes_more_pins_share_the_disc_torque():
    """In series with a soft groove contact the pins' approach grows with the same law on every pin, so the
    disc turns further and pins with a larger initial gap come into contact: more loaded pins, a lower peak."""
    no = ReducerStiffness.from_design(PRODUCT.with_values()).with_pins(groove=None).evaluate(T, *MODS)
    yes = RS.evaluate(T, *MODS)
    assert yes.extra["contact_pairs"][0] >= no.extra["contact_pairs"][0]
    assert yes.extra["max_pin_force"][0] < no.extra["max_pin_force"][0]


# ---------------------------------------------------------------------------------------------- the analysis
def _study(tmp_path, analysis: str, design: str = "data/products/rv80e/design.toml"):
    from conftest import write

    return write(tmp_path / "s.toml", f"""
[study]
name = "cc"
design = "{(ROOT / design).as_posix()}"
[model]
kind = "torsion_curve"
points = 6
[[factor]]
name = "delta_pin"
unit = "um"
dist = "uniform"
lower = 2
upper = 4
[[analysis]]
{analysis}
""")


def test_compliance_breakdown_analysis_puts_the_models_side_by_side(tmp_path):
    from rvtol.study import load_study, run_study

    study = load_study(_study(tmp_path, 'kind = "compliance_breakdown"\ntorque = { value = 392, unit = "N*m" }'),
                       n=4, executor="serial", progress=False)
    res = run_study(study)
    sec = res.sections[0]
    rows = {r["family"]: r for r in sec.summary["breakdown"]}
    chain, rigid, doc = ("20-DOF, compliance chain (arcsec)", "20-DOF, doc 000's rigid chain (arcsec)",
                         "doc 004 model (arcsec)")
    fams = [f for f in FAMILIES if f in rows]
    assert fams == list(FAMILIES)
    for col in (chain, rigid, doc):
        parts = [rows[f][col] for f in fams if rows[f][col] is not None]
        assert sum(parts) == pytest.approx(rows["total"][col], rel=1e-12)
    # the 20-DOF total is the solver's angle at that torque; doc 004's is its θ_Σ
    tau = 0.5 * T
    r = solve(G, np.linspace(0, tau, 9)[1:], 1e-8)
    assert rows["total"][chain] == pytest.approx(r.te[-1] * 648000 / math.pi, rel=1e-6)
    assert rows["total"][doc] == pytest.approx(RS.evaluate(tau, *MODS).total[0] * 648000 / math.pi, rel=1e-12)
    assert rows["input_shaft"][rigid] is None and rows["sun_support"][doc] is None
    assert {r["family"] for r in sec.summary["reductions"]} == set(G.chain.families) | {"turning_arm_bearings"}


def test_compliance_breakdown_checks_its_design_when_the_study_loads(tmp_path):
    from rvtol.study import load_study

    with pytest.raises(InputError) as e:      # doc 000's design has none of doc 004's keys
        load_study(_study(tmp_path, 'kind = "compliance_breakdown"', "data/designs/rv80e_te.toml"))
    assert e.value.key
    study = load_study(_study(tmp_path, 'kind = "compliance_breakdown"\nstiffness_model = false',
                              "data/designs/rv80e_te.toml"), n=2, executor="serial", progress=False)
    assert study.analyses


def test_models_switch_the_chain_off_from_the_study():
    from rvtol.models.torsion_curve.model import from_study as tc_study
    from rvtol.models.transmission_error.model import from_study as te_study
    from rvtol.params import Params
    from rvtol.spec import spec_from_table

    spec = spec_from_table({"factor": [{"name": "delta_pin", "unit": "um", "dist": "uniform", "lower": 0,
                                        "upper": 3}]})
    assert tc_study(Params({}), PRODUCT, spec).geometry.chain is not None
    assert tc_study(Params({"compliance_chain": False}), PRODUCT, spec).geometry.chain is None
    assert te_study(Params({"compliance_chain": False}), PRODUCT, spec).geometry.chain is None


def test_the_pin_flank_law_is_palmgrens_line_contact_for_the_disc_face():
    """studies/compliance_chain.md §8: doc 000's cycloid–pin law k = k0 P^0.1 (deflection P^0.9/k0) is Palmgren's
    line-contact law δ = 3.84e-5 Q^0.9/l^0.8 (Harris & Kotzalas vol. 1 ch. 6) for l = the 12-mm disc face,
    k0 = l^0.8/3.84e-5 = 1.90e5 (doc 000: 1.93e5, 1.5 % stiffer); doc 004's Hertz formula gives 1.15–1.45× its
    approach between 0.3 and 4 kN on the product's ⌀6 pin and flank radii of 10–100 mm (the logarithm's datum
    depth: the radii)."""
    from rvtol.elements import hertz
    from rvtol.elements.rolling_bearings import PALMGREN_LINE

    l = PRODUCT["cycloid.face_width"]
    assert l == 12.0 and G.k0_pin == 1.93e5
    assert l ** 0.8 / PALMGREN_LINE == pytest.approx(G.k0_pin, rel=0.016)
    r_pin = PRODUCT["pin.radius"]
    for F in (300.0, 1000.0, 4000.0):
        doc000 = F ** 0.9 / G.k0_pin
        assert doc000 == pytest.approx(PALMGREN_LINE * F ** 0.9 / l ** 0.8, rel=0.016)
        for rho in (10.0, 30.0, 100.0, -30.0):
            ratio = float(hertz.approach(F, l, r_pin, rho, E, NU)) / doc000
            assert 1.1 < ratio < 1.5, (F, rho, ratio)


# ---------------------------------------------------------------------------------------------- a unit's own preload
def test_a_cranks_own_preload_gives_the_pair_re_solved_at_that_preload():
    """A unit's crank-support preload (factor crank_support_preload, issue 39: shims, reading, run-in) against the
    chain re-made with the pair set to that preload (ChainElements.pair_at, rolling_bearings re-solved): the
    output angle at rated and at 3 % rated torque of the clearance-free reducer.  At the design preload (a node of
    the grid) the laws are the design's exactly; between nodes the interpolated law is within 0.1 % of the angle
    (measured: ≤ 0.04 % at 100–1400 N), and the preload moves the angle by 2–10 % over this range (so the check
    can fail).  Not between 675 and 700 N: there the pair's tilt tangent at the rated crank load changes regime
    (rollers leave its load zone) and the re-solved angle itself jumps by 1.5 %; interpolating across the jump is
    off by up to 0.6 % (0.8″ at rated) for a preload inside that gap."""
    el = G.chain.elements

    def angles(g, preload=None):
        st = ErrorState.zero(g.z_b)
        if preload is not None:
            st.preload[:] = preload
        r = QuasiStaticSolver(g, st, tol_f=1e-10).torsion(np.array([0.03 * T, T]))
        assert r.ok
        return r.q[:, L.THCA]

    base = angles(G)
    assert np.array_equal(angles(G, el.pair_preload), base)
    for P in (300.0, 1400.0):
        exact = replace(G, chain=reduced(replace(el, pair=el.pair_at(P), pair_preload=P), G))
        want = angles(exact)
        assert angles(G, P) == pytest.approx(want, rel=1e-3)
        assert np.max(np.abs(want / base - 1.0)) > 0.01
    # beyond the grid (a shim the supply could not match): the pair solved at that preload
    top = G.chain.preload_grid()[0][-1]
    beyond = G.chain.crank_law(2.0 * top)[0]
    exact = reduced(replace(el, pair=el.pair_at(2.0 * top), pair_preload=2.0 * top), G).crank_table
    assert np.allclose(beyond, exact, rtol=1e-12, atol=0.0)
    with pytest.raises(SpecError, match=">= 0 N"):
        G.chain.crank_law(-1.0)
