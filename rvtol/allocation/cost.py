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


def costs_from_table(data: dict, *, file: str | None = None) -> CostTable:
    root = Params(data, file=file)
    head = root.sub("costs")
    name = head.str("name", Path(file).stem if file else "costs")
    desc = head.str("description", "")
    source = head.str("source", "")
    cost_unit = head.str("cost_unit", "relative")
    head.finish()
    curves: dict[str, CostModel] = {}
    for t in root.tables("curve"):
        cm = curve_from_params(t)
        if cm.name in curves:
            raise t.error("name", f"duplicate curve name {cm.name!r}")
        curves[cm.name] = cm
    if not curves:
        raise root.error("curve", "a cost file needs at least one [[curve]]")
    root.finish()
    return CostTable(name, curves, cost_unit, desc, source, file)


def curve_from_params(t: Params) -> CostModel:
    name = t.str("name")
    kind = t.str("kind", choices=KINDS)
    unit = t.unit("unit")
    source = t.str("source", "")
    note = t.str("note", "")
    fit = None
    if "data" in t:
        if any(k in t for k in ("a", "b", "c")):
            raise t.error("data", "give either data (to fit) or the parameters a, b, c, not both")
        d = t.sub("data")
        ts = d.floats("tolerance", min_length=1, positive=True)
        cs = d.floats("cost", min_length=1, positive=True)
        d.finish()
        if len(ts) != len(cs):
            raise d.error("cost", f"expected {len(ts)} costs (one per tolerance), got {len(cs)}")
        fix_c = t.float("fix_c", None, positive=True)
        try:
            a, b, c, fit = fit_cost_model(kind, ts, cs, fix_c)
        except InputError as exc:
            raise t.error("data", exc.reason) from None
        lo_default, hi_default = min(ts), max(ts)
    else:
        a = t.float("a", nonnegative=True)
        b = t.float("b", positive=True)
        c = t.float("c", positive=True)
        lo_default = hi_default = None
    if "bounds" in t or lo_default is None:
        lo, hi = t.floats("bounds", length=2, positive=True)
    else:
        lo, hi = lo_default, hi_default
    if not lo < hi:
        raise t.error("bounds", f"expected [low, high] with low < high, got [{lo}, {hi}]")
    t.finish()
    return CostModel(name, kind, a, b, c, unit, lo, hi, source, note, fit)
