"""Two sub-ppm tails with closed forms, by every OpenTURNS method; disagreements flagged, the reference right.

Radius of a centred position deviation: x, y ~ N(0, σ) independent, r = √(x² + y²) is Rayleigh,
P(r > L) = exp(−L²/(2σ²)) (the χ distribution with 2 degrees of freedom); L = σ√(2 ln 2·10⁶) gives
exactly 0.50 ppm.  Every direction of u-space fails alike (a circle of design points): FORM sees one
point (Φ(−β) = 0.036 ppm, 14× too low), SORM's Breitung formula is undefined (curvature −1/β),
importance sampling about one point misses the rest of the circle while its standard error says
nothing; directional sampling is exact for a domain outside a sphere, subset simulation unbiased.

Uniform + triangular stack: u ~ U(−c, c), t ~ Tri(−c, 0, c) (mode 0), y = u + t ≤ 2c.  Near the top,
with v = c − u ∈ [0, 2c] (density 1/(2c)) and w = c − t ∈ [0, c] (density w/c²),
P(y > 2c − s) = ∫₀ˢ (w/c²)(s − w)/(2c) dw = (s/c)³/12 for s ≤ c.  With c = 0.1 mm and the limit
0.1979 mm (s/c = 0.021): 0.021³/12 = 0.77175 ppm.  FORM linearises a limit state curved by the two
bounded margins' transforms (2.1 ppm); SORM, importance sampling, subset and directional sampling hold
the exact value."""
import math

import numpy as np

import pytest
from scipy import stats

from rvtol.distributions import Distribution
from rvtol.model import LinearModel, Quantity
from rvtol.models.formula.model import FormulaModel
from rvtol.spec import Factor, ToleranceSpec
from rvtol.stacking import tail_probability
from rvtol.stacking.tail import APPROXIMATIONS

SIGMA = 0.01
L_RADIUS = SIGMA * math.sqrt(2 * math.log(2e6))
C, L_CONV = 0.1, 0.1979


def radius_case():
    spec = ToleranceSpec("r", tuple(Factor(n, "mm", Distribution.make("normal", mean=0.0, sigma=SIGMA)) for n in "xy"))
    return spec, FormulaModel.from_spec(spec, {"r": ("hypot(x, y)", "mm")})


def convolution_case():
    spec = ToleranceSpec("c", (Factor("u", "mm", Distribution.make("uniform", lower=-C, upper=C)),
                               Factor("t", "mm", Distribution.make("triangular", lower=-C, upper=C, mode=0.0))))
    return spec, LinearModel(spec.names, ["mm", "mm"], [Quantity("y", "mm")], [[1.0, 1.0]])


def test_the_radius_tail():
    exact = math.exp(-L_RADIUS ** 2 / (2 * SIGMA ** 2))
    assert exact == pytest.approx(0.5e-6, rel=1e-12)
    spec, m = radius_case()
    est = tail_probability(m, spec, "r", L_RADIUS, "upper", seed=3)
    # FORM finds a point of the circle (the kink at the origin does not stop it): β = L/σ, Φ(−β) far too low
    assert est.beta == pytest.approx(L_RADIUS / SIGMA, rel=1e-5) and est.pf_form < 0.1 * exact
    assert est.get("SORM").pf is None or abs(est.get("SORM").pf - exact) > 0.5 * exact   # undefined / wrong
    for name in ("subset", "directional"):
        e = est.get(name)
        assert abs(e.pf - exact) < 4 * e.se + 1e-9 * exact, (name, e.pf, e.se)
    assert est.reference == "directional" and est.pf_reference == pytest.approx(exact, rel=1e-3)
    # importance sampling about one design point: low, and flagged against the global samplers; FORM flagged too
    imp = est.get("importance sampling")
    assert imp.pf < 0.5 * exact
    assert any(d.startswith("importance sampling") and "directional" in d for d in est.disagreements)
    assert any(d.startswith("FORM") for d in est.disagreements)


def test_the_uniform_plus_triangular_tail():
    exact = ((2 * C - L_CONV) / C) ** 3 / 12
    assert 1e6 * exact == pytest.approx(0.77175, rel=1e-6)
    spec, m = convolution_case()
    est = tail_probability(m, spec, "y", L_CONV, "upper", seed=3)
    assert est.pf_form > 2 * exact and any(d.startswith("FORM") for d in est.disagreements)
    assert est.get("SORM").pf == pytest.approx(exact, rel=0.05)
    for name in ("importance sampling", "subset", "directional"):
        e = est.get(name)
        assert abs(e.pf - exact) < 4 * e.se, (name, e.pf, e.se)
    ref = est.get(est.reference)
    assert est.reference not in APPROXIMATIONS and abs(ref.pf - exact) < 4 * ref.se


# ----------------------------------------------------------------------------- estimates that are no estimates
def linear_normals(k=2):
    spec = ToleranceSpec("n", tuple(Factor(f"x{i}", "mm", Distribution.make("normal", mean=0.0, sigma=1.0))
                                    for i in range(k)))
    return spec, LinearModel(spec.names, ["mm"] * k, [Quantity("y", "mm")], [[1.0] * k])


def test_an_estimate_without_a_meaning_is_not_shown_as_a_number():
    """y = x₁ + x₂ of standard normals beyond 9√2 (β = 9, P = Φ(−9) = 1.1e-19, FORM exact): OpenTURNS' directional
    sampling finds no root within its search distance and returns 0 ± −1 (shown as "0 ± −1e+06 ppm"), subset
    simulation with 100 samples per level 6.5e-28 ± 1.8e-27 (c.o.v. 2.8) — which then became the reference and
    flagged the exact FORM.  Both are now "not estimated: …" and out of every comparison."""
    spec, m = linear_normals()
    est = tail_probability(m, spec, "y", 9.0 * math.sqrt(2), "upper", seed=1, samples=100,
                           methods=("FORM", "subset", "directional"))
    for name, why in (("directional", "standard error is undefined"), ("subset", "coefficient of variation")):
        e = est.get(name)
        assert e.pf is None and e.se is None and e.note.startswith("not estimated:") and why in e.note, e
        assert e.to_dict()["ppm"] is None
    assert est.reference == "FORM" and est.disagreements == []
    assert est.pf_form == pytest.approx(stats.norm.sf(9.0), rel=1e-6)


def test_not_estimated_rules():
    """The rules one by one, on the estimates themselves (module docstring of rvtol.stacking.tail)."""
    from rvtol.stacking.tail import MAX_COV, Estimate, _not_an_estimate

    assert MAX_COV == pytest.approx(1 / 3)
    ok = lambda e: _not_an_estimate(e, 2, 5.0) is None  # noqa: E731
    assert ok(Estimate("subset", 1e-6, 0.3e-6)) and not ok(Estimate("subset", 1e-6, 0.34e-6))   # c.o.v. 1/3
    assert not ok(Estimate("directional", 0.0, -1.0)) and not ok(Estimate("directional", 1e-6, math.nan))
    assert not ok(Estimate("subset", 0.0, 0.0))                        # no failure seen: a bound, not an estimate
    assert not ok(Estimate("importance sampling", 1e-6, 0.0))           # degenerate weights
    assert not ok(Estimate("importance sampling", 1.5, 0.1))            # not a probability
    assert ok(Estimate("FORM", 0.0)) and ok(Estimate("FORM", stats.norm.sf(5.0)))
    # SORM / multi-FORM above P(χ²₂ > β²) = exp(−β²/2): more than the whole space beyond the sphere of radius β
    ball = math.exp(-12.5)
    assert ok(Estimate("SORM", 0.99 * ball)) and not ok(Estimate("SORM", 1.01 * ball))
    assert not ok(Estimate("multi-FORM", 1.01 * math.exp(-8.0), beta=4.0)) and ok(Estimate("multi-FORM", 1e-9, beta=4.0))


def test_sorm_of_a_circle_of_design_points_is_not_estimated():
    """The radius tail (a curvature −1/β at u*): Breitung's formula returned 15 ppm where the whole space beyond the
    sphere of radius β holds 0.5 ppm."""
    spec, m = radius_case()
    est = tail_probability(m, spec, "r", L_RADIUS, "upper", seed=3, methods=("FORM", "SORM"))
    s = est.get("SORM")
    assert s.pf is None and s.note.startswith("not estimated:"), s


def test_failed_evaluations_count_as_failures_in_the_tails():
    """A model that cannot be evaluated where x₁ > 3 (standard normals), its values never beyond the limit 100: the
    probability of a failure (failed evaluations count, as in the yield) is Φ(−3) = 1.35e-3."""
    from rvtol.mc import run_monte_carlo
    from rvtol.model import FunctionModel
    from rvtol.spec import Requirement
    from rvtol.stacking.beside_monte_carlo import tail_probabilities

    spec, _ = linear_normals()
    m = FunctionModel(lambda X: np.where(X[:, 0] > 3.0, np.nan, X[:, 0] + 0.0 * X[:, 1])[:, None], spec.names,
                      [Quantity("y", "mm")], ["mm", "mm"])
    exact = stats.norm.sf(3.0)
    est = tail_probability(m, spec, "y", 100.0, "upper", seed=1, samples=1000, methods=("subset", "directional"))
    for name in ("subset", "directional"):
        e = est.get(name)
        assert e.pf is not None and abs(e.pf - exact) < 4 * e.se, (name, e.pf, e.se)
    assert est.failed_samples > 0 and any("count as failures" in n for n in est.notes)
    # the Monte Carlo's count beside them counts them too
    mc = run_monte_carlo(m, spec, 4000, "random", 5, requirements=[Requirement("y", upper=100.0)], progress=False)
    t = tail_probabilities(m, spec, mc, ["y"], None, samples=0, methods=("FORM",)).limits[0]
    assert t.k == int((mc.samples.values[:, 0] > 3.0).sum()) > 0


def test_the_out_of_reach_test_takes_the_supports_ends():
    """Two U(−1, 1), y = x₁ + x₂: P(y > 1.9999) = (0.0001/2)²/2 = 1.25e-9 is reachable only within 1e-4 of the
    supports' ends (normal scores beyond 3.7); FORM finds no point there, and that is what it must say — not
    "out of reach, P = 0", which a box of corners at ±3 (x = ±0.9973) would conclude (beyond the worst case: out of
    reach, ``tests/stacking/test_stacking.py``)."""
    from rvtol.stacking.tail import REACH

    assert stats.norm.sf(REACH) < 1e-16
    spec = ToleranceSpec("u", tuple(Factor(n, "mm", Distribution.make("uniform", lower=-1.0, upper=1.0)) for n in "ab"))
    m = LinearModel(spec.names, ["mm"] * 2, [Quantity("y", "mm")], [[1.0, 1.0]])
    near = tail_probability(m, spec, "y", 1.9999, "upper", methods=("FORM",))
    assert near.beta != math.inf and near.pf_form != 0.0 and "out of reach" not in near.get("FORM").note


# ----------------------------------------------------------------------------- the comparison, by hand
def tail_of(*estimates):
    from rvtol.stacking.tail import Estimate, TailEstimate, _compare

    est = TailEstimate("y", "mm", "upper", 1.0, [Estimate(m, pf, se) for m, pf, se in estimates])
    _compare(est)
    return est


def test_disagreeing_estimates_are_listed_once_each_and_the_suspect_left_out():
    """Importance sampling 1 ppm against subset 2 ppm and directional 2.1 ppm: both differences exceed three combined
    standard errors (1 > 3·√(0.0235² + 0.235²) = 0.71, 1.1 > 3·√(0.0235² + 0.1²) = 0.31), subset and directional
    agree (0.1 < 3·√(0.235² + 0.1²) = 0.77).  Importance sampling is the suspect; of the two others directional has
    the smaller c.o.v. (0.048 against 0.12): the reference.  FORM 2.05 ppm lies within 3 × 0.1 ppm of it, SORM 3 ppm
    outside.  Each pair is compared once; the messages in ppm, standard errors to two digits (0.02349998 ppm →
    0.023, just below the rounding point 0.0235)."""
    est = tail_of(("FORM", 2.05e-6, None), ("SORM", 3.0e-6, None), ("importance sampling", 1.0e-6, 0.02349998e-6),
                  ("subset", 2.0e-6, 0.235e-6), ("directional", 2.1e-6, 0.1e-6))
    assert est.reference == "directional" and est.pf_reference == 2.1e-6
    assert est.disagreements == [
        "importance sampling 1 ± 0.023 ppm and subset 2 ± 0.23 ppm differ by more than 3 combined standard errors",
        "importance sampling 1 ± 0.023 ppm and directional 2.1 ± 0.1 ppm differ by more than 3 combined standard errors",
        "SORM 3 ppm lies outside 3 standard errors of the reference (directional 2.1 ± 0.1 ppm)"]


def test_of_importance_and_subset_sampling_disagreeing_subset_is_the_reference():
    # subset simulation explores the whole space, importance sampling only about one design point (ROBUSTNESS)
    est = tail_of(("importance sampling", 1.0e-6, 0.01e-6), ("subset", 2.0e-6, 0.1e-6))
    assert est.reference == "subset" and len(est.disagreements) == 1


# ----------------------------------------------------------------------------- failed evaluations, corners
@pytest.mark.parametrize("side", ["upper", "lower"])
@pytest.mark.parametrize("limit", [0.0, 2.5, -2.5])
def test_a_failed_evaluation_lies_beyond_the_limit_on_either_side(side, limit):
    from rvtol.mc import Evaluator
    from rvtol.model import FunctionModel
    from rvtol.stacking.tail import _Limit

    spec, _ = linear_normals()
    m = FunctionModel(lambda X: np.where(X[:, 0] > 0.0, np.nan, 0.0 * X[:, 0] + limit)[:, None], spec.names,
                      [Quantity("y", "mm")], ["mm", "mm"])
    ls = _Limit(m, spec, "y", limit, side, Evaluator())
    y = ls.y(np.array([[1.0, 0.0], [-1.0, 0.0]]))          # the first cannot be evaluated, the second lies on the limit
    assert (y[0] > limit if side == "upper" else y[0] < limit) and y[1] == limit and ls.failed == 1


@pytest.mark.parametrize("coefficients, limit, out_of_reach", [
    ([-1.0, 1.0], 1.99, False),          # x₂ − x₁ of two U(−1, 1): 2 at one corner only, (−1, +1)
    ([-1.0, 1.0], 2.01, True),
    ([1.0, 1.0, 1.0], 2.99, False),      # x₁ + x₂ + x₃: 3 at the last of the 2³ corners only, (+1, +1, +1)
    ([1.0, 1.0, 1.0], 3.01, True)])
def test_out_of_reach_looks_at_every_corner_of_the_supports(coefficients, limit, out_of_reach):
    from rvtol.mc import Evaluator
    from rvtol.stacking.tail import _Limit, _out_of_reach

    k = len(coefficients)
    spec = ToleranceSpec("u", tuple(Factor(f"x{i}", "mm", Distribution.make("uniform", lower=-1.0, upper=1.0))
                                    for i in range(k)))
    m = LinearModel(spec.names, ["mm"] * k, [Quantity("y", "mm")], [coefficients])
    ls = _Limit(m, spec, "y", limit, "upper", Evaluator())
    assert _out_of_reach(spec, ls, lambda y: y > limit) is out_of_reach


def test_multi_form_keeps_three_design_points():
    """y = ⅓ ln Σ exp(3 xᵢ) of three standard normals (the largest of three, smoothed) beyond 4: three design points
    near 4 on the axes (β = 4 to 1e-6: the other two terms are negligible there), the union of their half-spaces
    1 − (1 − Φ(−4))³ = 9.50e-5; FORM, led along the diagonal by the gradient at the origin, sees one far point."""
    from rvtol.model import FunctionModel

    spec, _ = linear_normals(3)
    m = FunctionModel(lambda X: (np.log(np.exp(3.0 * X).sum(axis=1)) / 3.0)[:, None], spec.names,
                      [Quantity("y", "mm")], ["mm"] * 3)
    est = tail_probability(m, spec, "y", 4.0, "upper", seed=1, methods=("FORM", "multi-FORM"))
    e = est.get("multi-FORM")
    assert len(est.design_points) == 3 and e.beta == pytest.approx(4.0, rel=1e-5)
    assert e.pf == pytest.approx(1.0 - (1.0 - stats.norm.sf(4.0)) ** 3, rel=1e-3)



# ----------------------------------------------------------------------------- mutation run (issue 37)
def test_the_more_robust_of_two_disagreeing_methods_is_kept_whichever_comes_first():
    """Subset 3 ± 0.1 ppm listed before importance sampling 1 ± 0.1 ppm: 2 > 3·√2·0.1 = 0.42, they disagree; importance
    sampling (one design point) is the suspect, subset the reference; FORM 2.5e-6 is 2.5 ppm."""
    est = tail_of(("FORM", 2.5e-6, None), ("subset", 3.0e-6, 0.1e-6), ("importance sampling", 1.0e-6, 0.1e-6))
    assert est.reference == "subset" and est.ppm_form == pytest.approx(2.5, rel=1e-12)
    assert est.disagreements[0] == ("subset 3 ± 0.1 ppm and importance sampling 1 ± 0.1 ppm differ by more than 3 "
                                    "combined standard errors")


def test_two_equally_robust_methods_disagreeing_are_both_left_out():
    """Subset 2 ± 0.1 and directional 4 ± 0.1 ppm disagree (2 > 0.42) and are equally robust: both suspect.  Importance
    sampling 3 ± 0.5 ppm agrees with each (1 ≤ 3·√(0.1² + 0.5²) = 1.53), so it is the reference — not subset, whose
    c.o.v. (0.05) is the smaller."""
    est = tail_of(("subset", 2.0e-6, 0.1e-6), ("directional", 4.0e-6, 0.1e-6), ("importance sampling", 3.0e-6, 0.5e-6))
    assert est.reference == "importance sampling" and len(est.disagreements) == 1


def test_a_number_that_is_no_probability_is_shown_in_ppm():
    from rvtol.stacking.tail import Estimate, _not_an_estimate

    why = _not_an_estimate(Estimate("importance sampling", 1.5, 0.1), 2, 5.0)
    assert why == "the method returned 1.5e+06 ± 1e+05 ppm, not a probability"


@pytest.mark.parametrize("k, out_of_reach", [(12, True), (13, False)])
def test_out_of_reach_looks_at_the_corners_of_at_most_twelve_factors(k, out_of_reach):
    """y = Σ xᵢ of k U(−1, 1) beyond k + 0.5 (above the worst case k): out of reach by its 2¹² corners for 12
    factors; for 13 the corners are not tried (not out of reach: the methods run and say what they find)."""
    from rvtol.mc import Evaluator
    from rvtol.stacking.tail import _Limit, _out_of_reach

    spec = ToleranceSpec("u", tuple(Factor(f"x{i}", "mm", Distribution.make("uniform", lower=-1.0, upper=1.0))
                                    for i in range(k)))
    m = LinearModel(spec.names, ["mm"] * k, [Quantity("y", "mm")], [[1.0] * k])
    ls = _Limit(m, spec, "y", k + 0.5, "upper", Evaluator())
    assert _out_of_reach(spec, ls, lambda y: y > k + 0.5) is out_of_reach


def test_a_side_read_from_a_file_is_the_same_side():
    """``side`` read from a TOML file is a string equal to "upper" but not the interned literal: still the upper tail.
    y = x₁ + x₂ of standard normals above −√2: the nominal 0 already fails, β = −1 and P = Φ(1) = 0.841."""
    import sys
    import tomllib

    side = tomllib.loads('side = "upper"')["side"]
    assert side == "upper" and side is not sys.intern("upper")      # the premise: an equal, distinct string
    spec, m = linear_normals()
    est = tail_probability(m, spec, "y", -math.sqrt(2), side, methods=("FORM",))
    assert est.beta == pytest.approx(-1.0, rel=1e-6) and est.pf_form == pytest.approx(stats.norm.cdf(1.0), rel=1e-9)
    assert any("nominal point itself fails" in n for n in est.notes)


def test_each_methods_evaluations_are_its_own():
    """The model counts the rows it is given: one for the nominal point, then each method's own; their sum is the
    model's count (an estimate's count is what the model evaluated while that method ran, not a running total)."""
    from rvtol.model import FunctionModel

    spec, _ = linear_normals()
    rows = []
    m = FunctionModel(lambda X: (rows.append(len(X)) or X.sum(axis=1))[:, None], spec.names, [Quantity("y", "mm")],
                      ["mm", "mm"])
    est = tail_probability(m, spec, "y", 3.0 * math.sqrt(2), "upper", seed=1, samples=1000,
                           methods=("FORM", "SORM", "subset", "directional"))
    assert all(e.evaluations > 0 for e in est.estimates) and len(est.estimates) == 4
    assert 1 + sum(e.evaluations for e in est.estimates) == sum(rows) == est.evaluations


def test_form_accepts_a_point_within_a_millionth_of_the_scale_from_the_nominal_to_the_limit():
    """y = x − 1 ± 1.4e-6 (x ~ N(0, 1); the output jumps by 2.8e-6 at x = 2, never equal to the limit 1): FORM's point
    x = 2 + 1.4e-6 misses the limit by 2.8e-6, within 1e-6 of the scale |limit| + |nominal − limit| = 1 + 2 = 3
    (the nominal −1 two below the limit): accepted, β = 2, P = Φ(−2)."""
    from rvtol.model import FunctionModel

    spec = ToleranceSpec("n", (Factor("x", "mm", Distribution.make("normal", mean=0.0, sigma=1.0)),))
    m = FunctionModel(lambda X: (X[:, 0] - 1.0 + np.where(X[:, 0] >= 2.0, 1.4e-6, -1.4e-6))[:, None], spec.names,
                      [Quantity("y", "mm")], ["mm"])
    est = tail_probability(m, spec, "y", 1.0, "upper", methods=("FORM",))
    assert est.converged and est.beta == pytest.approx(2.0, rel=1e-5)
    assert est.pf_form == pytest.approx(stats.norm.sf(2.0), rel=1e-5)


def test_sorm_notes_tvedt_and_hohenbichler_in_ppm():
    """A plane limit state (y = x₁ + x₂ of standard normals beyond 3√2, β = 3, every curvature 0): Tvedt's and
    Hohenbichler's corrections are Φ(−3) = 1350 ppm, as the note says."""
    import re

    spec, m = linear_normals()
    est = tail_probability(m, spec, "y", 3.0 * math.sqrt(2), "upper", methods=("FORM", "SORM"))
    note = est.get("SORM").note
    for name in ("Tvedt", "Hohenbichler"):
        ppm = float(re.search(rf"{name} (\S+) ppm", note).group(1))
        assert ppm == pytest.approx(1e6 * stats.norm.sf(3.0), rel=5e-4), note


def test_directional_sampling_runs_the_directions_its_note_says():
    """samples / 20 directions in whole blocks of 50: 4000 samples → 200 directions; 1960 → 98 asked, one block of 50
    run — the very estimate (same seed) of 1000 samples, which ask exactly 50."""
    spec, m = linear_normals()

    def directional(samples):
        est = tail_probability(m, spec, "y", 3.0 * math.sqrt(2), "upper", seed=1, samples=samples,
                               methods=("directional",))
        return est.get("directional")

    assert directional(4000).note.startswith("200 directions")
    fifty, asked_98 = directional(1000), directional(1960)
    assert fifty.note.startswith("50 directions") and asked_98.note.startswith("50 directions")
    assert (asked_98.pf, asked_98.se, asked_98.evaluations) == (fifty.pf, fifty.se, fifty.evaluations)
