"""Published measurements of real reducers: one TOML file per source, with its citation and how it was read.

A file (``data/measurements/published/*.toml``; README there) holds::

    [source]
    id = "yang2021_mmt"                   # unique among the files a study reads
    title = "..."                         # citation: title, authors, publication (journal, volume, year, pages)
    authors = "..."
    publication = "..."
    doi = "..."                           # at least one of doi, url, document
    doi_note = "..."                      # optional: how the DOI was obtained, when not from the source itself
    url = "..."
    status = "read"                       # read | not read | not found
    read_from = "primary"                 # primary (the source itself) | secondary (a transcription of it)
    how_read = "..."                      # copied from a table / digitised from a figure, and the reading uncertainty
    accessed = "2026-11-27"
    reducer = "RV-80E"
    test_conditions = "..."               # optional
    notes = "..."                         # optional
    [source.estimated]                    # optional: what rvtol had to assume to predict this reducer
    geometry = "..."

    [[quantity]]                          # one published figure (a source that was read has at least one)
    id = "te_pp_prototype_1"
    quantity = "transmission_error_pp"    # what it is; a study maps these names to its model's outputs
    description = "..."
    reducer = "RV-80E"                    # the model of the reducer measured
    unit_under_test = "prototype #1"
    figure = "..."                        # the figure or table it came from
    kind = "range"                        # value | range | upper_limit | lower_limit | orders | order_amplitudes
    origin = "measurement"                # or "model": a published model's result (listed beside, never judged)
    min = -29.68                          # range: the printed extremes (the compared value is max − min)
    max = 30.39
    value = 1.0                           # value, upper_limit, lower_limit
    orders = [1, 40]                      # orders: the orders (per output revolution) the source calls strong
    unit = "arcsec"                       # not for orders
    reading_uncertainty = 0.005           # in unit: half the printed digit, or the digitising error

    # kind = "order_amplitudes": a measured spectrum's amplitude at each order, compared in SHAPE (each order's
    # amplitude over the reference order's) with the study's design when their order lattices agree
    orders = [1, 3, 39, 40]
    amplitudes = [61.0, 3.0, 4.1, 2.9]    # in unit, one per order
    relative_uncertainty = [0.05, 0.25, 0.2, 0.25]   # one per order (or one number): the reading's, relative
    pins = 40                             # the measured reducer's pin count z_b and ratio i (its order lattice)
    ratio = 81

    [[missing]]                           # what was looked for and not found / not read (a source not read has one)
    what = "..."
    status = "not found"
    tried = "..."

Every problem is one :class:`rvtol.errors.InputError` naming the file and the key.  Nothing here invents a
number: a source whose figures could not be read is stored with ``status = "not read"`` and no quantity.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

from .. import units
from ..errors import InputError
from ..params import Params, read_toml

#: how a published figure is compared with a prediction (:mod:`.agreement`)
KINDS = ("value", "range", "upper_limit", "lower_limit", "orders", "order_amplitudes")
#: where a published figure comes from: a measurement, or a published model's result (listed beside the prediction)
ORIGINS = ("measurement", "model")
#: what became of a source
STATUSES = ("read", "not read", "not found")
READ_FROM = ("primary", "secondary")


@dataclass(frozen=True)
class PublishedQuantity:
    """One published figure (in the file's ``unit``; ``value`` is the compared number: a range's width)."""

    source: str
    id: str
    quantity: str
    description: str
    reducer: str
    unit_under_test: str
    figure: str
    kind: str
    unit: str = ""
    value: float | None = None
    low: float | None = None            # range: the printed minimum
    high: float | None = None           # range: the printed maximum
    orders: tuple[int, ...] = ()
    reading_uncertainty: float = 0.0
    origin: str = "measurement"
    amplitudes: tuple[float, ...] = ()          # order_amplitudes: one per order (in unit)
    relative_uncertainty: tuple[float, ...] = ()
    pins: int | None = None                     # order_amplitudes: the measured reducer's z_b and ratio
    ratio: float | None = None

    @property
    def key(self) -> str:
        """``<source id>:<quantity id>``, how a study names it."""
        return f"{self.source}:{self.id}"

    @property
    def numeric(self) -> bool:
        return self.kind not in ("orders", "order_amplitudes")

    @property
    def measured(self) -> bool:
        return self.origin == "measurement"


@dataclass(frozen=True)
class MissingItem:
    """Something looked for in a source and not found or not read."""

    what: str
    status: str
    tried: str


@dataclass(frozen=True)
class PublishedSource:
    id: str
    title: str
    authors: str
    publication: str
    status: str
    read_from: str
    how_read: str
    accessed: str
    reducer: str
    file: str
    sha256: str
    year: int | None = None
    doi: str = ""
    doi_note: str = ""
    url: str = ""
    document: str = ""
    test_conditions: str = ""
    notes: str = ""
    estimated: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    quantities: tuple[PublishedQuantity, ...] = ()
    missing: tuple[MissingItem, ...] = ()

    @property
    def citation(self) -> str:
        """One line: authors, title, publication, DOI or URL."""
        where = f"doi:{self.doi}" if self.doi else (self.url or self.document)
        return f"{self.authors}. {self.title}. {self.publication}. {where}"


def _text(p: Params, name: str, default=None) -> str:
    v = p.str(name) if default is None else p.str(name, default)
    if default is None and not v.strip():
        raise p.error(name, "must not be empty")
    return v.strip()


def _orders(t: Params) -> tuple[int, ...]:
    orders = t.raw("orders")
    if not isinstance(orders, list) or not orders or not all(
            isinstance(o, int) and not isinstance(o, bool) and o >= 1 for o in orders):
        raise t.error("orders", "expected a non-empty array of integer orders ≥ 1 (per output revolution)")
    if len(set(orders)) != len(orders):
        raise t.error("orders", "an order appears twice")
    return tuple(orders)


def _per_order(t: Params, name: str, n: int, *, positive: bool) -> tuple[float, ...]:
    """An array of ``n`` numbers (one per order), or one number for every order."""
    raw = t.raw(name)
    vals = raw if isinstance(raw, list) else [raw] * n
    if len(vals) != n:
        raise t.error(name, f"expected one number per order ({n}), got {len(vals)}")
    out = []
    for i, v in enumerate(vals):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not v == v or abs(v) == float("inf"):
            raise t.error(name, f"entry {i + 1}: expected a number, got {v!r}")
        if (v <= 0) if positive else (v < 0):
            raise t.error(name, f"entry {i + 1}: must be {'> 0' if positive else '>= 0'}, got {v!r}")
        out.append(float(v))
    return tuple(out)


def _quantity(t: Params, source: str) -> PublishedQuantity:
    qid = _text(t, "id")
    kind = t.str("kind", choices=KINDS)
    common = dict(source=source, id=qid, quantity=_text(t, "quantity"), description=_text(t, "description"),
                  reducer=_text(t, "reducer"), unit_under_test=_text(t, "unit_under_test"),
                  figure=_text(t, "figure"), kind=kind, origin=t.str("origin", "measurement", choices=ORIGINS))
    if kind == "orders":
        orders = _orders(t)
        t.str("unit", "")                 # "1/rev" may be written; orders carry no unit of rvtol's
        t.finish()
        return PublishedQuantity(**common, orders=orders)
    if kind == "order_amplitudes":
        orders = _orders(t)
        unit = t.unit("unit")
        amps = _per_order(t, "amplitudes", len(orders), positive=True)
        rel = _per_order(t, "relative_uncertainty", len(orders), positive=False)
        pins = t.int("pins", min=2)
        ratio = t.float("ratio", positive=True)
        t.finish()
        return PublishedQuantity(**common, unit=unit, orders=orders, amplitudes=amps, relative_uncertainty=rel,
                                 pins=pins, ratio=ratio)
    unit = t.unit("unit")
    unc = t.float("reading_uncertainty", nonnegative=True)
    if kind == "range":
        lo, hi = t.float("min"), t.float("max")
        if not hi > lo:
            raise t.error("max", f"must be greater than min ({lo:g}), got {hi:g}")
        t.finish()
        return PublishedQuantity(**common, unit=unit, value=hi - lo, low=lo, high=hi, reading_uncertainty=unc)
    value = t.float("value")
    t.finish()
    return PublishedQuantity(**common, unit=unit, value=value, reading_uncertainty=unc)


def load_published(path: str | Path) -> PublishedSource:
    """Read and check one published-data file (module docstring)."""
    file = str(path)
    data, sha = read_toml(path)
    top = Params(data, file=file)
    s = top.sub("source")
    sid = _text(s, "id")
    status = s.str("status", choices=STATUSES)
    fields = dict(id=sid, title=_text(s, "title"), authors=_text(s, "authors"), publication=_text(s, "publication"),
                  status=status, read_from=s.str("read_from", choices=READ_FROM), how_read=_text(s, "how_read"),
                  accessed=_text(s, "accessed"), reducer=_text(s, "reducer"), file=file, sha256=sha,
                  doi=_text(s, "doi", ""), doi_note=_text(s, "doi_note", ""), url=_text(s, "url", ""), document=_text(s, "document", ""),
                  test_conditions=_text(s, "test_conditions", ""), notes=_text(s, "notes", ""))
    if not (fields["doi"] or fields["url"] or fields["document"]):
        raise s.error("doi", "give at least one of doi, url, document: where the source can be found")
    year = s.raw("year", None)
    if year is not None and (isinstance(year, bool) or not isinstance(year, int) or not 1900 <= year <= 2100):
        raise s.error("year", f"expected a year (integer), got {year!r}")
    est = s.sub("estimated", {})
    estimated = {k: est.str(k) for k in list(est.keys())}
    est.finish()
    s.finish()
    quantities = tuple(_quantity(t, sid) for t in top.tables("quantity"))
    ids = [q.id for q in quantities]
    dup = sorted({i for i in ids if ids.count(i) > 1})
    if dup:
        raise top.error("quantity", f"two quantities have the id {dup[0]!r}")
    missing = []
    for t in top.tables("missing"):
        missing.append(MissingItem(_text(t, "what"), t.str("status", choices=STATUSES[1:]), _text(t, "tried")))
        t.finish()
    top.finish()
    if status == "read" and not quantities:
        raise top.error("quantity", "a source that was read gives at least one [[quantity]] (else status = "
                                    "\"not read\" with a [[missing]] table saying what could not be read)")
    if status != "read":
        if quantities:
            raise top.error("quantity", f"a source with status {status!r} stores no figure: its numbers were not read")
        if not missing:
            raise top.error("missing", f"a source with status {status!r} says in a [[missing]] table what was "
                                       "looked for and why it could not be read")
    return PublishedSource(**fields, year=year, estimated=MappingProxyType(estimated), quantities=quantities,
                           missing=tuple(missing))


def load_published_files(paths) -> list[PublishedSource]:
    """Several files (in the order given); source ids must be unique."""
    out = [load_published(p) for p in paths]
    seen: dict[str, str] = {}
    for src in out:
        if src.id in seen:
            raise InputError(f"source id {src.id!r} is also used by {seen[src.id]}", file=src.file, key="source.id")
        seen[src.id] = src.file
    return out


def display_value(q: PublishedQuantity, unit: str) -> tuple[float, float]:
    """``(value, reading uncertainty)`` of ``q`` in ``unit`` (an output's display unit)."""
    return float(units.convert(q.value, q.unit, unit)), float(units.convert(q.reading_uncertainty, q.unit, unit))
