"""What this machine's core does per second: the reference for the benchmarks' "arithmetic limit".

``scalar_flop_rate()`` runs independent multiply-add chains over data in L1 cache, compiled by numba
without fast-math (no vectorised reduction): the rate the 20-DOF kernels' scalar loops could reach if
every operation were an independent fused multiply-add.  (The kernels' pin passes are vectorised and can
beat it; the Newton loop, the contact laws and the Cholesky factor are scalar.)
"""
from __future__ import annotations

import time

import numpy as np
from numba import njit


@njit(cache=True)
def _fma_chains(n, a, b):
    s0 = s1 = s2 = s3 = s4 = s5 = s6 = s7 = 0.0
    for _ in range(n):
        for k in range(0, a.size, 8):
            s0 += a[k] * b[k]
            s1 += a[k + 1] * b[k + 1]
            s2 += a[k + 2] * b[k + 2]
            s3 += a[k + 3] * b[k + 3]
            s4 += a[k + 4] * b[k + 4]
            s5 += a[k + 5] * b[k + 5]
            s6 += a[k + 6] * b[k + 6]
            s7 += a[k + 7] * b[k + 7]
    return s0 + s1 + s2 + s3 + s4 + s5 + s6 + s7


def scalar_flop_rate(repeat: int = 60) -> float:
    """Flop/s of independent scalar multiply-adds (2 flops each), best of ``repeat`` (CPU time)."""
    a = np.random.default_rng(0).random(512)
    b = a[::-1].copy()
    n = 1000
    _fma_chains(2, a, b)
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        _fma_chains(n, a, b)
        best = min(best, time.process_time() - t0)
    return 2.0 * a.size * n / best
