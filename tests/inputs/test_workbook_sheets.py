"""Which worksheet of a workbook is read, said in the study's inputs: a spec was always read from the first sheet, even a
hidden one ("rev A" hidden first, "rev B" active read rev A), a study could not name the sheet, and hidden rows were
read as factors without a word."""
import pytest
from openpyxl import Workbook

from rvtol.errors import SpecError
from rvtol.inputs.measured import read_measurements
from rvtol.spec import load_spec
from rvtol.study import load_study, run_study


def workbook(path, sheets, active=0, hidden_rows=()):
    """``sheets``: [(title, state, nominal of its one factor)]; ``hidden_rows`` hidden on the active sheet."""
    wb = Workbook()
    wb.remove(wb.active)
    for i, (title, state, nominal) in enumerate(sheets):
        ws = wb.create_sheet(title)
        for row in (["name", "nominal", "tolerance", "unit"], ["gap", nominal, "±0.1", "mm"], ["w", 5, "±0.1", "mm"]):
            ws.append(row)
        ws.sheet_state = state
        if i == active:
            for r in hidden_rows:
                ws.row_dimensions[r].hidden = True
    wb.active = active
    wb.save(path)
    return path


def test_a_hidden_first_sheet_is_not_read(tmp_path):
    p = workbook(tmp_path / "s.xlsx", [("rev A", "hidden", 10), ("rev B", "visible", 11)], active=1)
    spec = load_spec(p)
    assert (spec.sheet, spec.factor("gap").nominal) == ("rev B", 11.0)        # was rev A's 10


def test_several_visible_sheets_opened_on_another_than_the_first_are_refused(tmp_path):
    p = workbook(tmp_path / "s.xlsx", [("rev A", "visible", 10), ("rev B", "visible", 11)], active=1)
    with pytest.raises(SpecError, match=r"s\.xlsx: sheet: which sheet\? the workbook has 2 visible sheets \('rev A', "
                                        r"'rev B'\) and opens on 'rev B', not on the first one: name the sheet"):
        load_spec(p)
    assert load_spec(p, sheet="rev B").factor("gap").nominal == 11.0
    with pytest.raises(SpecError, match=r"no sheet 'rev C' \(sheets: rev A, rev B\)"):
        load_spec(p, sheet="rev C")
    q = workbook(tmp_path / "q.xlsx", [("rev A", "visible", 10), ("notes", "visible", 11)], active=0)
    assert load_spec(q).sheet == "rev A"          # opens on its first sheet: what everybody reads


def test_hidden_rows_are_refused_naming_them(tmp_path):
    p = workbook(tmp_path / "s.xlsx", [("spec", "visible", 10)], hidden_rows=(3,))
    with pytest.raises(SpecError, match=r"s\.xlsx: sheet 'spec', row 3: hidden row 3: a hidden row would be read like "
                                        r"any other, unseen"):
        load_spec(p)
    wb = Workbook()
    ws = wb.active
    for v in (["x"], [1.0], [2.0], [99.0], [3.0]):
        ws.append(v)
    ws.row_dimensions[4].hidden = True            # a filtered-out value
    wb.save(tmp_path / "m.xlsx")
    with pytest.raises(SpecError, match=r"row 4: hidden row 4"):
        read_measurements(tmp_path / "m.xlsx", "x")


STUDY = """[study]
name = "sheets"
spec = "spec.xlsx"
{sheet}
[model]
kind = "linear"
[[model.output]]
name = "y"
unit = "mm"
coefficients = {{ gap = 1.0, w = -1.0 }}
[[requirement]]
output = "y"
upper = 100.0
[sampling]
n = 200
"""


def test_a_study_names_the_sheet_and_the_run_records_it(tmp_path):
    workbook(tmp_path / "spec.xlsx", [("rev A", "visible", 10), ("rev B", "visible", 11)], active=1)
    study = tmp_path / "study.toml"
    study.write_text(STUDY.format(sheet=""), encoding="utf-8")
    with pytest.raises(SpecError, match="which sheet"):
        load_study(study)
    study.write_text(STUDY.format(sheet='spec_sheet = "rev C"'), encoding="utf-8")
    with pytest.raises(SpecError) as e:
        load_study(study)
    assert e.value.key == "study.spec_sheet" and "no sheet 'rev C'" in e.value.reason
    study.write_text(STUDY.format(sheet='spec_sheet = "rev B"'), encoding="utf-8")
    st = load_study(study)
    assert st.spec.factor("gap").nominal == 11.0
    assert st.inputs["spec"]["sheet"] == "rev B"
    run = run_study(load_study(study, n=16, executor="serial", progress=False))
    assert run.summary()["inputs"]["spec"]["sheet"] == "rev B"                  # summary.json
    files = next(s for s in run.standard_sections if s.key == "inputs").blocks[0].frame   # the report's inputs table
    assert files.set_index("role").loc["spec", "file"] == f"{tmp_path / 'spec.xlsx'} (sheet 'rev B')"


def test_spec_sheet_needs_a_workbook(tmp_path):
    (tmp_path / "spec.toml").write_text('[[factor]]\nname = "gap"\nunit = "mm"\nnominal = 10\ntolerance = "±0.1"\n'
                                        '[[factor]]\nname = "w"\nunit = "mm"\nnominal = 5\ntolerance = "±0.1"\n',
                                        encoding="utf-8")
    study = tmp_path / "study.toml"
    study.write_text(STUDY.format(sheet='spec_sheet = "rev B"').replace("spec.xlsx", "spec.toml"), encoding="utf-8")
    with pytest.raises(SpecError, match="spec.toml is not a workbook"):
        load_study(study)
