"""A run projected on more cores (rvtol.scaling): list scheduling by hand, the workers' CPU clock, the task log.

References: hand-scheduled task lists; a task that burns a known CPU time and one that only sleeps.  No wall-clock
assertions: what is checked is what a clock cannot make flaky (a busy loop's own CPU time, a sleep's lack of it,
counts and sums)."""
import json
import time

import pytest

from rvtol.cli import main
from rvtol.executors import make_executor, recording_task_cpu
from rvtol.scaling import makespan, projected

from conftest import ROOT


@pytest.mark.parametrize("workers, expected", [(1, 12.0), (2, 7.0), (3, 5.0), (5, 3.0), (16, 3.0)])
def test_tasks_are_handed_out_in_turn_to_the_first_free_worker(workers, expected):
    """[3, 3, 2, 2, 2] on 2 workers: 3 | 3, then 2 → the first (5), 2 → the second (5), 2 → the first (7);
    on 3: 3 | 3 | 2, then 2 → the third (4), 2 → the first free of 3, 3, 4 (5)."""
    assert makespan([3, 3, 2, 2, 2], workers) == expected


def test_a_free_worker_takes_the_next_task_not_the_next_in_a_round():
    """[5, 1, 1, 1, 1, 1] on 2 workers: the second worker takes every 1-s task while the first runs the 5-s one (5 s);
    handed out in rounds (1, 3, 5 to the first) it would take 7 s, sorted longest first 5 s as well — and
    [1, 1, 1, 1, 1, 5] in turn ends with the 5-s task on a worker free at 2 s (7 s): the order counts."""
    assert makespan([5, 1, 1, 1, 1, 1], 2) == 5.0
    assert makespan([1, 1, 1, 1, 1, 5], 2) == 7.0


def test_a_projection_replaces_each_call_by_its_schedule_and_keeps_the_rest():
    """A 10 s phase with a 4 s call of four 2-s tasks and a 1 s call run in this process (no tasks): on 2 cores
    6 + 4 + 0 = 10 s, on 4 cores 6 + 2 = 8 s, and 0.5 s more with a per-call cost (one call has tasks)."""
    calls = [{"wall": 4.0, "tasks": [2.0, 2.0, 2.0, 2.0]}, {"wall": 1.0, "tasks": []}]
    assert projected(10.0, calls, 2) == pytest.approx(10.0)
    assert projected(10.0, calls, 4) == pytest.approx(8.0)
    assert projected(10.0, calls, 4, per_call=0.5) == pytest.approx(8.5)


def _burn(seconds):
    t0 = time.thread_time()
    while time.thread_time() - t0 < seconds:
        pass
    return seconds


def _nap(seconds):
    time.sleep(seconds)
    return seconds


@pytest.mark.parametrize("kind", ["process", "dask"])
def test_a_task_is_timed_by_its_workers_cpu_clock_not_the_wall(kind):
    with make_executor(kind, 2) as ex, recording_task_cpu() as cpu:
        done = dict(ex.imap(_burn, [(0.15,), (0.15,)]))
        assert done == {0: 0.15, 1: 0.15}
        assert len(cpu) == 2 and min(cpu) >= 0.15
        list(ex.imap(_nap, [(0.3,)]))
        assert len(cpu) == 3 and cpu[2] < 0.15
    with make_executor(kind, 2) as ex:             # not recording: nothing is kept
        assert sorted(r for _, r in ex.imap(_burn, [(0.01,)])) == [0.01]


def test_the_task_log_lists_each_phases_calls_and_projects_the_run(tmp_path):
    log = tmp_path / "logs" / "tasks.json"
    rc = main(["run", str(ROOT / "studies" / "linear_stackup.toml"), "--out", str(tmp_path / "r"), "--n", "4000",
               "--executor", "process", "--workers", "2", "--quiet", "--no-pdf", "--task-log", str(log)])
    assert rc == 0
    d = json.loads(log.read_text())
    assert d["workers"] == 2 and d["projected"]["workers"] == 2
    mc = d["phases"]["monte_carlo"]
    # 4000 samples on 2 workers: 4 chunks a worker (rvtol.mc.auto_chunk_size), in one call
    assert len(mc["calls"]) == 1 and len(mc["calls"][0]["tasks_cpu_s"]) == 8
    assert all(t >= 0 for ph in d["phases"].values() for c in ph["calls"] for t in c["tasks_cpu_s"])
    calls = [{"wall": c["wall_s"], "tasks": c["tasks_cpu_s"]} for ph in d["phases"].values() for c in ph["calls"]]
    assert d["projected"]["run_s"] == pytest.approx(projected(d["run_s"], calls, 2), rel=1e-5)
    assert not list(log.parent.glob(".*"))             # no temporary file left beside it


@pytest.mark.parametrize("flag", ["--task-log", "--junit"])
@pytest.mark.parametrize("where", ["the folder", "inside"])
def test_a_file_the_report_folder_would_replace_is_refused_before_the_run(tmp_path, capsys, flag, where):
    out = tmp_path / "r"
    target = out if where == "the folder" else out / "summary.json"
    rc = main(["run", str(ROOT / "studies" / "linear_stackup.toml"), "--out", str(out), "--n", "100", "--quiet",
               flag, str(target)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and flag in err[0] and "report folder" in err[0]
    assert not out.exists()


def test_a_task_log_that_cannot_be_written_stops_the_run_before_it_starts(tmp_path, capsys):
    rc = main(["run", str(ROOT / "studies" / "linear_stackup.toml"), "--out", str(tmp_path / "r"), "--n", "100",
               "--quiet", "--task-log", str(tmp_path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "--task-log" in err[0] and "is a folder" in err[0]
    assert not (tmp_path / "r").exists()
