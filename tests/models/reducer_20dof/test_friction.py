"""Coulomb friction in the torsion (hysteresis) curve (issue 23 item 4; rvtol.models.reducer_20dof.friction).

The loop against the closed forms of a spring with Coulomb friction (with and without free play, friction
constant or proportional to the load); the output friction torque of the 20-DOF kernels against the NumPy
twin and against the work balance of two neighbouring frictionless equilibria; the slip rows against the
rigid-body motion of the disc; the maker's readings of a loop with friction on the RV-80E product."""
import dataclasses
import math
import re

import numpy as np
import pytest

from rvtol.design import load_design
from rvtol.errors import SpecError
from rvtol.models.torsion_curve.model import (DIRECTION, TorsionCurve, TorsionCurveModel, friction_loop,
                                              reading_points, torque_schedule)
from rvtol.models.reducer_20dof import _kernels as K
from rvtol.models.reducer_20dof import layout as L
from rvtol.models.reducer_20dof.contacts import pin_cos_sin
from rvtol.models.reducer_20dof.friction import Friction, friction_from_design, friction_table
from numpy_twin import ReferenceModel
from rvtol.models.reducer_20dof.quasistatic import QuasiStaticSolver

from conftest import ROOT

PRODUCT = ROOT / "data/products/rv80e/design.toml"


# --------------------------------------------------------------------------- closed forms
def spring_loop(k, c, tf, rated=1000.0, points=20, percent=3.0):
    """A spring of stiffness k with free play 2c and friction torque tf(T_e) at its output, through the
    torsion curve's loop construction and readings: the frictionless curve θ₀(T) = sign(T)(c + |T|/k)."""
    torque, branch = torque_schedule(rated, points, percent)

    def theta0(t):
        return np.sign(t) * (c + np.abs(t) / k)

    angle = theta0(torque)
    angle[0] = 0.0                          # the assembled state: anywhere in the play
    readings = []
    for b, tau in reading_points(rated, percent):
        d = DIRECTION[b]
        te = tau
        for _ in range(200):                # T_e + d tf(T_e) = tau
            te = tau - d * tf(te)
        readings.append((b, tau, float(theta0(te)), te, tf(te)))
    T, a, br, te, f, _ = friction_loop(torque, branch, angle, np.array([tf(t) for t in torque]), rated, readings)
    return TorsionCurve(T, a, br, rated, friction=f, elastic=te)


@pytest.mark.parametrize("c", [0.0, 0.02])
def test_spring_with_constant_coulomb_friction_and_free_play(c):
    """Loop width 2c + 2 T_f/k at zero torque, 2 T_f/k where the play is closed; lost motion and rigidity as
    without friction (the mid-points); the tips stick while the torque turns by 2 T_f."""
    k, Tf, rated = 50.0, 4.0, 1000.0
    curve = spring_loop(k, c, lambda t: Tf, rated)
    mt = curve.metrics(3.0)
    assert curve.descending(0.0) - curve.ascending(0.0) == pytest.approx(2 * c + 2 * Tf / k, rel=1e-12)
    eps = 1e-4 * rated                         # the backlash is read at ±ε (model docstring)
    assert mt.backlash == pytest.approx(2 * c + 2 * (Tf + eps) / k, rel=1e-12)
    assert mt.friction_width == pytest.approx(2 * Tf / k, rel=1e-12)
    for tau in (0.1 * rated, 0.5 * rated, -0.7 * rated):
        assert curve.descending(tau) - curve.ascending(tau) == pytest.approx(2 * Tf / k, rel=1e-12)
    assert mt.lost_motion == pytest.approx(2 * c + 2 * 0.03 * rated / k, rel=1e-12)     # friction cancels
    # tips on the loading branches: a = 2 (c + (T − T_f)/k)
    assert mt.rigidity == pytest.approx(2 * rated / (2 * c + 2 * (rated - Tf) / k), rel=1e-12)
    tip = curve.ascending(rated)
    for tau in (rated - 0.5 * Tf, rated - 1.9 * Tf):           # stuck at the tip's angle
        assert curve.descending(tau) == pytest.approx(tip, rel=1e-12)
    assert curve.descending(rated - 2.5 * Tf) < tip


def test_spring_with_friction_proportional_to_the_load():
    """T_f = μ T_e: branches θ = c + T/(k (1 ± μ)); width 2 μ T/(k (1 − μ²)), nothing at zero torque but the play."""
    k, c, mu, rated = 50.0, 0.01, 0.1, 1000.0
    curve = spring_loop(k, c, lambda t: mu * abs(t), rated)
    mt = curve.metrics(3.0)
    for tau in (0.03 * rated, 0.4 * rated, -0.03 * rated, -0.8 * rated):
        w = 2 * mu * abs(tau) / (k * (1 - mu ** 2))
        assert curve.descending(tau) - curve.ascending(tau) == pytest.approx(w, rel=1e-9)
    assert mt.friction_width == pytest.approx(2 * mu * 0.03 * rated / (k * (1 - mu ** 2)), rel=1e-9)
    # at ±ε (where the backlash is read) both branches carry T_e = ±ε/(1 − μ): the play and no friction width but
    # that of a torque of ε
    eps = 1e-4 * rated
    assert mt.backlash == pytest.approx(2 * c + 2 * eps / (k * (1 - mu)), rel=1e-9)
    # mid-points: (1/(1+μ) + 1/(1−μ))/2 = 1/(1 − μ²): second order in μ
    assert mt.lost_motion == pytest.approx(2 * c + 2 * 0.03 * rated / (k * (1 - mu ** 2)), rel=1e-9)


# --------------------------------------------------------------------------- the 20-DOF friction torque
@pytest.fixture(scope="module")
def product():
    from rvtol.models.reducer_20dof.geometry import geometry_from_design

    return geometry_from_design(load_design(PRODUCT))


def test_product_friction_coefficients_and_preload_load(product):
    f = product.friction
    assert (f.pin, f.needle, f.crank_support) == (0.15, 0.0020, 0.0018)
    assert (f.needle_bore, f.crank_support_bore) == (26.0, 20.0)
    # ISO 281: Y = 0.4 cot α; two bearings under the 1-kN preload: P0 = 2 Y F_a0
    assert f.crank_support_p0 == pytest.approx(2 * 0.4 / math.tan(math.radians(13.85)) * 1000.0, rel=1e-12)


def test_friction_coefficients_are_checked(tmp_path):
    # the coefficient without its plausible range (a range would refuse 1.2 first: tests/design/test_design_ranges.py)
    text = re.sub(r'(pin_sliding = \{ value = )0\.15(.*?), status = "document", range = \[[^]]*\]', r'\g<1>1.2\2',
                  PRODUCT.read_text(encoding="utf-8"), count=1)
    assert "value = 1.2" in text
    p = tmp_path / "design.toml"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(SpecError, match="friction coefficient must lie in"):
        friction_from_design(load_design(p))


def _state(g, rng):
    from rvtol.models.reducer_20dof.factors import ErrorFactors

    names = ["E_c", "E_h", "delta_b", "delta_pin", "R_pin_h[2]", "equidistance_mod", "moved_distance_mod"]
    x = np.array([2e-3, 2e-3, 1e-3, 2e-3, 1e-3, -15e-3, -30e-3]) * rng.uniform(0.5, 1.5, 7)
    return ErrorFactors(names, g.z_b).state(x)


def test_kernel_friction_torque_agrees_with_the_numpy_twin(product):
    rng = np.random.default_rng(11)
    T = product.rated_torque
    for trial, frac in enumerate((0.03, 0.4, -1.0)):
        st = _state(product, rng)
        s = QuasiStaticSolver(product, st, tol_f=1e-6)
        r = s.torsion(np.linspace(0.0, frac * T, 6))
        assert r.ok
        tf, parts = s.friction_torques(r)
        ref = ReferenceModel(product, st)
        for p in (2, 5):
            want, groups = ref.friction_torque(0.0, r.q[p], product.friction)
            assert tf[p] == pytest.approx(want, rel=1e-7)
            assert parts[p] == pytest.approx([groups["pin"], groups["cam"], groups["crank"]], rel=1e-7)
            assert tf[p] > 0


def test_friction_torque_is_the_work_of_the_contacts_per_output_angle(product):
    """Σ_c m_c |J_c Δq| / Δθ over two close frictionless equilibria (no tangent) equals the kernel's T_f."""
    T = product.rated_torque
    s = QuasiStaticSolver(product, None, tol_f=1e-9)
    fr = s.friction
    for t0 in (0.3 * T, 0.9 * T):
        h = 1e-4 * T
        r = s.torsion([t0 - h, t0, t0 + h])
        tf = s.friction_torques(r)[0][1]
        coef, off = np.zeros((fr.shape[0], 2, L.NZ)), np.zeros((fr.shape[0], 2))
        K.update_table(0.0, 0.0, s.prm, s.errors.err, s.errors.pin_err, s.errors.disc_h, pin_cos_sin(product), coef,
                       off)
        F, fc, kt = np.zeros(L.NDOF), np.zeros(fr.shape[0]), np.zeros((fr.shape[0], 3))
        K.contact_forces(r.q[1], s.table.kind, s.table.idx, coef, off, s.table.k0, s.table.pw, s.table.gap,
                         s.table.ser, s.table.tab, F, fc, kt)
        dq = r.q[2] - r.q[0]
        work = 0.0
        ji, jv = np.zeros(3, np.int64), np.zeros(3)
        for c in range(fr.shape[0]):
            n = K.friction_jacobian(c, fr, coef, s.table.idx, s.prm, ji, jv)
            m = fr[c, L.FR_MU] * (fc[c] + fr[c, L.FR_P0]) * fr[c, L.FR_ARM]
            work += m * abs(sum(jv[t] * dq[ji[t]] for t in range(n)))
        assert work / abs(dq[L.THCA]) == pytest.approx(tf, rel=2e-4)


def test_pin_slip_row_is_the_tangential_motion_of_the_disc_contact_point(product):
    """The disc moved by (η, e θ_do, θ_d) as a rigid body: the contact point's displacement along the flank
    tangent t = ẑ × n, from the geometry (pin centre, normal through the pitch point), equals J·q."""
    g = product
    fr = friction_table(g.friction, g.z_b)
    s = QuasiStaticSolver(g)
    coef, off = np.zeros((fr.shape[0], 2, L.NZ)), np.zeros((fr.shape[0], 2))
    theta_c = 0.37
    K.update_table(theta_c, 0.0, s.prm, s.errors.err, s.errors.pin_err, s.errors.disc_h, pin_cos_sin(g), coef, off)
    rng = np.random.default_rng(3)
    eta, tdo, td = rng.normal(0, 1e-3), rng.normal(0, 1e-3), rng.normal(0, 1e-5)
    ji, jv = np.zeros(3, np.int64), np.zeros(3)
    th_e = (1 - g.z_b) * theta_c                      # disc 1's eccentric direction
    ue, te = np.array([math.cos(th_e), math.sin(th_e)]), np.array([-math.sin(th_e), math.cos(th_e)])
    for k in (0, 7, 13, 22):
        c = L.C_PIN + k
        pin = g.r_pin_circle * np.array([math.cos(2 * math.pi * k / g.z_b), math.sin(2 * math.pi * k / g.z_b)])
        P = g.z_b * g.ecc * ue
        n = (pin - P) / np.linalg.norm(pin - P)
        C = pin - g.r_pin * n
        Od = g.ecc * ue
        u = eta * ue + g.ecc * tdo * te + td * np.array([-(C - Od)[1], (C - Od)[0]])
        t = np.array([-n[1], n[0]])
        q = np.zeros(L.NDOF)
        q[L.disc(0):L.disc(0) + 3] = eta, tdo, td
        m = K.friction_jacobian(c, fr, coef, s.table.idx, s.prm, ji, jv)
        assert m == 3
        assert sum(jv[i] * q[ji[i]] for i in range(3)) == pytest.approx(float(u @ t), rel=1e-10, abs=1e-15)


# --------------------------------------------------------------------------- the torsion curve
@pytest.fixture(scope="module")
def curves(product):
    names = ["equidistance_mod", "moved_distance_mod", "delta_b", "delta_pin"]
    x = np.array([-15e-3, -30e-3, 1.4e-3, 3e-3])
    out = {}
    for label, g in (("without", product), ("with", product),
                     ("half", dataclasses.replace(product, friction=product.friction.scaled(0.5))),
                     ("no preload", dataclasses.replace(product, friction=dataclasses.replace(product.friction,
                                                                                            crank_support_p0=0.0)))):
        m = TorsionCurveModel(g, names, friction=label != "without")
        out[label] = m.curve(x)
        assert out[label].ok
    return out


def test_zero_friction_is_the_frictionless_curve_bit_for_bit(product):
    names = ["delta_b", "delta_pin"]
    x = np.array([1e-3, 2e-3])
    zero = dataclasses.replace(product, friction=Friction(0.0, 0.0, 0.0, 26.0, 20.0, 3000.0))
    a = TorsionCurveModel(product, names, friction=False).curve(x)
    b = TorsionCurveModel(zero, names).curve(x)
    assert np.array_equal(a.torque, b.torque) and np.array_equal(a.angle, b.angle) and b.friction is None
    assert np.array_equal(TorsionCurveModel(product, names, friction=False).evaluate(x[None]),
                          TorsionCurveModel(zero, names).evaluate(x[None]))


def test_makers_readings_of_a_loop_with_friction(curves):
    without, with_, half, nop = (curves[k].metrics(3.0) for k in ("without", "with", "half", "no preload"))
    fw = with_.friction_width
    assert fw > 0.1 * math.pi / 180 / 3600 and without.friction_width < 1e-9 * fw
    # first order in μ: half the coefficients, half the width (the loads they act on barely change)
    assert half.friction_width / fw == pytest.approx(0.5, abs=0.03)
    # lost motion: the mid-points cancel the friction to first order
    assert abs(with_.lost_motion - without.lost_motion) < 0.1 * fw
    # backlash: only load-independent friction (the pairs' preload) holds a width at zero torque
    assert with_.backlash > without.backlash
    # (the load-proportional friction of the torque ε the backlash is read at remains: a few per cent of it)
    assert abs(nop.backlash - without.backlash) < 0.1 * (with_.backlash - without.backlash)
    # rigidity: the tips lie on the loading branches — stiffer readings, by about the friction's share
    assert without.rigidity < with_.rigidity < 1.1 * without.rigidity


# --------------------------------------------------------------------------- calibration
@pytest.fixture(scope="module")
def friction_design(tmp_path_factory):
    """Doc 000's 20-DOF RV-80E with pin friction μ = 0.1 (no needle or pair dimensions: pins only)."""
    text = (ROOT / "data/designs/rv80e_te.toml").read_text(encoding="utf-8")
    text += '\n[friction]\npin_sliding = { value = 0.1, unit = "1", source = "test" }\n'
    p = tmp_path_factory.mktemp("friction") / "design.toml"
    p.write_text(text, encoding="utf-8")
    return load_design(p)


def test_calibration_curve_follows_the_measured_path_through_the_loop(friction_design):
    """The calibration's model of a measured loop (in file order: the test's path) is the torsion-curve model's
    loop with friction at every point the latter solves exactly (both solve T_e + d T_f(T_e) = T)."""
    from rvtol.models.calibration.curves import CurveModel
    from synthetic_curves import _grid

    T = float(friction_design["reducer.rated_torque"])
    p = 0.03 * T
    path = np.array([p, 0.5 * T, T, 0.5 * T, p, -p, -0.5 * T, -T, -0.5 * T, -p])
    grid = dataclasses.replace(_grid("torsion", friction_design, 4, "loop", None), x=path, y=np.zeros(path.size),
                               lines=np.arange(path.size) + 1, include=np.ones(path.size, bool))
    (y,), status = CurveModel(friction_design, [grid], [], {"delta_b": 2e-3}).predict(np.zeros(0))
    assert status == 0
    tc = TorsionCurveModel(friction_design, ["delta_b"]).curve([2e-3])
    want = [tc.ascending(p), tc.ascending(0.5 * T), tc.ascending(T), None, tc.descending(p), tc.descending(-p),
            tc.descending(-0.5 * T), tc.descending(-T), None, tc.ascending(-p)]
    for k, w in enumerate(want):
        if w is not None:
            assert y[k] == pytest.approx(w, rel=1e-7), k
    assert y[4] - y[0] > 0.1 * float(np.radians(1 / 3600))          # the loop is open at +3 %


def test_calibration_separates_the_friction_loop_from_the_clearance(friction_design):
    """A synthetic loop with friction (pins μ = 0.15, i.e. scale 1.5 on the design's 0.1), clearance and
    compliance: the fit with a friction parameter recovers all three within their intervals, each separable
    (the width grows with the torque, the clearance opens the loop at zero torque, the compliance sets the
    mid-line's slope); without it the loop's width is left in the residuals."""
    from rvtol.models.calibration import calibrate
    from synthetic_curves import synthetic_measurement

    truth = {"compliance.all": 1.2, "clearance.crank_bearing": 2.0, "friction.pin": 1.5}
    arcsec = float(np.radians(1 / 3600))
    m = synthetic_measurement(friction_design, "torsion", truth, sigma=0.3 * arcsec, seed=20261201, points=12)
    f = calibrate(friction_design, [m], list(truth)).fit
    assert f.success and f.identifiability.ok
    for j, name in enumerate(f.names):
        if name in truth:
            want = float(units_to_base(truth[name], f.parameters[j].unit))
            assert f.ci[j, 0] <= want <= f.ci[j, 1], name
    blind = calibrate(friction_design, [m], ["compliance.all", "clearance.crank_bearing"]).fit
    assert blind.s2 > 5 * f.s2


def units_to_base(v, unit):
    from rvtol import units

    return units.to_base(v, unit)


class _SpringSolver:
    """A spring of stiffness k with free play ±c as the 20-DOF solver's stand-in for :meth:`_reading`: the
    frictionless angle θ₀(T_e) = sign(T_e)(c + |T_e|/k) and a friction torque that depends on the flank in
    contact (``tf_pos`` for T_e > 0, ``tf_neg`` below)."""

    def __init__(self, k, c, tf_pos, tf_neg):
        self.k, self.c, self.tf_pos, self.tf_neg = k, c, tf_pos, tf_neg

    def theta(self, te):
        return math.copysign(self.c + abs(te) / self.k, te) if te != 0 else 0.0

    def sweep(self, theta_c, torque, dth, q0):
        te = float(torque[0])
        return type("S", (), dict(ok=True, failure=0, te=np.array([self.theta(te)]), q=np.zeros((1, 1)),
                                  torque=np.array([te])))()

    def friction_torques(self, s):
        te = float(s.torque[0])
        return np.array([self.tf_pos if te > 0 else self.tf_neg]), None


def test_reading_point_stuck_at_the_far_edge_of_the_free_play():
    """Descending branch at −p with a friction T0 < p while the positive flank carries and T1 > p on the negative
    flank: no elastic torque satisfies T_e − T_f(T_e) = −p on either side (the positive side reaches only −T0, the
    negative side starts below −T1), so the reducer crosses the play and sticks at its negative edge, θ = −c; with
    T1 < p the reading is the ordinary root T_e = −p + T1, θ = −(c + (p − T1)/k); with T0 > p it stays on the
    positive flank, T_e = T0 − p (path dependence: the negative flank has a root too, T_e = −p + T1)."""
    k, c, rated, p = 50.0, 0.02, 1000.0, 30.0
    m = TorsionCurveModel.__new__(TorsionCurveModel)
    m.torque = rated
    torque, branch = torque_schedule(rated, 8, 3.0)
    r = type("R", (), dict(torque=torque, theta_c=np.zeros(torque.size), q=np.zeros((torque.size, 1))))()
    cases = [(10.0, 40.0, -c, None), (10.0, 20.0, -(c + (p - 20.0) / k), -p + 20.0),
             (45.0, 20.0, c + (45.0 - p) / k, 45.0 - p)]
    for t0, t1, angle, te in cases:
        solver = _SpringSolver(k, c, t0, t1)
        tf = np.array([t0 if t > 0 else t1 for t in torque])
        got = m._reading(solver, r, tf, branch, 1, -p)
        assert not isinstance(got, int)
        assert got[2] == pytest.approx(angle, rel=1e-9, abs=1e-6 * rated / k), (t0, t1)   # the edge: T_e ~ 1e-9 T_r
        if te is None:
            assert -1e-6 * rated < got[3] < 0.0                     # at the negative edge of the play
        else:
            assert got[3] == pytest.approx(te, rel=1e-9)
    # the first loading starts inside the play and reaches only the positive flank, though T_e + T_f(T_e) = p has
    # a root on the negative one too (T1 > p)
    got = m._reading(_SpringSolver(k, c, 10.0, 40.0), r, np.where(torque > 0, 10.0, 40.0), branch, 0, p)
    assert got[3] == pytest.approx(p - 10.0, rel=1e-9) and got[2] == pytest.approx(c + (p - 10.0) / k, rel=1e-9)


def test_a_clearance_free_reducer_with_friction_has_its_loop(product):
    """The clearance-free, error-free reducer (the torsion-curve report's first curve): no free play, so a reading
    that sticks at the edge of the play is solved at a small load its contacts can carry (their laws k0·P^0.1 have
    no stiffness at zero load) — a curve, not 'contact lost everywhere' — and its readings are the frictionless
    ones moved by the friction as on a reducer with play."""
    with_, without = (TorsionCurveModel(product, (), friction=f).curve() for f in (True, False))
    assert with_.ok and without.ok, with_.reason
    w, wo = with_.metrics(3.0), without.metrics(3.0)
    assert w.friction_width > 0.1 * math.pi / 180 / 3600 and wo.friction_width < 1e-9 * w.friction_width
    assert abs(w.lost_motion - wo.lost_motion) < 0.1 * w.friction_width
    assert wo.rigidity < w.rigidity < 1.1 * wo.rigidity
