"""Decimal commas in semicolon- and tab-separated tables (rvtol.inputs.sheets): a European spreadsheet saves
``25,011`` for 25.011 in a ``;`` or tab file, and every table reader reads it so.

The expected numbers are typed here; each reader is checked on a ``;`` file and a TSV: the low-level cell reader
(:func:`cell_number`), the header-row table (:meth:`Table.number`) and a reader built on it (a measured part
family, :mod:`rvtol.production.measured_parts`).  Comma-separated files are not tested here (in them a comma
separates cells or, quoted, is a thousands separator: another set of rules)."""
import numpy as np
import pytest

from conftest import write
from rvtol.errors import InputError
from rvtol.inputs.sheets import cell_number, decimal_comma, read_table
from rvtol.production.measured_parts import read_part_family
from rvtol.spec import spec_from_table

#: cell text in a ';' or tab file -> the number it means
COMMA_CELLS = {"25,011": 25.011, "-0,004": -0.004, "\u22120,5": -0.5, ",5": 0.5, "0,0105": 0.0105,
               "1,5e-3": 1.5e-3, "+3,25": 3.25, "25": 25.0}


@pytest.mark.parametrize("delimiter, comma", [(";", True), ("\t", True), (" ", True), (",", False), (None, False)])
def test_which_delimiters_allow_a_decimal_comma(delimiter, comma):
    assert decimal_comma(delimiter) is comma


def test_cell_number_reads_a_decimal_comma_where_allowed():
    for text, x in COMMA_CELLS.items():
        assert cell_number(text, comma=True) == x, text
    with pytest.raises(ValueError):
        cell_number("25,011", comma=False)
    for bad in ("25,0,1", "25;011", ",,5"):
        with pytest.raises(ValueError):
            cell_number(bad, comma=True)


@pytest.mark.parametrize("suffix, sep", [(".csv", ";"), (".tsv", "\t"), (".txt", ";")])
def test_a_header_table_reads_decimal_commas(tmp_path, suffix, sep):
    cells = list(COMMA_CELLS)
    p = write(tmp_path / f"t{suffix}", "# exported with a German locale\n" + f"x [mm]{sep}n\n"
              + "".join(f"{c}{sep}{i}\n" for i, c in enumerate(cells)))
    t = read_table(p)
    assert t.comma and t.names == ["x", "n"]
    got = [t.number(row, c, 0) for row, c in t.rows]
    assert got == list(COMMA_CELLS.values())
    row, c = t.rows[0]
    with pytest.raises(InputError, match="not a number: '25,0,1'"):
        t.number(row, ["25,0,1", "0"], 0)


def test_a_measured_part_family_in_a_semicolon_file_reads_decimal_commas(tmp_path):
    """Hand: 25,011 mm − in a ';' file − is 25.011 mm; 0,42 µm is 0.42e-3 mm; the uncertainty row 0,3 µm."""
    spec = spec_from_table({"factor": [
        {"name": "crank_1.bore", "unit": "mm", "dist": "normal", "mean": 25.0, "sigma": 0.01},
        {"name": "crank_1.x1", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 1.0}]})
    for sep, suffix in ((";", ".csv"), ("\t", ".tsv")):
        p = write(tmp_path / f"cranks{suffix}", sep.join(["serial", "bore [mm]", "x1 [um]"]) + "\n"
                  + sep.join(["uncertainty", "0,001", "0,3"]) + "\n"
                  + sep.join(["C-1", "25,011", "0,42"]) + "\n"
                  + sep.join(["C-2", "24,998", "-1,1"]) + "\n")
        fam = read_part_family(p, ["crank_1"], spec)
        np.testing.assert_allclose(fam.values, [[25.011, 0.42e-3], [24.998, -1.1e-3]], rtol=1e-15)
        np.testing.assert_allclose(fam.uncertainty, [[0.001, 0.3e-3], [0.001, 0.3e-3]], rtol=1e-15)
