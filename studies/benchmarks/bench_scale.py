"""The engine and the report at 10⁴, 10⁵ and 10⁶ samples for the cheap models: time, memory, report size.

For each model (linear, lost motion, stack-up: the models of ``linear_stackup.toml``,
``lost_motion_rv80e.toml`` and ``stackup_rv_crank_chain.toml``, without their analyses) and each n, a fresh
process runs the study as ``rvtol run`` would — Monte Carlo on the study's executor, statistics, verdicts,
convergence, the sign-off digest, ``summary.json``, ``samples.parquet``, ``report.html`` (no PDF) — and
reports the wall time of each phase, the peak resident memory (``resource.getrusage``) and the peak of
Python/NumPy allocations (``tracemalloc``, which NumPy reports to), and the size of each file.  The table
gives each phase's time per sample as a ratio to the smallest n (1.0 = linear) and the memory per sample.

Side by side, the plain-NumPy reference: the same model's ``evaluate`` on the same samples in one call
(no chunks, no executor, no statistics) — what the engine adds.

    python studies/benchmarks/bench_scale.py [--quick | --smoke] [--models linear,lost_motion,stackup] [--sizes 1e4,1e5,1e6]

``--quick``: 10⁴ and 10⁵ only; ``--smoke``: the linear model at 10³ and 2·10³ on the serial executor.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

from _timing import add_size_options, by_size, print_table

ROOT = Path(__file__).resolve().parents[2]
STUDIES = {"linear": "linear_stackup.toml", "lost_motion": "lost_motion_rv80e.toml",
           "stackup": "stackup_rv_crank_chain.toml"}


def one(model: str, n: int, trace: bool, executor: str | None = None) -> dict:
    """Run one study in this process; the figures as a dict."""
    from rvtol.study import load_study, run_study, write_outputs

    if trace:
        tracemalloc.start()
    t = {}
    t0 = time.perf_counter()
    st = load_study(ROOT / "studies" / STUDIES[model], n=n, pdf=False, progress=False, executor=executor)
    st.analyses = []
    t["load"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    res = run_study(st)
    t["monte_carlo"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    res.mc.statistics()
    res.mc.verdicts()
    res.mc.convergence()
    t["statistics"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    res.signoff    # noqa: B018  (the digest: given-data indices of every requirement)
    t["signoff_digest"] = time.perf_counter() - t0
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "r"
        t0 = time.perf_counter()
        write_outputs(res, out)
        t["report"] = time.perf_counter() - t0
        sizes = {f.name: f.stat().st_size for f in out.iterdir()}
    peak_py = tracemalloc.get_traced_memory()[1] if trace else None
    # plain NumPy: the model on the same samples in one call
    t0 = time.perf_counter()
    st.model.evaluate_with_status(res.mc.samples.values)
    t["numpy_direct"] = time.perf_counter() - t0
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    return {"model": model, "n": n, "times": t, "sizes": sizes, "peak_rss": rss, "peak_traced": peak_py,
            "executor": res.executor}


def run_child(model: str, n: int, trace: bool, executor: str | None) -> dict:
    cmd = ([sys.executable, __file__, "--one", model, str(n)] + (["--trace"] if trace else [])
           + (["--executor", executor] if executor else []))
    env = dict(os.environ)
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env).stdout
    return json.loads(out.strip().splitlines()[-1])


def main(models: list[str], sizes: list[int], executor: str | None = None) -> list:
    rows = []
    for m in models:
        base = None
        for n in sizes:
            r = run_child(m, n, True, executor)
            # time without tracemalloc (it slows allocation-heavy code): a second child
            r2 = run_child(m, n, False, executor)
            t = r2["times"]
            total = sum(v for k, v in t.items() if k not in ("load", "numpy_direct"))
            if base is None:
                base = (n, t, total)
            n0, t0, tot0 = base
            lin = {k: (t[k] / n) / (t0[k] / n0) if t0[k] > 0 else float("nan") for k in t}
            rows.append((f"{m}, n = {n:.0e}", f"{n / total:,.0f} samples/s",
                         f"MC {t['monte_carlo']:.2f} s ({r2['executor']}), statistics {t['statistics']:.2f} s, "
                         f"digest {t['signoff_digest']:.2f} s, report {t['report']:.2f} s; plain NumPy evaluate "
                         f"{t['numpy_direct']:.2f} s (engine MC / NumPy: {t['monte_carlo'] / t['numpy_direct']:.1f}×)"))
            rows.append(("", f"{r2['peak_rss'] / 2**20:,.0f} MiB RSS",
                         f"traced peak {r['peak_traced'] / 2**20:,.0f} MiB = {r['peak_traced'] / n:,.0f} B/sample; "
                         f"files: " + ", ".join(f"{k} {v / 2**20:.2f} MiB" for k, v in sorted(r2['sizes'].items()))))
            if n != n0:
                rows.append(("", "time/sample vs n = %.0e" % n0,
                             ", ".join(f"{k} {v:.2f}" for k, v in lin.items() if k != "load")
                             + f"; total {(total / n) / (tot0 / n0):.2f} (1.00 = linear)"))
    print_table(rows, ("model, samples", "value", "notes"))
    return rows


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_size_options(ap)
    ap.add_argument("--models", default=None, help=f"comma-separated subset of {', '.join(STUDIES)} (default all)")
    ap.add_argument("--sizes", default=None)
    ap.add_argument("--executor", default=None, help="serial | process | dask (default: the study's; --smoke: serial)")
    ap.add_argument("--one", nargs=2, metavar=("MODEL", "N"), help=argparse.SUPPRESS)
    ap.add_argument("--trace", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.one:
        print(json.dumps(one(a.one[0], int(a.one[1]), a.trace, a.executor)))
    else:
        sizes = ([int(float(s)) for s in a.sizes.split(",")] if a.sizes else
                 by_size(a.size, [1000, 2000], [10**4, 10**5], [10**4, 10**5, 10**6]))
        models = a.models.split(",") if a.models else by_size(a.size, ["linear"], list(STUDIES), list(STUDIES))
        main(models, sizes, a.executor or by_size(a.size, "serial", None, None))
