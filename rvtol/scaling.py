"""How long a run would take on more cores than the machine that ran it.

A run made with ``W`` workers and its parallel calls recorded (:func:`rvtol.mc.recording_calls`; ``rvtol run
--task-log``) knows, for each call, the CPU seconds of every task its workers ran.  On ``W`` dedicated cores a call
takes the time a pool needs to hand those tasks out in order, each to the first free worker (list scheduling:
:func:`makespan`), and the rest of the run — this process's own work between and around the calls — takes what it
took.  So a run made with ``--workers 16`` on a 2-core machine (the tasks share the cores, but each one's CPU time is
its own) gives the run on 16 cores (:func:`projected`).

What it leaves out: each call's cost of handing tasks out and taking results back (a process pool's 1–2 ms a call, a
Dask cluster's 10–16 ms on the machines this was measured on: :func:`projected`'s ``per_call``), a first call's wait
for the workers to start (a run whose study loads for a while hides it), the memory bandwidth the tasks would share
on a larger machine, and tasks that finish in another order there.  The tasks are this run's:
their number follows its worker count (:func:`rvtol.mc.auto_chunk_size`), so project a run made with the worker
count to project.
"""
from __future__ import annotations

import heapq
from typing import Iterable, Sequence

#: the version tag of ``--task-log``'s JSON (by which a later run recognises a file it may replace)
TASK_LOG_FORMAT = "rvtol-task-log/1"


def makespan(tasks: Sequence[float], workers: int) -> float:
    """Seconds for ``workers`` workers to run ``tasks`` (seconds each), each task to the first free worker in turn."""
    free = [0.0] * max(1, int(workers))
    for d in tasks:
        heapq.heappush(free, heapq.heappop(free) + float(d))
    return max(free)


def projected(wall: float, calls: Iterable[dict], workers: int, per_call: float = 0.0) -> float:
    """A phase (or a run) of ``wall`` seconds whose parallel calls were ``calls`` (:func:`rvtol.mc.recording_calls`),
    on ``workers`` dedicated cores: its calls' tasks scheduled by :func:`makespan` (plus ``per_call`` seconds each),
    the rest as it was.  A call with no tasks listed ran in this process and stays as it was."""
    out = float(wall)
    for c in calls:
        if c["tasks"]:
            out += makespan(c["tasks"], workers) + per_call - c["wall"]
    return out


def task_log(result) -> dict:
    """``rvtol run --task-log``'s content: each phase of a run (:class:`rvtol.study.StudyResult` made with
    ``record_calls``) with its wall time and its parallel calls, and the run projected on as many dedicated cores
    as it had workers (:func:`projected`)."""
    calls = result.calls or {}
    phases = {name: {"wall_s": wall, "parallel_s": result.parallel.get(name, 0.0),
                     "calls": [{"wall_s": round(c["wall"], 6), "tasks_cpu_s": [round(t, 6) for t in c["tasks"]]}
                               for c in calls.get(name, [])]}
              for name, wall in result.timings.items()}
    w = result.workers
    every = [c for cs in calls.values() for c in cs]
    return {
        "format": TASK_LOG_FORMAT, "study": result.study.name, "executor": result.executor, "workers": w,
        "run_s": result.elapsed,
        "projected": {
            "workers": w, "run_s": projected(result.elapsed, every, w),
            "phases_s": {name: projected(wall, calls.get(name, []), w) for name, wall in result.timings.items()},
            "method": f"each call's tasks (their CPU seconds) handed out in turn to {w} dedicated cores, the rest of "
                      "the run as it was; leaves out the cost of handing tasks out and results back (rvtol.scaling)"},
        "phases": phases}
