"""Timing and table helpers shared by the benchmark scripts.

The scripts are run from the repository root as ``python studies/benchmarks/bench_<x>.py``;
Python puts this folder on ``sys.path``, so they import these helpers as ``_timing``.
"""
from __future__ import annotations

import time


def best_of(f, repeat: int = 3):
    """``(best wall time of `repeat` calls of f in seconds, result of the last call)``."""
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return best, out


def best_time(f, repeat: int = 3) -> float:
    """Best wall time of ``repeat`` calls of ``f``, in seconds."""
    return best_of(f, repeat)[0]


def print_table(rows, headers=("measurement", "value", "ratio")) -> None:
    """Print ``(name, value, ratio/notes)`` rows as an aligned three-column table."""
    w0 = max(len(str(r[0])) for r in [headers, *rows])
    w1 = max(len(str(r[1])) for r in [headers, *rows])
    print(f"{headers[0]:<{w0}}  {headers[1]:>{w1}}  {headers[2]}")
    for a, b, c in rows:
        print(f"{a:<{w0}}  {b:>{w1}}  {c}")
