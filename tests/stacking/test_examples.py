"""Show: textbook and peer-tool stacks with published answers, kept as spreadsheets (data/examples/), run
through the CLI: worst case, RSS, MRSS and the 6σ dynamic RSS against the printed figures
(data/examples/published.toml, each recomputed by hand there), the Monte Carlo σ, mean and yield against the
closed forms of the same distributions, and the sub-ppm tail (FORM exact for these linear normal stacks,
importance sampling within its standard error) where the Monte Carlo sees nothing."""
import json
import math
import tomllib

import numpy as np
import pytest
from scipy import stats

from rvtol.cli import main

from conftest import ROOT

PUBLISHED = tomllib.loads((ROOT / "data" / "examples" / "published.toml").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = {}
    for name, ex in PUBLISHED.items():
        folder = tmp_path_factory.mktemp(name) / "report"
        rc = main(["run", str(ROOT / ex["study"]), "--out", str(folder), "--executor", "serial", "--no-pdf",
                   "--quiet", "--n", "5000"] + (["--tables", "xlsx"] if name == "mitcalc_demo" else []))
        out[name] = (rc, json.loads((folder / "summary.json").read_text()), folder)
    return out


@pytest.mark.parametrize("example, fig", [(n, f) for n, ex in PUBLISHED.items() for f in ex["figure"]],
                         ids=lambda v: v if isinstance(v, str) else v["convention"])
def test_published_stack_figures_are_reproduced(runs, example, fig):
    rc, summary, _ = runs[example]
    assert rc == 0
    ex = PUBLISHED[example]
    sc = summary["analyses"]["stack_conventions"][ex["output"]]
    assert sc["unit"] == ex["unit"]
    row = next(r for r in sc["conventions"] if r["convention"] == fig["convention"])
    res = fig["resolution"]
    for key in ("centre", "half_width", "sigma"):
        if key in fig:
            assert row[key] == pytest.approx(fig[key], abs=res), (key, row[key], fig[key])
    for key in ("low", "high"):   # printed with fewer digits than the half width in the handbook
        if key in fig:
            digits = len(repr(fig[key]).split(".")[1])
            assert row[key] == pytest.approx(fig[key], abs=max(res, 0.5 * 10 ** -digits)), (key, row[key], fig[key])


def _normal_stack(summary, output):
    """Mean and σ of the linear stack of the distributions (rvtol's own 'statistical' row: the closed form)."""
    row = next(r for r in summary["analyses"]["stack_conventions"][output]["conventions"]
               if r["convention"].startswith("statistical ±3σ"))
    return row["centre"], row["sigma"]


def test_monte_carlo_sigma_mean_and_yield_against_the_closed_forms(runs):
    for name, ex in PUBLISHED.items():
        _, s, _ = runs[name]
        o = s["outputs"][ex["output"]]
        n = o["n"]
        mu, sigma = _normal_stack(s, ex["output"])
        assert abs(o["mean"] - mu) < 4 * sigma / math.sqrt(n)
        assert abs(o["std"] - sigma) < 4 * sigma / math.sqrt(2 * n)
    # the handbook's RSS reads every tolerance as ±3σ: its σ is RSS/3
    _, s, _ = runs["handbook_motor_assembly"]
    assert _normal_stack(s, "gap")[1] == pytest.approx(0.03808 / 3, abs=5e-6 / 3)
    # MITCalc prints no rejects against [0.05, 0.8] mm: the Monte Carlo sees none, the tail estimates agree
    _, s, _ = runs["mitcalc_demo"]
    req = s["outputs"]["gap"]["requirements"][0]
    assert req["ppm"] == 0.0 and req["passed"]
    est = s["analyses"]["tail_probability"]["estimates"]
    total_ppm = sum(e["ppm_form"] for e in est)
    assert total_ppm == pytest.approx(PUBLISHED["mitcalc_demo"]["yield"]["published_reject_ppm"],
                                      abs=PUBLISHED["mitcalc_demo"]["yield"]["resolution_ppm"])


def test_the_sub_ppm_tail_where_the_monte_carlo_sees_nothing(runs):
    for name, ex in PUBLISHED.items():
        _, s, _ = runs[name]
        mu, sigma = _normal_stack(s, ex["output"])
        for e in s["analyses"]["tail_probability"]["estimates"]:
            z = (e["limit"] - mu) / sigma if e["side"] == "upper" else (mu - e["limit"]) / sigma
            exact = stats.norm.sf(z)                                  # linear stack of normals: FORM is exact
            assert e["form_converged"] and e["beta"] == pytest.approx(z, rel=1e-6)
            assert e["pf_form"] == pytest.approx(exact, rel=1e-5)
            assert abs(e["pf_importance_sampling"] - exact) < 4 * e["pf_importance_sampling_se"]
            assert e["mc_ppm"] == 0.0 and e["mc_ppm_ci"][1] > 100    # the sample bounds the tail only loosely
            assert e["ppm_form"] < 1.0                                  # sub-ppm


def test_the_tables_beside_parquet(runs):
    import pandas as pd

    _, s, folder = runs["mitcalc_demo"]
    samples = pd.read_excel(folder / "samples.xlsx")
    assert len(samples) == s["n"] and "gap [mm]" in samples.columns
    stats_ = pd.read_excel(folder / "statistics.xlsx", sheet_name=None)
    assert set(stats_) == {"statistics", "requirements"}
    assert stats_["statistics"].loc[0, "mean"] == pytest.approx(s["outputs"]["gap"]["mean"])
    assert stats_["requirements"].loc[0, "cpk_method"] == "percentile"
    np.testing.assert_allclose(samples["gap [mm]"], pd.read_parquet(folder / "samples.parquet")["gap [mm]"])
