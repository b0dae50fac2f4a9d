"""One reducer in full: its TE curve over one output revolution, the order spectrum and the peak forces.

:func:`chosen_reducer` picks the reducer (nominal, the Monte Carlo sample with the median or largest
Δθ_er, or factor values given); :func:`reducer_curve` runs it (quasi-static, optionally Newmark-β
beside) and returns a :class:`ReducerCurve`: the solvers' TE and forces, the largest orders of the
spectrum with the error families expected there (:mod:`.orders`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ... import units
from ...mc import map_chunks
from ...records import frame_records
from .model import TransmissionErrorModel
from .orders import families_frame

CONFIGURATIONS = ("nominal", "median", "worst", "values")


def chosen_reducer(configuration: str, spec, mc, output: str, values: dict[str, float] | None = None):
    """``(x, how)``: the study's factor row of the reducer ``configuration`` names (base units) and how it
    was chosen; ``output``: the Monte Carlo column of Δθ_er; ``values``: factor -> value (base units)."""
    x = spec.nominal_base()
    if configuration == "values":
        for n, v in (values or {}).items():
            x[spec.index(n)] = v
        return x, "factor values given in the study"
    if configuration == "nominal":
        return x, "every factor at its nominal value"
    y = mc.column(output)
    ok = np.flatnonzero(mc.ok & np.isfinite(y))
    if ok.size == 0:
        return x, "no successful Monte Carlo sample: nominal values instead"
    if configuration == "worst":
        i = ok[np.argmax(y[ok])]
    else:
        i = ok[np.argsort(y[ok])[ok.size // 2]]
    return mc.samples.values[i].copy(), f"Monte Carlo sample {i} ({configuration} Δθ_er)"


@dataclass
class ReducerCurve:
    """``results``: solver -> :class:`.model.TEResult`; ``factors``: the reducer's factor values as shown;
    ``solvers``: TE and peak forces per solver that converged; ``attributed``: the largest orders and their
    families."""

    how: str
    model: TransmissionErrorModel
    stage: str | None
    values: dict[str, float]           # factor -> value (base units)
    factors: pd.DataFrame
    results: dict
    solvers: pd.DataFrame
    top: pd.DataFrame | None = None
    attributed: pd.DataFrame | None = None
    on_rig: pd.DataFrame | None = None          # the orders the study's test rig reads (None: no rig)

    @property
    def good(self) -> dict:
        return {m: r for m, r in self.results.items() if r.ok}

    @property
    def failed(self) -> dict:
        return {m: r for m, r in self.results.items() if not r.ok}

    def to_frame(self) -> pd.DataFrame:
        return self.solvers

    def families(self) -> pd.DataFrame:
        return families_frame(self.model.geometry)

    def plot(self, what: str = "te"):
        """``"te"``: the TE curve(s) over one output revolution; ``"spectrum"``: the order spectrum."""
        from ...plotting import transmission as tp

        good = self.good
        if what == "spectrum":
            return tp.spectrum(next(iter(good.values())))
        return tp.te_curves(good) if len(good) > 1 else tp.te_curve(next(iter(good.values())))

    def summary(self) -> dict:
        good = self.good
        if not good:
            return {}
        out = {"configuration": self.how, "values": dict(self.values),
               "te_pp_arcsec": {m: r.te_pp for m, r in good.items()},
               "top_orders": frame_records(self.top), "order_attribution": frame_records(self.attributed)}
        if self.on_rig is not None:
            out.update(te_pp_rig_arcsec=next(iter(good.values())).te_pp_rig,
                       order_attribution_rig=frame_records(self.on_rig))
        return out


def _solver_row(mode: str, r) -> dict:
    rec = r.to_frame()
    pins = rec[["loaded pins disc 1", "loaded pins disc 2"]]
    return {"solver": mode, "Δθ_er [arcsec]": r.te_pp, "mean Δθ_ca [arcsec]": float(r.te.mean()),
            "max pin force [N]": rec["max pin force [N]"].max(),
            "max cycloid-crank bearing force [N]": rec["max cycloid-crank bearing force [N]"].max(),
            "max crank-carrier bearing force [N]": rec["max crank-carrier bearing force [N]"].max(),
            "loaded pins per disc (min-max)": f"{int(pins.min().min())}–{int(pins.max().max())}"}


def _run(model: TransmissionErrorModel, x):
    return model.run(x)


def reducer_curve(model: TransmissionErrorModel, x, how: str, names, shown_units, stage: str | None = None,
                  newmark: bool = False, evaluate=None, orders=()) -> ReducerCurve:
    """``model`` at its input row ``x`` (base units) over one output revolution; ``names`` and
    ``shown_units``: the factors as the report lists them (``x``'s order); ``newmark``: also the Newmark-β
    solver (``evaluate``: an :class:`rvtol.mc.Evaluator` — the two solvers then run side by side on its
    workers); ``orders``: listed in the order tables whatever their size (:func:`.orders.order_table`)."""
    models = {model.mode: model}
    if newmark and model.mode != "newmark":
        models["newmark"] = model.variant(mode="newmark")
    mapper = evaluate.map if evaluate is not None else map_chunks
    # on the workers even alone: they have run the model in the Monte Carlo (its kernels loaded, the model kept),
    # where this process would first load the compiled kernels (0.2 s, more than the solve)
    res = dict(zip(models, mapper(_run, [(m, x) for m in models.values()], single_inline=False)))
    factors = pd.DataFrame({"factor": names, "value": [float(units.from_base(v, u)) for v, u in zip(x, shown_units)],
                            "unit": [units.label(u) for u in shown_units]})
    rows = [_solver_row(m, r) for m, r in res.items() if r.ok]
    out = ReducerCurve(how, model, stage, dict(zip(names, map(float, x))), factors, res, pd.DataFrame(rows))
    good = out.good
    if good:
        first = next(iter(good.values()))
        out.top = first.top_orders(8)
        out.attributed = model.order_table(first, top=12, min_fraction=0.01, orders=orders)
        if first.te_rig is not None:          # the TE its test rig reads (rvtol/models/transmission_error/rig.py)
            out.on_rig = model.order_table(first, top=12, min_fraction=0.01, rig=True, orders=orders)
    return out
