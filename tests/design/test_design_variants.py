"""Design variants (``[design] extends``) and derived numbers (``formula``): a variant is a small file over its
base, the base's formulas are recomputed with the variant's numbers, each number says which file it came from,
and every mistake is one located error (rvtol.design)."""
import math
from pathlib import Path

import pytest

from rvtol.design import load_design
from rvtol.errors import InputError, SpecError
from rvtol.models.reducer_20dof.geometry import geometry_from_design, involute, inverse_involute

from conftest import ROOT

PRODUCT = ROOT / "data/products/rv80e/design.toml"
VARIANT = ROOT / "data/products/rv80e_153/design.toml"
RHO = 7850e-12          # steel, t/mm^3 (base units)


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


BASE = """
[design]
name = "base"
[gear]
teeth = { value = 16, unit = "1", source = "s" }
module = { value = 1.5, unit = "mm", source = "s" }
pitch_radius = { formula = "gear.module * gear.teeth / 2", unit = "mm", source = "d = m z" }
area = { formula = "pi * gear.pitch_radius ** 2", unit = "1", source = "π r² (mm², unit 1)" }
label = { value = "spur", unit = "1", source = "s" }
"""


def test_formula_is_evaluated_in_base_units_and_written_in_its_unit(tmp_path):
    d = load_design(write(tmp_path / "b.toml", BASE))
    assert d["gear.pitch_radius"] == pytest.approx(12.0)
    assert d["gear.area"] == pytest.approx(math.pi * 144.0)         # a formula of a formula
    p = d.param("gear.pitch_radius")
    assert p.formula == "gear.module * gear.teeth / 2" and p.value == pytest.approx(12.0)
    # replacing a number recomputes what derives from it
    assert d.with_values(**{"gear.teeth": 20})["gear.area"] == pytest.approx(math.pi * 15.0 ** 2)


def test_variant_overrides_its_base_and_says_where_each_number_came_from(tmp_path):
    base = write(tmp_path / "b.toml", BASE)
    (tmp_path / "v").mkdir()
    v = load_design(write(tmp_path / "v" / "design.toml", """
[design]
name = "variant"
extends = "../b.toml"
[gear]
teeth = { value = 20, unit = "1", source = "the variant's drawing" }
"""))
    assert v.name == "variant" and v.base[0] == str(base)
    assert v["gear.teeth"] == 20 and v["gear.module"] == 1.5
    assert v["gear.pitch_radius"] == pytest.approx(15.0)            # recomputed, not the base's 12
    assert v.where("gear.teeth") == str(tmp_path / "v" / "design.toml")
    assert v.where("gear.module") == str(base) and v.where("gear.pitch_radius") == str(base)
    frame = v.to_frame().set_index("parameter")
    assert frame.loc["gear.teeth", "file"] == "v/design.toml"
    assert frame.loc["gear.module", "file"] == f"{tmp_path.name}/b.toml"


@pytest.mark.parametrize("text, key, reason", [
    ('[gear]\nteth = { value = 20, unit = "1", source = "s" }', "gear.teth", "did you mean 'gear.teeth'"),
    ('[gear]\nteeth = { value = 20, formula = "1", unit = "1", source = "s" }', "gear.teeth.formula",
     "either as a value or as a formula"),
    ('[gear]\nteeth = { value = 20, unit = "1", source = "" }', "gear.teeth.source", "needs its source"),
    ('[gear]\nmodule = { formula = "gear.module * 2", unit = "mm", source = "s" }', "gear.module.formula", "cycle"),
    ('[gear]\nmodule = { formula = "gear.label * 2", unit = "mm", source = "s" }', "gear.module.formula",
     "not a single number"),
    ('[gear]\nmodule = { formula = "gear.modul * 2", unit = "mm", source = "s" }', "gear.module.formula",
     "unknown design number 'gear.modul'"),
    ('[gear]\nmodule = { formula = "gear.teeth ** (", unit = "mm", source = "s" }', "gear.module.formula", "formula"),
    ('[gear]\nmodule = { formula = "log(gear.teeth - 16)", unit = "mm", source = "s" }', "gear.module.formula",
     "evaluates to -inf"),
    ("", "-", "at least one number"),
])
def test_a_bad_variant_is_one_located_error(tmp_path, text, key, reason):
    write(tmp_path / "b.toml", BASE)
    v = write(tmp_path / "v.toml", '[design]\nname = "v"\nextends = "b.toml"\n' + text)
    with pytest.raises(InputError, match=reason) as e:
        load_design(v)
    assert e.value.file == str(v) and e.value.key == key


def test_variant_extends_one_level_and_a_file_that_exists(tmp_path):
    write(tmp_path / "b.toml", BASE)
    write(tmp_path / "v.toml", '[design]\nname = "v"\nextends = "b.toml"\n[gear]\nteeth = { value = 1, unit = "1", '
                                'source = "s" }')
    w = write(tmp_path / "w.toml", '[design]\nname = "w"\nextends = "v.toml"\n[gear]\nteeth = { value = 2, unit = '
                                   '"1", source = "s" }')
    with pytest.raises(SpecError, match="one level only") as e:
        load_design(w)
    assert (e.value.file, e.value.key) == (str(w), "design.extends")
    x = write(tmp_path / "x.toml", '[design]\nname = "x"\nextends = "nothere.toml"\n')
    with pytest.raises(SpecError, match="not found"):
        load_design(x)


def test_product_formulas_give_the_hand_computed_numbers():
    """The product's derived numbers, now formulas, are the values its notes computed by hand (README §1)."""
    d = load_design(PRODUCT)
    assert d["reducer.ratio"] == 81.0
    assert d["pin.groove_radius"] == pytest.approx(3.003)          # the build's 3-µm fit (build.toml [[choice]])
    for key, kg in (("mass.sun", 0.069), ("mass.planet_crank", 0.329), ("mass.disc", 1.050)):
        assert d.value(key, "kg") == pytest.approx(kg, abs=0.0006)
    assert d.value("mass.planet_crank_inertia", "kg*mm^2") == pytest.approx(66.4, abs=0.05)
    assert d.value("mass.disc_inertia", "kg*mm^2") == pytest.approx(3482, abs=0.5)


def test_rv80e_153_variant_recomputes_what_derives_from_its_numbers():
    """Yang et al.'s prototypes as a variant: only z1, z2, R, r_p written; the ratio, the pin gear, the groove,
    the first-stage masses recomputed (hand values: i = 1 + 40·38/10, K1 = 40·1.5/77.5, r_g = r_p + 2 µm,
    sun and planet as steel cylinders of the new pitch radii)."""
    v, b = load_design(VARIANT), load_design(PRODUCT)
    assert v["reducer.ratio"] == 153.0 and v.where("reducer.ratio") == str(PRODUCT)
    assert {k for k, p in v.params.items() if p.file == str(VARIANT)} == {
        "sun.teeth", "planet.teeth", "pin.circle_radius", "pin.radius"}
    assert v["pin.groove_radius"] == pytest.approx(4.003)
    sun = RHO * math.pi * ((1.75 * 10 / 2) ** 2 * 7 + 6 ** 2 * 40)
    assert v["mass.sun"] == pytest.approx(sun, rel=1e-12)
    assert v["mass.planet_crank"] - b["mass.planet_crank"] == pytest.approx(
        RHO * math.pi * 7 * ((1.75 * 38 / 2) ** 2 - 28 ** 2), rel=1e-9)
    assert v["mass.disc"] == pytest.approx(b["mass.disc"])          # R − r_p = 73.5 mm in both
    assert v["pin.count"] * v["cycloid.eccentricity"] / v["pin.circle_radius"] == pytest.approx(40 * 1.5 / 77.5)
    assert operating_centre_distance(v) == pytest.approx(operating_centre_distance(b))   # z1 + z2 = 48, same shifts
    assert abs(operating_centre_distance(v) - v["crank_bearing.centre_radius"]) < 1e-3


def operating_centre_distance(d):
    """a' = m (z_s + z_p)/2 · cos α / cos α' with inv α' = inv α + 2 tan α (x_s + x_p)/(z_s + z_p)."""
    zs, zp, m, a = d["sun.teeth"], d["planet.teeth"], d["sun.module"], d["sun.pressure_angle"]
    inv_w = involute(a) + 2 * math.tan(a) * (d["sun.profile_shift"] + d["planet.profile_shift"]) / (zs + zp)
    return m * (zs + zp) / 2 * math.cos(a) / math.cos(inverse_involute(inv_w))


def test_a_crank_circle_the_gears_do_not_have_is_refused_in_the_file_that_wrote_it(tmp_path):
    """A variant that changes z1 + z2 but keeps its base's written crank circle would put the cranks' elements
    where the planets are not: refused, naming the base file's key."""
    v = write(tmp_path / "v.toml", f'[design]\nname = "v"\nextends = "{PRODUCT}"\n'
                                   '[planet]\nteeth = { value = 36, unit = "1", source = "s" }\n')
    with pytest.raises(SpecError, match="operating centre distance") as e:
        geometry_from_design(load_design(v))
    assert (e.value.file, e.value.key) == (str(PRODUCT), "crank_bearing.centre_radius")
