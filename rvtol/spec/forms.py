"""The engineers' input forms of a ``[[factor]]`` table (:mod:`rvtol.inputs`): a tolerance in drawing notation
and the distribution read over its band, and measured values."""
from __future__ import annotations

from pathlib import Path

from ..distributions import Distribution, from_params
from ..errors import InputError
from ..inputs.geometric import is_geometric, parse_geometric
from ..inputs.measured import measured_factor
from ..inputs.notation import NotationError, Tolerance, parse_tolerance
from ..options import Given
from ..params import Params
from .gdt import frame_datums

#: distribution keys a factor written in drawing notation may add to refine its band's reading
_REFINING = ("mean", "sigma", "lower", "upper", "mode", "median", "shape", "scale", "shift")


def drawing_tolerance(g: Given, unit: str | None) -> Tolerance | None:
    """The factor's tolerance in drawing notation (``tolerance = "+0.10/-0.00"``, ``"25 H7"``…), or None
    for a number (a band width, read by :func:`rvtol.distributions.law`).  An ISO 2768 general tolerance of
    an angle needs ``shorter_side`` (mm, or ``{value, unit}``), one of a chamfer height or an external radius
    ``broken_edge = true`` (:func:`rvtol.inputs.notation.parse_tolerance`).  ``g``: the factor's declared keys
    (:class:`rvtol.spec.tables.FactorTable`)."""
    text = g.opts.tolerance
    side = g.get("shorter_side")
    edge = g.get("broken_edge", False)
    if not isinstance(text, str):
        if side is not None or edge:
            key = "shorter_side" if side is not None else "broken_edge"
            raise g.error(key, f"{key} belongs to an ISO 2768 general tolerance: give tolerance = \"ISO 2768-m\" (the "
                               "class of the drawing's title block)")
        return None
    g.get("tolerance")
    nominal = g.get("nominal")
    try:
        if is_geometric(text):
            if nominal not in (None, 0):
                raise g.error("nominal", f"a profile or form tolerance ({text!r}) is a deviation from the true "
                                         "profile or a magnitude: give no nominal (or 0)")
            if side is not None or edge:
                raise g.error("shorter_side" if side is not None else "broken_edge",
                              "belongs to an ISO 2768 general tolerance, not to a profile or form tolerance")
            return parse_geometric(text, unit=unit)
        if text.lstrip()[:1] in "⌀Øø∅":   # a position frame's datum letters (⌀0.5 A B C): what locates the zone
            text, _ = frame_datums(g, "tolerance", text)     # (a datum feature of size at MMB: datum_size)
        tol = parse_tolerance(text, nominal=nominal, unit=unit, shorter_side=side, broken_edge=edge)
    except NotationError as exc:
        raise g.error(exc.key or "tolerance", exc.reason) from None
    return tol


def nominal_stated(g: Given, drawing: Tolerance | None) -> None:
    """Deviations from a nominal the table does not give (``±0.1``, ``+0/-0.12`` without ``nominal``): read about 0
    they would invent one — refused, as a spreadsheet's missing nominal cell is (:mod:`rvtol.inputs.table_spec`)."""
    if drawing is None or "nominal" in g or drawing.nominal is not None \
            or drawing.form not in ("symmetric", "deviations") or any(k in g for k in ("mean", "median", "mode")):
        return
    raise g.error("nominal", f"missing nominal: the tolerance {g.data['tolerance']!r} is a deviation from it (write "
                             "nominal = 0 for a factor that is itself a deviation from its nominal, e.g. a position "
                             "or form error)")


def band_distribution(g: Given, tol: Tolerance) -> Distribution:
    """The distribution kind ``dist`` (default normal) read over a drawing tolerance's band
    (:meth:`rvtol.inputs.notation.Tolerance.factor_table`); distribution keys given beside it refine or
    override what the band gives (an explicit ``sigma`` replaces the band's σ)."""
    kind = g.get("dist", "rayleigh" if getattr(tol, "is_form", False) else "normal")
    level = g.get("sigma_level")
    try:
        table = tol.factor_table(kind, sigma_level=level)
    except NotationError as exc:
        raise g.error("sigma_level" if "sigma_level" in exc.reason else "dist", exc.reason) from None
    table.pop("nominal", None)
    given = {k: g.data[k] for k in _REFINING if k in g}      # as written (the distribution's origin shows them)
    g.used.update(given)
    if kind == "normal" and "sigma" in given:
        table.pop("tolerance", None)
    table.update(given)
    try:
        dist = from_params(Params(table, file=g.table.file, key=g.table.key))
    except InputError as exc:
        if (exc.key or "").rsplit(".", 1)[-1] not in given:   # a number the tolerance gave
            exc.key = g.table.path("tolerance")
        raise
    lo, hi = tol.limits
    slack = 1e-9 * max(abs(lo), abs(hi), hi - lo)
    if given and not lo - slack <= dist.mean <= hi + slack:
        key = next(iter(given))
        raise g.error(key, f"{key} = {given[key]!r} puts the {kind} distribution's mean at {dist.mean:.6g}, outside the "
                           f"drawing's limits {lo:.6g}..{hi:.6g} ({tol.text!r}): the parts it describes would not meet "
                           "the drawing — check the value (shift and mean are in the factor's unit)")
    return dist


def measured_distribution(g: Given):
    """``dist = "measured"``: the distribution of measured values
    (:func:`rvtol.inputs.measured.factor.measured_factor`; files relative to the spec file) and the record of the data
    behind it."""
    g.get("dist")
    file = g.table.file
    return measured_factor(g, Path(file).parent if file else Path("."))
