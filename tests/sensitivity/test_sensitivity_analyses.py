"""The sensitivity analyses inside a study: sections, summary, bad input named by file and key."""
import json

import numpy as np
import pytest

from rvtol.errors import InputError
from rvtol.study import load_study, run_study

from conftest import write

STUDY = """
[study]
name = "sens"

[model]
kind = "linear"

[[model.output]]
name = "gap"
unit = "mm"
display_unit = "um"
coefficients = { a = 1.0, b = -2.0 }

[[factor]]
name = "a"
unit = "um"
dist = "normal"
mean = 10.0
tolerance = 6.0

[[factor]]
name = "b"
unit = "um"
dist = "uniform"
lower = -1.0
upper = 3.0

[sampling]
n = 2000
seed = 4

[execution]
executor = "serial"
"""

ANALYSES = """
[[analysis]]
kind = "local_sensitivity"
[[analysis]]
kind = "sensitivity_curve"
factors = ["a"]
magnitudes = [0.5, 5, 15]
unit = "um"
[[analysis]]
kind = "contributions"
[[analysis]]
kind = "sobol"
n = 256
[[analysis]]
kind = "morris"
trajectories = 8
[[analysis]]
kind = "fast"
[[analysis]]
kind = "fast"
key = "rbd_fast"
method = "rbd"
[[analysis]]
kind = "delta"
num_resamples = 10
[[analysis]]
kind = "given_data"
num_resamples = 50
[[analysis]]
kind = "pce"
num_resamples = 20
"""


def test_every_sensitivity_analysis_runs_in_a_study(tmp_path):
    st = load_study(write(tmp_path / "s.toml", STUDY + ANALYSES), progress=False)
    res = run_study(st)
    keys = [s.key for s in res.sections]
    assert keys == ["local_sensitivity", "sensitivity_curve", "contributions", "sobol", "morris", "fast",
                    "rbd_fast", "delta", "given_data", "pce"]
    for s in res.sections:
        json.dumps(s.summary, allow_nan=False)   # JSON-able, no NaN
        assert any(hasattr(b, "png") for b in s.blocks), s.key   # every analysis draws its plot
    local = res.sections[0].summary["derivatives"]
    s = {r["factor"]: r["S"] for r in local}
    assert s["a"] == pytest.approx(1.0) and s["b"] == pytest.approx(-2.0)   # µm/µm
    pred = res.sections[2].summary["gap"]["prediction"]
    sd = np.hypot(1.0, 2.0 * 4 / np.sqrt(12))
    assert pred["std_rss"] == pytest.approx(sd, rel=1e-9)
    # the Monte Carlo routes: no model run; delta on its stated subsample (all 2000 here), the PCE exact
    # for this linear model (Q² = 1) and its indices the closed form within their intervals
    delta, given, pce = (s.summary for s in res.sections[7:])
    assert delta["settings"]["n"] == 2000 and given["n_evaluations"] == pce["n_evaluations"] == 0
    exact = {"a": 1.0 / sd ** 2, "b": (2.0 * 4 / np.sqrt(12)) ** 2 / sd ** 2}      # V_i / V of a − 2b
    v = pce["validation"][0]
    assert v["reliable"] and v["Q2_loo"] > 0.999999
    for rec in pce["indices"]:
        assert abs(rec["S1"] - exact[rec["factor"]]) <= rec["S1_conf"] + 1e-6
        assert abs(rec["ST"] - exact[rec["factor"]]) <= rec["ST_conf"] + 1e-6
    for rec in given["indices"]:
        assert abs(rec["S1"] - exact[rec["factor"]]) <= 2 * rec["S1_conf"]


@pytest.mark.parametrize("table, key", [
    ('kind = "sobol"\nn = 100', "analysis[0].n"),
    ('kind = "sobol"\noutputs = ["nope"]', "analysis[0].outputs"),
    ('kind = "morris"\nfactors = ["zz"]', "analysis[0].factors"),
    ('kind = "morris"\nlevels = 3', "analysis[0].levels"),
    ('kind = "sensitivity_curve"\nmagnitudes = [1.0]', "analysis[0].factors"),
    ('kind = "sensitivity_curve"\nfactors = ["a"]\nmagnitudes = [0.0]', "analysis[0].magnitudes"),
    ('kind = "sensitivity_curve"\nfactors = ["a"]\nmagnitudes = [1.0]\nunit = "deg"', "analysis[0].unit"),
    ('kind = "local_sensitivity"\nabs_step = { zz = 1.0 }', "analysis[0].abs_step.zz"),
    ('kind = "local_sensitivity"\npercnt = 5', "analysis[0].percnt"),
    ('kind = "fast"\nmethod = "rbd"\nsamples = "old"', "analysis[0].samples"),
    ('kind = "delta"\nn = 50', "analysis[0].n"),
    ('kind = "given_data"\nclasses = 1', "analysis[0].classes"),
    ('kind = "pce"\nmin_q2 = 1.5', "analysis[0].min_q2"),
    ('kind = "pce"\non_poor_fit = "ignore"', "analysis[0].on_poor_fit"),
    ('kind = "pce"\nmethod = "lasso"', "analysis[0].method"),
    ('kind = "pce"\nn = 20', "analysis[0].n"),
])
def test_bad_analysis_input_names_file_and_key(tmp_path, table, key):
    path = write(tmp_path / "s.toml", STUDY + "\n[[analysis]]\n" + table + "\n")
    with pytest.raises(InputError) as e:
        load_study(path)
    assert e.value.key == key and e.value.file == str(path)
