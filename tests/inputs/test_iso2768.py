"""ISO 2768 general tolerances (rvtol.inputs.iso2768): every cell of the standard's tables, typed here from the
standard row by row (a size range, then its classes) — not copied from the module, whose tables run class by class.

ISO 2768-1:1989 Table 1 (linear dimensions except broken edges) and ISO 2768-2:1989 Tables 1–4 (straightness
and flatness; perpendicularity; symmetry; circular run-out).  Ranges are "above … up to and including …"; the
first linear range includes 0.5 mm.  Each cell is checked at the range's first size above its lower bound, inside
it and at its upper bound, so a cell typed wrong or a range boundary moved by one cell fails.

ISO 2768-1 Table 2 (broken edges: external radii and chamfer heights) and Table 3 (angular dimensions, by the
length of the angle's shorter side) likewise, typed from the standard's rows as two public copies print them
(handfest.engineer "Allgemeintoleranzen nach ISO 2768-1"; CAMCUT "General Tolerances for Broken edges", ISO
2768-1:1989), and reached from the spec inputs (``shorter_side``, ``broken_edge``) in TOML and in a table."""
import math

import pytest

from rvtol.cli import main
from rvtol.errors import InputError
from rvtol.inputs import iso2768
from rvtol.inputs.notation import parse_tolerance
from rvtol.spec import load_spec

from conftest import write

#: ISO 2768-1 Table 1: (above, up to and including) mm -> permissible deviation ± (mm) in f, m, c, v; None: a dash
TABLE_1 = {
    (0.5, 3): (0.05, 0.1, 0.2, None),
    (3, 6): (0.05, 0.1, 0.3, 0.5),
    (6, 30): (0.1, 0.2, 0.5, 1.0),
    (30, 120): (0.15, 0.3, 0.8, 1.5),
    (120, 400): (0.2, 0.5, 1.2, 2.5),
    (400, 1000): (0.3, 0.8, 2.0, 4.0),
    (1000, 2000): (0.5, 1.2, 3.0, 6.0),
    (2000, 4000): (None, 2.0, 4.0, 8.0),
}
LINEAR_CLASSES = ("f", "m", "c", "v")

#: ISO 2768-1 Table 2, broken edges: (above, up to and including) mm -> ± mm in f, m, c, v; from 0.5 mm included
TABLE_2 = {
    (0.5, 3): (0.2, 0.2, 0.4, 0.4),
    (3, 6): (0.5, 0.5, 1.0, 1.0),
    (6, math.inf): (1.0, 1.0, 2.0, 2.0),
}
#: ISO 2768-1 Table 3, angular dimensions: the shorter side (above, up to and including) mm -> ± in f, m, c, v,
#: written as the standard prints it (degrees and minutes)
TABLE_3 = {
    (0, 10): ("1°", "1°", "1°30'", "3°"),
    (10, 50): ("0°30'", "0°30'", "1°", "2°"),
    (50, 120): ("0°20'", "0°20'", "0°30'", "1°"),
    (120, 400): ("0°10'", "0°10'", "0°15'", "0°30'"),
    (400, math.inf): ("0°5'", "0°5'", "0°10'", "0°20'"),
}


def degrees(text: str) -> float:
    """``"1°30'"`` -> 1.5 (degrees)."""
    d, _, m = text.partition("°")
    return float(d) + (float(m.rstrip("'")) / 60.0 if m else 0.0)


#: ISO 2768-2 Table 1: straightness and flatness by nominal length (mm), classes H, K, L
STRAIGHTNESS = {
    (0, 10): (0.02, 0.05, 0.1),
    (10, 30): (0.05, 0.1, 0.2),
    (30, 100): (0.1, 0.2, 0.4),
    (100, 300): (0.2, 0.4, 0.8),
    (300, 1000): (0.3, 0.6, 1.2),
    (1000, 3000): (0.4, 0.8, 1.6),
}
#: ISO 2768-2 Table 2: perpendicularity by the nominal length of the shorter side (mm)
PERPENDICULARITY = {
    (0, 100): (0.2, 0.4, 0.6),
    (100, 300): (0.3, 0.6, 1.0),
    (300, 1000): (0.4, 0.8, 1.5),
    (1000, 3000): (0.5, 1.0, 2.0),
}
#: ISO 2768-2 Table 3: symmetry by the nominal length (mm)
SYMMETRY = {
    (0, 100): (0.5, 0.6, 0.6),
    (100, 300): (0.5, 0.6, 1.0),
    (300, 1000): (0.5, 0.8, 1.5),
    (1000, 3000): (0.5, 1.0, 2.0),
}
#: ISO 2768-2 Table 4: circular run-out, whatever the size
RUNOUT = {"H": 0.1, "K": 0.2, "L": 0.5}
GEOMETRIC_CLASSES = ("H", "K", "L")


def sizes_in(above: float, up_to: float, first_included: bool = False) -> list[float]:
    """The first size above ``above`` (``above`` itself if the range includes it), one inside, and ``up_to`` (an open
    last range: a size ten times its lower bound and a very large one)."""
    first = above if first_included else math.nextafter(above, math.inf)
    if math.isinf(up_to):
        return [first, 10.0 * above, 1e9]
    return [first, 0.5 * (above + up_to), up_to]


@pytest.mark.parametrize("k, cls", list(enumerate(LINEAR_CLASSES)))
def test_every_cell_of_iso_2768_1_table_1(k, cls):
    for (above, up_to), row in TABLE_1.items():
        for size in sizes_in(above, up_to, first_included=above == 0.5):
            expected = row[k]
            if expected is None:
                with pytest.raises(InputError, match="a dash in the table"):
                    iso2768.linear(cls, size)
                continue
            assert iso2768.linear(cls, size) == expected, (cls, size)
            assert iso2768.linear(cls.upper(), -size) == expected, (cls, -size)
            # the drawing notation reads the same cell, both limits
            tol = parse_tolerance(f"{size!r} ISO 2768-{cls}")
            assert (tol.lower, tol.upper, tol.unit) == (-expected, expected, "mm"), (cls, size)


@pytest.mark.parametrize("size", [math.nextafter(0.5, 0.0), 0.0, math.nextafter(4000.0, math.inf), 5000.0])
def test_iso_2768_1_is_refused_outside_0_5_to_4000_mm(size):
    with pytest.raises(InputError, match="covers 0.5 … 4000 mm"):
        iso2768.linear("m", size)


def test_an_unknown_linear_class_is_refused():
    with pytest.raises(InputError, match="unknown ISO 2768-1 class"):
        iso2768.linear("k", 50)


@pytest.mark.parametrize("kind, table", [("straightness", STRAIGHTNESS), ("flatness", STRAIGHTNESS),
                                         ("perpendicularity", PERPENDICULARITY), ("symmetry", SYMMETRY)])
@pytest.mark.parametrize("k, cls", list(enumerate(GEOMETRIC_CLASSES)))
def test_every_cell_of_iso_2768_2_tables_1_to_3(kind, table, k, cls):
    for (above, up_to), row in table.items():
        for size in sizes_in(above, up_to):
            assert iso2768.geometric(kind, cls, size) == row[k], (kind, cls, size)
            assert iso2768.geometric(kind, cls.lower(), size) == row[k], (kind, cls.lower(), size)
    with pytest.raises(InputError, match="up to 3000 mm"):
        iso2768.geometric(kind, cls, math.nextafter(3000.0, math.inf))
    for bad in (None, 0.0, -1.0):
        with pytest.raises(InputError, match="needs the nominal length"):
            iso2768.geometric(kind, cls, bad)


@pytest.mark.parametrize("cls", GEOMETRIC_CLASSES)
def test_iso_2768_2_table_4_run_out_whatever_the_size(cls):
    assert iso2768.geometric("runout", cls) == RUNOUT[cls]
    assert iso2768.geometric("runout", cls, 5000.0) == RUNOUT[cls]


def test_an_unknown_geometric_class_or_tolerance_is_refused():
    with pytest.raises(InputError, match="unknown ISO 2768-2 class"):
        iso2768.geometric("flatness", "M", 50)
    with pytest.raises(InputError, match="unknown ISO 2768-2 tolerance"):
        iso2768.geometric("roundness", "K", 50)


@pytest.mark.parametrize("k, cls", list(enumerate(LINEAR_CLASSES)))
def test_every_cell_of_iso_2768_1_table_2_broken_edges(k, cls):
    for (above, up_to), row in TABLE_2.items():
        for size in sizes_in(above, up_to, first_included=above == 0.5):
            assert iso2768.broken_edge(cls, size) == row[k], (cls, size)
            assert iso2768.broken_edge(cls.upper(), -size) == row[k], (cls, -size)
            tol = parse_tolerance(f"{size!r} ISO 2768-{cls}", broken_edge=True)
            assert (tol.lower, tol.upper, tol.unit) == (-row[k], row[k], "mm"), (cls, size)
    for size in (math.nextafter(0.5, 0.0), 0.0, math.nan):
        with pytest.raises(InputError, match="Table 2 covers broken edges from 0.5 mm"):
            iso2768.broken_edge(cls, size)


@pytest.mark.parametrize("k, cls", list(enumerate(LINEAR_CLASSES)))
def test_every_cell_of_iso_2768_1_table_3_angles_by_the_shorter_side(k, cls):
    for (above, up_to), row in TABLE_3.items():
        for side in sizes_in(above, up_to):
            assert iso2768.angular(cls, side) / 60.0 == degrees(row[k]), (cls, side)
            # a 30° angle in degrees, minutes and radians: each reaches the same cell through rvtol.units
            expected = degrees(row[k])
            for nominal, unit, dev in ((30.0, "deg", expected), (1800.0, "arcmin", 60.0 * expected),
                                       (math.pi / 6, "rad", math.radians(expected))):
                tol = parse_tolerance(f"ISO 2768-{cls}", nominal=nominal, unit=unit, shorter_side=side)
                assert (tol.nominal, tol.unit) == (nominal, unit)
                assert (tol.lower, tol.upper) == pytest.approx((-dev, dev), rel=1e-14), (cls, side, unit)
    for side in (0.0, -1.0, math.nan):
        with pytest.raises(InputError, match="the shorter side of an angle is a length > 0"):
            iso2768.angular(cls, side)


def test_an_unknown_class_is_refused_by_every_table():
    for read in (iso2768.broken_edge, iso2768.angular):
        with pytest.raises(InputError, match=r"unknown ISO 2768-1 class 'k' \(f, m, c or v\)"):
            read("k", 5.0)
    with pytest.raises(InputError, match=r"unknown ISO 2768-1 class 'fine'"):
        parse_tolerance("50 ISO 2768-fine")


def test_an_angle_is_never_read_as_a_length():
    """An angle given an ISO 2768 class without its shorter side is refused, asking for it — not looked up in Table 1
    by its number of degrees; the same text with the side gives Table 3's ±0°30' (10 < 35 <= 50 mm)."""
    for text, kw in (("30 deg ISO 2768-m", {}), ("ISO 2768-m", {"nominal": 30.0, "unit": "deg"})):
        with pytest.raises(InputError, match="goes by the length of its shorter side") as e:
            parse_tolerance(text, **kw)
        assert e.value.key == "shorter_side"
        assert parse_tolerance(text, shorter_side=35, **kw).limits == (29.5, 30.5)


STUDY = """
[study]
name = "general"
spec = "{spec}"
exploratory = true

[model]
kind = "formula"
[[model.output]]
name = "y"
formula = "{factor}"
unit = "{unit}"
"""

ANGLE = '[[factor]]\nname = "alpha"\nunit = "deg"\nnominal = 30\n'
EDGE = '[[factor]]\nname = "chamfer"\nunit = "mm"\nnominal = 2\n'


def check(tmp_path, capsys, factor: str, spec: str, unit: str, name: str = "spec.toml") -> tuple[int, str]:
    write(tmp_path / name, spec)
    path = write(tmp_path / "study.toml", STUDY.format(spec=name, factor=factor, unit=unit))
    rc = main(["check", str(path)])
    return rc, capsys.readouterr().err.strip()


def test_an_angle_and_a_broken_edge_in_toml_and_in_a_table(tmp_path, capsys):
    toml = (ANGLE + 'tolerance = "ISO 2768-c"\nshorter_side = 35\n\n'
            + EDGE + 'tolerance = "ISO 2768-m"\nbroken_edge = true\n\n'
            + '[[factor]]\nname = "legs"\nunit = "deg"\nnominal = 90\ntolerance = "ISO 2768-v"\n'
            + 'shorter_side = { value = 0.5, unit = "m" }\n')
    table = ("name,nominal,tolerance,unit,shorter side,broken edge\n"
             "alpha,30,ISO 2768-c,deg,35,\nchamfer,2,ISO 2768-m,mm,,yes\nlegs,90,ISO 2768-v,deg,500,no\n")
    # by hand: c at 35 mm ±1°; m at 2 mm ±0.2 mm; v above 400 mm ±0°20'
    expected = [(29.0, 31.0), (1.8, 2.2), (90 - 1 / 3, 90 + 1 / 3)]
    for name, text in (("spec.toml", toml), ("spec.csv", table)):
        write(tmp_path / name, text)
        got = [v for f in load_spec(tmp_path / name).factors for v in f.limits]
        assert got == pytest.approx([v for pair in expected for v in pair], rel=1e-15), name
    assert check(tmp_path, capsys, "alpha", toml, "deg") == (0, "")


@pytest.mark.parametrize("spec, key, words", [
    (ANGLE + 'tolerance = "ISO 2768-m"\n', "factor[0].shorter_side",
     "an angle's general tolerance ('ISO 2768-m') goes by the length of its shorter side (ISO 2768-1 Table 3): give "
     "it in mm"),
    (ANGLE + 'tolerance = "ISO 2768-k"\nshorter_side = 35\n', "factor[0].tolerance",
     "unknown ISO 2768-1 class 'k' (f, m, c or v)"),
    (ANGLE + 'tolerance = "ISO 2768-m"\nshorter_side = 0\n', "factor[0].shorter_side", "must be > 0"),
    (ANGLE + 'tolerance = "ISO 2768-m"\nshorter_side = 35\nbroken_edge = true\n', "factor[0].broken_edge",
     "broken_edge marks a chamfer height or an external radius (a length, ISO 2768-1 Table 2), not an angle"),
    (EDGE.replace("nominal = 2", "nominal = 0.3") + 'tolerance = "ISO 2768-m"\nbroken_edge = true\n',
     "factor[0].tolerance", "ISO 2768-1 Table 2 covers broken edges from 0.5 mm, not 0.3 mm"),
    (EDGE + 'tolerance = "ISO 2768-m"\nshorter_side = 35\n', "factor[0].shorter_side",
     "shorter_side is for an angle (ISO 2768-1 Table 3); 'ISO 2768-m' is in mm"),
    (EDGE + 'tolerance = "±0.1"\nbroken_edge = true\n', "factor[0].broken_edge",
     "broken_edge belongs to an ISO 2768 general tolerance"),
    (EDGE + 'tolerance = 0.2\nbroken_edge = true\n', "factor[0].broken_edge",
     "broken_edge belongs to an ISO 2768 general tolerance: give tolerance = \"ISO 2768-m\""),
    (ANGLE + 'tolerance = 1.0\nshorter_side = 35\n', "factor[0].shorter_side",
     "shorter_side belongs to an ISO 2768 general tolerance"),
    (EDGE + 'tolerance = "ISO 2768-m"\nbroken_edge = "yes"\n', "factor[0].broken_edge", "expected true or false"),
])
def test_a_bad_general_tolerance_is_one_located_line_exit_2(tmp_path, capsys, spec, key, words):
    rc, err = check(tmp_path, capsys, "alpha" if "alpha" in spec else "chamfer", spec,
                    "deg" if "alpha" in spec else "mm")
    assert rc == 2 and "\n" not in err
    assert err.startswith(f"rvtol: error: {tmp_path / 'spec.toml'}: {key}: "), err
    assert words in err, err


@pytest.mark.parametrize("row, column, words", [
    ("alpha,30,ISO 2768-m,deg,,", "shorter side", "goes by the length of its shorter side"),
    ("chamfer,2,ISO 2768-m,mm,,maybe", "broken edge", "expected yes or no, got 'maybe'"),
    ("chamfer,0.4,ISO 2768-m,mm,,yes", "tolerance", "Table 2 covers broken edges from 0.5 mm, not 0.4 mm"),
])
def test_a_bad_general_tolerance_in_a_table_names_its_row_and_column(tmp_path, capsys, row, column, words):
    spec = "name,nominal,tolerance,unit,shorter side,broken edge\n" + row + "\n"
    rc, err = check(tmp_path, capsys, row.split(",")[0], spec, row.split(",")[3], "spec.csv")
    assert rc == 2 and "\n" not in err
    assert err.startswith(f"rvtol: error: {tmp_path / 'spec.csv'}: row 2, column '{column}': "), err
    assert words in err, err
