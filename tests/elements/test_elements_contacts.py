"""rvtol.elements.pin_groove: pin-in-groove line contact — hand computation, consistency with the disc–pin
formula of hertz.py, the flat-seat limit, Roark's cylinder-between-plates form, series with the disc–pin."""
import math

import numpy as np
import pytest

from rvtol.elements import chain, pin_groove
from rvtol.errors import SpecError

from rvtol.elements import hertz

E, NU = 206000.0, 0.3


def test_groove_approach_hand_computation():
    # pin r_p = 3.5 mm in a groove r_g = 3.52 mm, b = 10 mm, F = 1000 N, steel.  By hand:
    # E* = 206000 / (2·0.91) = 113186.81 MPa; R_e = 3.5·3.52/0.02 = 616 mm;
    # a = √(4·1000·616 / (π·10·113186.81)) = 0.832430 mm; ln(4·3.5/a) = 2.822464, ln(4·3.52/a) = 2.828162;
    # 2F/(π b)·(1−ν²)/E = 2.812252e-4 mm → w = 2.812252e-4 · (2/3 + 5.650626) = 1.776582e-3 mm
    assert pin_groove.half_width(1000.0, 10.0, 3.5, -3.52, E, NU) == pytest.approx(0.832430, rel=1e-6)
    w = pin_groove.groove_approach(1000.0, 10.0, 3.5, 3.52, E, NU)
    assert w == pytest.approx(1.776582e-3, rel=1e-6)
    assert pin_groove.groove_half_angle(1000.0, 10.0, 3.5, 3.52, E, NU) == pytest.approx(0.832430 / 3.5, rel=1e-6)


@pytest.mark.parametrize("R2", [41.5, -3.52, -5.0, 1e4])
def test_same_formula_as_the_disc_pin_contact_of_hertz_py(R2):
    F = np.array([0.0, 1.0, 350.0, 2400.0])
    ours = pin_groove.line_contact_approach(F, 10.0, 3.5, R2, E, NU)
    np.testing.assert_allclose(ours, hertz.approach(F, 10.0, 3.5, R2, E, NU), rtol=1e-14, atol=0)
    if R2 < 0:
        np.testing.assert_allclose(pin_groove.groove_approach(F, 10.0, 3.5, -R2, E, NU), ours, rtol=1e-14, atol=0)


def test_flat_seat_limit():
    F, b, rp, depth = 1500.0, 12.0, 3.5, 6.0
    flat = pin_groove.line_contact_approach(F, b, rp, math.inf, E, NU, depth2=depth)
    # cylinder on a flat: R_e = r_p; a = √(4 F r_p / (π b E*)); w = 2F/(πb)(1−ν²)/E (2/3 + ln(4r_p/a) + ln(4d/a))
    Es = E / (2 * (1 - NU ** 2))
    a = math.sqrt(4 * F * rp / (math.pi * b * Es))
    hand = 2 * F / (math.pi * b) * (1 - NU ** 2) / E * (2 / 3 + math.log(4 * rp / a) + math.log(4 * depth / a))
    assert flat == pytest.approx(hand, rel=1e-13)
    for rg, tol in ((1e4, 2e-4), (1e7, 2e-7)):
        assert pin_groove.groove_approach(F, b, rp, rg, E, NU, housing_depth=depth) == pytest.approx(flat, rel=tol)
    assert pin_groove.groove_approach(F, b, rp, math.inf, E, NU, housing_depth=depth) == pytest.approx(flat, rel=1e-14)


def test_width_conventions_and_roark_cylinder_between_plates():
    F, b, rp = 800.0, 10.0, 3.5
    half = pin_groove.line_contact_approach(F, b, rp, math.inf, E, NU, depth2=5.0)
    full = pin_groove.line_contact_approach(F, b, rp, math.inf, E, NU, depth2=5.0, width="full")
    assert half - full == pytest.approx(2 * F / (math.pi * b) * 2 * (1 - NU ** 2) / E * math.log(2), rel=1e-12)
    # Roark (7th ed., Table 14.1, cylinder between two flat plates): ΔD = 4p(1−ν²)/(πE) (1/3 + ln(2D/b_w)),
    # b_w = 2a the full contact width; the cylinder's share of two full-width contacts is exactly that
    p = F / b
    a = pin_groove.half_width(F, b, rp, math.inf, E, NU)
    pin_terms = 2 * (2 * p / math.pi * (1 - NU ** 2) / E * (1 / 3 + math.log(4 * rp / (2 * a))))
    roark = 4 * p * (1 - NU ** 2) / (math.pi * E) * (1 / 3 + math.log(2 * (2 * rp) / (2 * a)))
    assert pin_terms == pytest.approx(roark, rel=1e-14)
    # Roark's b_w = 2.15 √(p D / E) for steel (ν = 0.3)
    assert 2 * a == pytest.approx(2.15 * math.sqrt(p * 2 * rp / E), rel=2e-3)


def test_pin_path_in_series():
    kw = dict(b_disc=10.0, r_pin=3.5, rho_disc=41.5, b_groove=10.0, r_groove=3.52, E=E, nu=NU)
    F = np.array([50.0, 700.0, 1800.0])
    w = pin_groove.pin_path_approach(F, **kw)
    np.testing.assert_allclose(w, hertz.approach(F, 10.0, 3.5, 41.5, E, NU)
                               + pin_groove.groove_approach(F, 10.0, 3.5, 3.52, E, NU), rtol=1e-14)
    np.testing.assert_allclose(pin_groove.pin_path_force(w, **kw), F, rtol=1e-10)
    # tangent compliance of the chain = sum of the tangent compliances (same force in both contacts)
    for F0 in (1.0, 900.0):
        c = chain.tangent_compliance(F0, lambda f: pin_groove.pin_path_approach(f, **kw))
        c1 = chain.tangent_compliance(F0, lambda f: hertz.approach(f, 10.0, 3.5, 41.5, E, NU))
        c2 = chain.tangent_compliance(F0, lambda f: pin_groove.groove_approach(f, 10.0, 3.5, 3.52, E, NU))
        assert c == pytest.approx(c1 + c2, rel=1e-7)
    # analytic tangent compliance of the log law: dw/dF = w/F + 2/(πb) Σ (1−ν²)/E · (−1/2)
    F0 = 900.0
    w0 = pin_groove.groove_approach(F0, 10.0, 3.5, 3.52, E, NU)
    c2 = chain.tangent_compliance(F0, lambda f: pin_groove.groove_approach(f, 10.0, 3.5, 3.52, E, NU))
    assert c2 == pytest.approx(w0 / F0 - 2 / (math.pi * 10.0) * 2 * (1 - NU ** 2) / E * 0.5, rel=1e-7)


def test_bad_input():
    with pytest.raises(SpecError, match="conforming"):
        pin_groove.groove_approach(100.0, 10.0, 3.5, 3.5, E, NU)
    with pytest.raises(SpecError, match="housing_depth"):
        pin_groove.groove_approach(100.0, 10.0, 3.5, math.inf, E, NU)
    with pytest.raises(SpecError, match="'half'"):
        pin_groove.line_contact_approach(100.0, 10.0, 3.5, 40.0, E, NU, width="quarter")
    with pytest.raises(ValueError):
        pin_groove.groove_approach(-1.0, 10.0, 3.5, 3.6, E, NU)
