"""The scaling benchmark's Amdahl fit against Amdahl's law itself (no timing: made-up times)."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "studies" / "benchmarks"))
from bench_scaling import amdahl  # noqa: E402


@pytest.mark.parametrize("s", [0.0, 0.1, 0.3, 1.0])
def test_amdahl_fit_recovers_the_serial_share_of_exact_times(s):
    w = [1, 2, 4, 16]
    t = [100.0 * (s + (1 - s) / k) for k in w]
    assert amdahl(w, t) == pytest.approx(s, abs=1e-12)


def test_amdahl_two_points_by_hand_and_one_point_none():
    # T(2)/T(1) = 1/1.8: s = 2 r - 1 = 0.111...
    assert amdahl([1, 2], [180.0, 100.0]) == pytest.approx(2 * 100 / 180 - 1)
    assert amdahl([1], [5.0]) is None
