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
from ..options import REQUIRED, option, read_options
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


def _stripped(opts, error, required: tuple[str, ...], optional: tuple[str, ...]) -> None:
    """Each text key of ``opts`` without its surrounding blanks; a required one that is nothing else: the located
    error."""
    for k in required + optional:
        setattr(opts, k, getattr(opts, k).strip())
        if k in required and not getattr(opts, k):
            raise error(k, "must not be empty")


@dataclass
class SourceTable:
    """``[source]``: a published source — its citation, whether and how it was read."""

    id: str = option(REQUIRED, "unique among the files a study reads")
    status: str = option(REQUIRED, "what became of the source", choices=STATUSES)
    title: str = option(REQUIRED, "the citation's title")
    authors: str = option(REQUIRED, "the citation's authors")
    publication: str = option(REQUIRED, "journal, volume, year, pages")
    read_from: str = option(REQUIRED, "the source itself, or a transcription of it", choices=READ_FROM)
    how_read: str = option(REQUIRED, "copied from a table or digitised from a figure, and the reading's uncertainty")
    accessed: str = option(REQUIRED, "when it was read (a date)")
    reducer: str = option(REQUIRED, "the reducer the source measured")
    doi: str = option("", "the DOI (at least one of doi, url, document)")
    doi_note: str = option("", "how the DOI was obtained, when not from the source itself")
    url: str = option("", "where the source is")
    document: str = option("", "the document, when it has neither DOI nor URL")
    test_conditions: str = option("", "the test's conditions")
    notes: str = option("", "anything else a reader should know")
    year: int | None = option(None, "the year of publication", min=1900, max=2100)
    estimated: dict[str, str] = option({}, "what rvtol had to assume to predict this reducer: topic -> text")

    def complete(self, study, error):
        _stripped(self, error, ("id", "title", "authors", "publication", "how_read", "accessed", "reducer"),
                  ("doi", "doi_note", "url", "document", "test_conditions", "notes"))
        if not (self.doi or self.url or self.document):
            raise error("doi", "give at least one of doi, url, document: where the source can be found")


#: the keys each kind of figure takes beyond the common ones: required, and allowed as well
_KIND_KEYS = {
    "orders": (("orders",), ("unit",)),             # "1/rev" may be written; orders carry no unit of rvtol's
    "order_amplitudes": (("orders", "unit", "amplitudes", "relative_uncertainty", "pins", "ratio"), ()),
    "range": (("unit", "reading_uncertainty", "min", "max"), ()),
    **{k: (("unit", "reading_uncertainty", "value"), ()) for k in ("value", "upper_limit", "lower_limit")},
}

#: every key that only some kinds take, in the order they are checked
_KIND_SPECIFIC = tuple(dict.fromkeys(k for need, also in _KIND_KEYS.values() for k in need + also))


@dataclass
class FigureTable:
    """``[[quantity]]`` of a published-data file: one published figure, the keys its kind takes."""

    id: str = option(REQUIRED, "unique in the file (a study names it <source id>:<id>)")
    kind: str = option(REQUIRED, "how it is compared with a prediction", choices=KINDS)
    quantity: str = option(REQUIRED, "what it is: a study maps these names to its model's outputs")
    description: str = option(REQUIRED, "what was measured")
    reducer: str = option(REQUIRED, "the model of the reducer measured")
    unit_under_test: str = option(REQUIRED, "which unit (e.g. prototype #1)")
    figure: str = option(REQUIRED, "the figure or table it came from")
    origin: str = option("measurement", "a measurement, or a published model's result (listed beside, never judged)",
                         choices=ORIGINS)
    orders: object = option(None, "orders, order_amplitudes: the orders per output revolution (integers >= 1)")
    unit: str | None = option(None, "the figure's unit (not for orders)")
    reading_uncertainty: float | None = option(None, "value, range, limits: half the printed digit or the "
                                                     "digitising error, in unit", nonnegative=True)
    min: float | None = option(None, "range: the printed minimum")
    max: float | None = option(None, "range: the printed maximum (the compared value is max - min)")
    value: float | None = option(None, "value, upper_limit, lower_limit: the printed number")
    amplitudes: object = option(None, "order_amplitudes: the amplitude at each order, in unit (> 0)")
    relative_uncertainty: object = option(None, "order_amplitudes: each amplitude's relative reading uncertainty "
                                                "(one per order, or one number)")
    pins: int | None = option(None, "order_amplitudes: the measured reducer's pin count (its order lattice)", min=2)
    ratio: float | None = option(None, "order_amplitudes: the measured reducer's ratio", positive=True)

    def complete(self, study, error):
        _stripped(self, error, ("id", "quantity", "description", "reducer", "unit_under_test", "figure"), ())
        need, also = _KIND_KEYS[self.kind]
        for k in need:
            if getattr(self, k) is None:
                raise error(k, "missing required key")
        for k in _KIND_SPECIFIC:
            if getattr(self, k) is not None and k not in need + also:
                raise error(k, f"does not apply to a figure of kind {self.kind!r} (it takes "
                               f"{', '.join(need)})")


@dataclass
class MissingTable:
    """``[[missing]]`` of a published-data file: what was looked for and not found or not read."""

    what: str = option(REQUIRED, "what was looked for")
    status: str = option(REQUIRED, "why it is missing", choices=STATUSES[1:])
    tried: str = option(REQUIRED, "where and how it was looked for")

    def complete(self, study, error):
        _stripped(self, error, ("what", "tried"), ())


def _orders(t: Params, orders) -> tuple[int, ...]:
    if not isinstance(orders, list) or not orders or not all(
            isinstance(o, int) and not isinstance(o, bool) and o >= 1 for o in orders):
        raise t.error("orders", "expected a non-empty array of integer orders ≥ 1 (per output revolution)")
    if len(set(orders)) != len(orders):
        raise t.error("orders", "an order appears twice")
    return tuple(orders)


def _per_order(t: Params, name: str, raw, n: int, *, positive: bool) -> tuple[float, ...]:
    """An array of ``n`` numbers (one per order), or one number for every order."""
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
    o = read_options(FigureTable, t)
    t.finish()
    common = dict(source=source, id=o.id, quantity=o.quantity, description=o.description, reducer=o.reducer,
                  unit_under_test=o.unit_under_test, figure=o.figure, kind=o.kind, origin=o.origin)
    if o.kind == "orders":
        return PublishedQuantity(**common, orders=_orders(t, o.orders))
    unit = t.canonical_unit("unit", o.unit)
    if o.kind == "order_amplitudes":
        orders = _orders(t, o.orders)
        amps = _per_order(t, "amplitudes", o.amplitudes, len(orders), positive=True)
        rel = _per_order(t, "relative_uncertainty", o.relative_uncertainty, len(orders), positive=False)
        return PublishedQuantity(**common, unit=unit, orders=orders, amplitudes=amps, relative_uncertainty=rel,
                                 pins=o.pins, ratio=o.ratio)
    if o.kind == "range":
        if not o.max > o.min:
            raise t.error("max", f"must be greater than min ({o.min:g}), got {o.max:g}")
        return PublishedQuantity(**common, unit=unit, value=o.max - o.min, low=o.min, high=o.max,
                                 reading_uncertainty=o.reading_uncertainty)
    return PublishedQuantity(**common, unit=unit, value=o.value, reading_uncertainty=o.reading_uncertainty)


def load_published(path: str | Path) -> PublishedSource:
    """Read and check one published-data file (module docstring)."""
    file = str(path)
    data, sha = read_toml(path)
    top = Params(data, file=file)
    s = top.sub("source")
    h = read_options(SourceTable, s)
    s.finish()
    fields = {k: getattr(h, k) for k in ("id", "title", "authors", "publication", "status", "read_from", "how_read",
                                         "accessed", "reducer", "doi", "doi_note", "url", "document",
                                         "test_conditions", "notes", "year")}
    quantities = tuple(_quantity(t, h.id) for t in top.tables("quantity"))
    ids = [q.id for q in quantities]
    dup = sorted({i for i in ids if ids.count(i) > 1})
    if dup:
        raise top.error("quantity", f"two quantities have the id {dup[0]!r}")
    missing = []
    for t in top.tables("missing"):
        m = read_options(MissingTable, t)
        t.finish()
        missing.append(MissingItem(m.what, m.status, m.tried))
    top.finish()
    status = h.status
    if status == "read" and not quantities:
        raise top.error("quantity", "a source that was read gives at least one [[quantity]] (else status = "
                                    "\"not read\" with a [[missing]] table saying what could not be read)")
    if status != "read":
        if quantities:
            raise top.error("quantity", f"a source with status {status!r} stores no figure: its numbers were not read")
        if not missing:
            raise top.error("missing", f"a source with status {status!r} says in a [[missing]] table what was "
                                       "looked for and why it could not be read")
    return PublishedSource(**fields, file=file, sha256=sha, estimated=MappingProxyType(dict(h.estimated)),
                           quantities=quantities, missing=tuple(missing))


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
