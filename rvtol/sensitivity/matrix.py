"""The sensitivity matrix: drawing tolerance × output, five-point variance shares and Sobol total indices.

A drawing tolerance is a factor, or the factors that stand for one callout (the end-point
coordinates of a position zone, the copies of a per-pin family): :func:`rvtol.callouts.callout_of`.
Five-point: each factor's linearised variance contribution ``(S_i σ_i)²`` as a share of the output's
linearised variance (correlation ignored), summed per tolerance.  Sobol: ``top`` tolerances, taken from
every output in turn (:func:`top_tolerances`), are groups of their own, every other factor is one group
("all other tolerances"), so n·(top + 3) model runs give a total index per tolerance that includes its
interactions — the two maps side by side show where the linearisation misses.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import pandas as pd

from ..callouts import callout_of
from ..mc import Evaluator
from ..model import Model
from ..spec import ToleranceSpec
from . import global_ as gs
from .drivers import first_order_drivers
from .local import five_point

#: the Sobol group of every tolerance that is not among the top ones
REST = "all other tolerances"


@dataclass
class SensitivityMatrixResult:
    """``share``: five-point variance share (tolerance × output, every tolerance); ``total`` / ``total_conf``:
    Sobol total index and its half-width (the top tolerances and the rest); ``shown``: the tolerances the
    share map shows (the largest first)."""

    outputs: list[str]
    percent: float
    n: int
    confidence: float
    share: pd.DataFrame
    total: pd.DataFrame
    total_conf: pd.DataFrame
    shown: list[str]
    top: list[str]
    ranked_by_mc: list[str]            # outputs whose top tolerances came from the Monte Carlo (no linear share)
    n_five_point: int
    n_sobol: int
    notes: list[str] = field(default_factory=list)

    def to_frame(self) -> pd.DataFrame:
        """One row per (tolerance, output): share, ST and its half-width."""
        rows = []
        for t in self.share.index:
            for o in self.outputs:
                st = self.total.loc[t, o] if t in self.total.index else np.nan
                conf = self.total_conf.loc[t, o] if t in self.total_conf.index else np.nan
                rows.append({"tolerance": t, "output": o, "share": self.share.loc[t, o], "ST": st, "ST_conf": conf})
        return pd.DataFrame(rows)

    def total_table(self) -> pd.DataFrame:
        """The Sobol totals as ``ST ± half-width`` text, one row per tolerance."""
        table = self.total.copy()
        for o in self.outputs:
            table[o] = [f"{v:.2f} ± {c:.2f}" if np.isfinite(v) else "—"
                        for v, c in zip(self.total[o], self.total_conf[o])]
        return table.reset_index(names="drawing tolerance")

    def plot(self, which: str = "share"):
        from ..plotting.sensitivity import heatmap

        if which == "share":
            return heatmap(self.share.loc[self.shown], "Five-point linearised share of variance", "share", "{:.2f}",
                           vmax=1.0)
        return heatmap(self.total, f"Sobol total index (n = {self.n})", "ST", "{:.2f}", vmax=1.0)

    def summary(self) -> dict:
        return {"outputs": self.outputs, "percent": self.percent, "n_sobol": self.n,
                "five_point_share": {t: {o: _num(self.share.loc[t, o]) for o in self.outputs}
                                     for t in self.share.index},
                "sobol_total": {t: {o: {"ST": _num(self.total.loc[t, o]), "conf": _num(self.total_conf.loc[t, o])}
                                    for o in self.outputs} for t in self.total.index},
                "model_runs": {"five_point": self.n_five_point, "sobol": self.n_sobol}}


def sensitivity_matrix(model: Model, spec: ToleranceSpec, outputs: Sequence[str], factors: Sequence[str] | None = None,
                       percent: float = 10.0, top: int = 10, n: int = 64, seed: int | None = None,
                       num_resamples: int = 100, confidence: float = 0.95, evaluate: Evaluator | None = None,
                       mc=None) -> SensitivityMatrixResult:
    """Five-point shares of every drawing tolerance and Sobol totals of the ``top`` ones, for ``outputs``.

    ``mc`` (the study's Monte Carlo result) ranks the tolerances of an output the linearisation cannot
    see (a magnitude whose derivative vanishes at the nominal) by their first-order index.
    """
    outputs = list(outputs)
    idx = [spec.index(f) for f in factors] if factors else list(range(len(spec)))
    names = [spec.names[i] for i in idx]
    tol = {spec.names[i]: callout_of(spec.factors[i]) for i in idx}
    order = list(dict.fromkeys(tol[n_] for n_ in names))
    fp = five_point(model, spec, names, outputs, percent, None, evaluate)
    sd = spec.std_base()[idx]
    pos = {t: r for r, t in enumerate(order)}
    row = np.array([pos[tol[n_]] for n_ in names])
    shares = np.zeros((len(order), len(outputs)))
    for k, o in enumerate(outputs):
        c = (np.asarray(fp.gradient(o, names), dtype=float) * sd) ** 2
        total = np.nansum(c)
        v = c / total if total > 0 else np.full_like(c, np.nan)
        np.add.at(shares[:, k], row, np.where(np.isfinite(c), v, np.nan))   # in the factors' order; NaN stays NaN
    share = pd.DataFrame(shares, index=order, columns=outputs)
    rank = share.max(axis=1, skipna=True).sort_values(ascending=False)
    chosen, by_mc = top_tolerances(share, outputs, order, top, mc, model, spec, seed)
    groups = [tol[n_] if tol[n_] in chosen else REST for n_ in names]
    res = gs.sobol(model, spec, n, names, outputs, second_order=False, seed=seed, num_resamples=num_resamples,
                   confidence=confidence, evaluate=evaluate, groups=groups)
    rows = chosen + ([REST] if REST in groups else [])
    st = pd.DataFrame(np.nan, index=rows, columns=outputs)
    conf = st.copy()
    for _, r in res.frame.iterrows():
        st.loc[r["factor"], r["output"]] = r["ST"]
        conf.loc[r["factor"], r["output"]] = r["ST_conf"]
    shown = list(rank.index[:max(top, 20)])
    return SensitivityMatrixResult(outputs, percent, n, confidence, share, st, conf, shown, chosen, by_mc,
                                   4 * len(names) + 1, res.n_evaluations, fp.notes + res.notes)


def top_tolerances(share: pd.DataFrame, outputs: Sequence[str], order: Sequence[str], top: int, mc, model, spec,
                   seed) -> tuple[list[str], list[str]]:
    """``top`` drawing tolerances taken from every output in turn (its first, then its second, ...): by
    five-point share, or — where the share is undefined (a magnitude with zero derivative at the
    nominal) — by the first-order index the Monte Carlo samples give (:func:`rvtol.sensitivity.drivers.first_order_drivers`).
    Returns the tolerances and the outputs ranked from the Monte Carlo."""
    ranking, by_mc = {}, []
    for o in outputs:
        col = share[o].dropna()
        if len(col) and col.max() > 0:
            ranking[o] = [t for t in col.sort_values(ascending=False).index if col[t] > 0]
        else:
            by_mc.append(o)
    if by_mc and mc is not None:
        drivers = first_order_drivers(mc, model, spec, by_mc, seed)
        for o in by_mc:
            ranking[o] = [d.tolerance for d in drivers.get(o, []) if d.tolerance in order and d.s1 > 0]
    chosen, level = [], 0
    while len(chosen) < top and any(level < len(r) for r in ranking.values()):
        for o in outputs:
            r = ranking.get(o, [])
            if level < len(r) and r[level] not in chosen and len(chosen) < top:
                chosen.append(r[level])
        level += 1
    return chosen, [o for o in by_mc if ranking.get(o)]


def _num(v):
    v = float(v)
    return v if math.isfinite(v) else None
