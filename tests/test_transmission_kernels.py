"""20-DOF transmission-error model: numba kernels against the NumPy reference, derivatives against
finite differences, the kinematics against the rigid nominal motion, the Table 3 error patterns."""
import math

import numpy as np
import pytest

from rvtol.design import load_design
from rvtol.errors import InputError
from rvtol.models.transmission import _kernels as K
from rvtol.models.transmission import layout as L
from rvtol.models.transmission.contacts import pin_cos_sin, static_table
from rvtol.models.transmission.factors import ErrorFactors, ErrorState
from rvtol.models.transmission.geometry import geometry_from_design, inverse_involute, involute
from rvtol.models.transmission.reference import ReferenceModel

ALL = ["E_s", "beta_s", "A_s", "gamma_s", "E_p", "E_h", "E_c", "E_ca", "A_c", "gamma_c", "R_pin", "R_pin_phase",
       "AP_pin", "R_cyc", "R_cyc_phase", "AP_cyc", "delta_b", "delta_oc", "delta_ca", "delta_pin[3]", "delta_th[5]"]


@pytest.fixture(scope="module")
def geom(root=None):
    from pathlib import Path

    return geometry_from_design(load_design(Path(__file__).resolve().parents[1] / "data/designs/rv80e_te.toml"))


def random_errors(g, rng, scale=0.005):
    x = rng.uniform(0.0, scale, len(ALL))
    for i, n in enumerate(ALL):
        if n.startswith(("beta", "gamma")) or n.endswith("phase"):
            x[i] = rng.uniform(0.0, 2 * np.pi)
    return ErrorFactors(ALL, g.z_b).state(x)


def numba_forces(g, st, theta_c, q, dth_s=0.0):
    tab = static_table(g, st.err)
    coef, off = np.zeros((tab.n, 2, L.NZ)), np.zeros((tab.n, 2))
    K.update_table(theta_c, dth_s, g.prm(), st.err, st.pin_err, st.disc_h, pin_cos_sin(g), coef, off)
    F, fc, kt, Km = np.zeros(L.NDOF), np.zeros(tab.n), np.zeros((tab.n, 3)), np.zeros((L.NDOF, L.NDOF))
    energy = K.contact_forces(q, tab.kind, tab.idx, coef, off, tab.k0, tab.pw, tab.gap, F, fc, kt)
    K.tangent_matrix(tab.kind, tab.idx, coef, kt, Km)
    return F, Km, energy


def test_operating_pressure_angle_and_centre_distance(geom):
    # hand computation: inv α' = inv 20° + 2 tan 20° (0.519 − 0.555)/48 = 0.0143579...
    inv_w = involute(math.radians(20)) + 2 * math.tan(math.radians(20)) * (0.519 - 0.555) / 48
    assert involute(geom.alpha_w) == pytest.approx(inv_w, rel=1e-13)
    assert math.degrees(inverse_involute(involute(math.radians(25.0)))) == pytest.approx(25.0, abs=1e-10)
    assert math.degrees(geom.alpha_w) == pytest.approx(19.7608, abs=1e-4)
    assert geom.a_w == pytest.approx(42.0 * math.cos(math.radians(20)) / math.cos(geom.alpha_w), rel=1e-14)
    assert geom.ratio == 81.0
    assert geom.r_disc_pitch == pytest.approx(58.5)


def test_numba_and_numpy_agree_on_random_states(geom):
    rng = np.random.default_rng(7)
    for trial in range(12):
        st = random_errors(geom, rng)
        ref = ReferenceModel(geom, st)
        theta_c = rng.uniform(0, 2 * np.pi)
        q = rng.normal(0.0, 0.003, L.NDOF) / geom.arc_radii()   # a few µm of arc on every DOF
        dth_s = rng.normal(0.0, 1e-4)
        F, Km, _ = numba_forces(geom, st, theta_c, q, dth_s)
        Fr, Kr, parts = ref.forces(theta_c, q, dth_s)
        assert 5 < np.count_nonzero(parts["pin"]) < 2 * geom.z_b   # a mixed contact state
        assert np.max(np.abs(F - Fr)) <= 1e-9 * np.max(np.abs(Fr))
        assert np.max(np.abs(Km - Kr)) <= 1e-9 * np.max(np.abs(Kr))


def test_tangent_and_energy_are_consistent_with_forces(geom):
    """K = ∂F/∂q and F = ∂E/∂q by central differences (both implementations share nothing here)."""
    rng = np.random.default_rng(11)
    st = random_errors(geom, rng)
    theta_c = 0.37
    q = rng.normal(0.0, 0.004, L.NDOF) / geom.arc_radii()
    F, Km, _ = numba_forces(geom, st, theta_c, q)
    h = 1e-7 / geom.arc_radii()             # 0.1 nm of arc
    Kfd = np.zeros_like(Km)
    Ffd = np.zeros_like(F)
    for a in range(L.NDOF):
        dq = np.zeros(L.NDOF)
        dq[a] = h[a]
        Fp, _, Ep = numba_forces(geom, st, theta_c, q + dq)
        Fm, _, Em = numba_forces(geom, st, theta_c, q - dq)
        Kfd[:, a] = (Fp - Fm) / (2 * h[a])
        Ffd[a] = (Ep - Em) / (2 * h[a])
    scale = np.sqrt(np.outer(np.diag(Km), np.diag(Km)))
    assert np.max(np.abs(Kfd - Km) / scale) < 1e-5
    xs = geom.arc_radii()
    assert np.max(np.abs(Ffd - F) / xs) < 1e-5 * np.max(np.abs(F / xs))


def kinematic_mode(g, theta_c):
    """Nominal motion per radian of input: rigid rotation of carrier, cranks, discs (no deformation)."""
    i = g.ratio
    v = np.zeros(L.NDOF)
    for n in range(L.N_CRANK):
        b = L.planet(n)
        phi = theta_c + 2 * np.pi * n / 3
        v[b:b + 2] = g.a_w / i * np.array([-np.sin(phi), np.cos(phi)])   # crank centre rides the carrier
        v[b + 2] = (1 - g.z_b) / i                                      # absolute crank rotation
    for j in range(L.N_DISC):
        d = L.disc(j)
        v[d + 1] = (1 - g.z_b) / i      # the disc centre orbits with the eccentric
        v[d + 2] = 1.0 / i              # the disc spins with the carrier
    v[L.THCA] = 1.0 / i
    return v


def test_nominal_motion_leaves_every_contact_undeformed(geom):
    """Rigid kinematics: with the input turned by 1 rad and every body moved along the ideal motion,
    no relative displacement changes (this is what fixes the signs the document prints inconsistently)."""
    ref = ReferenceModel(geom)
    for theta_c in (0.0, 0.3, 1.9, 4.4):
        v = kinematic_mode(geom, theta_c)
        parts = ref.linear_parts(theta_c, dth_s=1.0)
        p0 = ref.linear_parts(theta_c, dth_s=0.0)
        for name, (G, h) in parts.items():
            change = G @ v + (h - p0[name][1])
            assert np.max(np.abs(change)) < 1e-12, name
        for name, (G, h) in p0.items():   # and with no error nothing is deformed at q = 0
            assert np.max(np.abs(h)) == 0.0, name


def test_finite_kinematics_small_step(geom):
    """Same check across positions: stepping θ_c by dθ changes nothing for an ideal reducer, i.e. the
    nominal contact geometry is conjugate (no TE source without errors)."""
    g = geom
    prm = g.prm()
    st = ErrorState.zero(g.z_b)
    tab = static_table(g, st.err)
    for th in np.linspace(0, 2 * np.pi, 7):
        coef, off = np.zeros((tab.n, 2, L.NZ)), np.zeros((tab.n, 2))
        K.update_table(th, 0.0, prm, st.err, st.pin_err, st.disc_h, pin_cos_sin(g), coef, off)
        assert np.all(off == 0.0)


def test_table3_patterns(geom):
    f = ErrorFactors(["E_c", "E_h", "E_ca", "delta_b", "R_pin", "AP_cyc", "A_c"], geom.z_b)
    e = 0.004
    st = f.state([e] * 7)
    deg = np.pi / 180
    np.testing.assert_allclose(st.err[L.E_C:L.E_C + 6], e)
    np.testing.assert_allclose(st.err[L.BETA_C:L.BETA_C + 6], np.array([90, 0, 270, 270, 180, 90]) * deg)
    np.testing.assert_allclose(st.err[L.BETA_H:L.BETA_H + 6], np.array([60, 210, 180, 60, 210, 180]) * deg)
    np.testing.assert_allclose(st.err[L.BETA_CA:L.BETA_CA + 3], np.array([60, 300, 180]) * deg)
    np.testing.assert_allclose(st.err[L.DELTA_B:L.DELTA_B + 6], e * np.array([1, 1, 0, 1, 0, 1]))
    assert st.err[L.A_C] == e and st.err[L.GAMMA_C] == 0.0
    theta_k = 2 * np.pi * np.arange(40) / 40
    np.testing.assert_allclose(st.pin_err[L.PIN_R, 0], e * np.sin(2 * theta_k), atol=1e-18)
    np.testing.assert_allclose(st.pin_err[L.PIN_R, 1], e * np.sin(2 * theta_k), atol=1e-18)
    # the disc field e·sin(2θ): Fourier sine coefficient of order 2 of the pitch field
    assert st.disc_h[0, L.DISC_AP, 2, 1] == pytest.approx(e) and st.disc_h[0, L.DISC_AP, 2, 0] == pytest.approx(0)


@pytest.mark.parametrize("names, msg", [
    (["E_x"], "unknown error factor"),
    (["E_c", "E_c[1,2]"], "set the same error"),
    (["E_c[3,1]"], "bad index"),
    (["R_pin_phase"], "needs its amplitude"),
    (["beta_c"], "needs an index"),
    (["R_pin[41]"], "out of range"),
])
def test_bad_factor_names(geom, names, msg):
    with pytest.raises(InputError, match=msg):
        ErrorFactors(names, geom.z_b)
