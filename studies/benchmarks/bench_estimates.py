"""The run's estimate (printed before computing) against the run: disk and time, on small studies.

Prints, per study, the estimated and the measured Monte Carlo time, report time and report folder size and
their ratios (issue 27: within 2×).  The machines are shared: a loaded machine slows a process pool's start
and its workers more than the in-process pilot; the load average is printed beside the figures.

    PYTHONPATH=. python studies/benchmarks/bench_estimates.py
"""
from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from rvtol.runguard import estimate_run, time_pilot  # noqa: E402
from rvtol.study import load_study, run_study, write_outputs  # noqa: E402

STUDIES = [("linear_stackup", "serial"), ("linear_stackup", "process"), ("stack_handbook_motor", "serial"),
           ("torsion_curve_rv80e", "serial")]


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"{'study':<24}{'executor':<9}{'MC est':>8}{'MC run':>8}{'ratio':>7}{'rep est':>8}{'rep run':>8}"
          f"{'ratio':>7}{'disk est':>10}{'disk':>10}{'ratio':>7}")
    for name, ex in STUDIES:
        st = load_study(ROOT / "studies" / f"{name}.toml", executor=ex, pdf=False, progress=False)
        st.analyses = []          # the estimate leaves the analyses out
        est = time_pilot(estimate_run(st), st)
        res = run_study(st)
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            out = write_outputs(res, Path(tmp) / "rep")
            t_rep = time.perf_counter() - t0 + res.timings.get("report", 0.0)   # rendering + writing
            disk = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())
        mc = res.timings["monte_carlo"]
        print(f"{name:<24}{ex:<9}{est.seconds:>8.2f}{mc:>8.2f}{est.seconds / mc:>7.2f}{est.report_seconds:>8.1f}"
              f"{t_rep:>8.1f}{est.report_seconds / t_rep:>7.2f}{est.disk / 1e6:>9.2f}M{disk / 1e6:>9.2f}M"
              f"{est.disk / disk:>7.2f}")


if __name__ == "__main__":
    main()
