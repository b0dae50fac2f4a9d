"""The published JSON Schema of summary.json (rvtol/ci/summary.schema.json) holds for every study's
summary, and it rejects what is not one (a schema that accepts anything would prove nothing)."""
import copy
import json

import pytest

from rvtol.ci.schema import SCHEMA_PATH, summary_errors, validate_summary
from rvtol.cli import main
from rvtol.errors import InputError
from rvtol.study import load_study, run_study

from conftest import ROOT, study_param

STUDIES = sorted((ROOT / "studies").glob("*.toml"))


def test_the_schema_is_a_valid_draft_2020_12_schema():
    from jsonschema import Draft202012Validator

    schema = json.loads(SCHEMA_PATH.read_text())
    Draft202012Validator.check_schema(schema)
    assert schema["properties"]["format"] == {"const": "rvtol-summary/1"}


@pytest.mark.parametrize("path", [study_param(p) for p in STUDIES])
def test_every_studys_summary_validates(path):
    """Each study at a small n: its Monte Carlo, requirements and verdict (the analyses' own tables are free-form
    objects in the schema and are exercised by the studies' own tests)."""
    study = load_study(path, n=16, executor="serial", progress=False)
    study.analyses = []
    summary = json.loads(json.dumps(run_study(study).summary(), allow_nan=False))
    assert summary_errors(summary) == []
    assert summary["verdict"] in ("PASS", "FAIL", "EXPLORATORY")  # no study is left without requirements


def test_a_full_cli_run_validates_and_broken_summaries_do_not(tmp_path):
    out = tmp_path / "lin"
    assert main(["run", str(ROOT / "studies" / "linear_stackup.toml"), "--out", str(out), "--n", "500",
                 "--executor", "serial", "--no-pdf", "--quiet"]) in (0, 1)
    good = json.loads((out / "summary.json").read_text())
    validate_summary(good)
    breakages = {
        "verdict": lambda s: s.update(verdict="MAYBE"),
        "passed": lambda s: s.update(passed=not s["passed"]),
        "outputs/axial_clearance: 'unit' is a required": lambda s: s["outputs"]["axial_clearance"].pop("unit"),
        "outputs/axial_clearance/requirements/0/yield_ci": lambda s: s["outputs"]["axial_clearance"]["requirements"][0]
        .update(yield_ci=[0.9]),
        "inputs/study/sha256": lambda s: s["inputs"]["study"].update(sha256="not a hash"),
        "n": lambda s: s.update(n=1),
        "format": lambda s: s.update(format="rvtol-summary/2"),
    }
    for where, breaks in breakages.items():
        bad = copy.deepcopy(good)
        breaks(bad)
        errors = summary_errors(bad)
        assert errors and any(e.startswith(where) for e in errors), (where, errors)
        with pytest.raises(InputError):
            validate_summary(bad, "x.json")
