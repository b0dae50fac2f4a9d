"""The pin ring's no-load preload (issue 39 item 1b, rvtol.models.pin_ring.preload): the 20-DOF reducer turned with
no load, each disc on its three cranks; the preload, the interference it comes from, and the drag at the output —
against the contact law, the pitch-point geometry and the crank supports' friction worked by hand."""
import math
from dataclasses import replace

import numpy as np
import pytest

from conftest import ROOT
from rvtol.design import load_design
from rvtol.models.pin_ring._kernels import noload_contacts_py
from rvtol.models.pin_ring.preload import PinRingPreloadModel
from rvtol.models.reducer_20dof import _kernels as K
from rvtol.models.reducer_20dof.friction import friction_from_design

DESIGN = ROOT / "data" / "products" / "rv80e" / "design.toml"
UM = 1e-3
#: the inputs give no profile modification (the sign-off maps it from the drawing): the disc's normal clearance is
#: delta_pin at every pin
CLEAR, TIGHT = 1.0 * UM, -1.0 * UM


@pytest.fixture(scope="module")
def design():
    return load_design(DESIGN)


@pytest.fixture(scope="module")
def rigid(design, te_geom):
    """doc 000's reducer and contact laws (no compliance chain: the pin law is f = (k0 δ)^(10/9)) with the product's
    friction coefficients and crank-support preload."""
    geometry = replace(te_geom, friction=friction_from_design(design))
    return PinRingPreloadModel(geometry, ["delta_pin"], per_crank_rev=8)


def test_a_ring_with_clearance_everywhere_has_no_preload_and_only_the_supports_drag(rigid, design):
    """delta_pin = +1 µm (undersize pins): 1 µm of normal clearance at every pin, no pin is closed. What is
    left of the no-load torque is the crank supports' preload: each pair's moment μ P0 d/2, P0 = 2 Y F_a0 with
    Y = 0.4 cot α_cup (ISO 281), turning z_b = 40 radians per output radian, three cranks, ÷ i at the input."""
    y = rigid.evaluate(np.array([[CLEAR]]))[0]
    assert y[:3].tolist() == [0.0, 0.0, 0.0] and y[4] == 0.0
    cup = math.radians(design.value("crank_support_bearing.cup_angle", "deg"))
    p0 = 2.0 * 0.4 / math.tan(cup) * design.value("crank_support_bearing.preload", "N")
    mu, d = design.value("friction.crank_support_bearing", "1"), design.value("crank_support_bearing.bore", "mm")
    hand = 3 * 40 * mu * p0 * d / 2 / 81
    assert y[3] == pytest.approx(hand, rel=1e-8)


def test_each_cranks_support_drag_follows_its_own_preload(rigid, design):
    """The unit's own preloads (crank_support_preload[i], as the build leaves them: here 400, 700, 1100 N) set each
    pair's P0 = 2 Y F_a0 and so its drag: the no-load torque is 40 μ d/2 Σ_i 2 Y P_i / 81 with no pin closed (before,
    every crank took the design's 1 kN whatever the unit's preload)."""
    m = PinRingPreloadModel(rigid.geometry, ["delta_pin"] + [f"crank_support_preload[{i}]" for i in (1, 2, 3)],
                            per_crank_rev=8)
    y = m.evaluate(np.array([[CLEAR, 400.0, 700.0, 1100.0]]))[0]
    cup = math.radians(design.value("crank_support_bearing.cup_angle", "deg"))
    mu, d = design.value("friction.crank_support_bearing", "1"), design.value("crank_support_bearing.bore", "mm")
    hand = 40 * mu * d / 2 * sum(2.0 * 0.4 / math.tan(cup) * p for p in (400.0, 700.0, 1100.0)) / 81
    assert y[2] == 0.0 and y[3] == pytest.approx(hand, rel=1e-8)


def test_the_preload_is_the_pin_law_at_the_interference(rigid):
    """delta_pin = −1 µm: 1 µm of interference at every pin of both discs. The most loaded pin's force and its
    approach beyond its clearance obey the rigid chain's pin law f = (k0 δ)^(10/9) (doc 000, Table 2). (Not bounded
    by the 1-µm overlap: every contact normal passes through the pitch point, not the disc's centre, so the pins'
    forces have a resultant; the disc moves against its needle rows and closes some pins further.)"""
    y = rigid.evaluate(np.array([[TIGHT]]))[0]
    force, interference = y[0], y[1]
    assert force > 0 and interference > 0
    k0 = rigid.geometry.k0_pin
    assert force == pytest.approx((k0 * interference) ** (10 / 9), rel=1e-6)
    assert y[2] > 0 and y[4] >= 2          # pins of both discs preloaded: a drag at the output


def test_the_pins_slide_by_their_distance_from_the_pitch_point(rigid):
    """λ_k = |P C_k| with the pitch point P at z_b e along disc j's eccentric (angle π j at carrier angle 0) and the
    contact point C_k one pin radius from pin k's centre (R_p at θ_k): on the nominal disc the normal through P
    hits the pin centre, so λ_k = |pin_k − P| − r_p — from the kernel's contact table against the plane geometry."""
    g = rigid.geometry
    s = rigid.solver(np.array([CLEAR]))
    r = s.rotation(0.0, 8)
    c = rigid.contacts(s, r)
    th = 2 * np.pi * np.arange(g.z_b) / g.z_b
    for j in (0, 1):
        P = g.z_b * g.ecc * np.array([np.cos(np.pi * j), np.sin(np.pi * j)])
        pins = g.r_pin_circle * np.stack([np.cos(th), np.sin(th)], axis=1)
        lam = np.linalg.norm(pins - P, axis=1) - g.r_pin
        np.testing.assert_allclose(c["lam"][0, j * g.z_b:(j + 1) * g.z_b], lam, rtol=1e-9)


def test_the_drag_is_mu_times_the_forces_times_their_slip(rigid):
    """pins = μ_pin Σ F_k λ_k per position, with the forces read independently of the kernel (Python's loop over the
    reference contact table, noload_contacts_py): the numba loop and the Python one agree position by position."""
    s = rigid.solver(np.array([TIGHT]))
    r = s.rotation(0.0, 8)
    c = rigid.contacts(s, r)
    py = rigid.contacts(s, r, kernel=noload_contacts_py)
    for k in ("force", "approach", "cos", "sin", "cams", "cranks", "lam"):
        np.testing.assert_allclose(c[k], py[k], rtol=1e-9, atol=1e-12, err_msg=k)
    pins, total = rigid.drag(py)
    mu = rigid.geometry.friction.pin
    np.testing.assert_allclose(pins, mu * np.sum(np.maximum(py["force"], 0) * py["lam"], axis=1), rtol=1e-12)
    assert np.all(total >= pins) and pins.max() == pytest.approx(rigid.evaluate(np.array([[TIGHT]]))[0, 2])
    assert np.allclose(py["force"].max(axis=1), r.rec[:, K.R_PIN_MAX], rtol=1e-9, atol=1e-9)


def test_bad_rows_get_a_status(rigid):
    Y, st = rigid.evaluate_with_status(np.array([[np.nan], [TIGHT]]))
    assert st[0] != 0 and np.isnan(Y[0]).all() and st[1] == 0
    m = PinRingPreloadModel(rigid.geometry, ["delta_b"], per_crank_rev=8)
    Y, st = m.evaluate_with_status(np.array([[-1.0 * UM]]))
    assert st[0] == 7 and "negative bearing clearance" in m.status_reasons[7]
