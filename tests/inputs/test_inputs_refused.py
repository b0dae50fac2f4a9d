"""Inputs that were accepted without a word (issue 37 item 10): a nominal beside limits that cannot be its own, an upper
deviation below the lower one, a shift that moves the mean off the drawing, the unit mil, a magnitude read over a band
about the nominal, and a unit-free formula summing factors of different units."""
import pytest

from rvtol import units
from rvtol.cli import main
from rvtol.errors import InputError, SpecError
from rvtol.inputs import iso286
from rvtol.inputs.notation import NotationError, parse_tolerance
from rvtol.spec import load_spec, spec_from_table
from rvtol.study import load_study, run_study


def factor(**keys):
    keys = {"name": "a", "unit": "mm", **keys}
    return spec_from_table({"factor": [keys]}, file="s.toml").factors[0]


def table(tmp_path, text):
    p = tmp_path / "s.csv"
    p.write_text(text, encoding="utf-8")
    return load_spec(p)


# -- a nominal beside limits ------------------------------------------------------------------------------------------
def test_a_nominal_beside_limits_that_cannot_be_its_own_is_refused(tmp_path):
    with pytest.raises(SpecError, match=r"factor\[0\]\.tolerance: .*the nominal 10 lies 0\.7 mm above its limits "
                                        r"9\.1\.\.9\.3"):
        factor(nominal=10, tolerance="9.1..9.3")                     # was accepted: nominal 10, parts at 9.2
    with pytest.raises(SpecError, match=r"row 2, column 'tolerance': .*the nominal 25 lies 5 mm below its limits 30\.\.31"):
        table(tmp_path, "name,nominal,tolerance,unit\nbore,25,30..31,mm\n")
    assert table(tmp_path, "name,nominal,tolerance,unit\nbore,25,24.95..25.05,mm\n").factors[0].band == (24.95, 25.05)
    with pytest.raises(NotationError, match="the nominal 30 lies 26.7 ° above its limits 3.1..3.3, farther than the "
                                            "band's own width"):
        parse_tolerance("3.1..3.3", nominal=30, unit="deg")


@pytest.mark.parametrize("cls", ["g6", "e8", "d9", "a11", "zc9", "A11", "ZC8"])
def test_an_iso_class_written_as_limits_beside_its_nominal_is_accepted(cls):
    """A band may lie off its nominal as far as ISO 286 puts any class (a11 at 25 mm: 0.3 mm below)."""
    lim = iso286.limits(cls, 25.0)
    lo, hi = 25 + lim.lower / 1000, 25 + lim.upper / 1000
    assert parse_tolerance(f"{lo:.3f}..{hi:.3f}", nominal=25, unit="mm").limits == pytest.approx((lo, hi))
    assert iso286.farthest_band(25.0) == 300.0 and iso286.farthest_band(400.0) == 2100.0


# -- an upper deviation below the lower one -------------------------------------------------------------------------
def test_swapped_plus_and_minus_tolerance_columns_are_refused(tmp_path):
    with pytest.raises(SpecError, match=r"row 2, column '\+tol': the upper deviation \(\+tol -0\.1\) is below the lower "
                                        r"one \(-tol, taken below the nominal: -0\.05\)"):
        table(tmp_path, "name,nominal,+tol,-tol,unit\ngap,10,-0.1,0.05,mm\n")   # was silently 9.9 … 9.95
    g6 = table(tmp_path, "name,nominal,+tol,-tol,unit\nshaft,25,-0.007,0.020,mm\n").factors[0]   # both below: fine
    assert g6.band == pytest.approx((24.980, 24.993))
    # either order of two signed deviations is the notation's, not a swap
    assert parse_tolerance("-0.05/+0.1", nominal=10).limits == pytest.approx((9.95, 10.1))


# -- a distribution's parameters putting the mean off the drawing -------------------------------------------------------
def test_a_shift_or_mean_outside_the_drawing_band_is_refused(tmp_path):
    with pytest.raises(SpecError, match=r"factor\[0\]\.shift: shift = 0\.6 puts the uniform distribution's mean at 10\.6, "
                                        r"outside the drawing's limits 9\.5\.\.10\.5"):
        factor(nominal=10, tolerance="±0.5", dist="uniform", shift=0.6)
    with pytest.raises(SpecError, match=r"row 2, column 'distribution': shift = 0\.5 puts the uniform distribution's "
                                        r"mean at 10\.5, outside the drawing's limits 9\.95\.\.10\.05"):
        table(tmp_path, "name,nominal,tolerance,distribution,unit\ngap,10,±0.05,uniform(shift=0.5),mm\n")
    with pytest.raises(SpecError, match=r"factor\[0\]\.mean: mean = 11"):
        factor(nominal=10, tolerance="±0.5", mean=11)
    assert factor(nominal=10, tolerance="±0.5", dist="uniform", shift=0.2).dist.mean == pytest.approx(10.2)


# -- mil, and "did you mean" of another dimension ---------------------------------------------------------------------
def test_mil_is_a_thousandth_of_an_inch():
    assert units.convert(1.0, "mil", "mm") == pytest.approx(0.0254, rel=1e-15)
    assert factor(unit="mil", nominal=0, tolerance="±2").band == (-2.0, 2.0)
    assert parse_tolerance("1 in ±5 mils", unit="mm").limits == pytest.approx((25.273, 25.527))


def test_did_you_mean_never_names_a_unit_of_another_dimension():
    """Each unit misspelt (a letter dropped or doubled) where a dimension is expected: the unit suggested, if any, is of
    that dimension (``mils`` for a length was answered "did you mean 'min'", a time)."""
    import re

    dims = {units.dimension(u) for u in units.known_units()}
    for u in units.known_units():
        for typo in {u[:-1], u + u[-1], "x" + u}:
            if not typo or typo in units.known_units():
                continue
            for dim in dims:
                try:
                    units.canonical(typo, dim)
                except InputError as exc:
                    m = re.search(r"did you mean '([^']+)'", exc.reason)
                    assert m is None or units.dimension(m.group(1)) == dim, (typo, dim, exc.reason)
                    assert f"unknown {dim.replace('_', ' ')} unit" in exc.reason


def test_a_measured_header_unit_is_suggested_in_the_factors_dimension(tmp_path):
    from rvtol.inputs.measured import read_measurements

    p = tmp_path / "m.csv"
    p.write_text("d [mn],n\n1,1\n2,2\n", encoding="utf-8")
    with pytest.raises(SpecError, match=r"row 1, column 'd \[mn\]': unknown length unit 'mn' \(did you mean 'm'\?\)"):
        read_measurements(p, "d", unit="mm")           # not 'min' (a time)


# -- a magnitude over a band about the nominal --------------------------------------------------------------------------
def test_a_magnitude_over_a_symmetric_band_is_refused_in_tables_and_toml_alike(tmp_path):
    why = r"a rayleigh factor is a magnitude .* '±0\.05' is a band about the nominal and does not say where they start"
    with pytest.raises(SpecError, match=r"row 2, column 'distribution': " + why):
        table(tmp_path, "name,nominal,tolerance,distribution,unit\nrun,10,±0.05,rayleigh,mm\n")   # was from 9.95
    with pytest.raises(SpecError, match=r"factor\[0\]\.dist: " + why):
        factor(nominal=10, tolerance="±0.05", dist="rayleigh")
    assert factor(tolerance="max 0.05", dist="rayleigh").band == (0.0, 0.05)
    assert factor(nominal=10, tolerance="+0.05/0", dist="rayleigh").band == pytest.approx((10.0, 10.05))


# -- a unit-free formula that sums mm and µm ----------------------------------------------------------------------------
STUDY = """[study]
name = "mixed"
[[factor]]
name = "housing"
unit = "mm"
nominal = 20
tolerance = "±0.02"
[[factor]]
name = "shim"
unit = "um"
nominal = 50
tolerance = "±5"
[model]
kind = "formula"
units = "{units}"
[[model.output]]
name = "gap"
formula = "housing - shim"
unit = "mm"
[[requirement]]
output = "gap"
lower = 0
"""


def test_a_factor_formula_summing_mm_and_um_says_so_in_the_run(tmp_path, capsys):
    p = tmp_path / "study.toml"
    p.write_text(STUDY.format(units="checked"), encoding="utf-8")
    assert load_study(p).notes == []
    p.write_text(STUDY.format(units="factor"), encoding="utf-8")
    st = load_study(p, n=16, executor="serial", progress=False)
    note = ("output 'gap': with units = \"factor\" the formula sums 'housing' (mm) and 'shim' (µm) as the numbers "
            "written — 1 µm counts as 1 mm")
    assert len(st.notes) == 1 and st.notes[0].startswith(note)
    assert main(["check", str(p)]) == 0
    assert f"rvtol: note: {note}" in capsys.readouterr().out
    st.analyses = []
    run = run_study(st)
    assert run.summary()["notes"] == st.notes                                     # summary.json
    assert [v for i, v in run_table_rows(run) if i == "note"] == st.notes         # the report's run table


def run_table_rows(run):
    from rvtol.report.standard import run_table

    frame = run_table(run).frame
    return list(zip(frame["item"], frame["value"]))
