"""The run's estimate (printed before computing) against the run: disk and time, on small studies.

Prints, per study, the estimated and the measured Monte Carlo time, report time and report folder size and
their ratios (issue 27: within 2×).  The machines are shared: a loaded machine slows a process pool's start
and its workers more than the in-process pilot; the load average is printed beside the figures.

    PYTHONPATH=. python studies/benchmarks/bench_estimates.py [--smoke]

``--smoke``: the linear study alone, serial and on the process pool, at 2 000 samples (its own: 20 000).
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from _timing import add_size_options, by_size, print_table  # noqa: E402
from rvtol.runguard import estimate_run, time_pilot  # noqa: E402
from rvtol.study import load_study, run_study, write_outputs  # noqa: E402

STUDIES = [("linear_stackup", "serial"), ("linear_stackup", "process"), ("stack_handbook_motor", "serial"),
           ("torsion_curve_rv80e", "serial")]


def main(size: str = "full") -> None:
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    rows = []
    for name, ex in by_size(size, STUDIES[:2], STUDIES, STUDIES):
        st = load_study(ROOT / "studies" / f"{name}.toml", executor=ex, pdf=False, progress=False,
                        n=by_size(size, 2000, None, None))
        st.analyses = []          # the estimate leaves the analyses out
        est = time_pilot(estimate_run(st), st)
        res = run_study(st)
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            out = write_outputs(res, Path(tmp) / "rep")
            t_rep = time.perf_counter() - t0 + res.timings.get("report", 0.0)   # rendering + writing
            disk = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())
        mc = res.timings["monte_carlo"]
        rows.append((f"{name} ({ex}, n = {st.options.n})", f"{est.seconds:.2f} s / {mc:.2f} s",
                     f"{est.report_seconds:.1f} s / {t_rep:.1f} s", f"{est.disk / 1e6:.2f} MB / {disk / 1e6:.2f} MB",
                     f"{est.seconds / mc:.2f}×, {est.report_seconds / t_rep:.2f}×, {est.disk / disk:.2f}×"))
    print_table(rows, ("study (executor)", "MC est / run", "report est / run", "disk est / run",
                       "estimate / run: MC, report, disk"))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_size_options(ap)
    main(ap.parse_args().size)
