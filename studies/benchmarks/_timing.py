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
    """Print ``(name, value, …, ratio/notes)`` rows as an aligned table: the name left-aligned, the values right-aligned,
    the last column as it is."""
    cols = len(headers)
    widths = [max(len(str(r[i])) for r in [headers, *rows]) for i in range(cols - 1)]
    for r in [headers, *rows]:
        cells = [f"{r[0]!s:<{widths[0]}}", *(f"{r[i]!s:>{widths[i]}}" for i in range(1, cols - 1))]
        print("  ".join([*cells, str(r[-1])]))
