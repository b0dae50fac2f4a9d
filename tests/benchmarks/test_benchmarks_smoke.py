"""Every benchmark script runs, as the user runs it, at its smoke size (issue 40 item 5: benchmarks that cannot rot).

``python studies/benchmarks/bench_<x>.py --smoke`` in a fresh process (the scripts import their helpers from
their own folder, which Python puts on ``sys.path`` only when it runs them): exit code 0, a table printed, and
every ratio it prints (``1.23×``) a positive finite number, no NaN or infinity among its figures.  No wall
clock is asserted: the smoke sizes measure nothing, they only run every code path.  ``run_all.py --list`` must
name every ``bench_*.py`` of the folder, so a new benchmark is run by both.
"""
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROOT

BENCH = ROOT / "studies" / "benchmarks"
SCRIPTS = sorted(p.name for p in BENCH.glob("bench_*.py"))
#: run by ``run_all.py --smoke``, not by the suite: each starts several processes of its own (≈ 10–40 s at the smoke
#: size, most of it importing rvtol in each), which the suite's 10-minute budget does not hold
PROCESS_HEAVY = {"bench_scale.py", "bench_scaling.py", "bench_dask.py", "bench_estimates.py", "bench_sensitivity.py"}
RATIO = re.compile(r"(\S+)×")
NOT_FINITE = re.compile(r"\b(nan|inf)\b", re.IGNORECASE)


def run(args: list[str]) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, *args], cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)


@pytest.mark.slow
@pytest.mark.parametrize("script", [x for x in SCRIPTS if x not in PROCESS_HEAVY])
def test_the_benchmark_runs_at_its_smoke_size_and_prints_positive_finite_ratios(script):
    p = run([str(BENCH / script), "--smoke"])
    assert p.returncode == 0, f"{script} --smoke: exit code {p.returncode}\n{p.stderr[-3000:]}"
    out = p.stdout
    ratios = RATIO.findall(out)
    assert ratios, f"{script} printed no ratio:\n{out}"
    for r in ratios:
        value = float(r.lstrip("(="))
        assert math.isfinite(value) and value > 0, f"{script}: ratio {r}× in\n{out}"
    assert not NOT_FINITE.search(out), f"{script}: a figure is not finite:\n{out}"


def test_run_all_lists_every_benchmark_script():
    p = run([str(BENCH / "run_all.py"), "--smoke", "--list"])
    assert p.returncode == 0, p.stderr
    listed = [Path(line.split()[1]).name for line in p.stdout.splitlines()]
    assert sorted(listed) == SCRIPTS
    assert all(line.split()[2:] == ["--smoke"] for line in p.stdout.splitlines())


def test_the_scripts_left_to_run_all_exist():
    """The suite leaves the process-heavy scripts to ``run_all.py --smoke``: a renamed one must not drop out of both."""
    assert PROCESS_HEAVY <= set(SCRIPTS)
