"""rvtol against OpenTURNS on the same Monte Carlo and Sobol work (the Ishigami function, closed-form indices).

1. Monte Carlo: n samples of three U(−π, π) factors, the function, and the statistics (mean, standard
   deviation, 0.135 % and 99.865 % quantiles): ``rvtol.mc.run_monte_carlo`` (serial, with its verdict
   machinery and confidence intervals) against ``ot.JointDistribution.getSample`` + ``ot.Sample`` statistics.
2. Saltelli Sobol indices, first and total order, N base samples: ``rvtol.sensitivity.global_.sobol`` (SALib,
   scrambled Sobol' design, bootstrap intervals) against ``ot.SaltelliSensitivityAlgorithm`` (its Monte Carlo
   design; ``ot.SobolIndicesExperiment``), both without second order; the error of each against the
   closed-form indices (Ishigami & Homma 1990).

OpenTURNS is a main dependency (reliability, functional chaos); without it this
prints one line and exits.

    python studies/benchmarks/bench_openturns.py [--quick | --smoke]
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from _timing import add_size_options, best_of, by_size, print_table

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests"))
from gsa_reference import ISH, ISH_SPEC, ishigami, ishigami_indices  # noqa: E402

from rvtol.mc import run_monte_carlo  # noqa: E402
from rvtol.sensitivity.global_ import sobol  # noqa: E402


def main(size: str = "full") -> None:
    try:
        import openturns as ot
    except ImportError:
        print("bench_openturns: OpenTURNS is not installed (pip install -e \".[bench]\"): skipped")
        return
    ot.Log.Show(ot.Log.NONE)
    rows = []
    # 1. Monte Carlo and statistics
    n = by_size(size, 1000, 100_000, 1_000_000)
    dist = ot.JointDistribution([ot.Uniform(-math.pi, math.pi)] * 3)
    f = ot.PythonFunction(3, 1, func_sample=lambda X: ishigami(np.asarray(X)))

    def ot_mc():
        ot.RandomGenerator.SetSeed(1)
        y = f(dist.getSample(n))
        return (y.computeMean()[0], y.computeStandardDeviation()[0], y.computeQuantile(0.00135)[0],
                y.computeQuantile(0.99865)[0])

    def rv_mc():
        mc = run_monte_carlo(ISH, ISH_SPEC, n, "random", 1, progress=False)
        s = mc.statistics()
        return float(s.loc["y", "mean"]), float(s.loc["y", "std"])

    t_ot, r_ot = best_of(ot_mc, 2)
    t_rv, r_rv = best_of(rv_mc, 2)
    rows.append((f"Monte Carlo + statistics, n = {n:,}: OpenTURNS", f"{t_ot:.3f} s", f"mean {r_ot[0]:.4f}, std {r_ot[1]:.4f}"))
    rows.append((f"Monte Carlo + statistics, n = {n:,}: rvtol", f"{t_rv:.3f} s",
                 f"{t_rv / t_ot:.2f}× OpenTURNS; mean {r_rv[0]:.4f}, std {r_rv[1]:.4f} (with CIs, verdicts, percentiles)"))
    # 2. Saltelli first and total indices
    N = by_size(size, 256, 4096, 32768)
    S1, ST, _ = ishigami_indices()

    def ot_sobol():
        ot.RandomGenerator.SetSeed(2)
        X = ot.SobolIndicesExperiment(dist, N, False).generate()
        alg = ot.SaltelliSensitivityAlgorithm(X, f(X), N)
        return np.array(alg.getFirstOrderIndices()), np.array(alg.getTotalOrderIndices())

    def rv_sobol():
        r = sobol(ISH, ISH_SPEC, n=N, second_order=False, seed=2, num_resamples=100).frame
        return r["S1"].to_numpy(), r["ST"].to_numpy()

    t_ot, (s1o, sto) = best_of(ot_sobol, 2)
    t_rv, (s1r, str_) = best_of(rv_sobol, 2)
    err = lambda a, b: float(np.max(np.abs(a - b)))  # noqa: E731
    rows.append((f"Saltelli S1 + ST, N = {N:,} (5 N runs): OpenTURNS", f"{t_ot:.3f} s",
                 f"max |error| S1 {err(s1o, S1):.4f}, ST {err(sto, ST):.4f}"))
    rows.append((f"Saltelli S1 + ST, N = {N:,} (5 N runs): rvtol", f"{t_rv:.3f} s",
                 f"{t_rv / t_ot:.2f}× OpenTURNS; max |error| S1 {err(s1r, S1):.4f}, ST {err(str_, ST):.4f} "
                 "(+ 100 bootstrap intervals)"))
    print(f"rvtol against OpenTURNS {ot.__version__} (Ishigami, serial, one process)")
    print_table(rows)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_size_options(ap)
    main(ap.parse_args().size)
