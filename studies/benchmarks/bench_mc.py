"""Monte Carlo engine benchmark: overhead per sample and per chunk, and parallel speed-up.

Everything is measured side by side in one process (the machines are shared and noisy), and
reported as ratios against a reference: the model called directly, and the serial executor.

    python studies/benchmarks/bench_mc.py [--quick | --smoke]
"""
from __future__ import annotations

import argparse

import numpy as np

from rvtol.executors import make_executor
from rvtol.mc import evaluate
from rvtol.testing import CpuBoundModel, TrivialModel

from _timing import add_size_options, best_time, by_size, print_table




def main(size: str = "full") -> None:
    rows = []
    # 1. overhead of the engine per sample: evaluate() in one chunk vs the model called directly
    n = by_size(size, 2000, 200_000, 1_000_000)
    m = TrivialModel(3)
    X = np.random.default_rng(0).random((n, 3))
    t_direct, t_engine = float("inf"), float("inf")
    for _ in range(7):  # interleaved, best of 7: the difference is a few ns per sample
        t_direct = min(t_direct, best_time(lambda: m.evaluate_with_status(X), repeat=1))
        t_engine = min(t_engine, best_time(lambda: evaluate(m, X, chunk_size=n, progress=False), repeat=1))
    rows.append(("engine overhead per sample (serial, 1 chunk)", f"{(t_engine - t_direct) / n * 1e9:.1f} ns",
                 f"{t_engine / t_direct:.2f}× direct call"))
    # 2. overhead per chunk: many small chunks vs one chunk, serial and process pool
    n2 = by_size(size, 2000, 100_000, 100_000)
    X2 = X[:n2]
    t_one = best_time(lambda: evaluate(m, X2, chunk_size=n2, progress=False))
    t_many = best_time(lambda: evaluate(m, X2, chunk_size=100, progress=False))
    rows.append(("overhead per chunk (serial)", f"{(t_many - t_one) / (n2 / 100 - 1) * 1e6:.1f} µs",
                 f"{n2 // 100} chunks of 100 vs 1 chunk"))
    # per task in the pool: tiny payloads, so the difference is dispatch, not data transfer
    X3 = X[:by_size(size, 200, 2000, 2000)]
    with make_executor("process", 2) as ex:
        evaluate(m, X3, ex, chunk_size=10, progress=False)  # start and warm the pool outside the timing
        t_p_few = best_time(lambda: evaluate(m, X3, ex, chunk_size=len(X3) // 2, progress=False), repeat=5)
        t_p_many = best_time(lambda: evaluate(m, X3, ex, chunk_size=1, progress=False), repeat=3)
    rows.append(("overhead per chunk (process pool, 2 workers)",
                 f"{(t_p_many - t_p_few) / (len(X3) - 2) * 1e6:.0f} µs",
                 f"{len(X3)} chunks of 1 vs 2 chunks of {len(X3) // 2}"))
    # 3. parallel speed-up of a CPU-bound model: 2 workers vs 1 (same pool type, same chunking)
    cm = CpuBoundModel(3, work=50_000)
    nc = by_size(size, 32, 400, 1600)
    Xc = np.random.default_rng(1).random((nc, 3))
    times = {}
    for w in (1, 2):
        with make_executor("process", w) as ex:
            evaluate(cm, Xc[:8], ex, chunk_size=4, progress=False)  # warm the pool
            times[w] = best_time(lambda: evaluate(cm, Xc, ex, chunk_size=nc // 16, progress=False), repeat=2)
    t_serial = best_time(lambda: evaluate(cm, Xc, chunk_size=nc // 16, progress=False), repeat=2)
    rows.append(("CPU-bound model, serial executor", f"{nc / t_serial:.0f} samples/s", "reference"))
    rows.append(("CPU-bound model, process pool 1 worker", f"{nc / times[1]:.0f} samples/s",
                 f"{t_serial / times[1]:.2f}× serial"))
    rows.append(("CPU-bound model, process pool 2 workers", f"{nc / times[2]:.0f} samples/s",
                 f"speed-up {times[1] / times[2]:.2f}× vs 1 worker (target ≥ 1.7×)"))
    print_table(rows)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    add_size_options(ap)
    main(ap.parse_args().size)
