"""Stack-up conventions against hand computation, the true worst case against analytic extremes (a position
zone's disc, an interior extreme a corner search misses), FORM exact on a linear normal stack (and every
OpenTURNS sampler within its error), SORM (Breitung's closed form) and importance sampling against numerical
integration of a curved sub-ppm tail."""
import math

import numpy as np
import pytest
from scipy import integrate, stats

from rvtol.distributions import Distribution
from rvtol.model import FunctionModel, LinearModel, Quantity
from rvtol.models.formula.model import FormulaModel
from rvtol.spec import Factor, ToleranceSpec
from rvtol.stacking import handbook_mrss_factor, stack_conventions, tail_probability, true_worst_case


def normal(name, mean, sigma, shift=0.0, limits=None, zone=""):
    return Factor(name, "mm", Distribution.make("normal", mean=mean, sigma=sigma, shift=shift), limits=limits,
                  zone=zone)


def test_conventions_equal_the_formulas_by_hand():
    # four parts: one with a drawing band and a shifted process (Cp 1.5, k 0.2), one uniform, one correlated pair
    fs = (normal("a", 10.0, 0.05 / 4.5, shift=0.2 * 0.05, limits=(9.95, 10.05)),
          Factor("b", "mm", Distribution.make("uniform", lower=4.98, upper=5.02)),
          normal("c", 3.0, 0.01), normal("d", 2.0, 0.02))
    corr = np.eye(4)
    corr[2, 3] = corr[3, 2] = 0.5
    spec = ToleranceSpec("s", fs, corr)
    a = np.array([1.0, -1.0, -2.0, 0.5])
    x0 = np.array([10.0, 5.0, 3.0, 2.0])
    y0 = float(a @ x0)
    sc = stack_conventions(spec, a, y0, x0, output="gap", out_unit="um", out_base_unit="mm",
                           sigma_levels=(3.0, 4.5), mrss_factor=1.6)
    t = np.array([0.05, 0.02, 0.03, 0.06])              # half bands (normals: ±3σ of their own)
    mu = np.array([10.01, 5.0, 3.0, 2.0])
    sd = np.array([0.05 / 4.5, 0.04 / math.sqrt(12), 0.01, 0.02])
    k = np.array([0.2, 0.0, 0.0, 0.0])
    wc = float(np.sum(np.abs(a) * t))
    rss = float(np.sqrt((a * t) @ corr @ (a * t)))      # the correlated pair's normals: the spec's ρ (issue 37)
    cf = 1 + 0.5 * (wc - rss) / (rss * (2 - 1))         # n = 4: √n − 1 = 1
    cov = np.outer(sd, sd) * corr
    sig = math.sqrt(a @ cov @ a)
    um = 1000.0
    row = sc.row
    assert sc.y_centre == pytest.approx(y0 * um)
    assert row("worst case (arithmetic)")["half_width"] == pytest.approx(wc * um)
    assert row("RSS")["half_width"] == pytest.approx(rss * um)
    assert row("MRSS, Bender")["half_width"] == pytest.approx(1.5 * rss * um)
    assert row("MRSS, handbook")["half_width"] == pytest.approx(cf * rss * um)
    assert handbook_mrss_factor(wc, rss, 4) == pytest.approx(cf)
    assert row("MRSS, given factor")["half_width"] == pytest.approx(1.6 * rss * um)
    r = row("statistical ±4.5σ (the distributions)")
    assert r["centre"] == pytest.approx((y0 + a @ (mu - x0)) * um) and r["half_width"] == pytest.approx(4.5 * sig * um)
    # the 6σ rows with the correlation too (c and d normal: Pearson's ρ is the spec's)
    assert row("6σ static ±3σ")["half_width"] == pytest.approx((0.01 + 3 * sig) * um)
    dyn = a * sd / (1 - k)
    assert row("6σ dynamic RSS ±3σ")["half_width"] == pytest.approx(3 * math.sqrt(dyn @ corr @ dyn) * um)
    e = a * t / (3 * 1.5)                                 # Cp 2, 1.5σ shift: Cpk 1.5
    conv = math.sqrt(e @ corr @ e)
    for name in ("RSS", "MRSS, Bender", "statistical ±3σ (the distributions)", "6σ static ±3σ", "6σ dynamic RSS ±3σ",
                 "6σ dynamic, 1.5σ shift ±3σ"):
        assert "correlation included" in row(name)["note"], name
    assert row("6σ dynamic, 1.5σ shift ±3σ")["half_width"] == pytest.approx(3 * conv * um)
    f = sc.factors.set_index("factor")
    assert f.loc["a", "Cp"] == pytest.approx(1.5) and f.loc["a", "Cpk"] == pytest.approx(1.2)
    assert f["wc_pct"].sum() == pytest.approx(100.0)


def zone_spec(radius=0.025):
    sigma = radius / math.sqrt(-2 * math.log(1 - (stats.norm.cdf(3) - stats.norm.cdf(-3))))
    return ToleranceSpec("z", (normal("h.x", 0.0, sigma, limits=(-radius, radius), zone="h"),
                               normal("h.y", 0.0, sigma, limits=(-radius, radius), zone="h"),
                               Factor("w", "mm", Distribution.make("uniform", lower=-0.01, upper=0.01))))


def test_a_position_zone_is_a_disc_in_the_worst_case():
    spec = zone_spec()
    a = np.array([2.0, 1.0, 1.0])
    sc = stack_conventions(spec, a, 0.0, np.zeros(3), out_unit="mm")
    disc = 0.025 * math.sqrt(5) + 0.01
    assert sc.row("worst case (arithmetic)")["half_width"] == pytest.approx(disc)   # not 0.025·3 + 0.01
    m = LinearModel(spec.names, ["mm"] * 3, [Quantity("y", "mm")], [a])
    wc = true_worst_case(m, spec, "y", gradient=a)
    assert (wc.low, wc.high) == (pytest.approx(-disc, abs=1e-9), pytest.approx(disc, abs=1e-9))
    x, y = wc.x_high["h.x"], wc.x_high["h.y"]
    assert math.hypot(x, y) == pytest.approx(0.025) and y / x == pytest.approx(0.5)   # along the gradient


def test_two_position_zones_are_two_discs_in_the_worst_case():
    """Zones h and k (k later in the alphabet), each a disc: 0.025·√(2² + 1²) + 0.01·√(3² + 4²), plus w's 0.01."""
    s = zone_spec().factors
    sig = s[0].dist.std * 0.01 / 0.025
    k = (normal("k.x", 0.0, sig, limits=(-0.01, 0.01), zone="k"), normal("k.y", 0.0, sig, limits=(-0.01, 0.01), zone="k"))
    spec = ToleranceSpec("zk", s + k)
    sc = stack_conventions(spec, np.array([2.0, 1.0, 1.0, 3.0, 4.0]), 0.0, np.zeros(5), out_unit="mm")
    assert sc.row("worst case (arithmetic)")["half_width"] == pytest.approx(0.025 * math.sqrt(5) + 0.01 + 0.01 * 5)


def test_the_true_worst_case_finds_an_interior_extreme_and_uses_the_analytic_gradient():
    fs = (Factor("p", "1", Distribution.make("uniform", lower=1.0, upper=2.0)),
          Factor("q", "1", Distribution.make("uniform", lower=-3.0, upper=0.5)),
          Factor("r", "1", Distribution.make("uniform", lower=-1.0, upper=2.0)))
    spec = ToleranceSpec("n", fs)
    f = FormulaModel({"y": "p*q - r**2"}, spec.names)
    # p·q over [1,2]×[-3,0.5]: max 1 (2·0.5), min -6 (2·-3); -r² over [-1,2]: max 0 (interior r = 0), min -4
    wc = true_worst_case(f, spec, "y")
    assert wc.high == pytest.approx(1.0, abs=1e-8) and wc.low == pytest.approx(-10.0, abs=1e-8)
    assert abs(wc.x_high["r"]) < 1e-4 and "analytic gradient" in wc.how
    py = FunctionModel(lambda X: (X[:, 0] * X[:, 1] - X[:, 2] ** 2)[:, None], spec.names, ["y"])
    wc2 = true_worst_case(py, spec, "y")
    assert wc2.high == pytest.approx(1.0, abs=1e-7) and "central differences" in wc2.how


def test_form_is_exact_for_a_linear_stack_of_correlated_normals_and_the_samplers_agree():
    fs = (normal("a", 1.0, 0.02), normal("b", 0.5, 0.01), normal("c", 0.2, 0.015))
    corr = np.array([[1, 0.3, 0], [0.3, 1, -0.2], [0, -0.2, 1.0]])
    spec = ToleranceSpec("l", fs, corr)
    a = np.array([1.0, -2.0, 1.5])
    m = LinearModel(spec.names, ["mm"] * 3, [Quantity("y", "mm", "um")], [a])
    mu, sd = np.array([1.0, 0.5, 0.2]), np.array([0.02, 0.01, 0.015])
    s = math.sqrt(a @ (np.outer(sd, sd) * corr) @ a)
    upper = (a @ mu + 5.2 * s) * 1000        # µm: a 0.1 ppm tail
    exact = stats.norm.sf(5.2)
    est = tail_probability(m, spec, "y", upper, "upper", seed=7)
    assert est.converged and est.beta == pytest.approx(5.2, rel=1e-6) and est.pf_form == pytest.approx(exact, rel=1e-5)
    # SORM of a plane is FORM (to the finite-difference Hessian OpenTURNS takes of the model: 0.5 %); every
    # sampling estimate holds the exact value within 4 of its standard errors
    assert est.get("SORM").pf == pytest.approx(exact, rel=5e-3)
    for name in ("importance sampling", "subset", "directional"):
        e = est.get(name)
        assert abs(e.pf - exact) < 4 * e.se, (name, e.pf, e.se)
    assert est.get("importance sampling").se < 0.1 * exact
    # the most probable failure point lies on the limit
    xs = np.array([est.x_star[n] for n in spec.names])
    assert a @ xs * 1000 == pytest.approx(upper, rel=1e-7)
    lo = tail_probability(m, spec, "y", (a @ mu - 4.0 * s) * 1000, "lower", methods=("FORM",))
    assert lo.beta == pytest.approx(4.0, rel=1e-6)


def test_importance_sampling_and_sorm_correct_form_on_a_curved_sub_ppm_tail():
    spec = ToleranceSpec("c", (normal("x1", 0.0, 1.0), normal("x2", 0.0, 1.0)))
    f = FormulaModel({"y": "x1 + 0.05*x2**2"}, spec.names, ["mm", "mm"], checked=False)   # 0.05 is per mm
    U = 5.0
    exact = integrate.quad(lambda v: stats.norm.pdf(v) * stats.norm.sf(U - 0.05 * v * v), -12, 12, epsabs=0,
                           epsrel=1e-10)[0]
    est = tail_probability(f, spec, "y", U, "upper", samples=20000, seed=11,
                           methods=("FORM", "SORM", "importance sampling"))
    assert est.beta == pytest.approx(5.0, rel=1e-5)
    assert est.pf_form == pytest.approx(stats.norm.sf(5.0), rel=1e-4) and est.pf_form < 0.8 * exact   # curvature
    # Breitung: Φ(−β)/√(1 + βκ), κ = −0.1 the curvature of x1 = 5 − 0.05 x2²: within 2 % of the exact tail
    assert est.get("SORM").pf == pytest.approx(stats.norm.sf(5.0) / math.sqrt(1 - 0.5), rel=1e-3)
    assert est.get("SORM").pf == pytest.approx(exact, rel=0.02)
    e = est.get("importance sampling")
    assert abs(e.pf - exact) < 4 * e.se and e.se < 0.05 * exact
    assert est.reference == "importance sampling" and any("FORM" in d for d in est.disagreements)
    assert 1e6 * e.pf < 1.0   # sub-ppm


def test_sorm_holds_breitungs_value_in_fifty_dimensions():
    # y = (x1 + … + x49)/7 + 0.05·x50² > 5: the design point at β = 5 along the first 49 axes, one curvature
    # κ = −0.1 (along x50), Breitung: Φ(−5)/√(1 + βκ) = Φ(−5)/√0.5 whatever the dimension. SORM from the design
    # point by Cobyla alone wandered off it in 50 dimensions and gave no result
    k = 50
    spec = ToleranceSpec("k50", tuple(normal(f"x{i}", 0.0, 1.0) for i in range(k)))
    f = FunctionModel(lambda X: (X[:, :-1].sum(axis=1) / math.sqrt(k - 1) + 0.05 * X[:, -1] ** 2)[:, None],
                      spec.names, [Quantity("y", "mm")], ["mm"] * k)
    est = tail_probability(f, spec, "y", 5.0, "upper", methods=("FORM", "SORM"))
    assert est.beta == pytest.approx(5.0, rel=1e-6)
    assert est.get("SORM").pf == pytest.approx(stats.norm.sf(5.0) / math.sqrt(0.5), rel=2e-3)


def test_a_limit_beyond_the_bounded_worst_case_has_no_failure_point():
    spec = ToleranceSpec("u", (Factor("u", "mm", Distribution.make("uniform", lower=-1.0, upper=1.0)),))
    m = LinearModel(["u"], ["mm"], [Quantity("y", "mm")], [[1.0]])
    est = tail_probability(m, spec, "y", 1.5, "upper", methods=("FORM", "importance sampling"))
    assert not est.x_star and est.pf_form == 0.0 and "out of reach" in est.get("FORM").note
    assert est.get("importance sampling").pf is None


ZONE_SPEC = """
[[factor]]
name = "hole.x"
unit = "mm"
tolerance = "⌀0.05"
zone = "hole"
[[factor]]
name = "hole.y"
unit = "mm"
tolerance = "⌀0.05"
zone = "hole"
[[factor]]
name = "w"
unit = "mm"
tolerance = "±0.01"
nominal = 0
dist = "uniform"
"""


def test_a_position_zone_read_from_a_spec_file_is_a_disc_and_its_coordinates_3_sigma_in_the_rss():
    """The zone's two coordinates as a spec file gives them (their zone names two strings the parser built): the worst
    case takes the disc, 0.025·√(2² + 1²); the RSS reads each coordinate's tolerance as its own 3σ, σ the Rayleigh σ
    whose 99.73 % radius is 0.025 (module docstring), and the uniform w's half band 0.01 as its 3σ.  Each factor's
    share of the RSS is its (a·s)² over their sum."""
    import tomllib

    from rvtol.spec import spec_from_table

    spec = spec_from_table(tomllib.loads(ZONE_SPEC))
    assert spec.factors[0].zone == spec.factors[1].zone and spec.factors[0].zone is not spec.factors[1].zone
    a = np.array([2.0, 1.0, 1.0])
    sc = stack_conventions(spec, a, 0.0, np.zeros(3), out_unit="mm")
    assert sc.row("worst case (arithmetic)")["half_width"] == pytest.approx(0.025 * math.sqrt(5) + 0.01)
    sigma = 0.025 / math.sqrt(-2 * math.log(1 - (stats.norm.cdf(3) - stats.norm.cdf(-3))))
    terms = np.array([(2 * 3 * sigma) ** 2, (3 * sigma) ** 2, 0.01 ** 2])
    assert sc.row("RSS")["half_width"] == pytest.approx(math.sqrt(terms.sum()))
    assert sc.factors["rss_pct"].tolist() == pytest.approx((100 * terms / terms.sum()).tolist())


def test_a_row_added_to_the_table_is_centred_between_its_ends_unless_told():
    """StackConventions.add (the comparison's rows: true worst case, second order, Monte Carlo): half width ½(high −
    low), centre ½(low + high), or the centre given (a Monte Carlo mean need not be the middle)."""
    import pandas as pd

    from rvtol.stacking.conventions import StackConventions

    sc = StackConventions("y", "mm", 0.0, pd.DataFrame(), pd.DataFrame())
    sc.add("range", 1.0, 4.0)
    sc.add("mean ±3σ", -2.0, 4.0, centre=0.5, sigma=2.0)
    assert (sc.row("range")["half_width"], sc.row("range")["centre"]) == (1.5, 2.5)
    mean = sc.row("mean ±3σ")
    assert (mean["half_width"], mean["centre"], mean["sigma"]) == (3.0, 0.5, 2.0)
    assert list(sc.frame.index) == [0, 1]          # each row the next of the table, as the conventions' own rows


def test_a_mean_outside_its_band_leaves_the_dynamic_rss_undefined_unless_the_factor_has_no_effect():
    """k = |μ − c|/t = 0.06/0.05 = 1.2 ≥ 1: Cpk ≤ 0, the inflation σ/(1 − k) has no meaning — the dynamic RSS row is
    NaN and a note says why; the same factor with zero sensitivity leaves it defined (σ_y of the other factor,
    3 · 0.01).  An unknown row is a KeyError."""
    import warnings

    fs = (normal("a", 10.0, 0.01, shift=0.06, limits=(9.95, 10.05)), normal("b", 5.0, 0.01))
    spec = ToleranceSpec("k", fs)
    x0 = np.array([10.0, 5.0])
    sc = stack_conventions(spec, np.array([1.0, 1.0]), 15.0, x0, out_unit="mm")
    assert sc.factors.set_index("factor").loc["a", "k"] == pytest.approx(1.2)
    assert math.isnan(sc.row("6σ dynamic RSS ±3σ")["half_width"])
    assert "a factor's mean lies outside its band (k ≥ 1): the dynamic RSS is undefined" in sc.notes
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # nor a RuntimeWarning for its 0·∞ on the user's terminal
        sc = stack_conventions(spec, np.array([0.0, 1.0]), 5.0, x0, out_unit="mm")
    assert sc.row("6σ dynamic RSS ±3σ")["half_width"] == pytest.approx(3 * 0.01)
    assert not any("undefined" in n for n in sc.notes)
    with pytest.raises(KeyError):
        sc.row("worst case (geometric)")


def test_one_contributor_has_no_handbook_mrss_but_keeps_the_given_factor():
    """n = 1: the handbook's C_f divides by √n − 1 = 0 — no row, a note says why; the study's own mrss_factor 1.2
    still gives its row, 1.2 × the RSS 0.05."""
    spec = ToleranceSpec("one", (normal("a", 1.0, 0.05 / 3),))
    sc = stack_conventions(spec, np.array([1.0]), 1.0, np.array([1.0]), out_unit="mm", mrss_factor=1.2)
    assert sc.row("MRSS, given factor")["half_width"] == pytest.approx(1.2 * 0.05)
    with pytest.raises(KeyError):
        sc.row("MRSS, handbook")
    assert "MRSS (handbook) needs at least two contributors" in sc.notes


def test_stack_conventions_is_called_by_keyword_and_takes_its_options_only_by_keyword():
    """The public signature (rvtol.stacking, docs/api.md): spec, gradient, y0 and x0 may be named; output and the
    options after it only by name (a positional one is refused rather than read as something else).  y = a − b,
    a ±0.02, b ±0.01: the worst case 0.03 either way."""
    spec = ToleranceSpec("kw", (normal("a", 1.0, 0.02 / 3), normal("b", 0.5, 0.01 / 3)))
    g, x0 = np.array([1.0, -1.0]), np.array([1.0, 0.5])
    by_name = stack_conventions(spec=spec, gradient=g, y0=0.5, x0=x0, output="y", out_unit="mm")
    by_position = stack_conventions(spec, g, 0.5, x0, output="y", out_unit="mm")
    for sc in (by_name, by_position):
        assert sc.row("worst case (arithmetic)")["half_width"] == pytest.approx(0.03)
    assert by_name.frame.equals(by_position.frame)
    with pytest.raises(TypeError):
        stack_conventions(spec, g, 0.5, x0, "y")
