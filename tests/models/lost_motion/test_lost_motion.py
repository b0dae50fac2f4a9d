"""Geometric lost motion (doc 001): formulas against hand computation, Monte Carlo against the analytic
prediction (tolerances from n), geometry derivation, bad input, the two studies."""
import math

import numpy as np
import pytest

from rvtol import units
from rvtol.design import load_design
from rvtol.errors import InputError
from rvtol.models.lost_motion.model import LostMotionGeometry, LostMotionModel, analytic, factor_moments
from rvtol.sampling import sample
from rvtol.sensitivity import five_point
from rvtol.spec import load_spec
from rvtol.study import load_study, run_study

from conftest import ROOT, needs_wing, study_param, write

DOC_DESIGN = ROOT / "data/designs/lost_motion_doc_example.toml"
DOC_SPEC = ROOT / "data/specs/lost_motion_doc_example.toml"
RV_DESIGN = ROOT / "data/designs/rv80e_te.toml"
RV_SPEC = ROOT / "data/specs/rv80e_lost_motion.toml"
K = 180 * 60 / math.pi


def _doc():
    g = LostMotionGeometry.from_design(load_design(DOC_DESIGN), "document")
    spec = load_spec(DOC_SPEC)
    return g, spec, LostMotionModel(g, spec.names)


def test_doc_example_formulas_against_hand_computation():
    # doc 001 inputs, computed here from the printed formulas step by step
    c, t = math.cos(math.radians(20)), math.tan(math.radians(20))
    j = 0.15 / (2 * c) + 2 * 0.02 * t + 0.01 * t                         # j̄1 + j̄2 + j̄3 = 0.098012 mm
    D = (0.05 / (6 * c)) ** 2 + (2 * 0.02 * t / 3) ** 2 + (0.01 * t / 3) ** 2
    hand = {
        "involute_stage": (2 * j * K / 50, math.sqrt(D) * K / 50),      # 13.4776′, 0.7000′
        "cycloid_stage": (K * (0.005 / 400 + 0.003 / (400 * 0.6)),
                          K * math.hypot(0.002 / 400, 0.001 / (400 * 0.6))),  # 0.08594′, 0.02237′
        "crank_bearing": (K / 30 * 0.02 / 1.5, K / 30 * 0.01 / 1.5),    # 1.5279′, 0.7639′
    }
    assert j == pytest.approx(0.0980118, abs=1e-7)
    assert hand["involute_stage"][0] == pytest.approx(13.4776, abs=1e-4)
    assert hand["crank_bearing"][0] == pytest.approx(1.52789, abs=1e-5)
    g, spec, model = _doc()
    a = analytic(g, factor_moments(spec, model)).set_index("stage")
    for stage, (mean, T) in hand.items():
        assert a.loc[stage, "mean"] == pytest.approx(mean, rel=1e-12)
        assert a.loc[stage, "T_doc"] == pytest.approx(T, rel=1e-12)
    tot_mean = hand["involute_stage"][0] / 100 + hand["cycloid_stage"][0] + hand["crank_bearing"][0]
    tot_T = math.sqrt((hand["involute_stage"][1] / 100) ** 2 + hand["cycloid_stage"][1] ** 2
                      + hand["crank_bearing"][1] ** 2)
    assert a.loc["lost_motion", "mean"] == pytest.approx(tot_mean, rel=1e-12)   # 1.7486′
    assert a.loc["lost_motion", "T_doc"] == pytest.approx(tot_T, rel=1e-12)     # 0.7643′
    # the written involute T is one σ of the angle at 1/d1: 6σ of the model is 12× larger; elsewhere T = 6σ
    assert a.loc["involute_stage", "T_6sigma"] == pytest.approx(12 * hand["involute_stage"][1], rel=1e-12)
    for s in ("cycloid_stage", "crank_bearing"):
        assert a.loc[s, "T_6sigma"] == pytest.approx(a.loc[s, "T_doc"], rel=1e-12)


def test_model_evaluates_the_formulas_per_sample():
    g, spec, model = _doc()
    X = np.array([[-0.06, 0.01, 0.02, 0.004, 0.002, 0.015],
                  [-0.09, 0.03, 0.0, 0.006, 0.004, 0.025]])
    Y = units.convert(model.evaluate(X), "rad", "arcmin")
    c, t = math.cos(math.radians(20)), math.tan(math.radians(20))
    for x, y in zip(X, Y):
        ew, da, fr, rc, rp, db = x
        phi12 = 2 * (-ew / c + 2 * da * t + fr * t) / 50 * K
        phi34 = (rc / 400 + rp / (400 * 0.6)) * K
        phib = db / (1.5 * 30) * K
        np.testing.assert_allclose(y, [phi12 / 100 + phi34 + phib, phi12, phi34, phib], rtol=1e-12)


def test_sensitivities_five_point_equal_the_document_partial_derivatives():
    g, spec, model = _doc()
    d = five_point(model, spec, outputs=["lost_motion"]).frame.set_index("factor")
    # S_Δrp = K/(a z_c √(1−K1²)) = 14.32′/mm; S_Δrc = K/(a z_c) = 8.59′/mm (doc 001, sensitivity section)
    assert units.convert(d.loc["Delta_r_p", "S_base"], "rad", "arcmin") == pytest.approx(K / 240, rel=1e-9)
    assert units.convert(d.loc["Delta_r_c", "S_base"], "rad", "arcmin") == pytest.approx(K / 400, rel=1e-9)
    assert d.loc["Delta_r_p", "S_unit"] == "arcmin/mm" and d.loc["E_w", "sign"] == "−"


@pytest.mark.parametrize("design, spec_path, extra", [(DOC_DESIGN, DOC_SPEC, False), (RV_DESIGN, RV_SPEC, True)])
def test_monte_carlo_mean_and_sigma_match_the_analytic_prediction(design, spec_path, extra):
    g = LostMotionGeometry.from_design(load_design(design))
    spec = load_spec(spec_path)
    ex = {"Delta_r_rp": g.coefficients()["cycloid_stage"]["Delta_r_c"]} if extra else {}
    model = LostMotionModel(g, spec.names, extra=ex)
    a = analytic(g, factor_moments(spec, model), ex).set_index("stage")
    n = 20000
    Y = units.convert(model.evaluate(sample(spec, n, "random", 4242).values), "rad", "arcmin")
    for j, name in enumerate(("lost_motion", "involute_stage", "cycloid_stage", "crank_bearing")):
        y = Y[:, j]
        mu, sd = a.loc[name, "mean"], a.loc[name, "sigma"]
        # 4 standard errors: mean SE = σ/√n; SE of s ≈ σ·√((κ−1)/(4n)) with the sample kurtosis κ
        assert abs(y.mean() - mu) <= 4 * sd / math.sqrt(n), name
        kappa = float(np.mean((y - y.mean()) ** 4) / np.var(y) ** 2)
        assert abs(y.std(ddof=1) - sd) <= 4 * sd * math.sqrt((kappa - 1) / (4 * n)), name


def test_rv80e_geometry_is_derived_from_the_design():
    g = LostMotionGeometry.from_design(load_design(RV_DESIGN), "document")
    assert g.pitch_diameter == pytest.approx(1.75 * 16)           # m z_sun
    assert g.K1 == pytest.approx(1.5 * 40 / 76.5)                 # a z_p / r_p
    # the crank circle is the operating centre distance a' (profile shifts x = 0.519, −0.555): the
    # 20-DOF geometry's a' from the same design
    from rvtol.models.reducer_20dof.geometry import geometry_from_design
    a_w = geometry_from_design(load_design(RV_DESIGN)).a_w
    assert g.bearing_radius == pytest.approx(a_w, rel=1e-12) and a_w == pytest.approx(41.9366, abs=1e-4)
    assert g.ratio == 81 and g.bearing_K == 1.5 and g.z_p == 40
    assert "sun.module" in g.origins["d1"]
    c = LostMotionGeometry.from_design(load_design(RV_DESIGN))           # consistent: K derived, not read
    assert c.mode == "consistent" and c.bearing_K == 1.0 and c.bearing_radius == g.bearing_radius


MODEL_STUDY = """
[study]
name = "lm"
design = "{design}"
spec = "{spec}"

[model]
kind = "lost_motion"
{model}
"""


@pytest.mark.parametrize("model, key", [
    ('[[model.cycloid_factor]]\nfactor = "Delta_r_c"\nderivative = "pin_radius"\nsource = "x"',
     "model.cycloid_factor[0].factor"),
    ('[[model.cycloid_factor]]\nfactor = "xi"\nderivative = "sideways"\nsource = "x"',
     "model.cycloid_factor[0].derivative"),
    ('[[model.cycloid_factor]]\nfactor = "xi"\nderivative = { value = 1, unit = "mm" }\nsource = "x"',
     "model.cycloid_factor[0].derivative.unit"),
    ('[model.nominal]\nDelta_zz = 0.0', "model.nominal.Delta_zz"),
    ('[model.nominal]\nE_w = 0.0', "model.nominal.E_w"),
    ('colour = "red"', "model.colour"),
])
def test_bad_model_tables_name_file_and_key(tmp_path, model, key):
    path = write(tmp_path / "s.toml", MODEL_STUDY.format(design=DOC_DESIGN, spec=DOC_SPEC, model=model))
    with pytest.raises(InputError) as e:
        load_study(path)
    assert e.value.key == key and e.value.file == str(path)


def test_bad_design_or_spec_names_the_file_and_key(tmp_path):
    text = DOC_DESIGN.read_text().replace("short_amplitude_coefficient = { value = 0.8",
                                          "short_amplitude_coefficient = { value = 1.2")
    bad_design = write(tmp_path / "d.toml", text)
    with pytest.raises(InputError) as e:
        load_study(write(tmp_path / "s.toml", MODEL_STUDY.format(design=bad_design, spec=DOC_SPEC, model="")))
    assert e.value.file == str(bad_design) and e.value.key == "cycloid.short_amplitude_coefficient"
    no_r = write(tmp_path / "d2.toml", DOC_DESIGN.read_text().replace("centre_radius = {", "centre_radiu = {"))
    with pytest.raises(InputError) as e:
        load_study(write(tmp_path / "s2.toml", MODEL_STUDY.format(design=no_r, spec=DOC_SPEC, model="")))
    assert e.value.file == str(no_r) and e.value.key == "crank_bearing.centre_radius"
    spec = write(tmp_path / "sp.toml", DOC_SPEC.read_text().replace('name = "Delta_b"', 'name = "Delta_B"'))
    with pytest.raises(InputError) as e:
        load_study(write(tmp_path / "s3.toml", MODEL_STUDY.format(design=DOC_DESIGN, spec=spec, model="")))
    assert e.value.file == str(spec) and "Delta_B" in e.value.reason


@pytest.mark.parametrize("path", [study_param(ROOT / "studies" / f"{name}.toml")
                                  for name in ("lost_motion_doc_example", "lost_motion_rv80e")])
def test_both_studies_load(path):
    st = load_study(path)
    assert st.model.output_names[0] == "lost_motion" and st.options.n == 5000


@needs_wing
def test_breakdown_and_reproduction_sections(tmp_path):
    text = f"""
[study]
name = "lm_doc"
design = "{DOC_DESIGN}"
spec = "{DOC_SPEC}"
requirements = "{ROOT / 'data/requirements/rv_lost_motion.toml'}"
[model]
kind = "lost_motion"
mode = "document"
[sampling]
n = 4000
method = "random"
seed = 3
[execution]
executor = "serial"
[[analysis]]
kind = "lost_motion_breakdown"
[[analysis]]
kind = "lost_motion_reproduction"
printed = "{ROOT / 'data/reproduction/doc001_lost_motion.toml'}"
"""
    res = run_study(load_study(write(tmp_path / "s.toml", text), progress=False))
    assert not res.passed   # the document's example, by its own formulas, exceeds 1 arcmin (mean 1.75′)
    brk, rep = res.sections
    z = brk.summary["mc_minus_analytic_se"]["lost_motion"]
    assert abs(z["mean"]) < 4 and abs(z["sigma"]) < 4   # MC within 4 standard errors of the analytic mean, σ
    rows = {r["figure"]: r for r in rep.summary["rows"]}
    assert rows["Δφt from the printed stages [′]"]["reproduced"] == "yes"
    assert rows["T_Δφt from the printed stages [′]"]["reproduced"] == "yes"
    assert rows["Δφ12 mean [′]"]["reproduced"] == "no" and rows["Δφ12 mean [′]"]["rvtol (doc formulas and inputs)"] \
        == "13.48"
    assert rows["S_Δrp [′/mm]"]["other reading"] == "five-point = 14.32"
    assert all(r["reason"] for r in rep.summary["rows"])
