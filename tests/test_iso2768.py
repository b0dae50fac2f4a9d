"""ISO 2768 general tolerances (rvtol.inputs.iso2768): every cell of the standard's tables, typed here from the
standard row by row (a size range, then its classes) — not copied from the module, whose tables run class by class.

ISO 2768-1:1989 Table 1 (linear dimensions except broken edges) and ISO 2768-2:1989 Tables 1–4 (straightness
and flatness; perpendicularity; symmetry; circular run-out).  Ranges are "above … up to and including …"; the
first linear range includes 0.5 mm.  Each cell is checked at the range's first size above its lower bound, inside
it and at its upper bound, so a cell typed wrong or a range boundary moved by one cell fails.  ISO 2768-1 Tables
2 (broken edges) and 3 (angular dimensions) are not implemented: ``ISO 2768-m`` on an angle is refused
(:func:`test_an_angle_is_refused_not_read_as_a_length`)."""
import math

import pytest

from rvtol.errors import InputError
from rvtol.inputs import iso2768
from rvtol.inputs.notation import parse_tolerance

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
    """The first size above ``above`` (``above`` itself if the range includes it), one inside, and ``up_to``."""
    first = above if first_included else math.nextafter(above, math.inf)
    return [first, 0.5 * (above + up_to), up_to]


@pytest.mark.parametrize("k, cls", enumerate(LINEAR_CLASSES))
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
@pytest.mark.parametrize("k, cls", enumerate(GEOMETRIC_CLASSES))
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


def test_an_angle_is_refused_not_read_as_a_length():
    """Table 3 (angular dimensions, by the shorter leg) is not implemented: an angle given an ISO 2768 class is
    refused with the units named, not looked up in Table 1 by its number of degrees."""
    for text, kw in (("30 deg ISO 2768-m", {}), ("ISO 2768-m", {"nominal": 30.0, "unit": "deg"})):
        with pytest.raises(InputError, match="cannot convert 'deg'"):
            parse_tolerance(text, **kw)
