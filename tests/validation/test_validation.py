"""Validation against published measurements (rvtol.validation): the stored files, the comparison rules against
hand-computed numbers, the tolerance-scale calibration against its closed form, the study analysis end to end."""

import numpy as np
import pytest

from conftest import ROOT, write
from rvtol.errors import InputError
from rvtol.model import Model, Quantity
from rvtol.sampling import sample
from rvtol.spec import spec_from_table
from rvtol.validation import (STATUSES, compare_limit, compare_orders, compare_value, load_published,
                              load_published_files, median_interval, validate)
from rvtol.validation.agreement import compare_shape

PUBLISHED = sorted((ROOT / "data" / "measurements" / "published").glob("*.toml"))


# --------------------------------------------------------------------------- the stored files
def test_the_published_folder_holds_files():
    assert len(PUBLISHED) >= 3


@pytest.mark.parametrize("path", PUBLISHED, ids=lambda p: p.name)
def test_every_stored_published_file_parses_and_carries_its_citation(path):
    src = load_published(path)
    for field in ("id", "title", "authors", "publication", "how_read", "accessed", "reducer"):
        assert getattr(src, field).strip(), field
    assert src.doi or src.url or src.document
    assert src.status in STATUSES and src.read_from in ("primary", "secondary")
    assert src.citation.startswith(src.authors)
    if src.status == "read":
        assert src.quantities
        for q in src.quantities:
            assert q.figure and q.description and q.reducer and q.unit_under_test
            if q.numeric:
                assert np.isfinite(q.value) and q.unit and q.reading_uncertainty >= 0
    else:
        assert not src.quantities and src.missing        # a source not read stores no number, says why


def test_the_stored_sources_have_distinct_ids():
    assert len({s.id for s in load_published_files(PUBLISHED)}) == len(PUBLISHED)


def test_a_range_is_compared_by_its_printed_extremes():
    """Yang et al. 2021, prototype #1: test RTE −29.68″ … +30.39″ → peak-to-peak 60.07″."""
    src = load_published(ROOT / "data/measurements/published/yang2021_mmt_rv80e_te.toml")
    q = {q.id: q for q in src.quantities}
    assert (q["te_pp_prototype_1"].low, q["te_pp_prototype_1"].high) == (-29.68, 30.39)
    assert q["te_pp_prototype_1"].value == pytest.approx(60.07, abs=1e-12)
    assert q["te_pp_prototype_2"].value == pytest.approx(64.64, abs=1e-12)


SOURCE = """
[source]
id = "s"
title = "A title"
authors = "A. Author"
publication = "J. 1 (2020) 1"
doi = "10.0/x"
status = "read"
read_from = "primary"
how_read = "copied from Table 2"
accessed = "2026-11-27"
reducer = "RV-80E"
"""
QTY = """
[[quantity]]
id = "q"
quantity = "y"
description = "d"
reducer = "RV-80E"
unit_under_test = "one unit"
figure = "Table 2"
kind = "{kind}"
{body}
"""


@pytest.mark.parametrize("text, key, reason", [
    (SOURCE.replace('title = "A title"\n', ""), "source.title", "missing required key"),
    (SOURCE.replace('doi = "10.0/x"\n', ""), "source.doi", "at least one of doi, url, document"),
    (SOURCE, "quantity", "at least one [[quantity]]"),
    (SOURCE.replace('"read"\n', '"not read"\n', 1), "missing", "what was looked for"),
    (SOURCE.replace('"read"\n', '"not read"\n', 1) + QTY.format(kind="value", body='value = 1.0\nunit = "um"\n'
                                                               'reading_uncertainty = 0.1'),
     "quantity", "stores no figure"),
    (SOURCE + QTY.format(kind="range", body='min = 2.0\nmax = 1.0\nunit = "um"\nreading_uncertainty = 0.1'),
     "quantity[0].max", "greater than min"),
    (SOURCE + QTY.format(kind="mean", body=""), "quantity[0].kind", "unknown value 'mean'"),
    (SOURCE + QTY.format(kind="value", body='value = 1.0\nunit = "um"'), "quantity[0].reading_uncertainty",
     "missing required key"),
    (SOURCE + QTY.format(kind="value", body='value = 1.0\nunit = "milimeter"\nreading_uncertainty = 0.1'),
     "quantity[0].unit", "unknown unit"),
    (SOURCE + QTY.format(kind="orders", body="orders = [1, 0]"), "quantity[0].orders", "integer orders"),
    (SOURCE + QTY.format(kind="order_amplitudes", body='orders = [1, 40]\namplitudes = [2.0]\nunit = "arcsec"\n'
                                                       'relative_uncertainty = 0.1\npins = 40\nratio = 81'),
     "quantity[0].amplitudes", "one number per order (2)"),
    (SOURCE + QTY.format(kind="order_amplitudes", body='orders = [1, 40]\namplitudes = [2.0, 0.0]\nunit = "arcsec"\n'
                                                       'relative_uncertainty = 0.1\npins = 40\nratio = 81'),
     "quantity[0].amplitudes", "entry 2: must be > 0"),
    (SOURCE + QTY.format(kind="value", body='value = 1.0\nunit = "um"\nreading_uncertainty = 0.1\norigin = "guess"'),
     "quantity[0].origin", "unknown value 'guess'"),
    (SOURCE + QTY.format(kind="value", body='value = 1.0\nunit = "um"\nreading_uncertainty = 0.1\npins = 40'),
     "quantity[0].pins", "does not apply to a figure of kind 'value'"),
    (SOURCE + QTY.format(kind="range", body='min = 1.0\nunit = "um"\nreading_uncertainty = 0.1'),
     "quantity[0].max", "missing required key"),
    (SOURCE + QTY.format(kind="value", body='value = 1.0\nunit = "um"\nreading_uncertainty = 0.1').replace(
        'figure = "Table 2"', 'figure = "  "'), "quantity[0].figure", "must not be empty"),
])
def test_a_bad_published_file_is_one_error_naming_file_and_key(tmp_path, text, key, reason):
    p = write(tmp_path / "bad.toml", text)
    with pytest.raises(InputError) as e:
        load_published(p)
    assert e.value.file == str(p) and e.value.key == key and reason in e.value.reason


def test_two_files_with_one_source_id_are_refused(tmp_path):
    body = SOURCE + QTY.format(kind="value", body='value = 1.0\nunit = "um"\nreading_uncertainty = 0.1')
    a, b = write(tmp_path / "a.toml", body), write(tmp_path / "b.toml", body)
    with pytest.raises(InputError, match="also used by"):
        load_published_files([a, b])


# --------------------------------------------------------------------------- comparison rules, by hand
def test_median_interval_is_conovers_order_statistic_interval():
    """n = 100 at 95 %: x_(40) and x_(61); coverage 1 − 2·B(39; 100, ½) = 1 − 2·0.017600 = 0.96480
    (B(39; 100, ½) from the binomial table); j = 41 would give 1 − 2·0.028444 = 0.94311 < 0.95."""
    lo, hi, cover = median_interval(np.arange(1.0, 101.0)[::-1], 0.95)
    assert (lo, hi) == (40.0, 61.0)
    assert cover == pytest.approx(0.96480, abs=5e-5)
    # five values cannot give 95 %: the widest interval, coverage 1 − 2/32
    assert median_interval([5.0, 1.0, 3.0, 2.0, 4.0], 0.95) == (1.0, 5.0, pytest.approx(0.9375))


VALUES = np.arange(1.0, 101.0)      # 1 … 100: median 50.5; numpy's P2.5 = 1 + 0.025·99 = 3.475, P97.5 = 97.525


def test_a_measured_value_against_the_predicted_units():
    r = compare_value(50.0, 0.0, VALUES)
    assert r["median"] == 50.5 and r["ratio"] == pytest.approx(50.5 / 50.0)
    assert (r["low"], r["high"]) == (pytest.approx(3.475), pytest.approx(97.525))
    assert r["percentile"] == 50.0 and r["verdict"] == "inside the predicted interval"
    assert compare_value(99.0, 0.0, VALUES)["verdict"] == "above the predicted interval"
    assert compare_value(99.0, 2.0, VALUES)["verdict"] == "inside the predicted interval"   # 97 ≤ 97.525
    assert compare_value(3.0, 0.4, VALUES)["verdict"] == "below the predicted interval"     # 3.4 < 3.475
    r = compare_value(200.0, 0.0, np.r_[VALUES, np.nan])       # a failed prediction does not count
    assert r["n"] == 100 and r["percentile"] == 100.0 and r["ratio"] == pytest.approx(50.5 / 200.0)


def test_a_catalogue_bound_against_the_predicted_units():
    r = compare_limit(98.0, True, VALUES)
    assert r["verdict"] == "consistent" and r["yield"] == 98.0            # P97.5 = 97.525 ≤ 98
    r = compare_limit(60.0, True, VALUES)
    assert r["verdict"] == "partly" and r["yield"] == 60.0                # median 50.5 ≤ 60 < 97.525
    r = compare_limit(40.0, True, VALUES)
    assert r["verdict"] == "contradicts" and r["yield"] == 40.0 and r["ratio"] == pytest.approx(50.5 / 40.0)
    r = compare_limit(5.0, False, VALUES)                                 # a lower bound: 96 units ≥ 5
    assert r["verdict"] == "partly" and r["yield"] == 96.0
    assert compare_limit(3.0, False, VALUES)["verdict"] == "consistent"   # P2.5 = 3.475 ≥ 3


def test_measured_strong_orders_against_predicted_spectra():
    """Two predicted reducers: amplitudes 3 and 6″ at order 1, 1 and 2″ at order 40, 0.05 and 0.1″ at order 80
    (spectra up to order 468) — medians 4.5, 1.5, 0.075″; shares of the largest order 1, 1/3, 1/60 on both; the
    third reducer failed (None). Order 500 lies above the spectra's highest order."""
    a = np.zeros(469)
    a[0], a[1], a[40], a[80] = 7.0, 3.0, 1.0, 0.05              # order 0 (the mean) is no order of the spectrum
    rows = {r["order"]: r for r in compare_orders([1, 40, 80, 500], [a, 2 * a, None], threshold=0.10)}
    assert rows[1]["amplitude"] == pytest.approx(4.5) and rows[1]["share"] == pytest.approx(1.0)
    assert rows[40]["amplitude"] == pytest.approx(1.5) and rows[40]["share"] == pytest.approx(1 / 3)
    assert rows[80]["amplitude"] == pytest.approx(0.075) and rows[80]["share"] == pytest.approx(1 / 60)
    assert rows[40]["verdict"] == "present" and rows[80]["verdict"] == "absent"
    assert rows[500]["verdict"] == "not resolved (highest order 468)"
    assert compare_orders([1], [None])[0]["verdict"] == "no successful prediction"


# --------------------------------------------------------------------------- validate: prediction and calibration
class Magnitude(Model):
    """y = |x| (µm): the median of y over a sample of x scaled by s is s × the unscaled one — a closed form."""

    inputs, input_units = ("x",), ("mm",)
    outputs = (Quantity("y", "mm", "um"),)

    def evaluate(self, X):
        return np.abs(np.asarray(X, dtype=float))


SPEC = spec_from_table({"factor": [{"name": "x", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 1.0}]})


def _files(tmp_path):
    body = SOURCE + QTY.format(kind="value", body='value = 2.0\nunit = "um"\nreading_uncertainty = 0.01') + \
        QTY.format(kind="upper_limit", body='value = 5.0\nunit = "um"\nreading_uncertainty = 0.0').replace(
            'id = "q"', 'id = "limit"') + \
        QTY.format(kind="value", body='value = 0.001\nunit = "mm"\nreading_uncertainty = 0.0').replace(
            'id = "q"', 'id = "other"').replace('reducer = "RV-80E"\nunit', 'reducer = "RV-20E"\nunit') + \
        QTY.format(kind="value", body='value = 1.0\nunit = "um"\nreading_uncertainty = 0.0').replace(
            'id = "q"', 'id = "unmapped"').replace('quantity = "y"', 'quantity = "z"')
    return load_published_files([write(tmp_path / "s.toml", body)])


def test_prediction_then_a_tolerance_scale_fitted_to_one_figure_and_the_others_held_out(tmp_path):
    n, seed = 200, 7
    x1 = np.abs(sample(SPEC, n, "lhs", seed).values[:, 0]) * 1e3          # the unscaled sample, µm
    res = validate(Magnitude(), SPEC, _files(tmp_path), {"y": "y"}, reducer="RV-80E", n=n, seed=seed,
                   calibrate_on="s:q", rtol=1e-9)
    before = res.stage("predicted (no calibration)").set_index("quantity")
    assert before.loc["q", "median"] == pytest.approx(np.median(x1))
    assert before.loc["q", "nominal"] == 0.0                              # |nominal x| = 0
    assert before.loc["q", "predicted / measured"] == pytest.approx(np.median(x1) / 2.0)
    assert before.loc["other", "verdict"] == ("not predicted: the study's design is an RV-80E; this figure's reducer: "
                                               "RV-20E (a study whose design is an RV-20E predicts it)")
    assert before.loc["unmapped", "verdict"] == "not predicted: the study maps no model output to 'z'"
    # closed form: median(|s·x|) = s·median(|x|) on the same uniform design → s* = 2 / median(|x|)
    s_star = 2.0 / np.median(x1)
    assert res.calibration.success and res.calibration.value == pytest.approx(s_star, rel=1e-7)
    after = res.stage(res.calibration.stage).set_index("quantity")
    assert after.loc["q", "median"] == pytest.approx(2.0, rel=1e-7) and after.loc["q", "role"] == "calibrated on"
    assert after.loc["limit", "role"] == "hold-out"
    assert after.loc["limit", "yield [%]"] == pytest.approx(100.0 * np.mean(s_star * x1 <= 5.0))
    assert "other" not in after.index                                     # not predicted: listed once


def test_a_figure_no_scale_can_reach_is_a_failed_calibration_not_an_error(tmp_path):
    res = validate(Magnitude(), SPEC, _files(tmp_path), {"y": "y"}, reducer="RV-80E", n=64, seed=3,
                   calibrate_on="s:q", bounds=(0.5, 1.5))
    assert not res.calibration.success and "no tolerance scale in [0.5, 1.5]" in res.calibration.message
    assert set(res.comparison["stage"]) == {"predicted (no calibration)"}


def test_calibrating_on_a_bound_or_an_unknown_figure_is_refused(tmp_path):
    files = _files(tmp_path)
    with pytest.raises(InputError, match="not a measured value"):
        validate(Magnitude(), SPEC, files, {"y": "y"}, reducer="RV-80E", n=16, seed=1, calibrate_on="s:limit")
    with pytest.raises(InputError, match="unknown published figure"):
        validate(Magnitude(), SPEC, files, {"y": "y"}, reducer="RV-80E", n=16, seed=1, calibrate_on="s:nope")


# --------------------------------------------------------------------------- the study analysis
STUDY = """
[study]
name = "v"
exploratory = true
[[factor]]
name = "x"
unit = "um"
dist = "normal"
mean = 0.0
sigma = 1.0
[model]
kind = "formula"
[[model.output]]
name = "y"
formula = "abs(x)"
unit = "um"
[sampling]
n = 128
method = "lhs"
seed = 11
[execution]
executor = "serial"
[[analysis]]
kind = "validation"
published = ["pub/*.toml"]
reducer = "RV-80E"
calibrate_on = "s:q"
[analysis.outputs]
y = "y"
"""


def test_the_study_analysis_predicts_calibrates_and_reports(tmp_path):
    from rvtol.study import load_study, run_study

    _files(tmp_path / "pub")
    st = load_study(write(tmp_path / "v.toml", STUDY), progress=False)
    sec = next(s for s in run_study(st).sections if s.key == "validation")
    summ = sec.summary
    assert summ["calibration"]["success"]
    rows = {(r["stage"][:5], r["quantity"]): r for r in summ["comparison"]}
    assert rows[("predi", "q")]["median"] == pytest.approx(float(np.median(np.abs(st_sample(st)))))
    assert rows[("after", "limit")]["role"] == "hold-out"
    assert {c["figures"] for c in summ["sources"]} == {4}


def st_sample(st):
    return sample(st.spec, st.options.n, st.options.method, st.options.seed).values[:, 0] * 1e3


@pytest.mark.parametrize("change, bad, key, reason", [
    ('published = ["pub/*.toml"]', 'published = ["nowhere/*.toml"]', "analysis[0].published", "matches no file"),
    ('y = "y"', 'y = "w"', "analysis[0].outputs", "y: unknown output name 'w'"),
    ('calibrate_on = "s:q"', 'calibrate_on = "s:limit"', "analysis[0].calibrate_on", "cannot be calibrated on"),
    ('calibrate_on = "s:q"', 'calibrate_on = "s:q"\nbounds = [2.0, 1.0]', "analysis[0].bounds", "low < high"),
    ('reducer = "RV-80E"', 'reducer = "RV-80E"\nte_model = "te"', "analysis[0].te_model", "unknown model name"),
])
def test_a_bad_validation_table_fails_when_the_study_loads(tmp_path, change, bad, key, reason):
    from rvtol.study import load_study

    _files(tmp_path / "pub")
    with pytest.raises(InputError) as e:
        load_study(write(tmp_path / "v.toml", STUDY.replace(change, bad)))
    assert e.value.key == key and reason in e.value.reason


# --------------------------------------------------------------------------- hold-outs that can fail (issue 39)
def _two_units(tmp_path, extra=""):
    """Two measured units of one design (q: 2 µm, q2: 3 µm), a bound of another quantity, a published model's
    own result."""
    body = SOURCE + QTY.format(kind="value", body='value = 2.0\nunit = "um"\nreading_uncertainty = 0.0') + \
        QTY.format(kind="value", body='value = 3.0\nunit = "um"\nreading_uncertainty = 0.0').replace(
            'id = "q"', 'id = "q2"') + \
        QTY.format(kind="value", body='value = 2.5\nunit = "um"\nreading_uncertainty = 0.0\norigin = "model"').replace(
            'id = "q"', 'id = "sim"') + extra
    return load_published_files([write(tmp_path / "s.toml", body)])


class TwoOutputs(Magnitude):
    """y = |x| and y_rig = |x| + 1 µm (a stand-in for the TE an assumed rig reads beside the reducer's own)."""

    outputs = (Quantity("y", "mm", "um"), Quantity("y_rig", "mm", "um"))

    def evaluate(self, X):
        y = np.abs(np.asarray(X, dtype=float))
        return np.column_stack([y[:, 0], y[:, 0] + 1e-3])


def test_another_unit_of_the_calibrated_design_is_not_counted_as_a_hold_out(tmp_path):
    """Calibrated on unit q, the model predicts unit q2 with the same distribution: its predicted / measured is
    2/3 = the ratio of the two measurements by construction (it could never discriminate), so it is labelled and
    not counted; the published model result is listed beside, never judged, and cannot be calibrated on."""
    res = validate(Magnitude(), SPEC, _two_units(tmp_path), {"y": "y"}, reducer="RV-80E", n=200, seed=7,
                   calibrate_on="s:q", rtol=1e-9)
    after = res.stage(res.calibration.stage).set_index("quantity")
    assert after.loc["q2", "role"] == "same predicted distribution as the calibration figure: not a hold-out"
    assert after.loc["q2", "predicted / measured"] == pytest.approx(2.0 / 3.0, rel=1e-6)
    before = res.stage("predicted (no calibration)").set_index("quantity")
    assert before.loc["sim", "role"].startswith("published model result (not a measurement)")
    assert "sim" not in set(res.misses()["quantity"])
    with pytest.raises(InputError, match="of a published model is not a measured value"):
        validate(Magnitude(), SPEC, _two_units(tmp_path), {"y": "y"}, reducer="RV-80E", n=16, seed=1,
                 calibrate_on="s:sim")


def test_a_sensitivity_output_is_a_row_beside_the_prediction_not_a_verdict(tmp_path):
    res = validate(TwoOutputs(), SPEC, _two_units(tmp_path), {"y": "y"}, reducer="RV-80E", n=128, seed=5,
                   sensitivity_outputs={"y": ["y_rig"]})
    rows = res.comparison[res.comparison["quantity"] == "q"].set_index("role")
    primary, rig = rows.loc[""], rows.loc["sensitivity: y_rig beside the prediction, not judged"]
    assert rig["median"] == pytest.approx(primary["median"] + 1.0)          # µm
    assert rig["nominal"] == pytest.approx(1.0)
    assert not res.misses()["role"].astype(str).str.startswith("sensitivity").any()


def test_a_measured_spectrum_is_compared_in_shape_by_hand():
    """Measured 2, 4, 1″ at orders 1, 40, 80 (±10 % each): ratios to order 40 0.5 (±14.1 %) and 0.25. Predicted
    reducers: order 1/order 40 = 0.4, 0.45, 0.5, 0.55, 0.6 → overlaps [0.429, 0.571]: consistent; order 80/40 =
    0.01 … 0.05 → below 0.25·(1 − 0.141): misses by 0.03/0.25 = 0.12 (the median's)."""
    spectra = []
    for k, r1 in enumerate((0.4, 0.45, 0.5, 0.55, 0.6)):
        a = np.zeros(100)
        a[40], a[1], a[80] = 2.0, 2.0 * r1, 2.0 * (0.01 + 0.01 * k)
        spectra.append(a)
    rows = {r["order"]: r for r in compare_shape([1, 40, 80], [2.0, 4.0, 1.0], [0.1, 0.1, 0.1], spectra + [None],
                                                 reference=40, interval=0.95)}
    assert rows[40]["verdict"] == "reference order"
    assert rows[1]["measured ratio"] == 0.5 and rows[1]["ratio uncertainty"] == pytest.approx(0.1 * np.sqrt(2))
    assert rows[1]["predicted ratio"] == pytest.approx(0.5) and rows[1]["verdict"] == "consistent"
    assert rows[80]["predicted ratio"] == pytest.approx(0.03) and rows[80]["n"] == 5
    assert rows[80]["verdict"] == "misses: predicted / measured ratio 0.12"
    assert compare_shape([1, 200], [1.0, 1.0], [0.1, 0.1], spectra, reference=1)[1]["verdict"].startswith(
        "not resolved")


SHAPE = """
[[quantity]]
id = "spectrum"
quantity = "transmission_error_spectrum"
description = "d"
reducer = "RV-160N"
unit_under_test = "one unit"
figure = "Table 9"
kind = "order_amplitudes"
orders = [1, 40]
amplitudes = [2.0, 4.0]
relative_uncertainty = 0.1
unit = "arcsec"
pins = 40
ratio = {ratio}
"""


def test_a_spectrum_of_another_reducer_is_compared_only_on_the_same_order_lattice(tmp_path):
    def spectra(X):
        out = []
        for x in X:
            a = np.zeros(60)
            a[40], a[1] = 4.0, 2.0 * (1 + abs(x[0]) * 100)
            out.append(a)
        return out

    for ratio, compared in ((81, True), (121, False)):
        files = _two_units(tmp_path, SHAPE.format(ratio=ratio))
        res = validate(Magnitude(), SPEC, files, {"y": "y"}, reducer="RV-80E", n=32, seed=2, te_spectra=spectra,
                       shape_of=("s:spectrum",), lattice=(40, 81.0))
        if compared:
            row = res.shape.set_index("order [1/rev]").loc[1]
            assert row["measured / order 40"] == 0.5 and row["verdict"] == "consistent"
        else:
            assert not len(res.shape)
            why = res.comparison.set_index("quantity").loc["spectrum", "verdict"]
            assert why == "not compared: its order lattice (pins 40, ratio 121) is not the design's (pins 40, ratio 81)"


def test_the_estimated_designs_band_beside_each_prediction(tmp_path):
    """y = g·x (µm) with x ~ N(1, 0.1) µm and an estimated gain g ∈ [1, 3] (design range): at nominal tolerances the
    designs give y = g, so the band is [min g, max g] of the drawn designs; a measured 2 µm lies within it, a
    measured 10 µm above every design by ×10/max(g·x units); a bound of 2.5 µm is met by the designs with g ≤ 2.5."""
    from rvtol.design import design_from_table
    from rvtol.epistemic import epistemic_band
    from rvtol.model import FunctionModel

    design = design_from_table({"design": {"name": "d"}, "a": {"g": {
        "value": 2.0, "unit": "1", "source": "s", "status": "estimate", "range": [1.0, 3.0], "basis": "b"}}})
    spec = spec_from_table({"factor": [{"name": "x", "unit": "um", "dist": "normal", "mean": 1.0, "sigma": 0.1}]})

    def maker(values):
        g = design.with_values(**values)["a.g"]
        return FunctionModel(lambda X: g * X, ["x"], [Quantity("y", "mm", "um")], ["mm"]), spec

    band = epistemic_band(design, maker, ["y"], n=40, seed=4, tolerance_samples=30)
    body = SOURCE + QTY.format(kind="value", body='value = 2.0\nunit = "um"\nreading_uncertainty = 0.0') + \
        QTY.format(kind="value", body='value = 10.0\nunit = "um"\nreading_uncertainty = 0.0').replace(
            'id = "q"', 'id = "far"') + \
        QTY.format(kind="upper_limit", body='value = 2.5\nunit = "um"\nreading_uncertainty = 0.0').replace(
            'id = "q"', 'id = "limit"')
    res = validate(maker({})[0], spec, load_published_files([write(tmp_path / "s.toml", body)]), {"y": "y"},
                   reducer="RV-80E", n=64, seed=1, epistemic=band)
    rows = res.stage("predicted (no calibration)").set_index("quantity")
    g = band.values[:, 0]
    assert rows.loc["q", "epistemic min"] == pytest.approx(g.min()) and rows.loc["q", "epistemic max"] == pytest.approx(g.max())
    assert rows.loc["q", "with the estimates"] == "within the estimates' reach"
    hi = band.band("y")["combined high"]
    assert rows.loc["far", "with the estimates"] == f"misses: above every design by ×{10.0 / hi:.3g} ({10.0 - hi:.4g} um)"
    assert rows.loc["limit", "with the estimates"] == f"{100 * np.mean(g <= 2.5):.3g} % of the designs meet it (nominal tolerances)"
    assert rows.loc["q", "estimated drivers (S1)"].startswith("a.g (")
    assert res.summary()["epistemic"]["bands"][0]["output"] == "y"
