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
* ``bench_pce`` — the PCE's OMP before/after, against OpenTURNS' and scikit-learn's LARS;
* ``bench_estimates`` — the run's printed estimate (time, disk) against the run;
* ``bench_stackup``, ``bench_stiffness``, ``bench_sensitivity``, ``bench_allocation`` — the other models'
  building blocks;
* ``bench_fe_cache`` — the product's finite-element seats built in a fresh process with a cold cache against a
  warm one;
* ``bench_tail`` — the tail estimates (FORM, SORM, importance sampling, subset) against OpenTURNS called directly
  on the same function, 2 and 50 factors;
* ``bench_multifidelity`` — multi-fidelity Monte Carlo against plain Monte Carlo at equal interval width (a closed
  form; the sign-off's 20-DOF lost motion and TE with a surrogate learned from 20-DOF runs, the lost motion also with
  the frictionless torsion curve; training and pilot runs charged).

Every script also takes ``--smoke`` (seconds, figures meaningless): ``tests/benchmarks/test_benchmarks_smoke.py`` runs
each so.

    python studies/benchmarks/run_all.py            # quick sizes (about 10 minutes on 2 cores)
    python studies/benchmarks/run_all.py --full     # the sizes quoted in the notes (10⁶ samples: longer)
    python studies/benchmarks/run_all.py --only transmission,gsa
    python studies/benchmarks/run_all.py --smoke    # every script at its smoke size
    python studies/benchmarks/run_all.py --list     # the commands, without running them
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ORDER = ("transmission", "gsa", "mc", "scale", "dask", "openturns", "pce", "stackup", "stiffness", "sensitivity",
         "allocation", "estimates", "scaling", "fe_cache", "tail", "multifidelity")


def command(name: str, size: str) -> list[str]:
    """The command line of ``bench_<name>.py`` at ``size`` (smoke, quick or full)."""
    return [sys.executable, str(HERE / f"bench_{name}.py")] + ([] if size == "full" else [f"--{size}"])


def main(size: str, only: list[str]) -> int:
    failed = []
    for name in only:
        cmd = command(name, size)
        print(f"\n=== bench_{name} {' '.join(cmd[2:])}", flush=True)
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
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--full", dest="size", action="store_const", const="full",
                   help="the full sizes (default: --quick for every script)")
    g.add_argument("--smoke", dest="size", action="store_const", const="smoke",
                   help="the smoke sizes (seconds each; what the test suite runs)")
    ap.set_defaults(size="quick")
    ap.add_argument("--only", default=",".join(ORDER), help="comma-separated subset of: " + ", ".join(ORDER))
    ap.add_argument("--list", action="store_true", help="print the commands, one a line, and run nothing")
    a = ap.parse_args()
    names = [s.strip() for s in a.only.split(",") if s.strip()]
    bad = [s for s in names if s not in ORDER]
    if bad:
        ap.error(f"unknown benchmark(s) {', '.join(bad)} (known: {', '.join(ORDER)})")
    if a.list:
        print("\n".join(" ".join(command(n, a.size)) for n in names))
        sys.exit(0)
    sys.exit(main(a.size, names))
