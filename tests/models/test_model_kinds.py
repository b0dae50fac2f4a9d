"""Models without a built-in kind keep the CLI, report and gate: formulas in the study file, a Python
factory named by module:function (imported from a folder next to the study, also in worker processes),
and a kind registered by an installed package's entry point."""
import json

import numpy as np
import pytest

from rvtol.cli import main
from rvtol.models.custom.model import ImportedModel
from rvtol.study import load_study, run_study

from conftest import write

HEAD = """
[study]
name = "{name}"
spec = "{root}/data/specs/rv80e_axial_stack.toml"

[[requirement]]
output = "axial_clearance"
lower = 70
upper = 120
unit = "um"
min_yield = 0.99

[sampling]
n = 600
seed = 5
"""

LINEAR = """
[model]
kind = "linear"
[[model.output]]
name = "axial_clearance"
unit = "mm"
display_unit = "um"
coefficients = { carrier_gap = 1.0, disc1_width = -1.0, disc2_width = -1.0 }
"""

FORMULA = """
[model]
kind = "formula"
[model.define]
discs = "disc1_width + disc2_width"
[[model.output]]
name = "axial_clearance"
formula = "carrier_gap - discs"
unit = "um"
"""

PYTHON = """
[model]
kind = "python"
factory = "gapmodel:make"
path = "."
scale = 1.0
"""

GAPMODEL = '''
import numpy as np
from rvtol.model import Model, Quantity


class Gap(Model):
    """A model class that lives only in this file: workers must import it to unpickle the model."""

    def __init__(self, names, scale):
        self.inputs = tuple(names)
        self.input_units = ("mm",) * len(names)
        self.outputs = (Quantity("axial_clearance", "mm", "um"),)
        self.scale = scale

    def evaluate(self, X):
        X = self.check_input(X)
        return (self.scale * (X[:, 0] - X[:, 1] - X[:, 2]))[:, None]


def make(params, design, spec):
    return Gap(spec.names, params.float("scale", positive=True))
'''


def study(tmp_path, root, name, model):
    return write(tmp_path / f"{name}.toml", HEAD.format(name=name, root=root) + model)


def test_a_formula_study_equals_the_linear_study(tmp_path, root):
    res = {}
    for name, model in (("lin", LINEAR), ("formula", FORMULA)):
        st = load_study(study(tmp_path, root, name, model), executor="serial", progress=False)
        res[name] = run_study(st)
    a, b = res["lin"].mc, res["formula"].mc
    np.testing.assert_allclose(b.Y, a.Y, rtol=0, atol=1e-9)   # µm; same samples, same arithmetic up to rounding
    assert res["formula"].passed == res["lin"].passed
    assert res["formula"].study.model.outputs[0].unit == "mm"   # base unit inside


def test_a_python_factory_next_to_the_study_runs_through_the_cli_on_worker_processes(tmp_path, root):
    write(tmp_path / "gapmodel.py", GAPMODEL)
    path = study(tmp_path, root, "python", PYTHON)
    st = load_study(path)
    assert isinstance(st.model, ImportedModel) and type(st.model.model).__name__ == "Gap"
    out = tmp_path / "rep"
    rc = main(["run", str(path), "--out", str(out), "--executor", "process", "--workers", "2", "--no-pdf",
               "--quiet"])
    assert rc == 0
    s = json.loads((out / "summary.json").read_text())
    lin = run_study(load_study(study(tmp_path, root, "lin", LINEAR), executor="serial", progress=False))
    assert s["outputs"]["axial_clearance"]["mean"] == pytest.approx(float(np.mean(lin.mc.Y[:, 0])), rel=1e-12)
    assert s["verdict"] == "PASS"


@pytest.mark.parametrize("model, key, words", [
    ('[model]\nkind = "python"\nfactory = "no_such_module_xyz:make"\n', "model.factory",
     "cannot import module 'no_such_module_xyz' (ModuleNotFoundError"),
    ('[model]\nkind = "python"\nfactory = "json:nope"\n', "model.factory", "module 'json' has no 'nope'"),
    ('[model]\nkind = "python"\nfactory = "json"\n', "model.factory", "expected 'module:function'"),
    ('[model]\nkind = "python"\nfactory = "json:dumps"\npath = "nowhere"\n', "model.path", "is not a folder"),
    ('[model]\nkind = "python"\nfactory = "gapmodel:make"\npath = "."\nscale = -1\n', "model.scale", "must be > 0"),
    ('[model]\nkind = "python"\nfactory = "gapmodel:make"\npath = "."\nscale = 1\ncolour = 1\n', "model.colour",
     "unknown key"),
    ('[model]\nkind = "python"\nfactory = "math:sqrt"\n', "model", "sqrt() takes exactly one argument"),
])
def test_bad_python_models_are_one_line_errors(tmp_path, root, capsys, model, key, words):
    write(tmp_path / "gapmodel.py", GAPMODEL)
    path = study(tmp_path, root, "bad", model)
    rc = main(["check", "--execute", str(path)])
    err = capsys.readouterr().err
    if "sqrt" in words:   # a factory with the wrong signature is a bug in it, not bad input: internal error
        assert rc == 3 and "TypeError" in err
        return
    assert rc == 2 and err.count("\n") == 1
    assert err.startswith(f"rvtol: error: {path}: {key}: ") and words in err, err


def test_a_factory_that_returns_no_model_is_refused(tmp_path, root, capsys):
    write(tmp_path / "notmodel.py", "def make(params, design, spec):\n    return 42\n")
    path = study(tmp_path, root, "bad", '[model]\nkind = "python"\nfactory = "notmodel:make"\npath = "."\n')
    assert main(["check", "--execute", str(path)]) == 2
    assert "factory 'notmodel:make' returned int, not an rvtol.model.Model" in capsys.readouterr().err


def test_an_entry_point_plugin_is_a_model_kind(tmp_path, root, monkeypatch, capsys):
    site = tmp_path / "site"
    write(site / "rvtol_demo_plugin.py", GAPMODEL + "\n\ndef from_study(params, design, spec):\n"
                                                    "    return make(params, design, spec)\n")
    dist = site / "rvtol_demo_plugin-0.1.dist-info"
    write(dist / "METADATA", "Metadata-Version: 2.1\nName: rvtol-demo-plugin\nVersion: 0.1\n")
    write(dist / "entry_points.txt", "[rvtol.models]\ndemo_gap = rvtol_demo_plugin:from_study\n"
                                     "broken_gap = rvtol_demo_plugin_missing:from_study\n")
    monkeypatch.syspath_prepend(str(site))
    assert main(["kinds"]) == 0
    assert "demo_gap (rvtol_demo_plugin:from_study)" in capsys.readouterr().out
    st = load_study(study(tmp_path, root, "plugin", '[model]\nkind = "demo_gap"\nscale = 1.0\n'),
                    executor="serial", progress=False)
    lin = load_study(study(tmp_path, root, "lin", LINEAR), executor="serial", progress=False)
    np.testing.assert_allclose(run_study(st).mc.Y, run_study(lin).mc.Y, rtol=1e-12)
    path = study(tmp_path, root, "broken", '[model]\nkind = "broken_gap"\n')
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"{path}: model.kind: model kind 'broken_gap' is registered by entry point" in err
    assert "ModuleNotFoundError" in err
    path = study(tmp_path, root, "unknown", '[model]\nkind = "no_such_kind"\n')
    assert main(["check", str(path)]) == 2
    assert "demo_gap" in capsys.readouterr().err   # the known kinds include the plug-in's
