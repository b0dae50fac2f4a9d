import math

import numpy as np
import pytest

from rvtol import units
from rvtol.errors import UnitError


def test_base_units_and_conversions():
    assert units.to_base(1.0, "um") == pytest.approx(1e-3)
    assert units.to_base(1.0, "m") == pytest.approx(1e3)
    assert units.convert(1.0, "arcmin", "arcsec") == pytest.approx(60.0)
    assert units.convert(1.0, "rad", "arcsec") == pytest.approx(180 * 3600 / math.pi, rel=1e-12)
    assert units.convert(1.0, "N*m", "N*mm") == pytest.approx(1000.0)
    assert units.convert(784.0, "N*m", "kN*m") == pytest.approx(0.784)
    # 1 N·m/arcmin = 1000 N·mm per (π/10800) rad
    assert units.to_base(1.0, "N*m/arcmin") == pytest.approx(1000 * 10800 / math.pi)
    # mass in tonnes keeps F = m·a consistent in mm, N, s
    assert units.to_base(1.0, "kg") * units.to_base(1.0, "m") == pytest.approx(1.0)  # 1 kg·m/s² = 1 N


def test_aliases_and_dimensions():
    assert units.canonical("µm") == "um"
    assert units.canonical("N·m") == "N*m"
    assert units.dimension("arcsec") == "angle"
    assert units.base_unit("um") == "mm"
    assert units.base_unit("arcmin") == "rad"


def test_arcsec_per_um_at_radius_matches_reference():
    # REFERENCE.md: 1 µm seen at a radius of R mm is 206.2648 / R arcsec
    assert units.arcsec_per_um_at_radius(76.5) == pytest.approx(206.2648 / 76.5, rel=1e-6)


def test_vectorised():
    a = np.array([1.0, 2.0])
    assert np.allclose(units.from_base(units.to_base(a, "um"), "um"), a)


@pytest.mark.parametrize("bad", ["milimeter", "mm2", 3])
def test_unknown_unit(bad):
    with pytest.raises(UnitError):
        units.canonical(bad)


def test_incompatible_conversion():
    with pytest.raises(UnitError):
        units.convert(1.0, "mm", "rad")


def test_inch_is_exactly_25_4_mm():
    # the international inch (1959): 25.4 mm exactly
    assert units.to_base(1.0, "in") == 25.4
    assert units.canonical('"') == "in" and units.canonical("inch") == "in"
    assert units.convert(1.0, "thou", "um") == pytest.approx(25.4, rel=1e-15)
    assert units.dimension("in") == "length"


def test_an_unknown_unit_of_one_named_dimension_lists_only_that_dimension():
    with pytest.raises(UnitError) as e:
        units.canonical("milimeter", "length")
    assert e.value.reason == "unknown length unit 'milimeter' (known: cm, in, m, mm, nm, thou, um)"


def test_a_value_in_its_base_unit_is_handed_back_untouched():
    # no copy of a sample array, and an integer stays an integer (3 mm is written "3", not "3.0")
    a = np.array([1.0, 2.0])
    assert units.to_base(a, "mm") is a and units.from_base(a, "rad") is a and units.convert(a, "N", "N") is a
    for unit in ("mm", "rad", "N", "N*mm", "s"):
        assert type(units.to_base(3, unit)) is int and type(units.from_base(3, unit)) is int
    assert repr(units.convert(3, "mm", "mm")) == "3"
