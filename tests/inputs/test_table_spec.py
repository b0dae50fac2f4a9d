"""Spec tables (CSV/XLSX): round trip TOML → table → spec, the issue's spreadsheet layout, errors
that name the sheet, row and column."""
import datetime
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy import stats

from rvtol.errors import InputError, SpecError
from rvtol.inputs.table_spec import spec_rows, write_table_spec
from rvtol.models.linear.model import stack_model
from rvtol.spec import load_spec

from conftest import ROOT

SPECS = sorted((ROOT / "data" / "specs").glob("*.toml")) + sorted((ROOT / "data" / "products").glob("*/tolerances.toml"))


def same_number(a, b):
    if a is None or b is None:
        return a is None and b is None
    return math.isclose(a, b, rel_tol=1e-11, abs_tol=1e-14)


def assert_same_spec(a, b):
    """Equal up to the 12 significant digits the table writes."""
    assert (a.name, a.description, a.names, a.units) == (b.name, b.description, b.names, b.units)
    for f, g in zip(a.factors, b.factors):
        assert (f.part, f.feature, f.group, f.description, f.source, f.dist.kind) == \
            (g.part, g.feature, g.group, g.description, g.source, g.dist.kind), f.name
        assert f.dist.p.keys() == g.dist.p.keys(), f.name
        for k in f.dist.p:
            assert same_number(f.dist.p[k], g.dist.p[k]), (f.name, k, f.dist.p[k], g.dist.p[k])
        assert same_number(f.dist.shift, g.dist.shift) and same_number(f.dist.sigma_level, g.dist.sigma_level)
        assert same_number(f.nominal, g.nominal), f.name
        assert all(same_number(x, y) for x, y in zip(f.band, g.band)), (f.name, f.band, g.band)
    if a.correlation is None:
        assert b.correlation is None
    else:
        np.testing.assert_allclose(a.correlation, b.correlation, rtol=0, atol=1e-12)


@pytest.mark.parametrize("ext", ["csv", "xlsx"])
@pytest.mark.parametrize("toml", SPECS, ids=[p.parent.name if p.stem == "tolerances" else p.stem for p in SPECS])
def test_round_trip_every_repository_spec(toml, ext, tmp_path):
    spec = load_spec(toml)
    path = write_table_spec(spec, tmp_path / f"{toml.stem}.{ext}")
    assert_same_spec(spec, load_spec(path))


def test_round_trip_keeps_coefficients(tmp_path):
    spec = load_spec(ROOT / "data/specs/rv80e_axial_stack.toml")
    coef = {"carrier_gap": 1.0, "disc1_width": -1.0, "disc2_width": -1.0}
    for ext in ("csv", "xlsx"):
        t = load_spec(write_table_spec(spec, tmp_path / f"s.{ext}", coefficients=coef))
        assert {f.name: f.direction for f in t.factors} == coef
        assert t.correlation[1, 2] == 0.5


ISSUE_CSV = """\
# the issue's layout: one row per contributor, +tol/-tol columns, a direction
name,part,feature,nominal,+tol,-tol,direction,distribution,unit,notes
housing,housing,bore depth,50,0.05,0.05,+,normal,mm,drawing 4711
spacer,spacer,width,20,0,0.02,-,uniform,mm,
bearing,bearing,width,29.9,0.01,-0.01,-,normal,mm,catalogue
"""


def test_issue_layout_and_linear_stack_against_closed_forms(tmp_path):
    p = tmp_path / "stack.csv"
    p.write_text(ISSUE_CSV, encoding="utf-8")
    s = load_spec(p)
    assert s.names == ("housing", "spacer", "bearing") and s.name == "stack"
    assert {f.name: f.direction for f in s.factors} == {"housing": 1.0, "spacer": -1.0, "bearing": -1.0}
    h, sp, b = s.factors
    assert (h.dist.mean, h.dist.std) == (pytest.approx(50.0), pytest.approx(0.1 / 6))
    assert sp.dist.kind == "uniform" and sp.dist.frozen.support() == pytest.approx((19.98, 20.0))
    assert (b.dist.mean, b.dist.std) == (pytest.approx(29.9), pytest.approx(0.02 / 6))
    assert (h.part, h.group, h.feature, h.nominal) == ("housing", "housing", "bore depth", 50.0)
    assert sp.limits == pytest.approx((19.98, 20.0)) and sp.band == pytest.approx((19.98, 20.0))
    # the stack model: gap = housing − spacer − bearing; mean and RSS σ by hand
    m = stack_model(s, "gap", display_unit="um")
    assert m.outputs[0].unit == "mm" and m.outputs[0].display_unit == "um"
    x = np.array([[50.0, 19.99, 29.9], [50.05, 19.98, 29.89]])
    np.testing.assert_allclose(m.evaluate(x)[:, 0], [0.11, 0.18], atol=1e-12)
    mean = 50.0 - 19.99 - 29.9
    sd = math.sqrt((0.1 / 6) ** 2 + stats.uniform(19.98, 0.02).var() + (0.02 / 6) ** 2)
    means = np.array([f.dist.mean for f in s.factors])
    sds = np.array([f.dist.std for f in s.factors])
    c = m.A[0]
    assert c @ means == pytest.approx(mean, abs=1e-12)
    assert math.sqrt(np.sum((c * sds) ** 2)) == pytest.approx(sd, rel=1e-12)


def test_drawing_notation_and_distribution_cells(tmp_path):
    p = tmp_path / "n.csv"
    p.write_text(
        "name;nominal;tolerance;distribution;unit;source\n"
        "bore;25;H7;normal;mm;ISO\n"
        "shaft;25;g6;truncnorm(sigma=0.002);mm;ISO\n"
        "clearance;25;H7/g6;;;fit\n"
        "gap;24,08;±0,0105;normal(shift=0,003);mm;decimal commas\n"   # ';' files from European Excel
        "runout;;max 0.01;weibull(shape=2);mm;\n"
        "wear;;;lognormal(median=2, shape=0.3);um;no band\n"
        "process;25;±0.05 Cpk 1.33 k 0.25;;mm;\n"
        "inch;1;+0.002/-0.001;uniform;in;\n",
        encoding="utf-8")
    with pytest.raises(SpecError, match=r"row 5, column 'distribution': .* write decimals with a point"):
        load_spec(p)
    p.write_text(p.read_text(encoding="utf-8").replace("shift=0,003", "shift=0.003"), encoding="utf-8")
    s = load_spec(p)
    f = {x.name: x for x in s.factors}
    assert f["bore"].dist.mean == pytest.approx(25.0105) and f["bore"].dist.std == pytest.approx(0.021 / 6)
    assert f["shaft"].dist.frozen.support() == pytest.approx((24.980, 24.993)) and f["shaft"].dist.p["sigma"] == 0.002
    assert f["clearance"].unit == "mm" and f["clearance"].nominal is None
    assert f["clearance"].dist.std == pytest.approx(math.hypot(0.021, 0.013) / 6)
    assert f["gap"].dist.mean == pytest.approx(24.083) and f["gap"].nominal == pytest.approx(24.08)
    assert f["runout"].dist.kind == "weibull" and f["runout"].dist.tolerance == pytest.approx(0.01)
    assert f["wear"].dist.p == {"median": 2.0, "shape": 0.3} and f["wear"].unit == "um"
    assert f["process"].dist.std == pytest.approx(0.1 / (6 * 1.33 / 0.75))
    assert f["inch"].unit == "in" and f["inch"].dist.frozen.support() == pytest.approx((0.999, 1.002))


def _xlsx(path, rows, title="Stack"):
    from openpyxl import Workbook

    wb = Workbook()
    ws = wb.active
    ws.title = title
    for r in rows:
        ws.append(r)
    wb.save(path)
    return path


HEAD = ["name", "part", "nominal", "unit", "tolerance", "distribution"]


@pytest.mark.parametrize("row,where,words", [
    (["a", "p", 25, "mm", "25 +0.1", "normal"], "column 'tolerance' (E)", "write both deviations"),
    (["a", "p", 25, "mm", 0.05, "normal"], "column 'tolerance' (E)", "bare number"),
    (["a", "p", 25, "mm", datetime.datetime(2024, 1, 2), "normal"], "column 'tolerance' (E)", "date"),
    (["a", "p", "x25", "mm", "±0.1", "normal"], "column 'nominal' (C)", "expected a number"),
    (["a", "p", 25, "milimeter", "±0.1", "normal"], "column 'unit' (D)", "unknown unit"),
    (["a", "p", 25, None, "±0.1", "normal"], "column 'unit' (D)", "missing unit"),
    (["a", "p", 25, "mm", "±0.1", "gauss"], "column 'distribution' (F)", "unknown distribution"),
    (["a", "p", 25, "mm", "±0.1", "normal(sigma=x)"], "column 'distribution' (F)", "needs a number"),
    (["a", "p", 25, "mm", "±0.1", "normal(foo=1)"], "column 'distribution' (F)", "key=value"),
    (["a", "p", 25, "mm", "±0.1", "lognormal"], "column 'distribution' (F)", "cannot be read as 'lognormal'"),
    (["a b!", "p", 25, "mm", "±0.1", "normal"], "column 'name' (A)", "invalid factor name"),
    (["a", "p", 25, "deg", "H7", "normal"], "column 'tolerance' (E)", "length tolerance"),
    (["a", "p", 25, "mm", "±0.1", "triangular(mode=30)"], "column 'distribution' (F)", "outside"),
    (["a", "p", 25, "mm", "±0.1", "normal", "oops"], "column G", "column without a header"),
])
def test_xlsx_errors_name_sheet_row_and_column(tmp_path, row, where, words):
    p = _xlsx(tmp_path / "s.xlsx", [["#spec", "t"], HEAD, ["ok", "p", 1, "mm", "±0.1", "normal"], row])
    with pytest.raises(SpecError) as e:
        load_spec(p)
    msg = str(e.value)
    assert msg.startswith(f"{p}: sheet 'Stack', row 4, column ") and where in msg and words in msg, msg
    assert "\n" not in msg


@pytest.mark.parametrize("text,words", [
    ("name,unit,tolerance\na,mm,-1..1\na,mm,-2..2\n", "row 3, column 'name': duplicate factor name 'a' (first in row 2)"),
    ("name,unit,tolerance,colour\na,mm,-1..1,red\n", "row 1, column 'colour': unknown column"),
    ("unit,tolerance\nmm,-1..1\n", "row 1: the header has no 'name' column"),
    ("name,unit,tolerance,+tol,-tol\na,mm,-1..1,1,1\n", "not both"),
    ("name,unit,+tol,-tol\na,mm,0.1,\n", "row 2, column '-tol': +tol and -tol go together"),
    ("name,unit,tolerance,direction\na,mm,-1..1,up\n", "row 2, column 'direction': expected a direction"),
    ("#correlation,a,b,2\nname,unit,tolerance\na,mm,-1..1\nb,mm,-1..1\n", "row 1: #correlation: must be <= 1.0"),
    ("#correlation,a,c,0.5\nname,unit,tolerance\na,mm,-1..1\nb,mm,-1..1\n", "unknown factor name 'c'"),
    ("#colour,red\nname,unit,tolerance\na,mm,-1..1\n", "row 1: unknown directive '#colour'"),
    ("name,unit,tolerance\n", "no factor rows"),
    ("", "no header row"),
])
def test_csv_errors_name_row_and_column(tmp_path, text, words):
    p = tmp_path / "s.csv"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(SpecError) as e:
        load_spec(p)
    assert words in str(e.value) and str(e.value).startswith(str(p)), str(e.value)


def test_file_level_errors(tmp_path):
    with pytest.raises(SpecError, match="file not found"):
        load_spec(tmp_path / "missing.csv")
    with pytest.raises(SpecError, match="unknown table format"):
        load_spec(tmp_path / "x.ods")
    bad = tmp_path / "bad.xlsx"
    bad.write_bytes(b"not a zip")
    with pytest.raises(SpecError, match="not a readable .xlsx"):
        load_spec(bad)
    p = _xlsx(tmp_path / "s.xlsx", [HEAD, ["a", "p", 1, "mm", "±0.1", "normal"]])
    with pytest.raises(SpecError, match="no sheet 'Other' \\(sheets: Stack\\)"):
        load_spec(p, sheet="Other")
    assert load_spec(p, sheet="Stack").names == ("a",)


def test_uncomputed_formula_is_not_read_as_blank(tmp_path):
    p = _xlsx(tmp_path / "f.xlsx", [HEAD, ["a", "p", "=20+5", "mm", "±0.1", "normal"]])
    with pytest.raises(SpecError, match=r"sheet 'Stack', row 2, column C: the formula =20\+5 has no stored value"):
        load_spec(p)


def test_rows_are_plain_and_measured_distributions_are_refused():
    spec = load_spec(ROOT / "data/specs/rv80e_axial_stack.toml")
    rows = spec_rows(spec)
    assert rows[0] == ["#spec", "rv80e_axial_stack"]
    assert rows[3][:6] == ["name", "part", "feature", "nominal", "tolerance", "distribution"]
    # the factor's band (shifted with its mean, as the TOML's numbers define it) and what gives the distribution
    assert rows[4][4] == "24.0725..24.0935" and rows[4][5] == "normal(mean=24.08, shift=0.003)"
    with pytest.raises(InputError, match="unknown factor"):
        spec_rows(spec, {"nope": 1.0})
    from rvtol.inputs.measured import empirical

    measured = replace(spec, factors=(replace(spec.factors[0], dist=empirical([24.08, 24.09, 24.07])),),
                       correlation=None)
    with pytest.raises(SpecError, match="'carrier_gap': a EmpiricalDistribution cannot be written"):
        spec_rows(measured)
