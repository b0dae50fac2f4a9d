"""Order attribution of the TE spectrum (rvtol.models.transmission_error.orders): each error family alone gives
orders on its lattice only (exact symmetries of the model, to the solver's tolerance) and its strongest
order where the kinematics says; two families together give their beats."""

import numpy as np
import pytest

from rvtol.models.transmission_error.model import TransmissionErrorModel
from rvtol.models.transmission_error.orders import (active_families, alias, expected_orders, families_frame,
                                              lattice_step, order_spectrum)

from conftest import ROOT

UM = 1e-3
#: positions per crank revolution: N = 81·40 = 3240 per output revolution, a multiple of 3, 40 and 120 (no
#: alias leaves its lattice) with the mesh order z_b·z_c = 1560 below N/2
PER = 81
#: off-lattice share of the spectrum (RMS over orders ≥ 1) allowed: the lattices are exact symmetries, so only
#: the solver's tolerance (residuals < 1e-5 N) is left — observed 1e-13 … 2e-8
OFF_LATTICE = 1e-6


def run(te_design, values):
    m = TransmissionErrorModel(te_design, list(values), per_crank_rev=PER)
    r = m.run(values)
    assert r.ok
    return m, r


def off_lattice_share(m, r):
    """RMS of the spectrum off the orders the active families are expected at, over the RMS of all orders ≥ 1."""
    k, a = order_spectrum(r.te)
    fams = active_families(m.factors.bindings, [r.factors[n] for n in m.inputs])
    ok = set()
    for f in fams:
        ok |= set(expected_orders(m.geometry, f, r.te.size))
    off = np.array([o not in ok for o in k])
    off[0] = False
    return np.sqrt(np.sum(a[off] ** 2) / np.sum(a[1:] ** 2)), a


def test_lattices_of_the_rv80e(te_geom):
    assert (te_geom.z_b, te_geom.z_c) == (40, 39)
    assert [lattice_step(te_geom, s) for s in ("housing", "carrier", "sun", "uniform")] == [3, 40, 40, 120]
    e = expected_orders(te_geom, "pin_ring", 1440)
    assert e[78] == "2·z_c" and e[81] == "2·z_c + 3" and e[3] == "3"
    assert 40 not in e and 1 not in e
    assert alias(1560, 1440) == 120
    assert "Z aliased from 1560" in expected_orders(te_geom, "uniform", 1440)[120]
    assert expected_orders(te_geom, "disc_profile", 3240)[80] == "2·z_b"
    assert len(families_frame(te_geom)) == 11          # with the crank phase (issue 39)


# values, family, strongest order, derivation (module doc of rvtol.models.transmission_error.orders)
SINGLE = [
    ({"R_cyc_h[1,1]": 5 * UM}, "disc_profile", 40, "disc 1, order 1: n·z_b"),
    ({"AP_cyc_h[2,2]": 3 * UM}, "disc_profile", 80, "disc 2 pitch, order 2"),
    ({"R_cyc_h[1,3]": 3 * UM}, "disc_profile", 120, "order 3 (an order the Table 3 patterns cannot give)"),
    ({"R_pin[4]": -3 * UM}, "pin_ring", 78, "one pin: both discs meet it half an eccentric turn apart: 2·z_c"),
    ({"AP_pin[9]": 3 * UM}, "pin_ring", 78, "one pin's pitch"),
    ({"delta_pin[4]": -3 * UM}, "pin_ring", 78, "one oversize pin"),
    ({"R_pin_h[2]": 3 * UM}, "pin_ring", 78, "pin-ring order 2 (even): 2·z_c"),
    ({"R_pin_h[3]": 3 * UM}, "pin_ring", 234, "pin-ring order 3 (odd: cancels between the discs at 3·z_c)"),
    ({"A_c": 5 * UM}, "carrier_offset", 78, "order-1 housing offset, common to both discs: 2·z_c"),
    ({"A_s": 5 * UM}, "input_support", 81, "housing-fixed sun offset: the sun's rotation i"),
    ({"E_h[1,1]": 3 * UM}, "disc_holes", 40, "one crank hole of disc 1"),
    ({"E_c[1,1]": 3 * UM}, "crank", 40, "one cam"),
    ({"delta_b[1,1]": 3 * UM}, "crank", 40, "one needle-bearing clearance"),
    ({"E_p[1]": 5 * UM}, "crank", 40, "one planet: turns its crank"),
    ({"phi_p[1]": 2e-4}, "crank_phase", 80, "one crank's phase: z_b cancels between the discs, 2·z_b"),
    ({"s_p[2]": 5 * UM}, "crank_phase", 80, "one planet's tooth thickness: the same as a phase"),
    ({"E_ca[1]": 3 * UM}, "carrier_bores", 80, "one carrier bore moves its crank under both discs: 2·z_b"),
    ({"E_s": 5 * UM}, "sun", 240, "sun eccentricity through three planets: 3(i − 1)"),
    ({"R_pc": 3 * UM}, "uniform", 1560, "pin-circle radius: only the mesh order Z"),
    ({"equidistance_mod": -15 * UM, "moved_distance_mod": -30 * UM}, "uniform", 1560, "profile modification"),
]


@pytest.mark.parametrize("values, family, strongest, why", SINGLE, ids=[s[3] for s in SINGLE])
def test_single_family_spectrum(te_design, values, family, strongest, why):
    m, r = run(te_design, values)
    assert set(active_families(m.factors.bindings, [r.factors[n] for n in m.inputs])) == {"nominal", family}
    share, a = off_lattice_share(m, r)
    assert share < OFF_LATTICE
    assert int(np.argmax(a[1:])) + 1 == strongest
    table = m.order_table(r, top=3)
    assert table["order [1/rev]"].iloc[0] == strongest and table["expected from"].iloc[0] != "—"


@pytest.mark.parametrize("values, odd, even", [
    ({"R_pin[4]": -3 * UM}, 39, 78),
    ({"R_pin_h[3]": 3 * UM}, 117, 234),
    ({"A_c": 5 * UM}, 39, 78),
    ({"E_ca[1]": 3 * UM}, 40, 80),
])
def test_errors_common_to_both_discs_cancel_at_odd_multiples(te_design, values, odd, even):
    """Disc 2 meets the pins with its other side: a common error's odd multiple cancels to first order
    (below 1 % of the even one; observed 2e-6 … 1.1e-3 of it)."""
    _, r = run(te_design, values)
    _, a = order_spectrum(r.te)
    assert a[odd] < 0.01 * a[even]


def test_two_families_beat_at_order_one(te_design):
    """One pin (housing-fixed, lattice 3) and a disc profile error (disc-fixed, lattice 40): alone neither
    has order 1 (their symmetries forbid it); together the nonlinear mesh mixes them at z_b − z_c = 1, and
    the table names the interaction."""
    pin, disc = {"R_pin[4]": -3 * UM}, {"R_cyc_h[1,1]": 3 * UM}
    amp = {}
    for name, v in (("pin", pin), ("disc", disc), ("both", {**pin, **disc})):
        m, r = run(te_design, v)
        amp[name] = order_spectrum(r.te)[1]
    for alone in ("pin", "disc"):
        assert amp[alone][1] < 1e-6 * amp[alone][1:].max()
    assert amp["both"][1] > 0.05 * amp["both"][1:].max()
    table = m.order_table(r, top=12)
    row = table[table["order [1/rev]"] == 1].iloc[0]
    assert row["expected from"] == "—" and row["interaction"] == "pin ring × disc profile: z_c − z_b"


def test_uniform_errors_shift_the_mean_by_their_backlash(te_design, te_geom):
    """A uniform opening of the pin stage has no order of its own; it moves the mean TE by the angle that
    takes up the normal clearance at the largest arm φ0 = arccos K1 (doc 004: n0 = Δr − √(1 − K1²)·ΔR, and a
    pin circle larger by δR acts as ΔR = −δR), n0/R_d — within 10 % (the rest: fewer pins carry the load, so
    the elastic wind-up grows)."""
    _, r0 = run(te_design, {"R_pc": 0.0})
    c1 = np.sqrt(1 - te_geom.K1 ** 2)
    for values, n0 in (({"R_pc": 3 * UM}, c1 * 3 * UM), ({"delta_pin": 3 * UM}, 3 * UM),
                       ({"equidistance_mod": -15 * UM, "moved_distance_mod": -30 * UM}, (-15 + c1 * 30) * UM)):
        _, r = run(te_design, values)
        shift = (r0.te.mean() - r.te.mean()) / 3600 * np.pi / 180        # arcsec -> rad, more wind-up
        assert shift == pytest.approx(n0 / te_geom.r_disc_pitch, rel=0.10)
        assert r.te_pp < 0.03 * abs(r.te.mean() - r0.te.mean())


# ----------------------------------------------------------------------------------- crank phase (issue 39 item 4)
def kinematic_shift(g, phi):
    """The TE of a phase φ common to the three cranks, rigid kinematics of both stages: the eccentrics turn
    φ ahead of the planets, θ_e = θ_p + φ with θ_p − θ_c = −(z_s/z_p)(θ_s − θ_c) and θ_e = (1 − z_b) θ_c
    give θ_c = θ_s/i − φ z_p/(z_s i) (rad)."""
    return -phi * g.z_p / (g.z_s * g.ratio)


ARCSEC = np.pi / 180 / 3600


def test_a_phase_common_to_the_three_cranks_shifts_the_te_by_the_kinematic_angle(te_design, te_geom):
    """φ on every crank (or a tooth thickness s on every planet: φ = −(s/2) cos α / r_bp) moves the mean TE by
    exactly the kinematic angle and adds no ripple below 3·z_b (the three cranks stay alike)."""
    _, r0 = run(te_design, {"R_pc": 0.0})
    g = te_geom
    for values, phi in (({"phi_p": 1e-4}, 1e-4), ({"s_p": 5 * UM}, -0.5 * 5 * UM * np.cos(g.alpha) / g.r_bp)):
        m, r = run(te_design, values)
        shift = (r.te.mean() - r0.te.mean()) * ARCSEC
        assert shift == pytest.approx(kinematic_shift(g, phi), rel=1e-6)
        _, a = order_spectrum(r.te - r0.te)
        off = [k for k in range(1, a.size) if k % (3 * g.z_b)]
        assert np.sqrt(np.sum(a[off] ** 2)) < 1e-6 * abs(shift / ARCSEC)


def test_one_crank_phase_gives_multiples_of_z_b_and_no_order_three(te_design, te_geom):
    """One crank's phase is a carrier-side error: multiples of z_b only (an exact symmetry — no order 3, no order
    1); z_b itself cancels between the discs (the rigid discs' compromise on three cams turns them by
    ±e·φ·cos(z_b θ)/(3a'), opposite for the two discs), so 2·z_b is the strongest; its mean shift is a third of
    the common phase's (first-order superposition: within 3 % at φ = 1e-4 rad, 1.8 % observed)."""
    phi = 1e-4
    _, r0 = run(te_design, {"R_pc": 0.0})
    m, r = run(te_design, {"phi_p[1]": phi})
    share, a = off_lattice_share(m, r)
    assert share < OFF_LATTICE
    assert a[3] < 1e-6 * a[1:].max() and a[1] < 1e-6 * a[1:].max()
    assert a[40] < 0.01 * a[80]
    shift = (r.te.mean() - r0.te.mean()) * ARCSEC
    assert shift == pytest.approx(kinematic_shift(te_geom, phi) / 3, rel=0.03)


def test_a_crank_phase_is_both_cams_moved_at_right_angles(te_design, te_geom):
    """φ_i ahead of the planet is, to the model, both cams of crank i moved e·φ_i perpendicular to their
    eccentrics (E_c[j,i] = eφ, β_c = 90°): the same TE to round-off."""
    phi, e = 2e-4, te_geom.ecc
    _, a = run(te_design, {"phi_p[2]": phi})
    _, b = run(te_design, {"E_c[1,2]": e * phi, "beta_c[1,2]": np.pi / 2, "E_c[2,2]": e * phi,
                           "beta_c[2,2]": np.pi / 2})
    assert np.abs(a.te - b.te).max() < 1e-9 * np.ptp(a.te)


def test_order_table_lists_order_three_and_the_input_orders_with_their_sources(te_design):
    """Asked orders are listed whatever their size: order 3 from a carrier offset (the three cranks passing a
    housing-fixed offset), the input orders i and 2·i from a sun-support offset; an order no active error gives
    says what could."""
    m, r = run(te_design, {"A_s": 5 * UM, "A_c": 5 * UM})
    t = m.order_table(r, top=3, orders=[3, 81, 162]).set_index("order [1/rev]")
    assert {3, 81, 162} <= set(t.index)
    assert "carrier offset [A_c]: 3" in t.loc[3, "expected from"]
    assert "sun support [A_s]: i;" in t.loc[81, "expected from"]
    assert "sun support [A_s]: 2·i" in t.loc[162, "expected from"]
    m, r = run(te_design, {"phi_p[1]": 2e-4})
    t = m.order_table(r, top=3, orders=[3, 81]).set_index("order [1/rev]")
    assert t.loc[3, "expected from"].startswith("— (no active error; could arise from: the three cranks passing "
                                                "housing-fixed errors")
    assert "sun-support offset A_s" in t.loc[81, "expected from"]
    assert t.loc[3, "amplitude [arcsec]"] < 1e-6 * t["amplitude [arcsec]"].max()
