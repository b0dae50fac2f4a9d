"""Runs that survive CI, through the real CLI (a subprocess wherever a signal or kill -9 is involved).

* kill -9 in the middle of a run, then ``--resume``: the result is bit-identical (summary.json numbers,
  samples.parquet bytes) to an uninterrupted run, and the killed run's workers do not outlive it;
* SIGTERM / SIGINT: exit 143 / 130 within seconds, one line on stderr, no process left, no output or
  temporary folder (only the named checkpoint for --resume);
* a lock: a second run to the same --out is refused (exit 2); stale temporary folders of killed runs are
  removed; an unwritable --out, an absurd n and a full disk are exit 2 before anything is computed.
"""
import glob
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

from rvtol.cli import main

from conftest import ROOT

STUDY = f"""
[study]
name = "stiff"
design = "{ROOT}/data/designs/rv80e_stiffness.toml"
spec = "{ROOT}/data/specs/rv80e_stiffness.toml"
[model]
kind = "torsional_stiffness"
torque = {{ value = 784, unit = "N*m" }}
[sampling]
n = 6000
method = "lhs"
seed = 7
[[requirement]]
output = "pin_backlash"
upper = 1.0
unit = "arcmin"
"""

#: 60 chunks of 100 samples (~30 ms each): long enough to be interrupted in the middle
ARGS = ["--no-pdf", "--quiet", "--chunk-size", "100"]


@pytest.fixture
def study(tmp_path) -> Path:
    p = tmp_path / "stiff.toml"
    p.write_text(STUDY)
    return p


def _env():
    return dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))


def start(study: Path, out: Path, *extra) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "rvtol", "run", str(study), "--out", str(out), *ARGS, *extra],
                            env=_env(), cwd=study.parent, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)


def chunks(out: Path) -> list[str]:
    return glob.glob(str(out.parent / f".{out.name}.rvtol-run" / "chunks" / "*.npz"))


def wait_for_chunks(p: subprocess.Popen, out: Path, k: int) -> None:
    deadline = time.monotonic() + 60
    while len(chunks(out)) < k:
        assert p.poll() is None, f"the run ended before {k} chunks were done: {p.communicate()}"
        assert time.monotonic() < deadline, "no progress"
        time.sleep(0.01)


def wait_gone(procs, timeout=10.0) -> list[int]:
    deadline = time.monotonic() + timeout
    while True:
        alive = [q.pid for q in procs if q.is_running() and q.status() != psutil.STATUS_ZOMBIE]
        if not alive or time.monotonic() > deadline:
            return alive
        time.sleep(0.1)


def numbers(summary_path: Path) -> dict:
    s = json.loads(summary_path.read_text())
    for k in ("created", "executor", "wall_time_s", "timings_s", "phase_time_s"):  # when, on what, how fast: not results
        s.pop(k)
    return s


def test_kill_9_mid_run_then_resume_is_bit_identical(study, tmp_path):
    out = tmp_path / "killed"
    p = start(study, out, "--executor", "process", "--workers", "2")
    wait_for_chunks(p, out, 8)
    workers = psutil.Process(p.pid).children(recursive=True)
    os.kill(p.pid, signal.SIGKILL)
    assert p.wait(timeout=30) == -signal.SIGKILL
    assert not out.exists()
    kept = len(chunks(out))
    assert 8 <= kept < 60
    assert wait_gone(workers) == [], "workers outlived the killed run"

    r = subprocess.run([sys.executable, "-m", "rvtol", "run", str(study), "--out", str(out), *ARGS,
                        "--executor", "serial", "--resume"],  # (any executor: chunks are the same)
                       env=_env(), cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert f"resuming: {kept} finished chunks" in r.stderr
    assert f"resumed: {kept} chunks ({100 * kept} evaluations) reused, {60 - kept} computed" in r.stderr

    ref = tmp_path / "uninterrupted"  # in-process: the same CLI
    assert main(["run", str(study), "--out", str(ref), *ARGS, "--executor", "serial"]) == 0
    assert numbers(out / "summary.json") == numbers(ref / "summary.json")
    assert (out / "samples.parquet").read_bytes() == (ref / "samples.parquet").read_bytes()
    assert sorted(q.name for q in tmp_path.iterdir()) == ["killed", "stiff.toml", "uninterrupted"]


@pytest.mark.parametrize("sig,code,group", [(signal.SIGTERM, 143, False), (signal.SIGINT, 130, True)])
def test_a_signal_stops_the_workers_and_leaves_no_process_and_no_folder(study, tmp_path, sig, code, group):
    """SIGTERM to the run (a CI cancel); SIGINT to the process group (Ctrl-C in a terminal)."""
    out = tmp_path / "out"
    p = start(study, out, "--executor", "process", "--workers", "2")
    wait_for_chunks(p, out, 3)
    procs = psutil.Process(p.pid).children(recursive=True)
    assert len(procs) >= 2  # the pool's workers (and the fork server, the resource tracker)
    (os.killpg if group else os.kill)(p.pid, sig)
    _, err = p.communicate(timeout=30)
    assert p.returncode == code, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"rvtol: stopped by {sig.name}: workers stopped, nothing written"), err
    assert "rerun with --resume" in lines[0]
    assert wait_gone(procs) == []
    # nothing half-written: no output folder, no temporary folder; only the checkpoint the message names
    assert sorted(q.name for q in tmp_path.iterdir()) == [".out.rvtol-run", "stiff.toml"]
    assert sorted(q.name for q in (tmp_path / ".out.rvtol-run").iterdir()) == ["chunks", "lock", "run.json"]


def test_two_runs_never_write_one_folder(study, tmp_path, capsys):
    out = tmp_path / "out"
    p = start(study, out, "--executor", "serial")
    try:
        wait_for_chunks(p, out, 2)
        rc = main(["run", str(study), "--out", str(out), "--no-pdf", "--quiet", "--executor", "serial", "--n", "100"])
        err = capsys.readouterr().err.strip()
        assert rc == 2 and err == (f"rvtol: error: {out}: --out: another rvtol run (pid {p.pid}) is writing this "
                                   "folder; wait for it or choose another --out")
    finally:
        os.kill(p.pid, signal.SIGTERM)
        p.communicate(timeout=30)
    assert p.returncode == 143


def test_stale_folders_of_killed_runs_are_removed(study, tmp_path):
    out = tmp_path / "out"
    out.mkdir()   # killed after its last rename: the new folder is in place, the one it replaced is stale
    (out / "summary.json").write_text('{"format": "rvtol-summary/1"}')
    for stale in (".out.tmp-0123456789ab", ".out.old-0123456789ab", ".out.rvtol-run/chunks"):
        (tmp_path / stale).mkdir(parents=True)
        (tmp_path / stale / "x").write_text("left by a killed run")
    (tmp_path / ".out.rvtol-run" / "lock").write_text("12345\n")  # a lock nobody holds
    assert main(["run", str(study), "--out", str(out), "--no-pdf", "--quiet", "--executor", "serial",
                 "--n", "300"]) in (0, 1)  # (300 samples do not demonstrate the yield: FAIL, beside the point)
    assert sorted(q.name for q in tmp_path.iterdir()) == ["out", "stiff.toml"]


def test_out_memory_and_disk_are_checked_before_computing(study, tmp_path, capsys, monkeypatch):
    def run(*extra):
        rc = main(["run", str(study), "--no-pdf", "--quiet", "--executor", "serial", *extra])
        return rc, capsys.readouterr().err.strip().splitlines()

    (tmp_path / "a_file").write_text("")
    rc, err = run("--out", str(tmp_path / "a_file" / "report"))
    assert rc == 2 and err == [f"rvtol: error: {tmp_path / 'a_file' / 'report'}: --out: {tmp_path / 'a_file'} is not a folder"]
    rc, err = run("--out", "/proc/rvtol-report")  # a file system nobody can create files in
    assert rc == 2 and len(err) == 1 and err[0].startswith("rvtol: error: /proc/rvtol-report: --out: cannot write in /proc")
    rc, err = run("--out", str(tmp_path / "r"), "--n", str(10**12))
    assert rc == 2 and len(err) == 1 and err[0].startswith("rvtol: error: <command line>: --n: n = 1,000,000,000,000 "
                                                           "needs about ") and "of memory" in err[0]
    import rvtol.runguard as rg

    monkeypatch.setattr(rg.shutil, "disk_usage", lambda p: type("U", (), {"free": 1000})())
    rc, err = run("--out", str(tmp_path / "r"), "--n", "200")
    assert rc == 2 and len(err) == 1 and err[0].startswith(f"rvtol: error: {tmp_path / 'r'}: --out: the run needs about")
    assert sorted(q.name for q in tmp_path.iterdir()) == ["a_file", "stiff.toml"]  # nothing written


def test_the_estimate_is_printed_before_the_run(study, tmp_path, capsys):
    assert main(["run", str(study), "--out", str(tmp_path / "o"), "--no-pdf", "--executor", "serial",
                 "--n", "300"]) in (0, 1)
    err = capsys.readouterr().err
    assert "rvtol: estimate: 300 samples × " in err and "ms/sample in a pilot" in err


def test_the_checkpoint_keeps_every_monte_carlo_chunk_and_only_costly_analysis_chunks(tmp_path, monkeypatch):
    import numpy as np

    import rvtol.checkpoint as cp
    from rvtol.mc import evaluate
    from rvtol.testing import FlakyModel

    model = FlakyModel(threshold=0.5)
    X = np.random.default_rng(0).random((1000, 2))
    ref = evaluate(model, X, chunk_size=100, progress=False)
    store = cp.ChunkStore(tmp_path / "chunks")
    evaluate(model, X, chunk_size=100, progress=False, store=store, persist="all")   # the Monte Carlo
    evaluate(model, X, chunk_size=100, progress=False, store=store)                  # an analysis: cheap chunks
    assert store.saved == 10 and store.count() == 10
    monkeypatch.setattr(cp, "COSTLY_SECONDS", 0.0)
    evaluate(model, X[:300], chunk_size=100, progress=False, store=store)            # costly ones are kept
    assert store.count() == 13
    monkeypatch.undo()
    # a resumed run numbers its evaluations the same way and reuses them, bit for bit
    again = cp.ChunkStore(tmp_path / "chunks")
    a = evaluate(model, X, chunk_size=100, progress=False, store=again, persist="all")
    evaluate(model, X, chunk_size=100, progress=False, store=again)
    b = evaluate(model, X[:300], chunk_size=100, progress=False, store=again)
    assert again.reused == 13 and again.saved == 0
    assert a.Y.tobytes() == ref.Y.tobytes() and a.status.tobytes() == ref.status.tobytes()
    assert b.Y.tobytes() == ref.Y[:300].tobytes()
    # other rows under the same call number are not mistaken for the kept ones
    other = cp.ChunkStore(tmp_path / "chunks")
    c = evaluate(model, X[::-1].copy(), chunk_size=100, progress=False, store=other, persist="all")
    assert other.reused == 0 and c.Y.tobytes() == ref.Y[::-1].tobytes()


def test_a_stop_signal_while_a_chunk_is_written_stops_the_run_after_the_file_is_whole(tmp_path, monkeypatch):
    """SIGTERM arriving inside numpy.savez (a CI cancel at the wrong moment, seen once under load): the run stops with
    Interrupted once the chunk file is whole — it ended as an internal error, the ZIP archive refusing to close over
    its half-written member ("Can't close the ZIP file while there is an open writing handle")."""
    import signal

    import numpy as np

    import rvtol.checkpoint as cp
    from rvtol.runguard import Interrupted, stopping_on_signals

    savez = np.savez

    class SignalOnFirstWrite:               # the file savez writes into: SIGTERM to this process at its first write
        def __init__(self, f):
            self.f, self.sent = f, False

        def write(self, b):
            if not self.sent:
                self.sent = True
                os.kill(os.getpid(), signal.SIGTERM)
            return self.f.write(b)

        def __getattr__(self, name):
            return getattr(self.f, name)

    monkeypatch.setattr(np, "savez", lambda f, **arrays: savez(SignalOnFirstWrite(f), **arrays))
    store = cp.ChunkStore(tmp_path / "chunks")
    call = store.begin("all")
    X, Y, status = np.zeros((3, 2)), np.arange(6.0).reshape(3, 2), np.zeros(3, dtype=np.int16)
    with pytest.raises(Interrupted) as ei:
        with stopping_on_signals():
            call.put(0, 3, X, Y, status)
    assert ei.value.signum == signal.SIGTERM and cp.HELD == {"depth": 0, "pending": None}
    monkeypatch.undo()
    got = cp.ChunkStore(tmp_path / "chunks").begin("all").get(0, 3, X)      # the chunk was kept whole
    assert got is not None and got[0].tobytes() == Y.tobytes() and store.count() == 1
