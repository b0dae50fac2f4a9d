"""What a report shows of a measured factor: a summary of its values, the fit ranking, the GoF test, Q-Q data."""
from __future__ import annotations

import math

import numpy as np

from ...precision import shown
from .factor import Measured
from .parametric import gof_test, qq_data


def _band(dist) -> float | None:
    """The band a measured factor's numbers are shown to resolve (:mod:`rvtol.precision`), where it has one."""
    t = getattr(dist, "tolerance", None)          # a distribution without a band: four significant digits
    return float(t) if isinstance(t, (int, float)) and math.isfinite(t) and t > 0 else None


def evidence(m: Measured, dist, *, n_mc: int = 499, seed: int | None = None) -> dict:
    """What a report shows of a measured factor (``dist`` its distribution):

    ``summary`` (one row: source, method, n, mean, s, the gauge share u²/s²), ``ranking`` (the AIC
    table of the fitted families, method fit), ``gof`` (the Anderson–Darling test with parametric
    bootstrap of the family used, ``n_mc`` samples from ``seed``; method fit) and ``qq`` (Q-Q data of
    the values the distribution was built from against it; fit and kde — the empirical distribution
    *is* its data).
    """
    import pandas as pd

    x = m.values
    gauge = (m.measurement_sigma ** 2 / float(np.var(x, ddof=1))) if m.measurement_sigma else 0.0
    out: dict = {"summary": pd.DataFrame([{
        "source": m.source, "method": m.method + (f" ({m.family})" if m.family else ""), "n": m.n,
        "mean": float(np.mean(x)), "s": float(np.std(x, ddof=1)), "min": float(np.min(x)), "max": float(np.max(x)),
        "gauge u²/s²": gauge, "distribution": dist.describe(number=lambda v: shown(v, _band(dist)))}]),
        "ranking": None, "gof": None, "qq": None,
        "file_statistics": pd.DataFrame(m.file_statistics) if m.file_statistics else None}
    if m.fit is not None:
        c = m.fit.candidate(m.family)
        out["ranking"] = m.fit.table()
        out["gof"] = gof_test(m.fit.data, c, m.fit.location, n_mc, seed)
        out["qq"] = qq_data(m.fit.data, c.frozen)
    elif m.method == "kde":
        out["qq"] = qq_data(dist.data, dist)
    return out
