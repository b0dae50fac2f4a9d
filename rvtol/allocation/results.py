"""Results of an allocation: tolerances, costs, verification, cost-vs-requirement curve."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .. import units
from .problem import AllocationProblem


@dataclass
class AllocationResult:
    """Allocated tolerances ±t (base units) of one method, with their costs."""

    method: str
    problem: AllocationProblem
    t: np.ndarray
    status: str = "optimal"
    feasible: bool = True
    constraint: str = ""
    history: list[float] = field(default_factory=list)  # GA: best feasible cost per generation (nan if none)
    evaluations: int = 0
    notes: list[str] = field(default_factory=list)

    @property
    def total_cost(self) -> float:
        return float(self.problem.cost(self.t)) if self.t is not None else math.nan

    def display_t(self) -> list[float]:
        p = self.problem
        if self.t is None:
            return [math.nan] * len(p.factors)
        return [float(units.from_base(v, p.spec.factor(n).unit)) for n, v in zip(p.factors, self.t)]

    def to_frame(self) -> pd.DataFrame:
        p = self.problem
        fs = [p.spec.factor(n) for n in p.factors]
        return pd.DataFrame({
            "factor": p.factors,
            "group": [f.group for f in fs],
            "unit": [f.unit for f in fs],
            "t_min": [float(units.from_base(v, f.unit)) for v, f in zip(p.lower, fs)],
            "t spec (±)": [float(units.from_base(v, f.unit)) for v, f in zip(p.t0, fs)],
            f"t {self.method} (±)": self.display_t(),
            "t_max": [float(units.from_base(v, f.unit)) for v, f in zip(p.upper, fs)],
            "cost curve": [c.name for c in p.curves],
            "cost": p.costs(self.t) if self.t is not None else math.nan,
        })

    def plot(self, ax=None, baseline: "AllocationResult | None" = None):
        from ..plotting.allocation import tolerance_bars

        return tolerance_bars([r for r in (baseline, self) if r is not None], ax=ax)


def component_axis_table(result: AllocationResult) -> pd.DataFrame | None:
    """Tolerances as a component × axis table when factor names end in x/y/z within a group (doc 002 Table 5)."""
    p = result.problem
    rows: dict[str, dict[str, float]] = {}
    for n, v in zip(p.factors, result.display_t()):
        g = p.spec.factor(n).group or n[:-1]
        if n[-1] not in "xyz":
            return None
        rows.setdefault(g, {})[f"{n[-1]} (±{p.spec.factor(n).unit})"] = v
    df = pd.DataFrame.from_dict(rows, orient="index")
    df.index.name = "component"
    return df.reset_index()


@dataclass
class Verification:
    """An independent Monte Carlo run of the allocated spec: verdict per requirement."""

    method: str
    n: int
    seed: int
    frame: pd.DataFrame  # output, limits, yield and Cpk with the lower bounds the verdict judges, passed

    @property
    def passed(self) -> bool:
        return bool(self.frame["passed"].all())

    def to_frame(self) -> pd.DataFrame:
        return self.frame

    def summary_row(self) -> dict:
        """The worst requirement (lowest Cpk, else lowest yield) and how many pass."""
        f = self.frame
        key = "Cpk" if f["Cpk"].notna().all() else "yield"
        w = f.loc[f[key].astype(float).idxmin()]
        return {"method": self.method, "passed": f"{int(f['passed'].sum())} of {len(f)}", "worst output": w["output"],
                "yield": w["yield"], "yield bound": w["yield_lo"], "Cpk": w["Cpk"], "Cpk bound": w["Cpk_lo"],
                "required": w["required"]}


@dataclass
class ParetoCurve:
    """Minimum cost against the requirement scale (limits × f about the nominal output)."""

    frame: pd.DataFrame  # scale, method columns -> cost
    cost_unit: str = "relative"

    def to_frame(self) -> pd.DataFrame:
        return self.frame

    def plot(self, ax=None):
        from ..plotting.allocation import pareto

        return pareto(self, ax=ax)
