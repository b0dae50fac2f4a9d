"""The sequential rule (rvtol.sequential) against independent references: the mixture integral by quadrature, the
martingale identity, and the achieved error rate under repeated looks by simulation beside the naive rule's."""
import math

import numpy as np
import pytest
from scipy import integrate, stats

from rvtol import sequential as sq

ALPHA = 0.05


def _mixture_by_quadrature(k, n, p0, tune_n):
    """ln of ∫_{p0}^1 (q/p0)^k ((1-q)/(1-p0))^(n-k) Beta(q; a, b) dq / P_Beta(q > p0), by scipy.integrate.quad."""
    a, b = p0 * tune_n, (1 - p0) * tune_n
    f = lambda q: math.exp(k * math.log(q / p0) + (n - k) * math.log((1 - q) / (1 - p0))   # noqa: E731
                           + stats.beta.logpdf(q, a, b))
    peak = [k / n] if p0 < k / n < 1 else None
    num, _ = integrate.quad(f, p0, 1, points=peak, limit=200, epsabs=0, epsrel=1e-11)
    return math.log(num / stats.beta.sf(p0, a, b))


@pytest.mark.parametrize("k,n,p0,tune_n", [(1500, 1500, 0.9973, 1500), (1495, 1500, 0.9973, 1500),
                                           (9990, 10000, 0.9973, 3000), (60, 100, 0.5, 100), (40, 100, 0.5, 100)])
def test_closed_form_matches_the_mixture_integral(k, n, p0, tune_n):
    assert float(sq.log_evidence(k, n, p0, tune_n)) == pytest.approx(_mixture_by_quadrature(k, n, p0, tune_n),
                                                                     abs=1e-8)


def test_evidence_is_a_martingale_at_p0_and_starts_at_one():
    """E[M_{n+1} | S_n] = M_n under p = p0: M_n(S) = p0 M_{n+1}(S + 1) + (1 − p0) M_{n+1}(S), exactly; M_0 = 1."""
    p0, m = 0.9, 200.0
    n = np.arange(0, 60)[:, None]
    s = np.arange(0, 60)[None, :]
    s, n = np.broadcast_arrays(s, n)
    keep = s <= n
    s, n = s[keep], n[keep]
    lhs = np.exp(sq.log_evidence(s, n, p0, m))
    rhs = p0 * np.exp(sq.log_evidence(s + 1, n + 1, p0, m)) + (1 - p0) * np.exp(sq.log_evidence(s, n + 1, p0, m))
    np.testing.assert_allclose(lhs, rhs, rtol=1e-9)
    assert float(sq.log_evidence(0, 0, p0, m)) == pytest.approx(0.0, abs=1e-12)


def test_evidence_grows_with_successes_and_stays_finite():
    """Strictly increasing in the successes at a fixed n, finite down to none at all (the far tail of the Beta
    posterior, where ``betaincc`` underflows, from its series)."""
    n = 2000
    e = sq.log_evidence(np.arange(n + 1), n, 0.9973, 2000)
    assert np.all(np.isfinite(e))
    assert np.all(np.diff(e) > 0)


def _log_tail_by_quadrature(x, a, b):
    """ln ∫_x^1 Beta(q; a, b) dq by mpmath quadrature (40 digits) on a grid scaled by the log-density's slope at x."""
    import mpmath

    mpmath.mp.dps = 40
    a, b, x = mpmath.mpf(a), mpmath.mpf(b), mpmath.mpf(x)
    at_x = (a - 1) * mpmath.log(x) + (b - 1) * mpmath.log(1 - x)
    step = 1 / abs((a - 1) / x - (b - 1) / (1 - x))
    grid = sorted({x, *(min(x + step * 2 ** j, mpmath.mpf(1)) for j in range(60))})
    inner = mpmath.quad(lambda q: mpmath.exp((a - 1) * mpmath.log(q) + (b - 1) * mpmath.log(1 - q) - at_x), grid)
    return float(mpmath.log(inner) + at_x - mpmath.log(mpmath.beta(a, b)))


@pytest.mark.parametrize("x,a,b", [(0.9973, 2691.3, 303.7), (0.5, 400.0, 2500.0), (0.99999, 999.99, 100000.01)])
def test_far_tail_of_the_beta_matches_quadrature(x, a, b):
    """Tails of e^-700 and beyond (where scipy's betaincc is 0 or denormal) against 40-digit quadrature."""
    from scipy import special

    assert special.betaincc(a, b, x) < 1e-250
    assert sq.log_beta_sf(x, a, b) == pytest.approx(_log_tail_by_quadrature(x, a, b), rel=1e-11)


def _per_pair(f, s, n):
    """``f(s, n)`` on the distinct (successes, n) pairs of the arrays only (the runs repeat them many times)."""
    s, n = np.broadcast_arrays(s, n)
    pairs, back = np.unique(np.stack([s.ravel(), n.ravel()]), axis=1, return_inverse=True)
    return f(pairs[0], pairs[1])[back.ravel()].reshape(s.shape)


def _looks(p, p0, batch, looks, runs, seed):
    """Cumulative successes after each batch of ``runs`` simulated runs at success probability ``p``."""
    g = np.random.default_rng(seed)
    s = np.cumsum(g.binomial(batch, p, size=(runs, looks)), axis=1)
    return s, batch * np.arange(1, looks + 1)


def test_repeated_looks_keep_the_error_rate_where_the_naive_rule_inflates_it():
    """4000 runs at a true yield exactly at the requirement (0.95), looked at after each of 20 batches of 100: the
    rate of a wrong PASS (the error the requirement's confidence bounds) stays ≤ α for the sequential rule; stopping
    the first time the fixed-n Clopper–Pearson bound crosses (the naive rule) makes it about 3× α; and the rule still
    decides a yield that does meet it (0.99) in nearly every run."""
    p0, runs = 0.95, 4000
    s, n = _looks(p0, p0, 100, 20, runs, seed=1)
    mc_error = 3 * math.sqrt(ALPHA * (1 - ALPHA) / runs)
    seq = _per_pair(lambda k, m: sq.evidence_reached(k, m, p0, ALPHA, 1000), s, n).any(axis=1).mean()
    cp = _per_pair(lambda k, m: np.where(k > 0, stats.beta.ppf(ALPHA, k, m - k + 1), 0.0), s, n)
    naive = (cp >= p0).any(axis=1).mean()
    once = (cp[:, -1] >= p0).mean()                   # one look at the final n: the fixed-n rule's own level
    assert seq <= ALPHA + mc_error
    assert naive > 2 * ALPHA
    assert once <= ALPHA + mc_error
    s, n = _looks(0.99, p0, 100, 20, 500, seed=2)
    assert _per_pair(lambda k, m: sq.evidence_reached(k, m, p0, ALPHA, 1000), s, n).any(axis=1).mean() > 0.95


@pytest.mark.parametrize("conforming,n,state", [(3000, 3000, sq.PASS), (980, 1000, sq.FAIL), (1495, 1500, sq.CONTINUE),
                                                (1108, 1108, sq.CONTINUE)])
def test_judge_yield_states(conforming, n, state):
    """A clean run of 3000 demonstrates 0.9973 under any number of looks; 1108 (the fixed-n success run, one look
    only) does not; 20 non-conforming in 1000 demonstrate the failure; 5 in 1500 decide nothing yet."""
    look = sq.judge_yield(conforming, n, 0.9973, ALPHA, tune_n=1500)
    assert look.state == state
    assert look.threshold == pytest.approx(1 / ALPHA)
    assert look.evidence["yield above"] == pytest.approx(math.exp(sq.log_evidence(conforming, n, 0.9973, 1500)))


def test_judge_median_counts_failed_samples_against_each_claim():
    y = np.linspace(-1, 1, 401)          # median 0: inside [-0.5, 0.5] with 75 % of the units on each limit's side
    ok = np.ones_like(y, dtype=bool)
    assert sq.judge_median(y, ok, -0.5, 0.5, ALPHA, 400).state == sq.PASS
    assert sq.judge_median(y + 2, ok, -0.5, 0.5, ALPHA, 400).state == sq.FAIL
    assert sq.judge_median(y, ok, None, 0.02, ALPHA, 400).state == sq.CONTINUE
    # failed samples may lie anywhere: 150 of them make neither "median ≤ 0.5" nor "median > 0.5" demonstrable
    bad = ok.copy()
    bad[:150] = False
    look = sq.judge_median(np.where(bad, y, np.nan), bad, None, 0.5, ALPHA, 400)
    assert look.state == sq.CONTINUE
    assert look.evidence["median ≤ upper"] < sq.judge_median(y, ok, None, 0.5, ALPHA, 400).evidence["median ≤ upper"]


# --------------------------------------------------------------------------- the sequential run
def _one_factor():
    from rvtol.model import LinearModel, Quantity
    from rvtol.spec import spec_from_table

    spec = spec_from_table({"factor": [{"name": "a", "unit": "mm", "dist": "normal", "mean": 0.0, "sigma": 1.0},
                                       {"name": "b", "unit": "mm", "dist": "uniform", "lower": -0.1, "upper": 0.1}]},
                           file="t.toml")
    return spec, LinearModel(spec.names, ["mm"] * 2, [Quantity("y", "mm", "mm")], [[1.0, 0.0]], [0.0])


def test_run_until_decided_stops_when_every_requirement_is_decided():
    """y = a ~ N(0, 1): y ≤ 4 (yield 0.99997) is demonstrated, y ≤ 2 (0.977) demonstrated to fail, both long before
    the budget; the samples are the fixed-n random design's of the same seed bit for bit, and the sequential
    verdicts replace the fixed-n ones."""
    from rvtol.mc import run_monte_carlo, run_until_decided
    from rvtol.spec import Requirement

    spec, model = _one_factor()
    reqs = [Requirement("y", upper=4.0, min_yield=0.9973, name="wide"),
            Requirement("y", upper=2.0, min_yield=0.9973, name="narrow")]
    r = run_until_decided(model, spec, 500, 50_000, seed=7, requirements=reqs, progress=False)
    stop = r.stopping
    assert stop.all_decided and stop.n == r.n < 50_000 and r.n % 500 == 0 and stop.looks == list(range(500, r.n + 1, 500))
    assert {v.requirement.label: v.state for v in r.verdicts()} == {"wide": "PASS", "narrow": "FAIL"}
    assert stop.decided["narrow"][0] < stop.decided["wide"][0]      # a 2 % shortfall shows before a clean pass
    fixed = run_monte_carlo(model, spec, r.n, "random", seed=7, progress=False)
    assert np.array_equal(r.samples.values, fixed.samples.values) and np.array_equal(r.Y, fixed.Y)
    narrow = next(v for v in r.verdicts() if v.requirement.label == "narrow")
    assert "failure demonstrated at look" in narrow.reasons[0]


def test_run_until_decided_ends_undecided_at_the_budget():
    """A yield on the requirement itself (Φ(2.7822) = 0.9973) is not decided by 4 looks of 500: UNDECIDED, and the
    reason says the budget ended it."""
    from rvtol.mc import run_until_decided
    from rvtol.spec import Requirement

    spec, model = _one_factor()
    r = run_until_decided(model, spec, 500, 2000, seed=1, requirements=[Requirement("y", upper=2.7822)],
                          progress=False)
    (v,) = r.verdicts()
    assert r.n == 2000 and r.stopping.looks == [500, 1000, 1500, 2000] and not r.stopping.all_decided
    assert v.state == "UNDECIDED" and "not decided within the budget max_n = 2,000" in v.reasons[0]
    assert r.stopping.to_dict()["stopped"] == "budget"


def test_run_until_decided_is_bit_identical_across_chunkings_and_resumes_from_its_chunks(tmp_path):
    """Another chunking (as another executor or worker count makes: :func:`rvtol.mc.evaluate` reassembles chunks by
    index, ``tests/mc/test_mc_engine.py``) gives the same bits and looks; a rerun on the same checkpoint folder redraws
    the same batches and evaluates nothing."""
    from rvtol.checkpoint import ChunkStore
    from rvtol.mc import run_until_decided
    from rvtol.spec import Requirement

    spec, model = _one_factor()
    reqs = [Requirement("y", upper=3.6, min_yield=0.999)]
    first = ChunkStore(tmp_path)
    ref = run_until_decided(model, spec, 400, 20_000, seed=3, requirements=reqs, progress=False, store=first)
    other = run_until_decided(model, spec, 400, 20_000, seed=3, requirements=reqs, chunk_size=97, progress=False)
    assert np.array_equal(other.Y, ref.Y) and other.stopping.looks == ref.stopping.looks
    again = ChunkStore(tmp_path)
    res = run_until_decided(model, spec, 400, 20_000, seed=3, requirements=reqs, progress=False, store=again)
    assert first.saved > 0 and again.reused == first.saved and again.saved == 0
    assert np.array_equal(res.Y, ref.Y) and res.stopping.looks == ref.stopping.looks


# --------------------------------------------------------------------------- the study keys and the command line
STUDY = """[study]
name = "t"
[sampling]
n = 200
seed = 1
{sampling}
[execution]
executor = "serial"
[[factor]]
name = "a"
unit = "mm"
dist = "normal"
mean = 1.0
tolerance = 0.1
[model]
kind = "formula"
[[model.output]]
name = "y"
formula = "a"
unit = "mm"
[[requirement]]
name = "r"
output = "y"
upper = 1.2
{requirement}
"""


def _cli(tmp_path, capsys, args, sampling="", requirement=""):
    from rvtol.cli import main

    p = tmp_path / "t.toml"
    p.write_text(STUDY.format(sampling=sampling, requirement=requirement), encoding="utf-8")
    rc = main([str(a) for a in [args[0], p, *args[1:]]])
    return rc, capsys.readouterr().err, p


@pytest.mark.parametrize("args,sampling,requirement,where,message", [
    (["check"], "until_decided = true\nmethod = \"lhs\"", "", "sampling.method", "a sequential run draws independent "
     "random samples, batch after batch (the anytime-valid rule assumes independent draws; a lhs design is neither "
     "independent nor extendable): method = \"random\" (or --method random), or leave it out"),
    (["run", "--until-decided", "--method", "sobol"], "", "", "--method", "a sequential run draws independent "
     "random samples, batch after batch (the anytime-valid rule assumes independent draws; a sobol design is neither "
     "independent nor extendable): --method random"),
    (["check"], "max_n = 1000", "", "sampling.max_n", "max_n is the budget of a sequential run: set until_decided = "
     "true (or --until-decided), or drop it"),
    (["run", "--max-n", "1000"], "", "", "--max-n", "max_n is the budget of a sequential run"),
    (["run", "--until-decided", "--max-n", "100"], "", "", "--max-n",
     "the budget max_n = 100 is smaller than one batch (n = 200)"),
    (["check"], "until_decided = true", "min_cpk = 1.33", "requirement[0]",
     "until_decided: a minimum Cpk has no anytime-valid bound here"),
])
def test_a_sequential_run_it_cannot_do_is_refused_in_one_line(tmp_path, capsys, args, sampling, requirement, where,
                                                                message):
    rc, err, p = _cli(tmp_path, capsys, args, sampling, requirement)
    file = "<command line>" if where.startswith("--") else str(p)
    assert rc == 2 and err.startswith(f"rvtol: error: {file}: {where}: {message}") and err.count("\n") == 1


def test_the_study_keys_and_the_flags_give_the_same_sequential_options(tmp_path):
    from rvtol.study import MAX_N_PER_BATCH, load_study

    p = tmp_path / "t.toml"
    p.write_text(STUDY.format(sampling="until_decided = true\nmax_n = 5000", requirement=""), encoding="utf-8")
    o = load_study(p).options
    assert (o.until_decided, o.max_n, o.method) == (True, 5000, "random")
    p.write_text(STUDY.format(sampling="", requirement=""), encoding="utf-8")
    o = load_study(p, until_decided=True).options
    assert (o.until_decided, o.max_n, o.method) == (True, MAX_N_PER_BATCH * 200, "random")
    assert load_study(p).options.method == "lhs" and not load_study(p).options.until_decided


def test_run_until_decided_judges_median_and_mean_bands():
    """The median of N(0, 1) inside [-0.3, 0.3] is demonstrated (P(y ≤ 0.3) = 0.618 > ½), inside [0.2, 1] is
    demonstrated not to be (P(y < 0.2) = 0.579 > ½), by the same rule at p₀ = ½; the mean inside [-0.3, 0.3] by its
    anytime-valid t interval."""
    from rvtol.mc import run_until_decided
    from rvtol.spec import Requirement

    spec, model = _one_factor()
    reqs = [Requirement("y", lower=-0.3, upper=0.3, statistic="median", name="centred"),
            Requirement("y", lower=0.2, upper=1.0, statistic="median", name="shifted"),
            Requirement("y", lower=-0.3, upper=0.3, statistic="mean", name="mean centred")]
    r = run_until_decided(model, spec, 200, 20_000, seed=5, requirements=reqs, progress=False)
    assert {v.requirement.label: v.state for v in r.verdicts()} == {"centred": "PASS", "shifted": "FAIL",
                                                                   "mean centred": "PASS"}
    lo, hi = r.stopping.decided["mean centred"][1].interval
    assert -0.3 <= lo < 0 < hi <= 0.3
    assert r.stopping.all_decided and r.n < 20_000
    assert set(r.stopping.decided["shifted"][1].evidence) == {"median ≤ upper", "median > upper", "median ≥ lower",
                                                              "median < lower"}


@pytest.mark.parametrize("method,refused", [("fit", True), ("empirical", False)])
def test_a_sequential_run_refuses_a_fitted_measured_factor(tmp_path, capsys, method, refused):
    """A law fitted to measured parts carries the fit's uncertainty, which more samples cannot decide; the data's own
    empirical law carries none (as in a fixed run) and is sampled like any factor."""
    from rvtol.cli import main

    (tmp_path / "cmm.csv").write_text("d\n" + "\n".join(f"{1 + 0.01 * math.sin(i):.5f}" for i in range(40)) + "\n",
                                      encoding="utf-8")
    study = STUDY.format(sampling="until_decided = true", requirement="").replace(
        'dist = "normal"\nmean = 1.0\ntolerance = 0.1', f'dist = "measured"\ndata = "cmm.csv"\nmethod = "{method}"')
    p = tmp_path / "t.toml"
    p.write_text(study, encoding="utf-8")
    rc = main(["check", str(p)])
    err = capsys.readouterr().err
    if refused:
        assert rc == 2 and err.startswith(f"rvtol: error: {p}: factor 'a': until_decided: a factor fitted to measured "
                                          "parts carries its fit's uncertainty")
    else:
        assert rc == 0, err


# --------------------------------------------------------------------------- a mean's band
@pytest.mark.parametrize("n,g", [(2, 0.05), (5, 1.0), (30, 0.02), (30, 0.5)])
def test_t_mixture_has_expectation_one_under_the_null(n, g):
    """E[BF_n] = ∫ BF_n(t) f_ν(t) dt = 1 with t Student's t of ν = n − 1 under μ = μ₀ (a test martingale's mean)."""
    val, _ = integrate.quad(lambda x: math.exp(float(sq.log_t_evidence(x * x, n, g)) + stats.t.logpdf(x, n - 1)),
                            -np.inf, np.inf, limit=400, epsabs=1e-13)
    assert val == pytest.approx(1.0, abs=1e-8)


def test_mean_interval_ends_are_where_the_evidence_reaches_one_over_alpha():
    s, n, m = 0.7, 400, 400.0
    h = sq.mean_halfwidth(s, n, ALPHA, m)
    t2 = n * h * h / (s * s)
    g = sq.effect_prior_variance(ALPHA, m)
    assert float(sq.log_t_evidence(t2, n, g)) == pytest.approx(math.log(1 / ALPHA), abs=1e-9)
    assert h > stats.t.ppf(1 - ALPHA / 2, n - 1) * s / math.sqrt(n)        # wider than the fixed-n interval
    assert sq.mean_halfwidth(s, 2, ALPHA, m) is None                        # n = 2: not bounded yet


def test_mean_interval_covers_under_repeated_looks_where_the_t_interval_does_not():
    """2000 normal runs looked at after each of 25 batches of 20: the anytime interval ever misses the true mean in at
    most α of them; the fixed-n 95 % t interval looked at as often misses far more often."""
    g = np.random.default_rng(3)
    runs, batch, looks = 2000, 20, 25
    y = g.standard_normal((runs, batch * looks))
    n = batch * np.arange(1, looks + 1)
    s1 = np.cumsum(y, axis=1)[:, n - 1]
    s2 = np.cumsum(y * y, axis=1)[:, n - 1]
    mean = s1 / n
    sd = np.sqrt((s2 - n * mean ** 2) / (n - 1))
    t2 = n * mean ** 2 / sd ** 2
    seq = (sq.log_t_evidence(t2, n, sq.effect_prior_variance(ALPHA, batch)) >= math.log(1 / ALPHA)).any(axis=1).mean()
    naive = (np.sqrt(t2) > stats.t.ppf(1 - ALPHA / 2, n - 1)).any(axis=1).mean()
    assert seq <= ALPHA + 3 * math.sqrt(ALPHA * (1 - ALPHA) / runs)
    assert naive > 3 * ALPHA


def test_judge_mean_states():
    y = np.random.default_rng(4).normal(1.0, 0.1, 400)
    ok = np.ones(400, dtype=bool)
    assert sq.judge_mean(y, ok, 0.9, 1.1, ALPHA, 400).state == sq.PASS
    assert sq.judge_mean(y, ok, 1.2, 2.0, ALPHA, 400).state == sq.FAIL
    look = sq.judge_mean(y, ok, 1.0, 2.0, ALPHA, 400)
    assert look.state == sq.CONTINUE and look.interval[0] < 1.0 < look.interval[1]
    ok[0] = False
    assert sq.judge_mean(y, ok, 0.9, 1.1, ALPHA, 400).interval is None
