"""rvtol.elements.disc_web: closed form against numerical integration of τ = T/(2π r² t), the equilibrium
equation of the stress field, and the thin-ring (thin-walled tube) limit."""
import math

import numpy as np
import pytest
from scipy import integrate

from rvtol.elements import disc_web
from rvtol.errors import SpecError

G = 206000.0 / 2.6


def test_closed_form_against_integrated_shear_strain():
    T, ri, ro, t = 3.775e5, 56.4, 70.0, 10.0
    beta = disc_web.annular_web_rotation(T, ri, ro, t, G)
    # dβ/dr = γ/r = τ/(G r)
    num, _ = integrate.quad(lambda r: disc_web.web_shear_stress(T, r, t) / (G * r), ri, ro, epsabs=0, epsrel=1e-13)
    assert beta == pytest.approx(num, rel=1e-12)
    assert disc_web.annular_web_stiffness(ri, ro, t, G) == pytest.approx(T / num, rel=1e-12)


def test_stress_field_is_in_equilibrium_and_carries_the_torque():
    T, t = 1.0e5, 8.0
    r = np.linspace(30.0, 70.0, 9)
    tau = disc_web.web_shear_stress(T, r, t)
    h = 1e-4
    dtau = (disc_web.web_shear_stress(T, r + h, t) - disc_web.web_shear_stress(T, r - h, t)) / (2 * h)
    # polar equilibrium without σ_θ gradient (axisymmetric): dτ/dr + 2τ/r = 0
    np.testing.assert_allclose(dtau + 2 * tau / r, 0.0, atol=1e-8 * tau.max())
    np.testing.assert_allclose(tau * 2 * math.pi * r ** 2 * t, T, rtol=1e-14)


def test_thin_ring_limit_is_a_thin_walled_tube():
    # a ring of radial width h ≪ r: shear flow T/(2π r² ) over t, γ = τ/G, rotation γ h / r
    T, r, h, t = 5.0e4, 60.0, 1e-3, 10.0
    beta = disc_web.annular_web_rotation(T, r - h / 2, r + h / 2, t, G)
    assert beta == pytest.approx(T / (2 * math.pi * r ** 2 * t * G) * h / r, rel=1e-6)


def test_stepped_web_is_annuli_in_series():
    T = 2.0e5
    radii, th = [40.0, 50.0, 65.0, 72.0], [12.0, 6.0, 10.0]
    parts = sum(disc_web.annular_web_rotation(T, radii[j], radii[j + 1], th[j], G) for j in range(3))
    assert disc_web.stepped_web_rotation(T, radii, th, G) == pytest.approx(parts, rel=1e-14)
    uni = disc_web.stepped_web_rotation(T, [40.0, 72.0], [10.0], G)
    assert uni == pytest.approx(disc_web.annular_web_rotation(T, 40.0, 72.0, 10.0, G), rel=1e-14)


def test_bad_input():
    with pytest.raises(SpecError, match="larger than r_inner"):
        disc_web.annular_web_stiffness(70.0, 60.0, 10.0, G)
    with pytest.raises(SpecError):
        disc_web.stepped_web_rotation(1.0, [40.0, 30.0], [10.0], G)
    with pytest.raises(ValueError):
        disc_web.web_shear_stress(1.0, 0.0, 10.0)
