"""Deviation domains: derived mean/covariance against 10⁶ samples; the multivariate normal model; magnitudes."""
import numpy as np
import pytest
from scipy import integrate, stats

from rvtol.distributions import Distribution
from rvtol.errors import InputError
from rvtol.models.stackup import domains as dm
from rvtol.models.stackup.deviation import (DeviationNormal, linear_magnitude, mean_square_magnitude,
                                     rotational_magnitude)

N = 1_000_000
Z = 4.5  # |z| allowed for a sampled moment against its derivation (≈ 7e-6 two-sided per check)


def in_plane_zone(z: "dm.ParallelPlaneZone"):
    """The face's four corners (±L/2, ±W/2) between the planes t1 and t2, its height at (x, y) being
    w − Δβ·x + Δα·y (small rotations); the other DOFs 0."""
    def inside(E):
        h = np.stack([E[:, 2] - E[:, 4] * x + E[:, 3] * y for x in (-z.L / 2, z.L / 2) for y in (-z.W / 2, z.W / 2)])
        slack = 1e-12 * z.dt
        return (h >= z.t1 - slack).all(axis=0) & (h <= z.t2 + slack).all(axis=0) & (E[:, [0, 1, 5]] == 0).all(axis=1)
    return inside


def in_cylinder(R, L: float):
    """Both ends of the axis (z = ±L/2: x = u ± Δβ·L/2, y = v ∓ Δα·L/2) within radius ``R`` (a number or one per
    sample) of the nominal axis; the other DOFs 0."""
    def inside(E):
        ends = [np.hypot(E[:, 0] + s * E[:, 4] * L / 2, E[:, 1] - s * E[:, 3] * L / 2) for s in (1, -1)]
        lim = np.asarray(R) * (1 + 1e-12)
        return (ends[0] <= lim) & (ends[1] <= lim) & (E[:, [2, 5]] == 0).all(axis=1)
    return inside


def assert_moments(domain, dist, seed, inside):
    """Every mean and covariance entry of 10⁶ samples within Z standard errors of the derivation, and every sample
    inside the zone by ``inside(E)`` (the zone's geometry written in the test)."""
    E = domain.sample(N, dist, seed=seed)
    mean, cov = domain.mean(dist), domain.cov(dist)
    c = E - E.mean(axis=0)
    S = c.T @ c / (N - 1)
    for i in range(6):
        se = E[:, i].std() / np.sqrt(N)
        if se == 0:
            assert E[:, i].max() == E[:, i].min() == mean[i]
            continue
        assert abs(E[:, i].mean() - mean[i]) < Z * se, (dist, i)
        for j in range(i, 6):
            prod = c[:, i] * c[:, j]
            se_ij = prod.std() / np.sqrt(N)
            if se_ij == 0:
                assert cov[i, j] == 0
                continue
            assert abs(S[i, j] - cov[i, j]) < Z * se_ij, (dist, i, j, S[i, j], cov[i, j])
    assert inside(E).all()
    return E


@pytest.mark.parametrize("dist", dm.DISTRIBUTIONS)
def test_planar_zone_moments(dist):
    z = dm.ParallelPlaneZone(0.002, 0.022, 40.0, 25.0)
    E = assert_moments(z, dist, 1, in_plane_zone(z))
    assert z.contains(E).all()


def test_planar_zone_closed_forms():
    z = dm.ParallelPlaneZone.symmetric(0.02, 40.0, 25.0)
    P = z.cov("uniform")
    assert P[2, 2] == pytest.approx(0.02**2 / 40)
    assert P[3, 3] == pytest.approx(0.02**2 / (10 * 25.0**2))  # α pairs with W
    assert P[4, 4] == pytest.approx(0.02**2 / (10 * 40.0**2))  # β pairs with L
    # the exact domain is the zone-corner condition: a face at the box corner leaves the zone
    E = np.zeros((2, 6))
    E[0, [2, 3, 4]] = z.box()[[2, 3, 4]] / 3.0 * 0.999
    E[1, [2, 3, 4]] = z.box()[[2, 3, 4]] / 3.0 * 1.001
    assert list(z.contains(E)) == [True, False]
    corners = np.array([[x, y] for x in (-20, 20) for y in (-12.5, 12.5)])
    height = E[:, 2:3] - E[:, 4:5] * corners[:, 0] + E[:, 3:4] * corners[:, 1]  # z = w − βx + αy
    assert np.abs(height[0]).max() <= 0.01 < np.abs(height[1]).max()


def test_planar_truncnorm_variance_by_independent_integration():
    """The nested-quadrature variance against a direct 3-D integral (scipy tplquad)."""
    z = dm.ParallelPlaneZone.symmetric(2.0, 1.0, 1.0, k=2.0)
    h, s = 1.0, 0.5
    phi = lambda x, y, w: np.exp(-(x * x + y * y + w * w) / (2 * s * s))  # noqa: E731
    lim = dict(gfun=lambda x: -(h - abs(x)), hfun=lambda x: h - abs(x),
               qfun=lambda x, y: -(h - abs(x) - abs(y)), rfun=lambda x, y: h - abs(x) - abs(y))
    num = integrate.tplquad(lambda w, y, x: x * x * phi(x, y, w), -h, h, **lim, epsrel=1e-9)[0]
    den = integrate.tplquad(lambda w, y, x: phi(x, y, w), -h, h, **lim, epsrel=1e-9)[0]
    assert z.scaled_variance("truncnorm") == pytest.approx(num / den, rel=1e-6)


@pytest.mark.parametrize("dist", dm.DISTRIBUTIONS)
def test_cylindrical_zone_moments(dist):
    z = dm.CylindricalZone(0.012, 46.0)
    E = assert_moments(z, dist, 2, in_cylinder(0.006, 46.0))
    assert z.contains(E).all()


def test_cylindrical_closed_forms_and_truncated_rayleigh():
    z = dm.CylindricalZone(0.02, 20.0)
    P = z.cov("uniform")
    assert P[0, 0] == pytest.approx(0.02**2 / 32) and P[3, 3] == pytest.approx(0.02**2 / (8 * 20.0**2))
    R, s = 1.0, 0.4
    num = integrate.quad(lambda r: r**3 * np.exp(-r * r / (2 * s * s)), 0, R)[0]
    den = integrate.quad(lambda r: r * np.exp(-r * r / (2 * s * s)), 0, R)[0]
    assert dm.truncated_rayleigh_ms(R, s) == pytest.approx(num / den, rel=1e-12)


@pytest.mark.parametrize("dist", dm.DISTRIBUTIONS)
@pytest.mark.parametrize("sizes", ["normal", "uniform"])
def test_clearance_fit_moments(dist, sizes):
    if sizes == "normal":
        hole, shaft = Distribution.make("normal", mean=0.0, sigma=0.004), Distribution.make("normal", mean=0.0, sigma=0.003)
    else:  # not normal: E[c⁺²] by nested expectation, with a real chance of interference
        hole, shaft = Distribution.make("uniform", lower=-0.01, upper=0.01), Distribution.make("uniform", lower=-0.008, upper=0.004)
    f = dm.ClearanceFit(0.01, hole, shaft, 12.0)
    c = f.clearances(N, seed=3)
    assert_moments(f, dist, 3, in_cylinder(0.5 * c, 12.0))      # each sample within its own clearance


def test_positive_part_mean_square_against_quadrature():
    hole, shaft = Distribution.make("normal", mean=0.002, sigma=0.004), Distribution.make("normal", mean=0.0, sigma=0.003)
    c0 = 0.003
    s = np.hypot(0.004, 0.003)
    ref = integrate.quad(lambda c: c * c * stats.norm.pdf(c, c0 + 0.002, s), 0, np.inf)[0]
    assert dm.positive_part_mean_square(c0, hole, shaft) == pytest.approx(ref, rel=1e-9)
    # uniform sizes: δD − δd is triangular on [−0.02, 0.02]; integrate the smooth pieces either side of 0
    u = Distribution.make("uniform", lower=-0.01, upper=0.01)
    tri = lambda d: (0.02 - abs(d)) / 0.02**2  # noqa: E731
    ref_u = sum(integrate.quad(lambda d: (c0 + d) ** 2 * tri(d), a, b, epsabs=0, epsrel=1e-13)[0]
                for a, b in ((-c0, 0.0), (0.0, 0.02)))
    assert dm.positive_part_mean_square(c0, u, u) == pytest.approx(ref_u, rel=1e-7)


def test_worst_case_of_a_clearance_fit():
    hole = Distribution.make("normal", mean=0.075, sigma=0.025)  # 0 … 0.15 at ±3σ
    shaft = Distribution.make("normal", mean=-0.05, sigma=0.1 / 6)  # −0.10 … 0
    f = dm.ClearanceFit(0.0, hole, shaft, 25.0)
    assert f.max_clearance() == pytest.approx(0.25)
    assert f.worst_case() == pytest.approx({"radial_offset": 0.125, "tilt": 0.01})


def test_concentric_map_is_uniform_on_the_disc():
    g = np.random.default_rng(5)
    p = dm.concentric_disk(g.uniform(-1, 1, N), g.uniform(-1, 1, N))
    r2 = (p**2).sum(axis=1)
    assert r2.max() <= 1 + 1e-15
    # uniform on the unit disc: r² ~ U(0, 1) and the angle ~ U(−π, π)
    assert stats.kstest(r2, "uniform").pvalue > 1e-4
    assert stats.kstest(np.arctan2(p[:, 1], p[:, 0]), stats.uniform(-np.pi, 2 * np.pi).cdf).pvalue > 1e-4
    np.testing.assert_allclose(dm.concentric_disk([0.5, 0.0, -1.0, 0.0], [0.0, 0.3, 0.0, 0.0]),
                               [[0.5, 0.0], [0.0, 0.3], [-1.0, 0.0], [0.0, 0.0]], atol=1e-16)


def test_bad_domain_inputs():
    with pytest.raises(InputError):
        dm.ParallelPlaneZone(0.01, 0.0, 10, 10)
    with pytest.raises(InputError):
        dm.CylindricalZone(-0.01, 10)
    with pytest.raises(InputError):
        dm.CylindricalZone(0.01, 10).sample(10, "gaussian")


# --------------------------------------------------------------------------- deviation statistics
def test_multivariate_normal_density_and_sampling():
    A = np.random.default_rng(1).normal(size=(6, 6))
    P = A @ A.T * 1e-4 + np.eye(6) * 1e-6
    mu = np.array([0.01, -0.02, 0.0, 1e-3, 0.0, -2e-3])
    d = DeviationNormal(mu, P)
    x = d.sample(7, seed=3)
    np.testing.assert_allclose(d.pdf(x), stats.multivariate_normal(mu, P).pdf(x), rtol=1e-10)
    E = d.sample(200_000, seed=4)
    se = np.sqrt(np.diag(P) / len(E))
    assert np.all(np.abs(E.mean(axis=0) - mu) < Z * se)
    fit = DeviationNormal.fit(E)
    assert np.all(np.abs(fit.std / d.std - 1) < Z / np.sqrt(2 * len(E)))


def test_singular_covariance_density_on_the_varying_dofs():
    z = dm.ParallelPlaneZone.symmetric(0.02, 40.0, 25.0)
    d = DeviationNormal(z.mean(), z.cov())
    a, m, P = d.restricted()
    assert list(a) == [2, 3, 4]
    E = np.zeros((2, 6))
    E[1, 0] = 1e-3  # off the support (u fixed at 0)
    ref = stats.multivariate_normal(m, P).pdf(E[0, a])
    assert d.pdf(E)[0] == pytest.approx(ref) and d.pdf(E)[1] == 0.0


def test_magnitudes_as_printed_and_mean_square():
    E = np.array([0.003, -0.004, 0.012, 1e-4, -2e-4, 3e-4])
    r = (10.0, 20.0, 30.0)
    e_ref = np.sqrt(0.003**2 + 0.004**2 + 0.012**2 + (1e-4 * 10) ** 2 + (2e-4 * 20) ** 2 + (3e-4 * 30) ** 2)
    eps_ref = np.sqrt((0.003 / 10) ** 2 + (0.004 / 20) ** 2 + (0.012 / 30) ** 2 + 1e-8 + 4e-8 + 9e-8)
    assert linear_magnitude(E, r) == pytest.approx(e_ref) and rotational_magnitude(E, r) == pytest.approx(eps_ref)
    d = DeviationNormal.independent([0.001, 0, 0, 1e-4, 0, 0], [0.002, 0.001, 0.003, 1e-4, 2e-4, 1e-4])
    S = d.sample(400_000, seed=9)
    for kind, fn in (("linear", linear_magnitude), ("rotational", rotational_magnitude)):
        m2 = fn(S, r) ** 2
        assert abs(m2.mean() - mean_square_magnitude(d.mean, d.cov, r, kind)) < Z * m2.std() / np.sqrt(len(S))
    with pytest.raises(InputError):
        linear_magnitude(E, (1.0, 0.0, 1.0))
