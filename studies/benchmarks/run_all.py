"""Every benchmark of ``studies/benchmarks/`` in one command, their tables one after the other.

Each script measures its figures as ratios against a reference implementation run side by side in its
own process (the machines are shared and noisy: compare ratios, not seconds):

* ``bench_transmission`` — the 20-DOF kernels before/after (the starting commit's kernels against today's),
  numba against the NumPy twin, the arithmetic limit per equilibrium and per Newmark step and the fraction
  achieved, Monte Carlo throughput on 1 core and 2 workers;
* ``bench_gsa`` — global sensitivity from the Monte Carlo samples (given data, PCE) against Saltelli: cost
  as a fraction of the Monte Carlo and agreement of the indices;
* ``bench_mc``, ``bench_scale`` — the engine's overhead, and 10⁴ … 10⁶ samples of the cheap models: time per
  sample by phase, peak memory, report size (linear = 1.0);
* ``bench_dask`` — process pool against Dask (LocalCluster, scheduler address);
* ``bench_scaling`` — the sign-off and the TE study at 1 … cores workers (and a Dask LocalCluster), phase by
  phase, with Amdahl's serial share;
* ``bench_openturns`` — rvtol against OpenTURNS on the same Monte Carlo and Sobol work (benchmark extra);
* ``bench_stackup``, ``bench_stiffness``, ``bench_sensitivity``, ``bench_allocation`` — the other models'
  building blocks.

    python studies/benchmarks/run_all.py            # quick sizes (about 10 minutes on 2 cores)
    python studies/benchmarks/run_all.py --full     # the sizes quoted in the notes (10⁶ samples: longer)
    python studies/benchmarks/run_all.py --only transmission,gsa
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ORDER = ("transmission", "gsa", "mc", "scale", "dask", "openturns", "stackup", "stiffness", "sensitivity",
         "allocation", "scaling")


def main(full: bool, only: list[str]) -> int:
    failed = []
    for name in only:
        cmd = [sys.executable, str(HERE / f"bench_{name}.py")] + ([] if full else ["--quick"])
        print(f"\n=== bench_{name} {'' if full else '--quick'}", flush=True)
        t0 = time.perf_counter()
        rc = subprocess.call(cmd, cwd=HERE.parents[1])
        print(f"--- bench_{name}: {time.perf_counter() - t0:.0f} s" + ("" if rc == 0 else f", exit code {rc}"), flush=True)
        if rc != 0:
            failed.append(name)
    if failed:
        print(f"\nfailed: {', '.join(failed)}")
    return 1 if failed else 0


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true", help="the full sizes (default: --quick for every script)")
    ap.add_argument("--only", default=",".join(ORDER), help="comma-separated subset of: " + ", ".join(ORDER))
    a = ap.parse_args()
    names = [s.strip() for s in a.only.split(",") if s.strip()]
    bad = [s for s in names if s not in ORDER]
    if bad:
        ap.error(f"unknown benchmark(s) {', '.join(bad)} (known: {', '.join(ORDER)})")
    sys.exit(main(a.full, names))
