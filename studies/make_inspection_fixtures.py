"""Write the round-trip fixtures of the QIF and DFQ readers from a known truth (rvtol.inputs.inspection).

    python studies/make_inspection_fixtures.py [--validate QIF3_XSD_DIR]

The truth is a part family in rvtol's own CSV (``truth.csv``: four crankshafts, a cam position in µm, a bore
diameter's deviation from its 40 mm nominal in mm, a cam angle in arcmin, each with its standard uncertainty).
The same parts are written

* as a QIF 3.0 document (``parts.qif``) in **inches and degrees** (FileUnits with their UnitConversion factors
  0.0254 m and π/180 rad), the bore as its measured *diameter* (nominal 40 mm + deviation) with the nominal's
  TargetValue, the cam position's uncertainty as each value's ``combinedUncertainty``, the others' in the mapping
  (``parts_qif_map.csv``);
* as a Q-DAS DFQ file (``parts.dfq``) in **µm, mm and degrees** (K2142), the bore again as a diameter with its
  nominal K2101, the first two parts as compact value lines (0x0F between characteristics, 0x14 between fields)
  and the other two as coded K0001 lines, the serial as K0014; every uncertainty in the mapping
  (``parts_dfq_map.csv``, each u in its characteristic's unit).

The values are written with 17 significant digits, so reading a file back and converting to the truth's units
gives the truth to a few units in the last place (``tests/inputs/test_inspection_formats.py``).  The QIF document is
built with the standard library's ElementTree — the writer is independent of the reader's xsdata bindings — and,
with ``--validate``, checked against the complete official QIF 3.0 schema (xmlschema; about 30 s to load).
The writers take any table (:func:`qif_document`, :func:`dfq_file`): the readers' property-based round trip in
``tests/inputs/test_inspection_formats.py`` writes random tables in random units with them.
"""
from __future__ import annotations

import math
import statistics
import sys
import uuid
import xml.etree.ElementTree as ET
from decimal import Decimal
from pathlib import Path

OUT = Path(__file__).resolve().parent.parent / "data" / "measurements" / "inspection"
QIF = "http://qifstandards.org/xsd/qif3"
NOMINAL_BORE_MM = 40.0
INCH_M = 0.0254
DEG_RAD = math.pi / 180.0

#: the truth: serial, cam x [um], u [um], bore deviation [mm], u [um], cam angle [arcmin], u [arcmin]
PARTS = [
    ("C-0001", 0.4213, 0.15, 0.00712, 0.8, 1.25, 0.3),
    ("C-0002", -1.0875, 0.15, -0.00431, 0.8, -0.75, 0.3),
    ("C-0003", 2.3001, 0.25, 0.01204, 0.8, 0.5, 0.3),
    ("C-0004", -0.0042, 0.15, -0.01518, 0.8, -2.125, 0.3),
]


def g(x: float) -> str:
    """17 significant digits as an xs:decimal (no exponent)."""
    return format(Decimal(repr(float(x))), "f")


def truth_csv() -> str:
    rows = ["# the truth the QIF and DFQ fixtures were written from (studies/make_inspection_fixtures.py)",
            "serial, cam.x [um], cam.x.u [um], bore.d [mm], bore.d.u [um], cam.angle [arcmin], cam.angle.u [arcmin]"]
    rows += [", ".join([s] + [g(v) for v in vals]) for s, *vals in PARTS]
    return "\n".join(rows) + "\n"


def _el(parent, tag, text=None, **attrs):
    e = ET.SubElement(parent, f"{{{QIF}}}{tag}", {k: str(v) for k, v in attrs.items()})
    if text is not None:
        e.text = str(text)
    return e


#: the fixture's QIF characteristics: (name, kind, unit name, nominal in that unit, tolerance half-width)
QIF_CHARACTERISTICS = (("CAM_X", "LinearCoordinate", "inch", 0.0, 0.002),
                       ("BORE_D", "Diameter", "inch", NOMINAL_BORE_MM / 25.4, 0.001),
                       ("CAM_ANGLE", "Angle", "degree", 0.0, 0.1))
#: the fixture's DFQ characteristics: (K2001 number, K2002 description, K2101 nominal, K2142 unit, tolerance half-width)
DFQ_CHARACTERISTICS = (("10", "cam x", 0.0, "µm", 2.0), ("20", "bore diameter", NOMINAL_BORE_MM, "mm", 0.02),
                       ("30", "cam angle", 0.0, "°", 0.1))


def qif_parts() -> list:
    """The truth as the QIF fixture's readings: (serial, [(value, combinedUncertainty or None)]) in inch and degree."""
    return [(serial, [(cam_um / 1000 / 25.4, cam_u / 1000 / 25.4), ((NOMINAL_BORE_MM + bore_mm) / 25.4, None),
                      (ang_arcmin / 60.0, ang_u / 60.0)])
            for serial, cam_um, cam_u, bore_mm, _bu, ang_arcmin, ang_u in PARTS]


def dfq_parts() -> list:
    """The truth as the DFQ fixture's values: (serial, [value]) in µm, mm and degrees."""
    return [(serial, [cam_um, NOMINAL_BORE_MM + bore_mm, ang_arcmin / 60.0])
            for serial, cam_um, _cu, bore_mm, _bu, ang_arcmin, _au in PARTS]


def _qif_unit(parent, tag, si_name, name, factor):
    u = _el(parent, tag)
    _el(u, "SIUnitName", si_name)
    _el(u, "UnitName", name)
    if factor is not None:
        _el(_el(u, "UnitConversion"), "Factor", g(factor))


def qif_document(characteristics=QIF_CHARACTERISTICS, parts=None, linear_units=(("inch", INCH_M),),
                 angular_units=(("degree", DEG_RAD),), statistics=None) -> bytes:
    """A QIF 3.0 MeasurementResults document: ``characteristics`` as :data:`QIF_CHARACTERISTICS` (kind ``Angle``
    in an angular unit, the others in a linear one), ``parts`` as :func:`qif_parts` (each value in its
    characteristic's unit); units (UnitName, factor to m or rad, or None to write no UnitConversion), the first of
    each the primary unit, the others OtherUnits named by the values' ``linearUnit`` / ``angularUnit``.

    ``statistics`` (optional): a QIF Statistics section of one study, ``(study kind, {characteristic index:
    excluded part indices})`` — per characteristic its measurements' ids, the excluded ones as ``Exclusions``, and
    the figures of :func:`lot_figures` of the others, in the characteristic's unit."""
    parts = qif_parts() if parts is None else parts
    ET.register_namespace("", QIF)
    ids = iter(range(1, 10_000))
    root = ET.Element(f"{{{QIF}}}QIFDocument", {"versionQIF": "3.0.0"})
    _el(root, "QPId", uuid.uuid5(uuid.NAMESPACE_URL, "rvtol/data/measurements/inspection/parts.qif"))
    version = _el(root, "Version")
    _el(version, "TimeCreated", "2026-11-29T00:00:00")
    standard = _el(_el(root, "StandardsDefinitions", n=1), "Standard", id=next(ids))
    _el(_el(standard, "Organization"), "StandardsOrganizationEnum", "ISO")
    _el(standard, "Designator", "1101")
    _el(standard, "Year", "2017")
    file_units = _el(root, "FileUnits")
    units = _el(file_units, "PrimaryUnits")
    _qif_unit(units, "AngularUnit", "radian", *angular_units[0])
    _qif_unit(units, "LinearUnit", "meter", *linear_units[0])
    if len(linear_units) > 1 or len(angular_units) > 1:
        others = _el(file_units, "OtherUnits", n=len(linear_units) + len(angular_units) - 2)
        for u in angular_units[1:]:
            _qif_unit(others, "AngularUnit", "radian", *u)
        for u in linear_units[1:]:
            _qif_unit(others, "LinearUnit", "meter", *u)
    primary = {linear_units[0][0], angular_units[0][0]}

    def in_unit(e, kind, unit):               # a value's unit attribute when it is not the primary unit
        if unit not in primary:
            e.set("angularUnit" if kind == "Angle" else "linearUnit", unit)
        return e

    ch = _el(root, "Characteristics")
    _el(ch, "FormalStandardId", standard.get("id"))
    defs, noms, items = (_el(ch, t, n=len(characteristics)) for t in ("CharacteristicDefinitions",
                                                                       "CharacteristicNominals",
                                                                       "CharacteristicItems"))
    kinds = []          # (kind, unit, item id) of each characteristic
    for name, kind, unit, target, limits in characteristics:
        d = _el(defs, f"{kind}CharacteristicDefinition", id=next(ids))
        tol = _el(d, "Tolerance")
        in_unit(_el(tol, "MaxValue", g(limits)), kind, unit)
        in_unit(_el(tol, "MinValue", g(-limits)), kind, unit)
        _el(tol, "DefinedAsLimit", "false")
        n = _el(noms, f"{kind}CharacteristicNominal", id=next(ids))
        _el(n, "CharacteristicDefinitionId", d.get("id"))
        in_unit(_el(n, "TargetValue", g(target)), kind, unit)
        if kind == "LinearCoordinate":
            _el(n, "Direction", "XAXIS")
        it = _el(items, f"{kind}CharacteristicItem", id=next(ids))
        _el(it, "Name", name)
        _el(it, "CharacteristicNominalId", n.get("id"))
        kinds.append((kind, unit, it.get("id")))
    results = _el(root, "Results")
    mset = _el(results, "MeasurementResultsSet", n=len(parts))
    components, measurement_ids = [], {}
    for serial, readings in parts:
        mr = _el(mset, "MeasurementResults", id=next(ids))
        cms = _el(_el(mr, "MeasuredCharacteristics"), "CharacteristicMeasurements", n=len(readings))
        for i, ((kind, unit, item), (value, u)) in enumerate(zip(kinds, readings)):
            m = _el(cms, f"{kind}CharacteristicMeasurement", id=next(ids))
            measurement_ids.setdefault(i, []).append(m.get("id"))
            _el(_el(m, "Status"), "CharacteristicStatusEnum", "PASS")
            _el(m, "CharacteristicItemId", item)
            if kind == "LinearCoordinate":
                _el(_el(m, "TypeOfCoordinates"), "CoordinateEnum", "CARTESIAN_3D")
            v = _el(m, "Value", g(value))
            if u is not None:
                v.set("combinedUncertainty", g(u))
                v.set("meanError", "0")
            in_unit(v, kind, unit)
        _el(_el(mr, "InspectionStatus"), "InspectionStatusEnum", "PASS")
        comp = str(next(ids))
        _el(_el(mr, "ActualComponentIds", n=1), "Id", comp)
        components.append((comp, serial))
    sets = _el(results, "ActualComponentSets", n=len(components))
    for comp, serial in components:
        ac = _el(_el(sets, "ActualComponentSet", n=1), "ActualComponent", id=comp)
        _el(ac, "SerialNumber", serial)
        _el(_el(ac, "Status"), "InspectionStatusEnum", "PASS")
    if statistics is not None:
        study_kind, chars = statistics
        study = _el(_el(_el(root, "Statistics"), "StatisticalStudiesResults", n=1), study_kind, id=next(ids))
        _el(_el(study, "Status"), "StatsEvalStatusEnum", "PASS")
        stats = _el(study, "CharacteristicsStats", n=len(chars))
        for i, excluded in chars.items():
            kind, unit, _item = kinds[i]
            cs = _el(stats, f"{kind}CharacteristicStats")
            mids = _el(cs, "MeasuredIds")
            id_list = _el(mids, "Ids", n=len(measurement_ids[i]))
            for mid in measurement_ids[i]:
                _el(id_list, "Id", mid)
            if excluded:
                ex = _el(mids, "Exclusions", n=len(excluded))
                for j in excluded:
                    e = _el(ex, "Exclusion")
                    _el(e, "Id", measurement_ids[i][j])
                    _el(_el(e, "Reason"), "ExclusionReasonEnum", "FLIER")
            _el(_el(cs, "Status"), "StatsEvalStatusEnum", "PASS")
            vstats = in_unit(_el(cs, "ValueStats"), kind, unit)
            kept = [p[1][i][0] for j, p in enumerate(parts) if j not in excluded]
            for name, value in lot_figures(kept, len(parts)).items():
                _el(_el(vstats, name), "Value", value if isinstance(value, int) else g(value))
        _el(study, "NumberOfSamples", len(parts))
    root.set("idMax", str(next(ids) - 1))
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8", xml_declaration=False) + b"\n"


def lot_figures(values, candidates: int) -> dict:
    """A QIF study's figures of ``values`` (the standard library's ``statistics``: the sample standard deviation,
    n − 1, as QIF's StandardDeviation), in the schema's order of the elements."""
    out = {"TotalNumber": candidates, "EffectiveNumber": len(values), "Average": statistics.fmean(values),
           "Maximum": max(values), "Minimum": min(values), "Range": max(values) - min(values)}
    if len(values) > 1:
        out["StandardDeviation"] = statistics.stdev(values)
    return out


def dfq_file(characteristics=DFQ_CHARACTERISTICS, parts=None, compact: int = 2) -> bytes:
    """A DFQ file: ``characteristics`` as :data:`DFQ_CHARACTERISTICS` (a nominal None: no K2101, K2110, K2111),
    ``parts`` as :func:`dfq_parts`; the first ``compact`` parts as value lines, the others as coded K0001 lines."""
    parts = dfq_parts() if parts is None else parts
    lines = [f"K0100 {len(characteristics)}", "K1001/1 RV-CRANK", "K1002/1 crankshaft (rvtol round-trip fixture)"]
    for i, (number, desc, nominal, unit, half) in enumerate(characteristics, 1):
        lines += [f"K2001/{i} {number}", f"K2002/{i} {desc}"]
        if nominal is not None:
            lines += [f"K2101/{i} {g(nominal)}", f"K2110/{i} {g(nominal - half)}", f"K2111/{i} {g(nominal + half)}"]
        lines.append(f"K2142/{i} {unit}")
    for j, (serial, values) in enumerate(parts):
        if j < compact:     # compact: value 0x14 attribute 0x14 date/time, characteristics separated by 0x0F
            lines.append("\x0f".join(f"{g(v)}\x140\x1401.11.2026/08:00:{j:02d}" for v in values))
            lines.append(f"K0014/0 {serial}")
        else:           # coded
            for i, v in enumerate(values, 1):
                lines += [f"K0001/{i} {g(v)}", f"K0014/{i} {serial}"]
    return ("\r\n".join(lines) + "\r\n").encode("cp1252")


QIF_MAP = """# parts.qif -> the crankshaft's features (the cam's uncertainties are in the file: combinedUncertainty)
characteristic, feature, reading, u [um]
CAM_X, cam.x, value,
BORE_D, bore.d, deviation, 0.8
CAM_ANGLE, cam.angle, value,
"""
DFQ_MAP = """# parts.dfq -> the crankshaft's features (K2002 descriptions; the bore by its number K2001);
# u in each characteristic's unit (K2142: um, mm, degree)
characteristic, feature, reading, u
cam x, cam.x, value, 0.15
20, bore.d, deviation, 0.0008
cam angle, cam.angle, value, 0.005
"""


#: the lot fixture: 24 crankshaft bores (mm), a seeded normal rounded to 0.1 µm as a CMM prints them
LOT_CHARACTERISTICS = (("CRANK_BORE_D", "Diameter", "mm", 40.0, 0.012),)
LOT_SEED, LOT_N, LOT_MEAN_MM, LOT_SD_MM = 2026, 24, 40.0035, 0.0028
LOT_EXCLUDED = (6,)      # the study's Exclusions (part indices): the 7th bore, re-measured


def lot_values() -> list[float]:
    import numpy as np

    x = np.random.default_rng(LOT_SEED).normal(LOT_MEAN_MM, LOT_SD_MM, LOT_N)
    return [round(float(v), 4) for v in x]


def lot_document() -> bytes:
    """``lot.qif``: the lot's bores in mm with a QIF CapabilityStudyResults of them (the 7th excluded)."""
    parts = [(f"L-{j + 1:04d}", [(v, None)]) for j, v in enumerate(lot_values())]
    return qif_document(LOT_CHARACTERISTICS, parts, linear_units=(("mm", 0.001),),
                        statistics=("CapabilityStudyResults", {0: list(LOT_EXCLUDED)}))


def main(argv: list[str]) -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "truth.csv").write_text(truth_csv(), encoding="utf-8")
    (OUT / "parts.qif").write_bytes(qif_document())
    (OUT / "lot.qif").write_bytes(lot_document())
    (OUT / "lot_truth.csv").write_text("# the lot.qif bores (studies/make_inspection_fixtures.py)\nserial, bore.d [mm]\n"
                                       + "".join(f"L-{j + 1:04d}, {v:.4f}\n" for j, v in enumerate(lot_values())),
                                       encoding="utf-8")
    (OUT / "parts.dfq").write_bytes(dfq_file())
    (OUT / "parts_qif_map.csv").write_text(QIF_MAP, encoding="utf-8")
    (OUT / "parts_dfq_map.csv").write_text(DFQ_MAP, encoding="utf-8")
    if "--validate" in argv:
        import xmlschema

        xsd = Path(argv[argv.index("--validate") + 1]) / "QIFApplications" / "QIFDocument.xsd"
        schema = xmlschema.XMLSchema(str(xsd))
        for name in ("parts.qif", "lot.qif"):
            errors = list(schema.iter_errors(str(OUT / name)))
            for e in errors[:5]:
                print("invalid:", e.reason, e.path, file=sys.stderr)
            print(f"{name} against {xsd}: {'valid' if not errors else f'{len(errors)} errors'}")


if __name__ == "__main__":
    main(sys.argv[1:])
