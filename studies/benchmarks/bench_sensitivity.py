"""Sensitivity benchmark: cost of each method relative to its model evaluations, and executor speed-up.

Measured side by side in one process (the machines are shared and noisy) and reported as ratios:

1. analysis overhead: each global method's total time against the bare model evaluations of the
   same design (what SALib's sampling and analysis add on a cheap model);
2. five-point: evaluations per factor (1 + 4k distinct points, shared centre) against 5k;
3. delta per factor on a 2-worker process pool against serial (the kernel density estimates are
   the costly part, so they run on the executor);
4. Sobol on a CPU-bound model through a 2-worker pool against serial.

    python studies/benchmarks/bench_sensitivity.py [--quick | --smoke]
"""
from __future__ import annotations

import argparse

import numpy as np

from rvtol.executors import make_executor
from rvtol.mc import Evaluator, evaluate
from rvtol.model import LinearModel, Quantity
from rvtol.sampling import sample
from rvtol.sensitivity import delta, five_point, morris, sobol
from rvtol.spec import spec_from_table
from rvtol.testing import CpuBoundModel

from _timing import add_size_options, best_of, by_size, print_table




def linear_case(k: int = 6):
    spec = spec_from_table({"factor": [{"name": f"x{i}", "unit": "um", "dist": "normal", "mean": 1.0 + i,
                                        "tolerance": 1.0} for i in range(k)]})
    model = LinearModel(spec.names, ["mm"] * k, [Quantity("y", "rad", "arcmin")], [np.linspace(0.1, 1.0, k)])
    return model, spec


def main(size: str = "full") -> None:
    rows = []
    model, spec = linear_case()
    # 1. method overhead vs the bare evaluations of the same number of rows
    n_base = by_size(size, 16, 256, 1024)
    counting = {"rows": 0}
    ev = Evaluator()

    def counted(m, X, desc):
        counting["rows"] += len(X)
        return ev(m, X, desc)

    for name, run in (("Sobol (S1, ST, S2)", lambda: sobol(model, spec, n_base, seed=1, evaluate=counted)),
                      ("Morris (r = 50)", lambda: morris(model, spec, 50, seed=1, evaluate=counted))):
        counting["rows"] = 0
        t_all, _ = best_of(run, repeat=1)
        X = sample(spec, counting["rows"], "random", 3).values
        t_eval, _ = best_of(lambda: evaluate(model, X, progress=False), repeat=1)
        rows.append((f"{name}: total / bare evaluations", f"{t_all / t_eval:.1f}×",
                     f"{counting['rows']} rows, {t_all * 1e3:.0f} ms"))
    # 2. five-point: distinct evaluated rows
    counting["rows"] = 0
    five_point(model, spec, evaluate=counted)
    rows.append(("five-point: rows evaluated / 5k", f"{counting['rows'] / (5 * len(spec)):.2f}",
                 f"{counting['rows']} rows for k = {len(spec)}"))
    # 3. delta on given samples: 2-worker pool vs serial
    n = by_size(size, 100, 1500, 4000)
    s = sample(spec, n, "random", 5)
    Y = model.outputs[0].to_display(model.evaluate(s.values))
    delta(model, spec, samples=s, Y=Y, seed=2, num_resamples=2)  # imports and caches outside the timing
    t_ser, a = best_of(lambda: delta(model, spec, samples=s, Y=Y, seed=2, num_resamples=20), repeat=1)
    with make_executor("process", 2) as ex:
        delta(model, spec, samples=s, Y=Y, seed=2, num_resamples=2, executor=ex)  # warm the pool
        t_par, b = best_of(lambda: delta(model, spec, samples=s, Y=Y, seed=2, num_resamples=20, executor=ex), repeat=1)
    assert a.frame.equals(b.frame)
    rows.append(("delta (k = 6, n = %d): serial / process(2)" % n, f"{t_ser / t_par:.2f}×",
                 f"{t_ser:.1f} s vs {t_par:.1f} s, identical indices"))
    # 4. Sobol on a CPU-bound model: serial vs process(2)
    cm = CpuBoundModel(3, work=200_000)
    cspec = spec_from_table({"factor": [{"name": f"x{i}", "unit": "1", "dist": "uniform", "lower": 0, "upper": 1}
                                        for i in range(3)]})
    nb = by_size(size, 4, 32, 128)
    t1, r1 = best_of(lambda: sobol(cm, cspec, nb, second_order=False, seed=4), repeat=1)
    with make_executor("process", 2) as ex:
        evaluate(cm, np.full((4, 3), 0.5), ex, progress=False)  # start the pool outside the timing
        t2, r2 = best_of(lambda: sobol(cm, cspec, nb, second_order=False, seed=4,
                                       evaluate=Evaluator(ex)), repeat=1)
    assert r1.frame.equals(r2.frame)
    rows.append((f"Sobol on a CPU-bound model ({nb * 5} rows): serial / process(2)", f"{t1 / t2:.2f}×",
                 f"{t1:.1f} s vs {t2:.1f} s, identical indices"))
    print_table(rows, ("measure", "ratio", "detail"))


if __name__ == "__main__":
    from threadpoolctl import threadpool_limits

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_size_options(ap)
    with threadpool_limits(1):  # one BLAS thread here too, as in the executor's workers: a fair serial baseline
        main(ap.parse_args().size)
