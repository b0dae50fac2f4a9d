import numpy as np
import pytest

from rvtol import units
from rvtol.design import load_design
from rvtol.errors import SpecError
from rvtol.spec import Requirement, load_requirements, load_spec


def test_designs_in_data_load_with_sources(root):
    for f in sorted((root / "data" / "designs").glob("*.toml")):
        d = load_design(f)
        assert d.name and len(d.params) > 0
        for p in d.params.values():
            assert p.source.strip(), f"{f.name}: {p.name} has no source"


def test_design_values_in_base_units(root):
    d = load_design(root / "data" / "designs" / "rv80e_te.toml")
    assert d["pin.circle_radius"] == pytest.approx(76.5)                      # mm
    assert d["sun.pressure_angle"] == pytest.approx(np.radians(20.0))         # rad
    assert d["reducer.rated_torque"] == pytest.approx(784e3)                  # N·mm
    assert d.value("reducer.rated_torque", "N*m") == pytest.approx(784.0)
    # the catalogue ratio follows from the teeth: i = 1 + z_pins·z_planet/z_sun
    assert d["reducer.ratio"] == 1 + d["pin.count"] * d["planet.teeth"] / d["sun.teeth"]
    d2 = d.with_values(**{"pin.radius": 3.5})
    assert d2["pin.radius"] == 3.5 and d["pin.radius"] == 3.0
    with pytest.raises(SpecError, match="no parameter"):
        d["pin.diameter"]


def test_array_parameters(root):
    d = load_design(root / "data" / "designs" / "bx40e.toml")
    assert np.allclose(d["example.part_errors"], [-1.6e-3, 5.3e-3, 5.8e-3, 3.2e-3])


def test_spec_nominal_defaults_to_mean_and_units(root):
    s = load_spec(root / "data" / "specs" / "rv80e_axial_stack.toml")
    f = s.factor("carrier_gap")
    assert f.nominal_value == pytest.approx(24.083)  # mean incl. the 3 µm shift
    assert s.std_base()[0] == pytest.approx(0.0035)
    assert s.correlation[1, 2] == 0.5 and s.correlation[0, 1] == 0.0
    assert s.scaled({"carrier_gap": 0.5}).std_base()[0] == pytest.approx(0.00175)


def test_requirements_file_and_unit_conversion(root):
    (r,) = load_requirements(root / "data" / "requirements" / "rv80e_axial_stack.toml")
    assert r.min_cpk == 1.33 and r.unit == "um"
    r_mm = r.in_unit("mm")
    assert r_mm.lower == pytest.approx(0.05) and r_mm.upper == pytest.approx(0.13)


def test_requirement_defaults():
    r = Requirement("y", upper=1.0)
    assert r.min_yield == Requirement.DEFAULT_MIN_YIELD and r.basis == "lower_bound"
    with pytest.raises(SpecError):
        Requirement("y")


@pytest.mark.parametrize("lower, upper", [(2.0, 1.0), (1.0, 1.0)])
def test_a_requirement_made_in_code_refuses_limits_in_the_wrong_order(lower, upper):
    """The study loader refuses them at the file's key; a Requirement built in code (the API) is held to the same
    rule — a band that conforms nowhere would judge every unit non-conforming."""
    with pytest.raises(SpecError, match=f"limits in the wrong order: lower {lower} >= upper {upper}"):
        Requirement("y", lower=lower, upper=upper, key="requirement[0]")


def test_unit_labels():
    assert units.label("um") == "µm" and units.label("N*m/arcmin") == "N·m/arcmin"


def test_requirement_unit_is_optional(tmp_path):
    p = tmp_path / "r.toml"
    p.write_text('[[requirement]]\noutput = "y"\nupper = 1.0\n')
    (r,) = load_requirements(p)
    assert r.unit is None and r.in_unit("arcmin").unit == "arcmin" and r.upper == 1.0
