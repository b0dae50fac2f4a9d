"""rvtol's tail estimates against OpenTURNS called directly on the same function (issue 40 item 4).

The function: y = (x₁ + … + x_{k−1})/√(k − 1) + 0.05·x_k² of k independent standard normals, the event y > 5 —
a curved sub-ppm tail whose exact probability is one integral (the first term is a standard normal independent of
x_k): P = ∫ φ(v) Φ̄(5 − 0.05 v²) dv (scipy quad).  Its design point lies at β = 5 along the first k − 1 axes,
Breitung's SORM is Φ(−5)/√(1 − 0.5) = 4.05e-7 whatever k.

Each method runs twice side by side in one process, best of a few repeats:

* **rvtol**: ``rvtol.stacking.tail.tail_probability`` on a ``FunctionModel`` of the function and a spec of k
  standard normal factors (the model's evaluation engine, the copula transform, the checks and the notes);
* **OpenTURNS direct**: the same numpy function as an ``ot.PythonFunction`` (``func_sample``) of ``ot.Normal(k)``,
  the same algorithm with the same settings (FORM by Abdo–Rackwitz from the origin; SORM; importance sampling
  about the FORM design point; subset simulation), what a user who knows OpenTURNS would write.

The ratio is rvtol's time over OpenTURNS'; the evaluations of the function each made are printed beside it.

    PYTHONPATH=. python studies/benchmarks/bench_tail.py [--quick | --smoke]
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from _timing import add_size_options, best_of, by_size, print_table  # noqa: E402
from rvtol.distributions import Distribution  # noqa: E402
from rvtol.model import FunctionModel, Quantity  # noqa: E402
from rvtol.spec import Factor, ToleranceSpec  # noqa: E402
from rvtol.stacking.tail import tail_probability  # noqa: E402

LIMIT = 5.0
CURVATURE = 0.05


def function(X: np.ndarray) -> np.ndarray:
    """y of every row of X (k columns)."""
    k = X.shape[1]
    return X[:, : k - 1].sum(axis=1) / math.sqrt(k - 1) + CURVATURE * X[:, k - 1] ** 2


def exact() -> float:
    from scipy import integrate, stats

    return integrate.quad(lambda v: stats.norm.pdf(v) * stats.norm.sf(LIMIT - CURVATURE * v * v), -12, 12,
                          epsabs=0, epsrel=1e-10)[0]


def rvtol_case(k: int, method: str, samples: int):
    spec = ToleranceSpec("tail", tuple(Factor(f"x{i}", "mm", Distribution.make("normal", mean=0.0, sigma=1.0))
                                       for i in range(k)))
    model = FunctionModel(lambda X: function(X)[:, None], spec.names, [Quantity("y", "mm")], ["mm"] * k)

    def run():
        est = tail_probability(model, spec, "y", LIMIT, "upper", samples=samples, seed=5, methods=(method,))
        e = est.get(method)
        return e.pf, est.evaluations
    return run


def direct_case(k: int, method: str, samples: int):
    import openturns as ot

    ot.Log.Show(ot.Log.NONE)
    counter = [0]

    def f(U):
        U = np.asarray(U)
        counter[0] += len(U)
        return function(U)[:, None]

    event = ot.ThresholdEvent(ot.CompositeRandomVector(ot.PythonFunction(k, 1, func_sample=f),
                                                       ot.RandomVector(ot.Normal(k))), ot.Greater(), LIMIT)
    block = 100

    def run():
        counter[0] = 0
        ot.RandomGenerator.SetSeed(5)
        if method == "SORM":
            algo = ot.SORM(ot.AbdoRackwitz(), event, [0.0] * k)
            algo.run()
            return float(algo.getResult().getEventProbabilityBreitung()), counter[0]
        form = ot.FORM(ot.AbdoRackwitz(), event, [0.0] * k)
        form.run()
        if method == "FORM":
            return float(form.getResult().getEventProbability()), counter[0]
        if method == "importance sampling":
            u = list(form.getResult().getStandardSpaceDesignPoint())
            algo = ot.ProbabilitySimulationAlgorithm(
                event, ot.ImportanceSamplingExperiment(ot.Normal(u, [1.0] * k, ot.CorrelationMatrix(k))))
        else:
            algo = ot.SubsetSampling(event)
            algo.setConditionalProbability(0.1)
        algo.setMaximumOuterSampling(max(1, samples // block))
        algo.setBlockSize(block)
        if method == "importance sampling":
            algo.setMaximumCoefficientOfVariation(-1.0)
        algo.run()
        return float(algo.getResult().getProbabilityEstimate()), counter[0]
    return run


def main(size: str) -> None:
    ks = by_size(size, (2,), (2, 50), (2, 10, 50))
    samples = by_size(size, 400, 4000, 4000)
    repeat = by_size(size, 1, 3, 5)
    p = exact()
    rvtol_case(2, "FORM", samples)()      # imports OpenTURNS and warms both paths before anything is timed
    print(f"exact P = {p:.4e}; Breitung's SORM {0.5 * math.erfc(LIMIT / math.sqrt(2)) / math.sqrt(1 - 2 * CURVATURE * LIMIT):.4e}")
    rows = []
    for k in ks:
        for method in ("FORM", "SORM", "importance sampling", "subset"):
            t_r, (pf_r, n_r) = best_of(rvtol_case(k, method, samples), repeat)
            t_d, (pf_d, n_d) = best_of(direct_case(k, method, samples), repeat)
            rows.append((f"k = {k}, {method}", f"{1e3 * t_r:.1f} ms / {1e3 * t_d:.1f} ms",
                         f"{n_r} / {n_d}", f"{pf_r:.3e} / {pf_d:.3e}" if pf_r is not None else f"— / {pf_d:.3e}",
                         f"{t_r / t_d:.2f}×"))
    print_table(rows, ("case", "rvtol / OpenTURNS", "evaluations", "P", "rvtol / OpenTURNS time"))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_size_options(ap)
    main(ap.parse_args().size)
