"""Reading a spec: a TOML file or a table (:func:`load_spec`), one ``[[factor]]`` table (or a family of N
copies) into factors, the ``[[correlation]]`` tables, several specs merged into one."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from .. import units
from ..distributions import ONE_SIDED, PARAMETERS, Distribution, law, origin_of
from ..inputs.measured.factor import MEASURED_KEYS
from ..options import Given, read_options
from ..errors import InputError, SpecError, did_you_mean
from ..inputs.sheets import READ_SUFFIXES as TABLE_SUFFIXES
from ..params import Params, read_toml
from ..patterns import expand as expand_patterns
from .factors import Factor, ToleranceSpec
from .tables import CorrelationTable, FactorTable, SpecHead
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
    head_table = root.sub("spec", {})
    head = read_options(SpecHead, head_table)
    head_table.finish()
    spec_name = head.name if head.name is not None else name or (Path(file).stem if file else "spec")
    desc = head.description
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
    :func:`factors_from_params`): its declared keys (:class:`rvtol.spec.tables.FactorTable`) read once, then its form
    — a law, a drawing tolerance read over its band, measured values — works from them; a key the table gives that
    its form does not read is refused (:func:`_refuse_unread`)."""
    view = Params(p.data, file=p.file, key=p.key)      # every declared key read: its errors know them all (a typo)
    g = Given(read_options(FactorTable, view), view)
    name = g.need("name")
    if not name or not NAME.match(name):
        raise g.error("name", f"invalid factor name {name!r} (letters, digits, _ [ ] , . - + and spaces)")
    unit = _unit(g)
    drawing = drawing_tolerance(g, unit)
    if unit is None:
        if drawing is None or drawing.unit is None:
            raise g.error("unit", "missing unit (the unit of the nominal and the tolerance, e.g. mm, um, in)")
        unit = drawing.unit
    measured = None
    if g.data.get("dist") == "measured":
        dist, measured = measured_distribution(g)
    elif drawing is not None:
        dist = band_distribution(g, drawing)
    else:
        dist = _law_on_nominal(g)
    nominal = g.get("nominal") if drawing is None else drawing.nominal
    desc = g.get("description")
    part = g.get("part")
    feature = g.get("feature")
    group = g.get("group", part)
    source = g.get("source")
    direction = stack_direction(g)
    zone = position_zone(g, drawing)
    gdt = material_condition(g, drawing, zone)
    frame = {"characteristic": getattr(drawing, "characteristic", ""), "datums": getattr(drawing, "datums", ()),
             "envelope": envelope_of(g, drawing)}
    composite, relating = composite_position(g, drawing, zone, unit, measured)
    frame.update(composite)
    gdt["frame"] = gdt["frame"] or composite["pattern"]     # a composite frame's features share its frame
    _refuse_unread(p, g, "a measured factor" if measured is not None else
                   f"a tolerance in drawing notation ({g.data['tolerance']!r})" if drawing is not None else
                   f"dist = {dist.kind!r}")
    nominal_stated(g, drawing)
    limits = drawing.limits if drawing is not None else None
    if relating is not None:      # the feature's own deviation is read in the feature-relating zone
        dist, limits = band_distribution(g, relating), relating.limits
    return Factor(name, unit, dist, nominal, desc, group, source, part=part, feature=feature, direction=direction,
                  limits=limits, measured=measured, zone=zone, **gdt, **frame)


def _unit(g: Given) -> str | None:
    """``unit``, canonical (:func:`rvtol.units.canonical`), or None when the table gives none."""
    u = g.get("unit")
    if u is None:
        return None
    try:
        return units.canonical(u)
    except InputError as exc:
        raise g.error("unit", exc.reason) from None


#: keys a factor's form may leave unread and the table still hold: a family's size (:func:`factors_from_params`)
_ALWAYS = ("multiplicity",)
#: the keys a factor's form reads only in some forms (a law's parameters, the measured data's)
_FORM_KEYS = tuple(dict.fromkeys(("dist", "tolerance") + PARAMETERS + MEASURED_KEYS))


def _refuse_unread(p: Params, g: Given, form: str) -> None:
    """A key the table gives that is not a factor's (a typo: named with the key it resembles), then one its form did
    not read (``alpha`` beside ``dist = "normal"``, ``bandwidth`` of a fit): one located error.  Every key is then
    marked read on ``p``."""
    g.table.finish()                   # the view read every declared key: what is left is no factor's key
    unread = sorted(k for k in p.data if k not in g.used and k not in _ALWAYS)
    if unread:
        k = unread[0]
        reads = [k for k in _FORM_KEYS if k in g.used]
        raise g.error(k, f"does not apply to {form} (it reads {', '.join(reads) or 'none of the law keys'})")
    for k in p.data:
        p.raw(k)


#: keys that place a factor's distribution; without any, a non-zero ``nominal`` places it
_LOCATION_KEYS = ("mean", "lower", "upper", "median", "mode", "shift")


def _law_on_nominal(g: Given) -> Distribution:
    """The factor's law (:func:`rvtol.distributions.law`), with ``mean = nominal`` when the table gives a non-zero
    nominal and nothing that places the distribution: ``nominal = 10.0, dist = "normal", tolerance = 0.06`` is
    10 ± 0.03, never 0 ± 0.03 (a distribution left at its default mean 0 beside a nominal of 10 is a silent wrong
    answer).  A one-sided (magnitude) kind has no mean to place: it must say where its values start (``shift``)."""
    kind = g.get("dist")
    if kind is None:
        raise g.error("dist", "missing required key")
    nominal = g.opts.nominal
    data = g.data
    if nominal is not None and nominal != 0 and not any(k in g for k in _LOCATION_KEYS):
        if kind in ONE_SIDED:
            raise g.error("nominal", f"a {kind} factor is a magnitude (its values start at 0): with nominal = "
                                     f"{data['nominal']} say where they start ('shift'), or give the nominal as 0")
        placed = Given(replace(g.opts, mean=nominal), g.table)
        placed.used = g.used                 # one table: what either takes counts as taken
        data = {**data, "mean": data["nominal"]}
        g = placed
    return law(kind, g, origin_of(data))


def stack_direction(g: Given) -> float | None:
    """``direction``: the factor's sign or coefficient in a one-dimensional stack (``+``, ``-`` or a number)."""
    v = g.get("direction")
    if isinstance(v, str):
        if v.strip().replace("\u2212", "-") in ("+", "-"):
            return 1.0 if v.strip() == "+" else -1.0
        raise g.error("direction", f"expected a number (or + or -), got the string {v!r}")
    return v


def correlation_from_tables(tables: list[Params], names: list[str]) -> np.ndarray | None:
    if not tables:
        return None
    k = len(names)
    c = np.eye(k)
    given: dict[tuple[int, int], str] = {}   # pair -> the table that gave it: a second one contradicts or repeats
    for t in tables:
        o = read_options(CorrelationTable, t)
        if o.pair is not None:
            if len(o.pair) != 2:
                raise t.error("pair", "a pair names exactly two factors")
            for key in ("factors", "matrix"):
                if getattr(o, key) is not None:
                    raise t.error(key, "a pair's correlation is rho: give pair and rho, or factors and matrix")
            fs = o.pair
            rho = Given(o, t).need("rho")
            m = np.array([[1.0, rho], [rho, 1.0]])
        else:
            if o.rho is not None:
                raise t.error("rho", "rho is a pair's correlation: give pair = [a, b] with it (or factors and matrix)")
            fs = Given(o, t).need("factors")
            rows = Given(o, t).need("matrix")
            if len(rows) != len(fs):
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
                raise t.error("pair" if o.pair is not None else "factors",
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
                        raise t.error("pair" if o.pair is not None else "factors",
                                      f"the correlation of {names[pair[0]]!r} and {names[pair[1]]!r} is given twice "
                                      f"(first in {given[pair]}; {same}): give each pair once")
                    given[pair] = t.key
                if a != b:
                    c[ia, ib] = m[a, b]
    w = np.linalg.eigvalsh(c)
    if w.min() <= 1e-10:
        raise SpecError("correlation matrix is not positive definite", file=tables[0].file, key="correlation")
    return c
