"""Measured part families from QIF 3.0 and Q-DAS DFQ files through a mapping (rvtol.inputs.inspection).

References: the truth the fixtures were written from (``data/measurements/inspection/truth.csv`` read by the
CSV reader, studies/make_inspection_fixtures.py); for the public QIF sample, the standard library's ElementTree
reading the same file independently of the xsdata bindings; for the public DFQ sample, its values as printed in
the file.
"""
import hashlib
import math
import xml.etree.ElementTree as ET

import numpy as np
import pint
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import ROOT, run_cli, write
from rvtol import units
from rvtol.errors import InputError
from rvtol.inputs.inspection import characteristic_values, check_statistics, mapped_table, read_dfq, read_qif
from rvtol.production import FamilySource, load_measured_units
from rvtol.production.measured_parts import read_part_family
from rvtol.spec import spec_from_table

DATA = ROOT / "data" / "measurements" / "inspection"
SPEC = spec_from_table({"factor": [
    {"name": "crank_1.cam.x", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 1.0},
    {"name": "crank_1.bore.d", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 5.0},
    {"name": "crank_1.cam.angle", "unit": "arcmin", "dist": "normal", "mean": 0.0, "sigma": 1.0},
]})
TOL = dict(rtol=1e-12, atol=1e-13)     # base units (mm, rad): the 17 significant digits the fixtures were written with


@pytest.fixture(scope="module")
def truth():
    return read_part_family(DATA / "truth.csv", ["crank_1"], SPEC)


def test_qif_reads_back_the_truth_it_was_written_from_in_inch_and_degree(truth):
    fam = read_part_family(DATA / "parts.qif", ["crank_1"], SPEC, mapping=DATA / "parts_qif_map.csv")
    assert fam.serials == truth.serials and fam.columns == truth.columns
    assert fam.units == ("in", "in", "deg")           # the file's units, known to rvtol by their UnitConversion
    np.testing.assert_allclose(fam.values, truth.values, **TOL)
    np.testing.assert_allclose(fam.uncertainty, truth.uncertainty, **TOL)   # C-0003's cam: its own 0.25 µm


def test_dfq_reads_back_the_truth_it_was_written_from_compact_and_coded(truth):
    fam = read_part_family(DATA / "parts.dfq", ["crank_1"], SPEC, mapping=DATA / "parts_dfq_map.csv")
    assert fam.serials == truth.serials and fam.columns == truth.columns
    assert fam.units == ("um", "mm", "deg")           # K2142 µm, mm, ° (Windows-1252 bytes)
    np.testing.assert_allclose(fam.values, truth.values, **TOL)
    u = truth.uncertainty.copy()
    u[2, 0] = 0.15e-3                                 # the mapping's one u for the cam, where the QIF had C-0003's own
    np.testing.assert_allclose(fam.uncertainty, u, **TOL)


def _elementtree_positions(path, names):
    """Independent reference: serial -> [value of each named characteristic] by ElementTree."""
    ns = {"q": "http://qifstandards.org/xsd/qif3"}
    root = ET.parse(path).getroot()
    item_id = {it.findtext("q:Name", namespaces=ns): it.get("id")
               for it in root.find("q:Characteristics/q:CharacteristicItems", ns)}
    serial = {c.get("id"): c.findtext("q:SerialNumber", namespaces=ns) for c in root.iter(f"{{{ns['q']}}}ActualComponent")}
    out = {}
    for mr in root.iter(f"{{{ns['q']}}}MeasurementResults"):
        values = {m.findtext("q:CharacteristicItemId", namespaces=ns): float(m.findtext("q:Value", namespaces=ns))
                  for m in mr.find("q:MeasuredCharacteristics/q:CharacteristicMeasurements", ns)}
        out[serial[mr.findtext("q:ActualComponentIds/q:Id", namespaces=ns)]] = [values[item_id[n]] for n in names]
    return out


def test_the_public_qif_sample_reads_back_as_elementtree_reads_it(tmp_path):
    names = ["W1RXXMRA19P", "W1RXXMRA20P", "W1RXXMRA21P", "W1RXXMRA22P"]
    spec = spec_from_table({"factor": [{"name": f"panel.hole_{k}.position", "unit": "mm", "dist": "normal",
                                        "mean": 0.0, "sigma": 1.0} for k in range(4)]})
    mapping = write(tmp_path / "map.csv", "characteristic, feature, u [um]\n"
                    + "".join(f"{n}, hole_{k}.position, 10\n" for k, n in enumerate(names)))
    sample = DATA / "public" / "SheetMetal_QIF_Results_6_samples.QIF"
    fam = read_part_family(sample, ["panel"], spec, mapping=mapping)
    ref = _elementtree_positions(sample, names)
    assert fam.serials == tuple(f"SN580280{k}" for k in range(1, 7)) == tuple(ref)
    assert fam.values.tolist() == [ref[s] for s in fam.serials]       # mm: exactly the file's numbers
    assert np.all(fam.uncertainty == 0.01)


def test_a_characteristic_measured_twice_on_a_part_is_refused_by_name(tmp_path):
    # the public sample measures each point profile twice per part (the second reading 0)
    spec = spec_from_table({"factor": [{"name": "panel.edge", "unit": "mm", "dist": "normal", "sigma": 1.0}]})
    mapping = write(tmp_path / "map.csv", "characteristic, feature, u [um]\nW1RFTMRA02V, edge, 10\n")
    with pytest.raises(InputError) as exc:
        read_part_family(DATA / "public" / "SheetMetal_QIF_Results_6_samples.QIF", ["panel"], spec, mapping=mapping)
    assert exc.value.key == "MeasurementResults id=199" and "measured 2 times" in exc.value.reason


def test_the_public_dfq_sample_reads_its_printed_values_and_is_refused_as_a_family_without_serials(tmp_path):
    path = DATA / "public" / "basicDfq_singlePart_threeCharacteristics.dfq"
    f = read_dfq(path)
    assert [c.names for c in f.characteristics.values()] == [(f"<characteristic_code_{i}>",) for i in (1, 2, 3)]
    assert [c.nominal for c in f.characteristics.values()] == [1.5, 3.0, 4.5]
    assert [[p.readings[k][0][0] for k in ("1", "2", "3")] for p in f.parts] == [
        [1.6, 3.1, 4.6], [1.7, 3.2, 4.7], [1.8, 3.3, 4.8]]
    mapping = write(tmp_path / "map.csv", "characteristic, feature, unit, u\n<characteristic_code_1>, a, mm, 0\n")
    with pytest.raises(InputError) as exc:
        mapped_table(path, mapping)
    assert (exc.value.file, exc.value.key) == (str(path), "value set 1 (line 11)")
    assert "no serial number" in exc.value.reason


QIF_MAP = (DATA / "parts_qif_map.csv").read_text(encoding="utf-8")
QIF = (DATA / "parts.qif").read_text(encoding="utf-8")
DFQ_MAP = (DATA / "parts_dfq_map.csv").read_text(encoding="utf-8")
DFQ = (DATA / "parts.dfq").read_bytes().decode("cp1252")

BAD = [
    # (case, which file is bad, file suffix, data text, mapping text, the error's file, key, a word of the reason)
    ("unknown characteristic", "qif", QIF, QIF_MAP.replace("BORE_D,", "BORE_DD,"), "map", "row 4, column 'characteristic'",
     "did you mean 'BORE_D'"),
    ("feature not in the spec", "qif", QIF, QIF_MAP.replace("bore.d,", "bore.dia,"), "map", "row 4, column 'feature'",
     "no factor 'crank_1.bore.dia'"),
    ("not well-formed", "qif", QIF[:-40], QIF_MAP, "data", "-", "not well-formed"),
    ("value not a number", "qif", QIF.replace(">0.0000165866141732283", ">x0.0000165866141732283"), QIF_MAP,
     "data", "QIFDocument", "QIF 3.0"),
    ("no serial", "qif", QIF.replace("<SerialNumber>C-0002</SerialNumber>", ""), QIF_MAP, "data",
     "MeasurementResults id=16", "no serial number"),
    ("no uncertainty anywhere", "qif", QIF, QIF_MAP.replace("deviation, 0.8", "deviation,"), "map",
     "row 4, column 'characteristic'", "no measurement uncertainty"),
    ("unknown reading", "qif", QIF, QIF_MAP.replace("deviation", "deviaton"), "map", "row 4, column 'reading'",
     "reading must be"),
    ("unknown column", "qif", QIF, QIF_MAP.replace("reading,", "readings,"), "map", "row 2, column 'readings'",
     "unknown column"),
    ("u of another dimension", "qif", QIF, QIF_MAP.replace("u [um]", "u [arcmin]"), "map", "row 4, column 'u [arcmin]'",
     "does not fit"),
    ("dfq value not a number", "dfq", DFQ.replace("K0001/2 40.01204", "K0001/2 40.0x1204"), DFQ_MAP, "data",
     "line 28", "not a number"),
    ("dfq text for a mapped value", "dfq", DFQ.replace("K0001/3 0.008333333333333333", "K0001/3 n.i.O."), DFQ_MAP,
     "data", "line 30", "not a number: 'n.i.O.'"),
    ("dfq unit of another dimension", "dfq", DFQ, DFQ_MAP.replace("reading, u", "reading, unit, u").replace(
        "cam x, cam.x, value,", "cam x, cam.x, value, deg,").replace("20, bore.d, deviation,", "20, bore.d, deviation, ,")
     .replace("cam angle, cam.angle, value,", "cam angle, cam.angle, value, ,"), "map", "row 4, column 'unit'",
     "gives 'cam x' in um, not deg"),
    ("dfq deviation without nominal", "dfq", DFQ.replace("K2101/2 40.0\r\n", ""), DFQ_MAP, "map",
     "row 5, column 'reading'", "no nominal"),
    ("dfq without part idents", "dfq", DFQ.replace("K0014/0 C-0002\r\n", ""), DFQ_MAP, "data",
     "value set 2 (line 24)", "no serial number"),
]


@pytest.mark.parametrize("case, fmt, data, mapping, where, key, words", BAD, ids=[b[0] for b in BAD])
def test_bad_inspection_files_name_the_file_and_the_place(tmp_path, case, fmt, data, mapping, where, key, words):
    path = tmp_path / f"parts.{fmt}"
    path.write_bytes(data.encode("cp1252") if fmt == "dfq" else data.encode("utf-8"))
    m = write(tmp_path / "map.csv", mapping)
    with pytest.raises(InputError) as exc:
        read_part_family(path, ["crank_1"], SPEC, mapping=m)
    assert exc.value.file == str(m if where == "map" else path), (exc.value.file, exc.value.key, exc.value.reason)
    assert exc.value.key == key and words in exc.value.reason, (exc.value.key, exc.value.reason)
    assert "\n" not in str(exc.value) and len(exc.value.reason) < 300      # one line for the CLI


def test_a_qif_file_without_a_mapping_and_a_csv_with_one_are_refused(tmp_path):
    with pytest.raises(InputError) as exc:
        read_part_family(DATA / "parts.qif", ["crank_1"], SPEC)
    assert exc.value.key == "mapping" and "needs a mapping" in exc.value.reason
    with pytest.raises(InputError) as exc:
        read_part_family(DATA / "truth.csv", ["crank_1"], SPEC, mapping=DATA / "parts_qif_map.csv")
    assert exc.value.key == "mapping"


STUDY = """
[study]
name = "qif_units"
[[factor]]
name = "crank_1.cam.x"
unit = "um"
dist = "normal"
sigma = 1.0
[[factor]]
name = "crank_1.bore.d"
unit = "um"
dist = "normal"
sigma = 5.0
[[factor]]
name = "crank_1.cam.angle"
unit = "arcmin"
dist = "normal"
sigma = 1.0
[model]
kind = "linear"
[[model.output]]
name = "play"
unit = "um"
coefficients = { "crank_1.cam.x" = 1.0, "crank_1.bore.d" = 0.5 }
[[requirement]]
output = "play"
upper = 30.0
unit = "um"
min_yield = 0.95
[sampling]
n = 50
seed = 1
[execution]
executor = "serial"
[report]
pdf = false
[[analysis]]
kind = "per_unit_prediction"
kits = "kits.csv"
[[analysis.parts]]
file = "FILE"
mapping = "MAPPING"
slots = ["crank_1"]
"""


def _study(file, mapping) -> str:
    return STUDY.replace("FILE", str(file)).replace("MAPPING", str(mapping))


def test_a_study_names_a_qif_file_and_its_mapping_where_it_names_a_csv(tmp_path, capsys):
    kits = write(tmp_path / "kits.csv", "reducer, crank_1\nR1, C-0003\nR2, C-0001\n")
    study = write(tmp_path / "s.toml", _study(DATA / "parts.qif", DATA / "parts_qif_map.csv"))
    rc, err = run_cli(["check", study], capsys)
    assert rc == 0, err
    mu = load_measured_units(SPEC, kits, [FamilySource(DATA / "parts.qif", ("crank_1",),
                                                       mapping=DATA / "parts_qif_map.csv")])
    truth = read_part_family(DATA / "truth.csv", ["crank_1"], SPEC)
    np.testing.assert_allclose(mu.value, truth.values[[2, 0]], **TOL)
    files = mu.files()                                  # the study's input record: the data file and its mapping
    assert files["mapping:parts"]["path"] == str(DATA / "parts_qif_map.csv")
    assert files["parts:parts"]["sha256"] == hashlib.sha256((DATA / "parts.qif").read_bytes()).hexdigest()
    # bad input through the CLI: one line naming the mapping's row, exit 2, no traceback
    bad = write(tmp_path / "bad_map.csv", QIF_MAP.replace("CAM_X,", "CAM_Y,"))
    study = write(tmp_path / "s.toml", _study(DATA / "parts.qif", bad))
    rc, err = run_cli(["check", study], capsys)
    assert rc == 2 and len(err) == 1, err
    assert err[0].startswith(f"rvtol: error: {bad}: row 3, column 'characteristic': no characteristic 'CAM_Y'")


def test_a_dfq_part_ident_written_before_the_values_is_the_first_value_sets(tmp_path):
    # aqdef-tools' parser tests: a /0 entry written before the values applies to the first value set only
    path = tmp_path / "p.dfq"
    path.write_bytes("K0100 1\r\nK2001/1 1\r\nK2002/1 d\r\nK2142/1 mm\r\nK0014/0 A-1\r\nK0001/1 0.5\r\n"
                     "K0001/1 -0,7\r\nK0014/1 A-2\r\n".encode("cp1252"))
    f = read_dfq(path)
    assert [(p.serial, p.readings["1"]) for p in f.parts] == [("A-1", [(0.5, None)]), ("A-2", [(-0.7, None)])]


def test_a_dfq_characteristic_the_mapping_does_not_name_may_hold_anything(tmp_path, truth):
    # an attribute's text, a unit rvtol does not know, a nominal that is not a number: not read unless mapped
    path = tmp_path / "parts.dfq"
    path.write_bytes(DFQ.replace("K0001/3 0.008333333333333333", "K0001/3 n.i.O.").replace("K2142/3 °", "K2142/3 bar")
                     .replace("K2101/3 0.0", "K2101/3 OK").encode("cp1252"))
    m = write(tmp_path / "map.csv", DFQ_MAP.replace("cam angle, cam.angle, value, 0.005\n", ""))
    fam = read_part_family(path, ["crank_1"], SPEC, mapping=m)
    np.testing.assert_allclose(fam.values, truth.values[:, :2], **TOL)


# --------------------------------------------------------------------------- round trip of random truth tables
def _fixture_writers():
    """The fixture generator's QIF and DFQ writers (studies/make_inspection_fixtures.py, not a package)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("make_inspection_fixtures",
                                                  ROOT / "studies" / "make_inspection_fixtures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


FIXTURES = _fixture_writers()
UREG = pint.UnitRegistry()
#: per dimension: (QIF UnitName, its factor to m or rad as QIF's UnitConversion, DFQ K2142 text, pint's name);
#: "foot" and "grad" are units rvtol does not know: QIF's reader converts them by their factor (DFQ: not offered)
UNITS = {
    "length": [("mm", 1e-3, "mm", "mm"), ("um", 1e-6, "µm", "micrometer"), ("inch", 0.0254, "in", "inch"),
               ("thou", 2.54e-5, "thou", "thou"), ("cm", 1e-2, "cm", "cm"), ("foot", 0.3048, None, "foot")],
    "angle": [("degree", math.pi / 180, "°", "degree"), ("radian", 1.0, "rad", "radian"),
              ("arcmin", math.pi / 10800, "arcmin", "arcminute"), ("arcsec", math.pi / 648000, "arcsec", "arcsecond"),
              ("mrad", 1e-3, "mrad", "milliradian"), ("grad", math.pi / 200, None, "gradian")],
}
BASE = {"length": "mm", "angle": "radian"}          # the spec's factor units below (rvtol's base: mm, rad)
NUMBER = st.one_of(st.just(0.0), st.floats(-1e3, 1e3, allow_nan=False, allow_subnormal=False))


@st.composite
def truth_tables(draw):
    """A few serials × a few characteristics: each a dimension, a unit, a nominal, a reading (value or deviation),
    a mapping u, and one value per serial — every number as written in the file, in the characteristic's unit."""
    n_parts = draw(st.integers(1, 4))
    chars = []
    for k in range(draw(st.integers(1, 3))):
        dim = draw(st.sampled_from(sorted(UNITS)))
        chars.append(dict(dim=dim, unit=draw(st.sampled_from(UNITS[dim])), nominal=draw(NUMBER),
                          deviation=draw(st.booleans()), u=draw(st.floats(0.0, 10.0, allow_subnormal=False)),
                          values=draw(st.lists(NUMBER, min_size=n_parts, max_size=n_parts)),
                          conversion=draw(st.booleans())))
    return n_parts, chars


def _oracle(x, ch):
    """pint: a number written in ``ch``'s unit, in the factor's unit."""
    return UREG.Quantity(x, ch["unit"][3]).to(BASE[ch["dim"]]).magnitude


def _write_qif(path, n_parts, chars):
    linear, angular = [], []
    for ch in chars:                # each unit once; a known name without UnitConversion when drawn so
        name, factor = ch["unit"][:2]
        factor = factor if ch["conversion"] or name in ("foot", "grad") else None
        units = linear if ch["dim"] == "length" else angular
        if name not in [u[0] for u in units]:
            units.append((name, factor))
    linear = linear or [("mm", 1e-3)]
    angular = angular or [("radian", 1.0)]
    characteristics = [(f"CH{k}", "Angle" if ch["dim"] == "angle" else ("Diameter", "LinearCoordinate")[k % 2],
                        ch["unit"][0], ch["nominal"], 1.0) for k, ch in enumerate(chars)]
    parts = [(f"S-{j}", [(ch["values"][j], None) for ch in chars]) for j in range(n_parts)]
    # a study of every characteristic, the first part excluded from those read as deviations (when there are two)
    study = ("SimpleStudyResults", {k: [0] if ch["deviation"] and n_parts > 1 else [] for k, ch in enumerate(chars)})
    path.write_bytes(FIXTURES.qif_document(characteristics, parts, linear, angular, statistics=study))
    return [f"CH{k}" for k in range(len(chars))]


def _item_ids(path) -> list[str]:
    """The CharacteristicItem ids of a QIF file in document order (ElementTree)."""
    ns = {"q": "http://qifstandards.org/xsd/qif3"}
    return [it.get("id") for it in ET.parse(path).getroot().find("q:Characteristics/q:CharacteristicItems", ns)]


def _write_dfq(path, n_parts, chars, compact):
    characteristics = [(str(10 * (k + 1)), f"char {k}", ch["nominal"] if ch["deviation"] or ch["conversion"] else None,
                        ch["unit"][2], 1.0) for k, ch in enumerate(chars)]
    parts = [(f"S-{j}", [ch["values"][j] for ch in chars]) for j in range(n_parts)]
    path.write_bytes(FIXTURES.dfq_file(characteristics, parts, compact))
    return [f"char {k}" for k in range(len(chars))]


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(table=truth_tables(), fmt=st.sampled_from(["qif", "dfq"]), compact=st.integers(0, 4))
def test_random_truth_tables_read_back_from_qif_and_dfq_as_pint_converts_them(tmp_path, table, fmt, compact):
    n_parts, chars = table
    if fmt == "dfq":
        chars = [ch for ch in chars if ch["unit"][2] is not None] or [dict(chars[0], unit=UNITS[chars[0]["dim"]][0])]
    path = tmp_path / f"parts.{fmt}"
    names = _write_qif(path, n_parts, chars) if fmt == "qif" else _write_dfq(path, n_parts, chars, compact)
    mapping = write(tmp_path / "map.csv", "characteristic, feature, reading, u\n" + "".join(
        f"{n}, f{k}, {'deviation' if ch['deviation'] else 'value'}, {ch['u']!r}\n"
        for k, (n, ch) in enumerate(zip(names, chars))))
    spec = spec_from_table({"factor": [{"name": f"p.f{k}", "unit": "mm" if ch["dim"] == "length" else "rad",
                                        "dist": "normal", "mean": 0.0, "sigma": 1.0} for k, ch in enumerate(chars)]})
    fam = read_part_family(path, ["p"], spec, mapping=mapping)     # the file's statistics agree with its values
    assert fam.serials == tuple(f"S-{j}" for j in range(n_parts))
    if fmt == "qif":
        f = read_qif(path)
        for k, ch in enumerate(chars):
            rows = {r["figure"]: r["file"] for r in check_statistics(f, f"{_item_ids(path)[k]}")}
            kept = [_oracle(x, ch) for j, x in enumerate(ch["values"]) if not (j == 0 and ch["deviation"] and n_parts > 1)]
            average = units.to_base(rows["Average"], f.characteristics[_item_ids(path)[k]].unit)   # in mm or rad
            assert rows["EffectiveNumber"] == len(kept) and rows["TotalNumber"] == n_parts
            assert math.isclose(average, math.fsum(kept) / len(kept), rel_tol=1e-12,
                                abs_tol=1e-12 * max(abs(v) for v in kept))
    for k, ch in enumerate(chars):
        nominal = ch["nominal"] if ch["deviation"] else 0.0
        # the reader subtracts the nominal after scaling, the oracle before: they agree to the nominal's ulp
        scale = abs(_oracle(nominal, ch))
        for j, x in enumerate(ch["values"]):
            ref = _oracle(x - nominal, ch)
            assert abs(fam.values[j, k] - ref) <= 1e-12 * (abs(ref) + scale), (j, k, fam.values[j, k], ref)
        np.testing.assert_allclose(fam.uncertainty[:, k], _oracle(ch["u"], ch), rtol=1e-12, atol=0)


def _one_characteristic_qif(tmp_path, linear, angular, value, u_cell, nominal=None):
    """A QIF of one linear characteristic (two parts: ``value`` and -``value``) in the units ``linear``, mapped with
    a u without a header unit (its deviation from ``nominal`` when one is given)."""
    path = tmp_path / "p.qif"
    parts = [("S-0", [(value, None)]), ("S-1", [(-value, None)])]
    path.write_bytes(FIXTURES.qif_document([("CH0", "Diameter", linear[0][0], nominal or 0.0, 1.0)], parts, linear,
                                           angular))
    reading = "value" if nominal is None else "deviation"
    mapping = write(tmp_path / "map.csv", f"characteristic, feature, reading, u\nCH0, f0, {reading}, {u_cell}\n")
    spec = spec_from_table({"factor": [{"name": "p.f0", "unit": "mm", "dist": "normal", "sigma": 1.0}]})
    return read_part_family(path, ["p"], spec, mapping=mapping)


def test_a_qif_unit_named_by_its_si_name_without_unitconversion_is_the_si_unit(tmp_path):
    # found by the round trip above: <UnitName>meter</UnitName> (radian) with no UnitConversion — the schema's fixed
    # SIUnitName, i.e. the SI unit itself — was refused as "unknown length unit 'meter'"
    fam = _one_characteristic_qif(tmp_path, [("meter", None)], [("radian", None)], 0.0123, 2e-6)
    np.testing.assert_allclose(fam.values[:, 0], UREG.Quantity(np.array([0.0123, -0.0123]), "m").to("mm").magnitude,
                               rtol=1e-12)
    np.testing.assert_allclose(fam.uncertainty[:, 0], UREG.Quantity(2e-6, "m").to("mm").magnitude, rtol=1e-12)


def test_a_mapping_u_for_a_qif_unit_rvtol_does_not_know_is_in_that_unit(tmp_path):
    # found by the round trip above: a file in feet (converted to mm by its factor 0.3048 m) with a mapping u of
    # 0.5 (in the values' unit: feet) read the u as 0.5 mm
    fam = _one_characteristic_qif(tmp_path, [("foot", 0.3048)], [("degree", math.pi / 180)], 0.25, 0.5)
    np.testing.assert_allclose(fam.values[:, 0], UREG.Quantity(np.array([0.25, -0.25]), "foot").to("mm").magnitude,
                               rtol=1e-12)
    np.testing.assert_allclose(fam.uncertainty[:, 0], UREG.Quantity(0.5, "foot").to("mm").magnitude, rtol=1e-12)


def test_a_qif_deviation_in_a_unit_rvtol_does_not_know_subtracts_the_nominal_in_that_unit(tmp_path):
    # found by the round trip above: a file in feet, value 0.25 ft on a nominal of 0.1 ft, read as a deviation, was
    # 0.25 ft in mm less 0.1 (the nominal left in feet): 76.1 mm instead of 0.15 ft = 45.72 mm
    fam = _one_characteristic_qif(tmp_path, [("foot", 0.3048)], [("degree", math.pi / 180)], 0.25, 0.5, nominal=0.1)
    np.testing.assert_allclose(fam.values[:, 0], UREG.Quantity(np.array([0.15, -0.35]), "foot").to("mm").magnitude,
                               rtol=1e-12)


# --------------------------------------------------------------------------- QIF Statistics


def _lot_truth() -> list[float]:
    rows = [line.split(",") for line in (DATA / "lot_truth.csv").read_text("utf-8").splitlines()[2:]]
    return [float(v) for _, v in rows]


def test_a_qif_lot_reads_back_its_values_and_its_capability_study_as_the_standard_library_computes_it():
    values, unit, rows = characteristic_values(DATA / "lot.qif", "CRANK_BORE_D", "um")
    truth = _lot_truth()
    assert unit == "um" and len(values) == 24
    np.testing.assert_allclose(values, [1000.0 * v for v in truth], rtol=1e-15)
    kept = [1000.0 * v for j, v in enumerate(truth) if j != 6]          # the study excludes the 7th bore
    import statistics
    want = {"TotalNumber": 24, "EffectiveNumber": 23, "Average": statistics.fmean(kept),
            "StandardDeviation": statistics.stdev(kept), "Minimum": min(kept), "Maximum": max(kept),
            "Range": max(kept) - min(kept)}
    assert [r["figure"] for r in rows] == list(want)
    for r in rows:
        assert r["study"].startswith("CapabilityStudyResults id=")
        assert math.isclose(r["file"], want[r["figure"]], rel_tol=1e-12), r
        assert math.isclose(r["recomputed"], want[r["figure"]], rel_tol=1e-12), r


def _tampered(tmp_path, figure: str, value: str):
    text = (DATA / "lot.qif").read_text("utf-8")
    head, tail = text.split(f"<{figure}>", 1)
    old = tail.split("<Value>", 1)[1].split("</Value>", 1)[0]
    path = tmp_path / "lot.qif"
    path.write_text(head + f"<{figure}>" + tail.replace(f"<Value>{old}</Value>", f"<Value>{value}</Value>", 1),
                    "utf-8")
    return path, float(old)


def test_a_qif_statistic_that_its_own_measurements_contradict_is_refused_by_study_and_figure(tmp_path):
    path, old = _tampered(tmp_path, "Average", "40.0034")       # the mean of all 24, not of the 23 the study keeps
    with pytest.raises(InputError) as exc:
        characteristic_values(path, "CRANK_BORE_D", "mm")
    assert exc.value.file == str(path)
    assert exc.value.key.startswith("CapabilityStudyResults id=") and "DiameterCharacteristicStats (1st)" in exc.value.key
    assert "Average 40.0034 mm of 'CRANK_BORE_D' disagrees with its 23 measurements (40.00328696 mm)" \
        in exc.value.reason
    # a figure written to fewer digits agrees to those digits: the mean rounded to 0.1 µm
    path, _ = _tampered(tmp_path, "Average", f"{old:.4f}")
    characteristic_values(path, "CRANK_BORE_D", "mm")


def test_a_population_standard_deviation_is_named_as_such(tmp_path):
    kept = [v for j, v in enumerate(_lot_truth()) if j != 6]
    pop = float(np.std(kept, ddof=0))
    path, _ = _tampered(tmp_path, "StandardDeviation", repr(pop))
    with pytest.raises(InputError) as exc:
        characteristic_values(path, "CRANK_BORE_D", "mm")
    assert "StandardDeviation" in exc.value.reason and "population standard deviation" in exc.value.reason


def test_a_mapped_part_family_is_checked_against_the_files_statistics_too(tmp_path):
    path, _ = _tampered(tmp_path, "Maximum", "40.0099")
    spec = spec_from_table({"factor": [{"name": "crank.bore", "unit": "mm", "dist": "normal", "sigma": 1.0}]})
    mapping = write(tmp_path / "map.csv", "characteristic, feature, reading, u [um]\nCRANK_BORE_D, bore, deviation, 0.5\n")
    with pytest.raises(InputError) as exc:
        read_part_family(path, ["crank"], spec, mapping=mapping)
    assert "Maximum 40.0099 mm" in exc.value.reason and exc.value.key.startswith("CapabilityStudyResults")
    fam = read_part_family(DATA / "lot.qif", ["crank"], spec, mapping=mapping)       # the untouched file reads
    np.testing.assert_allclose(fam.values[:, 0], np.array(_lot_truth()) - 40.0, atol=1e-12)


def test_the_public_all_in_one_samples_statistics_do_not_all_reproduce_from_its_measurements(tmp_path):
    # the DMSC's All-in-one.QIF (public/): a SimpleStudyResults of two spheres. As published it has no FileUnits —
    # a value in no stated unit is refused; with the FileUnits a CMM writes (mm), its sphere diameter's Average
    # 25.3441663869135 is the mean of its two measurements (25.008…, 25.680…), but its sphericity's Average
    # 0.251457258827 is the first measurement itself: the mean of 0.251457258827 and 0.051042207099 is 0.151249732963
    sample = DATA / "public" / "All-in-one.QIF"
    with pytest.raises(InputError) as exc:
        read_qif(sample)
    assert "no linear unit (primary) in FileUnits" in exc.value.reason
    text = sample.read_text("utf-8").replace("  <Characteristics>\n", (
        "  <FileUnits><PrimaryUnits><LinearUnit><SIUnitName>meter</SIUnitName><UnitName>mm</UnitName>"
        "<UnitConversion><Factor>0.001</Factor></UnitConversion></LinearUnit></PrimaryUnits></FileUnits>\n"
        "  <Characteristics>\n"), 1)
    path = write(tmp_path / "all.qif", text)
    f = read_qif(path)
    by_name = {c.names[0]: c.key for c in f.characteristics.values()}
    rows = check_statistics(f, by_name["SphericalDiameter1"])
    assert [(r["figure"], r["file"]) for r in rows] == [("Average", 25.3441663869135)]
    assert math.isclose(rows[0]["recomputed"], (25.008279671621001 + 25.680053102205999) / 2, rel_tol=1e-15)
    with pytest.raises(InputError) as exc:
        check_statistics(f, by_name["Sphericity1"])
    assert "Average 0.251457258827 mm of 'Sphericity1' disagrees with its 2 measurements (0.151249733 mm)" \
        in exc.value.reason


def test_a_statistics_only_qif_is_refused_with_the_reason(tmp_path):
    text = (DATA / "lot.qif").read_text("utf-8")
    start, end = text.index("  <Results>"), text.index("</Results>") + len("</Results>\n")
    path = write(tmp_path / "stats_only.qif", text[:start] + text[end:])
    with pytest.raises(InputError) as exc:
        read_qif(path)
    assert "holds Statistics only" in exc.value.reason and exc.value.key == "Results"


def test_a_measured_factor_reads_a_qif_characteristic_and_the_report_gets_its_statistics(tmp_path):
    import shutil

    from rvtol.inputs.measured import evidence

    shutil.copy(DATA / "lot.qif", tmp_path / "lot.qif")
    spec = spec_from_table({"factor": [{"name": "bore", "unit": "um", "dist": "measured", "data": "lot.qif",
                                        "column": "CRANK_BORE_D", "families": ["normal"]}]},
                           file=str(tmp_path / "spec.toml"))
    f = spec.factors[0]
    truth = 1000.0 * np.array(_lot_truth())
    np.testing.assert_allclose(np.sort(f.measured.values), np.sort(truth), rtol=1e-15)
    assert math.isclose(f.dist.mean, truth.mean(), rel_tol=1e-12)
    ev = evidence(f.measured, f.dist, n_mc=19, seed=1)
    # the fitted law is shown to resolve its band (rvtol.precision): μ within 1/100 of the band of the mean, not
    # "μ=4e+04" of four significant digits
    import re
    mu = float(re.search(r"μ=([-\d.]+)", ev["summary"]["distribution"][0]).group(1))
    assert abs(mu - truth.mean()) <= f.dist.tolerance / 100
    assert list(ev["file_statistics"]["figure"]) == ["TotalNumber", "EffectiveNumber", "Average",
                                                     "StandardDeviation", "Minimum", "Maximum", "Range"]
    with pytest.raises(InputError) as exc:        # no characteristic named: which of the file's?
        spec_from_table({"factor": [{"name": "bore", "unit": "um", "dist": "measured", "data": "lot.qif"}]},
                        file=str(tmp_path / "spec.toml"))
    assert "name one in the factor's 'column'" in exc.value.reason
    with pytest.raises(InputError) as exc:
        spec_from_table({"factor": [{"name": "bore", "unit": "um", "dist": "measured", "data": "lot.qif",
                                     "column": "CRANK_BORE"}]}, file=str(tmp_path / "spec.toml"))
    assert "no characteristic 'CRANK_BORE'" in exc.value.reason and "CRANK_BORE_D" in exc.value.reason


@pytest.mark.parametrize("figure,value,words", [
    ("Average", "NaN", "Average NaN is not a finite number"),              # was an internal error (exit 3)
    ("Maximum", "INF", "Maximum Infinity is not a finite number"),
    # rounded more coarsely than the values spread (s = 2.0 µm): so rounded they would agree with anything
    ("Range", "0", "Range 0 mm of 'CRANK_BORE_D' is rounded to ±0.5 mm, more coarsely than its 23 values vary"),
    ("Minimum", "4E1", "Minimum 4E+1 mm of 'CRANK_BORE_D' is rounded to ±5 mm"),
])
def test_a_figure_that_is_no_number_or_coarser_than_its_values_is_refused(tmp_path, capsys, figure, value, words):
    path, _ = _tampered(tmp_path, figure, value)
    with pytest.raises(InputError) as exc:
        characteristic_values(path, "CRANK_BORE_D", "mm")
    assert words in exc.value.reason and exc.value.key.startswith("CapabilityStudyResults id=")
    study = write(tmp_path / "study.toml", '[study]\nname = "s"\n[[factor]]\nname = "bore"\nunit = "mm"\n'
                  'dist = "measured"\ndata = "lot.qif"\ncolumn = "CRANK_BORE_D"\n[model]\nkind = "formula"\n'
                  '[[model.output]]\nname = "y"\nformula = "bore"\nunit = "mm"\n')
    rc, err = run_cli(["check", study], capsys)
    assert rc == 2 and len(err) == 1 and words in err[0], err


def _without_value(tmp_path, measurement_id: str):
    text = (DATA / "lot.qif").read_text("utf-8")
    head, tail = text.split(f'<DiameterCharacteristicMeasurement id="{measurement_id}">', 1)
    block, rest = tail.split("</DiameterCharacteristicMeasurement>", 1)
    block = block[: block.index("<Value")] + block[block.index("</Value>") + len("</Value>"):]
    return write(tmp_path / "lot.qif", head + f'<DiameterCharacteristicMeasurement id="{measurement_id}">' + block
                 + "</DiameterCharacteristicMeasurement>" + rest)


def _measurement_ids():
    root = ET.parse(DATA / "lot.qif").getroot()
    return [m.get("id") for m in root.iter("{http://qifstandards.org/xsd/qif3}DiameterCharacteristicMeasurement")]


def test_a_measurement_without_a_value_is_read_and_refused_only_when_the_study_counts_it(tmp_path):
    ids = _measurement_ids()
    # the 7th, which the study excludes: valid QIF (Value is optional); the part has no reading, the study agrees
    f = read_qif(_without_value(tmp_path, ids[6]))
    key = next(iter(f.characteristics))
    assert [r["figure"] for r in check_statistics(f, key)][:2] == ["TotalNumber", "EffectiveNumber"]
    f = read_qif(_without_value(tmp_path, ids[0]))          # one the study counts
    with pytest.raises(InputError) as exc:
        check_statistics(f, key)
    assert f"it counts measurement id={ids[0]}, which has no value" in exc.value.reason


def test_a_value_or_nominal_that_is_no_number_is_a_located_error(tmp_path):
    ids = _measurement_ids()
    text = (DATA / "lot.qif").read_text("utf-8")
    head, tail = text.split(f'<DiameterCharacteristicMeasurement id="{ids[2]}">', 1)
    old = tail.split("<Value>", 1)[1].split("</Value>", 1)[0]
    path = write(tmp_path / "nan.qif", head + f'<DiameterCharacteristicMeasurement id="{ids[2]}">'
                 + tail.replace(f"<Value>{old}</Value>", "<Value>NaN</Value>", 1))
    with pytest.raises(InputError) as exc:
        characteristic_values(path, "CRANK_BORE_D", "mm")
    assert f"measurement id={ids[2]} of 'CRANK_BORE_D': the value NaN is not a finite number" in exc.value.reason
    assert exc.value.key.startswith("MeasurementResults id=")
    path = write(tmp_path / "nominal.qif", text.replace("<TargetValue>40.0</TargetValue>", "<TargetValue>NaN</TargetValue>", 1))
    assert "<TargetValue>NaN</TargetValue>" in path.read_text("utf-8")
    spec = spec_from_table({"factor": [{"name": "crank.bore", "unit": "mm", "dist": "normal", "sigma": 1.0}]})
    mapping = write(tmp_path / "map.csv", "characteristic, feature, reading, u [um]\nCRANK_BORE_D, bore, deviation, 0.5\n")
    with pytest.raises(InputError) as exc:
        read_part_family(path, ["crank"], spec, mapping=mapping)
    assert "its nominal (TargetValue) NaN is not a finite number" in exc.value.reason


def test_the_standard_deviation_of_one_kept_value_is_not_checked(tmp_path):
    text = (DATA / "lot.qif").read_text("utf-8")
    ids = _measurement_ids()
    keep = ids[0]
    ex = "".join(f"<Exclusion><Id>{i}</Id><Reason><ExclusionReasonEnum>FLIER</ExclusionReasonEnum></Reason>"
                 "</Exclusion>" for i in ids[1:])
    start, end = text.index("<Exclusions"), text.index("</Exclusions>") + len("</Exclusions>")
    text = text[:start] + f'<Exclusions n="{len(ids) - 1}">{ex}</Exclusions>' + text[end:]
    first = _lot_truth()[0]
    for fig, value in (("EffectiveNumber", "1"), ("Average", repr(first)), ("Maximum", repr(first)),
                       ("Minimum", repr(first)), ("Range", "0"), ("StandardDeviation", "0")):
        head, tail = text.split(f"<{fig}>", 1)
        old = tail.split("<Value>", 1)[1].split("</Value>", 1)[0]
        text = head + f"<{fig}>" + tail.replace(f"<Value>{old}</Value>", f"<Value>{value}</Value>", 1)
    f = read_qif(write(tmp_path / "one.qif", text))
    rows = check_statistics(f, next(iter(f.characteristics)))
    assert keep and "StandardDeviation" not in [r["figure"] for r in rows] and len(rows) == 6


def _rewritten(tmp_path, values_fmt: str, figures: dict, first_value: str | None = None):
    """lot.qif with every measured value written by ``values_fmt`` (the first as ``first_value`` if given) and the
    study's figures replaced (name -> text)."""
    ns = "{http://qifstandards.org/xsd/qif3}"
    ET.register_namespace("", ns[1:-1])
    tree = ET.parse(DATA / "lot.qif")
    root = tree.getroot()
    for i, m in enumerate(root.iter(f"{ns}DiameterCharacteristicMeasurement")):
        v = m.find(f"{ns}Value")
        v.text = first_value if i == 0 and first_value is not None else format(float(v.text), values_fmt)
    stats_el = next(root.iter(f"{ns}ValueStats"))
    for name, text in figures.items():
        stats_el.find(f"{ns}{name}/{ns}Value").text = text
    path = tmp_path / "lot.qif"
    tree.write(path, xml_declaration=True, encoding="utf-8")
    return path


def test_figures_rounded_to_fewer_digits_than_the_values_are_read_when_they_resolve_the_spread(tmp_path):
    # values to 6 decimals, the study's figures to 4 (the standard deviation 0.0019765 mm written 0.0020): ordinary
    kept = [v for j, v in enumerate(_lot_truth()) if j != 6]
    import statistics
    figs = {"Average": f"{statistics.fmean(kept):.4f}", "StandardDeviation": f"{statistics.stdev(kept):.4f}",
            "Range": f"{max(kept) - min(kept):.4f}"}
    assert figs["StandardDeviation"] == "0.0020"
    values, _, rows = characteristic_values(_rewritten(tmp_path, ".6f", figs), "CRANK_BORE_D", "mm")
    assert {r["figure"]: r["file"] for r in rows}["StandardDeviation"] == 0.002


def test_one_value_written_short_does_not_let_a_coarse_figure_through(tmp_path):
    # one kept value written "40.0" (to ±0.05 mm), every other figure exact, and Range "0": the values spread by
    # s = 2.1 µm, which a figure rounded to ±0.5 mm cannot be checked against (it would agree with anything)
    import statistics
    kept = [40.0] + [v for j, v in enumerate(_lot_truth()) if j not in (0, 6)]
    figs = {"Average": repr(statistics.fmean(kept)), "StandardDeviation": repr(statistics.stdev(kept)),
            "Minimum": repr(min(kept)), "Maximum": repr(max(kept)), "Range": "0"}
    path = _rewritten(tmp_path, ".4f", figs, first_value="40.0")
    with pytest.raises(InputError) as exc:
        characteristic_values(path, "CRANK_BORE_D", "mm")
    assert "Range 0 mm of 'CRANK_BORE_D' is rounded to ±0.5 mm, more coarsely than its 23 values vary" \
        in exc.value.reason
    figs["Range"] = repr(max(kept) - min(kept))
    for name, text in (("Range", "0.0"), ("Average", "40.0")):    # nor one decimal, the short value's own step
        bad = dict(figs, **{name: text})
        with pytest.raises(InputError) as exc:
            characteristic_values(_rewritten(tmp_path, ".4f", bad, first_value="40.0"), "CRANK_BORE_D", "mm")
        assert f"{name} {text} mm of 'CRANK_BORE_D' is rounded to ±0.05 mm" in exc.value.reason
    characteristic_values(_rewritten(tmp_path, ".4f", figs, first_value="40.0"), "CRANK_BORE_D", "mm")   # reads


def test_a_figure_of_values_that_do_not_vary_is_held_to_its_own_digits(tmp_path):
    ids = _measurement_ids()
    figs = {"Average": "40.0034", "Minimum": "40.0034", "Maximum": "40.0034", "Range": "0", "StandardDeviation": "0"}
    path = _rewritten(tmp_path, ".4f", figs)
    text = path.read_text("utf-8")
    import re
    text = re.sub(r"(<DiameterCharacteristicMeasurement id=\"\d+\">.*?<Value>)[^<]*(</Value>)",
                  lambda m: m.group(1) + "40.003412" + m.group(2), text, flags=re.S)
    f = read_qif(write(tmp_path / "equal.qif", text))
    rows = check_statistics(f, next(iter(f.characteristics)))
    assert {r["figure"] for r in rows} >= {"Average", "Range"} and ids
    text2 = text.replace("<Value>40.0034</Value>", "<Value>40.004</Value>")
    with pytest.raises(InputError):                      # 40.004 is not 40.003412 to its own digits (40.003 is)
        check_statistics(read_qif(write(tmp_path / "equal2.qif", text2)), next(iter(f.characteristics)))
