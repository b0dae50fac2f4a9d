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


# --------------------------------------------------------------------------- helpers: tiny studies through the CLI
import json  # noqa: E402
import os  # noqa: E402

from rvtol.cli import main  # noqa: E402

FACTORS = """
[[factor]]
name = "a"
unit = "mm"
dist = "normal"
mean = 1.0
tolerance = 0.1

[[factor]]
name = "b"
unit = "mm"
dist = "normal"
mean = 2.0
tolerance = 0.1
"""

FORMULA = """
[model]
kind = "formula"
[[model.output]]
name = "y"
formula = "{formula}"
unit = "{unit}"
"""


def write_study(tmp_path, body, name="t", n=200):
    p = tmp_path / f"{name}.toml"
    p.write_text(f'[study]\nname = "{name}"\n[sampling]\nn = {n}\nseed = 1\n[execution]\nexecutor = "serial"\n'
                 + body, encoding="utf-8")
    return p


def run_cli(args, capsys):
    rc = main([str(a) for a in args])
    out = capsys.readouterr()
    return rc, out.out, out.err


# --------------------------------------------------------------------------- item 3: contradictions, failing formulas
@pytest.mark.parametrize("extra,message", [
    ('[[correlation]]\npair = ["a", "b"]\nrho = 0.5\n[[correlation]]\npair = ["b", "a"]\nrho = -0.5\n',
     "correlation[1].pair: the correlation of 'a' and 'b' is given twice (first in correlation[0]; 0.5 there, "
     "-0.5 here): give each pair once"),
    ('[[correlation]]\npair = ["a", "b"]\nrho = 0.5\n[[correlation]]\nfactors = ["a", "b"]\n'
     'matrix = [[1, 0.5], [0.5, 1]]\n',
     "correlation[1].factors: the correlation of 'a' and 'b' is given twice (first in correlation[0]; the same): "
     "give each pair once"),
    ('[[requirement]]\nname = "gap"\noutput = "y"\nupper = 5\n[[requirement]]\nname = "gap"\noutput = "y"\n'
     'lower = 0\n',
     "requirement[1].name: requirement 'gap' is given twice (first as requirement[0]): give each requirement its "
     "own name"),
    ('[[requirement]]\noutput = "y"\nupper = 5\n[[requirement]]\noutput = "y"\nupper = 5\nmin_cpk = 1\n',
     "requirement[1].name: requirement 'y ≤ 5' is given twice (first as requirement[0]): give each requirement "
     "its own name"),
])
def test_contradictions_are_refused_at_load_time(tmp_path, capsys, extra, message):
    p = write_study(tmp_path, FACTORS + FORMULA.format(formula="a + b", unit="mm") + extra)
    rc, out, err = run_cli(["check", p], capsys)
    assert (rc, err) == (2, f"rvtol: error: {p}: {message}\n")


@pytest.mark.parametrize("formula,message", [
    ("1 / (a - 1)", "output 'y' fails at the nominal: a division by zero"),
    ("sqrt(b - 1.9 * a)", "output 'y' fails at a corner of the bands (a high, b low): the square root of a "
                           "negative number"),
    ("exp(700 * a)", "output 'y' fails at a corner of the bands (a high): an overflow (a number beyond "
                     "±1.8e308)"),
    ("log(a - 0.96)", "output 'y' fails at a corner of the bands (a low): the logarithm of a negative "
                      "number"),
    ("acos(b - 1)", "output 'y' fails at a corner of the bands (b high): asin/acos of a number beyond ±1"),
])
def test_check_evaluates_formulas_at_the_nominal_and_the_corners(tmp_path, capsys, formula, message):
    # a ~ N(1, (0.1/6)²), band [0.95, 1.05]; b ~ N(2, ·), band [1.95, 2.05]; the corners are those of the factors
    # the formula uses, in the order (lo, lo), (lo, hi), (hi, lo), …; each failure by hand — 1/(a − 1) at a = 1;
    # b − 1.9·a = 0.1 at the nominal, 1.95 − 1.995 = −0.045 at (a high, b low); 700·1.05 = 735 > ln(1.8e308) = 709.8
    # (700 < 709.8 at the nominal); a − 0.96 = −0.01 at a = 0.95; b − 1 = 1.05 at b = 2.05
    body = FACTORS.replace('unit = "mm"', 'unit = "1"')
    p = write_study(tmp_path, body + FORMULA.format(formula=formula, unit="1"))
    rc, out, err = run_cli(["check", p], capsys)
    assert (rc, err) == (2, f"rvtol: error: {p}: model.output[0].formula: {message}\n")


def test_a_comparison_of_two_studies_is_refused(tmp_path, capsys):
    body = FACTORS + FORMULA.format(formula="a + b", unit="mm") + '[[requirement]]\noutput = "y"\nupper = 5\n'
    a, b = write_study(tmp_path, body, "alpha"), write_study(tmp_path, body, "beta")
    for p in (a, b):   # 200 samples cannot demonstrate 99.73 % (success-run n = 1109): FAIL, exit 1
        assert run_cli(["run", p, "--out", tmp_path / p.stem, "--no-pdf", "--quiet"], capsys)[0] == 1
    rc, out, err = run_cli(["compare", tmp_path / "alpha", tmp_path / "beta"], capsys)
    assert (rc, err) == (2, f"rvtol: error: {tmp_path / 'alpha'}: BASE: the baseline is a run of study 'alpha', "
                            "this is a run of study 'beta': compare runs of one study\n")
    before = sorted(os.listdir(tmp_path / "beta"))
    rc, out, err = run_cli(["run", b, "--out", tmp_path / "beta", "--baseline", tmp_path / "alpha", "--quiet"], capsys)
    assert (rc, err) == (2, f"rvtol: error: {tmp_path / 'alpha'}: --baseline: the baseline is a run of study "
                            "'alpha', this is study 'beta': compare runs of one study\n")
    assert sorted(os.listdir(tmp_path / "beta")) == before


# --------------------------------------------------------------------------- item 4: only regular files
def test_only_regular_files_are_read(tmp_path, capsys):
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    (tmp_path / "folder.toml").mkdir()
    big = tmp_path / "big.toml"
    big.write_bytes(b"#" * (2 * 2**20 + 10))
    cases = [("/dev/zero", "is a device, expected a TOML file (rvtol reads only regular files)"),
             (str(fifo), "is a FIFO (named pipe), expected a TOML file (rvtol reads only regular files)"),
             (str(tmp_path / "folder.toml"), "is a directory, expected a TOML file")]
    for spec, reason in cases:
        p = write_study(tmp_path, f'[study]\nspec = "{spec}"\n'.replace("[study]\n", "") +
                        FORMULA.format(formula="a", unit="mm"))
        p.write_text(p.read_text().replace('name = "t"\n', f'name = "t"\nspec = "{spec}"\n', 1).replace(
            f'spec = "{spec}"\n[model]', "[model]", 1))
        rc, out, err = run_cli(["check", p], capsys)
        assert (rc, err) == (2, f"rvtol: error: {spec}: -: {reason}\n"), spec
    os.environ["RVTOL_MAX_INPUT_MB"] = "1"
    try:
        p = write_study(tmp_path, FORMULA.format(formula="a", unit="mm"))
        p.write_text(p.read_text().replace('name = "t"\n', f'name = "t"\nspec = "{big}"\n', 1))
        rc, out, err = run_cli(["check", p], capsys)
        assert (rc, err) == (2, f"rvtol: error: {big}: -: is 2 MB, more than rvtol reads (1 MB; set "
                                "RVTOL_MAX_INPUT_MB to allow more)\n")
    finally:
        del os.environ["RVTOL_MAX_INPUT_MB"]


# --------------------------------------------------------------------------- item 6: Python models
GOOD_MODEL = '''
import sys
import numpy as np
from rvtol.model import Model, Quantity


class Gap(Model):
    def __init__(self, names, mode):
        self.inputs = tuple(names)
        self.input_units = ("mm",) * len(names)
        self.outputs = (Quantity("y", "mm"),)
        self.mode = mode

    def evaluate(self, X):
        X = self.check_input(X)
        if self.mode == "exit":
            sys.exit(0)
        if self.mode == "raise":
            raise ValueError("the model's own bug")
        return (X[:, 0] + X[:, 1])[:, None]


def make(params, design, spec):
    mode = params.str("mode", "ok")
    if mode == "factory_exit":
        sys.exit(0)
    return Gap(spec.names, mode)
'''


@pytest.mark.parametrize("mode,executor,message", [
    ("factory_exit", "serial", "model.factory: factory 'usermodel:make' called sys.exit(0)"),
    ("exit", "serial", "model.factory: the model of factory 'usermodel:make' called sys.exit(0)"),
    ("raise", "process", "model.factory: the model of factory 'usermodel:make' raised ValueError: the model's "
                         "own bug"),
])
def test_a_python_model_that_exits_or_raises_is_exit_3_with_its_message(tmp_path, capsys, mode, executor, message):
    (tmp_path / "usermodel.py").write_text(GOOD_MODEL, encoding="utf-8")
    p = write_study(tmp_path, FACTORS + f'[model]\nkind = "python"\nfactory = "usermodel:make"\npath = "."\n'
                    f'mode = "{mode}"\n[[requirement]]\noutput = "y"\nupper = 5\n')
    out = tmp_path / "rep"
    rc, _, err = run_cli(["run", p, "--out", out, "--executor", executor, "--workers", "1", "--no-pdf", "--quiet",
                          "--junit", tmp_path / "j.xml"], capsys)
    where = p if mode == "factory_exit" else "<input>"
    assert (rc, err) == (3, f"rvtol: error: {where}: {message} (the model's own code; nothing written)\n")
    assert not out.exists() and not (tmp_path / "j.xml").exists()


def test_check_validates_a_python_model_without_running_it(tmp_path, capsys):
    (tmp_path / "usermodel2.py").write_text(GOOD_MODEL + "\nsys.exit(7)   # would stop rvtol if imported\n",
                                            encoding="utf-8")
    p = write_study(tmp_path, FACTORS + '[model]\nkind = "python"\nfactory = "usermodel2:make"\npath = "."\n'
                                        'mode = "factory_exit"\n')
    rc, out, err = run_cli(["check", p], capsys)
    assert rc == 0 and err == ""
    assert out == (f"rvtol: {p}: ok — 2 factors, 0 requirements; factory 'usermodel2:make' found in usermodel2.py "
                   "(not run)\nrvtol: note: the model's code was not run, so its outputs, the requirements' and "
                   "gates' outputs and the analyses are unchecked: rvtol check --execute runs it\n")
    rc, out, err = run_cli(["check", "--execute", p], capsys)
    assert (rc, err) == (3, f"rvtol: error: {p}: model.factory: module 'usermodel2' called sys.exit(7) while "
                            "imported (the model's own code; nothing written)\n")
    for factory, message in [("usermodel2:nope", "module 'usermodel2' (usermodel2.py) defines no 'nope' at its top "
                                                 "level"),
                             ("nomodule:make", "cannot find module 'nomodule'")]:
        p.write_text(p.read_text().replace("usermodel2:make", factory))
        rc, out, err = run_cli(["check", p], capsys)
        assert (rc, err) == (2, f"rvtol: error: {p}: model.factory: {message}\n")
        p.write_text(p.read_text().replace(factory, "usermodel2:make"))
    (tmp_path / "usermodel2.py").write_text("def make(params, design, spec)\n    return 1\n", encoding="utf-8")
    rc, out, err = run_cli(["check", p], capsys)
    assert (rc, err) == (2, f"rvtol: error: {p}: model.factory: usermodel2.py line 1: expected ':'\n")


def test_file_contents_are_not_echoed(tmp_path, capsys):
    """A study that names a data file by mistake: the error says what is wrong, not what the file holds."""
    (tmp_path / "data.csv").write_text("password,hunter2,secret\n1,2,3\n", encoding="utf-8")
    p = write_study(tmp_path, FORMULA.format(formula="a", unit="mm"))
    p.write_text(p.read_text().replace('name = "t"\n', 'name = "t"\nspec = "data.csv"\n', 1))
    rc, out, err = run_cli(["check", p], capsys)
    assert rc == 2 and "hunter2" not in err and "password" not in err and "secret" not in err
    assert err == (f"rvtol: error: {tmp_path / 'data.csv'}: row 1: not the header of a spec table: none of its 3 "
                   "cells is a known column (name, part, feature, nominal, tolerance, distribution, unit, direction, "
                   "source, +tol, -tol)\n")


# --------------------------------------------------------------------------- item 5: a report folder is rvtol's alone
def test_files_rvtol_did_not_write_are_never_deleted(tmp_path, capsys):
    p = write_study(tmp_path, FACTORS + FORMULA.format(formula="a + b", unit="mm") +
                    '[[requirement]]\noutput = "y"\nupper = 5\n')
    out = tmp_path / "rep"
    assert run_cli(["run", p, "--out", out, "--no-pdf", "--quiet"], capsys)[0] == 1
    manifest = (out / ".rvtol-files").read_text(encoding="utf-8").split("\n")
    assert sorted(manifest) == sorted(x.name for x in out.iterdir())
    assert run_cli(["run", p, "--out", out, "--no-pdf", "--quiet"], capsys)[0] == 1   # its own files: replaced
    (out / "my notes.txt").write_text("mine", encoding="utf-8")
    (out / "sketches").mkdir()
    rc, _, err = run_cli(["run", p, "--out", out, "--no-pdf", "--quiet"], capsys)
    assert (rc, err) == (2, f"rvtol: error: {out}: --out: holds files rvtol did not write (my notes.txt, sketches); "
                            "a run replaces the whole folder: move them elsewhere first\n")
    assert (out / "my notes.txt").read_text(encoding="utf-8") == "mine" and (out / "sketches").is_dir()


# --------------------------------------------------------------------------- item 7: a first study in five minutes
def test_rvtol_init_writes_a_study_that_runs_as_written(tmp_path, capsys):
    folder = tmp_path / "first"
    assert run_cli(["init", folder], capsys)[0] == 0
    rc, out, err = run_cli(["run", folder / "study.toml", "--out", tmp_path / "rep", "--quiet"], capsys)
    assert rc == 0, err
    s = json.loads((tmp_path / "rep" / "summary.json").read_text(encoding="utf-8"))
    gap, pin = s["outputs"]["gap"], s["outputs"]["pin_height"]
    # by hand: gap = 60 − 2·(18 − 0.06) − 23.8 = 0.32 mm; σ = √(2·(0.1/6)² + 2·(0.12/6)²) mm = 36.82 µm
    sd = 1000 * (2 * (0.1 / 6) ** 2 + 2 * (0.12 / 6) ** 2) ** 0.5
    assert gap["unit"] == "um" and abs(gap["mean"] - 320.0) < 4 * sd / 5000 ** 0.5
    assert abs(gap["std"] / sd - 1) < 0.05
    # the V-groove pin with its angle in degrees: 1.27·(1 + √2) mm (sin of radians, not of 45 "radians")
    assert abs(pin["mean"] - 1.27 * (1 + 2 ** 0.5)) < 1e-4
    assert s["verdict"] == "PASS"
    rc, _, err = run_cli(["init", folder], capsys)     # never overwrites
    assert (rc, err) == (2, f"rvtol: error: {folder}: DIR: study.toml, spec.csv exist already: rvtol init writes a "
                            "new study only into a folder without one\n")


# --------------------------------------------------------------------------- messages (the list, item 8)
@pytest.mark.parametrize("factor,message", [
    ('mean = 1\ntolerence = 0.1\n', "factor[0].tolerence: unknown key (did you mean 'tolerance'?)"),
    ('dist = "normal"\nmean = 1\ntolerence = 0.1\n', "factor[0].tolerence: unknown key (did you mean 'tolerance'?)"),
    ('tolerence = "±0.1"\nnominal = 1\n', "factor[0].tolerence: unknown key (did you mean 'tolerance'?)"),
])
def test_a_misspelt_key_is_named_not_reported_missing(tmp_path, capsys, factor, message):
    p = write_study(tmp_path, f'[[factor]]\nname = "a"\nunit = "mm"\n{factor}' + FORMULA.format(formula="a", unit="mm"))
    rc, _, err = run_cli(["check", p], capsys)
    assert (rc, err) == (2, f"rvtol: error: {p}: {message}\n")


def test_a_txt_spec_and_utf16_tables_give_accurate_messages(tmp_path, capsys):
    txt = tmp_path / "spec.txt"
    txt.write_text('[[factor]]\nname = "a"\nunit = "mm"\ndist = "normal"\nmean = 1\ntolerance = 0.1\n', encoding="utf-8")
    with pytest.raises(InputError) as e:
        load_spec(txt)
    assert str(e.value) == (f"{txt}: -: a spec is a TOML file (.toml) or a table (.csv, .tsv or .xlsx), not .txt: "
                            "rename it after what it holds (a tab-separated table: .tsv)")
    # Excel's "Unicode text": UTF-16 with a byte-order mark — read
    table = "name\tnominal\ttolerance\tunit\nbore\t25\tH7\tmm\n"
    u16 = tmp_path / "spec.tsv"
    u16.write_bytes(table.encode("utf-16"))
    assert load_spec(u16).factors[0].band == pytest.approx((25.0, 25.021))
    # UTF-16 without its mark: named, not misread as Windows-1252
    bare = tmp_path / "bare.csv"
    bare.write_bytes(table.replace("\t", ",").encode("utf-16-le"))
    with pytest.raises(InputError) as e:
        load_spec(bare)
    assert str(e.value) == (f"{bare}: -: not a text file (it holds NUL bytes) — it looks like UTF-16 without a "
                            "byte-order mark: save it as UTF-8")


# --------------------------------------------------------------------------- a nominal places the distribution
def _one_factor_spec(tmp_path, factor: str):
    from rvtol.spec import load_spec

    p = tmp_path / "spec.toml"
    p.write_text('[[factor]]\nname = "a"\nunit = "mm"\n' + factor)
    return load_spec(p)


def test_a_nominal_without_a_mean_centres_the_distribution(tmp_path):
    """nominal 10, normal, tolerance 0.06 (±3σ) is 10 ± 0.03: mean 10, σ 0.01 — never 0 ± 0.03 beside a nominal of 10."""
    f = _one_factor_spec(tmp_path, 'nominal = 10.0\ndist = "normal"\ntolerance = 0.06\n').factors[0]
    assert f.dist.mean == pytest.approx(10.0) and f.dist.std == pytest.approx(0.01)
    assert f.band == pytest.approx((9.97, 10.03))
    u = _one_factor_spec(tmp_path, 'nominal = 5\ndist = "uniform"\ntolerance = 0.2\n').factors[0]
    assert u.band == pytest.approx((4.9, 5.1))


def test_an_explicit_mean_is_kept_beside_a_nominal(tmp_path):
    f = _one_factor_spec(tmp_path, 'nominal = 10.0\nmean = 10.01\ndist = "normal"\ntolerance = 0.06\n').factors[0]
    assert f.dist.mean == pytest.approx(10.01)


def test_a_magnitude_with_a_nonzero_nominal_must_say_where_it_starts(tmp_path):
    from rvtol.errors import InputError

    with pytest.raises(InputError, match=r"factor\[0\]\.nominal: a rayleigh factor is a magnitude"):
        _one_factor_spec(tmp_path, 'nominal = 0.01\ndist = "rayleigh"\ntolerance = 0.02\n')


@pytest.mark.parametrize("tolerance", ["+0/-0.12", "±0.1"])
def test_a_toml_factor_in_deviations_needs_its_nominal(tmp_path, tolerance):
    """As a spreadsheet's missing nominal cell: deviations read about an unstated nominal would invent 0."""
    from rvtol.errors import InputError

    with pytest.raises(InputError, match=r"factor\[0\]\.nominal: missing nominal"):
        _one_factor_spec(tmp_path, f'tolerance = "{tolerance}"\n')
    assert _one_factor_spec(tmp_path, f'nominal = 0\ntolerance = "{tolerance}"\n').factors[0].nominal == 0
    assert _one_factor_spec(tmp_path, f'nominal = 5\ntolerance = "{tolerance}"\n').factors[0].dist.mean > 4.8


def test_a_measured_files_header_is_not_echoed(tmp_path):
    """The first line of a file a study names may hold anything (a credential pasted by mistake): an error names a
    close column only, never the line."""
    from rvtol.errors import InputError
    from rvtol.inputs.measured import read_measurements

    p = tmp_path / "m.csv"
    p.write_text("AWS_SECRET_ACCESS_KEY=wJalrEXAMPLEKEY\n1.0\n2.0\n")
    with pytest.raises(InputError) as e:
        read_measurements(p, "bore")
    assert "wJalr" not in str(e.value) and "no column 'bore'" in str(e.value)
    p.write_text("bore_d,x\n1.0,2\n2.0,3\n")
    with pytest.raises(InputError, match="did you mean 'bore_d'"):
        read_measurements(p, "bore_dd")
