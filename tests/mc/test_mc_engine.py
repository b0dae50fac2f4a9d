"""The engine: closed-form linear stack-up, bitwise determinism across executors and chunkings,
failure accounting."""
import math

import numpy as np
import pytest

from rvtol.executors import make_executor
from rvtol.mc import evaluate, run_monte_carlo
from rvtol.model import LinearModel, Quantity
from rvtol.spec import Requirement, spec_from_table
from rvtol.testing import STATUS_REFUSED, FlakyModel


def linear_spec():
    return spec_from_table({"factor": [
        {"name": "a", "unit": "um", "dist": "normal", "mean": 5.0, "tolerance": 30.0},
        {"name": "b", "unit": "mm", "dist": "uniform", "lower": -0.01, "upper": 0.01},
        {"name": "c", "unit": "um", "dist": "rayleigh", "tolerance": 10.0},
        {"name": "d", "unit": "um", "dist": "triangular", "lower": -6.0, "upper": 6.0},
    ], "correlation": [{"pair": ["a", "c"], "rho": 0.4}]}, file="t.toml")


def linear_model(spec):
    return LinearModel(spec.names, ["mm"] * 4, [Quantity("gap", "mm", "um"), Quantity("sum", "mm", "mm")],
                       [[1.0, -1.0, 2.0, 0.5], [1.0, 1.0, 1.0, 1.0]], [0.02, 0.0])


def test_linear_chain_converges_to_rss_mean_and_sigma():
    spec = spec_from_table({"factor": [
        {"name": "a", "unit": "um", "dist": "normal", "mean": 5.0, "tolerance": 30.0},
        {"name": "b", "unit": "mm", "dist": "uniform", "lower": -0.01, "upper": 0.01},
        {"name": "d", "unit": "um", "dist": "triangular", "lower": -6.0, "upper": 6.0},
    ]}, file="t.toml")
    coef = np.array([1.0, -1.0, 0.5])
    m = LinearModel(spec.names, ["mm"] * 3, [Quantity("gap", "mm", "um")], [coef], [0.02])
    n = 50_000
    r = run_monte_carlo(m, spec, n, "random", seed=3)
    mean = 20.0 + 5.0  # µm: constant + a's mean
    # RSS in µm; each term: (coefficient·σ_i, excess kurtosis κ_i) — normal 0, uniform −1.2, triangular −0.6
    terms = [(5.0, 0.0), (20.0 / math.sqrt(12), -1.2), (0.5 * 12.0 / math.sqrt(24), -0.6)]
    sig = math.sqrt(sum(s**2 for s, _ in terms))
    kappa = sum(k * s**4 for s, k in terms) / sig**4          # excess kurtosis of the sum
    se_var = sig**2 * math.sqrt(2 / (n - 1) + kappa / n)       # standard error of s²
    y = r.column("gap")
    assert abs(y.mean() - mean) < 4 * sig / math.sqrt(n)
    assert abs(y.var(ddof=1) - sig**2) < 4 * se_var


@pytest.fixture(scope="module")
def reference():
    spec = linear_spec()
    return spec, linear_model(spec), run_monte_carlo(linear_model(spec), spec, 3000, "lhs", seed=42,
                                                     progress=False)


@pytest.mark.parametrize("kind,workers,chunk", [("serial", 1, 97), ("process", 2, 500), ("process", 2, 64),
                                                 ("dask", 2, 700), ("dask", 2, 128)])
def test_bitwise_identical_across_executors_and_chunks(reference, kind, workers, chunk):
    spec, model, ref = reference
    with make_executor(kind, workers) as ex:
        r = run_monte_carlo(model, spec, 3000, "lhs", seed=42, executor=ex, chunk_size=chunk, progress=False)
    assert np.array_equal(r.Y, ref.Y)  # bit for bit
    assert np.array_equal(r.samples.values, ref.samples.values)
    assert np.array_equal(r.status, ref.status)


def test_failures_are_counted_reported_and_non_conforming():
    spec = spec_from_table({"factor": [
        {"name": "x0", "unit": "mm", "dist": "uniform", "lower": 0.0, "upper": 1.0},
        {"name": "x1", "unit": "mm", "dist": "uniform", "lower": 0.0, "upper": 1.0},
    ]}, file="t.toml")
    m = FlakyModel(threshold=0.9)
    with make_executor("process", 2) as ex:
        r = run_monte_carlo(m, spec, 2000, "lhs", seed=1, requirements=[Requirement("y", upper=1e9)],
                            executor=ex, progress=False)
    n_bad = int((r.samples.values[:, 0] > 0.9).sum())
    assert n_bad == 200  # LHS: exactly 10 % of the strata
    f = r.failures()
    assert list(f["status"]) == [STATUS_REFUSED] and int(f["count"].iloc[0]) == n_bad
    assert "refused" in f["reason"].iloc[0]
    assert r.statistics().loc["y", "failed"] == n_bad
    v = r.verdicts()[0]
    assert v.yield_.conforming == 2000 - n_bad and not v.passed
    assert any("could not be evaluated" in s for s in v.reasons)
    assert np.isnan(r.Y[~r.ok]).all() and np.isfinite(r.Y[r.ok]).all()


def test_evaluate_rejects_wrong_shape():
    spec = linear_spec()
    from rvtol.errors import ModelError

    with pytest.raises(ModelError):
        evaluate(linear_model(spec), np.zeros((3, 2)))


def test_requirement_verdict_basis():
    spec = linear_spec()
    m = linear_model(spec)
    # a limit at the sample's own 99th percentile: estimate ~0.99 passes min 0.985 but the
    # lower confidence bound with n=3000 does not pass min 0.989
    r0 = run_monte_carlo(m, spec, 3000, "lhs", seed=42, progress=False)
    lim = float(np.quantile(r0.column("gap"), 0.99))
    est = Requirement("gap", upper=lim, unit="um", min_yield=0.989, basis="estimate")
    lb = Requirement("gap", upper=lim, unit="um", min_yield=0.989, basis="lower_bound")
    r = run_monte_carlo(m, spec, 3000, "lhs", seed=42, requirements=[est, lb], progress=False)
    v_est, v_lb = r.verdicts()
    assert v_est.passed and not v_lb.passed


def test_requirement_units_are_converted():
    spec = linear_spec()
    m = linear_model(spec)
    r = run_monte_carlo(m, spec, 500, "lhs", seed=1, requirements=[Requirement("gap", upper=0.5, unit="mm")],
                        progress=False)
    assert r.requirements[0].unit == "um" and r.requirements[0].upper == pytest.approx(500.0)


def test_dask_scheduler_address_path(reference):
    """`--scheduler ADDR`: connect to a running cluster (here a LocalCluster we start ourselves)."""
    import logging

    from dask.distributed import LocalCluster

    spec, model, ref = reference
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=logging.ERROR) as cluster:
        with make_executor("dask", scheduler=cluster.scheduler_address) as ex:
            r = run_monte_carlo(model, spec, 3000, "lhs", seed=42, executor=ex, chunk_size=1000, progress=False)
            assert ex.workers == 1
    assert np.array_equal(r.Y, ref.Y)


def test_unreachable_scheduler_is_an_input_error():
    from rvtol.errors import InputError
    from rvtol.executors import DaskExecutor

    with pytest.raises(InputError, match="cannot reach Dask scheduler"):
        with DaskExecutor(scheduler="tcp://127.0.0.1:1", connect_timeout=1.0) as ex:
            ex.client


def test_requirement_chooses_the_yield_interval():
    from rvtol import stats as st

    spec = linear_spec()
    m = linear_model(spec)
    cp = Requirement("gap", upper=40.0, unit="um")
    wi = Requirement("gap", upper=40.0, unit="um", interval="wilson")
    r = run_monte_carlo(m, spec, 1500, "lhs", seed=2, requirements=[cp, wi], progress=False)
    v_cp, v_wi = r.verdicts()
    k, n = v_cp.yield_.conforming, v_cp.yield_.n
    assert (v_cp.yield_.lo, v_cp.yield_.hi) == pytest.approx(st.proportion_ci(k, n, 0.95, "exact"))
    assert (v_wi.yield_.lo, v_wi.yield_.hi) == pytest.approx(st.proportion_ci(k, n, 0.95, "wilson"))
    assert v_wi.to_dict()["yield_interval"] == "wilson"


class _NanButOk(LinearModel):
    """A model that returns NaN for x0 > 0 while claiming success (status 0)."""

    def evaluate_with_status(self, X):
        Y = self.evaluate(X)
        Y[X[:, 0] > 0] = np.nan
        return Y, np.zeros(len(X), dtype=np.int16)


def test_nonfinite_output_with_status_ok_is_a_counted_failure():
    spec = spec_from_table({"factor": [{"name": "a", "unit": "mm", "dist": "uniform", "lower": -1, "upper": 1}]},
                           file="t.toml")
    m = _NanButOk(spec.names, ["mm"], [Quantity("y", "mm")], [[1.0]])
    r = run_monte_carlo(m, spec, 1000, "lhs", seed=1, progress=False)
    n_bad = int((r.samples.values[:, 0] > 0).sum())
    assert n_bad == 500 and int(r.failures()["count"].sum()) == n_bad
    assert np.isfinite(r.statistics().loc["y", "mean"])


def test_cpk_only_requirement_fails_when_samples_fail():
    spec = spec_from_table({"factor": [
        {"name": "x0", "unit": "mm", "dist": "uniform", "lower": 0.0, "upper": 1.0},
        {"name": "x1", "unit": "mm", "dist": "uniform", "lower": 0.0, "upper": 1.0},
    ]}, file="t.toml")
    req = Requirement("y", lower=-5000.0, upper=5000.0, unit="um", min_cpk=1.0)  # the evaluated rows: Cpk ≈ 4
    r = run_monte_carlo(FlakyModel(threshold=0.5), spec, 2000, "lhs", seed=1, requirements=[req], progress=False)
    v = r.verdicts()[0]
    assert v.capability["cpk_lo"] > 1.0          # the evaluated half alone would pass
    assert not v.passed and any("Cpk is not demonstrated" in s for s in v.reasons)


def test_output_overflowing_its_display_unit_is_a_failure_not_a_crash():
    spec = spec_from_table({"factor": [{"name": "a", "unit": "mm", "dist": "normal", "mean": 1e307,
                                        "sigma": 1e306}]}, file="t.toml")
    m = LinearModel(spec.names, ["mm"], [Quantity("y", "mm", "um")], [[1.0]])  # 1e307 mm = 1e310 µm: inf
    r = run_monte_carlo(m, spec, 200, "lhs", seed=1, progress=False)
    assert r.failures()["count"].sum() > 0 and np.isnan(r.Y[~r.ok]).all()
