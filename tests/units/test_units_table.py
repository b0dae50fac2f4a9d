"""Every unit rvtol knows against pint (rvtol.units): the factor to the base unit of its dimension (mm, rad, N, s,
tonne and their products, the project's base units), each unit's pint spelling typed here.  A factor typed wrong
in the table (a conversion every input and report goes through) fails here, whichever unit it is."""
import pint
import pytest

from rvtol import units
from rvtol.errors import UnitError

UREG = pint.UnitRegistry()

#: rvtol's unit -> the same unit in pint's words
PINT = {
    "1": "dimensionless", "%": "percent",
    "mm": "millimeter", "um": "micrometer", "nm": "nanometer", "cm": "centimeter", "m": "meter", "in": "inch",
    "thou": "thou",
    "rad": "radian", "mrad": "milliradian", "urad": "microradian", "deg": "degree", "arcmin": "arcminute",
    "arcsec": "arcsecond",
    "N": "newton", "kN": "kilonewton",
    "N*mm": "newton * millimeter", "N*m": "newton * meter", "kN*m": "kilonewton * meter",
    "N/mm": "newton / millimeter", "N/um": "newton / micrometer", "N/m": "newton / meter",
    "N*mm/rad": "newton * millimeter / radian", "N*m/rad": "newton * meter / radian",
    "N*m/arcmin": "newton * meter / arcminute", "N*m/arcsec": "newton * meter / arcsecond",
    "MPa": "megapascal", "GPa": "gigapascal", "Pa": "pascal",
    "s": "second", "ms": "millisecond", "min": "minute",
    "rad/s": "radian / second", "rpm": "revolution / minute",
    "t": "tonne", "kg": "kilogram", "g": "gram",
    "t*mm^2": "tonne * millimeter ** 2", "kg*mm^2": "kilogram * millimeter ** 2", "kg*m^2": "kilogram * meter ** 2",
    "kg/m^3": "kilogram / meter ** 3", "t/mm^3": "tonne / millimeter ** 3",
    "N*s/mm": "newton * second / millimeter", "N*s/m": "newton * second / meter",
    "rad/mm": "radian / millimeter", "arcmin/mm": "arcminute / millimeter", "arcsec/um": "arcsecond / micrometer",
    "arcmin/um": "arcminute / micrometer",
}
#: each dimension's base unit (mm, N, rad, s; mass in tonnes so that N = t·mm/s²), in pint's words
BASE = {
    "dimensionless": "dimensionless", "length": "millimeter", "angle": "radian", "force": "newton",
    "torque": "newton * millimeter", "stiffness": "newton / millimeter",
    "torsional_stiffness": "newton * millimeter / radian", "pressure": "megapascal", "time": "second",
    "angular_speed": "radian / second", "mass": "tonne", "inertia": "tonne * millimeter ** 2",
    "density": "tonne / millimeter ** 3", "damping": "newton * second / millimeter",
    "angle_per_length": "radian / millimeter",
}


def test_every_unit_is_checked():
    assert set(units.known_units()) == set(PINT) | {"cost"}


@pytest.mark.parametrize("unit", sorted(PINT))
def test_each_unit_converts_to_its_base_as_pint_does(unit):
    expected = UREG.Quantity(1.0, PINT[unit]).to(BASE[units.dimension(unit)]).magnitude
    assert units.factor(unit) == pytest.approx(expected, rel=1e-14, abs=0.0)
    assert units.to_base(2.0, unit) == pytest.approx(2.0 * expected, rel=1e-14, abs=0.0)
    assert units.from_base(2.0 * expected, unit) == pytest.approx(2.0, rel=1e-14)


def test_each_dimension_has_its_base_unit():
    assert {d: units.BASE_UNITS[d] for d in BASE} == {
        "dimensionless": "1", "length": "mm", "angle": "rad", "force": "N", "torque": "N*mm", "stiffness": "N/mm",
        "torsional_stiffness": "N*mm/rad", "pressure": "MPa", "time": "s", "angular_speed": "rad/s", "mass": "t",
        "inertia": "t*mm^2", "density": "t/mm^3", "damping": "N*s/mm", "angle_per_length": "rad/mm"}
    assert units.dimension("cost") == "cost" and units.factor("cost") == 1.0


def test_a_unit_of_another_dimension_is_named_with_its_own():
    with pytest.raises(UnitError, match=r"unit 'deg' is an? angle, expected length or force"):
        units.require_dimension("deg", ("length", "force"))
    assert units.require_dimension("µm", "length") == "um"


def test_labels_and_an_unknown_unit_printed_as_written():
    assert [units.label(u) for u in ("um", "µm", "deg", "N*m/arcmin", "kg*m^2", "1", "mm")] == [
        "µm", "µm", "°", "N·m/arcmin", "kg·m²", "–", "mm"]
    assert units.label("milimeter") == "milimeter" and units.label(3) == "3"      # a label never raises


def test_a_number_label_writes_infinity_as_such():
    assert [units.number_label(v) for v in (float("inf"), 0.25, 1e4, 1e-7)] == ["∞", "0.25", "10000", "1e-07"]
