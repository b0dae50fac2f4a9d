"""Distributions from measured values: fits recover known parameters (tolerances from n and the
Fisher information), AIC picks the family on clear cases, AD by hand, KDE against scipy, empirical
resampling, measurement uncertainty, reading files, and sampling through rvtol's engine."""
import math
import pickle

import numpy as np

from rvtol.spec import spec_from_table
import pytest
from scipy import integrate, stats

from rvtol.errors import InputError, SpecError
from rvtol.inputs import measured as M
from rvtol.params import Params
from rvtol.sampling import sample, uniform_design
from rvtol.spec import Factor, ToleranceSpec

N = 2000


def draw(d, n=N, seed=7):
    return d.rvs(n, random_state=np.random.default_rng(seed))


# ------------------------------------------------------------------ recovering known parameters
def test_normal_recovers_mean_and_sigma():
    mu, sd = 25.01, 0.004
    r = M.fit(draw(stats.norm(mu, sd)), families=["normal"], gof=None)
    p = r.best.params
    assert abs(p["loc"] - mu) < 4 * sd / math.sqrt(N)              # SE of the mean
    assert abs(p["scale"] - sd) < 4 * sd / math.sqrt(2 * N)        # SE of the MLE σ
    d = r.distribution()
    assert d.kind == "normal" and d.p == {"mean": p["loc"], "sigma": p["scale"]}


def test_lognormal_recovers_median_and_shape():
    med, s = 3.0, 0.5
    p = M.fit(draw(stats.lognorm(s, 0, med)), families=["lognormal"], gof=None).best.params
    assert abs(p["s"] - s) < 4 * s / math.sqrt(2 * N)
    assert abs(math.log(p["scale"] / med)) < 4 * s / math.sqrt(N)  # ln(median) is the mean of ln x


def test_weibull_recovers_shape_and_scale():
    k, lam = 2.5, 3.0
    p = M.fit(draw(stats.weibull_min(k, 0, lam)), families=["weibull"], gof=None).best.params
    # asymptotic SEs of the Weibull MLE: √6/π·k/√n and λ/(k√n)·√(1 + 6(1−γ)²/π²)
    se_k = math.sqrt(6) / math.pi * k / math.sqrt(N)
    se_l = lam / (k * math.sqrt(N)) * math.sqrt(1 + 6 * (1 - np.euler_gamma) ** 2 / math.pi ** 2)
    assert abs(p["c"] - k) < 4 * se_k and abs(p["scale"] - lam) < 4 * se_l


def test_rayleigh_recovers_sigma_and_maps_to_the_spec_kind():
    sig = 1.7
    r = M.fit(draw(stats.rayleigh(0, sig)), families=["rayleigh"], gof=None)
    assert abs(r.best.params["scale"] - sig) < 4 * sig / (2 * math.sqrt(N))
    t = r.factor_table()
    assert t == {"dist": "rayleigh", "sigma": r.best.params["scale"]}
    from rvtol.distributions import from_params

    assert from_params(Params(t, file="f", key="k")) == r.distribution()


CLEAR = {  # family: (true distribution, n) — ΔAIC to the runner-up must exceed 10
    "normal": (stats.norm(5, 1), 1000),
    "lognormal": (stats.lognorm(0.8, 0, 2), 1000),
    "weibull": (stats.weibull_min(1.5, 0, 3), 2000),
    "gamma": (stats.gamma(4, 0, 0.5), 1000),
    "uniform": (stats.uniform(5, 2), 1000),
}


@pytest.mark.parametrize("family", sorted(CLEAR))
def test_aic_picks_the_family_on_clear_cases(family):
    d, n = CLEAR[family]
    t = M.fit(draw(d, n, seed=11), gof=None).table()
    assert t.family[0] == family
    assert t.delta_aic[1] > 10.0
    assert t.weight[0] > 0.99


def test_nested_families_rayleigh_is_a_weibull_of_shape_2():
    r = M.fit(draw(stats.rayleigh(0, 2), 1000, seed=11), gof=None)
    assert r.best.family in ("rayleigh", "weibull")
    w = r.candidate("weibull").params["c"]
    assert abs(w - 2.0) < 4 * math.sqrt(6) / math.pi * 2.0 / math.sqrt(1000)


def test_aic_and_loglik_by_hand():
    x = draw(stats.norm(1, 2), 500)
    c = M.fit(x, families=["normal"], gof=None).best
    sd = x.std()
    ll = -0.5 * len(x) * (math.log(2 * math.pi * sd * sd) + 1)   # closed form at the MLE
    assert c.loglik == pytest.approx(ll, rel=1e-12)
    assert c.aic == pytest.approx(4 - 2 * ll, rel=1e-12)


# ------------------------------------------------------------------ goodness of fit, Q-Q
def _ad(x, cdf):
    x = np.sort(x)
    n = len(x)
    F = cdf(x)
    i = np.arange(1, n + 1)
    return -n - np.mean((2 * i - 1) * (np.log(F) + np.log1p(-F[::-1])))


def test_anderson_darling_bootstrap():
    x = draw(stats.norm(10, 1), 400, seed=3)
    r = M.fit(x, families=["normal", "lognormal"], n_mc=199, seed=1)
    g = r.gof[0]
    assert g.test.startswith("Anderson-Darling") and g.family == r.best.family
    assert r.best.family == "normal"
    # the statistic by hand and by scipy.stats.anderson (both, as Stephens' tables, with s of ddof = 1)
    ref = stats.norm(x.mean(), x.std(ddof=1))
    assert g.statistic == pytest.approx(_ad(x, ref.cdf), rel=1e-9)
    assert g.statistic == pytest.approx(stats.anderson(x, "norm", method="interpolate").statistic, rel=1e-9)
    assert g.pvalue > 0.01
    # the wrong family is rejected: lognormal data (s = 0.8) judged as normal
    y = draw(stats.lognorm(0.8, 0, 2), 400, seed=3)
    bad = M.fit(y, families=["normal"], n_mc=199, seed=1).gof[0]
    assert bad.pvalue < 0.01
    # the naive KS p-value is reported and is larger than the bootstrap AD one for a wrong family
    assert M.fit(y, families=["normal"], gof=None).best.ks_pvalue_naive >= 0.0
    u = M.fit(draw(stats.uniform(0, 1), 300), families=["uniform"], n_mc=99).gof[0]
    assert u.test.startswith("Cramér-von Mises") and math.isfinite(u.statistic)


def test_qq_data():
    x = draw(stats.norm(0, 1), 300)
    r = M.fit(x, families=["normal"], gof=None)
    q = r.qq()
    n = len(x)
    np.testing.assert_array_equal(q["sample"], np.sort(x))
    np.testing.assert_allclose(q["p"], (np.arange(1, n + 1) - 0.5) / n)
    np.testing.assert_allclose(q["theoretical"], stats.norm.ppf(q["p"], *stats.norm.fit(x)), rtol=1e-12)
    assert np.corrcoef(q["theoretical"], q["sample"])[0, 1] > 0.995


def test_gamma_is_a_spec_kind_and_its_factor_table_round_trips():
    """Gamma became a spec kind (issue 25): the fitted family writes a [[factor]] table that reads back the same law."""
    r = M.fit(draw(stats.gamma(4, 0, 0.5), 500), families=["gamma"], gof=None)
    d = r.distribution()
    assert d.kind == "gamma" and d.mean == pytest.approx(r.best.frozen.mean())
    assert d.scaled(2.0).std == pytest.approx(2 * d.std)
    t = r.factor_table()
    assert t["dist"] == "gamma"
    back = spec_from_table({"factor": [{"name": "g", "unit": "mm", **t}]}).factors[0].dist
    p = np.array([0.01, 0.5, 0.99])
    np.testing.assert_allclose(back.ppf(p), r.best.frozen.ppf(p), rtol=1e-12)


def test_positive_families_are_skipped_for_data_below_their_location():
    r = M.fit(draw(stats.norm(0, 1), 200), gof=None)
    assert set(r.skipped) == {"lognormal", "weibull", "gamma", "rayleigh"}
    assert r.best.family == "normal"


# ------------------------------------------------------------------ empirical and KDE
def test_empirical_is_the_inverse_ecdf():
    x = draw(stats.norm(5, 1), 50)
    e = M.empirical(x)
    xs = np.sort(x)
    k = np.arange(1, 51)
    np.testing.assert_array_equal(e.ppf(k / 50), xs)              # u = k/n → x₍k₎
    np.testing.assert_array_equal(e.ppf((k - 0.5) / 50), xs)
    assert e.ppf(2.0 ** -53) == xs[0] and e.ppf(1 - 2.0 ** -53) == xs[-1]
    np.testing.assert_array_equal(e.cdf(xs), k / 50)
    assert (e.mean, e.std) == (pytest.approx(x.mean()), pytest.approx(x.std()))
    ei = M.empirical(x, interpolate=True)
    np.testing.assert_allclose(ei.ppf((k - 0.5) / 50), xs)
    # moments of the interpolated ECDF against numerical integration of its quantile function
    kinks = list((k - 0.5) / 50)   # the quantile function is linear between the Hazen positions
    m1 = integrate.quad(lambda u: ei.ppf(u), 0, 1, points=kinks, limit=500)[0]
    m2 = integrate.quad(lambda u: ei.ppf(u) ** 2, 0, 1, points=kinks, limit=500)[0]
    assert ei.mean == pytest.approx(m1, rel=1e-7) and ei.std == pytest.approx(math.sqrt(m2 - m1 * m1), rel=1e-6)
    assert M.empirical(x).scaled(0.5).std == pytest.approx(0.5 * x.std())


def test_empirical_factor_samples_through_the_engine():
    x = draw(stats.norm(12.0, 0.003), 200)
    f = Factor("disc_width", "mm", M.empirical(x))
    spec = ToleranceSpec("measured", (f,))
    s = sample(spec, 20_000, "lhs", seed=1)
    v = s.values[:, 0]
    assert set(np.unique(v)) <= set(x)                             # resampling: only measured parts
    assert abs(v.mean() - x.mean()) < 4 * x.std() / math.sqrt(20_000)
    assert "empirical(resampled, n=200" in spec.to_frame()["distribution"][0]
    assert pickle.loads(pickle.dumps(f)).dist.ppf(0.3) == f.dist.ppf(0.3)


def test_kde_against_scipy_and_its_inverse():
    x = draw(stats.lognorm(0.4, 0, 2), 300)
    k = M.kde(x)
    ref = stats.gaussian_kde(x)
    assert k.bandwidth == pytest.approx(math.sqrt(ref.covariance[0, 0]), rel=1e-12)
    grid = np.linspace(0.5, 6, 9)
    np.testing.assert_allclose(k.cdf(grid), [ref.integrate_box_1d(-np.inf, g) for g in grid], atol=1e-12)
    np.testing.assert_allclose(k.pdf(grid), ref(grid), rtol=1e-10)
    u = np.concatenate([[2.0 ** -53, 1e-12, 1e-6], uniform_design(2000, 1, seed=2)[:, 0],
                        [1 - 1e-6, 1 - 1e-12, 1 - 2.0 ** -53]])
    q = k.ppf(u)
    assert np.all(np.isfinite(q)) and np.all(np.diff(q[3:-3][np.argsort(u[3:-3])]) >= 0)
    lower = u <= 0.5
    np.testing.assert_allclose(k.cdf(q[lower]), u[lower], rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(k.sf(q[~lower]), 1 - u[~lower], rtol=1e-9, atol=1e-15)
    # mean and variance: closed form (mixture) against numerical integration of the density
    t = np.linspace(x.min() - 12 * k.bandwidth, x.max() + 12 * k.bandwidth, 100_001)
    f = k.pdf(t)
    m = integrate.simpson(t * f, x=t)
    v = integrate.simpson((t - m) ** 2 * f, x=t)
    assert k.mean == pytest.approx(m, rel=1e-8) and k.std == pytest.approx(math.sqrt(v), rel=1e-7)
    # row-deterministic: solving in pieces gives the same bits
    np.testing.assert_array_equal(k.ppf(u), np.concatenate([k.ppf(u[:700]), k.ppf(u[700:])]))
    assert M.kde(x, bandwidth="silverman").bandwidth == pytest.approx(
        math.sqrt(stats.gaussian_kde(x, "silverman").covariance[0, 0]))
    assert M.kde(x, bandwidth=0.1).bandwidth == 0.1
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(k)).ppf(u[:50]), k.ppf(u[:50]))


# ------------------------------------------------------------------ measurement uncertainty
def test_measurement_uncertainty_is_deconvolved():
    n, sp, um = 4000, 0.020, 0.010
    rng = np.random.default_rng(5)
    obs = rng.normal(10.0, sp, n) + rng.normal(0.0, um, n)          # part + gauge error
    so = math.hypot(sp, um)
    se = math.sqrt(2.0 / n) * so ** 2 / (2 * sp)                    # SE of √(s² − u²)
    r = M.fit(obs, families=["normal"], measurement_sigma=um, gof=None)
    assert abs(r.best.params["scale"] - sp) < 4 * se
    assert r.gauge_fraction == pytest.approx(um ** 2 / np.var(obs, ddof=1))
    raw = M.fit(obs, families=["normal"], gof=None).best.params["scale"]
    assert abs(raw - sp) > 6 * se                                    # without it σ is the observed one
    e = M.empirical(obs, measurement_sigma=um)
    assert e.mean == pytest.approx(obs.mean()) and abs(e.std - sp) < 4 * se
    with pytest.raises(InputError, match="cannot resolve"):
        M.fit(obs, measurement_sigma=0.05)


# ------------------------------------------------------------------ reading files
def test_read_measurements(tmp_path):
    p = tmp_path / "cmm.csv"
    p.write_text("# CMM export\npart,bore,runout\n1,25.011,0.004\n2,25.008,\n3,25.013,0.006\n", encoding="utf-8")
    np.testing.assert_array_equal(M.read_measurements(p, "bore"), [25.011, 25.008, 25.013])
    np.testing.assert_array_equal(M.read_measurements(p, "Runout"), [0.004, 0.006])   # blanks skipped
    np.testing.assert_array_equal(M.read_measurements(p, 2), [25.011, 25.008, 25.013])
    with pytest.raises(SpecError, match="several columns \\(part, bore, runout\\)"):
        M.read_measurements(p)
    # the header is not echoed (its first line may hold anything): a close name only
    with pytest.raises(SpecError, match="no column 'bores' in the header row \\(did you mean 'bore'\\?\\)"):
        M.read_measurements(p, "bores")
    q = tmp_path / "one.txt"
    q.write_text("25,011\n25,008\n25,013\n", encoding="utf-8")
    with pytest.raises(SpecError, match="several columns"):
        M.read_measurements(q)   # a comma is read as the delimiter, never guessed as a decimal comma
    q.write_text("x;y\n25,011;1\n25,0085;2\n", encoding="utf-8")   # 25,0085: this column writes decimal commas
    np.testing.assert_array_equal(M.read_measurements(q, "x"), [25.011, 25.0085])
    q.write_text("x;y\n25,011;1\n25,008;2\n", encoding="utf-8")    # 25.011 or 25011: nothing says which
    with pytest.raises(SpecError, match=r"row 2, column 'x': '25,011' is ambiguous: 25.011 with a decimal comma or "
                                        r"25011 with a thousands separator.* write 25.011 or 25011"):
        M.read_measurements(q, "x")
    b = tmp_path / "bad.csv"
    b.write_text("bore\n25.01\nn/a\n", encoding="utf-8")
    with pytest.raises(SpecError) as e:
        M.read_measurements(b)
    assert str(e.value) == f"{b}: row 3, column 'bore': expected a number, got 'n/a'"
    from openpyxl import Workbook

    wb = Workbook()
    wb.active.title = "CMM"
    for row in (["bore"], [25.01], [25.02], ["oops"]):
        wb.active.append(row)
    wb.save(tmp_path / "m.xlsx")
    with pytest.raises(SpecError, match="sheet 'CMM', row 4, column 'bore'"):
        M.read_measurements(tmp_path / "m.xlsx")


def test_read_measurements_goes_through_the_table_reader(tmp_path):
    """A header cell ``name [unit]`` (rvtol.inputs.sheets.split_header) is found by its name and its unit converted
    to the factor's (hand: 25.011 mm = 25011 µm); a TSV with decimal commas; an XLSX sheet with a unit header."""
    p = tmp_path / "cmm.csv"
    p.write_text("# CMM export\npart,d [mm],\"E_c[1,2] [um]\"\n1,25.011,4\n2,25.008,6\n", encoding="utf-8")
    np.testing.assert_array_equal(M.read_measurements(p, "d"), [25.011, 25.008])
    np.testing.assert_array_equal(M.read_measurements(p, "d [mm]"), [25.011, 25.008])   # as written
    np.testing.assert_allclose(M.read_measurements(p, "d", unit="um"), [25011.0, 25008.0], rtol=1e-15)
    np.testing.assert_allclose(M.read_measurements(p, "E_c[1,2]", unit="mm"), [0.004, 0.006], rtol=1e-15)
    with pytest.raises(SpecError, match="row 2, column 'd \\[mm\\]': cannot convert 'mm' \\(length\\)"):
        M.read_measurements(p, "d", unit="deg")
    t = tmp_path / "cmm.tsv"
    t.write_text("# exported with a German locale\nbore [mm]\truns\n25,011\t1\n25,01\t2\n", encoding="utf-8")
    np.testing.assert_array_equal(M.read_measurements(t, "bore"), [25.011, 25.01])
    from openpyxl import Workbook

    wb = Workbook()
    wb.active.title = "CMM"
    for row in (["# gauge G-12"], ["d [um]"], [11.0], [8.0], [13.0]):
        wb.active.append(row)
    wb.save(tmp_path / "d.xlsx")
    np.testing.assert_allclose(M.read_measurements(tmp_path / "d.xlsx", "d", unit="mm"), [0.011, 0.008, 0.013],
                               rtol=1e-15)
    d, rec = M.measured_factor(Params({"data": "d.xlsx", "column": "d", "unit": "mm", "method": "empirical"},
                                      file="s.toml", key="factor[0]"), tmp_path)
    np.testing.assert_allclose(rec.values, [0.011, 0.008, 0.013], rtol=1e-15)


def test_spec_loader_hook(tmp_path):
    p = tmp_path / "cmm.csv"
    x = draw(stats.norm(25.01, 0.004), 300)
    p.write_text("bore\n" + "\n".join(repr(float(v)) for v in x), encoding="utf-8")
    d = M.measured_from_params(Params({"data": "cmm.csv", "method": "empirical"}, file="s.toml", key="factor[0]"),
                               tmp_path)
    assert d.kind == "empirical" and d.n == 300
    d = M.measured_from_params(Params({"data": "cmm.csv", "families": ["normal", "uniform"]}, file="s.toml",
                                      key="factor[0]"), tmp_path)
    assert d.kind == "normal"
    with pytest.raises(SpecError, match="s.toml: factor\\[0\\].method: unknown value 'spline'"):
        M.measured_from_params(Params({"data": "cmm.csv", "method": "spline"}, file="s.toml", key="factor[0]"),
                               tmp_path)
    with pytest.raises(SpecError, match="file not found"):
        M.measured_from_params(Params({"data": "nope.csv"}, file="s.toml", key="factor[0]"), tmp_path)


def test_bad_values_are_refused():
    with pytest.raises(InputError, match="not finite"):
        M.empirical([1.0, np.nan, 2.0])
    with pytest.raises(InputError, match="all values are equal"):
        M.kde([1.0, 1.0, 1.0])
    with pytest.raises(InputError, match="at least 8"):
        M.fit([1.0, 2.0, 3.0])
    with pytest.raises(InputError, match="unknown method"):
        M.from_measurements([1.0, 2.0], method="spline")
