"""Cost–tolerance models: reciprocal power and exponential, fitted to (tolerance, cost) data.

* ``reciprocal_power``: C(t) = a + b / t^c   (doc 002; c = 1 is its "C_i = a_i + b_i / t_i")
* ``exponential``:      C(t) = a + b · exp(−c t)

Both are convex and decreasing in t for a ≥ 0, b > 0, c > 0, which is what
the convex allocation needs.  ``t`` is the tolerance half-band (±t) in the
curve's ``unit``.

File format (``data/costs/*.toml``)::

    [costs]
    name = "bx40e_angular"
    description = "..."
    source = "..."
    cost_unit = "relative"          # a label: cost has no physical unit in rvtol

    [[curve]]
    name = "ground_axis"
    kind = "reciprocal_power"       # or "exponential"
    unit = "mrad"                   # unit of the tolerances (written and in the formula)
    data = { tolerance = [0.5, 1, 2, 4], cost = [9.1, 5.0, 3.1, 2.0] }   # fitted with scipy
    fix_c = 1.0                     # optional: hold the exponent/rate c fixed while fitting
    # or the parameters themselves:  a = 1.0, b = 2.0, c = 1.0
    bounds = [0.5, 6.0]             # optional: t range the curve is valid on (default: the data range)
    source = "..."
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import optimize

from .. import units
from ..errors import InputError
from ..options import REQUIRED, option, read_options
from ..params import Params, read_toml

KINDS = ("reciprocal_power", "exponential")


def basis(kind: str, t: np.ndarray, c: float) -> np.ndarray:
    """The shape g(t; c) in C = a + b·g."""
    t = np.asarray(t, float)
    if kind == "reciprocal_power":
        return t ** (-c)
    if kind == "exponential":
        return np.exp(-c * t)
    raise ValueError(f"unknown cost model kind {kind!r}")


@dataclass(frozen=True)
class FitReport:
    tolerance: tuple[float, ...]
    cost: tuple[float, ...]
    rmse: float
    r2: float
    fixed_c: bool


@dataclass(frozen=True)
class CostModel:
    """``C(t) = a + b·g(t; c)`` with t in ``unit``, valid on ``[t_min, t_max]``."""

    name: str
    kind: str
    a: float
    b: float
    c: float
    unit: str
    t_min: float
    t_max: float
    source: str = ""
    note: str = ""
    fit: FitReport | None = field(default=None, compare=False)

    def __post_init__(self):
        if self.kind not in KINDS:
            raise InputError(f"unknown cost model kind {self.kind!r} (expected one of: {', '.join(KINDS)})",
                             key="kind")

    def __call__(self, t) -> np.ndarray:
        """Cost at tolerance ``t`` (in ``unit``)."""
        return self.a + self.b * basis(self.kind, t, self.c)

    def cost_base(self, t_base) -> np.ndarray:
        """Cost at tolerance ``t_base`` given in base units (rad, mm)."""
        return self(units.from_base(np.asarray(t_base, float), self.unit))

    def expr(self, t):
        """The cvxpy expression of the cost of a cvxpy variable ``t`` (in ``unit``)."""
        import cvxpy as cp

        if self.kind == "reciprocal_power":
            # exact power cone (no rational approximation of the exponent)
            g = cp.inv_pos(t) if self.c == 1.0 else cp.power(t, -self.c, approx=False)
        else:
            g = cp.exp(-self.c * t)
        return self.a + self.b * g

    @property
    def bounds_base(self) -> tuple[float, float]:
        return float(units.to_base(self.t_min, self.unit)), float(units.to_base(self.t_max, self.unit))

    def formula(self) -> str:
        if self.kind == "reciprocal_power":
            return f"{self.a:.4g} + {self.b:.4g}/t^{self.c:.4g}"
        return f"{self.a:.4g} + {self.b:.4g}·exp(−{self.c:.4g}·t)"


def fit_cost_model(kind: str, t, cost, fix_c: float | None = None) -> tuple[float, float, float, FitReport]:
    """Least-squares fit of ``a, b, c`` (a ≥ 0, b > 0, c > 0) to ``(t, cost)`` points.

    For a given c the model is linear in (a, b), so c is found by a bounded
    1-D search over the residual of the linear fit (scipy ``minimize_scalar``
    on log c), then all three are refined together with ``curve_fit``.
    With ``fix_c`` only (a, b) are fitted (linear least squares, non-negative).
    """
    t = np.asarray(t, float)
    y = np.asarray(cost, float)
    if t.shape != y.shape or t.ndim != 1:
        raise InputError("tolerance and cost need the same length", key="data")
    need = 2 if fix_c is not None else 3
    if len(t) < need + 1:
        raise InputError(f"need at least {need + 1} (tolerance, cost) points to fit {need} parameters, "
                         f"got {len(t)}", key="data")
    if np.any(t <= 0) or not np.all(np.isfinite(t)):
        raise InputError("tolerances must be finite and > 0", key="data.tolerance")
    if not np.all(np.isfinite(y)):
        raise InputError("costs must be finite", key="data.cost")
    if len(np.unique(t)) < need:
        raise InputError(f"need at least {need} distinct tolerances", key="data.tolerance")

    def linear(c):
        G = np.column_stack([np.ones_like(t), basis(kind, t, c)])
        (a, b), rnorm = optimize.nnls(G, y)
        return a, b, rnorm

    if fix_c is not None:
        c = float(fix_c)
        a, b, _ = linear(c)
    else:
        scale = 1.0 / float(np.median(t)) if kind == "exponential" else 1.0
        res = optimize.minimize_scalar(lambda lc: linear(scale * math.exp(lc))[2], bounds=(-6.0, 4.0),
                                       method="bounded", options={"xatol": 1e-10})
        c = scale * math.exp(res.x)
        a, b, _ = linear(c)
        model = lambda tt, aa, bb, cc: aa + bb * basis(kind, tt, cc)  # noqa: E731
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", optimize.OptimizeWarning)
                p, _ = optimize.curve_fit(model, t, y, p0=[a, max(b, 1e-12), c],
                                          bounds=([0.0, 0.0, 1e-9], [np.inf, np.inf, np.inf]), maxfev=20000)
            if np.sum((model(t, *p) - y) ** 2) <= np.sum((model(t, a, b, c) - y) ** 2):
                a, b, c = (float(v) for v in p)
        except (RuntimeError, ValueError):
            pass  # keep the 1-D search result
    if not b > 0:
        raise InputError("the fitted cost does not fall with the tolerance (b = 0): the data do not fit "
                         f"a {kind} model", key="data")
    pred = a + b * basis(kind, t, c)
    ss_res = float(np.sum((pred - y) ** 2))
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    rep = FitReport(tuple(t), tuple(y), math.sqrt(ss_res / len(t)), 1.0 - ss_res / ss_tot if ss_tot > 0 else 1.0,
                    fix_c is not None)
    return float(a), float(b), float(c), rep


# --------------------------------------------------------------------------- loading
@dataclass(frozen=True)
class CostTable:
    name: str
    curves: dict[str, CostModel]
    cost_unit: str = "relative"
    description: str = ""
    source: str = ""
    file: str | None = None

    def __getitem__(self, name: str) -> CostModel:
        if name not in self.curves:
            raise InputError(f"unknown cost curve {name!r} (known: {', '.join(self.curves)})", file=self.file,
                             key="curve")
        return self.curves[name]


def load_costs(path: str | Path) -> CostTable:
    data, _ = read_toml(path)
    return costs_from_table(data, file=str(path))


@dataclass
class CostsHead:
    """``[costs]``: a cost file's name and where its curves come from."""

    name: str | None = option(None, "the table's name (default: the file's name)")
    description: str = option("", "what the costs are")
    source: str = option("", "where they come from")
    cost_unit: str = option("relative", "a label for the cost (rvtol gives cost no physical unit)")


@dataclass
class CostData:
    """``data``: (tolerance, cost) pairs a curve is fitted to."""

    tolerance: list[float] = option(REQUIRED, "the tolerances (±t, the curve's unit)", min_length=1, positive=True)
    cost: list[float] = option(REQUIRED, "the cost of each tolerance", min_length=1, positive=True)


@dataclass
class CurveTable:
    """``[[curve]]``: one cost–tolerance curve, fitted to data or given by its parameters a, b, c."""

    name: str = option(REQUIRED, "the curve's name, as an allocation names it")
    kind: str = option(REQUIRED, "C(t) = a + b / t^c, or a + b · exp(−c t)", choices=KINDS)
    unit: str = option(REQUIRED, "the unit of the tolerances (written and in the formula)")
    source: str = option("", "where the curve comes from")
    note: str = option("", "a remark for the report")
    data: CostData | None = option(None, "{ tolerance = [...], cost = [...] } to fit the curve to (scipy), instead "
                                         "of a, b, c")
    fix_c: float | None = option(None, "with data: c held at this value while fitting", positive=True)
    a: float | None = option(None, "the fixed cost (without data)", nonnegative=True)
    b: float | None = option(None, "the scale (without data)", positive=True)
    c: float | None = option(None, "the exponent or rate (without data)", positive=True)
    bounds: list[float] | None = option(None, "[low, high]: the t range the curve holds on (default: the data's)",
                                        positive=True)

    def complete(self, study, error):
        given = [k for k in ("a", "b", "c") if getattr(self, k) is not None]
        if self.data is not None and given:
            raise error("data", "give either data (to fit) or the parameters a, b, c, not both")
        if self.data is None:
            for k in ("a", "b", "c"):
                if getattr(self, k) is None:
                    raise error(k, "missing required key")
            if self.fix_c is not None:
                raise error("fix_c", "holds c while fitting data: give data, or c itself")
            if self.bounds is None:
                raise error("bounds", "missing required key")
        if self.bounds is not None and len(self.bounds) != 2:
            raise error("bounds", f"expected 2 numbers [low, high], got {len(self.bounds)}")


def costs_from_table(data: dict, *, file: str | None = None) -> CostTable:
    root = Params(data, file=file)
    head = root.sub("costs")
    h = read_options(CostsHead, head)
    head.finish()
    name = h.name if h.name is not None else (Path(file).stem if file else "costs")
    curves: dict[str, CostModel] = {}
    for t in root.tables("curve"):
        cm = curve_from_params(t)
        if cm.name in curves:
            raise t.error("name", f"duplicate curve name {cm.name!r}")
        curves[cm.name] = cm
    if not curves:
        raise root.error("curve", "a cost file needs at least one [[curve]]")
    root.finish()
    return CostTable(name, curves, h.cost_unit, h.description, h.source, file)


def curve_from_params(t: Params) -> CostModel:
    o = read_options(CurveTable, t)
    t.finish()
    unit = t.canonical_unit("unit", o.unit)
    fit = None
    if o.data is not None:
        ts, cs = o.data.tolerance, o.data.cost
        if len(ts) != len(cs):
            raise t.error("data.cost", f"expected {len(ts)} costs (one per tolerance), got {len(cs)}")
        try:
            a, b, c, fit = fit_cost_model(o.kind, ts, cs, o.fix_c)
        except InputError as exc:
            raise t.error("data", exc.reason) from None
        lo, hi = (min(ts), max(ts)) if o.bounds is None else o.bounds
    else:
        a, b, c = o.a, o.b, o.c
        lo, hi = o.bounds
    if not lo < hi:
        raise t.error("bounds", f"expected [low, high] with low < high, got [{lo}, {hi}]")
    name, kind, source, note = o.name, o.kind, o.source, o.note
    return CostModel(name, kind, a, b, c, unit, lo, hi, source, note, fit)
