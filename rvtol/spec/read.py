"""Reading a spec: a TOML file or a table (:func:`load_spec`), one ``[[factor]]`` table (or a family of N
copies) into factors, the ``[[correlation]]`` tables, several specs merged into one."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from ..distributions import ONE_SIDED, from_params
from ..errors import InputError, SpecError, did_you_mean
from ..inputs.sheets import READ_SUFFIXES as TABLE_SUFFIXES
from ..params import Params, read_toml
from ..patterns import expand as expand_patterns
from .factors import Factor, ToleranceSpec
from .forms import (
    band_distribution,
    drawing_tolerance,
    measured_distribution,
    nominal_stated,
)
from .gdt import (
    NAME,
    composite_position,
    envelope_of,
    material_condition,
    position_zone,
)


def load_spec(path: str | Path, *, sheet: str | None = None) -> ToleranceSpec:
    """A spec file: TOML, or a table (``.csv``/``.tsv``/``.xlsx``, see :func:`load_table_spec`; ``sheet``: the
    worksheet of a workbook, by default the one :func:`rvtol.inputs.sheets.read_rows` can tell without guessing)."""
    if Path(path).suffix.lower() == ".txt":     # a TOML spec saved as text, or a table: say which to name it
        raise SpecError("a spec is a TOML file (.toml) or a table (.csv, .tsv or .xlsx), not .txt: rename it after "
                        "what it holds (a tab-separated table: .tsv)", file=str(path), key="-")
    if Path(path).suffix.lower() in TABLE_SUFFIXES + (".ods", ".xls"):   # the last two: "save as .xlsx"
        return load_table_spec(path, sheet=sheet)
    if sheet is not None:
        raise SpecError(f"a sheet ({sheet!r}) is named, but a {Path(path).suffix or 'TOML'} spec has no sheets",
                        file=str(path), key="sheet")
    data, sha = read_toml(path)
    spec = spec_from_table(data, file=str(path))
    return replace(spec, sha256=sha)


def load_table_spec(path: str | Path, *, sheet: str | None = None) -> ToleranceSpec:
    """A spec table (:mod:`rvtol.inputs.table_spec`): its rows read as ``[[factor]]`` tables, every error
    at its sheet, row and column."""
    from ..inputs.table_spec import read_spec_table

    table = read_spec_table(path, sheet=sheet)
    try:
        spec = spec_from_table(table.document, file=str(path))
    except InputError as exc:
        raise table.locate(exc) from None
    return replace(spec, sha256=table.sha256, sheet=table.location.sheet)


def spec_from_table(data: dict, *, file: str | None = None, name: str | None = None) -> ToleranceSpec:
    """Build a spec from a parsed TOML document (``[spec]``, ``[[factor]]``, ``[[correlation]]``)."""
    root = Params(data, file=file)
    head = root.sub("spec", {})
    spec_name = head.str("name", name or (Path(file).stem if file else "spec"))
    desc = head.str("description", "")
    head.finish(allow=("source",))
    head.raw("source", None)
    tables = root.tables("factor")
    if not tables:
        raise root.error("factor", "a spec needs at least one [[factor]]")
    factors = [f for t in tables for f in factors_from_params(t)]
    names = [f.name for f in factors]
    origin = [t for t in tables for _ in range(_multiplicity(t))]
    seen: set[str] = set()
    for i, n in enumerate(names):
        if n in seen:
            raise origin[i].error("name", f"duplicate factor name {n!r}")
        seen.add(n)
    factors = expand_patterns(factors, file)        # a composite frame's pattern translations (rvtol.patterns)
    names = [f.name for f in factors]
    corr = correlation_from_tables(root.tables("correlation"), names)
    root.raw("rig", None)       # a test rig's description: its parameters beside its tolerances (transmission_error.rig)
    root.finish()
    return ToleranceSpec(spec_name, tuple(factors), corr, desc, file)


def merge_specs(specs) -> ToleranceSpec:
    """Several specs as one (a study's ``spec = [a, b]``: e.g. the product's drawing tolerances and a test rig's):
    the factors one after the other, each spec's correlation a block of the whole (none between the files);
    a factor name in two files is refused."""
    specs = list(specs)
    if len(specs) == 1:
        return specs[0]
    seen: dict[str, str] = {}
    for s in specs:
        for n in s.names:
            if n in seen:
                raise SpecError(f"factor {n!r} is in {seen[n]} and in {s.file}: a name can be in one spec only",
                                file=s.file, key="factor")
            seen[n] = str(s.file)
    k = sum(len(s) for s in specs)
    corr = None
    if any(s.correlation is not None for s in specs):
        corr = np.eye(k)
        i = 0
        for s in specs:
            if s.correlation is not None:
                corr[i:i + len(s), i:i + len(s)] = s.correlation
            i += len(s)
    return ToleranceSpec(" + ".join(s.name for s in specs), tuple(f for s in specs for f in s.factors), corr,
                         " ".join(s.description for s in specs if s.description), specs[0].file,
                         ";".join(str(s.sha256) for s in specs))


#: the placeholder of a family factor's index
FAMILY_INDEX = "[k]"


def _multiplicity(p: Params) -> int:
    """How many factors a ``[[factor]]`` table stands for (1, or a family's ``multiplicity``)."""
    if "multiplicity" not in p:
        return 1
    return p.int("multiplicity", min=1)


def factors_from_params(p: Params) -> list[Factor]:
    """The factor of one ``[[factor]]`` table, or the N copies of a family (module docstring)."""
    f = factor_from_params(p)
    n = _multiplicity(p)
    p.finish()
    marks = f.name.count(FAMILY_INDEX)
    if "multiplicity" not in p.data:
        if marks:
            raise p.error("multiplicity", f"factor name {f.name!r} holds {FAMILY_INDEX}: a family needs "
                                          "'multiplicity = N' (the number of copies)")
        return [f]
    if marks != 1:
        raise p.error("name", f"a family (multiplicity = {n}) needs {FAMILY_INDEX} exactly once in its name, "
                              f"got {f.name!r}")
    return [replace(f, name=f.name.replace(FAMILY_INDEX, f"[{k}]"), family=f.name) for k in range(1, n + 1)]


def factor_from_params(p: Params) -> Factor:
    """One factor from a ``[[factor]]`` table (a family's template; ``multiplicity`` is read by
    :func:`factors_from_params`)."""
    name = p.str("name")
    if not name or not NAME.match(name):
        raise p.error("name", f"invalid factor name {name!r} (letters, digits, _ [ ] , . - + and spaces)")
    unit = p.unit("unit", None)
    drawing = drawing_tolerance(p, unit)
    if unit is None:
        if drawing is None or drawing.unit is None:
            raise p.error("unit", "missing unit (the unit of the nominal and the tolerance, e.g. mm, um, in)")
        unit = drawing.unit
    measured = None
    if p.data.get("dist") == "measured":
        dist, measured = measured_distribution(p)
    elif drawing is not None:
        dist = band_distribution(p, drawing)
    else:
        dist = from_params(_located_on_nominal(p))
    nominal = p.float("nominal", None) if drawing is None else drawing.nominal
    desc = p.str("description", "")
    part = p.str("part", "")
    feature = p.str("feature", "")
    group = p.str("group", part)
    source = p.str("source", "")
    direction = stack_direction(p)
    zone = position_zone(p, drawing)
    gdt = material_condition(p, drawing, zone)
    frame = {"characteristic": getattr(drawing, "characteristic", ""), "datums": getattr(drawing, "datums", ()),
             "envelope": envelope_of(p, drawing)}
    composite, relating = composite_position(p, drawing, zone, unit, measured)
    frame.update(composite)
    gdt["frame"] = gdt["frame"] or composite["pattern"]     # a composite frame's features share its frame
    p.finish(allow=("multiplicity",))
    nominal_stated(p, drawing)
    limits = drawing.limits if drawing is not None else None
    if relating is not None:      # the feature's own deviation is read in the feature-relating zone
        dist, limits = band_distribution(p, relating), relating.limits
    return Factor(name, unit, dist, nominal, desc, group, source, part=part, feature=feature, direction=direction,
                  limits=limits, measured=measured, zone=zone, **gdt, **frame)


#: keys that place a factor's distribution; without any, a non-zero ``nominal`` places it
_LOCATION_KEYS = ("mean", "lower", "upper", "median", "mode", "shift")


def _located_on_nominal(p: Params) -> Params:
    """The factor's table with ``mean = nominal`` when it gives a non-zero nominal and nothing that places the
    distribution: ``nominal = 10.0, dist = "normal", tolerance = 0.06`` is 10 ± 0.03, never 0 ± 0.03 (a distribution
    left at its default mean 0 beside a nominal of 10 is a silent wrong answer).  A one-sided (magnitude) kind has
    no mean to place: it must say where its values start (``shift``)."""
    nominal = p.data.get("nominal")
    if not isinstance(nominal, (int, float)) or isinstance(nominal, bool) or nominal == 0 \
            or any(k in p.data for k in _LOCATION_KEYS):
        return p
    kind = p.data.get("dist")
    if kind in ONE_SIDED:
        raise p.error("nominal", f"a {kind} factor is a magnitude (its values start at 0): with nominal = {nominal} "
                                 "say where they start ('shift'), or give the nominal as 0")
    placed = Params({**p.data, "mean": nominal}, file=p.file, key=p.key)
    placed._probed = p._probed          # one table: what either reads counts as read (p.finish sees it)
    placed._read = p._read
    return placed


def stack_direction(p: Params) -> float | None:
    """``direction``: the factor's sign or coefficient in a one-dimensional stack (``+``, ``-`` or a number)."""
    v = p.raw("direction", None)
    if isinstance(v, str) and v.strip().replace("\u2212", "-") in ("+", "-"):
        return 1.0 if v.strip() == "+" else -1.0
    return None if v is None else p.float("direction")


def correlation_from_tables(tables: list[Params], names: list[str]) -> np.ndarray | None:
    if not tables:
        return None
    k = len(names)
    c = np.eye(k)
    given: dict[tuple[int, int], str] = {}   # pair -> the table that gave it: a second one contradicts or repeats
    for t in tables:
        if "pair" in t:
            fs = t.strs("pair")
            if len(fs) != 2:
                raise t.error("pair", "a pair names exactly two factors")
            rho = t.float("rho", min=-1.0, max=1.0)
            m = np.array([[1.0, rho], [rho, 1.0]])
        else:
            fs = t.strs("factors", min_length=2)
            rows = t.raw("matrix")
            if not isinstance(rows, list) or len(rows) != len(fs):
                raise t.error("matrix", f"expected a {len(fs)}×{len(fs)} matrix")
            m = np.array([Params({"r": r}, file=t.file, key=t.path("matrix")).floats("r", length=len(fs))
                          for r in rows])
            if not np.allclose(m, m.T, atol=1e-12):
                raise t.error("matrix", "correlation matrix is not symmetric")
            if not np.allclose(np.diag(m), 1.0):
                raise t.error("matrix", "correlation matrix needs ones on the diagonal")
            if np.any(np.abs(m) > 1.0):
                raise t.error("matrix", "correlations must lie in [-1, 1]")
        idx = []
        for f in fs:
            if f not in names:
                raise t.error("factors" if "factors" in t else "pair",
                              f"unknown factor name {f!r}{did_you_mean(f, names)}")
            idx.append(names.index(f))
        if len(set(idx)) != len(idx):
            raise t.error("factors", "a factor is named twice")
        t.finish()
        for a, ia in enumerate(idx):
            for b, ib in enumerate(idx):
                if a < b:
                    pair = (min(ia, ib), max(ia, ib))
                    if pair in given:
                        prev = c[ia, ib]
                        same = "the same" if prev == m[a, b] else f"{prev:g} there, {m[a, b]:g} here"
                        raise t.error("factors" if "factors" in t.data else "pair",
                                      f"the correlation of {names[pair[0]]!r} and {names[pair[1]]!r} is given twice "
                                      f"(first in {given[pair]}; {same}): give each pair once")
                    given[pair] = t.key
                if a != b:
                    c[ia, ib] = m[a, b]
    w = np.linalg.eigvalsh(c)
    if w.min() <= 1e-10:
        raise SpecError("correlation matrix is not positive definite", file=tables[0].file, key="correlation")
    return c
