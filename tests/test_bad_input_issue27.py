"""Issue 27's bad inputs, table-driven, each with the exact one-line message it must give.

Every case here was a silent wrong answer or a misleading message before; the message checked is
the whole line the CLI prints after ``rvtol: error: ``."""
from pathlib import Path

import pytest

from rvtol.errors import InputError
from rvtol.spec import load_spec

DEV_FIX = "write 0 for a factor that is itself a deviation from its nominal, e.g. a position or form error"


# --------------------------------------------------------------------------- item 2: nothing invented
@pytest.mark.parametrize("name,text,message", [
    ("no nominal column", "name,unit,tolerance\nok,mm,20..21\na,mm,±0.05\n",
     f"row 3, column 'nominal': no 'nominal' column: the tolerance '±0.05' is a deviation from a nominal (add the "
     f"column; {DEV_FIX})"),
    ("blank nominal cell", "name,nominal,unit,tolerance\na,25,mm,±0.05\nb,,mm,+0.1/-0\n",
     f"row 3, column 'nominal': missing nominal: the tolerance '+0.1/-0' is a deviation from it ({DEV_FIX})"),
    ("+tol/-tol without nominal", "name,unit,+tol,-tol\na,mm,0.1,0.1\n",
     f"row 2, column 'nominal': no 'nominal' column: the tolerance '±0.1' is a deviation from a nominal (add "
     f"the column; {DEV_FIX})"),
])
def test_csv_spec_never_invents_a_nominal(tmp_path, name, text, message):
    p = tmp_path / "s.csv"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(InputError) as e:
        load_spec(p)
    assert str(e.value) == f"{p}: {message}"


def test_csv_spec_without_nominal_reads_what_needs_none(tmp_path):
    """Absolute limits, a magnitude, an ISO class with its size and an explicit 0 need no invented number."""
    p = tmp_path / "s.csv"
    p.write_text("name,nominal,unit,tolerance,distribution\nlim,,mm,24.95..25.05,\nrun,,mm,max 0.02,rayleigh\n"
                 "bore,,,25 H7,\ndev,0,um,±3,\n", encoding="utf-8")
    s = {f.name: f for f in load_spec(p).factors}
    assert s["lim"].band == pytest.approx((24.95, 25.05)) and s["lim"].nominal is None
    assert s["bore"].band == pytest.approx((25.0, 25.021)) and s["bore"].nominal == 25.0
    assert s["dev"].nominal == 0.0 and s["dev"].band == pytest.approx((-3.0, 3.0))


def _xlsx(path, rows, merge=(), title="Stack"):
    from openpyxl import Workbook

    wb = Workbook()
    ws = wb.active
    ws.title = title
    for r in rows:
        ws.append(r)
    for m in merge:
        ws.merge_cells(m)
    wb.save(path)
    return path


def test_xlsx_merged_nominal_cells_are_refused_at_their_row_and_column(tmp_path):
    rows = [["#spec", "merged", None, None, None], ["name", "part", "nominal", "unit", "tolerance"],
            ["a", "shaft", 25, "mm", "±0.1"], ["b", "shaft", None, "mm", "±0.1"], ["c", "shaft", None, "mm", "±0.2"]]
    p = _xlsx(tmp_path / "m.xlsx", rows, merge=["C3:C5"])
    with pytest.raises(InputError) as e:
        load_spec(p)
    assert str(e.value) == (f"{p}: sheet 'Stack', row 3, column 'nominal' (C): merged cells C3:C5: only the first "
                            "cell of a merged range holds the value, the others read as blank — unmerge them and "
                            "write the value in every row")
    # a merged title in the metadata rows above the header is harmless
    ok = _xlsx(tmp_path / "ok.xlsx", [["#description", "a long title", None, None, None]] + rows[1:3],
               merge=["B1:E1"])
    assert load_spec(ok).names == ("a",)
