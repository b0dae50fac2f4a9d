"""The screening estimate (doc 001's formula) beside the maker's lost motion on the 20-DOF torsion curve.

:func:`screening_plan` settles, when the study loads, where both sides come from (:class:`ScreeningPlan`):
the study's model may be the lost-motion model (the torsion curve is evaluated on a subsample,
sub-stream ``screening_subsample``), the torsion-curve model (its Monte Carlo outputs are the maker's
figures; the screening estimate is computed for every sample), a composed study with a torsion-curve
and a lost-motion stage (both stages' Monte Carlo results on every sample, the screening in both modes
on the screening stage's mapped inputs) or any model with ``screening_inputs(X)`` (:mod:`.bridge`, which
also gives the factor bridge between the two vocabularies).

:func:`screening_comparison` evaluates both on the same reducers and returns a
:class:`ScreeningComparison`: per reducer the two screening modes, the torsion curve's backlash and
lost motion (the involute-stage play added in series), their statistics, the per-factor rates (document,
consistent, 20-DOF finite differences) and the reducers at quantiles of the screening estimate.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ... import units
from ...errors import InputError
from ...records import frame_records
from ...units import convert
from ..lost_motion.model import FACTORS, LostMotionGeometry
from ..torsion_curve.model import TorsionCurveModel
from ..reducer_20dof.geometry import geometry_from_design
from .bridge import ScreeningInputs, backlash_rates, screening_inputs, screening_models

SOURCES = ("lost_motion", "torsion_curve", "composed", "own")
#: what the per-reducer columns hold (``percent``: the torque band of the maker's lost motion)
LABELS = {
    "document": "doc 001 as printed (document mode)",
    "consistent": "screening estimate: doc 001, consistent mode",
    "backlash": "torsion curve: backlash at zero torque",
    "lost_motion": "torsion curve: lost motion ±{p:g} % rated (maker's definition)",
    "elastic": "lost motion − backlash: elastic part within ±{p:g} % (and play taken up only under load)",
    "involute": "involute-stage play at the output (Δφ12/i, in series)",
    "gap": "torsion-curve lost motion − screening estimate",
}
#: the 20-DOF factor a doc-001 factor's rate is measured with
RATE_FACTOR = {"Delta_b": "δ_b = Δ/2, all six bearings", "Delta_r_c": "delta_pin (every pin)",
               "Delta_r_p": "R_pin[k] (every pin)"}
BILATERAL = "— (bilateral mesh: played in series, ÷ i)"


@dataclass(frozen=True)
class ScreeningPlan:
    """Where the comparison's two sides come from (settled when the study loads).

    ``tc`` / ``lm``: the torsion-curve and lost-motion stages of a composed study
    (:class:`rvtol.analysis.ModelTarget`), None otherwise; ``g20``: the 20-DOF geometry of the torsion
    curve; ``limit``: arcmin (None: no limit to count against)."""

    source: str
    g20: object
    lm_geometry: LostMotionGeometry
    percent: float
    samples: int
    limit: float | None
    tc: object = None
    lm: object = None


def screening_plan(study, design20, source: str, tc=None, lm=None, *, design_given: bool, percent: float | None,
                   samples: int, limit: float | None) -> ScreeningPlan:
    """The plan for ``study`` (``source`` one of :data:`SOURCES`; ``design20``: the 20-DOF design of the
    torsion curve; ``limit`` in base units or None: the study's requirement on the lost motion, else the
    design's ``reducer.lost_motion_limit``).  Raises :class:`InputError` with the key to blame."""
    m = study.model
    g20 = tc.model.geometry if source == "composed" and not design_given else geometry_from_design(design20)
    if source == "lost_motion":
        lm_geometry = m.geometry
    elif source == "composed":
        lm_geometry = lm.model.geometry
    else:
        d = study.design if study.design is not None else design20
        try:
            lm_geometry = LostMotionGeometry.from_design(d, "document")
        except (InputError, KeyError):
            lm_geometry = LostMotionGeometry.from_design(d, "consistent")
    same = (lm_geometry.cycloid_teeth == g20.z_c and math.isclose(lm_geometry.eccentricity, g20.ecc, rel_tol=1e-9)
            and math.isclose(lm_geometry.ratio, g20.ratio, rel_tol=1e-9)
            and math.isclose(lm_geometry.K1, g20.K1, rel_tol=1e-9))
    if not same:
        raise InputError("the torsion curve's design is not the reducer of the screening estimate (cycloid teeth, "
                         "eccentricity, ratio or K1 differ)", key="design")
    if source in ("torsion_curve", "composed"):
        tcm = tc.model if source == "composed" else m
        if percent is None:
            percent = tcm.percent
        elif percent != tcm.percent:
            raise InputError(f"the study's torsion-curve model reads lost motion at ±{tcm.percent:g} % (its Monte "
                             "Carlo outputs are used): give the same percent", key="percent")
    elif percent is None:
        percent = 3.0
    if limit is None:
        out = tc.output("lost_motion") if source == "composed" else "lost_motion"
        req = [r for r in study.requirements if r.output == out and r.upper is not None and r.per_unit]
        if req:
            q = next(q for q in m.outputs if q.name == out)
            limit = float(units.to_base(req[0].upper, req[0].unit or q.shown_unit))
        elif "reducer.lost_motion_limit" in design20:
            limit = float(design20["reducer.lost_motion_limit"])
    limit = None if limit is None else float(units.from_base(limit, "arcmin"))
    return ScreeningPlan(source, g20, lm_geometry, percent, samples, limit, tc, lm)


@dataclass
class ScreeningComparison:
    """``frame``: per reducer (arcmin) the columns of :data:`LABELS`; ``statistics``, ``rates`` and
    ``quantiles``: the report's tables; ``failed``: reducers that could not be evaluated."""

    frame: pd.DataFrame
    statistics: pd.DataFrame
    rates: pd.DataFrame
    quantiles: pd.DataFrame
    percent: float
    limit: float | None
    source: str
    n_drawn: int
    failed: int
    n_evaluated: int
    unseen_by_tc: tuple[str, ...] = ()
    unseen_by_lm: tuple[str, ...] = ()
    stages: tuple[str | None, str | None] = (None, None)     # torsion-curve and lost-motion stage (composed)
    labels: dict = field(default_factory=dict)

    def to_frame(self) -> pd.DataFrame:
        return self.frame

    @property
    def means(self) -> pd.Series:
        return self.frame.mean()

    def plot(self):
        """Per reducer: the screening estimate against the torsion-curve lost motion."""
        from ...plotting.lost_motion import screening_scatter

        return screening_scatter(self.frame["consistent"].to_numpy(), self.frame["lost_motion"].to_numpy(),
                                 self.limit, self.percent)

    def summary(self) -> dict:
        m = self.means
        return {"n": int(len(self.frame)), "failed": self.failed, "percent": self.percent,
                "limit_arcmin": self.limit, "mean_arcmin": {c: float(m[c]) for c in self.labels},
                "statistics": frame_records(self.statistics), "rates": frame_records(self.rates),
                "quantiles": frame_records(self.quantiles),
                "unseen_by_torsion_curve": list(self.unseen_by_tc), "unseen_by_screening": list(self.unseen_by_lm)}


def _composed_inputs(plan: ScreeningPlan, model, spec, mc, rows) -> ScreeningInputs:
    """Both stages' vocabularies in a composed study: the screening stage's mapped inputs of every row;
    the drawing tolerances one stage depends on and the other does not (by part)."""
    lm = plan.lm.model
    X_lm = plan.lm.inputs(mc.samples.values[rows])
    deps = model.depends_on()
    d_tc, d_lm = deps.get(plan.tc.output("lost_motion"), set()), deps.get(plan.lm.output("lost_motion"), set())

    def by_part(names):
        parts = {}
        for n in names:
            g = spec.factor(n).group or n
            parts[g] = parts.get(g, 0) + 1
        return tuple(f"{g} ({k} factor{'s' if k > 1 else ''})" for g, k in sorted(parts.items()))

    return ScreeningInputs(lm.inputs, X_lm, plan.tc.model.inputs, None, by_part(d_lm - d_tc),
                           by_part(d_tc - d_lm), dict(lm.extra), dict(lm.extra_like))


def _rows(plan: ScreeningPlan, mc, seed) -> np.ndarray:
    from ...sampling import substream

    n = mc.n
    if plan.source in ("torsion_curve", "composed") or plan.samples >= n:
        return np.arange(n)
    return np.sort(substream(seed, "screening_subsample").choice(n, plan.samples, replace=False))


def _statistics(d: pd.DataFrame, labels: dict, limit: float | None, confidence: float) -> pd.DataFrame:
    from ...stats import proportion_ci

    rows = []
    for c, label in labels.items():
        y = np.sort(d[c].to_numpy())
        row = {"quantity": label, "mean [′]": y.mean(), "σ [′]": y.std(ddof=1) if len(y) > 1 else math.nan,
               "P50 [′]": np.quantile(y, 0.5), "P99 [′]": np.quantile(y, 0.99), "max [′]": y[-1]}
        if limit is not None and c in ("document", "consistent", "backlash", "lost_motion"):
            k = int((y > limit).sum())
            lo, hi = proportion_ci(k, len(y), confidence)
            row[f"share > {limit:g}′ [{confidence:.0%} CI]"] = f"{k / len(y):.4f} [{lo:.4f}, {hi:.4f}]"
        rows.append(row)
    return pd.DataFrame(rows)


def _rates(plan: ScreeningPlan, models, inputs: ScreeningInputs, evaluate) -> pd.DataFrame:
    """Per factor, the rates at the output: document, consistent mode and the 20-DOF torsion curve."""
    per_um = lambda v: float(convert(v, "rad/mm", "arcmin/um"))  # noqa: E731
    p = plan.percent
    rates = backlash_rates(plan.g20, percent=p, evaluate=lambda mdl, X: (lambda r: (r.Y, r.status))(
        evaluate(mdl, X, "20-DOF backlash rates")))
    cd = models["document"].geometry.output_coefficients(models["document"].extra)
    cc = models["consistent"].geometry.output_coefficients(models["consistent"].extra)
    rows = []
    for f in [n for n in (*FACTORS, *inputs.extra) if n in cd]:
        like = f if f in rates else inputs.extra_like.get(f)
        r20 = rates.get(like) if like else None
        rows.append({
            "factor": f, "document [′/µm]": per_um(cd[f]), "consistent [′/µm]": per_um(cc[f]),
            "20-DOF backlash [′/µm]": per_um(r20["backlash"]) if r20 else math.nan,
            f"20-DOF lost motion ±{p:g} % [′/µm]": per_um(r20["lost_motion"]) if r20 else math.nan,
            "document / 20-DOF": cd[f] / r20["backlash"] if r20 else math.nan,
            "consistent / 20-DOF": cc[f] / r20["backlash"] if r20 else math.nan,
            "20-DOF factor": RATE_FACTOR.get(like, BILATERAL if f in ("E_w", "Delta_a", "Delta_F_r") else "—"),
        })
    return pd.DataFrame(rows)


def _quantiles(d: pd.DataFrame, p: float) -> pd.DataFrame:
    """The reducers at quantiles of the screening estimate."""
    rows = []
    order = d.sort_values("consistent")
    for q in (0.5, 0.9, 0.99, 1.0):
        r = order.iloc[min(len(order) - 1, int(round(q * (len(order) - 1))))]
        rows.append({"screening quantile": f"P{100 * q:g}" if q < 1 else "max",
                     "document [′]": r["document"], "consistent [′]": r["consistent"],
                     "torsion-curve backlash [′]": r["backlash"],
                     f"torsion-curve lost motion ±{p:g} % [′]": r["lost_motion"],
                     "elastic part [′]": r["elastic"]})
    return pd.DataFrame(rows)


def screening_comparison(plan: ScreeningPlan, model, spec, mc, seed, evaluate) -> ScreeningComparison:
    """Both sides on the same reducers of the study's Monte Carlo ``mc`` (``evaluate``: the study's
    evaluator, ``seed``: its seed — the subsample's sub-stream)."""
    amin = lambda v: np.asarray(units.from_base(v, "arcmin"), dtype=float)  # noqa: E731
    rows = _rows(plan, mc, seed)
    if plan.source == "composed":
        inputs = _composed_inputs(plan, model, spec, mc, rows)
    else:
        inputs = screening_inputs(model, mc.samples.values[rows], plan.g20.z_b)
    if plan.source in ("torsion_curve", "composed"):
        out = plan.tc.output if plan.source == "composed" else str
        ok = mc.ok[rows]
        tc_lm, tc_bl = mc.column(out("lost_motion"))[rows], mc.column(out("backlash"))[rows]   # arcmin
    else:
        tcm = TorsionCurveModel(plan.g20, inputs.tc_names, percent=plan.percent)
        e = evaluate(tcm, inputs.X_tc, "torsion curves (screening)")
        ok = e.ok
        tc_lm, tc_bl = amin(e.Y[:, 0]), amin(e.Y[:, 2])
    models = screening_models(plan.lm_geometry, inputs)
    doc = evaluate(models["document"], inputs.X_lm, "screening (document)")
    con = evaluate(models["consistent"], inputs.X_lm, "screening (consistent)")
    ok = ok & doc.ok & con.ok
    inv = amin(con.Y[:, 1]) / models["consistent"].geometry.ratio   # involute play at the output, in series
    d = pd.DataFrame({"document": amin(doc.Y[:, 0]), "consistent": amin(con.Y[:, 0]), "involute": inv,
                      "backlash": tc_bl + inv, "lost_motion": tc_lm + inv, "elastic": tc_lm - tc_bl})[ok]
    d["gap"] = d["lost_motion"] - d["consistent"]
    labels = {c: lab.format(p=plan.percent) for c, lab in LABELS.items()}
    stages = (plan.tc.stage, plan.lm.stage) if plan.source == "composed" else (None, None)
    return ScreeningComparison(d, _statistics(d, labels, plan.limit, mc.confidence),
                               _rates(plan, models, inputs, evaluate), _quantiles(d, plan.percent),
                               plan.percent, plan.limit, plan.source, len(rows), int((~ok).sum()), len(ok),
                               tuple(inputs.unseen_by_tc), tuple(inputs.unseen_by_lm), stages, labels)
