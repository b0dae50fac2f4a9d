"""The linearised chain beside the Monte Carlo: worst case, RSS and loop signs of each KC output.

:func:`linear_stackup` linearises the chain analytically at the nominal point (small-displacement torsors
carried through the assembly program, :mod:`.linearise`) and returns a :class:`LinearStackup`: per
output the worst-case and RSS figures of its form (signed component, norm of a pair, weighted
magnitude, margin), the Monte Carlo's beside them, and the contributors with their loop-method signs.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ...errors import InputError
from ...records import frame_records
from ...stats import percentile_ci
from ...units import label
from .linearise import COVERAGE, Factors, OutputLinearisation, linearise_output
from .model import StackupModel

#: what the WC / RSS / MC columns hold, per kind of output
BASIS = {
    "dof": "signed: WC = arithmetic worst case; RSS = mean ± 3σ; MC = P0.135 / P99.865",
    "norm": "magnitude: WC high = max over the tolerance box; RSS high = P99.73 of the linearised pair's norm; "
            "MC high = P99.73",
    "weighted": "‖e‖/‖ε‖: WC high = upper bound; RSS high = rms; MC high = rms",
    "none": "margin: Monte Carlo only (MC low = P0.27, MC high = P99.73)",
}
COLUMNS = ["output", "unit", "kind", "WC low", "WC high", "RSS mean", "RSS σ", "RSS low", "RSS high", "MC mean", "MC σ",
           "MC low", "MC high", "MC max"]


def check_linearisable(model: StackupModel) -> None:
    """Raise :class:`InputError` if a fit of ``model`` floats in a worst-case mode (not differentiable)."""
    worst = model.nonlinear_floats()
    if worst:
        raise InputError(f"fit {worst[0]!r} floats in a worst-case mode, which is not differentiable in its "
                         "direction; linearise a model with uniform (or centred) floats")


def mc_figures(mc, name: str, form: str) -> dict:
    """The Monte Carlo figures of output ``name`` that match the linearised ones of its ``form``."""
    y = mc.column(name)
    y = np.sort(y[np.isfinite(y)])
    if len(y) == 0:
        return {}
    out = {"MC mean": float(y.mean()), "MC σ": float(y.std(ddof=1)) if len(y) > 1 else float("nan")}
    if form == "dof":
        out["MC low"] = percentile_ci(y, 0.00135)[0]
        out["MC high"] = percentile_ci(y, 0.99865)[0]
    elif form == "weighted":
        out["MC high"] = float(np.sqrt(np.mean(y**2)))
    else:
        if form == "none":
            out["MC low"] = percentile_ci(y, 1 - COVERAGE)[0]
        out["MC high"] = percentile_ci(y, COVERAGE)[0]
    out["MC min"], out["MC max"] = float(y[0]), float(y[-1])
    return out


@dataclass
class OutputFigures:
    """One output: its linearisation, the Monte Carlo figures and its largest contributors (``top``)."""

    name: str
    linear: OutputLinearisation
    mc: dict
    top: pd.DataFrame | None = None

    def plot(self, top: int = 12):
        from ...plotting.stackup import contribution_bars

        return contribution_bars(self.linear, top=top)

    def summary(self) -> dict:
        lin = self.linear
        out = {"form": lin.form, "linear": lin.figures, "monte_carlo": self.mc, "notes": lin.notes}
        if not lin.contributions.empty:
            out["contributions"] = frame_records(lin.contributions)
        return out


@dataclass
class LinearStackup:
    outputs: list[OutputFigures]
    top: int
    figures: list[str] = field(default_factory=list)     # outputs that get a contribution chart

    def to_frame(self) -> pd.DataFrame:
        """One row per output: worst case, RSS and Monte Carlo figures (display units)."""
        rows = [{"output": o.name, "unit": label(o.linear.unit), "kind": o.linear.form, **o.linear.figures, **o.mc}
                for o in self.outputs]
        return pd.DataFrame(rows).reindex(columns=COLUMNS)

    def summary(self) -> dict:
        return {"outputs": {o.name: o.summary() for o in self.outputs}}

    def plot(self, output: str | None = None):
        """The contribution chart of ``output`` (default: the first the study charts, else the first output) with
        its ``top`` contributors — the report's figure."""
        name = output or (self.figures[0] if self.figures else self.outputs[0].name)
        for o in self.outputs:
            if o.name == name:
                return o.plot(self.top)
        raise ValueError(f"no output {name!r} (outputs: {', '.join(o.name for o in self.outputs)})")


def linear_stackup(model: StackupModel, spec, mc, outputs, top: int = 12, figures=()) -> LinearStackup:
    """Worst case and RSS of the linearised chain of each of ``outputs`` beside the Monte Carlo ``mc``;
    ``top`` contributors per output; ``figures``: the outputs whose contributions are charted."""
    fx = Factors.of(spec)
    J = model.jacobian(fx.x0)
    E0 = model.kc_deviations(fx.x0[None])[0]
    out = []
    for name in outputs:
        lin = linearise_output(model, spec, name, J, fx, E0)
        o = OutputFigures(name, lin, mc_figures(mc, name, lin.form))
        if not lin.contributions.empty:
            o.top = lin.contributions.sort_values("variance share %", ascending=False).head(top)
        out.append(o)
    return LinearStackup(out, top, list(figures))
