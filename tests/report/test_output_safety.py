"""Issue 37: every output format safe for what it may contain — control characters refused in a study's text (and
shown as escapes by every writer anyway), spreadsheet text never a formula, --tables xlsx checked before computing,
a hint never echoing a line of a file, an output never named like a factor."""
import json
import xml.etree.ElementTree as ET
from pathlib import Path

import openpyxl
import pandas as pd
import pytest

from conftest import ab_requirement, ab_study, run_cli



def study(tmp_path: Path, head="", output="y", requirement='"gap"') -> Path:
    p = tmp_path / "s.toml"
    p.write_text(ab_study("s", head=head, output=output, requirements=ab_requirement(requirement, output), seed=1),
                 encoding="utf-8")
    return p


def run(args, capsys):
    return run_cli(args, capsys)


# --------------------------------------------------------------------------- refused where the study gives them
@pytest.mark.parametrize("head,requirement,key,reason", [
    ("", r'"gap\u001b[31m"', "requirement[0].name", "holds the control character U+001B at character 4: a name may "
                                                     "hold none"),
    ("", r'"gap\nplay"', "requirement[0].name", "holds a line break or a tab U+000A at character 4: a name may hold "
                                               "none"),
    ("", r'"gap\u0085"', "requirement[0].name", "holds the control character U+0085 at character 4: a name may hold "
                                               "none"),
    ("", r'"gap\u2028"', "requirement[0].name", "holds a line break or a tab U+2028 at character 4: a name may hold "
                                               "none"),
    (r'title = "Gap\u0007"', '"gap"', "study.title", "holds the control character U+0007 at character 4: a name may "
                                                      "hold none"),
    (r'description = "x\u001b[2J"', '"gap"', "study.description", "holds the control character U+001B at character "
                                                                   "2: text in a study may hold none"),
])
def test_control_characters_are_refused_at_their_key(tmp_path, capsys, head, requirement, key, reason):
    p = study(tmp_path, head=head, requirement=requirement)
    rc, err = run(["check", p], capsys)
    assert rc == 2 and err == [f"rvtol: error: {p}: {key}: {reason}"]


def test_a_description_may_span_lines(tmp_path, capsys):
    p = study(tmp_path, head='description = """two\nlines\tand a tab"""')
    assert run(["check", p], capsys)[0] == 0


def test_an_output_named_like_a_factor_is_refused(tmp_path, capsys):
    """It replaced the factor's column in samples.parquet (same name, same unit)."""
    p = study(tmp_path, output="a")
    rc, err = run(["check", p], capsys)
    assert rc == 2 and err == [f"rvtol: error: {p}: model.output[0].name: an output and a factor share the name 'a': "
                               "the samples, statistics and report could not tell them apart; rename the output"]


def test_an_output_a_python_model_names_is_checked_too(tmp_path, capsys):
    (tmp_path / "mymodel.py").write_text(
        "from rvtol.model import Model, Quantity\n"
        "class M(Model):\n"
        "    inputs, input_units, outputs = ('a', 'b'), ('mm', 'mm'), (Quantity('y\\x1b[8m', 'mm'),)\n"
        "    def evaluate(self, X):\n"
        "        return X[:, :1] - X[:, 1:]\n"
        "def make(params, design, spec):\n"
        "    return M()\n", encoding="utf-8")
    p = study(tmp_path)
    text = p.read_text(encoding="utf-8").replace('kind = "formula"', 'kind = "python"\nfactory = "mymodel:make"\n'
                                                 'path = "."')
    p.write_text(text.split("[[model.output]]")[0] + "[sampling]" + text.split("[sampling]")[1], encoding="utf-8")
    rc, err = run(["check", "--execute", p], capsys)
    assert rc == 2 and err == [f"rvtol: error: {p}: model: the model's output 'y\\x1b[8m' holds the control "
                               "character U+001B at character 2: a name may hold none"]


# --------------------------------------------------------------------------- the writers: safe anyway
def _summary_of_a_run(tmp_path, capsys) -> dict:
    assert run(["run", study(tmp_path), "--out", tmp_path / "r", "--quiet"], capsys)[0] == 0
    return json.loads((tmp_path / "r" / "summary.json").read_text(encoding="utf-8"))


def test_junit_and_markdown_show_a_control_character_that_reaches_them_as_its_escape(tmp_path, capsys):
    from rvtol.ci.junit import write_junit
    from rvtol.ci.markdown import render_markdown

    summary = _summary_of_a_run(tmp_path, capsys)
    summary["outputs"]["y"]["requirements"][0]["requirement"] = "gap\x1b[31m\x00\ud800"
    summary["title"] = "T\x07"
    write_junit(tmp_path / "j.xml", summary)
    case = ET.parse(tmp_path / "j.xml").find(".//testcase")          # well-formed XML
    assert case.get("name") == "gap\\x1b[31m\\x00\\ud800"
    md = render_markdown(summary)
    assert "gap\\x1b[31m\\x00\\ud800" in md and "T\\x07" in md and "\x1b" not in md and "\x07" not in md


def test_spreadsheet_text_is_never_a_formula_and_never_crashes(tmp_path):
    from rvtol.inputs.sheets import write_frames

    df = pd.DataFrame({"name": ['=HYPERLINK("http://x.example","click")', "+A1*2", "-2 um", "@SUM(A1)", "bad\x1b",
                                "-0.5"],
                       "=cmd|' /C calc'!A0": [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]})
    write_frames(tmp_path / "t.xlsx", {"t": df})
    ws = openpyxl.load_workbook(tmp_path / "t.xlsx")["t"]
    cells = [c for row in ws.iter_rows() for c in row]
    assert all(c.data_type in ("s", "n") for c in cells)                  # text or a number: no formula
    assert [c.value for c in cells[::2]] == ["name", '=HYPERLINK("http://x.example","click")', "+A1*2", "-2 um",
                                            "@SUM(A1)", "bad\\x1b", "-0.5"]
    assert [c.quotePrefix for c in cells[2::2]] == [True, True, True, True, False, True]   # text when edited
    assert ws["B1"].value == "=cmd|' /C calc'!A0" and ws["B1"].data_type == "s"
    write_frames(tmp_path / "t.csv", {"t": df})
    back = pd.read_csv(tmp_path / "t.csv", encoding="utf-8-sig")
    assert back.columns.tolist() == ["name", "'=cmd|' /C calc'!A0"]
    assert back["name"].tolist() == ["'=HYPERLINK(\"http://x.example\",\"click\")", "'+A1*2", "'-2 um", "'@SUM(A1)",
                                     "bad\\x1b", "-0.5"]                  # a signed number runs nothing: as it is
    assert back.iloc[:, 1].tolist() == [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]     # numbers stay numbers


def test_a_requirement_named_like_a_formula_is_text_in_statistics_xlsx(tmp_path, capsys):
    p = study(tmp_path, requirement=r'"=HYPERLINK(\"http://evil.example\",\"click\")"')
    assert run(["run", p, "--out", tmp_path / "r", "--quiet", "--tables", "xlsx"], capsys)[0] == 0
    ws = openpyxl.load_workbook(tmp_path / "r" / "statistics.xlsx")["requirements"]
    assert (ws["A2"].value, ws["A2"].data_type) == ('=HYPERLINK("http://evil.example","click")', "s")


# --------------------------------------------------------------------------- --tables xlsx checked before computing
def test_tables_xlsx_too_wide_or_too_large_for_memory_is_refused_before_computing(tmp_path, capsys, monkeypatch):
    import rvtol.runguard
    import rvtol.study

    p = study(tmp_path)
    monkeypatch.setattr(rvtol.study.load, "XLSX_MAX_COLUMNS", 3)           # a, b, y, status: 4 columns
    rc, err = run(["run", p, "--out", tmp_path / "r", "--quiet", "--tables", "xlsx"], capsys)
    assert rc == 2 and err == [f"rvtol: error: {p}: report.tables: 4 columns (factors, outputs, status) do not fit an "
                               "XLSX sheet (3): write the samples as csv"]
    monkeypatch.undo()
    # openpyxl holds every cell until it saves: 20 000 samples × 4 columns × 400 B = 32 MB beside the Monte Carlo's
    # 20 000 × (2 × 40 + 32 + 32) B = 2.9 MB
    monkeypatch.setattr(rvtol.runguard, "available_memory", lambda: 20_000_000)
    rc, err = run(["run", p, "--out", tmp_path / "r", "--quiet", "--tables", "xlsx", "--n", "20000"], capsys)
    assert rc == 2 and err[0].startswith("rvtol: error: <command line>: --n: n = 20,000 needs about 34.9 MB of memory")
    assert not (tmp_path / "r").exists()


# --------------------------------------------------------------------------- hints never echo a file's line
@pytest.mark.parametrize("header,column", [("password=hunter2", "password"), ("token: abc123", "token"),
                                           ("root:$6$salt$hash:19000:0:99999:7:::", "root")])
def test_a_hint_never_echoes_a_line_of_a_named_file(tmp_path, header, column):
    from rvtol.errors import InputError
    from rvtol.inputs.measured import read_measurements

    p = tmp_path / "m.csv"
    p.write_text(f"{header}\n1.0\n2.0\n", encoding="utf-8")
    with pytest.raises(InputError) as e:
        read_measurements(p, column)
    assert str(e.value) == f"{p}: row 1: no column {column!r} in the header row"
