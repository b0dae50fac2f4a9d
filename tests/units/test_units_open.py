"""Units outside rvtol's table, read by pint with the dimension check kept (issue 42 item 4; rvtol.units).

References: the SI prefixes by hand (1 m² = 10⁶ mm², 1 cm² = 100 mm², 1 h = 60 min = 3600 s, 1 N/mm² = 1 MPa
= 10⁶ Pa) and, where the hand gets tedious, pint itself on the unit as written."""
import math

import pytest

from rvtol import units
from rvtol.cli import main
from rvtol.errors import UnitError
from rvtol.mc import run_monte_carlo
from rvtol.models.formula import dimensions
from rvtol.study import load_study

from conftest import write


def test_an_area_converts_between_mm2_cm2_and_m2():
    assert units.convert(2.5e6, "mm²", "m^2") == pytest.approx(2.5, rel=1e-15)
    assert units.convert(3.0, "cm^2", "mm**2") == pytest.approx(300.0, rel=1e-15)
    assert units.to_base(1.0, "m²") == pytest.approx(1e6, rel=1e-15)
    # one area, whatever the spelling: mm², mm^2, mm**2 and mm*mm are the same unit, printed mm²
    assert {units.canonical(u) for u in ("mm²", "mm^2", " mm**2 ", "mm*mm")} == {"mm**2"}
    assert units.dimension("cm²") == units.base_unit("cm²") == "mm**2" and units.label("mm^2") == "mm²"


def test_a_time_in_hours_or_minutes_converts_to_seconds():
    assert units.convert(1.5, "h", "min") == pytest.approx(90.0, rel=1e-15)     # h read by pint, min in the table
    assert units.convert(2.0, "min", "s") == 120.0
    assert units.dimension("h") == "time" and units.base_unit("hour") == "s"


def test_a_mass_and_a_cost_outside_the_table_reach_the_table_units():
    assert units.convert(1.0, "lb", "kg") == pytest.approx(0.45359237, rel=1e-15)    # the international pound
    assert units.dimension("lb") == "mass" and units.base_unit("lb") == "t"
    assert units.convert(1.0, "cost/m", "cost/mm") == pytest.approx(1e-3, rel=1e-15)


def test_a_pressure_in_n_per_mm2_is_megapascals():
    assert units.convert(250.0, "N/mm²", "MPa") == pytest.approx(250.0, rel=1e-15)
    assert units.convert(250.0, "MPa", "N/mm^2") == pytest.approx(250.0, rel=1e-15)
    assert units.convert(210.0, "kN/mm^2", "GPa") == pytest.approx(210.0, rel=1e-15)
    assert units.dimension("N/mm²") == "pressure" and units.base_unit("N/mm²") == "MPa"


def test_a_unit_of_another_dimension_is_refused():
    with pytest.raises(UnitError, match=r"cannot convert 'mm²' \(mm\*\*2\) to 'mm' \(length\)"):
        units.convert(1.0, "mm²", "mm")
    with pytest.raises(UnitError, match=r"unit 'cm\^2' is a mm\*\*2, expected length"):
        units.require_dimension("cm^2", "length")
    # an angle stays a dimension of its own (pint calls radians and ppm both dimensionless), and so does a frequency
    # beside an angular speed (rad/s, rpm: pint gives Hz the same dimensionality)
    assert units.dimension("grad") == "angle" and units.dimension("ppm") == "dimensionless"
    assert units.convert(200.0, "grad", "deg") == pytest.approx(180.0, rel=1e-15)
    assert units.convert(5e4, "ppm", "%") == pytest.approx(5.0, rel=1e-15)
    for a, b in (("grad", "ppm"), ("Hz", "rpm"), ("deg/s", "Hz")):
        with pytest.raises(UnitError, match="cannot convert"):
            units.convert(1.0, a, b)
    assert units.convert(1.0, "deg/s", "rpm") == pytest.approx(60.0 / 360.0, rel=1e-14)


def test_a_unit_of_the_table_keeps_the_tables_factor_to_the_last_bit():
    """pint's own arithmetic differs from the table's in the last bit for some units (arcmin, nm): the table's stay
    the hand definitions (π/10800 rad, 10⁻⁶ mm) exactly, with pint loaded or not."""
    units.factor("cm^2")                                  # pint is loaded
    assert units.factor("arcmin") == math.pi / 10800.0 and units.factor("′") == math.pi / 10800.0
    assert units.factor("nm") == 1e-6 and units.factor("kg/m^3") == 1e-12
    assert units.label("1") == "–" and units.label("kg*m^2") == "kg·m²"


def test_a_unit_pint_does_not_know_is_the_same_error_as_before():
    with pytest.raises(UnitError) as e:
        units.canonical("mmm", "length")
    assert e.value.reason == "unknown length unit 'mmm' (did you mean 'mm'?) (known: cm, in, m, mm, nm, thou, um)"


@pytest.mark.parametrize("unit, dim, hint", [
    ("de", "angle", "did you mean 'deg'?"),       # pint: a deci-elementary-charge
    ("degC", "length", "known: "),                # an offset scale: no product of powers of base units
    ("A", "force", "known: "),                    # an ampere: outside mm, t, s, rad and K
])
def test_a_unit_pint_reads_as_none_of_rvtols_is_unknown(unit, dim, hint):
    with pytest.raises(UnitError, match=f"unknown {dim} unit '{unit}'") as e:
        units.canonical(unit, dim)
    assert hint in e.value.reason
    assert units.label(unit) == unit          # a label never raises


def test_a_temperature_coefficient_reaches_the_formula_registry():
    # 23 µm/(m·K) (aluminium) is 2.3e-5 per kelvin; the formula registry holds kelvin for it
    assert units.convert(23.0, "um/m/K", "1/K") == pytest.approx(2.3e-5, rel=1e-14)
    q = dimensions.quantity("um/m/K")
    assert q.magnitude == pytest.approx(2.3e-5 / 23.0, rel=1e-14) and str(q.units) == "1 / kelvin"
    assert dimensions.quantity("cm^2").to("mm**2").magnitude == pytest.approx(100.0, rel=1e-15)


STUDY = """
[study]
name = "plate"
spec = "spec.toml"

[model]
kind = "formula"
[[model.output]]
name = "area"
formula = "3 * A"
unit = "m^2"

[sampling]
n = 400
seed = 3
"""

SPEC = """
[[factor]]
name = "A"
unit = "cm²"
dist = "normal"
mean = 12.5
tolerance = 0.6
"""


def test_a_monte_carlo_study_with_a_factor_in_cm2_and_an_output_in_m2(tmp_path):
    """y = 3·A with A ~ N(12.5 cm², σ = 0.6/6 = 0.1 cm²): by hand y = 3·A·10⁻⁴ m² in every sample, with mean
    37.5 cm² = 3.75e-3 m² and σ 0.3 cm² = 3e-5 m²; 400 Latin-hypercube draws give them within a few standard errors
    (σ/√n = 1.5e-6 m²)."""
    path = write(tmp_path / "plate.toml", STUDY)
    write(tmp_path / "spec.toml", SPEC)
    st = load_study(path, executor="serial", progress=False)
    assert st.spec.factors[0].unit == "cm**2" and st.model.outputs[0].unit == "mm**2"
    mc = run_monte_carlo(st.model, st.spec, 400, seed=3, progress=False)
    a_cm2 = mc.samples.display_values()[:, 0]
    assert mc.samples.values[:, 0] == pytest.approx(100.0 * a_cm2, rel=1e-15)          # base: mm²
    assert mc.Y[:, 0] == pytest.approx(3.0 * a_cm2 * 1e-4, rel=1e-14)                 # shown in m²
    assert mc.Y[:, 0].mean() == pytest.approx(3.75e-3, abs=4 * 1.5e-6)
    assert mc.Y[:, 0].std(ddof=1) == pytest.approx(3e-5, rel=0.15)


def test_an_area_given_a_length_output_is_one_located_line_exit_2(tmp_path, capsys):
    path = write(tmp_path / "plate.toml", STUDY.replace('unit = "m^2"', 'unit = "mm"'))
    write(tmp_path / "spec.toml", SPEC)
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith(f"rvtol: error: {path}: model.output[0].formula: output 'area': ")
    assert "the output's unit 'mm' is a length (mm)" in err
