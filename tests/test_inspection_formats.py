"""Measured part families from QIF 3.0 and Q-DAS DFQ files through a mapping (rvtol.inputs.inspection).

References: the truth the fixtures were written from (``data/measurements/inspection/truth.csv`` read by the
CSV reader, studies/make_inspection_fixtures.py); for the public QIF sample, the standard library's ElementTree
reading the same file independently of the xsdata bindings; for the public DFQ sample, its values as printed in
the file.
"""
import hashlib
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from conftest import ROOT, run_cli, write
from rvtol.errors import InputError
from rvtol.inputs.inspection import mapped_table, read_dfq
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
