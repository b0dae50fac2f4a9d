"""Bolted joint (VDI 2230), Greenwood–Williamson roughness and the slice model of a tilted roller, each against a
closed form or a hand computation."""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from rvtol.elements.bolted_joint import BoltedJoint
from rvtol.elements.rolling_bearings import edge_loaded_approach
from rvtol.elements.roughness import GreenwoodWilliamson, sigma_from_ra
from rvtol.errors import SpecError

E = 206000.0
ES = E / (2 * (1 - 0.09))


def test_gw_stiffness_is_the_derivative_of_the_pressure_and_matches_the_integrals():
    g = GreenwoodWilliamson.from_ra(0.1e-3, 0.2e-3, 0.02, ES)
    assert g.sigma == pytest.approx(math.sqrt(math.pi / 2) * math.hypot(0.1e-3, 0.2e-3), rel=1e-12)
    assert g.eta * g.sigma * g.beta == pytest.approx(0.04, rel=1e-12)
    for d in (-0.5 * g.sigma, 0.5 * g.sigma, 2.0 * g.sigma):
        h = 1e-4 * g.sigma
        assert g.stiffness(d) == pytest.approx(-(g.pressure(d + h) - g.pressure(d - h)) / (2 * h), rel=1e-6)
        # p(d) by a second, independent quadrature (the Gaussian in its own variable)
        s = g.sigma
        ref = g.eta * 4 / 3 * ES * math.sqrt(g.beta) * quad(
            lambda u: (s * u - d) ** 1.5 * math.exp(-u * u / 2) / math.sqrt(2 * math.pi), d / s, 15)[0]
        assert g.pressure(d) == pytest.approx(ref, rel=1e-4)      # two quadratures of (z − d)^1.5
    p = 25.0
    assert g.pressure(g.separation(p)) == pytest.approx(p, rel=1e-10)
    assert g.layer_compliance(p, 40.0) == pytest.approx(1 / (g.stiffness(g.separation(p)) * 40.0), rel=1e-12)
    # the layer stiffens with pressure (fewer, then more summits in contact)
    assert g.stiffness_at_pressure(100.0) > g.stiffness_at_pressure(10.0) > 0
    assert sigma_from_ra(1e-3) == pytest.approx(1.2533141373155e-3, rel=1e-12)


def test_vdi2230_resiliences_and_preload_by_hand():
    j = BoltedJoint(8.0, 16.0, 20.0, 14.0, E)
    P, d2, d3 = 1.25, 7.188, 6.466
    AN, A3 = math.pi * 64 / 4, math.pi * d3 ** 2 / 4
    assert j.bolt_resilience() == pytest.approx((0.5 * 8 / AN + 16 / A3 + 0.5 * 8 / A3 + 0.33 * 8 / AN) / E, rel=1e-12)
    d0 = (d2 + d3) / 2
    t = 1.5 * d2 / d0 * (P / (math.pi * d2) + 1.155 * 0.12)
    FM = 0.9 * 940 * math.pi * d0 ** 2 / 4 / math.sqrt(1 + 3 * t * t)
    assert j.assembly_preload() == pytest.approx(FM, rel=1e-12)
    assert j.preload() == pytest.approx(FM / 1.6, rel=1e-12)
    # cone + sleeve and pure cone agree where the cone just fills the interface (D'_A = D_A,Gr)
    dW, dh = 12.0, 8.8
    tphi = lambda DA, lK: 0.348 + 0.013 * math.log(lK / dW) + 0.193 * math.log(DA / dW)  # noqa: E731
    lK = 10.0
    DA = 30.0
    for _ in range(50):                       # D_A,Gr depends on D_A through tan φ: fixed point
        DA = dW + 2 * lK * tphi(DA, lK)
    cone = BoltedJoint(8.0, lK, DA, DA, E).clamped_resilience()
    sleeve = BoltedJoint(8.0, lK, DA * (1 - 1e-9), DA * (1 - 1e-9), E).clamped_resilience()
    assert cone == pytest.approx(sleeve, rel=1e-6)


def test_joint_interface_and_its_checks():
    g = GreenwoodWilliamson.from_ra(0.8e-3, 0.8e-3, 0.02, ES)
    j = BoltedJoint(8.0, 16.0, 20.0, 14.0, E, bolts=2)
    p = j.preload() / j.interface_area
    kn = g.stiffness_at_pressure(p)
    assert j.tilt_compliance(g) == pytest.approx(1 / (kn * j.interface_inertia), rel=1e-12)
    assert j.shear_compliance(g, 0.3) == pytest.approx(1 / (2 * 0.7 / 1.7 * kn * j.interface_area), rel=1e-12)
    ok = j.opening_and_slip(10_000.0, 1000.0)
    assert not ok["opens"] and not ok["slips"]
    assert j.opening_and_slip(1e7, 0.0)["opens"] and j.opening_and_slip(0.0, 1e5)["slips"]
    with pytest.raises(SpecError):
        BoltedJoint(7.0, 16.0, 20.0, 14.0, E)


def test_tilted_roller_slice_model_closed_forms():
    """Linear law: δ0 = δ while every slice carries; once one end lifts (2δ < γl), δ0 = √(2δlγ) − γl/2.  Palmgren's
    10/9: the same load with a tilt needs a slightly smaller middle approach while all slices carry (Jensen:
    the mean of a convex power exceeds the power of the mean); the slices then carry exactly the load."""
    d, L = 5e-3, 10.0
    assert edge_loaded_approach(d, 0.0, L) == d
    assert edge_loaded_approach(d, 2e-4, L, slices=2000, exponent=1.0) == pytest.approx(d, rel=1e-9)
    g = 2e-3
    assert edge_loaded_approach(d, g, L, slices=20000, exponent=1.0) == pytest.approx(
        math.sqrt(2 * d * L * g) - g * L / 2, rel=1e-4)
    d0 = edge_loaded_approach(d, 2e-4, L)
    assert d0 < d
    x = (np.arange(400) + 0.5) / 400 * L - L / 2
    assert np.mean((d0 + 2e-4 * x) ** (10 / 9)) == pytest.approx(d ** (10 / 9), rel=1e-10)
