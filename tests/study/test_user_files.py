"""Issue 37: no user file lost — every file a run (or a comparison) writes never replaces an input of the run
or a file rvtol did not write, checked before anything is computed; the window between a run's two final
renames recovered, not deleted."""
import json
import os
import signal
from pathlib import Path

import pytest

from conftest import AB_SPEC_CSV, ab_requirement, ab_study, run_cli

SPEC = AB_SPEC_CSV
STUDY = ab_study("gap", spec="spec.csv", requirements=ab_requirement(), seed=1)


@pytest.fixture
def study(tmp_path) -> Path:
    (tmp_path / "spec.csv").write_text(SPEC, encoding="utf-8")
    p = tmp_path / "study.toml"
    p.write_text(STUDY, encoding="utf-8")
    return p


def run(args, capsys):
    return run_cli(args, capsys)


def contents(folder: Path) -> dict:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.parametrize("flag,target,what", [
    ("--junit", "study.toml", "is an input of this run"),
    ("--markdown", "spec.csv", "is an input of this run"),
    ("--task-log", "study.toml", "is an input of this run"),
    ("--junit", "notes.txt", "exists and is not a JUnit report rvtol wrote"),
    ("--markdown", "notes.txt", "exists and is not a Markdown summary rvtol wrote"),
    ("--task-log", "notes.txt", "exists and is not a task log rvtol wrote"),
])
def test_a_flag_never_replaces_an_input_or_a_file_rvtol_did_not_write(study, tmp_path, capsys, flag, target, what):
    (tmp_path / "notes.txt").write_text("my notes\n", encoding="utf-8")
    before = contents(tmp_path)
    rc, err = run(["run", study, "--out", tmp_path / "rep", "--quiet", flag, tmp_path / target], capsys)
    assert rc == 2 and len(err) == 1, err
    assert err[0].startswith(f"rvtol: error: {tmp_path / target}: {flag}: {what}")
    assert contents(tmp_path) == before            # checked before the run: nothing written, nothing replaced


def test_a_symlink_or_a_hard_link_to_an_input_is_the_input(study, tmp_path, capsys):
    os.symlink(tmp_path / "study.toml", tmp_path / "link.xml")
    os.link(tmp_path / "spec.csv", tmp_path / "hard.md")
    for flag, target in (("--junit", "link.xml"), ("--markdown", "hard.md")):
        rc, err = run(["run", study, "--out", tmp_path / "rep", "--quiet", flag, tmp_path / target], capsys)
        assert rc == 2 and "is an input of this run" in err[0]
    assert (tmp_path / "study.toml").read_text(encoding="utf-8") == STUDY


def test_rvtol_replaces_its_own_outputs_of_the_same_kind(study, tmp_path, capsys):
    files = {"--junit": tmp_path / "ci" / "junit.xml", "--markdown": tmp_path / "ci" / "summary.md",
             "--task-log": tmp_path / "ci" / "tasks.json"}
    args = ["run", study, "--out", tmp_path / "rep", "--quiet", *[x for kv in files.items() for x in kv]]
    assert run(args, capsys)[0] == 0
    first = {k: p.read_bytes() for k, p in files.items()}
    assert json.loads(first["--task-log"])["format"] == "rvtol-task-log/1"
    assert run(args, capsys)[0] == 0                # the second run replaces its own three files
    assert all(p.exists() for p in files.values()) and not list((tmp_path / "ci").glob(".*"))
    # but not another kind's: a Markdown summary is not a JUnit report
    rc, err = run(["run", study, "--out", tmp_path / "rep", "--quiet", "--junit", files["--markdown"]], capsys)
    assert rc == 2 and "exists and is not a JUnit report rvtol wrote" in err[0]


def test_two_flags_naming_one_file_are_refused(study, tmp_path, capsys):
    rc, err = run(["run", study, "--out", tmp_path / "rep", "--quiet", "--junit", tmp_path / "x",
                   "--markdown", tmp_path / "x"], capsys)
    assert rc == 2 and err == [f"rvtol: error: {tmp_path / 'x'}: --markdown: names the same file as --junit: give "
                               "each output its own file"]
    assert not (tmp_path / "rep").exists()


def test_the_report_folder_never_replaces_a_folder_holding_an_input(study, tmp_path, capsys):
    """The accepted baseline is an input of the run: --out onto it would replace it with the run it judges."""
    base = tmp_path / "base"
    assert run(["run", study, "--out", base, "--quiet"], capsys)[0] == 0
    before = contents(base)
    rc, err = run(["run", study, "--out", base, "--baseline", base, "--quiet"], capsys)
    assert rc == 2 and len(err) == 1 and err[0].startswith(f"rvtol: error: {base}: --out: holds an input of this run "
                                                           f"({base}{os.sep}")
    assert err[0].endswith("), and the run replaces the whole folder: choose another --out")
    assert contents(base) == before


def test_compare_never_replaces_its_inputs_or_foreign_files(study, tmp_path, capsys):
    a, b = tmp_path / "a", tmp_path / "b"
    for out in (a, b):
        assert run(["run", study, "--out", out, "--quiet"], capsys)[0] == 0
    (tmp_path / "notes.txt").write_text("my notes\n", encoding="utf-8")
    before = contents(tmp_path)
    for flag, target, what in (("--out", a / "summary.json", "is an input of this run"),
                               ("--junit", b / "samples.parquet", "is an input of this run"),
                               ("--markdown", tmp_path / "notes.txt", "exists and is not a Markdown summary"),
                               ("--out", tmp_path / "notes.txt", "exists and is not a comparison (JSON)")):
        rc, err = run(["compare", a, b, flag, target], capsys)
        assert rc == 2 and err[0].startswith(f"rvtol: error: {target}: {flag}: {what}"), err
    assert contents(tmp_path) == before
    out = tmp_path / "cmp.json"
    assert run(["compare", a, b, "--out", out], capsys)[0] == 0
    assert run(["compare", a, b, "--out", out], capsys)[0] == 0      # its own comparison: replaced


def test_a_run_stopped_between_its_two_final_renames_leaves_the_previous_folder_in_place(study, tmp_path, capsys,
                                                                                          monkeypatch):
    from rvtol.runguard import Interrupted

    out = tmp_path / "rep"
    assert run(["run", study, "--out", out, "--quiet"], capsys)[0] == 0
    before = contents(out)
    real = os.replace

    def stopped_after_the_first(src, dst):
        if Path(src).name.startswith(".rep.tmp-"):      # the second rename: a SIGTERM arrives just before it
            raise Interrupted(signal.SIGTERM)
        return real(src, dst)

    monkeypatch.setattr(os, "replace", stopped_after_the_first)
    rc, err = run(["run", study, "--out", out, "--quiet", "--n", "400"], capsys)
    monkeypatch.undo()
    assert rc == 143 and contents(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [".rep.rvtol-run", "rep", "spec.csv", "study.toml"]


def test_the_next_run_restores_the_folder_a_kill_9_between_the_renames_left_aside(study, tmp_path, capsys,
                                                                                   monkeypatch):
    """kill -9 between the renames: the previous report is under ``.rep.old-*``, the new one under ``.rep.tmp-*``,
    ``rep`` is missing.  The next run to it puts the previous one back before it computes anything (here it is
    then stopped by a SIGTERM while computing: the previous report is in place, not deleted)."""
    import rvtol.study
    from rvtol.runguard import Interrupted

    out = tmp_path / "rep"
    assert run(["run", study, "--out", out, "--quiet"], capsys)[0] == 0
    before = contents(out)
    os.replace(out, tmp_path / ".rep.old-0123456789ab")          # the state kill -9 left
    (tmp_path / ".rep.tmp-ba9876543210").mkdir()
    (tmp_path / ".rep.tmp-ba9876543210" / "summary.json").write_text("{}")

    def stopped(*args, **kwargs):
        raise Interrupted(signal.SIGTERM)

    monkeypatch.setattr(rvtol.study, "run_study", stopped)
    rc, err = run(["run", study, "--out", out, "--quiet"], capsys)
    assert rc == 143 and contents(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [".rep.rvtol-run", "rep", "spec.csv", "study.toml"]
