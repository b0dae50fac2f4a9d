"""A measured factor: the distribution of its values by method, from Python or from a spec's ``[[factor]]`` table.

The methods: ``fit`` (a parametric family, :mod:`rvtol.inputs.measured.parametric`), ``empirical`` (resampling the
values) and ``kde`` (their kernel density; both :mod:`rvtol.inputs.measured.nonparametric`).  The values come from
a file of measured values (:mod:`rvtol.inputs.measured.read`) or a QIF / DFQ inspection file
(:mod:`rvtol.inputs.inspection`).  :class:`Measured` records what the distribution was built from, for the report
(:mod:`rvtol.inputs.measured.report_tables`).
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np

from ...errors import InputError, SpecError
from ...options import Given, option, read_options
from ...params import Params
from ..inspection import characteristic_values, is_inspection_file
from .parametric import DEFAULT_FAMILIES, FitReport, fit
from .nonparametric import empirical, kde
from .read import read_measurements
from .values import clean_values

METHODS = ("fit", "empirical", "kde")


# ----------------------------------------------------------------------------- one entry point
def from_measurements(values, method: str = "fit", **kw):
    """A factor distribution from measured values by ``method`` (fit | empirical | kde).

    ``fit`` returns the best family's distribution (``family=`` picks another); keyword
    arguments go to :func:`fit`, :func:`empirical` or :func:`kde`.
    """
    if method == "empirical":
        return empirical(values, **kw)
    if method == "kde":
        return kde(values, **kw)
    if method == "fit":
        family = kw.pop("family", None)
        return fit(values, **kw).distribution(family)
    raise InputError(f"unknown method {method!r} (expected one of: {', '.join(METHODS)})")


# ----------------------------------------------------------------------------- a spec's [[factor]] table
#: a key of a factor with ``dist = "measured"`` only
_ONLY = " (dist = \"measured\")"


@dataclass
class MeasuredKeys:
    """The keys of a ``[[factor]]`` table with ``dist = "measured"`` (besides name, unit, …), declared
    (:mod:`rvtol.options`; a part of :class:`rvtol.spec.tables.FactorTable`)."""

    data: str | None = option(None, "the file of measured values, relative to the spec file (csv, xlsx, QIF, DFQ)"
                              + _ONLY)
    column: str | int | None = option(None, "the data's column (a name or a 1-based number; a QIF/DFQ file: its "
                                            "characteristic)" + _ONLY)
    sheet: str | None = option(None, "the data's worksheet (an xlsx file)" + _ONLY)
    method: str = option("fit", "how the values become a distribution" + _ONLY, choices=METHODS)
    families: list[str] = option(list(DEFAULT_FAMILIES), "the families fitted (method fit)" + _ONLY)
    family: str | None = option(None, "the fitted family used (method fit; default: the best)" + _ONLY)
    location: float | None = option(None, "the fitted families' location (method fit; default 0)" + _ONLY)
    interpolate: bool = option(False, "interpolate between the values (method empirical)" + _ONLY)
    bandwidth: float | str = option("scott", "the kernel's bandwidth: scott, silverman or a number (method kde)"
                                    + _ONLY)
    measurement_sigma: float | None = option(None, "the measurement's standard uncertainty, taken out of the "
                                                   "values' spread" + _ONLY, positive=True)


#: the keys of a ``[[factor]]`` table with ``dist = "measured"`` (besides name, unit, …)
MEASURED_KEYS = tuple(f.name for f in fields(MeasuredKeys))


@dataclass(frozen=True, eq=False)
class Measured:
    """The data behind a measured factor's distribution, for the report (fit tables, Q-Q plot)."""

    values: np.ndarray            # as read from the file (before any measurement-uncertainty correction)
    data: str                     # the file as the spec names it
    column: str | int | None
    sheet: str | None
    method: str                   # fit | empirical | kde
    measurement_sigma: float | None = None
    fit: FitReport | None = None  # the ranked candidates (method fit; without the GoF test, run by the report)
    family: str | None = None     # the family used (fit)
    file_statistics: list = field(default_factory=list)   # a QIF file's own Statistics of the values, recomputed
                                                          # (rvtol.inputs.inspection.check_statistics)

    @property
    def n(self) -> int:
        return int(self.values.size)

    @property
    def source(self) -> str:
        return self.data + (f"[{self.column}]" if self.column is not None else "")


def measured_factor(g, base_dir: Path | str = ".") -> tuple[object, Measured]:
    """The spec-loader hook: a ``[[factor]]`` table's measured-data keys → ``(distribution, Measured)``.

    ``g``: the table's declared keys (:class:`MeasuredKeys`, read once: a spec's factor reads them with the rest of
    :class:`rvtol.spec.tables.FactorTable`) as :class:`rvtol.options.Given` (what this takes is recorded; a key of
    another method is refused by the spec reader), or a :class:`rvtol.params.Params` of the table: ``data`` (file, relative to ``base_dir``), ``column``, ``sheet``, ``method`` (fit | empirical | kde,
    default fit), ``families`` and ``family`` (fit), ``location`` (fit), ``interpolate`` (empirical), ``bandwidth``
    (kde: scott | silverman | number), ``measurement_sigma``.  The caller reads ``dist``, ``name``, ``unit``… as for
    any factor.  ``data`` may be a QIF 3.0 or DFQ file
    (:func:`rvtol.inputs.inspection.characteristic_values`): ``column`` then names its characteristic (the QIF item's
    Name or ``id:N``, the DFQ description K2002 or number K2001), the values are every part's reading of it in the
    factor's unit, and a QIF file's own Statistics of them are checked and shown in the report.
    """
    if isinstance(g, Params):
        g = Given(read_options(MeasuredKeys, g), g)
    path = Path(g.need("data"))
    path = path if path.is_absolute() else Path(base_dir) / path
    col = g.get("column")
    sheet = g.get("sheet")
    method = g.get("method", "fit")
    u = g.get("measurement_sigma")
    try:
        unit = g.data.get("unit")    # the factor's unit: a header's unit (d [um]) is converted to it
        unit = unit if isinstance(unit, str) else None
        statistics = []
        if is_inspection_file(path):   # QIF / DFQ: ``column`` names the characteristic
            if sheet is not None:
                raise g.error("sheet", f"a sheet is read from an xlsx file, not from {path.name}")
            got, _, statistics = characteristic_values(path, col, unit)
            values = clean_values(got)
        else:
            values = read_measurements(path, col, sheet=sheet, unit=unit)
    except InputError as exc:
        if exc.key in (None, "-"):   # the file as a whole (missing, unreadable): the spec's key
            raise g.error("data", f"{exc.reason}: {exc.file}") from None
        raise                        # a cell of the data file: that file, row and column
    origin = f"{method} of {path.name}" + (f"[{col}]" if col is not None else "")
    record = dict(values=values, data=str(g.data["data"]), column=col, sheet=sheet, method=method,
                  measurement_sigma=u, file_statistics=statistics)
    try:
        if method == "empirical":
            d = empirical(values, interpolate=g.get("interpolate", False), measurement_sigma=u, origin=origin)
            return d, Measured(**record)
        if method == "kde":
            bw = g.get("bandwidth", "scott")
            return kde(values, bandwidth=bw, measurement_sigma=u, origin=origin), Measured(**record)
        fams = g.get("families", list(DEFAULT_FAMILIES))
        family = g.get("family")
        loc = g.get("location", 0.0)
        rep = fit(values, families=fams, location=loc, measurement_sigma=u, gof=None, origin=origin)
        d = rep.distribution(family)
        return d, Measured(**record, fit=rep, family=rep.candidate(family).family)
    except SpecError:
        raise
    except InputError as exc:
        raise g.error("family" if "was not fitted" in exc.reason else "data", exc.reason) from None


def measured_from_params(p, base_dir: Path | str = ".") -> object:
    """The distribution of :func:`measured_factor` alone."""
    return measured_factor(p, base_dir)[0]
