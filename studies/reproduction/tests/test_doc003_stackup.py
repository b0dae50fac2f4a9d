"""Doc 003: the shaft–hole study's printed figures and the planar zone's printed formulas against rvtol."""
from pathlib import Path

import pytest

pytest.importorskip("rvtol_reproduction", reason="the reproduction wing is not installed "
                                                  "(python -m pip install -e studies/reproduction)")

from rvtol.plugin import ParallelPlaneZone
from rvtol.study import load_study, run_study
from rvtol_reproduction.doc003_stackup import planar_record

ROOT = Path(__file__).resolve().parents[3]   # the repository


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


def test_planar_record_states_the_documents_formulas():
    z = ParallelPlaneZone(0.0, 0.02, 40.0, 25.0)
    rec = planar_record(z).set_index("quantity")
    doc = rec["document (printed formula)"]
    assert doc["mean Δw"] == pytest.approx(0.01) and doc["mean Δα"] == pytest.approx(0.02 / 80)
    assert doc["σ²(Δw)"] == pytest.approx(0.02**2 / 12) and doc["σ²(Δα)"] == pytest.approx(0.02**2 / (3 * 40**2))
    assert doc["bound |Δα|"] == pytest.approx(2 * 0.02 / 40)
    # the printed variances are those of the tight box, not of the printed bounds
    assert rec.loc["σ²(Δw)", "box (derived)"] == pytest.approx(doc["σ²(Δw)"])
    assert rec.loc["σ34 = cov(Δw, Δα)", "exact domain (derived)"] == 0.0
