"""Both stack-up studies end to end (small n): sections, the shaft–hole record, the CLI and summary.json."""
import json

import pytest

from rvtol.cli import main
from rvtol.study import load_study, run_study

from conftest import ROOT


def test_rv_crank_chain_study_end_to_end(tmp_path, capsys):
    out = tmp_path / "report"
    code = main(["run", str(ROOT / "studies/stackup_rv_crank_chain.toml"), "--n", "600", "--executor", "serial",
                 "--no-pdf", "--quiet", "--out", str(out)])
    assert code in (0, 1), capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    an = summary["analyses"]
    assert {"stackup_graph", "stackup_linear", "stackup_sequences", "stackup_domains"} <= set(an)
    lin = an["stackup_linear"]["outputs"]["cycloid_axis.radial"]
    assert lin["form"] == "norm" and lin["linear"]["WC high"] > lin["linear"]["RSS high"] > 0
    seqs = {(r["output"], r["sequence"]) for r in an["stackup_sequences"]["statistics"]}
    assert ("main_bearing_misfit.radial", "cycloid_first") in seqs
    assert ("cycloid_axis.tilt", "carrier_first") in seqs and ("cycloid_axis.tilt", "cycloid_first") in seqs
    html = (out / "report.html").read_text()
    assert "assembly graph" in html and "<img" in html
