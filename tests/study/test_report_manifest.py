"""The report folder's manifest (``.rvtol-files``, rvtol.study.write_outputs): the list of the files a run wrote,
which the next run reads to tell its own files from a user's (rvtol.study.foreign_files).

After a run that writes every kind of file — summary, samples, report, the tables in CSV and XLSX (with the
requirements' table), an extra file (comparison.json) and a file an analysis adds — the manifest lists exactly the
folder's entries (independent reference: the folder listed with os.listdir), every listed file exists, and the
next run into the same folder replaces it without calling any of its files foreign.  One small run (n = 200, no
PDF) is shared by the tests."""
import os

import pytest

from conftest import write
from rvtol.blocks import Section
from rvtol.study import MANIFEST, foreign_files, load_study, run_study, write_outputs

STUDY = """[study]
name = "m"
[sampling]
n = 200
seed = 1
[execution]
executor = "serial"
[report]
pdf = false
tables = ["csv", "xlsx"]
[[factor]]
name = "a"
unit = "mm"
dist = "normal"
mean = 1.0
tolerance = 0.1
[[factor]]
name = "b"
unit = "mm"
dist = "uniform"
lower = 1.9
upper = 2.1
[model]
kind = "formula"
[[model.output]]
name = "y"
formula = "a + b"
unit = "mm"
[[requirement]]
output = "y"
upper = 5
"""
#: what this run writes (typed by hand: the fixed files, both table formats, the requirements' CSV, the extras)
EXPECTED = {MANIFEST, "summary.json", "samples.parquet", "report.html", "samples.csv", "statistics.csv",
            "requirements.csv", "samples.xlsx", "statistics.xlsx", "comparison.json", "per_unit_test.csv"}


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    folder = tmp_path_factory.mktemp("manifest")
    res = run_study(load_study(write(folder / "m.toml", STUDY), progress=False))
    res.sections.append(Section("unit_test", "An analysis with a file").add_file("per_unit_test.csv",
                                                                               "serial,y\nC-1,3.0\n"))
    return res


def manifest(folder) -> list[str]:
    return (folder / MANIFEST).read_text(encoding="utf-8").split("\n")


def test_the_manifest_lists_every_file_the_run_wrote_and_only_those(result, tmp_path):
    out = write_outputs(result, tmp_path / "rep", extra_files={"comparison.json": "{}"})
    listed = manifest(out)
    assert len(listed) == len(set(listed))
    assert set(listed) == set(os.listdir(out)) == EXPECTED
    assert all((out / name).is_file() for name in listed)
    assert foreign_files(out) == []


def test_the_next_run_replaces_its_own_files_and_lists_the_new_set(result, tmp_path):
    out = write_outputs(result, tmp_path / "rep", extra_files={"comparison.json": "{}"})
    files = result.sections[-1].files
    saved = dict(files)
    try:
        files.clear()                                     # the next run: no analysis file, no comparison
        out = write_outputs(result, out)
    finally:
        files.update(saved)
    assert set(manifest(out)) == set(os.listdir(out)) == EXPECTED - {"comparison.json", "per_unit_test.csv"}
    (out / "notes.txt").write_text("mine", encoding="utf-8")
    assert foreign_files(out) == ["notes.txt"]


def test_a_folder_without_a_manifest_knows_only_the_fixed_names(tmp_path):
    """A report folder written before the manifest existed: its fixed file names are rvtol's, anything else is not."""
    for name in ("summary.json", "report.html", "samples.csv", "per_unit_x.csv", "notes.txt"):
        (tmp_path / name).write_text("x", encoding="utf-8")
    assert foreign_files(tmp_path) == ["notes.txt", "per_unit_x.csv"]


def test_the_runs_last_line_names_every_file_it_wrote(tmp_path, capsys):
    """`rvtol run`'s last line lists the files beside report.html from the folder's manifest: the requirements' CSV
    was left out of it (the line was built from the options, not from what was written)."""
    from rvtol.cli import main

    study = write(tmp_path / "m.toml", STUDY)
    code = main(["run", str(study), "--out", str(tmp_path / "rep"), "--quiet"])
    line = capsys.readouterr().out.strip().splitlines()[-1]
    assert code in (0, 1) and line.startswith("verdict: ")       # n = 200 may not demonstrate the yield: either

    named = set(line.split("(+ ", 1)[1].rstrip(")").split(", "))
    assert named == EXPECTED - {MANIFEST, "report.html", "comparison.json", "per_unit_test.csv"}
