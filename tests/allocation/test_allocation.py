"""Tolerance allocation: cost fits, convex optimum vs closed forms, GA vs convex, independent MC check."""
import math

from dataclasses import replace

import numpy as np
import pytest

from rvtol.models.adjustment import AdjustedAssemblyModel, load_assembly
from rvtol.allocation.baseline import uniform_baseline, verify
from rvtol.allocation.convex import solve_convex
from rvtol.allocation.cost import CostModel, fit_cost_model, load_costs
from rvtol.allocation.ga import GASettings, solve_ga
from rvtol.allocation.problem import (AllocationProblem, LinearisedConstraint, MonteCarloConstraint,
                                      expand_requirements, linearise)
from rvtol.distributions import Distribution
from rvtol.errors import InputError
from rvtol.model import LinearModel, Quantity
from rvtol.sampling import to_factors
from rvtol.spec import Factor, Requirement, ToleranceSpec, load_spec


# --------------------------------------------------------------------------- cost models
@pytest.mark.parametrize("kind,a,b,c", [("reciprocal_power", 1.2, 3.0, 1.4), ("reciprocal_power", 0.0, 2.0, 0.6),
                                        ("exponential", 0.8, 5.0, 0.9), ("exponential", 2.0, 40.0, 3.0)])
def test_cost_fit_recovers_known_parameters(kind, a, b, c):
    t = np.array([0.3, 0.5, 0.8, 1.2, 2.0, 3.0, 5.0])
    y = a + b * (t ** -c if kind == "reciprocal_power" else np.exp(-c * t))
    fa, fb, fc, rep = fit_cost_model(kind, t, y)
    assert (fa, fb, fc) == pytest.approx((a, b, c), rel=1e-6, abs=1e-8)
    assert rep.r2 == pytest.approx(1.0, abs=1e-10)


def test_cost_fit_with_fixed_exponent_is_linear_least_squares():
    t = np.array([0.5, 1.0, 2.0, 4.0])
    y = 0.7 + 2.2 / t + np.array([0.01, -0.02, 0.015, -0.005])
    fa, fb, fc, _ = fit_cost_model("reciprocal_power", t, y, fix_c=1.0)
    G = np.column_stack([np.ones_like(t), 1 / t])
    ref = np.linalg.lstsq(G, y, rcond=None)[0]
    assert (fa, fb, fc) == pytest.approx((ref[0], ref[1], 1.0), rel=1e-12)


def test_cost_data_file_loads(root):
    table = load_costs(root / "data/costs/bx40e_angular.toml")
    c = table["ground_axis"]
    assert c.c == 1.0 and c.b > 0 and c.fit.r2 > 0.99
    assert float(c(1.0)) == pytest.approx(c.a + c.b)


def _cost_file(tmp_path, curve: str):
    p = tmp_path / "c.toml"
    p.write_text('[costs]\nname = "x"\n\n[[curve]]\nname = "k"\nunit = "mrad"\n' + curve, encoding="utf-8")
    return p


@pytest.mark.parametrize("curve,key,reason", [
    ('kind = "quadratic"\na = 1\nb = 1\nc = 1\nbounds = [1, 2]', "curve[0].kind", "unknown value"),
    ('kind = "exponential"\na = 1\nb = 1\nc = 1', "curve[0].bounds", "missing required key"),
    ('kind = "exponential"\na = 1\nb = 1\nc = 1\nbounds = [2, 1]', "curve[0].bounds", "low < high"),
    ('kind = "exponential"\na = 1\nb = -1\nc = 1\nbounds = [1, 2]', "curve[0].b", "> 0"),
    ('kind = "exponential"\ndata = { tolerance = [1, 2, 3], cost = [3, 2] }', "curve[0].data.cost", "expected 3 costs"),
    ('kind = "exponential"\ndata = { tolerance = [1, 2, 3], cost = [3, 2, 1] }', "curve[0].data", "at least 4"),
    ('kind = "exponential"\ndata = { tolerance = [1, -2, 3, 4], cost = [4, 3, 2, 1] }',
     "curve[0].data.tolerance[1]", "> 0"),
    ('kind = "reciprocal_power"\nfix_c = 1\ndata = { tolerance = [1, 2, 3, 4], cost = [1, 2, 3, 4] }',
     "curve[0].data", "does not fall"),
    ('kind = "exponential"\na = 1\nb = 1\nc = 1\nbounds = [1, 2]\ndata = { tolerance = [1], cost = [1] }',
     "curve[0].data", "not both"),
    ('kind = "exponential"\na = 1\nb = 1\nc = 1\nbounds = [1, 2]\nfix = 1', "curve[0].fix", "unknown key"),
    ('kind = "exponential"\na = 1\nb = 1\nc = 1\nbounds = [1, 2]\nfix_c = 1', "curve[0].fix_c", "give data, or c"),
    ('kind = "exponential"\na = 1\nb = 1\nc = 1\nbounds = [1, 2, 3]', "curve[0].bounds", "expected 2 numbers"),
    ('kind = "exponential"\nb = 1\nc = 1\nbounds = [1, 2]', "curve[0].a", "missing required key"),
])
def test_bad_cost_file(tmp_path, curve, key, reason):
    p = _cost_file(tmp_path, curve)
    with pytest.raises(InputError) as ei:
        load_costs(p)
    assert ei.value.file == str(p)
    assert ei.value.key == key, (ei.value.key, ei.value.reason)
    assert reason in ei.value.reason


# --------------------------------------------------------------------------- a linear test problem
def linear_problem(k, b, limit=1.0, kind="reciprocal_power", min_cpk=1.0, t_range=(1e-3, 10.0)):
    """y = Σ k_i x_i, x_i normal with ±t_i = 3σ_i (spec: ±1), |y| ≤ limit, Cpk ≥ min_cpk."""
    names = [f"x{i}" for i in range(len(k))]
    spec = ToleranceSpec("lin", tuple(Factor(n, "mm", Distribution.make("normal", mean=0.0, sigma=1 / 3)) for n in names))
    model = LinearModel(names, ["mm"] * len(k), [Quantity("y", "mm")], [k])
    curves = [CostModel(f"c{i}", kind, 0.5, bi, 1.0, "mm", *t_range) for i, bi in enumerate(b)]
    reqs = expand_requirements([Requirement("y", -limit, limit, "mm", min_cpk=min_cpk, basis="estimate")], model)
    return AllocationProblem(model, spec, names, curves, reqs)


K = np.array([1.0, -2.0, 0.5, 3.0])
B = np.array([1.0, 4.0, 2.0, 0.5])


def test_convex_rss_matches_lagrange_closed_form():
    """C = a + b/t, Σ (k t)² ≤ L²: KKT b_i/t_i² = 2λ k_i² t_i  ⇒  t_i ∝ (b_i / k_i²)^(1/3)."""
    p = linear_problem(K, B, limit=1.0)
    res = solve_convex(p, LinearisedConstraint(p, linearise(p), "rss"))
    t = (B / K**2) ** (1 / 3)
    t *= 1.0 / math.sqrt(np.sum((K * t) ** 2))
    # interior point, duality gap closed to 1e-9: on a flat optimum t is good to ~sqrt(1e-9) = 3e-5
    np.testing.assert_allclose(res.t, t, rtol=5e-5)
    assert res.total_cost == pytest.approx(np.sum(0.5 + B / t), rel=1e-8)  # gap and feasibility 1e-9


def test_convex_worst_case_matches_lagrange_closed_form():
    """C = a + b/t, Σ |k| t ≤ L (t = ±3σ band): KKT b_i/t_i² = λ |k_i|  ⇒  t_i ∝ sqrt(b_i / |k_i|)."""
    p = linear_problem(K, B, limit=2.0)
    res = solve_convex(p, LinearisedConstraint(p, linearise(p), "worst_case"))
    t = np.sqrt(B / np.abs(K))
    t *= 2.0 / np.sum(np.abs(K) * t)
    np.testing.assert_allclose(res.t, t, rtol=5e-5)


def test_bounds_are_respected_and_infeasible_is_reported():
    p = linear_problem(K, B, limit=1.0, t_range=(0.2, 10.0))
    res = solve_convex(p, LinearisedConstraint(p, linearise(p), "rss"))
    assert res.feasible and np.all(res.t >= 0.2 - 1e-9)
    tight = linear_problem(K, B, limit=0.1, t_range=(0.2, 10.0))
    con = LinearisedConstraint(tight, linearise(tight), "rss")
    assert not solve_convex(tight, con).feasible
    assert not uniform_baseline(tight, con).feasible


@pytest.mark.parametrize("mode", ["rss", "worst_case"])
def test_nominal_output_outside_the_limits_is_infeasible(mode):
    """|y| ≤ L around y0 = 0 shifted to [0.5, 2]: the nominal output already fails, no tolerance can help."""
    p = linear_problem(K, B, limit=1.0)
    p = p.with_requirements([Requirement("y", 0.5, 2.0, "mm", min_cpk=1.0, basis="estimate")])
    con = LinearisedConstraint(p, linearise(p), mode)
    assert con.lin.margin[0] == pytest.approx(-0.5)
    assert np.all(con.violation(np.array([p.lower, p.t0])) > 0)
    assert not solve_convex(p, con).feasible
    assert not uniform_baseline(p, con).feasible


@pytest.mark.parametrize("lo, hi", [(0.5, 2.0), (-2.0, -0.5), (None, -0.5)])
def test_design_levers_shift_the_nominal_to_the_limit_by_hand(lo, hi):
    """y = Σ k_i x_i + 0.4 e (spec: normal, ±1 = 3σ; e Rayleigh) must lie in [lo, hi]: the nominal 0.1 fails, no
    tolerance helps. Each lever is the mean shift of one x_i alone that moves y0 to the missed limit ± z σ_y, z = 3 Cpk, σ_y² = Σ (k_i/3)²
    (hand computation of the linear model); a one-sided factor (an error magnitude) is not a lever."""
    from rvtol.allocation.problem import design_levers

    names = ["x0", "x1", "x2", "x3", "e"]
    k = list(K) + [0.4]
    dists = [Distribution.make("normal", mean=0.0, sigma=1 / 3)] * 4 + [Distribution.make("rayleigh", sigma=0.2)]
    spec = ToleranceSpec("lin", tuple(Factor(n, "mm", d) for n, d in zip(names, dists)))
    model = LinearModel(names, ["mm"] * 5, [Quantity("y", "mm")], [k])
    curves = [CostModel(f"c{i}", "reciprocal_power", 0.5, 1.0, 1.0, "mm", 1e-3, 10.0) for i in range(4)]
    reqs = expand_requirements([Requirement("y", lo, hi, "mm", min_cpk=1.0, basis="estimate")], model)
    p = AllocationProblem(model, spec, names[:4], curves, reqs)
    lin = linearise(p)
    con = LinearisedConstraint(p, lin, "rss")
    assert "NOMINAL design" in " ".join(con.binding())
    frame = next(iter(design_levers(p, lin).values()))
    y0 = 0.4 * spec.factor("e").dist.mean                # 0.1 mm: below the lower limit
    sigma = math.sqrt(sum((ki * d.std) ** 2 for ki, d in zip(k, dists)))
    need = (lo + 3.0 * sigma if lo is not None and y0 <= lo else hi - 3.0 * sigma) - y0
    got = dict(zip(frame["lever (mean shift of)"], frame["shift needed alone"]))
    assert set(got) == {"x0", "x1", "x2", "x3"}
    for i in range(4):
        assert got[f"x{i}"] == pytest.approx(need / K[i], rel=1e-6)
    assert list(frame["lever (mean shift of)"]) == [f"x{i}" for i in np.argsort(-np.abs(K))]


def test_uniform_baseline_is_the_largest_common_scale():
    p = linear_problem(K, B, limit=1.0)
    res = uniform_baseline(p, LinearisedConstraint(p, linearise(p), "rss"))
    s = 1.0 / math.sqrt(np.sum((K * p.t0) ** 2))  # Σ (k s t0)² = L²
    np.testing.assert_allclose(res.t, s * p.t0, rtol=1e-9)


def test_linearised_sigma_is_exact_for_a_linear_model():
    p = linear_problem(K, B, limit=1.0)
    con = LinearisedConstraint(p, linearise(p), "rss")
    t = np.array([0.1, 0.2, 0.3, 0.05])
    sigma = math.sqrt(np.sum((K * t / 3) ** 2))
    assert con.load(t)[0, 0] == pytest.approx((3 * sigma) ** 2 / 1.0, rel=1e-9)


@pytest.mark.parametrize("dist", [
    Distribution.make("normal", mean=0.3, sigma=0.2), Distribution.make("uniform", lower=-0.1, upper=0.5),
    Distribution.make("triangular", lower=0.0, mode=0.1, upper=0.5),
    Distribution.make("truncnorm", mean=0.0, sigma=0.2, lower=-0.4, upper=0.5),
    Distribution.make("rayleigh", sigma=0.1, shift=0.05), Distribution.make("lognormal", median=0.2, shape=0.4),
    Distribution.make("weibull", shape=1.7, scale=0.3)])
def test_monte_carlo_constraint_scales_like_the_spine(dist):
    """The affine fast path equals ``spec.scaled`` + ``to_factors`` for every distribution kind."""
    spec = ToleranceSpec("s", (Factor("a", "um", dist), Factor("b", "um", Distribution.make("normal", mean=0.0, sigma=1.0))))
    model = LinearModel(["a", "b"], ["mm", "mm"], [Quantity("y", "mm")], [[1.0, 1.0]])
    req = expand_requirements([Requirement("y", None, 1.0, "mm", min_yield=0.9)], model)
    p = AllocationProblem(model, spec, ["a"], [CostModel("c", "exponential", 0, 1, 1, "um", 0.01, 10)], req)
    mc = MonteCarloConstraint(p, 500, "random", 3)
    assert not np.isnan(mc.centre[0])
    for f in (0.3, 1.0, 2.7):
        t = p.t0 * f
        np.testing.assert_allclose(mc.samples(t), to_factors(p.spec_at(t), mc.U), rtol=1e-12, atol=1e-15)


def test_monte_carlo_constraint_outputs_built_in_workers_equal_the_samples_evaluated():
    """The candidates' outputs built from chunks of the design (in the workers of a process pool, or in-process)
    are bit for bit the model evaluated on :meth:`MonteCarloConstraint.samples` (the reference path); a repeated
    candidate is answered without a new evaluation and still counts its rows."""
    from rvtol.executors import make_executor
    from rvtol.mc import Evaluator, evaluate

    p = linear_problem(K, B, limit=1.0)
    T = p.t0[None, :] * np.array([[0.3], [1.0], [0.3], [2.2]])
    ref = [evaluate(p.model, MonteCarloConstraint(p, 700, "lhs", 4).samples(t), progress=False).Y for t in T]
    with make_executor("process", 2) as ex:
        for ev in (None, Evaluator(), Evaluator(ex, chunk_size=100)):
            mc = MonteCarloConstraint(p, 700, "lhs", 4, ev)
            got = mc.outputs(T)
            assert mc.evaluations == 4 * 700
            # only the outputs the requirements judge come back
            assert mc.columns.tolist() == sorted({p.model.output_index(r.output) for r in p.requirements})
            for g, r in zip(got, ref):
                np.testing.assert_array_equal(g, r[:, mc.columns])
            assert got[0] is got[2]            # the repeated candidate: one evaluation
            later = mc.outputs(T[:2] * 1.1)    # a later batch: the workers keep the design's chunks
            for g, t in zip(later, T[:2] * 1.1):
                np.testing.assert_array_equal(g, evaluate(p.model, mc.samples(t), progress=False).Y[:, mc.columns])


def test_pattern_requirements_expand_and_unknown_pattern_fails():
    model = LinearModel(["a"], ["mm"], [Quantity("d_1", "mm"), Quantity("d_2", "mm"), Quantity("e", "mm")],
                        [[1.0], [2.0], [3.0]])
    out = expand_requirements([Requirement("d_*", -1.0, 1.0, "mm", min_cpk=1.0)], model)
    assert [r.output for r in out] == ["d_1", "d_2"]
    with pytest.raises(InputError, match="matches no output"):
        expand_requirements([Requirement("q_*", -1.0, 1.0, "mm")], model)


@pytest.mark.parametrize("interval,method", [("clopper-pearson", "exact"), ("wilson", "wilson")])
def test_monte_carlo_yield_bound_uses_the_requirements_interval(interval, method):
    from rvtol.stats import proportion_ci

    p = linear_problem(K, B, limit=1.0)
    req = expand_requirements([Requirement("y", -1.0, 1.0, "mm", min_yield=0.99, interval=interval)], p.model)
    mc = MonteCarloConstraint(p.with_requirements(req), 400, "random", 5)
    m = mc.measures(p.t0[None, :] * 0.3)[0][0]
    k = round(m["yield"] * 400)
    assert 0 < k < 400
    # the sign-off's bound (one-sided 95 % by default) = the lower end of SciPy's two-sided 90 % interval
    assert m["yield_lo"] == pytest.approx(proportion_ci(k, 400, 0.90, method)[0], rel=1e-10)
    two = p.with_requirements([replace(req[0], bound="two-sided")])
    m2 = MonteCarloConstraint(two, 400, "random", 5).measures(p.t0[None, :] * 0.3)[0][0]
    assert m2["yield_lo"] == pytest.approx(proportion_ci(k, 400, 0.95, method)[0], rel=1e-10)


class FailsAwayFromZero(LinearModel):
    """y = Σ x_i, but no value where x1 ≠ 0: the five-point stencil of x1 fails, the nominal does not."""

    def evaluate(self, X):
        Y = super().evaluate(X)
        Y[X[:, 1] != 0.0] = np.nan
        return Y


@pytest.mark.parametrize("mode", ["rss", "worst_case"])
def test_a_factor_without_gradient_makes_the_linearisation_unavailable(mode):
    """A NaN derivative is not a zero one: the constraint must not treat the factor as harmless."""
    p = linear_problem(K, B, limit=1.0)
    p = AllocationProblem(FailsAwayFromZero(p.model.inputs, p.model.input_units, p.model.outputs, [K]),
                          p.spec, p.factors, p.curves, p.requirements)
    con = LinearisedConstraint(p, linearise(p), mode)
    assert con.unavailable == ["x1"]
    assert np.all(con.violation(np.array([p.lower, p.t0])) > 0)
    res = solve_convex(p, con)
    assert not res.feasible and "x1" in " ".join(res.notes)


def abs_square(X):
    return np.abs(X[:, 0]) + X[:, 1] ** 2


# --------------------------------------------------------------------------- BX40E: GA vs convex, MC check
@pytest.fixture(scope="module")
def bx40e_3d(request):
    root = request.config.rootpath
    spec = load_spec(root / "data/specs/bx40e_assembly_3d.toml")
    model = AdjustedAssemblyModel(load_assembly(root / "data/assemblies/bx40e_3d.toml"), spec.names)
    curve = load_costs(root / "data/costs/bx40e_angular.toml")["ground_axis"]
    names = [n for n in spec.names if n.startswith("dtheta")]
    reqs = expand_requirements([Requirement("delta_*", -1.0, 1.0, "arcmin", min_cpk=1.0, basis="estimate")], model)
    return AllocationProblem(model, spec, names, [curve] * len(names), reqs)


def test_ga_lands_within_two_percent_of_the_convex_optimum(bx40e_3d):
    p = bx40e_3d
    con = LinearisedConstraint(p, linearise(p), "rss")
    cv = solve_convex(p, con)
    ga = solve_ga(p, con, GASettings(population=60, generations=200, parents=30, seed=20020402))
    assert cv.feasible and ga.feasible
    gap = ga.total_cost / cv.total_cost - 1.0
    assert -1e-6 <= gap <= 0.02, gap
    again = solve_ga(p, con, GASettings(population=60, generations=200, parents=30, seed=20020402))
    np.testing.assert_array_equal(again.t, ga.t)  # seeded: reproducible to the bit


def test_penalty_handling_also_reaches_the_convex_optimum():
    """Penalty rules (fitness −(cost + μ·violation)); the result is the best candidate that meets the constraint."""
    p = linear_problem(K, B, limit=1.0)
    con = LinearisedConstraint(p, linearise(p), "rss")
    cv = solve_convex(p, con)
    ga = solve_ga(p, con, GASettings(population=30, generations=80, parents=15, handling="penalty", seed=1))
    assert ga.feasible and con.violation(ga.t)[0] == 0.0
    assert -1e-6 <= ga.total_cost / cv.total_cost - 1.0 <= 0.02


def test_ga_allocation_on_monte_carlo_cpk_holds_in_an_independent_run(root):
    spec = load_spec(root / "data/specs/bx40e_assembly_2d.toml")
    model = AdjustedAssemblyModel(load_assembly(root / "data/assemblies/bx40e_2d.toml"), spec.names)
    curve = load_costs(root / "data/costs/bx40e_angular.toml")["ground_axis"]
    names = [f"dtheta_{i}" for i in range(1, 5)]
    reqs = expand_requirements([Requirement("delta_*", -1.0, 1.0, "arcmin", min_cpk=1.0)], model)  # lower bound
    p = AllocationProblem(model, spec, names, [curve] * 4, reqs)
    res = solve_ga(p, MonteCarloConstraint(p, 1000, "lhs", 11), GASettings(population=24, generations=40,
                                                                               parents=12, seed=5))
    assert res.feasible
    # exact Cpk of the linear adjusted assembly at the allocated tolerances (normal inputs)
    M_w, M_v = model.adjuster.linear_map()
    sig = p.spec_at(res.t).std_base()
    sw = np.array([sig[spec.index(n)] for n in model.w_names])
    sv = np.array([sig[spec.index(n)] for n in model.v_names])
    sigma_out = np.sqrt((M_w * sw) ** 2 @ np.ones(4) + (M_v * sv) ** 2 @ np.ones(4))
    limit = math.pi / 10800.0
    assert np.all(limit / (3 * sigma_out) >= 1.0)
    check = verify(res, 20000, 987)
    assert check.passed, check.frame


def test_ga_respects_the_requirement_it_was_given_on_a_nonlinear_model():
    """Any Model: y = |x0| + x1² (not linear) with a yield constraint; the GA solution meets it in a fresh run."""
    from rvtol.model import FunctionModel

    spec = ToleranceSpec("n", (Factor("x0", "mm", Distribution.make("normal", mean=0.0, sigma=0.1)),
                               Factor("x1", "mm", Distribution.make("uniform", lower=-0.5, upper=0.5))))
    model = FunctionModel(abs_square, ["x0", "x1"], [Quantity("y", "mm")], ["mm", "mm"])
    reqs = expand_requirements([Requirement("y", None, 0.2, "mm", min_yield=0.99, basis="estimate")], model)
    curves = [CostModel("c", "reciprocal_power", 0.0, 1.0, 1.0, "mm", 0.01, 1.0)] * 2
    p = AllocationProblem(model, spec, ["x0", "x1"], curves, reqs)
    res = solve_ga(p, MonteCarloConstraint(p, 4000, "lhs", 2), GASettings(population=20, generations=30,
                                                                              parents=10, seed=9))
    assert res.feasible
    check = verify(res, 40000, 77)
    # the GA sits on the boundary of the estimate: allow the binomial noise of both samples (3 σ)
    y = check.frame["yield"].iloc[0]
    assert y >= 0.99 - 3 * math.sqrt(0.99 * 0.01 * (1 / 4000 + 1 / 40000))


def test_tied_factors_share_one_tolerance_at_the_lagrange_optimum():
    """x0 and x1 tied (one drawing callout, equal spec tolerances): with t0 = t1 = τ the problem is one variable
    of cost b0 + b1 over τ and RSS weight k0² + k1², so KKT gives τ ∝ ((b0 + b1)/(k0² + k1²))^(1/3) beside
    t_i ∝ (b_i/k_i²)^(1/3) of the others, scaled onto Σ (k t)² = L². The GA's genes are the free tolerances only."""
    p = linear_problem(K, B, limit=1.0)
    p = replace(p, ties=(("x0", "x1"),))
    assert list(p.free) == [0, 2, 3]
    res = solve_convex(p, LinearisedConstraint(p, linearise(p), "rss"))
    tau = ((B[0] + B[1]) / (K[0] ** 2 + K[1] ** 2)) ** (1 / 3)
    t = np.array([tau, tau, *((B[2:] / K[2:] ** 2) ** (1 / 3))])
    t *= 1.0 / math.sqrt(np.sum((K * t) ** 2))
    np.testing.assert_allclose(res.t, t, rtol=5e-5)
    ga = solve_ga(p, LinearisedConstraint(p, linearise(p), "rss"), GASettings(population=30, generations=80,
                                                                               parents=15, seed=1))
    assert ga.feasible and ga.t[0] == ga.t[1]
    assert -1e-6 <= ga.total_cost / res.total_cost - 1.0 <= 0.02


def test_drawing_ties_group_the_coordinates_and_copies_of_one_callout():
    from rvtol.allocation.allocate import drawing_ties

    unit = Distribution.make("normal", mean=0.0, sigma=1.0)
    fs = (Factor("hole.position.x1", "um", unit), Factor("hole.position.y1", "um", unit),
          Factor("pins[1].d", "um", unit, part="pins", feature="pin diameter", family="pins[k].d"),
          Factor("pins[2].d", "um", unit, part="pins", feature="pin diameter", family="pins[k].d"),
          Factor("lone", "um", unit))
    spec = ToleranceSpec("t", fs)
    assert drawing_ties(spec, list(spec.names)) == (("hole.position.x1", "hole.position.y1"), ("pins[1].d", "pins[2].d"))
    assert drawing_ties(spec, ["hole.position.x1", "lone"]) == ()


def test_ga_confirmation_returns_the_cheapest_candidate_that_a_fresh_sample_also_accepts():
    """The same design as confirmation changes nothing (rank 1 = the unconfirmed best, bit for bit); a fresh
    design returns a candidate feasible on both samples and never cheaper than the unconfirmed best."""
    p = linear_problem(K, B, limit=1.0)
    con = MonteCarloConstraint(p, 400, "lhs", 11)
    settings = GASettings(population=16, generations=15, parents=8, seed=2)
    plain = solve_ga(p, con, settings)
    same = solve_ga(p, con, settings, confirm=MonteCarloConstraint(p, 400, "lhs", 11))
    np.testing.assert_array_equal(same.t, plain.t)
    assert "rank 1 by cost" in same.notes[0]
    fresh = MonteCarloConstraint(p, 400, "lhs", 12)
    res = solve_ga(p, con, settings, confirm=fresh)
    assert res.feasible and con.violation(res.t[None, :])[0] <= 0 and fresh.violation(res.t[None, :])[0] <= 0
    assert res.total_cost >= plain.total_cost
