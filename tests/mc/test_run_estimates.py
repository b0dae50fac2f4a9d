"""The run's disk estimate against the report folder it writes (issue 27, item 4): within 2× on small studies.
(The time estimate is compared with the run by studies/benchmarks/bench_estimates.py — no wall clock in tests.)"""
import json
from pathlib import Path

import pytest

from rvtol.cli import main
from rvtol.runguard import estimate_run
from rvtol.study import load_study

from conftest import ROOT


def _folder_bytes(folder: Path) -> int:
    return sum(p.stat().st_size for p in folder.rglob("*") if p.is_file())


@pytest.mark.parametrize("study,n", [("linear_stackup", 4000), ("stack_handbook_motor", 4000), ("init", 3000)])
def test_disk_estimate_is_within_2x_of_the_report_folder(tmp_path, capsys, study, n):
    if study == "init":
        assert main(["init", str(tmp_path / "first")]) == 0
        path = tmp_path / "first" / "study.toml"
    else:
        path = ROOT / "studies" / f"{study}.toml"
    st = load_study(path, n=n, pdf=False, executor="serial")
    est = estimate_run(st)
    out = tmp_path / "rep"
    rc = main(["run", str(path), "--out", str(out), "--n", str(n), "--no-pdf", "--executor", "serial", "--quiet"])
    assert rc in (0, 1), capsys.readouterr().err
    actual = _folder_bytes(out)
    assert json.loads((out / "summary.json").read_text(encoding="utf-8"))["n"] == n
    assert actual / 2 <= est.disk <= 2 * actual, (est.disk, actual)
