"""How the sign-off and the TE study scale with workers, phase by phase, with Amdahl's serial share.

Each run is ``rvtol run STUDY --no-pdf --workers W`` in a fresh process (its phases' wall times from
summary.json's ``phase_time_s``, or ``timings_s`` for code that has no profile), at W = 1, 2, … up to the
machine's cores (and on a Dask LocalCluster of 1 and the largest W, where Dask is installed).  The worker counts
are interleaved and repeated (``--repeat``): the machines are shared and their load varies, so each figure
is the best of its repeats and the load average is printed beside the table.

Per phase: the best wall time at each W (``whole run``: the run's phases together, summary.json's
``wall_time_s``; ``command``: the whole ``rvtol run`` process — Python's start, loading the study, the run and
writing the outputs), the speed-up against W = 1, and the serial share ``s`` of
Amdahl's law ``T(W) = T(1) (s + (1 − s)/W)`` fitted by least squares on ``T(W)/T(1) − 1/W = s (1 − 1/W)``.
Beside it the CPU time of the main process in the first configuration, which the load of other users does
not inflate (with one worker it includes the work ``Evaluator.map`` then does in-process).

``--code DIR`` (repeatable) runs the same studies with ``PYTHONPATH=DIR`` — e.g. a pristine checkout of
main beside this worktree, in the same session, for a before/after table.

    python studies/benchmarks/bench_scaling.py                       # sign-off at --n 300, TE at --n 1000
    python studies/benchmarks/bench_scaling.py --quick               # --n 100 / 300, 1 and 2 workers, once
    python studies/benchmarks/bench_scaling.py --smoke               # the linear study (seconds), 2 workers, projected
    python studies/benchmarks/bench_scaling.py --signoff-n 1500 --te-n 10000 --repeat 2
    python studies/benchmarks/bench_scaling.py --code /work/main --code . --only te --workers 1,2
    python studies/benchmarks/bench_scaling.py --only signoff --workers 1,2 --repeat 1 --no-dask --project 16

``--project 16`` runs the process-pool configurations with ``rvtol run --task-log`` (the CPU seconds of every task of
every parallel call) and adds, per study, a process-pool run at 16 workers with its task log.  Scheduled on 16 dedicated cores
(:mod:`rvtol.scaling`), they give the run on a machine this one is not; the same projection of the run at the
measured count sits beside that count's measured time, as the check of the method.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from _timing import add_size_options, print_table

ROOT = Path(__file__).resolve().parents[2]
#: the studies it runs: the sign-off, the TE study, and (``--smoke``) the linear stack-up (the engine alone: seconds)
STUDIES = {"signoff": "rv80e_signoff.toml", "te": "transmission_error_rv80e.toml", "linear": "linear_stackup.toml"}
#: a phase shorter than this (s) at a configuration is taken as absent there
ABSENT_S = 0.01

#: run the CLI in this process and report its own CPU time
_RUNNER = """
import json, resource, sys
from rvtol.cli import main
argv, out = sys.argv[1:-1], sys.argv[-1]
try:
    code = main(argv)
except SystemExit as e:
    code = e.code
own = resource.getrusage(resource.RUSAGE_SELF)
json.dump({"code": code, "main_cpu": own.ru_utime + own.ru_stime},
          open(out, "w"))
"""


def run_once(code_dir: Path, study: str, n: int, executor: str, workers: int, out: Path,
             task_log: bool = False) -> dict:
    """One run of ``study``: wall time, per-phase wall and parallel time, CPU of the main process and workers;
    with ``task_log``, also the run projected on as many dedicated cores as it had workers (``rvtol run
    --task-log``, :mod:`rvtol.scaling`)."""
    env = {**os.environ, "PYTHONPATH": str(code_dir)}
    cpu_file = out.with_suffix(".cpu.json")
    log = out.with_suffix(".tasks.json")
    cmd = [sys.executable, "-c", _RUNNER, "run", str(code_dir / "studies" / study), "--no-pdf", "--quiet",
           "--n", str(n), "--executor", executor, "--workers", str(workers), "--out", str(out),
           *(["--task-log", str(log)] if task_log else []), str(cpu_file)]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, cwd=code_dir, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if not cpu_file.exists():
        raise RuntimeError(f"{' '.join(cmd[3:])} failed:\n{p.stderr[-2000:]}")
    cpu = json.loads(cpu_file.read_text())
    s = json.loads((out / "summary.json").read_text())
    prof = s.get("phase_time_s") or {k: {"wall": v, "parallel": None} for k, v in s["timings_s"].items()}
    projected = json.loads(log.read_text())["projected"] if task_log else None
    return {"process": wall, "run": s["wall_time_s"], "phases": prof, "projected": projected, **cpu}


def amdahl(workers, times) -> float | None:
    """Serial share ``s`` from wall times at several worker counts (least squares; None below two counts)."""
    w = np.asarray(workers, float)
    a = 1.0 - 1.0 / w
    if len(w) < 2 or not np.any(a > 0) or not times[0] > 0:
        return None
    r = np.asarray(times, float) / times[0]
    return float(np.clip(np.sum((r - 1.0 / w) * a) / np.sum(a * a), 0.0, 1.0))


def measure(code_dirs, studies, ns, worker_counts, repeat, dask_counts, tmp: Path, task_log: bool = False) -> dict:
    """``{(code, study, config): [runs]}``, configurations interleaved inside each repeat; with ``task_log``, the
    process-pool runs also projected on their own worker count of dedicated cores."""
    configs = [("process", w) for w in worker_counts] + [("dask", w) for w in dask_counts]
    runs: dict = {}
    for rep in range(repeat):
        for st in studies:
            for executor, w in configs:
                for code in code_dirs:      # the code versions side by side at each configuration
                    key = (str(code), st, f"{executor} {w}")
                    out = tmp / f"{abs(hash(key))}_{rep}"
                    r = run_once(code, STUDIES[st], ns[st], executor, w, out, task_log and executor == "process")
                    r["load"] = os.getloadavg()[0]
                    runs.setdefault(key, []).append(r)
                    print(f"  [{rep + 1}/{repeat}] {code} {st} {executor} {w}: {r['run']:.1f} s "
                          f"(load {r['load']:.1f})", file=sys.stderr, flush=True)
    return runs


def projections(runs: dict, code_dirs, studies, ns, worker_counts, project_counts, tmp: Path) -> dict:
    """``{(code, study): {W: run}}``: at the largest measured count its best measured run (measured with its task
    log: where the projection is checked against the measurement), and one process-pool run with its task log at
    each other count to project."""
    out: dict = {}
    base = max(worker_counts)
    for st in studies:
        for code in code_dirs:
            out[(str(code), st)] = {base: min(runs[(str(code), st, f"process {base}")], key=lambda r: r["run"])}
        for w in sorted(set(project_counts) - {base}):
            for code in code_dirs:
                r = run_once(code, STUDIES[st], ns[st], "process", w, tmp / f"{abs(hash((str(code), st, w)))}_p",
                             task_log=True)
                out.setdefault((str(code), st), {})[w] = r
                print(f"  [projection] {code} {st} process {w}: {r['run']:.1f} s run here, "
                      f"{r['projected']['run_s']:.1f} s on {w} dedicated cores", file=sys.stderr, flush=True)
    return out


def report_projections(proj: dict, runs: dict, ns) -> None:
    """Per phase: the measured best at the largest measured count, the projection of a run at that count, and the
    projection at each count to project with its speed-up against the projection at the measured count."""
    for (code, st), by_w in proj.items():
        ws = sorted(by_w)
        base, targets = ws[0], ws[1:]
        measured = min(runs.get((code, st, f"process {base}"), [by_w[base]]), key=lambda r: r["run"])
        rows = []
        for ph in [*by_w[base]["projected"]["phases_s"], "whole run"]:
            def get(r):
                return r["projected"]["run_s"] if ph == "whole run" else r["projected"]["phases_s"].get(ph)
            m = measured["run"] if ph == "whole run" else measured["phases"].get(ph, {}).get("wall")
            p0 = get(by_w[base])
            cells = [f"{m:7.1f} s" if m is not None else "", f"{p0:7.1f} s"]
            for w in targets:
                p = get(by_w[w])
                cells.append(f"{p:7.1f} s ({p0 / p:.2f}×)" if p else "—")
            rows.append((ph, *cells))
        print(f"\n{STUDIES[st]} --n {ns[st]} — code {code}: projected on dedicated cores (each call's tasks by "
              f"their CPU seconds in a run with that many workers, handed out in turn; the rest as it ran: "
              f"rvtol.scaling)")
        print_table(rows, headers=("phase", f"process {base} here", f"projected at {base}",
                                   *(f"projected at {w} (against {base})" for w in targets)))


def report(runs: dict, code_dirs, studies, worker_counts, ns) -> None:
    for st in studies:
        for code in code_dirs:
            cfgs = [c for (cd, s, c) in runs if cd == str(code) and s == st]
            best = {c: min(runs[(str(code), st, c)], key=lambda r: r["run"]) for c in cfgs}
            first = best[cfgs[0]]
            phases = list(first["phases"]) + ["whole run", "command"]
            whole = {"whole run": "run", "command": "process"}
            rows = []
            for ph in phases:
                t = {c: (best[c][whole[ph]] if ph in whole else best[c]["phases"].get(ph, {}).get("wall"))
                     for c in cfgs}
                if any(v is None for v in t.values()):
                    continue
                # a phase some configurations do not have (the figures: one worker renders each as it is made,
                # inside the other phases) has no speed-up and no fit
                absent = [c for c in cfgs if t[c] < ABSENT_S]
                fits = {}
                for kind in ("process", "dask"):
                    own = [c for c in cfgs if c.startswith(kind)]
                    fits[kind] = (amdahl([int(c.split()[1]) for c in own], [t[c] for c in own])
                                  if own and not absent else None)
                par = None if ph in whole else first["phases"][ph].get("parallel")
                cells = "  ".join(f"{c}: {t[c]:7.1f} s (" + (f"{t[cfgs[0]] / t[c]:.2f}×" if not absent else "—")
                                  + (f"; {t['dask 1'] / t[c]:.2f}× Dask 1" if c.startswith("dask") and c != "dask 1"
                                     and "dask 1" in t and not absent else "") + ")" for c in cfgs)
                extra = "".join(f"  Amdahl s = {v:.0%}" + (" (Dask)" if k == "dask" else "")
                                for k, v in fits.items() if v is not None)
                if absent and len(absent) < len(cfgs):
                    extra += f"  none at {', '.join(absent)}: done inside the other phases there"
                if par is not None and t[cfgs[0]] > 0:
                    extra += f"  in parallel evaluation at 1 worker: {par / t[cfgs[0]]:.0%}"
                rows.append((ph, cells, extra))
            loads = [r["load"] for c in cfgs for r in runs[(str(code), st, c)]]
            print(f"\n{STUDIES[st]} --n {ns[st]} — code {code}; best of "
                  f"{len(runs[(str(code), st, cfgs[0])])}; load average {min(loads):.1f}–{max(loads):.1f} "
                  f"on {os.cpu_count()} cores; CPU time of the main process at {cfgs[0]}: "
                  f"{first['main_cpu']:.1f} s")
            print_table(rows, headers=("phase", "wall time (speed-up against the first column)", ""))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", default="signoff,te", help="studies: signoff, te, linear (comma-separated)")
    ap.add_argument("--signoff-n", type=int, default=300, help="sign-off samples (the study's own: 1500)")
    ap.add_argument("--te-n", type=int, default=1000, help="TE study samples (the study's own: 10000)")
    ap.add_argument("--linear-n", type=int, default=20000, help="linear stack-up samples (the study's own: 20000)")
    ap.add_argument("--workers", default=None, help="worker counts, e.g. 1,2,4 (default 1 … cores)")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--code", action="append", default=None, help="a checkout to run (repeatable; default: this one)")
    ap.add_argument("--no-dask", action="store_true", help="skip the Dask LocalCluster")
    ap.add_argument("--dask-workers", default=None,
                    help="Dask LocalCluster worker counts (default: 1 and the largest of --workers)")
    ap.add_argument("--save", type=Path, help="also write every run's figures to this JSON file")
    add_size_options(ap)
    ap.add_argument("--project", default=None, help="worker counts to project the run on, e.g. 16 (rvtol.scaling: "
                    "a run with that many workers on this machine, its tasks' CPU times scheduled on as many cores)")
    a = ap.parse_args()
    if a.size == "quick":      # sign-off --n 100, TE --n 300, one repeat, 1 and 2 workers
        a.signoff_n, a.te_n, a.repeat, a.workers = 100, 300, 1, a.workers or "1,2"
    elif a.size == "smoke":    # every code path (task log and projection too) on the linear study, no Dask
        a.only, a.linear_n, a.repeat, a.workers, a.no_dask = "linear", 2000, 1, "2", True
        a.project = a.project or "2"
    counts = ([int(w) for w in a.workers.split(",")] if a.workers
              else list(range(1, (os.cpu_count() or 1) + 1)))
    try:
        import dask.distributed  # noqa: F401
        dask = not a.no_dask
    except ImportError:
        dask = False
    dask_counts = ([int(w) for w in a.dask_workers.split(",")] if a.dask_workers
                   else sorted({1, max(counts)})) if dask else []
    code_dirs = [Path(c).resolve() for c in (a.code or [ROOT])]
    studies = [s for s in a.only.split(",") if s]
    ns = {"signoff": a.signoff_n, "te": a.te_n, "linear": a.linear_n}
    project_counts = [int(w) for w in a.project.split(",")] if a.project else []
    with tempfile.TemporaryDirectory(prefix="bench_scaling_") as tmp:
        runs = measure(code_dirs, studies, ns, counts, a.repeat, dask_counts, Path(tmp), bool(project_counts))
        proj = projections(runs, code_dirs, studies, ns, counts, project_counts, Path(tmp)) if project_counts else {}
    if a.save:
        a.save.write_text(json.dumps({**{" | ".join(k): v for k, v in runs.items()},
                                      **{f"{c} | {st} | projection": v for (c, st), v in proj.items()}}, indent=1))
    report(runs, code_dirs, studies, counts, ns)
    report_projections(proj, runs, ns)


if __name__ == "__main__":
    main()
