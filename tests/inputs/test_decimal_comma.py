"""Decimal commas in semicolon- and tab-separated tables (rvtol.inputs.sheets): a European spreadsheet saves
``25,011`` for 25.011 in a ``;`` or tab file, and every table reader reads it so.

The expected numbers are typed here; each reader is checked on a ``;`` file and a TSV: how a file uses the comma
(:func:`comma_role`: a ``25,011`` is decided by the file's other numbers), the cell reader (:func:`cell_number`),
the header-row table (:meth:`Table.number`) and a reader built on it (a measured part family,
:mod:`rvtol.production.measured_parts`).  Comma-separated files and thousands separators are
tests/inputs/test_sheet_numbers.py's."""
import numpy as np
import pytest

from conftest import write
from rvtol.errors import InputError
from rvtol.inputs.sheets import DECIMAL, EITHER, THOUSANDS, cell_number, comma_role, read_table
from rvtol.production.measured_parts import read_part_family
from rvtol.spec import spec_from_table

#: cell text in a ';' or tab file -> the number it means
COMMA_CELLS = {"25,011": 25.011, "-0,004": -0.004, "\u22120,5": -0.5, ",5": 0.5, "0,0105": 0.0105,
               "1,5e-3": 1.5e-3, "+3,25": 3.25, "25": 25.0}


@pytest.mark.parametrize("delimiter", [";", "\t", " "])
def test_a_file_whose_numbers_write_decimal_commas_reads_them_so(delimiter):
    assert comma_role(delimiter, list(COMMA_CELLS)) == DECIMAL
    assert comma_role(delimiter, ["25,011", "0,5"]) == DECIMAL            # 0,5 decides the 25,011 beside it
    assert comma_role(delimiter, ["25,011", "3"]) == EITHER               # nothing decides: refused when read
    assert comma_role(",", list(COMMA_CELLS)) == THOUSANDS                # a comma-separated file: never decimal


def test_cell_number_reads_a_decimal_comma_where_the_file_writes_them():
    for text, x in COMMA_CELLS.items():
        assert cell_number(text, DECIMAL) == x, text
    assert cell_number("0,0105", EITHER) == 0.0105                       # no thousands group: a decimal comma
    with pytest.raises(ValueError):
        cell_number("25,011", EITHER)
    for bad in ("25,0,1", "25;011", ",,5"):
        with pytest.raises(ValueError):
            cell_number(bad, DECIMAL)


@pytest.mark.parametrize("suffix, sep", [(".csv", ";"), (".tsv", "\t"), (".txt", ";")])
def test_a_header_table_reads_decimal_commas(tmp_path, suffix, sep):
    cells = list(COMMA_CELLS)
    p = write(tmp_path / f"t{suffix}", "# exported with a German locale\n" + f"x [mm]{sep}n\n"
              + "".join(f"{c}{sep}{i}\n" for i, c in enumerate(cells)))
    t = read_table(p)
    assert t.comma == DECIMAL and t.names == ["x", "n"]
    got = [t.number(row, c, 0) for row, c in t.rows]
    assert got == list(COMMA_CELLS.values())
    row, c = t.rows[0]
    with pytest.raises(InputError, match="25,0,1"):
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
