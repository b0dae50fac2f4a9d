"""Both stack-up studies end to end (small n): sections, the shaft–hole record, the CLI and summary.json."""
import json
from pathlib import Path

import pytest

from rvtol.cli import main
from rvtol.study import load_study, run_study

ROOT = Path(__file__).resolve().parents[1]


def test_shaft_hole_study_records_the_printed_figures():
    st = load_study(ROOT / "studies/stackup_shaft_hole.toml", n=400, executor="serial", progress=False)
    res = run_study(st)
    secs = {s.key: s for s in res.sections}
    assert set(secs) == {"stackup_shaft_hole", "stackup_linear", "stackup_graph", "stackup_domains"}
    rec = {r["figure"]: r for r in secs["stackup_shaft_hole"].summary["figures"]}
    assert secs["stackup_shaft_hole"].summary["max_clearance_mm"] == pytest.approx(0.25)
    assert rec["maximum linear deviation from the size difference"]["reproduced"].startswith("yes")
    for f in ("linear deviation magnitude ‖e(E)‖", "rotational deviation magnitude ‖ε(E)‖", "angular error Δθ"):
        assert rec[f]["reproduced"] == "no"
    assert rec["angular error Δθ"]["rvtol WC"] == pytest.approx(0.5729578, rel=1e-6)  # c/L = 0.01 rad
    assert rec["linear deviation magnitude ‖e(E)‖"]["rvtol WC"] == pytest.approx(0.125)
    # the domain checks agree with their derivations (|z| < 4.5 on 10⁶ samples); the as-printed interference
    # fit, whose clearance is positive in ~1e-5 of the samples, gets no z at all (too few samples deviate)
    for name, d in secs["stackup_domains"].summary.items():
        printed = "as printed" in name
        assert ("samples_deviating" in d) == printed, name
        for row in d["moments"]:
            for z in ("z(mean)", "z(σ)"):
                if printed:
                    assert row[z] is None, (name, row)
                else:
                    assert row[z] is not None and abs(row[z]) < 4.5, (name, row)


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
