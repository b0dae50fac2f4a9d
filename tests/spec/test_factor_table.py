"""A spec's ``[[factor]]``, ``[spec]`` and ``[[correlation]]`` tables are declared (rvtol.spec.tables, issue 38 item
1): every key a spec table can give is a declared key, and a declared key the factor's form does not read (another
law's parameter, another method's) is refused at that key, saying what the form reads — in TOML and in a CSV row."""
from __future__ import annotations

import pytest

from conftest import write
from rvtol.errors import SpecError
from rvtol.inputs import table_spec
from rvtol.options import describe
from rvtol.registry import table_options
from rvtol.spec import load_spec


def test_every_key_a_spec_table_gives_is_a_declared_factor_key():
    """The CSV/XLSX reader turns rows into ``[[factor]]`` tables: each key it can write (its columns, its distribution
    cell's parameters, a measured cell's) is one ``rvtol kinds factor`` lists."""
    declared = {o.key for o in describe(table_options("factor"))}
    written = ({"name", "unit", "nominal", "tolerance", "dist", "direction", "multiplicity", "basic", "shorter_side",
                "broken_edge", "separate"} | set(table_spec._KEY_OF.values()) | set(table_spec.CELL_KEYS)
               | set(table_spec.MEASURED_CELL_KEYS))
    assert written <= declared, written - declared
    assert {o.key for o in describe(table_options("correlation"))} == {"pair", "rho", "factors", "matrix"}
    assert {o.key for o in describe(table_options("spec"))} == {"name", "description", "source"}


@pytest.mark.parametrize("factor, key, words", [
    ('dist = "normal"\nsigma = 0.01\nalpha = 2', "alpha", "does not apply to dist = 'normal'"),
    ('dist = "normal"\nsigma = 0.01\ntolerance = 0.06', "tolerance", "does not apply to dist = 'normal' (it reads "
                                                                     "dist, mean, sigma, shift, sigma_level)"),
    ('dist = "weibull"\nshape = 2\nscale = 1\nmean = 1', "mean", "does not apply to dist = 'weibull'"),
    ('nominal = 1\ntolerance = "±0.1"\nskewness = 0.3', "skewness", "does not apply to a tolerance in drawing "
                                                                    "notation ('±0.1')"),
    ('dist = "normal"\nsigma = 0.01\nmethod = "kde"', "method", "does not apply to dist = 'normal'"),
])
def test_a_key_the_form_does_not_read_is_refused_at_the_key(tmp_path, factor, key, words):
    p = write(tmp_path / "spec.toml", f'[[factor]]\nname = "a"\nunit = "mm"\n{factor}\n')
    with pytest.raises(SpecError) as e:
        load_spec(p)
    assert str(e.value).startswith(f"{p}: factor[0].{key}: ") and words in str(e.value), str(e.value)


def test_a_measured_factor_refuses_another_methods_key(tmp_path):
    (tmp_path / "m.csv").write_text("d\n" + "\n".join(str(1 + 0.01 * i) for i in range(12)), encoding="utf-8")
    p = write(tmp_path / "spec.toml", '[[factor]]\nname = "a"\nunit = "mm"\ndist = "measured"\ndata = "m.csv"\n'
                                      'method = "empirical"\nbandwidth = 0.1\n')
    with pytest.raises(SpecError, match=r"factor\[0\]\.bandwidth: does not apply to a measured factor"):
        load_spec(p)


def test_a_csv_cell_parameter_the_law_does_not_read_is_refused_at_its_row_and_column(tmp_path):
    p = tmp_path / "s.csv"
    p.write_text("name,unit,tolerance,distribution\na,mm,-1..1,normal\nb,mm,-1..1,normal(alpha=2)\n", encoding="utf-8")
    with pytest.raises(SpecError) as e:
        load_spec(p)
    assert str(e.value).startswith(f"{p}: row 3, column 'distribution'") and "does not apply" in str(e.value), \
        str(e.value)


@pytest.mark.parametrize("corr, key, words", [
    ('pair = ["a", "b"]\nrho = 0.5\nfactors = ["a", "b"]', "factors", "give pair and rho, or factors and matrix"),
    ('factors = ["a", "b"]\nmatrix = [[1, 0.5], [0.5, 1]]\nrho = 0.5', "rho", "give pair = [a, b] with it"),
    ('pair = ["a", "b"]\nrho = 1.5', "rho", "must be <= 1"),
])
def test_a_correlation_of_two_forms_at_once_is_refused_at_the_key(tmp_path, corr, key, words):
    p = write(tmp_path / "spec.toml", '[[factor]]\nname = "a"\nunit = "mm"\ndist = "normal"\nsigma = 1\n'
                                      '[[factor]]\nname = "b"\nunit = "mm"\ndist = "normal"\nsigma = 1\n'
                                      f'[[correlation]]\n{corr}\n')
    with pytest.raises(SpecError) as e:
        load_spec(p)
    assert str(e.value).startswith(f"{p}: correlation[0].{key}: ") and words in str(e.value), str(e.value)
