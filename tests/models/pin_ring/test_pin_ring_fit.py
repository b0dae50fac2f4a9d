"""The discs' fit in the pin ring, per pin (rvtol.models.pin_ring; derivation in data/products/rv80e/mapping.md §6).

References: the cycloid geometry by hand (n(φ) of the profile modification, doc 004; the contact normal through
the pitch point and its arm R_d sin α, doc 000 §1.3), scipy.optimize.linprog for the linear programme, and the
isotropic reading the per-pin criterion replaces.
"""
import math

import numpy as np
import pytest
from scipy.optimize import linprog

from rvtol.design import load_design
from rvtol.errors import InputError
from rvtol.models.pin_ring.fit import disc_fit_margin, turn_free_margin
from rvtol.models.pin_ring.model import PinRingFitModel, from_study
from rvtol.models.reducer_20dof.contacts import pin_contacts
from rvtol.params import Params

from conftest import ROOT

UM = 1e-3
DR, DRM, G = -22.11 * UM, -30.0 * UM, 5.0 * UM        # the RV-80E as built: Δr_p, ΔR_p, the pin's clearance g


@pytest.fixture(scope="module")
def design():
    return load_design(ROOT / "data/products/rv80e/design.toml")


@pytest.fixture(scope="module")
def model(design):
    names = ["disc_u[1]", "disc_v[1]", "disc_alpha[1]", "disc_beta[1]", "disc_u[2]", "disc_v[2]",
             "equidistance_mod[1]", "moved_distance_mod[1]", "equidistance_mod[2]", "moved_distance_mod[2]",
             "delta_pin"]
    return PinRingFitModel(design, names, 12.0)


def _row(model, **offsets):
    """The as-built profile and pins (uniform), and the disc offsets given (mm, rad)."""
    x = np.zeros(len(model.inputs))
    vals = {"equidistance_mod[1]": DR, "moved_distance_mod[1]": DRM, "equidistance_mod[2]": DR,
            "moved_distance_mod[2]": DRM, "delta_pin": G, **offsets}
    for k, v in vals.items():
        x[model.inputs.index(k)] = v
    return x


def _hand(design):
    """Pin angles from the eccentric, n(φ) + g, cos α, sin α and R_d sin α by hand (doc 004, doc 000)."""
    zb, e, rp = int(design["pin.count"]), design["cycloid.eccentricity"], design["pin.circle_radius"]
    K1 = zb * e / rp
    phi = 2 * np.pi * np.arange(zb) / zb
    S = np.sqrt(1 + K1 ** 2 - 2 * K1 * np.cos(phi))
    c = DR - DRM * (1 - K1 * np.cos(phi)) / S + G
    return phi, c, (np.cos(phi) - K1) / S, np.sin(phi) / S, (zb - 1) * e * np.sin(phi) / S


def test_the_kernels_pin_geometry_is_the_cycloids(design, model):
    """Normals from the pitch point P = z_b e u_e to each pin centre, arms R_d sin α, clearances n(φ) + g."""
    phi, c, ca, sa, arm = _hand(design)
    C = model.clearances(_row(model)[None])[0]
    np.testing.assert_allclose(C[0], c, rtol=0, atol=1e-15)
    np.testing.assert_allclose(model.normal[0], np.stack([ca, sa], axis=1), rtol=0, atol=1e-15)
    np.testing.assert_allclose(model.arm[0], arm, rtol=0, atol=1e-12)
    # disc 2: its eccentric along −x, the same pins seen from the other side
    np.testing.assert_allclose(C[1], np.roll(c, len(c) // 2), rtol=0, atol=1e-15)
    # the as-built numbers of build.md: ≈ 1.5 µm across the eccentric direction (φ0 = 38.3°), 12.9 µm along it
    assert c.min() == pytest.approx(1.527e-3, abs=1e-6) and c[0] == pytest.approx(12.89e-3, abs=1e-5)


def test_zero_offset_leaves_the_tightest_pin(design, model):
    """(1) No offset: margin = min_k c_k (the ring is symmetric about the eccentric: the best turn is none)."""
    _, c, *_ = _hand(design)
    y = model.evaluate(_row(model)[None])[0]
    assert y[0] == pytest.approx(c.min(), abs=1e-15) and y[2] == pytest.approx(c.min(), abs=1e-15)
    assert y[1] == pytest.approx(c.min(), abs=1e-15)                # clearance_min


@pytest.mark.parametrize("d_um", [2.0, 5.0, -5.0, 12.0])
def test_an_offset_along_the_eccentric_against_one_across_it(design, model, d_um):
    """(2) Along the eccentric (x for disc 1): by symmetry ψ = 0 and m = min_k (c_k − d cos α_k), by hand from n(φ).
    Across it (y): the disc rolls about P (every normal passes through P): ψ = −d/R_d takes it up, m = min c."""
    _, c, ca, _, _ = _hand(design)
    d = d_um * UM
    along = model.evaluate(_row(model, **{"disc_u[1]": d})[None])[0, 0]
    assert along == pytest.approx(np.min(c - d * ca), abs=1e-12)
    across = model.evaluate(_row(model, **{"disc_v[1]": d})[None])[0, 0]
    assert across == pytest.approx(c.min(), abs=1e-12)
    # disc 2's eccentric points along −x: +u in housing axes is −d along its eccentric
    d2 = model.evaluate(_row(model, **{"disc_u[2]": d})[None])[0, 2]
    assert d2 == pytest.approx(np.min(c + d * ca), abs=1e-12)
    if d_um == 5.0:   # the numbers by hand: 5 µm towards the eccentric leaves 1.120 µm, away from it 1.132 µm
        assert along == pytest.approx(1.1199e-3, abs=1e-7) and d2 == pytest.approx(1.1318e-3, abs=1e-7)


def test_a_tilted_disc_must_fit_at_both_faces(design, model):
    """A tilt α about x puts the faces at y = ∓α b/2: the turn takes up their mean (0), not their difference,
    so m = min_k (c_k − α b/2 |sin α_k|) (ψ = 0 by symmetry)."""
    _, c, _, sa, _ = _hand(design)
    tilt = math.radians(1 / 60)                                     # 1′
    m = model.evaluate(_row(model, **{"disc_alpha[1]": tilt})[None])[0, 0]
    assert m == pytest.approx(np.min(c - tilt * 6.0 * np.abs(sa)), abs=1e-12)
    assert m < c.min() - 1.5e-3                                     # 1′ over 12 mm: 1.75 µm at the φ0 pins


def _linprog_margin(a, arm):
    """max t s.t. t + arm_k ψ ≤ a_k (ψ, t free) with HiGHS."""
    A = np.column_stack([arm, np.ones_like(arm)])
    r = linprog([0.0, -1.0], A_ub=A, b_ub=a, bounds=[(None, None), (None, None)], method="highs")
    assert r.status == 0, r.message
    return r.x[1]


def test_the_closed_form_is_the_linear_programme():
    """(3) The closed form against scipy.optimize.linprog on random rings (units: µm, arms ~ R_d)."""
    rng = np.random.default_rng(7)
    for _ in range(60):
        m = int(rng.integers(3, 30))
        arm = rng.normal(0.0, 40.0, m)
        arm[rng.random(m) < 0.1] = 0.0                                # flat constraints too
        arm[0], arm[1] = abs(arm[0]) + 1.0, -abs(arm[1]) - 1.0        # both signs: a bounded turn
        a = rng.normal(2.0, 3.0, (4, m))
        got = turn_free_margin(a, arm)
        for row, g in zip(a, got):
            assert g == pytest.approx(_linprog_margin(row, arm), abs=1e-7)
    # a disc with random normals, arms and two faces
    zb = 40
    th = rng.uniform(0, 2 * np.pi, zb)
    normal = np.stack([np.cos(th), np.sin(th)], axis=1)
    arm = 58.5 * np.sin(rng.uniform(0, 2 * np.pi, zb))
    c = rng.normal(3.0, 2.0, (5, zb))
    faces = rng.normal(0.0, 4.0, (5, 2, 2))
    got = disc_fit_margin(c, normal, arm, faces)
    for i in range(5):
        A = np.column_stack([np.concatenate([arm, arm]), np.ones(2 * zb)])
        b = np.concatenate([c[i] - normal @ faces[i, 0], c[i] - normal @ faces[i, 1]])
        r = linprog([0.0, -1.0], A_ub=A, b_ub=b, bounds=[(None, None), (None, None)], method="highs")
        assert got[i] == pytest.approx(r.x[1], abs=1e-7)
    # nothing bounds the turn: +inf
    assert turn_free_margin(np.array([[1.0, 2.0]]), np.array([1.0, 2.0]))[0] == np.inf


def test_the_isotropic_case_is_the_old_reading():
    """(4) One clearance c at every pin, radial normals (no arm): m = c − max_k n_k·d — c − |d| for an offset
    towards a pin, and within |d|(1 − cos(π/z)) of it otherwise (c − |d| for a dense ring)."""
    c = 1.5
    for z in (40, 3600):
        th = 2 * np.pi * np.arange(z) / z
        normal = np.stack([np.cos(th), np.sin(th)], axis=1)
        for d in ([3.0, 0.0], [0.0, -2.0], [2.0, 2.5], [-4.0, 1.0]):
            d = np.array(d)
            m = disc_fit_margin(np.full(z, c), normal, np.zeros(z), np.stack([d, d])[None])[0]
            r = np.hypot(*d)
            assert c - r - 1e-12 <= m <= c - r * math.cos(math.pi / z) + 1e-12
            if abs(d[1]) < 1e-15 or abs(d[0]) < 1e-15:
                assert m == pytest.approx(c - r, abs=1e-12)


def test_the_clearances_are_the_kernels_sample_by_sample(design):
    """The model's sum of columns against the kernel's table (pin_contacts) on random reducers: every pin-ring,
    pin and disc-pattern factor, phases included, and factors that do not reach the pins."""
    names = ["R_pc", "R_pin_h[2]", "R_pin_h_phase[2]", "AP_pin_h[2]", "AP_pin_h_phase[2]", "R_pin[3]", "AP_pin[7]",
             "delta_pin[5]", "delta_pin", "equidistance_mod[1]", "moved_distance_mod[1]", "equidistance_mod[2]",
             "moved_distance_mod[2]", "R_cyc_h[1,2]", "R_cyc_h_phase[1,2]", "AP_cyc_h[2,2]", "AP_cyc_h_phase[2,2]",
             "R_cyc_c[2,1]", "E_c[1,1]", "beta_c[1,1]", "delta_b[2,3]", "disc_u[1]"]
    m = PinRingFitModel(design, names, 12.0)
    rng = np.random.default_rng(3)
    X = rng.normal(0.0, 3 * UM, (8, len(names)))
    for p in ("R_pin_h_phase[2]", "AP_pin_h_phase[2]", "R_cyc_h_phase[1,2]", "AP_cyc_h_phase[2,2]", "beta_c[1,1]"):
        X[:, names.index(p)] = rng.uniform(0, 2 * np.pi, 8)
    X[:, names.index("delta_b[2,3]")] = np.abs(X[:, names.index("delta_b[2,3]")])
    C = m.clearances(X)
    err = [n for n in names if n != "disc_u[1]"]
    for x, c in zip(X, C):
        ref = pin_contacts(m.geometry, m.factors.state(x[[names.index(n) for n in err]])).clearance
        np.testing.assert_allclose(c, ref, rtol=0, atol=1e-15)
    deps = m.dependencies()
    assert not {"E_c[1,1]", "beta_c[1,1]", "delta_b[2,3]"} & (deps["disc_1.margin"] | deps["disc_2.margin"])
    assert "R_cyc_h[1,2]" in deps["disc_1.margin"] and "R_cyc_h[1,2]" not in deps["disc_2.margin"]
    assert "disc_u[1]" in deps["disc_1.margin"] and "disc_u[1]" not in deps["disc_1.clearance_min"]
    # row-deterministic: a row's result does not depend on the rows evaluated with it
    Y = m.evaluate(X)
    np.testing.assert_array_equal(np.vstack([m.evaluate(X[:3]), m.evaluate(X[3:])]), Y)


def test_a_bad_pin_ring_table_names_its_key(design):
    with pytest.raises(InputError) as e:
        from_study(Params({"width": -1.0}, file="s.toml", key="model[6]"), design, _Names(["disc_u[1]"]))
    assert e.value.key == "model[6].width"
    with pytest.raises(InputError, match="unknown error factor 'disc_w\\[1\\]'"):
        PinRingFitModel(design, ["disc_w[1]"], 12.0)


class _Names:
    def __init__(self, names):
        self.names = tuple(names)
