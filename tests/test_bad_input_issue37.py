"""Issue 37's bad inputs that were an internal error (exit 3) or accepted without a word: each is now one line,
exit 2, before anything is computed."""
from pathlib import Path

import pytest

from rvtol.cli import main

STUDY = """[study]
name = "{name}"
[[factor]]
name = "a"
unit = "mm"
nominal = 10
tolerance = "±0.05"
[[factor]]
name = "b"
unit = "mm"
nominal = 4
tolerance = "±0.05"
[model]
kind = "formula"
[[model.output]]
name = "y"
formula = "a - b"
unit = "mm"
[sampling]
n = 200
[execution]
executor = "serial"
[report]
pdf = false
"""


def run(args, capsys):
    rc = main([str(a) for a in args])
    cap = capsys.readouterr()
    return rc, cap.err.strip().splitlines()


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


# --------------------------------------------------------------------------- exit 3 on bad input
def test_a_study_name_too_long_for_a_folder_is_refused_at_its_key(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    p = write(tmp_path / "s.toml", STUDY.format(name="x" * 300))
    rc, err = run(["run", p, "--quiet"], capsys)
    assert rc == 2 and err == [f"rvtol: error: {p}: study.name: the study name is 300 bytes long, and it names the "
                               "report folder: at most 237 (a file name's 255, less the temporary names rvtol gives "
                               "beside it); give a shorter name"]
    assert run(["check", p], capsys)[0] == 2           # check says so too, before any run
    # 237 bytes (multi-byte characters counted as bytes) is the longest that runs, with its temporaries beside it
    p = write(tmp_path / "s.toml", STUDY.format(name="é" * 118 + "x"))
    assert run(["run", p, "--quiet"], capsys)[0] == 4
    assert (tmp_path / "reports" / ("é" * 118 + "x") / "summary.json").exists()


def test_output_names_too_long_are_refused_before_the_run(tmp_path, capsys):
    p = write(tmp_path / "s.toml", STUDY.format(name="s"))
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
    p = write(tmp_path / "s.toml", STUDY.format(name="s"))
    base = tmp_path / "base"
    base.mkdir()
    write(base / "summary.json", "[" * 100_000 + "]" * 100_000)
    rc, err = run(["run", p, "--quiet", "--out", tmp_path / "r", "--baseline", base], capsys)
    assert rc == 2 and err == [f"rvtol: error: {base / 'summary.json'}: --baseline: cannot read summary.json (too "
                               "deeply nested (arrays or tables within each other, deeper than rvtol's parser "
                               "follows))"]
