"""Global sensitivity (SALib) against analytic references.

* Sobol: Ishigami (a=7, b=0.1) and the Sobol G function (a = 0, 1, 4.5, 9, 99, 99)
  have closed-form S1, ST (and S13); estimates must lie within their own 95 % CIs;
* Morris: the exact mean |elementary effect| over the whole 4-level grid
  (enumerated), within the bootstrap CI (99.7 %: three indices on a lumpy EE
  population, see the test); exact for a linear model on uniform factors;
* linear model: first-order Sobol (and eFAST, RBD-FAST) = normalised squared
  sensitivities (S_i σ_i)² / Σ, whatever each factor's distribution;
* delta on correlated normal inputs against δ computed by quadrature.
"""
import itertools
import math

import numpy as np
import pytest
from scipy import stats

from rvtol.distributions import coverage
from rvtol.errors import InputError
from rvtol.model import FunctionModel, LinearModel, Quantity
from rvtol.sampling import sample
from rvtol.sensitivity import delta, design_to_factors, fast, morris, rbd_fast, sobol
from rvtol.spec import spec_from_table

from gsa_reference import (G_A, G_MODEL, G_SPEC, ISH, ISH_SPEC, g_function, g_indices, ishigami, ishigami_indices,
                           linear_case)


def _within(est, true, conf, scale=1.0):
    """|estimate − truth| within the CI half-width (plus float round-off)."""
    return np.abs(np.asarray(est) - true) <= np.asarray(conf) + 1e-9 * scale


# --------------------------------------------------------------------------- Sobol
def test_sobol_ishigami_first_total_and_second_order_within_ci():
    S1, ST, S13 = ishigami_indices()
    res = sobol(ISH, ISH_SPEC, n=4096, seed=20261121)
    d = res.frame
    assert res.n_evaluations == 4096 * (2 * 3 + 2)
    assert _within(d["S1"], S1, d["S1_conf"]).all(), d
    assert _within(d["ST"], ST, d["ST_conf"]).all(), d
    s2 = res.second_order.set_index(["factor_i", "factor_j"])
    assert _within(s2.loc[("x1", "x3"), "S2"], S13, s2.loc[("x1", "x3"), "S2_conf"])
    for pair in [("x1", "x2"), ("x2", "x3")]:
        assert _within(s2.loc[pair, "S2"], 0.0, s2.loc[pair, "S2_conf"])
    # the CIs are informative, not huge
    assert d["S1_conf"].max() < 0.1 and d["ST_conf"].max() < 0.1


def test_sobol_g_function_within_ci():
    S1, ST = g_indices()
    d = sobol(G_MODEL, G_SPEC, n=4096, second_order=False, seed=7).frame
    assert _within(d["S1"], S1, d["S1_conf"]).all(), d
    assert _within(d["ST"], ST, d["ST_conf"]).all(), d
    assert list(d.sort_values("ST", ascending=False)["factor"][:4]) == ["g0", "g1", "g2", "g3"]


def test_linear_model_first_order_sobol_equals_normalised_squared_sensitivities():
    model, spec, share = linear_case()
    d = sobol(model, spec, n=2048, second_order=False, seed=3).frame
    assert _within(d["S1"], share, d["S1_conf"]).all(), d
    assert _within(d["ST"], share, d["ST_conf"]).all(), d
    assert d.set_index("factor").loc["s", "ST"] == pytest.approx(0.0, abs=1e-12)


def test_linear_model_fast_and_rbd_fast_first_order():
    model, spec, share = linear_case()
    # eFAST: its bootstrap CIs are flagged unreliable by SALib (kept as a note), so the check uses a fixed
    # tolerance of 0.02: the interference error of eFAST at n = 1025 per factor with M = 4 is < 1 %.
    e = fast(model, spec, n=1025, seed=3)
    assert np.allclose(e.frame["S1"], share, atol=0.02), e.frame
    assert any("unreliable" in n for n in e.notes)
    # RBD-FAST on a given LHS sample (the Monte Carlo path): within its CI
    s = sample(spec, 4096, "lhs", 11)
    Y = model.outputs[0].to_display(model.evaluate(s.values))
    r = rbd_fast(model, spec, samples=s, Y=Y, seed=3)
    assert r.n_evaluations == 0
    assert _within(r.frame["S1"], share, r.frame["S1_conf"]).all(), r.frame


# --------------------------------------------------------------------------- Morris
def _morris_population_mu_star(f, mapping, k, levels=4):
    """Mean |EE| over every grid point where the factor can step up by Δ (the Morris EE population)."""
    grid = np.array(list(itertools.product(np.linspace(0.0, 1.0, levels), repeat=k)))
    step = levels / (2 * (levels - 1))
    out = []
    for i in range(k):
        u = grid[grid[:, i] + step <= 1 + 1e-12]
        u2 = u.copy()
        u2[:, i] += step
        out.append(np.mean(np.abs(f(mapping(u2))[:, 0] - f(mapping(u))[:, 0]) / step))
    return np.array(out)


def test_morris_ishigami_mu_star_within_ci():
    q = 0.5 * (1 - coverage(3.0))  # each factor's range: its ±3σ-equivalent probability band

    def mapping(u):
        return -math.pi + 2 * math.pi * (q + (1 - 2 * q) * u)

    exact = _morris_population_mu_star(ishigami, mapping, 3)
    # 99.7 % intervals: three comparisons on a population of only 32 distinct EEs per factor, where the
    # bootstrap interval of μ* is known to run narrow; the truth is exact (enumerated), the seed arbitrary.
    res = morris(ISH, ISH_SPEC, trajectories=100, seed=12345, confidence=0.997)
    d = res.frame
    assert res.n_evaluations == 100 * 4
    assert _within(d["mu_star"], exact, d["mu_star_conf"], scale=10).all(), (d, exact)
    assert d.set_index("factor").loc["x1", "mu"] > 0   # x1 acts through sin(x1): mean effect positive


def test_morris_g_function_mu_star_within_ci():
    spec = spec_from_table({"factor": [{"name": f"g{i}", "unit": "1", "dist": "uniform", "lower": 0, "upper": 1}
                                       for i in range(len(G_A))]})
    model = FunctionModel(g_function, spec.names, ["y"])
    q = 0.5 * (1 - coverage(3.0))
    exact = _morris_population_mu_star(g_function, lambda u: q + (1 - 2 * q) * u, len(G_A))
    d = morris(model, spec, trajectories=100, seed=12345, confidence=0.997).frame   # 99.7 %: as for Ishigami
    assert _within(d["mu_star"], exact, d["mu_star_conf"], scale=10).all(), (d, exact)
    assert list(d.sort_values("mu_star", ascending=False)["factor"][:4]) == ["g0", "g1", "g2", "g3"]


def test_morris_linear_model_is_exact():
    spec = spec_from_table({"factor": [{"name": n, "unit": "um", "dist": "uniform", "lower": 0.0, "upper": w}
                                       for n, w in (("a", 2.0), ("b", 5.0))]})
    c = np.array([[3.0, -1.5]])
    model = LinearModel(spec.names, ["mm", "mm"], [Quantity("y", "mm", "um")], c)
    d = morris(model, spec, trajectories=10, seed=1).frame.set_index("factor")
    q = 0.5 * (1 - coverage(3.0))
    for name, w, ci in (("a", 2.0, 3.0), ("b", 5.0, -1.5)):
        # EE = c·(range in µm)·(1 − 2q) per unit of probability; output in µm
        assert d.loc[name, "mu_star"] == pytest.approx(abs(ci) * w * (1 - 2 * q), rel=1e-9)
        assert d.loc[name, "sigma"] == pytest.approx(0.0, abs=1e-9)


# --------------------------------------------------------------------------- delta
def _delta_exact(c, mu, sd, R, i, nq=60):
    """δ_i = ½ E[∫|f_Y − f_Y|X_i| dy] for Y = c·X, X ~ N(mu, diag(sd) R diag(sd)).

    Gauss–Hermite over x_i (60 nodes) and a fine trapezoid over y (40 001 points over ±12 σ_Y).
    """
    S = R * np.outer(sd, sd)
    vy, my, cov = c @ S @ c, c @ mu, c @ S[:, i]
    vc = vy - cov**2 / S[i, i]
    z, w = np.polynomial.hermite_e.hermegauss(nq)
    w = w / w.sum()
    y = np.linspace(my - 12 * math.sqrt(vy), my + 12 * math.sqrt(vy), 40001)
    m = my + cov / sd[i] * z
    diff = np.abs(stats.norm.pdf(y, my, math.sqrt(vy))[None, :] - stats.norm.pdf(y[None, :], m[:, None], math.sqrt(vc)))
    return 0.5 * float(w @ np.trapezoid(diff, y, axis=1))


def test_delta_with_correlated_inputs_against_quadrature():
    c, mu, sd, rho = np.array([1.0, -2.0, 0.5]), np.array([3.0, 0.0, 1.0]), np.array([1.0, 0.5, 2.0]), 0.6
    R = np.eye(3)
    R[0, 1] = R[1, 0] = rho
    spec = spec_from_table({"factor": [{"name": n, "unit": "mm", "dist": "normal", "mean": m, "sigma": s}
                                       for n, m, s in zip("pqr", mu, sd)],
                            "correlation": [{"pair": ["p", "q"], "rho": rho}]})
    model = LinearModel(spec.names, ["mm"] * 3, [Quantity("y", "mm")], [c])
    exact = np.array([_delta_exact(c, mu, sd, R, i) for i in range(3)])
    d = delta(model, spec, n=4000, seed=5, num_resamples=20).frame
    # Plischke's kernel estimator at n = 4000, measured over 20 seeds (10-29): bias +0.015, +0.013, −0.019 and
    # scatter σ 0.011, 0.011, 0.018 for p, q, r (max |error| 0.045), both larger than its bootstrap interval
    # (~0.01, sampling error only). Tolerance 0.04 absolute at this fixed seed (errors 0.008, 0.023, 0.011):
    # about bias + 1.5σ, so another seed may need a looser bound; the ranking check below is the robust one.
    assert np.allclose(d["delta"], exact, atol=0.04), (d, exact)
    assert list(d.sort_values("delta")["factor"])[-1] == "r"   # r drives the output; p, q cancel out


# --------------------------------------------------------------------------- plumbing
def test_design_maps_probabilities_through_each_factors_distribution():
    spec = spec_from_table({"factor": [
        {"name": "n", "unit": "um", "dist": "normal", "mean": 1.0, "tolerance": 6.0},
        {"name": "r", "unit": "um", "dist": "rayleigh", "tolerance": 12.0},
        {"name": "k", "unit": "mm", "dist": "normal", "mean": 5.0, "tolerance": 1.0}]})
    U = np.array([[0.5, 0.5], [0.975, 0.1]])
    X = design_to_factors(spec, [0, 1], U)
    assert X[0, 0] == pytest.approx(1e-3) and X[1, 0] == pytest.approx(1e-3 * (1 + stats.norm.ppf(0.975)))
    assert X[1, 1] == pytest.approx(1e-3 * spec.factor("r").dist.ppf(0.1))
    assert np.all(X[:, 2] == 5.0)   # not analysed: nominal


def test_failed_and_constant_outputs_are_reported_not_hidden():
    from rvtol.testing import FlakyModel

    spec = spec_from_table({"factor": [{"name": n, "unit": "mm", "dist": "normal", "mean": 0.0, "sigma": 1.0}
                                       for n in ("x0", "x1")]})
    res = sobol(FlakyModel(threshold=2.0), spec, n=64, seed=1, second_order=False)
    assert res.n_failed > 0 and res.frame["S1"].isna().all() and any("failed" in n for n in res.notes)
    const = FunctionModel(lambda X: np.zeros((len(X), 1)), spec.names, ["z"], input_units=["mm", "mm"])
    res2 = morris(const, spec, trajectories=4, seed=1)
    assert (res2.frame["mu_star"] == 0).all() and any("does not vary" in n for n in res2.notes)


def test_delta_is_the_same_on_any_executor():
    from rvtol.executors import make_executor

    model, spec, _ = linear_case()
    s = sample(spec, 1200, "random", 2)
    Y = model.outputs[0].to_display(model.evaluate(s.values))
    serial = delta(model, spec, samples=s, Y=Y, seed=9, num_resamples=10).frame
    with make_executor("process", 2) as ex:
        parallel = delta(model, spec, samples=s, Y=Y, seed=9, num_resamples=10, executor=ex).frame
    assert serial.equals(parallel)


def test_delta_of_one_factor_leaves_the_process_random_state_and_warnings_as_they_were():
    """δ runs through SALib's public analyze with its own seed; SALib (1.6) seeds NumPy's global generator and
    replaces the global warning formatter — both are restored.  A factor whose positive side is one bin (the
    step variant fails: analyze keeps δ, S1 is NaN) and a constant factor (NaN) as analyze gives them; the same
    seed gives the same numbers."""
    import warnings

    from rvtol.sensitivity.global_ import _delta_one

    rng = np.random.default_rng(3)
    X = rng.uniform(-np.pi, np.pi, (600, 2))
    y = np.sin(X[:, 0]) + 7 * np.sin(X[:, 1]) ** 2 + 0.1 * X[:, 1] ** 4 * np.sin(X[:, 0])
    np.random.seed(2024)
    before = np.random.get_state()[1].copy()
    fmt, filters = warnings.formatwarning, list(warnings.filters)
    a = _delta_one("a", X[:, 1], y, 12, 0.95, 12345)
    assert np.array_equal(np.random.get_state()[1], before)
    assert warnings.formatwarning is fmt and warnings.filters == filters
    assert a == _delta_one("a", X[:, 1], y, 12, 0.95, 12345)
    assert a != _delta_one("a", X[:, 1], y, 12, 0.95, 54321)
    assert 0.0 < a["delta"] < 1.0 and a["delta_conf"] > 0.0 and 0.0 < a["S1"] < 1.0
    one_bin = np.where(np.arange(600) < 300, -rng.uniform(0, 1, 600), rng.uniform(0.95, 1.0, 600))
    one_bin[300] = 1e-6
    got = _delta_one("a", one_bin, y, 12, 0.95, 7)
    assert np.isfinite(got["delta"]) and np.isnan(got["S1"])
    assert np.isnan(_delta_one("a", np.ones(600), y, 12, 0.95, 1)["delta"])


def test_delta_refuses_a_confidence_outside_0_1():
    model, spec, _ = linear_case()
    for c in (0.0, 1.0, 1.5):
        with pytest.raises(InputError, match="confidence"):
            delta(model, spec, n=200, seed=1, num_resamples=10, confidence=c)


def test_sobol_of_groups_matches_the_additive_closed_form():
    """Y = a + b + 2c + d·e (uniform [0, 1]): groups {a, b}, {c}, {d, e} have total indices in closed form."""
    from rvtol.model import FunctionModel, Quantity
    from rvtol.sensitivity.global_ import sobol
    from rvtol.spec import spec_from_table

    spec = spec_from_table({"factor": [{"name": n, "unit": "1", "dist": "uniform", "lower": 0, "upper": 1}
                                       for n in "abcde"]})
    model = FunctionModel(lambda X: X[:, 0] + X[:, 1] + 2 * X[:, 2] + X[:, 3] * X[:, 4], list("abcde"),
                          [Quantity("y")])
    v_ab, v_c = 2 / 12, 4 / 12
    v_de = (1 / 3) ** 2 - (1 / 4) ** 2          # Var(d·e) of independent uniforms
    V = v_ab + v_c + v_de
    res = sobol(model, spec, 2048, second_order=False, seed=3, groups=["ab", "ab", "c", "de", "de"])
    fr = res.for_output("y").set_index("factor")
    assert list(fr.index) == ["ab", "c", "de"] and res.n_evaluations == 2048 * 5
    for g, v in (("ab", v_ab), ("c", v_c), ("de", v_de)):
        assert abs(fr.loc[g, "ST"] - v / V) < max(3 * fr.loc[g, "ST_conf"], 0.02), g
        assert abs(fr.loc[g, "S1"] - v / V) < max(3 * fr.loc[g, "S1_conf"], 0.02), g
