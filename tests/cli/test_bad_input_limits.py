"""Issue 37's bad inputs that were an internal error (exit 3) or accepted without a word: each is now one line,
exit 2, before anything is computed."""
import pytest

from conftest import ab_study, run_cli, write


def run(args, capsys):
    return run_cli(args, capsys)


# --------------------------------------------------------------------------- exit 3 on bad input
def test_a_study_name_too_long_for_a_folder_is_refused_at_its_key(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    p = write(tmp_path / "s.toml", ab_study("x" * 300, n=200))
    rc, err = run(["run", p, "--quiet"], capsys)
    assert rc == 2 and err == [f"rvtol: error: {p}: study.name: the study name is 300 bytes long, and it names the "
                               "report folder: at most 237 (a file name's 255, less the temporary names rvtol gives "
                               "beside it); give a shorter name"]
    assert run(["check", p], capsys)[0] == 2           # check says so too, before any run
    # 237 bytes (multi-byte characters counted as bytes) is the longest that runs, with its temporaries beside it
    p = write(tmp_path / "s.toml", ab_study("é" * 118 + "x", n=200))
    assert run(["run", p, "--quiet"], capsys)[0] == 4
    assert (tmp_path / "reports" / ("é" * 118 + "x") / "summary.json").exists()


def test_output_names_too_long_are_refused_before_the_run(tmp_path, capsys):
    p = write(tmp_path / "s.toml", ab_study("s", n=200))
    long = tmp_path / ("y" * 250)
    rc, err = run(["run", p, "--quiet", "--out", long], capsys)
    assert rc == 2 and err == [f"rvtol: error: {long}: --out: the folder's name is 250 bytes long: at most 237 (a file "
                               "name's 255, less the temporary names rvtol gives beside it)"]
    rc, err = run(["run", p, "--quiet", "--out", tmp_path / "r", "--junit", long], capsys)
    assert rc == 2 and err == [f"rvtol: error: {long}: --junit: the file's name is 250 bytes long: at most 231 (a file "
                               "name's 255, less the temporary name rvtol writes it under first)"]
    assert sorted(q.name for q in tmp_path.iterdir()) == ["s.toml"]


@pytest.mark.parametrize("value", ["[" * 100_000 + "]" * 100_000, "{b=" * 100_000 + "1" + "}" * 100_000],
                         ids=["arrays", "tables"])
@pytest.mark.parametrize("command", ["run", "check"])
def test_a_toml_nested_100000_deep_is_refused(tmp_path, capsys, value, command):
    p = write(tmp_path / "deep.toml", f"a = {value}\n")
    rc, err = run([command, p], capsys)
    assert rc == 2 and err == [f"rvtol: error: {p}: -: too deeply nested (arrays or tables within each other, deeper "
                               "than rvtol's parser follows)"]


def test_a_baseline_summary_nested_100000_deep_is_refused(tmp_path, capsys):
    p = write(tmp_path / "s.toml", ab_study("s", n=200))
    base = tmp_path / "base"
    base.mkdir()
    write(base / "summary.json", "[" * 100_000 + "]" * 100_000)
    rc, err = run(["run", p, "--quiet", "--out", tmp_path / "r", "--baseline", base], capsys)
    assert rc == 2 and err == [f"rvtol: error: {base / 'summary.json'}: --baseline: cannot read summary.json (too "
                               "deeply nested (arrays or tables within each other, deeper than rvtol's parser "
                               "follows))"]


# --------------------------------------------------------------------------- run flags accepted without a word
def test_serial_with_workers_is_a_contradiction(tmp_path, capsys):
    p = write(tmp_path / "s.toml", ab_study("s", n=200))
    rc, err = run(["run", p, "--quiet", "--executor", "serial", "--workers", "4"], capsys)
    assert rc == 2 and err == ["rvtol: error: <command line>: --workers: 4 workers with --executor serial, which "
                               "evaluates everything in this process: ask for the process or dask executor"]
    rc, err = run(["run", p, "--quiet", "--executor", "serial", "--scheduler", "tcp://127.0.0.1:1"], capsys)
    assert rc == 2 and err == ["rvtol: error: <command line>: --scheduler: a Dask scheduler with --executor serial, "
                               "which does not use one"]
    q = write(tmp_path / "q.toml", ab_study("q", n=200).replace('executor = "serial"',
                                                                  'executor = "serial"\nworkers = 4'))
    rc, err = run(["check", q], capsys)
    assert rc == 2 and err == [f"rvtol: error: {q}: execution.workers: 4 workers with executor = 'serial', which "
                               "evaluates everything in this process: ask for the process or dask executor"]
    assert not (tmp_path / "reports").exists()


def test_the_command_line_overrides_the_file_s_execution_keys_it_contradicts():
    """One source contradicting itself is refused (above); the command line over the study file is an override."""
    from rvtol.params import Params
    from rvtol.study import execution_keys, read_table_options

    def ex(file, **cli):
        root = Params({"execution": file}, file="s.toml")
        return execution_keys(read_table_options(root, "execution"), cli, root.error)

    assert ex({"executor": "serial"}, workers=4) == {"executor": "process", "workers": 4, "scheduler": None}
    assert ex({"workers": 4}, executor="serial") == {"executor": "serial", "workers": None, "scheduler": None}
    assert ex({"executor": "process"}, scheduler="tcp://h:1") == {"executor": "dask", "workers": None,
                                                                  "scheduler": "tcp://h:1"}
    assert ex({"scheduler": "tcp://h:1"}, executor="process") == {"executor": "process", "workers": None,
                                                                   "scheduler": None}
    assert ex({"executor": "serial", "workers": 1}) == {"executor": "serial", "workers": 1, "scheduler": None}


def test_more_workers_than_the_machine_holds_are_refused_before_any_starts(tmp_path, capsys, monkeypatch):
    import psutil

    import rvtol.runguard as rg

    p = write(tmp_path / "s.toml", ab_study("s", n=200))
    monkeypatch.setattr(rg, "available_memory", lambda: 4_000_000_000)
    before = len(psutil.Process().children(recursive=True))
    rc, err = run(["run", p, "--quiet", "--out", tmp_path / "r", "--executor", "process", "--workers", "1000"], capsys)
    assert rc == 2 and err == ["rvtol: error: <command line>: --workers: 1000 workers need about 36 GB of memory "
                               "(36 MB each, beside the Monte Carlo's 28.8 kB) and 4 GB are available: at most 111 "
                               "workers fit"]
    assert len(psutil.Process().children(recursive=True)) == before          # no pool was started early
    monkeypatch.setattr(rg, "open_files_limit", lambda: 1024)
    rc, err = run(["run", p, "--quiet", "--out", tmp_path / "r", "--executor", "process", "--workers", "500"], capsys)
    assert rc == 2 and err == ["rvtol: error: <command line>: --workers: 500 workers need about 1064 open files and "
                               "this process may open 1024 (ulimit -n): at most 480 workers"]
    assert not (tmp_path / "r").exists()
    # rvtol/docs/command_line.md's --workers 16 on a small machine (a task log projected on 16 cores) holds, with a note
    assert rg.workers_problem("process", 16, None) is None


def test_more_workers_than_cores_get_a_note(capsys, monkeypatch):
    import os

    from rvtol.cli import _note_shared_cores
    from rvtol.study import RunOptions

    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    _note_shared_cores(RunOptions(executor="process", workers=16))
    assert capsys.readouterr().err == ("rvtol: note: 16 workers share 2 cores: the run is no faster than on 2 "
                                       "(--task-log projects it on 16 dedicated cores)\n")
    for o in (RunOptions(executor="process", workers=2), RunOptions(executor="serial"),
              RunOptions(executor="dask", workers=16, scheduler="tcp://h:1")):
        _note_shared_cores(o)
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("version", ["v2", "v1"])
def test_a_container_s_memory_limit_is_the_memory_available(tmp_path, capsys, monkeypatch, version):
    """The machine's free memory (psutil) does not show a control group's limit: an n whose own estimate exceeds
    the container's memory was accepted."""
    import rvtol.runguard as rg

    cg = tmp_path / "cgroup"
    if version == "v2":
        (tmp_path / "proc").write_text("0::/job/step\n")
        for d, files in ((cg, {}), (cg / "job", {"memory.max": "300000000", "memory.current": "220000000"}),
                         (cg / "job" / "step", {"memory.max": "max", "memory.current": "90000000"})):
            d.mkdir(parents=True)
            for k, v in files.items():
                (d / k).write_text(v + "\n")
        left = 80_000_000                       # the parent's limit less its usage; the step has no limit of its own
    else:
        (tmp_path / "proc").write_text("5:cpu,cpuacct:/\n4:memory:/job\n0::/\n")
        (cg / "memory" / "job").mkdir(parents=True)
        (cg / "memory" / "memory.limit_in_bytes").write_text("9223372036854771712\n")     # the root: no limit
        (cg / "memory" / "job" / "memory.limit_in_bytes").write_text("150000000\n")
        (cg / "memory" / "job" / "memory.usage_in_bytes").write_text("50000000\n")
        left = 100_000_000
    monkeypatch.setattr(rg, "PROC_CGROUP", tmp_path / "proc")
    monkeypatch.setattr(rg, "CGROUP_ROOT", cg)
    assert rg.cgroup_memory_left() == left and rg.available_memory() == left
    p = write(tmp_path / "s.toml", ab_study("s", n=200))
    n = 1_000_000                               # 1e6 × (2 × 40 + 32 + 32) B = 144 MB
    rc, err = run(["run", p, "--quiet", "--out", tmp_path / "r", "--n", str(n)], capsys)
    assert rc == 2 and err == [f"rvtol: error: <command line>: --n: n = 1,000,000 needs about 144 MB of memory for "
                               f"the Monte Carlo (2 factors, 1 outputs) and {rg.human_bytes(left)} are available; "
                               f"lower n (about {int(n * left / 144_000_000):,} fit)"]
    monkeypatch.setattr(rg, "CGROUP_ROOT", tmp_path / "nowhere")             # no such files: no limit
    assert rg.cgroup_memory_left() is None
