"""Doc 004 torsion-angle model: components, statics, the Model over tolerance factors, the study."""
import math

import numpy as np
import pytest

from rvtol import units
from rvtol.design import load_design
from rvtol.errors import InputError
from rvtol.elements import carrier, crankshaft, involute, rolling_bearings
from rvtol.models.stiffness.model import STATUS_GEOMETRY, STATUS_INTERFERENCE, from_study
from rvtol.models.stiffness.torsion_angle import ReducerStiffness
from rvtol.params import Params
from rvtol.spec import spec_from_table

from conftest import ROOT

DESIGN = load_design(ROOT / "data/designs/rv80e_stiffness.toml")
RS = ReducerStiffness.from_design(DESIGN)
MODS = (-0.015, -0.030)
RATED = 784e3


def test_palmgren_bearing_deflection_by_hand():
    # Q_max = 4.08 * 1000 / 18 = 226.667 N; δ = 2 * 3.84e-5 * 226.667^0.9 / 8^0.8
    #       = 7.68e-5 * 131.78 / 5.2780 = 1.91751e-3 mm
    assert rolling_bearings.radial_deflection(1000.0, 18, 8.0) == pytest.approx(1.91751e-3, rel=1e-5)


def test_iso6336_single_stiffness_by_hand():
    # q' = 0.04723 + 0.15551/21 + 0.25791/42 = 0.0607760 -> c'_th = 16.4539 N/(mm µm)
    assert involute.single_stiffness_th(21, 42) == pytest.approx(16.4539, rel=1e-5)
    # mesh stiffness: full value from 100 N/mm specific load, proportional below
    k_full = involute.mesh_stiffness(21, 42, 1.25, math.radians(20), 7.0, 1400.0)
    k_half = involute.mesh_stiffness(21, 42, 1.25, math.radians(20), 7.0, 350.0)
    assert k_full == pytest.approx(involute.mesh_stiffness(21, 42, 1.25, math.radians(20), 7.0, 700.0))
    assert k_half == pytest.approx(0.5 * k_full, rel=1e-12)


def test_crank_beam_against_roark_and_overhang_closed_form():
    L, d, E, nu = 38.0, 22.0, 206000.0, 0.3
    G = E / (2 * (1 + nu))
    EI = E * math.pi * d ** 4 / 64
    kGA = 6 * (1 + nu) / (7 + 6 * nu) * G * math.pi * d ** 2 / 4
    A = crankshaft.influence_matrix([-10.0, 13.5, 24.5], L, d, E, nu)
    x, s = 13.5, 24.5   # Roark, simply supported, load at s, deflection at x < s, plus Timoshenko shear
    roark = (L - s) * x * (L ** 2 - (L - s) ** 2 - x ** 2) / (6 * EI * L) + (L - s) * x / (kGA * L)
    assert A[1, 2] == pytest.approx(roark, rel=1e-10)
    assert A[2, 1] == pytest.approx(A[1, 2], rel=1e-12)      # Maxwell reciprocity
    c = 10.0            # tip of an overhang c under its own load: c²(L+c)/(3EI) + c(L+c)/(L κGA)
    assert A[0, 0] == pytest.approx(c ** 2 * (L + c) / (3 * EI) + c * (L + c) / (L * kGA), rel=1e-10)


def test_carrier_pillar_stiffness_by_hand():
    # 20 x 14 mm pillar, 24 mm: I = 14*20³/12 = 9333.3 mm⁴; h³/(12EI) = 13824/(12*206000*9333.3) = 5.9917e-7;
    # G = 79230.8, h/(5/6 G A) = 24/(0.83333*79230.8*280) = 1.29819e-6 -> k = 1/1.89736e-6 = 5.27049e5 N/mm
    k = carrier.pillar_stiffness(20.0, 14.0, 24.0, 206000.0, 0.3)
    assert k == pytest.approx(5.27049e5, rel=1e-5)


def test_statics_cranks_deliver_the_output_torque_to_the_carrier():
    res = RS.evaluate(np.array([RATED, 0.3 * RATED]), *MODS, crank_angle=0.4)
    _, cs = res.contacts[0]
    ld = RS.crank_loads(cs, 0.4)
    total = ld.support_torque(RS.crank_radius, RS.support_span).sum(axis=0)
    np.testing.assert_allclose(-total, res.torque, rtol=1e-12)
    # disc torque: pins' moment about the cycloid centre on both discs = T (1 - 1/i) z_c / z_p
    np.testing.assert_allclose(2 * cs.force @ cs.arm, res.torque * (1 - 1 / 81) * 39 / 40, rtol=1e-12)


def test_torsion_angle_composition_and_virtual_work_ratios():
    res = RS.evaluate(np.array([RATED, -RATED, 0.0]), *MODS)
    th = res.theta
    assert np.all(th[0] > 0)
    np.testing.assert_allclose(th[1], -th[0], rtol=1e-12)     # pins and cranks symmetric at phase 0
    assert np.all(th[2] == 0)
    assert res.total[0] == pytest.approx(th[0].sum())
    # θ2 = i_b β with i_b = (1 - 1/i) z_c / z_p = 0.962963
    assert RS.i_b == pytest.approx((1 - 1 / 81) * 39 / 40)
    assert th[0, 1] == pytest.approx(RS.i_b * res.extra["beta"][0], rel=1e-12)
    # involute: θ1 = T/(3 i² r_b1² k_X) (sun rotation under T/i on three meshes, divided by i)
    rb1 = 1.25 * 21 / 2 * math.cos(math.radians(20))
    Ft = RATED / (81 * 3 * rb1) * math.cos(math.radians(20))
    kX = involute.mesh_stiffness(21, 42, 1.25, math.radians(20), 7.0, Ft)
    assert th[0, 0] == pytest.approx(RATED / (3 * 81 ** 2 * rb1 ** 2 * kX), rel=1e-12)
    # carrier: the end plate receives T_c (half of the cranks' tangential load) plus the gear share
    assert res.rigidity[0] == pytest.approx(RATED / res.total[0])


def test_tangential_bearing_kinematics_is_doc004_theta3():
    # doc 004: θ3 = z_c Δδ_s i_b / (z_p a_0) with one Δδ_s; with all bearing forces set equal the
    # tangential variant reduces to it (i_b = 1 - 1/i here, z_c/z_p written out)
    from dataclasses import replace
    rs = replace(RS, bearing_kinematics="tangential")
    res = rs.evaluate(RATED, *MODS)
    _, cs = res.contacts[0]
    ld = rs.crank_loads(cs)
    delta = rolling_bearings.radial_deflection(ld.bearing_force, rs.bearing_rollers, rs.bearing_length)
    doc = 39 / 40 * (1 - 1 / 81) * delta.mean() / rs.crank_radius
    assert res.component("crank_bearings")[0] == pytest.approx(doc, rel=1e-12)


def _spec(*names):
    table = {"equidistance_mod": (-15, 6), "moved_distance_mod": (-30, 6), "pin_circle_error": (0, 10),
             "pin_radius_error": (0, 4)}
    return spec_from_table({"factor": [{"name": n, "unit": "um", "dist": "normal", "mean": table[n][0],
                                        "tolerance": table[n][1]} for n in names]})


def test_model_over_factors_matches_direct_evaluation_and_flags_interference():
    spec = _spec("pin_radius_error", "pin_circle_error")
    m = from_study(Params({"torque": {"value": 600, "unit": "N*m"}}), DESIGN, spec)
    m.check_spec(spec)
    X = np.array([[0.0, 0.0], [0.002, -0.004], [0.01, 0.01]])   # mm; last: radial clearance < 0
    Y, status = m.evaluate_with_status(X)
    direct = RS.evaluate(6e5, *MODS, pin_radius_error=X[:2, 0], pin_circle_error=X[:2, 1])
    np.testing.assert_allclose(Y[:2, m.output_index("theta_total")], direct.total, rtol=1e-13)
    np.testing.assert_allclose(Y[:2, m.output_index("pin_backlash")], direct.pin_backlash, rtol=1e-13)
    assert list(status) == [0, 0, STATUS_INTERFERENCE]
    assert np.isnan(Y[2]).all()
    assert m.output("theta_total").shown_unit == "arcsec"
    # row determinism: a row's result does not depend on the chunk
    Y1, _ = m.evaluate_with_status(X[1:2])
    np.testing.assert_array_equal(Y1[0], Y[1])


def test_model_rejects_unknown_factor_and_missing_design():
    with pytest.raises(InputError, match="unknown factor name 'E_c'"):
        from_study(Params({}), DESIGN, spec_from_table({"factor": [{"name": "E_c", "unit": "um", "dist": "normal",
                                                                    "mean": 0, "tolerance": 1}]}))
    with pytest.raises(InputError, match="needs a design"):
        from_study(Params({}), None, _spec("pin_radius_error"))
    with pytest.raises(InputError, match="bearing_kinematics"):
        from_study(Params({"bearing_kinematics": "exact"}), DESIGN, _spec("pin_radius_error"))


@pytest.mark.parametrize("key, value, msg", [
    ("cycloid.width", 0.0, "must be > 0"),
    ("crank_bearing.rollers", -18.0, "whole number"),
    ("crank.shaft_diameter", -22.0, "must be > 0"),
    ("material.youngs_modulus", 0.0, "must be > 0"),
    ("material.poisson_ratio", 0.6, "< 0.5"),
    ("cycloid.eccentricity", 2.5, "K1"),
    ("pin.count", 41.0, "z_p = z_c \\+ 1"),
    ("reducer.cranks", 4.0, "3 cranks"),
    ("crank.disc_pitch", 50.0, "< 38"),
])
def test_bad_design_numbers_name_the_design_key(key, value, msg):
    """Bad design numbers fail before any computation, naming the design file and key (no NaN, no traceback)."""
    bad = DESIGN.with_values(**{key: value})      # base units (mm, MPa)
    with pytest.raises(InputError, match=msg) as exc:
        from_study(Params({}), bad, _spec("pin_radius_error"))
    assert exc.value.key == key and exc.value.file == DESIGN.file


def test_moved_distance_beyond_the_pin_circle_is_a_geometry_failure():
    m = from_study(Params({}), DESIGN, _spec("moved_distance_mod"))
    Y, status = m.evaluate_with_status(np.array([[-0.03], [-20.0], [-80.0]]))   # mm; K1' >= 1, R_p + ΔR_p < 0
    assert list(status) == [0, STATUS_GEOMETRY, STATUS_GEOMETRY] and np.isnan(Y[1:]).all()


def test_stiffness_breakdown_analysis_components_sum_to_the_total(tmp_path):
    """The generic breakdown (kind = "stiffness_breakdown"): θ1…θ5 add up to θ_Σ, no document column."""
    from conftest import write
    from rvtol.study import load_study, run_study

    text = (ROOT / "studies/stiffness_rv80e.toml").read_text(encoding="utf-8").replace('"../data/', f'"{ROOT.as_posix()}/data/')
    head = text[:text.index("[[analysis]]")]
    p = write(tmp_path / "s.toml", head + '[[analysis]]\nkind = "stiffness_breakdown"\ntorque_fractions = [0.5, 1.0]\n')
    res = run_study(load_study(p, n=16, executor="serial", progress=False))
    brk, contact = res.sections
    comp = brk.summary["components"]
    assert "doc 004 (arcsec)" not in comp[0]
    total = comp[-1]["θ (arcsec)"]
    assert sum(r["θ (arcsec)"] for r in comp[:-1]) == pytest.approx(total, rel=1e-12)
    assert [r["torque (N·m)"] for r in brk.summary["versus_torque"]] == pytest.approx([392.0, 784.0])
    assert contact.key == "stiffness_contact" and contact.summary["pins"]
