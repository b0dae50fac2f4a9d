"""Timing, table and size helpers shared by the benchmark scripts.

The scripts are run from the repository root as ``python studies/benchmarks/bench_<x>.py``;
Python puts this folder on ``sys.path``, so they import these helpers as ``_timing``.

Every script runs at one of :data:`SIZES`: ``--smoke`` (seconds: the smallest sizes that still run every code
path; ``tests/benchmarks/test_benchmarks_smoke.py`` runs each script so, so a change that breaks one fails the tests —
its figures mean nothing), ``--quick`` (minutes, what ``run_all.py`` runs by default) or the full sizes (no option).
"""
from __future__ import annotations

import argparse
import time

#: the sizes a benchmark runs at, smallest first
SIZES = ("smoke", "quick", "full")


def add_size_options(ap: argparse.ArgumentParser) -> None:
    """``--smoke`` / ``--quick`` (exclusive) on ``ap``; the parsed ``size`` is one of :data:`SIZES` (default full)."""
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--quick", dest="size", action="store_const", const="quick", help="smaller sizes (minutes)")
    g.add_argument("--smoke", dest="size", action="store_const", const="smoke",
                   help="the smallest sizes that run every code path (seconds; the test suite runs these)")
    ap.set_defaults(size="full")


def by_size(size: str, smoke, quick, full):
    """The value of ``smoke``, ``quick`` or ``full`` that ``size`` (one of :data:`SIZES`) names."""
    return dict(zip(SIZES, (smoke, quick, full)))[size]


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
