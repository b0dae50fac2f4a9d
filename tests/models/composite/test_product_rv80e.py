"""The RV-80E sign-off study: one drawing sample drives the stack-up, the 20-DOF torsion curve and TE and
doc 001's screening through the declared mapping, and equals the direct computation of mapping.md."""
import copy
import math
from dataclasses import replace

import numpy as np
import pytest

import rv80e_reference as ref
from conftest import ROOT
from rvtol.executors import make_executor
from rvtol.mc import run_monte_carlo
from rvtol.models.composite.model import CompositeModel
from rvtol.models.pin_ring.preload import PinRingPreloadModel
from rvtol.models.torsion_curve.model import TorsionCurveModel
from rvtol.models.reducer_20dof import layout as L
from rvtol.models.transmission_error.model import TransmissionErrorModel
from rvtol.models.transmission_error.rig import INPUTS as RIG_INPUTS
from rvtol.sampling import sample
from rvtol.study import load_study

STUDY = ROOT / "studies" / "rv80e_signoff.toml"
UM = 1e-3                      # mm per µm


@pytest.fixture(scope="module")
def study():
    return load_study(STUDY, n=3, executor="serial", progress=False)


@pytest.fixture(scope="module")
def drawn(study):
    """20 random reducers: the sample (base units) and the factor values in their drawing units."""
    ss = sample(study.spec, 20, "random", seed=5)
    return ss.values, ref.values(ss)


def _stackup_matrix(model: CompositeModel, X):
    """The stack-up's inputs on the parts as drawn."""
    env = {n: X[:, j] for j, n in enumerate(model.inputs)}
    for q in model.quantities:
        env[q.name] = np.broadcast_to(np.asarray(q.expression.evaluate(env), float), (len(X),))
    st = model.stage("stackup")
    return st.model, CompositeModel.stage_matrix(st, env, len(X))


def test_the_study_composes_six_models_on_the_drawing_spec(study):
    m = study.model
    # 284 drawing factors (tolerances.toml: 281 and the three planets' clocking, issue 39), the TE rig's 4
    # (data/rigs/te_rig_single_head.toml), the 19 gauge errors of the build and its 3 process factors (build.toml:
    # the run-in settling of each crank's preloaded stack)
    assert len(study.spec) == 284 + 4 + 19 + 3 and m.inputs == study.spec.names
    assert sum(n.startswith("gauge.") for n in m.inputs) == 19 and m.build is study.build
    assert sum(n.startswith("process.") for n in m.inputs) == 3
    assert sum(n.startswith("rig.") for n in m.inputs) == 4
    assert [s.name for s in m.stages] == ["stackup", "disc_location", "torsion", "te", "screening", "reducer",
                                          "pin_ring", "pin_preload"]
    assert m.stage("pin_preload").model.inputs == m.stage("torsion").model.inputs
    torsion, te, ring = m.stage("torsion"), m.stage("te"), m.stage("pin_ring")
    n = len(torsion.model.inputs)          # same_inputs_as, the planets' driving flanks and the rig's chain beside it
    assert te.model.inputs[:n] == torsion.model.inputs and te.inputs[:n] == torsion.inputs
    assert te.model.inputs[n:] == ("s_p[1]", "s_p[2]", "s_p[3]") + RIG_INPUTS
    # the pin-ring fit: the torsion curve's mapping (the pins' clearances) and the stack-up's disc places
    assert ring.model.inputs[:n] == torsion.model.inputs and ring.inputs[:n] == torsion.inputs
    assert [e.text for e in ring.inputs[n:]] == [f"stackup.disc_{j}_in_pin_ring.{c}" for j in (1, 2)
                                                 for c in ("u", "v", "alpha", "beta")]
    assert len(torsion.model.inputs) == 189 and len(m.stage("screening").model.inputs) == 7   # + phi_p[1..3], the preloads
    assert {r.output for r in study.requirements} <= set(m.output_names)


def test_the_discs_place_in_the_pin_ring_is_the_chain_through_crank_1(drawn, study):
    """disc_j_in_pin_ring (u, v) at the disc's mid-plane z_j, housing axes: the carrier's axis in the housing
    H(z_j) + crank 1's axis in the carrier a_1(z_j) + cam j on crank 1 c_1j − the disc's hole 1 h_j1 (the disc goes
    onto crank 1's cam, centred; at the reference position every part's axes are the housing's) — exactly to first
    order (the analytic linearisation); the exact-rotation chain differs by second-order terms only (products of
    the parts' tilts, ~3e-4 rad, with lever arms up to the 42-mm crank circle: nanometres), which the same sample
    at half its deviations shows: the difference falls by 4."""
    X, v = drawn
    su, Xs = _stackup_matrix(study.model, X)
    J = su.jacobian()
    rest = []
    for scale in (1.0, 0.5):
        devs, status = su.kc_deviations(scale * Xs)
        assert (status == 0).all()
        r = []
        for j in (1, 2):
            z = ref.Z_DISC[j]
            uv = (ref.axis_at(v, "housing.main_raceways.coaxiality", z) + ref.a(v, 1, z) + ref.cam(v, 1, j)
                  - ref.hole(v, j, 1)) * UM * scale
            name = f"disc_{j}_in_pin_ring"
            np.testing.assert_allclose(scale * (Xs @ J[name].T)[:, :2], uv, rtol=0, atol=1e-12, err_msg=name)
            r.append(np.abs(devs[name][:, :2] - uv).max())
        rest.append(max(r))
    assert rest[0] < 5e-6 and rest[1] == pytest.approx(rest[0] / 4, rel=0.1)


def test_the_discs_tilt_on_three_cranks_is_the_mean_of_the_rows_and_reduces_to_the_single_crank_chain(drawn, study):
    """disc_location.disc_j.tilt = |mean_i (cam i's tilt in the housing − hole i's tilt in the disc)| (issue 39: the
    three needle rows' balance). Its crank-1 term alone is the stack-up's single-crank chain disc_j_in_pin_ring
    (α, β) — the frames and signs the stage combines are the stack-up's own; and on three rows the tilt is smaller
    than on one in the mean square (independent rows: the mean of three)."""
    X, _ = drawn
    m = study.model
    env, status = m.environment(X, {"stackup", "disc_location"})
    assert (status == 0).all()
    for j in (1, 2):
        one = {c: env[f"stackup.crank_1_cam_{j}_tilt.{c}"] - env[f"stackup.disc_{j}_hole_1.{c}"] for c in ("alpha", "beta")}
        for c in ("alpha", "beta"):
            np.testing.assert_allclose(one[c], env[f"stackup.disc_{j}_in_pin_ring.{c}"], rtol=0, atol=1e-10)
        mean = [np.mean([env[f"stackup.crank_{i}_cam_{j}_tilt.{c}"] - env[f"stackup.disc_{j}_hole_{i}.{c}"]
                         for i in (1, 2, 3)], axis=0) for c in ("alpha", "beta")]
        three = env[f"disc_location.disc_{j}.tilt"]
        np.testing.assert_allclose(three, np.hypot(*mean), rtol=1e-12)
        assert np.mean(three ** 2) < np.mean(one["alpha"] ** 2 + one["beta"] ** 2)


def test_stackup_kcs_equal_the_direct_formulas(drawn, study):
    """Every body-relative KC of the product assembly is the formula of mapping.md §1 — exactly to first
    order (the stack-up's analytic linearisation), and the exact-rotation chain within its second-order
    terms (a tilt ω of the carrier raceways moves a crank bore at r = 42 mm by ≈ |ω|² r / 2 ≤ 6e-7 mm)."""
    X, v = drawn
    su, Xs = _stackup_matrix(study.model, X)
    direct = ref.stackup_kcs(v)
    devs, status = su.kc_deviations(Xs)
    J = su.jacobian()
    assert (status == 0).all() and len(direct) == 28
    for name, uv in direct.items():
        linear = (Xs @ J[name].T)[:, :2]
        np.testing.assert_allclose(linear, uv * UM, rtol=0, atol=1e-12, err_msg=name)
        np.testing.assert_allclose(devs[name][:, :2], uv * UM, rtol=0, atol=1e-6, err_msg=name)


def _state_vectors(err):
    """The error state with every (magnitude, phase) pair as the 2-vector it stands for."""
    out = err.copy()
    pairs = [(L.E_S, L.BETA_S), (L.A_C, L.GAMMA_C)] + [(L.E_P + i, L.BETA_P + i) for i in range(3)] \
        + [(L.E_CA + i, L.BETA_CA + i) for i in range(3)] + [(L.E_C + k, L.BETA_C + k) for k in range(6)] \
        + [(L.E_H + k, L.BETA_H + k) for k in range(6)]
    for mag, ang in pairs:
        out[mag], out[ang] = err[mag] * np.cos(err[ang]), err[mag] * np.sin(err[ang])
    return out


def test_torsion_te_and_screening_inputs_equal_the_direct_computation(drawn, study):
    """The declared mapping on the parts as drawn (the build, which only replaces the values of the factors it
    sets, is tested in tests/production/test_build.py)."""
    X, v = drawn
    m, design = study.model.without_build(), study.design
    Xt = m.stage_inputs("torsion", X)
    Xe = m.stage_inputs("te", X)
    np.testing.assert_array_equal(Xe[:, :Xt.shape[1]], Xt)
    te_in = list(m.stage("te").model.inputs)
    # the planets' tooth thickness on the driving flank: the TE stage's own (issue 39)
    for i in (1, 2, 3):
        np.testing.assert_allclose(Xe[:, te_in.index(f"s_p[{i}]")], v[f"crank_{i}.planet_gear.tooth_thickness"] * UM,
                                   rtol=1e-12, atol=1e-15)
    # the TE rig's rings are centred with a dial indicator on the turning shafts (data/rigs: centring = "indicated"):
    # each is eccentric about its rotation axis by the rig's centring alone — the pilot's position and the raceways'
    # runout are indicated away (adding them counted them twice, issue 39)
    for c in ("x", "y"):
        for side in ("output", "input"):
            np.testing.assert_allclose(Xe[:, te_in.index(f"rig.{side}_eccentricity.{c}")],
                                       v[f"rig.{side}_encoder.centring.{c}"] * UM, rtol=1e-12, atol=1e-15)
    torsion = m.stage("torsion").model
    for row in range(len(X)):
        got, want = torsion.state(Xt[row]), ref.te_state(v, design, row)
        np.testing.assert_allclose(got.pin_err, want.pin_err, rtol=0, atol=1e-12)
        np.testing.assert_allclose(got.disc_h, want.disc_h, rtol=0, atol=1e-12)
        np.testing.assert_allclose(_state_vectors(got.err), _state_vectors(want.err), rtol=0, atol=1e-6)
    lm = m.stage("screening").model
    Xl = m.stage_inputs("screening", X)
    for name, col in ref.lm_inputs(v, design).items():
        np.testing.assert_allclose(Xl[:, lm.inputs.index(name)], col * UM, rtol=0,
                                   atol=1e-6 if name == "Delta_a" else 1e-12, err_msg=name)


def test_a_sample_through_the_composition_equals_the_models_on_the_direct_state(drawn, study):
    X, v = drawn
    m = study.model.without_build()
    rows = X[:2]
    Y, status = m.evaluate_with_status(rows)
    assert (status == 0).all()
    torsion, te = m.stage("torsion").model, m.stage("te").model
    for row in range(len(rows)):
        state = ref.te_state(v, study.design, row)
        te_state = ref.te_state(v, study.design, row, te=True)
        curve = copy.copy(torsion)
        curve.state = lambda x, s=state: s
        metrics = curve.curve(np.zeros(len(torsion.inputs))).metrics(torsion.percent)
        # the stack-up-derived inputs equal the direct formulas to 1e-6 mm (first-order formulas vs exact rotations,
        # test above); at the 41.9-mm crank circle that moves an output angle by ≲ 4 × 1e-6/41.9 rad (four
        # crank/cam vectors): the angles agree to that, the rigidity to 1e-5
        for name, value, tol in (("lost_motion", metrics.lost_motion, 1e-7), ("backlash", metrics.backlash, 1e-7),
                                 ("torsional_rigidity", metrics.rigidity, 0.0)):
            assert Y[row, m.output_index(f"torsion.{name}")] == pytest.approx(value, rel=1e-5, abs=tol), name
        x_te = m.stage_inputs("te", rows)[row]
        r, ext, ext_rig = te._sweep(te_state, te.rig_terms(x_te))
        assert Y[row, m.output_index("te.te_pp")] == pytest.approx(ext.pp, rel=1e-5, abs=1e-7)
        assert Y[row, m.output_index("te.te_pp_rig")] == pytest.approx(ext_rig.pp, rel=1e-5, abs=1e-7)
        # stage 5: the first stage's free play in series with the torsion curve (plays add; rigidity unchanged)
        play = Y[row, m.output_index("screening.involute_stage")] / study.design["reducer.ratio"]
        assert play > 0
        for name in ("lost_motion", "backlash"):
            assert Y[row, m.output_index(f"reducer.{name}")] == pytest.approx(
                Y[row, m.output_index(f"torsion.{name}")] + play, rel=1e-12), name


def _cheap(m: CompositeModel) -> CompositeModel:
    """The same composition with coarse 20-DOF settings (same inputs and structure, faster)."""
    stages = []
    for st in m.stages:
        if isinstance(st.model, TorsionCurveModel):
            st = replace(st, model=TorsionCurveModel(st.model.geometry, st.model.inputs, points=4))
        elif isinstance(st.model, TransmissionErrorModel):
            st = replace(st, model=TransmissionErrorModel(st.model.geometry, st.model.inputs, per_crank_rev=8,
                                                          rig=st.model.rig))
        elif isinstance(st.model, PinRingPreloadModel):
            st = replace(st, model=PinRingPreloadModel(st.model.geometry, st.model.inputs, per_crank_rev=8))
        stages.append(st)
    return CompositeModel(m.inputs, m.input_units, list(m.quantities), stages, m.build)


#: the cylindricities of the needle raceways (they reduce the fitted two-point clearance, mapping.toml)
NEEDLE_FORMS = ({f"disc_{j}.crank_hole_{i}.form" for j in (1, 2) for i in (1, 2, 3)}
                | {f"crank_{i}.cam_{j}.form" for j in (1, 2) for i in (1, 2, 3)})
#: the bore and eccentric sizes the needle gauges are fitted to (build.toml)
FITTED_SIZES = ({f"disc_{j}.crank_hole_{i}.diameter" for j in (1, 2) for i in (1, 2, 3)}
                | {f"crank_{i}.cam_{j}.diameter" for j in (1, 2) for i in (1, 2, 3)})
FITTED_SIZES |= {f"gauge.{n}" for n in FITTED_SIZES}          # … and their readings' errors


def test_each_drawing_factor_moves_exactly_the_outputs_that_depend_on_it(study):
    """The reducer as built: one drawing factor or gauge error at a time, +1 µm and −5 µm (+1 and −5 mrad on an
    angle; 1e-3 and 5e-3 × (1 + |nominal|) in base units) from the nominal
    (both signs: a min() over discs moves one way only): no output moves that ``depends_on`` does not
    name, and every output it names moves — except torsion-curve outputs of single pins: with the input
    locked, pins whose contact normal points (nearly) at the disc centre carry nothing near zero torque,
    and each disc's modification opens its pins from n0 = 3.6 µm at φ0 to 15 µm at φ = 0°, 180° (n_j(φ)),
    so only the pins around φ0 carry load at low torque and the backlash, a minimum over the pins, moves
    only with the pins that close first: the other pins' errors cannot move those figures (the TE sweep,
    a full revolution, sees every pin).  And the sizes the needle sets are fitted to: at the nominal every set
    is fitted to 1 µm two-point clearance, less than the nominal cylindricities (0.73 + 0.55 µm), so it is
    slightly preloaded (zero clearance in the 20-DOF model, mapping.md §3); a bore or eccentric step moves the
    gauge chosen and the fitted clearance, not the physics.  The discs' per-pin fit in the pin ring is a minimum
    over the pins too: a pin's own factor moves it only if the step can make that pin one of the tightest — a pin
    whose clearance against a disc is within the 5-µm step of that disc's tightest (the pins along the eccentric
    have 12.9 µm, those near φ0 = 38.3° from it 1.8 µm, mapping.md §6). The pins' no-load preload (stage
    pin_preload) is zero at the nominal, where every pin keeps its fitted clearance: a step moves it only where it
    closes a pin."""
    m = _cheap(study.model)
    deps = m.depends_on()
    x0 = study.spec.nominal_base()
    k = len(x0)
    runs = []
    for step in (1e-3, -5e-3):
        X = np.repeat(x0[None], k + 1, axis=0)
        X[1:] += np.diag(step * (1 + np.abs(x0)))
        Y, status = m.evaluate_with_status(X)
        assert (status == 0).all()
        runs.append(Y)
    unused, inactive, ring_pins = [], set(), set()
    for j, f in enumerate(study.spec.factors):
        moved = {o for i, o in enumerate(m.output_names) if any(Y[0, i] != Y[j + 1, i] for Y in runs)}
        want = {o for o, d in deps.items() if f.name in d}
        assert moved <= want, f.name
        missing = want - moved
        missing -= {o for o in missing if o.startswith("pin_preload.")}      # no pin closed by the step (docstring)
        if f.name in FITTED_SIZES | NEEDLE_FORMS:
            # through a needle set fitted below its cylindricities (docstring): a step moves the physics only if
            # it opens the set (the fit absorbs most size steps: a gauge one class up or down), and doc 001's Δ,
            # the tighter disc's mean over its three sets, not while the other disc's sets stay preloaded (0)
            assert moved and all(o.startswith(("torsion.", "reducer.", "te.", "screening.")) for o in missing), \
                (f.name, missing)
            assert f.name in NEEDLE_FORMS or any(o.startswith("build.needles.") for o in moved), f.name
            continue
        assert all(o.startswith(("torsion.", "reducer.", "pin_ring.")) for o in missing) and (not missing or f.family), (f.name, missing)
        inactive |= {f.name} if any(not o.startswith("pin_ring.") for o in missing) else set()
        if f.family and any(o.startswith("pin_ring.") for o in moved):
            ring_pins.add(int(f.name.split("[")[1].split("]")[0]))
        unused += [] if moved else [f.name]
    # the per-pin factors that move the pin-ring fit belong to pins a 5-µm step can make the tightest against a disc
    C = m.stage("pin_ring").model.clearances(m.stage_inputs("pin_ring", x0[None]))[0]
    near = {k + 1 for k in range(C.shape[1]) if any(C[j, k] - C[j].min() <= 5e-3 * (1 + 1e-3) for j in (0, 1))}
    assert ring_pins and ring_pins <= near and not {1, 21} & near, sorted(ring_pins - near)
    # a minority of the 120 per-pin factors: 43 at the built nominal, where the needle sets are fitted to zero play
    # and the cranks hold each disc, so the backlash (a minimum over the pins) sees only the pins that close first;
    # 4 on the same parts as drawn (needle play 2.7 µm lets the disc find more pins); 26 before issue 23
    assert len(inactive) < 60
    # mapping.md §8: the drawing tolerances no model uses (axial widths and gap) and the factors the build sets
    # (the pin set's lot and the needle sets' clearances are chosen per reducer, build.toml): their drawn values
    # do not reach the reducer; the crank-hole and eccentric sizes now do, through the needle fits
    assert sorted(unused) == sorted(["disc_1.width", "disc_2.width", "carrier.disc_gap", "pins.diameter_lot"]
                                    + [f"needles.disc_{j}.crank_{i}.clearance" for j in (1, 2) for i in (1, 2, 3)])


TWENTY_DOF = {"torsion.lost_motion", "torsion.backlash", "torsion.torsional_rigidity", "torsion.rigidity_50_100",
              "torsion.rigidity_clearance_free", "torsion.friction_width", "te.te_pp", "te.te_pp_rig",
              "reducer.lost_motion", "reducer.backlash"}
#: outputs that count something (whole numbers): a small step need not change them
COUNTS = {"pin_preload.preloaded_pins_max"}
#: the pin ring's no-load turn (stage pin_preload): the same 20-DOF reducer, no load on the output
PIN_PRELOAD = {f"pin_preload.{q}" for q in ("interference_max", "preload_max", "preloaded_pins_max", "pin_drag_max",
                                           "no_load_torque_max")}          # stage 5 adds the first stage's play in series
FIRST_STAGE = {"screening.involute_stage", "reducer.lost_motion", "reducer.backlash", "reducer.first_stage_play"}


@pytest.mark.parametrize("factor, outputs", [
    # by hand from mapping.md: tooth thickness reaches only doc 001's involute stage (E_w) and, through it, the
    # first stage's play in the reducer stage
    ("sun.tooth_thickness", {"screening.lost_motion"} | FIRST_STAGE),
    ("disc_1.width", set()),                                      # axial: no model
    # a carrier bore: crank 2's axis (stack-up KC), E_ca[2] of the 20-DOF, Δa of doc 001 and, since the discs sit
    # on all three cranks (issue 39), both discs' tilt where their needle rows locate them
    ("carrier.crank_bore_2.position.y1", {"stackup.crank_2_axis.radial", "stackup.crank_2_axis.tilt",
                                          "disc_location.disc_1.tilt", "disc_location.disc_2.tilt",
                                          "screening.lost_motion"} | FIRST_STAGE | TWENTY_DOF | PIN_PRELOAD),
    # the groove size: every pin's clearance g_k (the 20-DOF stages and the discs' per-pin fit in the pin ring), their
    # mean ḡ (doc 001's ξ) and, through the pin set the build chooses from it, the fitted pin-stage clearance
    ("housing.pin_groove.diameter", {"pin_clearance_mean", "pin_ring.disc_1.margin", "pin_ring.disc_2.margin",
                                     "pin_ring.disc_1.clearance_min", "pin_ring.disc_2.clearance_min",
                                     "screening.lost_motion",
                                     "screening.cycloid_stage", "build.pins.clearance"} | TWENTY_DOF | PIN_PRELOAD),
    # the end play of crank 1's bearing stack sets the preload its shim leaves, which the 20-DOF chains read
    # (crank_support_preload[1], issue 39)
    ("crank_1.support_pair.end_play", {"build.crank_1.support_pair.preload"} | TWENTY_DOF | PIN_PRELOAD),
    # and so does the stack's run-in settling
    ("process.crank_2.support_pair.settling", {"build.crank_2.support_pair.preload"} | TWENTY_DOF | PIN_PRELOAD),
    # the output pilot's position: not the reducer, and not a TE rig whose ring is centred by dial indicator on the
    # turning flange (issue 39: the indicator takes the pilot's eccentricity out)
    ("carrier.output_pilot.position.x", {"pilot_eccentricity.x"}),
    # a planet's clocking on its crank: the crank's phase in both 20-DOF stages (issue 39)
    ("crank_2.planet_gear.clocking", TWENTY_DOF | PIN_PRELOAD),
    # a planet's tooth thickness: doc 001's involute stage as before, and now the TE's driving flank (issue 39)
    ("crank_1.planet_gear.tooth_thickness", {"screening.lost_motion", "te.te_pp", "te.te_pp_rig"} | FIRST_STAGE),
    # the rig's own centring of its input ring: the rig's TE alone
    ("rig.input_encoder.centring.y", {"te.te_pp_rig"}),
])
def test_changing_one_drawing_tolerance_moves_exactly_its_outputs(study, factor, outputs):
    """The study's Monte Carlo (3 reducers, same seed) with one drawing tolerance doubled."""
    deps = study.model.depends_on()
    with make_executor("serial") as ex:
        runs = [run_monte_carlo(study.model, spec, 3, "lhs", 11, executor=ex, progress=False)
                for spec in (study.spec, study.spec.scaled({factor: 2.0}))]
    moved = {o for o in study.model.output_names if not np.array_equal(runs[0].column(o), runs[1].column(o))}
    assert outputs == {o for o, d in deps.items() if factor in d}
    # a count (of preloaded pins) moves only where the step closes or opens a pin: in 3 units it need not
    assert outputs - COUNTS <= moved <= outputs


def _order_1(res) -> tuple[complex, complex]:
    """The order-1 Fourier coefficients (arcsec) of the reducer's TE and of the TE the rig reads, ``c = a − i b``
    for ``a cos θ + b sin θ`` (the positions are uniform over one output revolution)."""
    c = lambda y: 2.0 / y.size * np.sum(y * np.exp(-1j * res.theta_c))  # noqa: E731
    return c(np.asarray(res.te)), c(np.asarray(res.te_rig))


def test_runout_sources_read_at_order_1_as_e_over_r_and_add_as_vectors(study):
    """Issue 23 item 5 through the whole model (drawing factors → mapping → TE stage with its rig), as issue 39
    corrected it.  The assumed rig centres its output ring with a dial indicator on the turning flange: the ring is
    eccentric about the rotation axis by the rig's centring alone, which reads (e_x sin θ + e_y cos θ)/R at order 1
    (R = 100 mm, the rig's ⌀200 ring; two components add as vectors).  The flange pilot's position p and the main
    raceways' runout m (axis end points at z = ±21 mm) — what a ring centred by its fit on the pilot would carry,
    mapping.toml pilot_eccentricity = p − m(z_f) with m extrapolated to the flange face z_f = 32 mm (checked here by
    the formula) — are indicated away: they reach neither the rig's reading nor the reducer's own TE (the carrier's
    translation moves all crank bores together: the two discs cancel it)."""
    m = study.model.without_build()
    st = m.stage("te").model
    te = TransmissionErrorModel(st.geometry, st.inputs, per_crank_rev=8, rig=st.rig)
    R = st.rig.output.radius
    assert R == 100.0 and st.rig.output.centring == "indicated"
    x0, names = study.spec.nominal_base(), list(study.spec.names)
    arcsec = float(np.degrees(1.0) * 3600.0)

    def setx(**values):
        x = x0.copy()
        for k, v in values.items():
            x[names.index(k)] = v * UM
        return x

    def run(**values):
        res = te.run(m.stage_inputs("te", setx(**values)[None])[0])
        assert res.ok
        return _order_1(res)

    def closed_form(ex, ey):                     # µm → the coefficient a − i b of (e_x sin θ + e_y cos θ)/R
        return (ey - 1j * ex) * UM / R * arcsec

    own0, rig0 = run()
    assert abs(own0) < 1e-6 and abs(rig0) < 1e-6
    pilot = {"carrier.output_pilot.position.x": 4.0}
    runout = {"carrier.main_raceways.runout.y1": 3.0, "carrier.main_raceways.runout.y2": 3.0}
    tilted = {"carrier.main_raceways.runout.x1": 3.0, "carrier.main_raceways.runout.x2": -3.0}
    for label, (values, e) in {"pilot": (pilot, (4.0, 0.0)), "runout": (runout, (0.0, -3.0)),
                               "tilted runout": (tilted, (-3.0 * (21 + 32) / 42 + 3.0 * (21 - 32) / 42, 0.0))}.items():
        own, on_rig = run(**values)
        assert abs(own) < 1e-6 and abs(on_rig) < 1e-6, label             # indicated away
        Y, status = m.evaluate_with_status(setx(**values)[None])
        got = [Y[0, m.output_index(f"pilot_eccentricity.{c}")] / UM for c in ("x", "y")]
        assert got == pytest.approx(list(e), abs=1e-9), label            # what a pilot-centred ring would carry
    got = {}
    for label, (values, e) in {"x": ({"rig.output_encoder.centring.x": 4.0}, (4.0, 0.0)),
                               "y": ({"rig.output_encoder.centring.y": -3.0}, (0.0, -3.0))}.items():
        own, on_rig = run(**values)
        assert abs(own) < 1e-6, label
        assert on_rig == pytest.approx(closed_form(*e), abs=1e-6), label
        got[label] = on_rig
    # the two components of known phase: the vector sum, |(4, −3)| = 5 µm → 5 µm/100 mm = 10.31″
    own, both = run(**{"rig.output_encoder.centring.x": 4.0, "rig.output_encoder.centring.y": -3.0})
    assert abs(own) < 1e-6
    assert both == pytest.approx(got["x"] + got["y"], abs=1e-6)
    assert abs(both) == pytest.approx(5.0 * UM / R * arcsec, rel=1e-9)
    assert abs(both) < abs(got["x"]) + abs(got["y"]) - 1.0               # not the arithmetic sum
