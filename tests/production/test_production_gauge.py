"""Gauge studies as the measured features' uncertainty, and the ISO 14253-1 decision per unit."""
import io
import json
import math

import numpy as np
import pandas as pd
import pytest
from conftest import write

from rvtol.errors import InputError
from rvtol.mc import Evaluator
from rvtol.model import STATUS_NONFINITE, STATUS_OK, LinearModel, Quantity
from rvtol.production import FamilySource, load_measured_units, predict_units, texts
from rvtol.production.msa import Gauge, read_gauge_study
from rvtol.production.per_unit import (
    CONFORMANCE_PROVEN,
    NONCONFORMANCE_PROVEN,
    NOT_PROVEN,
    UnitPredictions,
    guard_banded,
)
from rvtol.spec import Requirement, spec_from_table
from rvtol.study import load_study

SPEC = spec_from_table({"factor": [
    {"name": "crank_1.cam.x", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 1.0},
    {"name": "crank_2.cam.x", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 1.0},
    {"name": "crank_1.cam.y", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 1.0},
    {"name": "crank_2.cam.y", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 1.0},
]})
# 3 parts × 2 appraisers × 2 trials built from chosen effects (tests/production/test_msa.py::_constructed, d = 0.1):
# σ²_GRR = 0.02 + 0.13 + 2.72/6 = 0.603333 µm² (interaction kept, p = 0.0055)
GAUGE_ROWS = [(p, a, t, 10.0 + pe + ae + ie + (-0.1 if t == 1 else 0.1))
              for p, pe, ie_row in ((1, -2.0, (0.3, -0.3)), (2, 0.0, (-0.1, 0.1)), (3, 2.0, (-0.2, 0.2)))
              for a, ae, ie in (("A", -0.5, ie_row[0]), ("B", 0.5, ie_row[1])) for t in (1, 2)]
VAR_GRR = 0.02 + 0.13 + 2.72 / 6


def _gauge_file(tmp_path, unit="um", name="gauge.csv"):
    body = "".join(f"{p}, {a}, {t}, {v:.12g}\n" for p, a, t, v in GAUGE_ROWS)
    return write(tmp_path / name, f"# gauge study\npart, appraiser, trial, value [{unit}]\n{body}")


CRANKS = """serial, cam.x [um], cam.y [um]
uncertainty, , 0.5
C1, 0.5, 0.1
C2, -1.25, 0.2
"""
KITS = "reducer, crank_1, crank_2\nR1, C1, C2\n"


def _units(tmp_path, cranks=CRANKS, gauges=None, calibration=0.0):
    g = read_gauge_study(_gauge_file(tmp_path))
    gauges = (Gauge(g, ("cam.x",), calibration),) if gauges is None else gauges
    return load_measured_units(SPEC, write(tmp_path / "kits.csv", KITS),
                               [FamilySource(write(tmp_path / "cranks.csv", cranks), ("crank_1", "crank_2"),
                                             gauges=gauges)])


def test_a_gauge_study_gives_its_features_the_grr_uncertainty_combined_with_calibration(tmp_path):
    """u = √(σ²_GRR + u_cal²) in the study's unit (µm) -> base units (mm); the other feature keeps its typed u."""
    mu = _units(tmp_path, calibration=0.3)
    u_um = math.sqrt(VAR_GRR + 0.3 ** 2)
    np.testing.assert_allclose(mu.uncertainty[0], np.array([u_um, u_um, 0.5, 0.5]) * 1e-3, rtol=1e-12)
    assert any(k.startswith("gauge:cranks:") for k in mu.files())
    frame = mu.gauge_frame()
    assert frame.loc[0, "u"] == pytest.approx(u_um) and frame.loc[0, "σ GRR"] == pytest.approx(math.sqrt(VAR_GRR))


def test_a_gauge_study_in_another_unit_is_converted(tmp_path):
    g = read_gauge_study(_gauge_file(tmp_path, unit="nm"))      # the same numbers read as nm
    mu = _units(tmp_path, gauges=(Gauge(g, ("cam.x",)),))
    assert mu.uncertainty[0, 0] == pytest.approx(math.sqrt(VAR_GRR) * 1e-6, rel=1e-12)


@pytest.mark.parametrize("cranks, features, unit, key, reason", [
    (CRANKS.replace("uncertainty, ,", "uncertainty, 0.2,"), ("cam.x",), "um", "row 2, column 'cam.x [um]'",
     "an uncertainty here and the gauge study 'gauge.csv'"),
    ("serial, cam.x [um], cam.x.u [um], cam.y [um]\nuncertainty, , , 0.5\nC1, 0.5, 0.1, 0\nC2, 1, 0.1, 0\n",
     ("cam.x",), "um", "row 1, column 'cam.x.u [um]'", "an uncertainty here and the gauge study"),
    (CRANKS, ("cam.z",), "um", "row 1", "no feature column 'cam.z' for the gauge study 'gauge.csv'"),
    (CRANKS, ("cam.x",), "deg", "row 1, column 'cam.x [um]'", "reads in 'deg', which does not fit"),
    (CRANKS.replace("uncertainty, , 0.5", "uncertainty, , "), ("cam.x",), "um", "row 2, column 'cam.y [um]'",
     "a column 'cam.y.u' or a gauge study"),
])
def test_a_gauge_study_that_does_not_fit_the_family_is_one_located_error(tmp_path, cranks, features, unit, key,
                                                                        reason):
    g = read_gauge_study(_gauge_file(tmp_path, unit=unit))
    with pytest.raises(InputError) as exc:
        _units(tmp_path, cranks, gauges=(Gauge(g, features),))
    assert exc.value.file == str(tmp_path / "cranks.csv") and exc.value.key == key and reason in exc.value.reason, (
        exc.value.key, exc.value.reason)


# --------------------------------------------------------------------------- ISO 14253-1
@pytest.mark.parametrize("y, expected", [
    (2.0, CONFORMANCE_PROVEN), (1.999, NOT_PROVEN), (8.0, CONFORMANCE_PROVEN), (8.001, NOT_PROVEN),
    (5.0, CONFORMANCE_PROVEN), (-2.0, NOT_PROVEN), (-2.001, NONCONFORMANCE_PROVEN), (12.0, NOT_PROVEN),
    (12.001, NONCONFORMANCE_PROVEN), (0.0, NOT_PROVEN), (10.0, NOT_PROVEN), (math.nan, NOT_PROVEN),
])
def test_the_guard_bands_are_the_tolerance_zone_reduced_and_enlarged_by_k_u(y, expected):
    """Zone [0, 10], u = 1, k = 2: U = 2; conformance proven on [2, 8] (closed), non-conformance proven below −2
    or above 12, undecided between (the limits themselves included)."""
    assert guard_banded(y, 1.0, 0.0, 10.0, k=2.0) == expected


def test_the_guard_band_cases_at_the_edges():
    assert guard_banded(-100.0, 1.0, None, 10.0) == CONFORMANCE_PROVEN           # one-sided: only the upper limit
    assert guard_banded(8.5, 1.0, None, 10.0) == NOT_PROVEN
    assert guard_banded(1.5, 1.0, 0.0, 3.0) == NOT_PROVEN                        # 2U > the zone: never proven
    assert guard_banded(10.0, 0.0, 0.0, 10.0) == CONFORMANCE_PROVEN              # u = 0: the zone itself
    assert guard_banded(10.000001, 0.0, 0.0, 10.0) == NONCONFORMANCE_PROVEN
    assert guard_banded(7.0, 1.0, 0.0, 10.0, k=3.0) == CONFORMANCE_PROVEN        # k = 3: [3, 7]
    assert guard_banded(7.01, 1.0, 0.0, 10.0, k=3.0) == NOT_PROVEN
    assert guard_banded(-3.01, 1.0, 0.0, 10.0, k=3.0) == NONCONFORMANCE_PROVEN


def test_each_unit_and_requirement_gets_the_decision_on_its_prediction(tmp_path):
    """Every factor measured with u = 0: y is the model at the measured values exactly and u = 0, so the decision
    is the tolerance zone itself: y = 0.5 − 1.25 + 0.1 + 0.2 = −0.45 µm; upper 0 proven, upper −1 non-conformance
    proven.  With the gauge's u on cam.x (and 0.5 µm on cam.y) the decision reads mean ± 2·std of the samples."""
    cranks = CRANKS.replace("uncertainty, , 0.5", "uncertainty, , 0")
    model = LinearModel(SPEC.names, ["mm"] * 4, [Quantity("y", "mm", "um")], [np.ones(4)])
    reqs = [Requirement("y", upper=0.0, unit="um", name="ok"), Requirement("y", upper=-1.0, unit="um", name="bad")]
    exact = load_measured_units(SPEC, write(tmp_path / "kits.csv", KITS), [FamilySource(
        write(tmp_path / "exact.csv", cranks.replace("uncertainty, ,", "uncertainty, 0,")), ("crank_1", "crank_2"))])
    pred = predict_units(model, SPEC, exact, 8, evaluator=Evaluator(), requirements=reqs, seed=1)
    req = pred.requirement_frame().set_index("requirement")
    assert req.loc["ok", "y"] == pytest.approx(-0.45, abs=1e-12) and req.loc["ok", "u"] == 0.0
    assert req.loc["ok", "ISO 14253-1"] == CONFORMANCE_PROVEN and req.loc["bad", "ISO 14253-1"] == NONCONFORMANCE_PROVEN
    row = pred.unit_frame().iloc[0]
    assert row["ok: ISO 14253-1 (k=2)"] == CONFORMANCE_PROVEN and row["bad: ISO 14253-1 (k=2)"] == NONCONFORMANCE_PROVEN
    assert "ok: ISO 14253-1 (y ± U, k=2)" in pred.verdict_table().columns

    noisy = predict_units(model, SPEC, _units(tmp_path, calibration=0.3), 400, evaluator=Evaluator(),
                          requirements=reqs, seed=2, coverage_factor=3.0)
    out = noisy.output_frame().iloc[0]
    r = noisy.requirement_frame().set_index("requirement")
    assert r.loc["ok", "y"] == pytest.approx(out["mean"]) and r.loc["ok", "u"] == pytest.approx(out["std"])
    assert r.loc["ok", "U"] == pytest.approx(3.0 * out["std"])
    # u_y = √(2·(σ²_GRR + 0.09) + 2·0.25) = 1.364 µm: −0.45 is inside [−∞, 0] but not by 3u -> undecided
    assert math.sqrt(2 * (VAR_GRR + 0.09) + 2 * 0.25) == pytest.approx(r.loc["ok", "u"], rel=0.15)
    assert r.loc["ok", "ISO 14253-1"] == NOT_PROVEN


STUDY = """
[study]
name = "gauge"
[[factor]]
name = "crank_1.cam.x"
unit = "um"
dist = "normal"
mean = 0.0
sigma = 1.0
[[factor]]
name = "crank_2.cam.x"
unit = "um"
dist = "normal"
mean = 0.0
sigma = 1.0
[model]
kind = "linear"
[[model.output]]
name = "play"
unit = "um"
coefficients = { "crank_1.cam.x" = 1.0, "crank_2.cam.x" = 1.0 }
[[requirement]]
output = "play"
lower = -6.0
upper = 6.0
unit = "um"
min_yield = 0.95
[sampling]
n = 200
seed = 9
[execution]
executor = "serial"
[report]
pdf = false
[[analysis]]
kind = "per_unit_prediction"
kits = "kits.csv"
[[analysis.parts]]
file = "cranks.csv"
slots = ["crank_1", "crank_2"]
[[analysis.parts.gauge]]
file = "gauge.csv"
features = ["cam.x"]
calibration_u = 0.3
tolerance = 12.0
"""


def test_a_study_names_the_gauge_study_and_reports_it(tmp_path, monkeypatch):
    """The study's keys reach the analysis; its per_unit.csv, summary and report blocks carry the gauge and the
    decision (the analysis run directly: run_study's standard sections are not what is tested here)."""
    _gauge_file(tmp_path)
    write(tmp_path / "cranks.csv", "serial, cam.x [um]\nC1, 0.5\nC2, -1.25\nC3, 5.5\nC4, 4.0\n")
    write(tmp_path / "kits.csv", "reducer, crank_1, crank_2\nR1, C1, C2\nR2, C3, C4\n")
    study = load_study(write(tmp_path / "s.toml", STUDY), progress=False)
    assert any(k.startswith("per_unit_prediction:gauge:") for k in study.inputs)
    (a,) = study.analyses
    o, p = a.options, a.plan
    assert o.coverage_factor == 2.0
    pred = predict_units(p.model, study.spec, p.units, p.n, evaluator=Evaluator(), requirements=p.requirements,
                         seed=9, coverage_factor=o.coverage_factor)
    table = pd.read_csv(io.StringIO(a.files(pred)["per_unit.csv"]))
    # u_play = √2·√(σ²_GRR + 0.09) = 1.178 µm, U = 2.355: R1 play −0.75 within [−3.645, 3.645] -> proven;
    # R2 play 9.5 > 6 + 2.355 -> non-conformance proven
    assert list(table["play in [-6, 6] µm: ISO 14253-1 (k=2)"]) == [CONFORMANCE_PROVEN, NONCONFORMANCE_PROVEN]
    summary = a.summary(pred)
    (g,) = summary["gauges"]
    assert g["u"] == pytest.approx(math.sqrt(VAR_GRR + 0.09)) and g["ndc"] == 3 and g["acceptance"] == "unacceptable"
    json.dumps(summary)
    assert summary["units"][0]["requirements"][0]["iso14253"]["decision"] == CONFORMANCE_PROVEN
    monkeypatch.setattr(texts, "figure_png", lambda fig: b"")     # the layout, not the rendering of its figures
    captions = [getattr(b, "caption", "") for b in texts.per_unit(pred, o, p)]
    assert any(c.startswith("Gauge studies") for c in captions)


def test_a_bad_gauge_study_fails_the_study_at_load_time_in_its_own_file(tmp_path):
    g = write(tmp_path / "gauge.csv", "part, appraiser, value [um]\n1, A, 0.1\n1, A, 0.2\n2, A, 0.3\n2, A, 0.1\n")
    write(tmp_path / "cranks.csv", "serial, cam.x [um]\nC1, 0.5\nC2, -1.25\n")
    write(tmp_path / "kits.csv", "reducer, crank_1, crank_2\nR1, C1, C2\n")
    with pytest.raises(InputError) as exc:
        load_study(write(tmp_path / "s.toml", STUDY), progress=False)
    assert exc.value.file == str(g) and exc.value.key == "row 1, column 'appraiser'"
    assert "1 appraiser: a crossed gauge study needs at least 2 appraisers" in exc.value.reason


def test_a_unit_with_fewer_than_two_evaluated_samples_is_undecided():
    """One sample of two evaluated (the other failed): its spread is unknown, so nothing is proven either way —
    even far inside the limits."""
    pred = UnitPredictions(("R1",), (Quantity("y", "mm", "um"),), np.array([[[0.0], [np.nan]]]),
                           np.array([[STATUS_OK, STATUS_NONFINITE]]), (Requirement("y", upper=100.0),), 0.95,
                           np.array([1]), {})
    row = pred.requirement_frame().iloc[0]
    assert row["y"] == 0.0 and math.isnan(row["u"]) and row["ISO 14253-1"] == NOT_PROVEN
