"""20-DOF transmission-error model: numba kernels against the NumPy reference, derivatives against
finite differences, the kinematics against the rigid nominal motion, the Table 3 error patterns."""
import math

import numpy as np
import pytest

from rvtol.design import load_design
from rvtol.errors import InputError
from rvtol.models.reducer_20dof import _kernels as K
from rvtol.models.reducer_20dof import layout as L
from rvtol.models.reducer_20dof.contacts import pin_cos_sin, static_table
from rvtol.models.reducer_20dof.factors import ErrorFactors, ErrorState
from rvtol.models.reducer_20dof.geometry import geometry_from_design, inverse_involute, involute
from numpy_twin import ReferenceModel

from conftest import ROOT

ALL = ["E_s", "beta_s", "A_s", "gamma_s", "E_p", "E_h", "E_c", "E_ca", "A_c", "gamma_c", "R_pin", "R_pin_phase",
       "AP_pin", "R_cyc", "R_cyc_phase", "AP_cyc", "delta_b", "delta_oc", "delta_ca", "delta_pin[3]", "delta_th[5]",
       # part errors of issue 12: pin circle, pin-ring and per-disc harmonics, per-disc profile modification
       "R_pc", "R_pin[7]", "R_pin_h[3]", "R_pin_h_phase[3]", "AP_pin_c[1]", "R_cyc_h[1,1]", "R_cyc_h_phase[1,1]",
       "AP_cyc_s[2,3]", "R_cyc_c[2,4]", "equidistance_mod[1]", "equidistance_mod[2]", "moved_distance_mod",
       # issue 39: the cranks' phases and the planets' tooth thicknesses (mesh offsets)
       "phi_p[1]", "phi_p[3]", "s_p"]


@pytest.fixture(scope="module")
def geom(root=None):
    return geometry_from_design(load_design(ROOT / "data/designs/rv80e_te.toml"))


def random_errors(g, rng, scale=0.005):
    x = rng.uniform(0.0, scale, len(ALL))
    for i, n in enumerate(ALL):
        if n.startswith(("beta", "gamma")) or "phase" in n:
            x[i] = rng.uniform(0.0, 2 * np.pi)
        elif n.startswith("phi_p"):         # a crank phase (rad): 0.2 mrad is 5 µm at the planet's base circle
            x[i] = rng.uniform(0.0, 2e-4)
    return ErrorFactors(ALL, g.z_b).state(x)


def numba_forces(g, st, theta_c, q, dth_s=0.0):
    tab = static_table(g, st.err, st.preload)
    coef, off = np.zeros((tab.n, 2, L.NZ)), np.zeros((tab.n, 2))
    K.update_table(theta_c, dth_s, g.prm(), st.err, st.pin_err, st.disc_h, pin_cos_sin(g), coef, off)
    F, fc, kt, Km = np.zeros(L.NDOF), np.zeros(tab.n), np.zeros((tab.n, 3)), np.zeros((L.NDOF, L.NDOF))
    energy = K.contact_forces(q, tab.kind, tab.idx, coef, off, tab.k0, tab.pw, tab.gap, tab.ser, tab.tab, F, fc, kt)
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


@pytest.fixture(scope="module")
def product():
    """The RV-80E product design: doc 000's laws with the compliance chain in series (series laws)."""
    return geometry_from_design(load_design(ROOT / "data/products/rv80e/design.toml"))


def test_numba_and_numpy_agree_with_the_compliance_chain(product):
    """Series laws (linear terms, pair table, groove log law) in the kernels against the twin's own
    evaluation (brentq on its own δ terms, SciPy's Hermite spline, rvtol.elements.chain.series)."""
    assert product.chain is not None
    rng = np.random.default_rng(5)
    for trial in range(4):
        st = random_errors(product, rng)
        ref = ReferenceModel(product, st)
        theta_c = rng.uniform(0, 2 * np.pi)
        q = rng.normal(0.0, 0.003, L.NDOF) / product.arc_radii()
        F, Km, _ = numba_forces(product, st, theta_c, q, 1e-4)
        Fr, Kr, parts = ref.forces(theta_c, q, 1e-4)
        assert 5 < np.count_nonzero(parts["pin"]) < 2 * product.z_b
        assert np.max(np.abs(F - Fr)) <= 1e-9 * np.max(np.abs(Fr))
        assert np.max(np.abs(Km - Kr)) <= 1e-9 * np.max(np.abs(Kr))


def test_numba_and_numpy_agree_with_each_cranks_own_support_preload(product):
    """Each crank's own preload (factor crank_support_preload[i], issue 39): its interpolated pair law and cam tilt
    terms in the kernels' table against the twin's own evaluation of the same laws (brentq, SciPy's Hermite)."""
    rng = np.random.default_rng(9)
    st = random_errors(product, rng)
    st.preload[:] = (400.0, 1000.0, 1700.0)
    assert static_table(product, st.err, st.preload).tab.shape[0] == 3 + 3   # 3 own pair laws + the design's 3
    ref = ReferenceModel(product, st)
    theta_c = 1.1
    q = rng.normal(0.0, 0.003, L.NDOF) / product.arc_radii()
    F, Km, _ = numba_forces(product, st, theta_c, q, 1e-4)
    Fr, Kr, _ = ref.forces(theta_c, q, 1e-4)
    assert np.max(np.abs(F - Fr)) <= 1e-9 * np.max(np.abs(Fr))
    assert np.max(np.abs(Km - Kr)) <= 1e-9 * np.max(np.abs(Kr))
    st.preload[:] = np.nan                       # the design's preload: the crank rows differ
    F0, _, _ = numba_forces(product, st, theta_c, q, 1e-4)
    assert np.max(np.abs(F0 - F)) > 1e-3 * np.max(np.abs(F))


def test_crank_support_preload_factors():
    f = ErrorFactors(["crank_support_preload[2]", "delta_pin"], 40)
    assert f.units == ("N", "mm")
    assert np.isnan(f.state([0.0, 0.0]).preload[[0, 2]]).all() and f.state([800.0, 0.0]).preload[1] == 800.0
    assert (ErrorFactors(["crank_support_preload"], 40).state([900.0]).preload == 900.0).all()
    for bad, msg in ((["crank_support_preload[4]"], "bad index"),
                     (["crank_support_preload", "crank_support_preload[1]"], "set the same error")):
        with pytest.raises(InputError, match=msg):
            ErrorFactors(bad, 40)
    with pytest.raises(InputError, match=">= 0 N"):
        ErrorFactors(["crank_support_preload[1]"], 40).state([-5.0])


@pytest.mark.parametrize("which", ["geom", "product"])
def test_tangent_and_energy_are_consistent_with_forces(which, request):
    """K = ∂F/∂q and F = ∂E/∂q by central differences (both implementations share nothing here)."""
    geom = request.getfixturevalue(which)
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
    """Without errors every contact offset is zero at every position (the error terms are the only
    offsets; conjugacy itself is checked by the nominal-motion and exact-geometry tests)."""
    g = geom
    prm = g.prm()
    st = ErrorState.zero(g.z_b)
    tab = static_table(g, st.err)
    for th in np.linspace(0, 2 * np.pi, 7):
        coef, off = np.zeros((tab.n, 2, L.NZ)), np.zeros((tab.n, 2))
        K.update_table(th, 0.0, prm, st.err, st.pin_err, st.disc_h, pin_cos_sin(g), coef, off)
        assert np.all(off == 0.0)


def _rot(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s], [s, c]])


def _u(a):
    return np.array([math.cos(a), math.sin(a)])


def _exact_minus_linear(g, theta_c, q, st):
    """Largest |exact − kernel| relative displacement (mm) over the cycloid–crank and crank–carrier
    bearings and all pins, the exact one from finite rigid-body motions of the bodies and, for the pins,
    the distance from each pin centre to the cycloid profile generated as the envelope of the pin
    circles along the ideal motion (independent of the kernel's α, arms and error projections)."""
    from scipy.optimize import minimize_scalar

    tab = static_table(g, st.err, st.preload)
    coef, off = np.zeros((tab.n, 2, L.NZ)), np.zeros((tab.n, 2))
    K.update_table(theta_c, 0.0, g.prm(), st.err, st.pin_err, st.disc_h, pin_cos_sin(g), coef, off)

    def lin(c):
        return off[c] + np.array([sum(coef[c, r, m] * q[tab.idx[c, r, m]] for m in range(L.NZ)
                                      if tab.idx[c, r, m] >= 0) for r in range(2)])

    e, aw, rr, zb, err = g.ecc, g.a_w, g.r_pin, g.z_b, st.err
    worst = 0.0
    for i in range(3):      # crank-carrier: crank centre minus (errored) carrier hole
        b, h = L.planet(i), theta_c + 2 * math.pi * i / 3
        hole = (q[L.XCA:L.YCA + 1] + _rot(theta_c + q[L.THCA]) @ (aw * _u(2 * math.pi * i / 3))
                + err[L.E_CA + i] * _u(h + q[L.THCA] + err[L.BETA_CA + i]))
        worst = max(worst, np.abs(aw * _u(h) + q[b:b + 2] - hole - lin(L.C_CRANK + i)).max())
    for j in range(2):
        th_e = (1 - zb) * theta_c + math.pi * j
        d = L.disc(j)
        centre, spin = (e + q[d]) * _u(th_e + q[d + 1]), theta_c + q[d + 2]
        for i in range(3):  # cam (on the turned, shifted crank) minus the disc's crank hole
            b, h = L.planet(i), theta_c + 2 * math.pi * i / 3
            cam = (aw * _u(h) + q[b:b + 2] + e * _u(th_e + q[b + 2])
                   + err[L.E_C + 3 * j + i] * _u(th_e + q[b + 2] + err[L.BETA_C + 3 * j + i]))
            hole = (centre + _rot(spin) @ (aw * _u(2 * math.pi * i / 3))
                    + err[L.E_H + 3 * j + i] * _u(spin + 2 * math.pi * i / 3 + err[L.BETA_H + 3 * j + i]))
            worst = max(worst, np.abs(cam - hole - lin(L.C_CAM + 3 * j + i)).max())
        for k in range(zb):
            th_k = 2 * math.pi * k / zb

            def track(t):   # pin k's centre in the disc frame along the ideal motion (carrier angle t)
                return _rot(-t) @ (g.r_pin_circle * _u(th_k) - e * _u((1 - zb) * t + math.pi * j))

            def profile(t, dt=1e-6):
                tan = (track(t + dt) - track(t - dt)) / (2 * dt)
                n = np.array([tan[1], -tan[0]]) / np.hypot(*tan)
                p = track(t)
                return p - rr * (n if n @ p > 0 else -n)

            pin = (g.r_pin_circle * _u(th_k) + st.pin_err[L.PIN_R, j, k] * _u(th_k)
                   + st.pin_err[L.PIN_AP, j, k] * _u(th_k + math.pi / 2))
            dist = minimize_scalar(lambda t: np.hypot(*(centre + _rot(spin) @ profile(t) - pin)),
                                   bracket=(theta_c - 2e-3, theta_c + 2e-3), tol=1e-10).fun
            worst = max(worst, abs((rr - dist) - lin(L.C_PIN + j * zb + k)[0]))
    return worst


def test_contact_displacements_match_exact_rigid_body_geometry(geom):
    """Independent of the derivation in the kernels: finite rigid-body positions and the cycloid
    profile generated as an envelope give the same relative displacements to first order — the
    residual falls 100-fold when the motions and errors shrink 10-fold (second-order terms only)."""
    rng = np.random.default_rng(3)
    names = ["E_c[1,1]", "E_c[1,2]", "E_c[2,3]", "E_h[1,2]", "E_h[2,1]", "E_ca[1]", "E_ca[3]", "R_pin", "AP_pin",
             "R_pin_phase", "AP_pin_phase"]
    x = np.append(rng.uniform(0.001, 0.003, 9), rng.uniform(0, 2 * np.pi, 2))
    f = ErrorFactors(names, geom.z_b)
    q = rng.normal(0.0, 0.002, L.NDOF) / geom.arc_radii()
    theta_c = 0.37
    scale = np.where([n.endswith("phase") for n in names], 1.0, 0.1)
    big = _exact_minus_linear(geom, theta_c, q, f.state(x))
    small = _exact_minus_linear(geom, theta_c, q / 10, f.state(x * scale))
    assert big < 5e-4                      # mm, against relative displacements of several µm
    assert 60 < big / small < 160          # quadratic: a first-order mismatch would give ~10


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


def test_an_unloading_contact_reaches_zero_force_in_a_few_newton_steps():
    """A Hertz contact f = (k0 d)^p carrying 1000 N whose load drops to 1e-6 N: Newton's tangent shrinks the
    deflection only by 1 − 1/p per step toward zero force (the force by (1 − 1/p)^p = 0.078 for p = 1/0.9), so
    pure Newton needs ⌈ln(1000 N / tol_f) / ln(1/0.078)⌉ = 8 steps to the tolerance; the secant slope of an
    unloading contact (``_kernels._slope``) is the exact slope to zero and takes it there in 2 — to the same
    equilibrium (d = Q^(1/p) / k0)."""
    k0, p, Q, tol = 2.0e5, 1.0 / 0.9, 1e-6, 1e-5
    idx = np.full((1, 2, L.NZ), -1, np.int64)
    idx[0, 0, 0] = 0
    coef = np.zeros((1, 2, L.NZ))
    coef[0, 0, 0] = 1.0
    args = (np.array([L.UNILATERAL], np.int64), idx, coef, np.zeros((1, 2)), np.array([k0]), np.array([p]),
            np.zeros(1), np.zeros((1, L.NSER)), np.zeros((1, 4, 2)), 0, np.array([Q]), np.zeros((1, 1)),
            np.zeros(1), False, np.zeros(1), np.ones(1), tol, 50, 1e300)
    ws = K.workspace(1, 1)
    q = np.array([1000.0 ** (1 / p) / k0])              # the equilibrium under 1000 N
    ws[2][0] = 1000.0                                   # its force: the previous evaluation's
    status, iterations = K.newton(q, *args, ws)
    assert status == L.ST_OK
    assert (k0 * q[0]) ** p == pytest.approx(Q, abs=tol)
    newton_steps = int(np.ceil(np.log(1000.0 / tol) / np.log(1.0 / (1.0 - 1.0 / p) ** p)))
    assert newton_steps == 8
    assert iterations <= 2 < newton_steps
