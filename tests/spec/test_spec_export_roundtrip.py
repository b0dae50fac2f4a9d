"""``rvtol spec export``: never over its own input (``spec.csv --out spec.csv --force`` rewrote it and lost the user's
comment lines and notes column), comment rows and notes kept, no spreadsheet formula written, and random specs in
TOML, CSV and XLSX through export and back giving the same factors."""
import json
import math
import os
import zipfile

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from openpyxl import Workbook, load_workbook

from rvtol.cli import main
from rvtol.errors import SpecError
from rvtol.inputs.sheets import read_rows
from rvtol.inputs.table_spec import read_spec_table, write_table_spec
from rvtol.spec import load_spec

SPEC = ("# drawing 4711 rev C, checked by J. Doe\n"
        "#spec,stack\n"
        "name,nominal,tolerance,distribution,unit,multiplicity,notes\n"
        "# the pins come from supplier X\n"
        "pins[k].d,3,±0.002,normal,mm,3,CMM lot 7\n"
        "bore,25,H7,uniform,mm,,see drawing\n"
        "# end of the drawing's list\n")


def export(src, out, *extra):
    return main(["spec", "export", str(src), "--out", str(out), *extra])


def test_export_refuses_its_own_input_by_any_name(tmp_path, capsys):
    spec = tmp_path / "spec.csv"
    spec.write_text(SPEC, encoding="utf-8")
    link = tmp_path / "link.csv"
    link.symlink_to(spec)
    hard = tmp_path / "hard.csv"
    os.link(spec, hard)
    for out in (spec, link, hard, tmp_path / "." / "spec.csv"):
        assert export(spec, out, "--force") == 2
        err = capsys.readouterr().err
        assert f"rvtol: error: {out}: --out: is the spec being exported" in err
    assert spec.read_text(encoding="utf-8") == SPEC                    # untouched (was rewritten without comments)


def test_export_refuses_a_measured_factors_data(tmp_path, capsys):
    (tmp_path / "cmm.csv").write_text("d\n" + "\n".join(f"{25 + 0.001 * i:.3f}" for i in range(20)) + "\n",
                                      encoding="utf-8")
    spec = tmp_path / "spec.toml"
    spec.write_text('[[factor]]\nname = "d"\nunit = "mm"\ndist = "measured"\ndata = "cmm.csv"\nmethod = "empirical"\n',
                    encoding="utf-8")
    before = (tmp_path / "cmm.csv").read_bytes()
    assert export(spec, tmp_path / "cmm.csv", "--force") == 2
    assert "is the measured data of the spec (cmm.csv)" in capsys.readouterr().err
    assert (tmp_path / "cmm.csv").read_bytes() == before


@pytest.mark.parametrize("ext", ["csv", "xlsx"])
def test_comments_and_notes_survive_the_round_trip(tmp_path, ext):
    spec = tmp_path / "spec.csv"
    spec.write_text(SPEC, encoding="utf-8")
    out = tmp_path / f"out.{ext}"
    assert export(spec, out) == 0
    back = tmp_path / "back.csv"
    assert export(out, back) == 0
    def comments(path):
        return [[c for c in cells if c not in (None, "")] for _, cells in read_rows(path).rows
                if str(cells[0]).startswith("# ")]

    assert comments(back) == comments(spec) == [["# drawing 4711 rev C", "checked by J. Doe"],
                                                 ["# the pins come from supplier X"], ["# end of the drawing's list"]]
    assert read_spec_table(back).comments == read_spec_table(spec).comments     # each in its place
    table = read_spec_table(back)
    assert table.extra == {"notes": {"pins[k].d": "CMM lot 7", "bore": "see drawing"}}
    assert_same_factors(load_spec(spec), load_spec(back))
    assert [f.family for f in load_spec(back).factors] == ["pins[k].d"] * 3 + [""]   # one row, multiplicity 3


FORMULAS = ['=HYPERLINK("http://x","y")', "@SUM(A1)", "+cmd|' /C calc'!A0", "-2+3+cmd|' /C calc'!A0"]


def test_no_cell_is_written_as_a_formula(tmp_path, capsys):
    spec = tmp_path / "spec.toml"
    spec.write_text("".join(f'[[factor]]\nname = "f{i}"\nunit = "mm"\nnominal = 10\ntolerance = "+0.1/-0.05"\n'
                            f'part = {json.dumps(text)}\n' for i, text in enumerate(FORMULAS)), encoding="utf-8")
    out = tmp_path / "out.xlsx"
    assert export(spec, out) == 0
    sheet = zipfile.ZipFile(out).read("xl/worksheets/sheet1.xml")
    assert b"<f>" not in sheet and b"<f " not in sheet                  # no formula anywhere
    ws = load_workbook(out).active
    parts = [c.value for c in ws["B"] if c.value in FORMULAS]
    assert parts == FORMULAS and all(c.data_type == "s" and c.quotePrefix for c in ws["B"] if c.value in FORMULAS)
    tol = [c for c in ws["E"] if c.value == "+0.1/-0.05"]
    assert len(tol) == len(FORMULAS) and all(c.data_type == "s" for c in tol)   # a deviation stays text
    assert [f.part for f in load_spec(out).factors] == FORMULAS             # read back as written
    assert export(spec, tmp_path / "out.csv") == 2                          # a CSV cannot mark text: refused
    assert "out.csv: row 3, column B: '=HYPERLINK(\"http://x\",\"y\")' would run as a formula" in capsys.readouterr().err
    assert not (tmp_path / "out.csv").exists()


@pytest.mark.parametrize("text,formula", [("=1+1", True), ("@SUM(A1)", True), ("\tx", True), ("\rx", True),
                                          ("+cmd|' /C calc'!A0", True), ("-2+3+cmd|' /C calc'!A0", True),
                                          ("+0.1/-0.05 on the drawing", True), ("+0.1/-0.05", False), ("-0.5", False),
                                          ("-0.1..0.2", False), ("+", False), ("-", False), ("±0.05", False),
                                          ("housing", False), ("# note", False)])
def test_formula_like(text, formula):
    from rvtol.inputs.sheets import formula_like

    assert formula_like(text) is formula


def test_deviations_starting_with_a_sign_round_trip_in_csv(tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text('[[factor]]\nname = "a"\nunit = "mm"\nnominal = 10\ntolerance = "+0.1/-0"\ndirection = "-"\n'
                    '[[factor]]\nname = "b"\nunit = "mm"\nnominal = 0\ntolerance = "-0.2/-0.1"\npart = "-"\n',
                    encoding="utf-8")
    out = tmp_path / "out.csv"
    assert export(spec, out) == 0
    assert_same_factors(load_spec(spec), load_spec(out))


# -- random specs through export and back ------------------------------------------------------------------------------
TEXTS = ["", "housing", "Ø25 H7 bore", "doc 000, Table 1", "+0.1/-0.05 on the drawing", "=HYPERLINK(\"x\")",
         "größe µm ±", "# not a comment"]


@st.composite
def random_factor(draw, i):
    unit = draw(st.sampled_from(["mm", "um", "in", "deg"]))
    nominal = draw(st.sampled_from([0, 1, 10, 25.4, 100])) if unit != "deg" else draw(st.sampled_from([0, 30, 90]))
    a, b = (draw(st.sampled_from([0.001, 0.005, 0.02, 0.1, 0.25])) for _ in range(2))
    form, kind = draw(st.sampled_from([("pm", "normal"), ("dev", "normal"), ("dev", "uniform"), ("dev", "triangular"),
                                       ("pm", "truncnorm"), ("limits", "uniform"), ("max", "rayleigh"),
                                       ("from_nominal", "weibull")]))
    tol = {"pm": f"±{a}", "dev": f"+{a}/-{b}", "limits": f"{nominal - a}..{nominal + b}", "max": f"max {a}",
           "from_nominal": f"+{a}/0"}[form]
    keys = {"name": f"p{i}[k]" if draw(st.booleans()) and form != "limits" else f"f{i}", "unit": unit,
            "tolerance": tol, "dist": kind}
    if form != "max":
        keys["nominal"] = nominal
    if kind == "normal" and draw(st.booleans()):
        keys["sigma_level"] = draw(st.sampled_from([2.0, 4.0]))
    if kind in ("normal", "uniform") and form != "limits" and draw(st.booleans()):
        keys["shift"] = min(a, b) / 2
    if kind == "weibull":
        keys["shape"] = 2.0
    for k in ("part", "feature", "source"):
        if text := draw(st.sampled_from(TEXTS)):
            keys[k] = text
    if draw(st.booleans()):
        keys["direction"] = draw(st.sampled_from(["+", "-", 0.5]))
    if "[k]" in keys["name"]:
        keys["multiplicity"] = draw(st.integers(2, 3))
    return keys


def toml_text(factors):
    def value(v):
        return json.dumps(v) if isinstance(v, str) else repr(v)

    return "[spec]\nname = \"random\"\n" + "".join(
        "[[factor]]\n" + "".join(f"{k} = {value(v)}\n" for k, v in f.items()) for f in factors)


def table_rows(factors):
    head = ["name", "part", "feature", "nominal", "tolerance", "distribution", "unit", "direction", "source",
            "multiplicity", "notes"]
    rows = [["# written by hand"], ["#spec", "random"], head]
    for f in factors:
        params = {k: f[k] for k in ("sigma_level", "shift", "shape") if k in f}
        cell = f["dist"] + ("(" + ", ".join(f"{k}={v}" for k, v in params.items()) + ")" if params else "")
        rows.append([f["name"], f.get("part"), f.get("feature"), f.get("nominal"), f["tolerance"], cell, f["unit"],
                     f.get("direction"), f.get("source"), f.get("multiplicity"), f"note on {f['name']}"])
        rows.append([f"# after {f['name']}"])
    return rows


def write_source(path, factors):
    if path.suffix == ".toml":
        path.write_text(toml_text(factors), encoding="utf-8")
    elif path.suffix == ".xlsx":
        wb = Workbook()
        for row in table_rows(factors):
            wb.active.append(row)
            for c in wb.active[wb.active.max_row]:
                c.data_type = "s" if isinstance(c.value, str) else c.data_type
        wb.save(path)
    else:
        import csv

        with open(path, "w", encoding="utf-8", newline="") as fh:
            csv.writer(fh).writerows([["" if v is None else v for v in r] for r in table_rows(factors)])


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(st.lists(st.integers(0, 10**6), min_size=1, max_size=4, unique=True).flatmap(
    lambda ids: st.tuples(*[random_factor(i) for i in ids])), st.sampled_from(["toml", "csv", "xlsx"]),
    st.sampled_from(["csv", "xlsx"]))
def test_random_specs_round_trip_through_export(tmp_path, factors, source, target):
    src = tmp_path / f"src.{source}"
    out = tmp_path / f"out.{target}"
    write_source(src, factors)
    spec = load_spec(src)
    keep = read_spec_table(src) if source != "toml" else None
    from rvtol.inputs.sheets import formula_like

    formula = any(formula_like(v) for f in factors for k, v in f.items() if k in ("part", "feature", "source"))
    if target == "csv" and formula:
        with pytest.raises(SpecError, match="would run as a formula"):
            write_table_spec(spec, out, keep=keep)
        return
    write_table_spec(spec, out, keep=keep)
    back = load_spec(out)
    assert_same_factors(spec, back)
    if keep is not None:                       # comments in place, notes kept
        again = read_spec_table(out)
        assert again.extra == keep.extra
        assert [c for _, c in again.comments] == [c for _, c in keep.comments]


def assert_same_factors(a, b):
    """The same factors, up to the 12 significant digits a table writes."""
    def same(x, y):
        return (x is None and y is None) or (x is not None and y is not None and
                                             math.isclose(x, y, rel_tol=1e-11, abs_tol=1e-13))

    assert a.names == b.names and a.units == b.units
    for f, g in zip(a.factors, b.factors):
        assert (f.part, f.feature, f.source, f.group, f.description, f.family, f.dist.kind) == \
            (g.part, g.feature, g.source, g.group, g.description, g.family, g.dist.kind), f.name
        assert same(f.nominal, g.nominal) and same(f.direction, g.direction), f.name
        assert all(same(x, y) for x, y in zip(f.band, g.band)), (f.name, f.band, g.band)
        assert same(f.dist.mean, g.dist.mean) and same(f.dist.std, g.dist.std), (f.name, f.dist, g.dist)
    if a.correlation is None:
        assert b.correlation is None
    else:
        np.testing.assert_allclose(a.correlation, b.correlation, rtol=0, atol=1e-12)
