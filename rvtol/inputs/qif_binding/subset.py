"""Write the subset of the QIF 3.0 schema rvtol binds: ``python subset.py QIF3_XSD_DIR OUT.xsd``.

QIF3_XSD_DIR is the official QIF 3.0 schema tree (``QIFApplications/QIFDocument.xsd`` and
``QIFLibrary/*.xsd``).  The subset is made mechanically, not written by hand:

1. every ``xs:include``d file is read and its global definitions pooled (one target namespace);
2. the content models of the types in :data:`KEEP` are cut to the child elements named there
   (every attribute stays); every other type keeps its whole definition, verbatim;
3. only the definitions reachable from the global element ``QIFDocument`` are written — following
   ``type``, ``base``, ``ref``, ``itemType``, ``memberTypes``, attribute groups and groups, and
   from an abstract element to the members of its substitution group.

A document valid against the full schema is read through the subset with the elements the subset
cut skipped (the binding's parser is told to ignore unknown elements); an element the subset keeps
has the official definition, so its values are typed as the standard types them.
"""
from __future__ import annotations

import copy
import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

XS = "http://www.w3.org/2001/XMLSchema"
QIF = "http://qifstandards.org/xsd/qif3"
ROOT = "QIFDocument"

#: complex type (a full-match pattern of its name) -> the child elements (name or ref) kept in its content model
KEEP = {
    "QIFDocumentType": {"Version", "FileUnits", "Characteristics", "Results", "Statistics"},
    "ResultsType": {"MeasurementResultsSet", "ActualComponentSets"},
    "MeasurementResultsType": {"MeasuredCharacteristics", "ActualComponentIds"},
    "ActualComponentType": {"SerialNumber"},
    "CharacteristicsType": {"CharacteristicNominals", "CharacteristicItems"},
    "MeasuredCharacteristicsType": {"CharacteristicMeasurements"},
    # one characteristic of any kind: its name, the links item -> nominal, measurement -> item, the values
    r"\w*Characteristic(Nominal|Item|Measurement)(Base)?Type": {
        "Name", "CharacteristicNominalId", "CharacteristicItemId", "TargetValue", "Value"},
    # QIF Statistics: each study's per-characteristic statistics of its values (the measurements they name, or
    # the values themselves) and what it computed of them (Average, StandardDeviation, Minimum, …)
    "StatisticsType": {"StatisticalStudiesResults"},
    "StatisticalStudyResultsBaseType": {"CharacteristicsStats"},
    "MultipleProductInstanceStudyResultsBaseType": {"NumberOfSamples"},
    r"\w*StudyResultsType": set(),
    "CharacteristicStatsEvalBaseType": {"MeasuredIds", "MeasuredValues"},
    r"\w*CharacteristicStatsEvalType": {"ValueStats"},
    r"Stats(WithTol)?NumericalBaseType": {"NumericCharacteristicStatsValue", "NumericCharacteristicWithTolStatsValue"},
}
#: what no value is read from: annotations, identity constraints (they name paths the subset cut)
DROPPED = ("annotation", "key", "keyref", "unique")
REF_ATTRS = ("type", "base", "ref", "itemType", "substitutionGroup")


def local(qname: str | None) -> str | None:
    """The local part of a reference in the QIF namespace (None for an xs: type)."""
    if not qname:
        return None
    prefix, _, name = qname.rpartition(":")
    return None if prefix == "xs" else name


def read_pool(entry: Path) -> dict[tuple[str, str], ET.Element]:
    """(kind, name) -> global definition, over ``entry`` and every file it includes."""
    pool: dict[tuple[str, str], ET.Element] = {}
    todo, seen = [entry.resolve()], set()
    while todo:
        path = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        for node in ET.parse(path).getroot():
            tag = node.tag.split("}")[1]
            if tag == "include":
                todo.append((path.parent / node.get("schemaLocation")).resolve())
            elif node.get("name"):
                pool[(tag, node.get("name"))] = node
    return pool


def cut(node: ET.Element, keep: set[str]) -> ET.Element:
    """A copy of a complex type without the child elements not in ``keep``."""
    node = copy.deepcopy(node)
    for parent in node.iter():
        for child in list(parent):
            if child.tag == f"{{{XS}}}element" and (child.get("name") or local(child.get("ref"))) not in keep:
                parent.remove(child)
    return node


def bare(node: ET.Element) -> ET.Element:
    """A copy without :data:`DROPPED` children."""
    node = copy.deepcopy(node)
    for parent in node.iter():
        for child in list(parent):
            if child.tag.split("}")[1] in DROPPED:
                parent.remove(child)
    return node


def references(node: ET.Element) -> set[str]:
    out = set()
    for n in node.iter():
        for a in REF_ATTRS:
            if n.get(a) and not (a == "substitutionGroup" and n is node):
                out.add(local(n.get(a)))
        for m in (n.get("memberTypes") or "").split():
            out.add(local(m))
    out.discard(None)
    return out


def subset(pool: dict[tuple[str, str], ET.Element]) -> list[ET.Element]:
    by_name: dict[str, list[ET.Element]] = {}
    members: dict[str, list[str]] = {}
    for (kind, name), node in pool.items():
        by_name.setdefault(name, []).append(node)
        if kind == "element" and node.get("substitutionGroup"):
            members.setdefault(local(node.get("substitutionGroup")), []).append(name)
    written, todo, seen = [], [ROOT], set()
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        for node in by_name.get(name, []):
            kind = node.tag.split("}")[1]
            keep = next((k for pat, k in KEEP.items() if re.fullmatch(pat, name)), None)
            if kind == "complexType" and keep is not None:
                node = cut(node, keep)
            node = bare(node)
            written.append(node)
            todo.extend(references(node))
            if kind == "element":
                todo.extend(members.get(name, []))
    order = {key: i for i, key in enumerate(pool)}     # the schema's own order (not the walk's, which follows sets)
    return sorted(written, key=lambda n: order[(n.tag.split("}")[1], n.get("name"))])


def main(qif_dir: str, out: str) -> None:
    pool = read_pool(Path(qif_dir) / "QIFApplications" / "QIFDocument.xsd")
    nodes = subset(pool)
    ET.register_namespace("xs", XS)
    ET.register_namespace("", QIF)
    schema = ET.Element(f"{{{XS}}}schema", {"targetNamespace": QIF, "elementFormDefault": "qualified",
                                            "attributeFormDefault": "unqualified", "version": "3.0.0",
                                            "xmlns": QIF})
    schema.extend(nodes)
    ET.indent(schema)
    Path(out).write_text("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- generated by subset.py from the QIF 3.0 "
                         "schema: do not edit -->\n" + ET.tostring(schema, encoding="unicode") + "\n", "utf-8")
    print(f"{len(nodes)} global definitions of {len(pool)}", file=sys.stderr)


if __name__ == "__main__":
    main(*sys.argv[1:])
