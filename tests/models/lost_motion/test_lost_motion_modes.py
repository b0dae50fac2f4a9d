"""Doc 001's two modes: the consistent mode's rates against the 20-DOF torsion curve's backlash rates per factor,
closed forms of the derivation, the factor bridge, and the screening analysis beside the torsion curve."""
import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from rvtol import units
from rvtol.design import load_design
from rvtol.errors import InputError
from rvtol.model import Model, Quantity
from rvtol.models.lost_motion.model import LostMotionGeometry, LostMotionModel
from rvtol.models.screening import bridge as S
from rvtol.models.torsion_curve.model import TorsionCurveModel
from rvtol.models.reducer_20dof.geometry import geometry_from_design
from rvtol.models.reducer_20dof.quasistatic import QuasiStaticSolver
from rvtol.study import load_study, run_study

from conftest import ROOT, needs_wing, write

RV = load_design(ROOT / "data/designs/rv80e_te.toml")
G20 = geometry_from_design(RV)
CONS = LostMotionGeometry.from_design(RV, "consistent")
DOC = LostMotionGeometry.from_design(RV, "document")
PINS = S.pin_names(G20.z_b)
NAMES = S.CAMS + ("delta_pin", "delta_th") + PINS
REF, H = 0.002, 0.001                 # mm: 2 µm of clearance on the bearings and pins, ±1 µm steps
# doc-001 factor -> the 20-DOF factors one unit of it moves (Δ = 2δ_b; a pin-roller undersize ξ is a gap at every pin)
DIRECTIONS = {"Delta_b": {n: 0.5 for n in S.CAMS}, "Delta_r_c": {"delta_pin": 1.0},
              "xi_pin_roller": {"delta_th": 1.0}, "Delta_r_p": {n: 1.0 for n in PINS}}


@pytest.fixture(scope="module")
def fd_rates():
    """Central differences of the 20-DOF backlash and lost motion per doc-001 factor (rad/mm at the output)."""
    m = TorsionCurveModel(G20, NAMES)
    x0 = np.zeros(len(NAMES))
    x0[:7] = REF                       # six bearings and the pins; delta_th and R_pin start at zero
    rows = []
    for d in DIRECTIONS.values():
        v = np.array([d.get(n, 0.0) for n in NAMES])
        rows += [x0 + H * v, x0 - H * v]
    Y, status = m.evaluate_with_status(np.array(rows))
    assert not status.any()
    return {f: {"backlash": (Y[2 * k, 2] - Y[2 * k + 1, 2]) / (2 * H),
                "lost_motion": (Y[2 * k, 0] - Y[2 * k + 1, 0]) / (2 * H)} for k, f in enumerate(DIRECTIONS)}


def test_consistent_coefficients_are_the_closed_forms_of_the_kinematics():
    c = CONS.output_coefficients()
    ib = 78 / 81                                  # (1 − 1/81) · 39/40
    a_w = 41.93664                                # m(z_s + z_pl)/2 · cos α / cos α_w with x = 0.519, −0.555
    root = math.sqrt(1 - (1.5 * 40 / 76.5) ** 2)
    assert CONS.disc_to_output == pytest.approx(ib, rel=1e-14)
    assert c["Delta_b"] == pytest.approx(ib / a_w, rel=1e-6)                 # K = 1
    assert c["Delta_r_c"] == pytest.approx(2 * ib / (1.5 * 39), rel=1e-14)   # flank to flank
    assert c["Delta_r_p"] == pytest.approx(2 * ib * root / (1.5 * 39), rel=1e-14)
    ca, sw = math.cos(math.radians(20)), math.sin(CONS.alpha_w)
    assert c["E_w"] == pytest.approx(-2 / (28 * ca) / 81, rel=1e-14)
    assert c["Delta_a"] == pytest.approx(4 * sw / (28 * ca) / 81, rel=1e-14)
    # document mode: as printed, no disc-to-output ratio, K from the design
    d = DOC.output_coefficients()
    assert d["Delta_b"] == pytest.approx(1 / (1.5 * a_w), rel=1e-6)
    assert d["Delta_r_c"] == pytest.approx(1 / (1.5 * 39), rel=1e-14)
    assert d["Delta_r_p"] == pytest.approx(1 / (1.5 * 39 * root), rel=1e-14)
    assert d["Delta_a"] == pytest.approx(4 * math.tan(math.radians(20)) / 28 / 81, rel=1e-14)


def test_the_first_contact_pin_multiplies_the_pin_circle_term_by_sqrt_1_minus_K1_squared():
    """min over the pin angle of gap/arm for a pin-circle error: (1 − K1 cos φ)/sin φ, numerically."""
    for K1 in (0.3, 0.6, 0.784, 0.9):
        r = minimize_scalar(lambda p: (1 - K1 * math.cos(p)) / math.sin(p), bounds=(1e-6, math.pi - 1e-6),
                            method="bounded", options={"xatol": 1e-12})
        assert r.fun == pytest.approx(math.sqrt(1 - K1 ** 2), rel=1e-9)
        assert math.cos(r.x) == pytest.approx(K1, abs=1e-5)           # at the largest arm, cos φ0 = K1


@pytest.mark.parametrize("factor", list(DIRECTIONS))
def test_consistent_rates_equal_the_20dof_backlash_rates(fd_rates, factor):
    like = "Delta_r_c" if factor == "xi_pin_roller" else factor     # derivative = "cycloid_radius"
    consistent = CONS.output_coefficients()[like]
    assert fd_rates[factor]["backlash"] == pytest.approx(consistent, rel=0.02)
    # the lost motion at ±3 % grows a little faster (the soft low-load range of the contact laws is re-entered)
    assert consistent < fd_rates[factor]["lost_motion"] < 1.1 * consistent


def test_document_rates_are_off_by_the_factors_the_derivation_names(fd_rates):
    ib, K1 = CONS.disc_to_output, CONS.K1
    doc = DOC.output_coefficients()
    assert doc["Delta_r_p"] / fd_rates["Delta_r_p"]["backlash"] == pytest.approx(1 / (2 * (1 - K1 ** 2) * ib),
                                                                                 rel=0.02)   # ≈ 1.35
    assert doc["Delta_b"] / fd_rates["Delta_b"]["backlash"] == pytest.approx(1 / (1.5 * ib), rel=0.02)  # ≈ 0.69
    assert doc["Delta_r_c"] / fd_rates["Delta_r_c"]["backlash"] == pytest.approx(1 / (2 * ib), rel=0.02)


def test_backlash_rates_function_is_the_same_finite_difference(fd_rates):
    r = S.backlash_rates(G20)
    for f in ("Delta_b", "Delta_r_c", "Delta_r_p"):
        for q in ("backlash", "lost_motion"):
            assert r[f][q] == pytest.approx(fd_rates[f][q], rel=1e-9)


def test_the_20dof_refers_an_input_play_to_the_output_by_1_over_i():
    """The involute stage seen through the reducer: the locked input turned by δ turns the output δ/i."""
    s = QuasiStaticSolver(G20, tol_f=1e-9)
    T, d = 0.1 * G20.rated_torque, 1e-3
    r = s.sweep([0.0, 0.0], [T, T], [0.0, d])
    assert r.ok
    assert (r.te[1] - r.te[0]) == pytest.approx(d / G20.ratio, rel=1e-6)
    assert CONS.to_output["involute_stage"] == pytest.approx(1 / G20.ratio, rel=1e-14)


# --------------------------------------------------------------------------- the bridge
def test_bridge_from_doc001_to_the_20dof_factors():
    m = LostMotionModel(CONS, ["E_w", "Delta_r_c", "Delta_r_p", "Delta_b", "xi", "zeta"],
                        extra={"xi": 1.0, "zeta": 2.0}, extra_like={"xi": "Delta_r_c"}, nominal={"Delta_a": 0.01})
    X = np.array([[-0.03, 0.003, 0.001, 0.004, 0.0005, 0.1]])
    b = S.lost_motion_to_torsion_curve(m, G20.z_b, X)
    x = dict(zip(b.tc_names, b.X_tc[0]))
    assert all(x[n] == pytest.approx(0.002) for n in S.CAMS)          # δ_b = Δ/2
    assert x["delta_pin"] == pytest.approx(0.0035)                     # Δr_c + ξ
    assert all(x[n] == pytest.approx(0.001) for n in PINS)            # Δr_p on every pin
    assert b.unseen_by_tc == ("zeta",)                                  # involute factors are played in series


def test_bridge_from_the_20dof_factors_to_doc001():
    names = S.CAMS + ("delta_pin", "delta_th", "E_c") + PINS[:2]
    m = TorsionCurveModel(G20, names)
    x = np.r_[[1, 2, 3, 1, 1, 1], [3, 0.5, 2], [4, 0]] * 1e-3
    b = S.torsion_curve_to_lost_motion(m, x)
    got = dict(zip(b.lm_names, b.X_lm[0]))
    assert got["Delta_b"] == pytest.approx(2 * 1e-3)          # 2 · min over discs of the mean (disc 2: 1 µm)
    assert got["Delta_r_c"] == pytest.approx(3.5e-3)
    assert got["Delta_r_p"] == pytest.approx(4e-3 / 40)       # mean radial position of the 40 pins
    assert b.unseen_by_lm == ("E_c",)
    g = TorsionCurveModel(G20, ("delta_b",))                  # the group: Table 3 pattern (e, e, 0), (e, 0, e)
    assert S.torsion_curve_to_lost_motion(g, [0.003]).X_lm[0, 0] == pytest.approx(2 * 0.002)


class _Own(Model):
    """A model that is neither: it gives both vocabularies itself (the screening_inputs protocol)."""

    inputs = ("c",)
    input_units = ("mm",)
    outputs = (Quantity("y", "mm", "um"),)

    def evaluate(self, X):
        return np.asarray(X, float)

    def screening_inputs(self, X):
        c = np.asarray(X, float)[:, :1]
        return {"lost_motion": (("Delta_b",), 2 * c), "torsion_curve": (S.CAMS, np.repeat(c, 6, axis=1))}


def test_a_model_can_give_both_vocabularies_itself():
    b = S.screening_inputs(_Own(), np.array([[0.001], [0.002]]), G20.z_b)
    assert b.lm_names == ("Delta_b",) and b.X_lm[:, 0] == pytest.approx([0.002, 0.004])
    assert b.tc_names == S.CAMS and b.X_tc.shape == (2, 6)
    with pytest.raises(InputError):
        S.screening_inputs(object(), np.zeros((1, 1)), G20.z_b)


# --------------------------------------------------------------------------- studies
LM_STUDY = """
[study]
name = "lm_screen"
design = "{design}"
spec = "{spec}"
[model]
kind = "lost_motion"
{mode}
[[model.cycloid_factor]]
factor = "Delta_r_rp"
derivative = "cycloid_radius"
source = "pin-roller undersize"
[sampling]
n = 200
method = "random"
seed = 7
[execution]
executor = "serial"
[[requirement]]
output = "lost_motion"
upper = 1.0
unit = "arcmin"
[[analysis]]
kind = "lost_motion_screening"
samples = 40
percent = {percent}
"""


def _lm_study(tmp_path, mode="", percent=3.0, extra=""):
    return write(tmp_path / "s.toml", LM_STUDY.format(design=ROOT / "data/designs/rv80e_te.toml",
                                                       spec=ROOT / "data/specs/rv80e_lost_motion.toml",
                                                       mode=mode, percent=percent) + extra)


def test_screening_analysis_sets_both_on_the_same_reducers(tmp_path):
    st = load_study(_lm_study(tmp_path, percent=5.0), progress=False)
    assert st.model.mode == "consistent"                       # the default for new studies
    res = run_study(st)
    sec = res.sections[0]
    s = sec.summary
    assert s["n"] == 40 and s["failed"] == 0 and s["percent"] == 5.0 and s["limit_arcmin"] == 1.0
    # recompute the subsample independently: same rows of the Monte Carlo, both models directly
    from rvtol.sampling import substream
    rows = np.sort(substream(st.options.seed, "screening_subsample").choice(200, 40, replace=False))
    X = res.mc.samples.values[rows]
    lm = st.model.evaluate(X)
    cols = list(st.model.inputs)
    x20 = np.zeros((40, len(S.CAMS) + 1 + G20.z_b))
    x20[:, :6] = X[:, [cols.index("Delta_b")]] / 2
    x20[:, 6] = X[:, cols.index("Delta_r_c")] + X[:, cols.index("Delta_r_rp")]
    x20[:, 7:] = X[:, [cols.index("Delta_r_p")]]
    tc = TorsionCurveModel(G20, S.CAMS + ("delta_pin",) + PINS, percent=5.0).evaluate(x20)
    amin = lambda v: units.from_base(v, "arcmin")  # noqa: E731
    inv = amin(lm[:, 1]) / 81
    mean = s["mean_arcmin"]
    assert mean["consistent"] == pytest.approx(amin(lm[:, 0]).mean(), rel=1e-12)
    assert mean["lost_motion"] == pytest.approx((amin(tc[:, 0]) + inv).mean(), rel=1e-12)
    assert mean["backlash"] == pytest.approx((amin(tc[:, 2]) + inv).mean(), rel=1e-12)
    assert mean["elastic"] == pytest.approx(amin(tc[:, 0] - tc[:, 2]).mean(), rel=1e-12)
    # the consistent estimate is the torsion curve's zero-load backlash, per reducer within a few %
    assert mean["consistent"] == pytest.approx(mean["backlash"], rel=0.02)
    rates = {r["factor"]: r for r in s["rates"]}
    for f in ("Delta_b", "Delta_r_c", "Delta_r_p", "Delta_r_rp"):
        assert rates[f]["consistent / 20-DOF"] == pytest.approx(1.0, rel=0.02)


def test_screening_analysis_on_a_torsion_curve_study_uses_its_outputs(tmp_path):
    assert 'kind = "lost_motion_screening"' in (ROOT / "studies/torsion_curve_rv80e.toml").read_text()
    factors = "".join(f"""
[[factor]]
name = "{n}"
unit = "um"
dist = "uniform"
lower = 0
upper = 3
""" for n in S.CAMS + ("delta_pin",))
    text = f"""
[study]
name = "tc_screen"
design = "{ROOT / 'data/designs/rv80e_te.toml'}"
[model]
kind = "torsion_curve"
percent = 5.0
{factors}
[sampling]
n = 24
method = "random"
seed = 3
[execution]
executor = "serial"
[[analysis]]
kind = "lost_motion_screening"
"""
    st = load_study(write(tmp_path / "tc.toml", text), progress=False)
    res = run_study(st)
    s = res.sections[0].summary
    assert s["n"] == 24 and s["percent"] == 5.0 and s["limit_arcmin"] == 1.0      # design's lost_motion_limit
    assert s["mean_arcmin"]["lost_motion"] == pytest.approx(np.mean(res.mc.column("lost_motion")), rel=1e-12)
    X = res.mc.samples.values
    delta = 2 * np.minimum(X[:, :3].mean(axis=1), X[:, 3:6].mean(axis=1))    # 2 · min over discs of the mean
    c = CONS.output_coefficients()
    screen = units.from_base(c["Delta_b"] * delta + c["Delta_r_c"] * X[:, 6], "arcmin")
    assert s["mean_arcmin"]["consistent"] == pytest.approx(screen.mean(), rel=1e-12)
    with pytest.raises(InputError) as e:     # the Monte Carlo outputs are read at the model's percent
        load_study(write(tmp_path / "tc2.toml", text + "percent = 3.0\n"))
    assert e.value.key.endswith("percent")


@needs_wing
def test_mode_and_reproduction_inputs_are_checked(tmp_path):
    with pytest.raises(InputError) as e:
        load_study(_lm_study(tmp_path, mode='mode = "printed"'))
    assert e.value.key == "model.mode"
    repro = f'\n[[analysis]]\nkind = "lost_motion_reproduction"\nprinted = "{ROOT / "data/reproduction/doc001_lost_motion.toml"}"\n'
    with pytest.raises(InputError) as e:
        load_study(_lm_study(tmp_path, extra=repro))
    assert "document" in e.value.reason and e.value.key.endswith(".kind")
    assert load_study(_lm_study(tmp_path, mode='mode = "document"', extra=repro)).model.mode == "document"


def test_screening_analysis_inputs_are_checked(tmp_path):
    doc = (f'[study]\nname = "x"\ndesign = "{ROOT / "data/designs/lost_motion_doc_example.toml"}"\n'
           f'spec = "{ROOT / "data/specs/lost_motion_doc_example.toml"}"\n[model]\nkind = "lost_motion"\n'
           '[[analysis]]\nkind = "lost_motion_screening"\n')
    with pytest.raises(InputError) as e:          # doc 001's example is no 20-DOF design
        load_study(write(tmp_path / "a.toml", doc))
    assert e.value.file.endswith("lost_motion_doc_example.toml") and e.value.key == "sun.teeth"
    with pytest.raises(InputError) as e:          # another reducer's torsion curve
        load_study(write(tmp_path / "b.toml", doc + f'design = "{ROOT / "data/designs/rv80e_te.toml"}"\n'))
    assert e.value.key == "analysis[0].design"
    with pytest.raises(InputError) as e:
        load_study(write(tmp_path / "c.toml", _lm_study(tmp_path).read_text().replace("samples = 40", "samples = 3")))
    assert e.value.key == "analysis[0].samples"
