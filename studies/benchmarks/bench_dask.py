"""Where model evaluations run: the process pool against Dask (a LocalCluster, and a scheduler address).

The same Monte Carlo work — the 20-DOF transmission-error model of ``transmission_error_rv80e.toml``
(tens of ms per sample: the work a cluster is for) and a cheap linear model (µs per sample: the
overhead alone) — evaluated through ``rvtol.mc.evaluate`` on each executor, side by side in one
process; ratios against the process pool with the same number of workers.  Results are checked to be
bit-identical across executors (the engine's contract).

    python studies/benchmarks/bench_dask.py [--quick | --smoke] [--workers 2]

``--smoke`` runs the process pool alone (the Dask clusters take tens of seconds to start on a loaded machine; the
test suite's Dask tests cover the executor).
"""
from __future__ import annotations

import argparse
import contextlib
import time
from pathlib import Path

import numpy as np

from rvtol.executors import make_executor
from rvtol.mc import evaluate
from rvtol.sampling import sample
from rvtol.study import load_study
from rvtol.testing import TrivialModel

from _timing import add_size_options, by_size, print_table

ROOT = Path(__file__).resolve().parents[2]


def timed(model, X, executor, chunk_size):
    evaluate(model, X[: 2 * executor.workers], executor, chunk_size=1, progress=False)   # start-up, compilation
    t0 = time.perf_counter()
    ev = evaluate(model, X, executor, chunk_size=chunk_size, progress=False)
    return time.perf_counter() - t0, ev.Y


def main(size: str = "full", workers: int = 2) -> None:
    from dask.distributed import LocalCluster

    study = load_study(ROOT / "studies" / "transmission_error_rv80e.toml", executor="serial", progress=False)
    n_te = by_size(size, 2 * workers, 64, 400)
    n_lin = by_size(size, 1000, 200_000, 200_000)
    cases = [("20-DOF TE model", study.model, sample(study.spec, n_te, "lhs", seed=1).values, max(n_te // 16, 1)),
             ("linear model (overhead)", TrivialModel(3), np.random.default_rng(0).random((n_lin, 3)), n_lin // 20)]
    rows = []
    dask = size != "smoke"
    with (LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) if dask
          else contextlib.nullcontext()) as cluster:
        for label, model, X, cs in cases:
            times, results = {}, {}
            executors = [("process pool", "process", None)]
            if dask:
                executors += [("Dask LocalCluster", "dask", None),
                              ("Dask scheduler address", "dask", cluster.scheduler_address)]
            for name, kind, sched in executors:
                with make_executor(kind, workers, sched) as ex:
                    times[name], results[name] = timed(model, X, ex, cs)
            ref = times["process pool"]
            for name, t in times.items():
                same = np.array_equal(results[name], results["process pool"], equal_nan=True)
                rows.append((f"{label}, {name} ({len(X)} samples, chunks of {cs})", f"{t:.2f} s",
                             f"{t / ref:.2f}× process pool; {len(X) / t:,.0f} samples/s"
                             + ("" if same else "  RESULTS DIFFER")))
    print(f"Executors, {workers} workers each (the scheduler address: a LocalCluster started here, reached over TCP)")
    print_table(rows)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_size_options(ap)
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()
    main(a.size, a.workers)
