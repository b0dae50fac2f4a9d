"""First-order indices from given data and delta on a subsample (rvtol.sensitivity.given_data).

References: closed-form S1 of Ishigami, Sobol' G and a linear model (gsa_reference), SALib's
Saltelli and RBD-FAST estimators on the same function.  Tolerance rule: each estimate within its
own bootstrap interval (at 1 − 0.05/m for m comparisons) of the analytic value, plus the bound
on the discretisation bias of the classes where it is not negligible.  Fixed seeds; no
wall-clock assertions.
"""
import numpy as np
import pytest
from gsa_reference import (G_MODEL, G_SPEC, ISH, ISH_SPEC, bonferroni, evaluate_display, g_indices,
                           ishigami_indices, linear_case)

from rvtol.errors import InputError
from rvtol.model import LinearModel, Quantity
from rvtol.sampling import sample
from rvtol.sensitivity import rbd_fast, sobol
from rvtol.sensitivity.given_data import (DELTA_DEFAULT_N, correlation_ratio, default_classes, delta_given,
                                          delta_subsample, first_order_given_data, given_data)
from rvtol.spec import spec_from_table


def _within(est, true, conf, extra=0.0):
    return np.abs(np.asarray(est) - true) <= np.asarray(conf) + extra + 1e-12


def test_ishigami_first_order_from_the_monte_carlo_sample():
    S1, _, _ = ishigami_indices()
    s = sample(ISH_SPEC, 4096, "lhs", 20261123)
    res = given_data(ISH, ISH_SPEC, s, evaluate_display(ISH, s), seed=1, confidence=bonferroni(3))
    d = res.frame
    # discretisation bias of the 64 classes: ≤ mean(g')²/(12 M² V) = 5.8/M² = 0.0014 for x2 (module notes)
    assert res.settings["classes"] == 64 and res.n_evaluations == 0
    assert _within(d["S1"], S1, d["S1_conf"], 0.0014).all(), (d, S1)
    assert ((d["S1_low"] <= S1 + 0.0014) & (S1 - 0.0014 <= d["S1_high"])).all(), (d, S1)
    assert d["S1_conf"].max() < 0.05


def test_sobol_g_first_order_from_given_data():
    S1, _ = g_indices()
    s = sample(G_SPEC, 4096, "lhs", 3)
    d = given_data(G_MODEL, G_SPEC, s, evaluate_display(G_MODEL, s), seed=2, confidence=bonferroni(6)).frame
    assert _within(d["S1"], S1, d["S1_conf"]).all(), (d, S1)
    assert list(d.sort_values("S1", ascending=False)["factor"][:2]) == ["g0", "g1"]


def test_linear_model_first_order_from_given_data():
    model, spec, share = linear_case()
    s = sample(spec, 4000, "random", 9)
    d = given_data(model, spec, s, evaluate_display(model, s), seed=4, confidence=bonferroni(5)).frame
    assert _within(d["S1"], share, d["S1_conf"]).all(), (d, share)


def test_given_data_agrees_with_saltelli_and_rbd_fast_within_their_intervals():
    """Given-data S1 on 4 096 Monte Carlo runs against SALib Saltelli (5 120 runs) and SALib RBD-FAST
    (EASI) on the same given sample: differences within √(c_a² + c_b²)."""
    conf = bonferroni(6)
    sal = sobol(ISH, ISH_SPEC, n=1024, second_order=False, seed=21, confidence=conf).frame
    s = sample(ISH_SPEC, 4096, "lhs", 22)
    Y = evaluate_display(ISH, s)
    gd = given_data(ISH, ISH_SPEC, s, Y, seed=23, confidence=conf).frame
    rb = rbd_fast(ISH, ISH_SPEC, samples=s, Y=Y, seed=24, confidence=conf).frame
    for other in (sal, rb):
        assert (np.abs(gd["S1"] - other["S1"]) <= np.hypot(gd["S1_conf"], other["S1_conf"])).all(), (gd, other)


def test_kelley_correction_removes_the_noise_bias():
    """y independent of 20 inputs: the plain between-class share has bias (M−1)/n = 0.0154 at n = 4096;
    the corrected one averages 0 within 4 standard errors (sd of one index ≈ √(2(M−1))/n = 0.0028)."""
    rng = np.random.default_rng(5)
    n, k = 4096, 20
    X, y = rng.random((n, k)), rng.standard_normal(n)
    res = first_order_given_data(X, y, seed=6, num_resamples=50)
    M = res["M"]
    assert M == default_classes(n) == 64
    plain = []
    for i in range(k):
        c = np.minimum((np.argsort(np.argsort(X[:, i])) * M) // n, M - 1)
        means = np.bincount(c, y, M) / np.bincount(c, minlength=M)
        plain.append(np.sum(np.bincount(c, minlength=M) * (means - y.mean()) ** 2) / np.sum((y - y.mean()) ** 2))
    sd_one = np.sqrt(2 * (M - 1)) / n
    assert np.mean(plain) == pytest.approx((M - 1) / n, abs=4 * sd_one / np.sqrt(k))
    assert abs(np.mean(res["S1"])) < 4 * sd_one / np.sqrt(k)
    # the bootstrap interval is centred on the corrected estimate, not on the plain one
    mid = 0.5 * (res["S1_low"] + res["S1_high"])
    assert abs(np.mean(mid - res["S1"])) < 4 * sd_one / np.sqrt(k)
    assert correlation_ratio(X[:, 0], y) == pytest.approx(res["S1"][0])


def test_correlated_inputs_are_noted():
    spec = spec_from_table({"factor": [{"name": n, "unit": "mm", "dist": "normal", "mean": 0.0, "sigma": 1.0}
                                       for n in "pqr"],
                            "correlation": [{"pair": ["p", "q"], "rho": 0.6}]})
    model = LinearModel(spec.names, ["mm"] * 3, [Quantity("y", "mm")], [[1.0, -2.0, 0.5]])
    s = sample(spec, 2000, "random", 3)
    res = given_data(model, spec, s, evaluate_display(model, s), seed=1)
    assert any("dependent" in n and "delta" in n for n in res.notes)
    # y = p − 2q + r/2 with corr(p, q) = 0.6: V = 1 + 4 − 2.4 + 0.25 = 2.85; Var E[y|p] = (1 − 1.2)² = 0.04
    d = res.frame.set_index("factor")
    assert _within(d.loc["p", "S1"], 0.04 / 2.85, d.loc["p", "S1_conf"])
    assert _within(d.loc["q", "S1"], (0.6 - 2) ** 2 / 2.85, d.loc["q", "S1_conf"])


# --------------------------------------------------------------------------- delta on a subsample
def test_delta_subsample_has_a_stated_default_size():
    model, spec, _ = linear_case()
    s = sample(spec, 5000, "random", 1)
    Y = evaluate_display(model, s)
    assert DELTA_DEFAULT_N == 2000
    sub, Ysub, note = delta_subsample(s, Y, seed=3)
    assert len(sub) == len(Ysub) == 2000 and "2000 of the 5000" in note
    rows = [int(np.flatnonzero((s.values == v).all(axis=1))[0]) for v in sub.values[:50]]
    assert rows == sorted(rows)   # a subset, in the original order
    np.testing.assert_array_equal(Ysub[:50], Y[rows])
    again, _, _ = delta_subsample(s, Y, seed=3)
    other, _, _ = delta_subsample(s, Y, seed=4)
    assert np.array_equal(again.values, sub.values) and not np.array_equal(other.values, sub.values)
    whole, Yw, note = delta_subsample(s, Y, n=None)
    assert whole is s and "all 5000" in note
    with pytest.raises(InputError):
        delta_subsample(s, Y, n=10)


def test_delta_given_runs_on_the_subsample_and_says_so():
    model, spec, _ = linear_case()
    s = sample(spec, 3000, "random", 2)
    res = delta_given(model, spec, s, evaluate_display(model, s), n=600, seed=5, num_resamples=10)
    assert res.settings["n"] == 600 and res.settings["n_given"] == 3000 and res.n_evaluations == 0
    assert "600 of the 3000" in res.notes[0]
    d = res.frame.set_index("factor")
    assert d["delta"].idxmax() == "q" and d.loc["s", "delta"] < d.loc["t", "delta"]   # q carries 82 % of V


def test_indices_alone_skip_the_bootstrap_and_equal_the_ones_with_intervals():
    """num_resamples = 0 (the sign-off digest: drivers need no interval): the same S1, per column the
    correlation ratio by hand, the interval columns NaN; one ranking of the factors serves every output."""
    s = sample(ISH_SPEC, 2048, "lhs", 7)
    Y = evaluate_display(ISH, s)
    full = given_data(ISH, ISH_SPEC, s, Y, seed=1, num_resamples=50).frame
    bare = given_data(ISH, ISH_SPEC, s, Y, seed=1, num_resamples=0).frame
    np.testing.assert_array_equal(bare["S1"], full["S1"])
    assert bare[["S1_conf", "S1_low", "S1_high"]].isna().all().all()
    X = s.values
    for i, name in enumerate(ISH_SPEC.names):
        assert bare.loc[bare["factor"] == name, "S1"].item() == pytest.approx(correlation_ratio(X[:, i], Y[:, 0]))
    with pytest.raises(InputError):
        first_order_given_data(X, Y[:, 0], num_resamples=5)


def test_one_ranking_serves_the_classes_and_the_dependence_check(monkeypatch):
    """One ranking of X, a column at a time: the classes equal each column's own ranking, and the Spearman
    matrix of U = F(X) equals scipy's (Pearson of ``rankdata(U)``) — a tie-free column by the CDF's order, a
    column with ties (a flat stretch of F, a constant) by average ranks —, summed over row blocks as over the
    whole; the dependence check gives the same pairs either way."""
    from scipy import stats as sps

    from rvtol.sensitivity import given_data as gd
    from rvtol.sensitivity._given import correlated_pairs

    rng = np.random.default_rng(3)
    n = 500
    a = rng.standard_normal(n)
    X = np.column_stack([a, a + 0.5 * rng.standard_normal(n), rng.random(n), np.full(n, 2.0)])
    cdfs = [sps.norm.cdf, lambda x: sps.norm.cdf(x / np.sqrt(1.25)),
            lambda x: np.clip(x, 0.3, 0.7),                   # a CDF flat at both ends: ties in U, not in X
            lambda x: np.full(len(x), 0.5)]
    U = np.column_stack([f(X[:, j]) for j, f in enumerate(cdfs)])
    with np.errstate(invalid="ignore", divide="ignore"):
        expect = np.corrcoef(sps.rankdata(U, axis=0), rowvar=False)
    for block in (n, 64):                                      # one block, several
        monkeypatch.setattr(gd, "GRAM_BLOCK", block)
        C, rho = gd.classes_and_spearman(X, cdfs, [0, 2, 3], classes=10)
        np.testing.assert_allclose(rho, expect, rtol=0, atol=1e-13)     # NaN where the constant column is
        for c, j in enumerate((0, 2, 3)):
            np.testing.assert_array_equal(C[:, c], gd.class_index(X[:, j], 10))
            assert np.bincount(C[:, c]).tolist() == [50] * 10           # equal-count classes
    names = ["a", "b", "c", "d"]
    pairs = correlated_pairs(names, rho=rho, n=n)
    assert [p[:2] for p in pairs] == [p[:2] for p in correlated_pairs(names, U)] == [("a", "b")]
    assert pairs[0][2] == pytest.approx(correlated_pairs(names, U)[0][2], abs=1e-13)
    with pytest.raises(ValueError, match="sample size n"):
        correlated_pairs(names, rho=rho)
