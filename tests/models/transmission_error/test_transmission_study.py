"""The transmission-error study: loading, bad input, the analyses on a small configuration."""

import pytest

from rvtol.errors import InputError
from rvtol.study import load_study, run_study

from conftest import ROOT, needs_wing, write

DESIGN = (ROOT / "data/designs/rv80e_te.toml").as_posix()


def study_text(model="", analyses="", factors=None):
    factors = factors or """
[[factor]]
name = "E_c"
unit = "um"
dist = "uniform"
lower = 0.5
upper = 1.5

[[factor]]
name = "delta_b"
unit = "um"
dist = "uniform"
lower = 1.0
upper = 3.0
"""
    return f"""
[study]
name = "te_small"
design = "{DESIGN}"

[model]
kind = "transmission_error"
per_crank_rev = 12
{model}

[sampling]
n = 4
seed = 3

[execution]
executor = "serial"
{factors}
{analyses}
"""


@pytest.mark.parametrize("model, factors, key", [
    ('mode = "explicit"', None, "model.mode"),
    ("harmonic = 9", None, "model.harmonic"),
    ("load_torque = -5", None, "model.load_torque"),
    ("bogus = 1", None, "model.bogus"),
    ("max_order = 100", None, "model.max_order"),        # per_crank_rev is set too: one or the other
    ("", '[[factor]]\nname = "E_q"\nunit = "um"\ndist = "uniform"\nlower = 0\nupper = 1\n', "factor"),
    ("", '[[factor]]\nname = "E_c"\nunit = "deg"\ndist = "uniform"\nlower = 0\nupper = 1\n', "factor.unit"),
])
def test_bad_study_input_names_file_and_key(tmp_path, model, factors, key):
    p = write(tmp_path / "s.toml", study_text(model, factors=factors))
    with pytest.raises(InputError) as exc:
        load_study(p)
    assert exc.value.key == key and exc.value.file == str(p)


@pytest.mark.parametrize("kind, key, value, options", [
    ("transmission_error", "mass.disc", -1e-3, {"mode": "newmark"}),            # t: base units
    ("transmission_error", "damping.modal_ratio", -0.05, {"mode": "newmark"}),
    ("transmission_error", "sun.pressure_angle", 1.7, {}),                       # rad: > 90°
    ("torsion_curve", "reducer.rated_torque", -784e3, {}),
])
def test_bad_design_numbers_name_the_design_file_and_key(kind, key, value, options):
    """A bad number in the design file is reported there (not as a key of the study's [model] table)."""
    from rvtol.design import load_design
    from rvtol.params import Params
    from rvtol.registry import MODELS
    from rvtol.spec import spec_from_table
    import importlib

    design = load_design(DESIGN).with_values(**{key: value})
    spec = spec_from_table({"factor": [{"name": "delta_b", "unit": "um", "dist": "uniform", "lower": 0,
                                        "upper": 3}]})
    module, factory = MODELS[kind].split(":")
    with pytest.raises(InputError) as exc:
        getattr(importlib.import_module(module), factory)(Params(dict(options), file="study.toml", key="model"),
                                                          design, spec)
    assert exc.value.key == key and exc.value.file == DESIGN


@needs_wing
def test_sensitivity_and_curve_analyses_small(tmp_path):
    analyses = """
[[analysis]]
kind = "transmission_error_reproduction"
printed = "PRINTED"
factors = ["E_c", "delta_b", "E_s"]
magnitudes = [1.0, 2.0]

[[analysis]]
kind = "transmission_error_curve"
configuration = "values"
values = { E_c = 2.0 }
"""
    analyses = analyses.replace("PRINTED", (ROOT / "data/reproduction/doc000_transmission_error.toml").as_posix())
    res = run_study(load_study(write(tmp_path / "s.toml", study_text(analyses=analyses)), progress=False))
    assert res.mc.ok.all()
    sens, curve = res.sections
    rank = {r["factor"]: r for r in sens.summary["ranking"]}
    assert rank["E_c"]["rvtol class"] == "high" and rank["E_s"]["rvtol class"] == "negligible"
    assert rank["E_c"]["document class"] == "high"
    printed = {r["factor"]: r for r in sens.summary["printed"]}
    assert set(printed) == {"E_c", "delta_b"}
    lin = {r["factor"]: r["ratio"] for r in sens.summary["linearity"]}
    assert lin["E_c"] == pytest.approx(2.0, rel=0.06)
    assert curve.summary["te_pp_arcsec"]["quasistatic"] > 1.0
    assert curve.summary["top_orders"][0]["order [1/rev]"] == 40
    first = curve.summary["order_attribution"][0]     # E_c = 2 µm on all six cams: crank-fixed, order z_b
    assert first["order [1/rev]"] == 40 and first["expected from"].startswith("cranks [E_c")


def test_generic_sensitivity_analysis_has_no_document_columns(tmp_path):
    """kind = "transmission_error_sensitivity" ranks by rvtol's classes alone (the document is the reproduction's)."""
    analyses = """
[[analysis]]
kind = "transmission_error_sensitivity"
factors = ["E_c", "E_s"]
magnitudes = [1.0]
"""
    res = run_study(load_study(write(tmp_path / "s.toml", study_text(analyses=analyses)), n=4, progress=False))
    (sens,) = res.sections
    rank = {r["factor"]: r for r in sens.summary["ranking"]}
    assert rank["E_c"]["rvtol class"] == "high" and "document class" not in rank["E_c"] and "printed" not in sens.summary
