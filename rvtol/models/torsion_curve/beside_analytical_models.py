"""The 20-DOF torsion curve beside rvtol's analytical models: curves, clearance sweeps, rigidity, compliance.

:func:`torsion_curve_study` — what ``[[analysis]] kind = "torsion_curve"`` shows, a
:class:`TorsionCurveStudy` of three results:

* :class:`SimulatedCurves` (:func:`simulated_curves`) — the curve of the clearance-free reducer (and at
  the spec's mean errors) with the maker's figures;
* :class:`ClearanceSweep` (:func:`clearance_sweep`) — lost motion and backlash against the
  crank-bearing and pin clearances beside the lost-motion model (:mod:`rvtol.models.lost_motion.model`,
  doc 001's formula) in both its modes;
* :class:`RigidityComparison` (:func:`rigidity_comparison`) — the 20-DOF angle at rated torque split by
  virtual work, beside the elastic torsion-angle model (:mod:`rvtol.models.stiffness`).

:func:`compliance_comparison` — ``kind = "compliance_breakdown"``, a :class:`ComplianceComparison`:
the output angle per compliance family, the 20-DOF model with the design's compliance chain, with
doc 000's rigid chain and the torsion-angle model side by side.

**Analytical rates.**  Doc 001's formula in its two modes (:mod:`rvtol.models.lost_motion.model`): as
printed (``Δφ_b = Δ/(K r)`` with ``K ≈ 1.5``, ``Δφ34 = Δr_c/(a z_c)``, no disc-to-output ratio) and
consistent (``K = 1``: a disc on three bearings 120° apart turns ``Δ / r`` flank to flank;
``2 Δr_c/(a z_c)`` for a normal gap Δr_c at every pin; the output turns ``i_b = (1 − 1/i) z_c / z_p``
times the disc's rotation).  In the 20-DOF model ``δ_b`` is the radius of a bearing's free-play circle,
so the radial internal clearance is ``Δ = 2 δ_b``; a pin clearance ``δ`` is a normal gap at every pin,
doc 001's per-side ``Δr_c`` (an equidistant modification).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from ... import units
from ...elements.reducer_chain import FAMILIES
from ...errors import SolverError
from ...records import frame_records
from ..lost_motion.model import LostMotionGeometry, LostMotionModel
from ..stiffness.cycloid_contact import PinGear
from ..stiffness.torsion_angle import LABELS, ReducerStiffness
from ..reducer_20dof import layout as L
from ..reducer_20dof.quasistatic import QuasiStaticSolver
from .model import CAMS, RIGIDITY_READINGS, TorsionCurve, TorsionCurveModel, compliance_breakdown

BREAKDOWN_LABELS = {**FAMILIES, "sun_planet_mesh": "sun–planet meshes (≈ θ1)", "cycloid_pin": "cycloid–pin contacts (≈ θ2)",
                    "turning_arm_bearings": "cycloid–crank bearings (≈ θ3)"}

_arcmin = lambda v: units.from_base(v, "arcmin")  # noqa: E731
_arcsec = lambda v: float(units.from_base(v, "arcsec"))  # noqa: E731


def output_ratio(g) -> float:
    """``i_b``: output rotation per rotation of a disc relative to the carrier."""
    return (1.0 - 1.0 / g.ratio) * g.z_c / g.z_b


def analytic_geometry(g, K: float = 1.5, mode: str = "document") -> LostMotionGeometry:
    """Doc 001's lost-motion geometry for the 20-DOF reducer ``g`` (``K``: doc 001's clearance coefficient,
    used in document mode)."""
    return LostMotionGeometry(pressure_angle=g.alpha, pitch_diameter=g.module * g.z_s, ratio=g.ratio,
                              eccentricity=g.ecc, cycloid_teeth=float(g.z_c), K1=g.K1, bearing_radius=g.a_w,
                              bearing_K=K if mode == "document" else 1.0, mode=mode, working_pressure_angle=g.alpha_w,
                              pins=float(g.z_b), origins={"r": "operating centre distance a' of the 20-DOF geometry"})


def analytic_lost_motion(g, K: float, Delta_b=0.0, Delta_r_c=0.0, mode: str = "document") -> np.ndarray:
    """Doc 001's total lost motion (rad) for crank-bearing clearance ``Δ`` and cycloid clearance ``Δr_c``."""
    m = LostMotionModel(analytic_geometry(g, K, mode), ["Delta_b", "Delta_r_c"])
    X = np.column_stack(np.broadcast_arrays(np.atleast_1d(np.asarray(Delta_b, float)),
                                            np.atleast_1d(np.asarray(Delta_r_c, float))))
    return m.evaluate(X)[:, 0]


def _free_curve(model: TorsionCurveModel, friction: bool = True) -> TorsionCurve:
    """The clearance-free, error-free curve of ``model``'s reducer (``friction``: with the design's Coulomb
    friction, if it has any)."""
    return TorsionCurveModel(model.geometry, (), percent=model.percent, points=model.points,
                             torque=model.torque, friction=friction).curve()


# --------------------------------------------------------------------------- the curves
@dataclass
class SimulatedCurves:
    """``metrics``: the maker's figures of each curve; ``curves``: (label, curve) pairs."""

    metrics: pd.DataFrame
    curves: list
    percent: float
    torque: float           # N·mm
    points: int
    friction: bool = False  # the curves include the design's Coulomb friction

    def to_frame(self) -> pd.DataFrame:
        return self.metrics

    def plot(self, zoom: bool = False):
        """The curves over the whole cycle, or (``zoom``) within ±10 % of rated torque."""
        from ...plotting.stiffness import plot_torsion_curves

        return plot_torsion_curves([(lab, c) for lab, c in self.curves if c.ok], self.percent,
                                   float(units.from_base(self.torque, "N*m")), zoom)

    def summary(self) -> dict:
        return {"curves": frame_records(self.metrics)}


def _metrics_row(label: str, curve: TorsionCurve, percent: float) -> dict:
    if not curve.ok:
        return {"reducer": label, "status": curve.reason}
    mt = curve.metrics(percent)
    return {"reducer": label,
            f"lost motion ±{percent:g} % (arcmin)": units.from_base(mt.lost_motion, "arcmin"),
            "backlash (arcmin)": units.from_base(mt.backlash, "arcmin"),
            "rigidity b/a (N·m/arcmin)": units.from_base(mt.rigidity, "N*m/arcmin"),
            "rigidity 50–100 % (N·m/arcmin)": units.from_base(mt.rigidity_50_100, "N*m/arcmin"),
            "rigidity b/a less backlash (N·m/arcmin)": units.from_base(mt.rigidity_clearance_free, "N*m/arcmin"),
            "angle at +rated (arcmin)": units.from_base(mt.angle_at_rated, "arcmin"),
            "largest hysteresis width (arcsec)": units.from_base(mt.hysteresis_width, "arcsec"),
            f"friction width ±{percent:g} % (arcsec)": units.from_base(mt.friction_width, "arcsec")}


def simulated_curves(model: TorsionCurveModel, mean_inputs=None) -> SimulatedCurves:
    """The clearance-free, error-free curve of ``model``'s reducer and (``mean_inputs``: one row of the
    model's inputs) the curve at the spec's mean errors."""
    free = _free_curve(model)
    rows = [_metrics_row("clearance-free, error-free", free, model.percent)]
    curves = [("clearance-free", free)]
    if mean_inputs is not None:
        c = model.curve(mean_inputs)
        rows.append(_metrics_row("all factors at the spec's mean", c, model.percent))
        curves.append(("spec mean", c))
    return SimulatedCurves(pd.DataFrame(rows), curves, model.percent, model.torque, model.points,
                           bool(model.friction))


# --------------------------------------------------------------------------- lost motion against clearances
@dataclass
class ClearanceSweep:
    """``crank_bearing`` / ``pins``: the 20-DOF lost motion and backlash against the clearance beside the
    lost-motion model in both modes; ``rates``: the first-order rates of each (arcmin/µm)."""

    rates: pd.DataFrame
    crank_bearing: pd.DataFrame
    pins: pd.DataFrame
    K: float
    i_b: float
    document_share_b: float        # doc 001 as printed / consistent, crank bearings
    document_share_c: float        # the same for the pin clearance
    percent: float

    def to_frame(self) -> pd.DataFrame:
        return self.crank_bearing

    def plot(self):
        """Lost motion and backlash against δ_b, 20-DOF and analytical."""
        from ...plotting.stiffness import plot_sweep

        cam = self.crank_bearing
        return plot_sweep(cam, "δ_b (µm)", [c for c in cam.columns if "arcmin" in c],
                          ylabel="lost motion / backlash [arcmin]")

    def summary(self) -> dict:
        return {"rates": frame_records(self.rates), "crank_bearing": frame_records(self.crank_bearing),
                "pins": frame_records(self.pins)}


def _slope(x, y) -> float:
    return float(np.polyfit(x, y, 1)[0])


def clearance_sweep(model: TorsionCurveModel, clearances, pin_clearances, K: float = 1.5) -> ClearanceSweep:
    """Clearances (mm) on all six crank bearings (δ_b) and, separately, at every pin (δ), on ``model``'s
    reducer; ``K``: doc 001's clearance coefficient of the document mode."""
    clearances, pin_clearances = np.asarray(clearances, float), np.asarray(pin_clearances, float)
    g = model.geometry
    sub = TorsionCurveModel(g, CAMS, percent=model.percent, points=model.points, torque=model.torque)
    Y = sub.evaluate(np.repeat(clearances[:, None], 6, axis=1))
    lm, bl = Y[:, 0], Y[:, 2]
    Delta = 2.0 * clearances
    doc_label, con_label = f"doc 001 as printed, K = {K:g} (arcmin)", "doc 001, consistent mode (arcmin)"
    cam = pd.DataFrame({
        "δ_b (µm)": clearances * 1e3, "Δ = 2δ_b (µm)": Delta * 1e3,
        "20-DOF lost motion (arcmin)": _arcmin(lm), "20-DOF backlash (arcmin)": _arcmin(bl),
        doc_label: _arcmin(lm[0] + analytic_lost_motion(g, K, Delta)),
        con_label: _arcmin(lm[0] + analytic_lost_motion(g, K, Delta, mode="consistent")),
    })
    pin = TorsionCurveModel(g, ("delta_pin",), percent=model.percent, points=model.points, torque=model.torque)
    Yp = pin.evaluate(pin_clearances[:, None])
    pins = pd.DataFrame({
        "pin clearance δ = Δr_c (µm)": pin_clearances * 1e3,
        "20-DOF lost motion (arcmin)": _arcmin(Yp[:, 0]), "20-DOF backlash (arcmin)": _arcmin(Yp[:, 2]),
        doc_label: _arcmin(Yp[0, 0] + analytic_lost_motion(g, K, 0.0, pin_clearances)),
        con_label: _arcmin(Yp[0, 0] + analytic_lost_motion(g, K, 0.0, pin_clearances, mode="consistent")),
    })
    sel = clearances >= 0.002 - 1e-12
    if sel.sum() < 2:
        sel = np.ones_like(clearances, bool)
    doc = analytic_geometry(g, K).output_coefficients()
    con = analytic_geometry(g, mode="consistent").output_coefficients()
    per_um = lambda c: _arcmin(c) * 1e-3  # noqa: E731
    rates = pd.DataFrame({
        "rate": ["d(lost motion)/dδ_b, crank bearings", "d(backlash)/dδ_b, crank bearings",
                 "d(lost motion)/dδ, pins", "d(backlash)/dδ, pins"],
        "20-DOF (arcmin/µm)": [1e-3 * _slope(clearances[sel], _arcmin(lm[sel])), 1e-3 * _slope(clearances, _arcmin(bl)),
                               1e-3 * _slope(pin_clearances, _arcmin(Yp[:, 0])),
                               1e-3 * _slope(pin_clearances, _arcmin(Yp[:, 2]))],
        f"doc 001 as printed, K = {K:g} (arcmin/µm)": [per_um(2 * doc["Delta_b"])] * 2 + [per_um(doc["Delta_r_c"])] * 2,
        "doc 001 consistent: K = 1, × i_b (arcmin/µm)": [per_um(2 * con["Delta_b"])] * 2
                                                        + [per_um(con["Delta_r_c"])] * 2,
    })
    return ClearanceSweep(rates, cam, pins, K, output_ratio(g), doc["Delta_b"] / con["Delta_b"],
                          doc["Delta_r_c"] / con["Delta_r_c"], model.percent)


# --------------------------------------------------------------------------- rigidity
@dataclass
class RigidityComparison:
    """``breakdown``: the 20-DOF angle at +rated per element (arcsec); ``readings``: the clearance-free curve's
    rigidity under each reading of the maker's b/a (:data:`.model.RIGIDITY_READINGS`, N·m/arcmin);
    ``torsion_angle``: the elastic torsion-angle model's components on its own reducer and with the 20-DOF's
    geometry (None without it)."""

    breakdown: pd.DataFrame
    torque: float                 # N·mm
    rigidity: float               # b/a of the clearance-free curve, N·mm/rad
    angle: float                  # the virtual-work sum at +rated, rad
    solver_angle: float           # the solver's angle at +rated, rad
    chain: bool                   # the 20-DOF model carries the design's compliance elements
    readings: dict
    torsion_angle: pd.DataFrame | None = None

    def to_frame(self) -> pd.DataFrame:
        return self.breakdown

    def readings_table(self) -> pd.DataFrame:
        return pd.DataFrame({"output": list(RIGIDITY_READINGS), "reading": list(RIGIDITY_READINGS.values()),
                             "clearance-free reducer (N·m/arcmin)": [self.readings[k] for k in RIGIDITY_READINGS]})

    def summary(self) -> dict:
        return {"breakdown_20dof": frame_records(self.breakdown),
                "rigidity_b_over_a_Nm_per_arcmin": float(units.from_base(self.rigidity, "N*m/arcmin")),
                "rigidity_readings_clearance_free_Nm_per_arcmin": self.readings,
                "rigidity_readings": dict(RIGIDITY_READINGS),
                "part1": frame_records(self.torsion_angle) if self.torsion_angle is not None else None}


def torsion_angle_beside(g, stiffness: ReducerStiffness, modifications, face_width: float, T: float) -> pd.DataFrame:
    """The elastic torsion-angle model's components at ``T`` on its own reducer (with its profile
    ``modifications``) and with the 20-DOF reducer ``g``'s pin gear and first stage, unmodified (arcsec)."""
    pins = PinGear(z_p=g.z_b, z_c=g.z_c, R_p=g.r_pin_circle, r_p=g.r_pin, a=g.ecc, b=face_width, E=stiffness.pins.E,
                   nu=stiffness.pins.nu)
    same = replace(stiffness, pins=pins, z1=g.z_s, z2=g.z_p, module=g.module, pressure_angle=g.alpha)
    a = stiffness.evaluate(T, *modifications)
    b = same.evaluate(T, 0.0, 0.0)
    asec = lambda v: units.from_base(v, "arcsec")  # noqa: E731
    return pd.DataFrame({"component": [LABELS[c] for c in a.components] + ["Total θ_Σ"],
                         "doc 004 RV-80E (arcsec)": np.append(asec(a.theta[0]), asec(a.total[0])),
                         "doc 000 geometry (arcsec)": np.append(asec(b.theta[0]), asec(b.total[0]))})


def rigidity_comparison(model: TorsionCurveModel, part1=None) -> RigidityComparison:
    """The clearance-free curve's angle at +rated split by virtual work; ``part1`` = (stiffness model, its
    modifications, the face width of the 20-DOF design's discs): the torsion-angle model beside."""
    g = model.geometry
    free = _free_curve(model, friction=False)     # virtual work: no friction
    T = model.torque
    k = int(np.flatnonzero(np.isclose(free.torque, T))[0])
    bd = compliance_breakdown(g, None, free.q[k], T)
    rows = [{"element": BREAKDOWN_LABELS[n], "20-DOF at +rated (arcsec)": _arcsec(v)} for n, v in bd.items()]
    total20 = sum(bd.values())
    rows.append({"element": "total", "20-DOF at +rated (arcsec)": _arcsec(total20)})
    comp = torsion_angle_beside(g, *part1, T) if part1 is not None else None
    mt = free.metrics(model.percent)
    readings = {k: float(units.from_base(v, "N*m/arcmin")) for k, v in mt.readings().items()}
    return RigidityComparison(pd.DataFrame(rows), T, mt.rigidity, total20, float(free.angle[k]), g.chain is not None,
                              readings, comp)


# --------------------------------------------------------------------------- the torsion_curve analysis
@dataclass
class TorsionCurveStudy:
    curves: SimulatedCurves
    clearances: ClearanceSweep
    rigidity: RigidityComparison

    def to_frame(self) -> pd.DataFrame:
        return self.curves.metrics

    def summary(self) -> dict:
        return self.curves.summary()

    def plot(self, which: str = "curves", zoom: bool = False):
        """The report's figure of ``which``: ``curves`` (the torsion curves; ``zoom``: within ±10 % of rated
        torque) or ``clearances`` (lost motion against δ_b).  The rigidity comparison is a table and has no
        figure: asking for it is an error."""
        if which == "curves":
            return self.curves.plot(zoom=zoom)
        if which == "clearances":
            return self.clearances.plot()
        if which == "rigidity":
            raise ValueError("the rigidity comparison has no figure (the report shows it as text and a table)")
        raise ValueError(f"unknown figure {which!r} (expected curves or clearances)")


def torsion_curve_study(model: TorsionCurveModel, mean_inputs, clearances, pin_clearances, K: float = 1.5,
                        part1=None) -> TorsionCurveStudy:
    """:func:`simulated_curves`, :func:`clearance_sweep` and :func:`rigidity_comparison` of one reducer."""
    return TorsionCurveStudy(simulated_curves(model, mean_inputs), clearance_sweep(model, clearances, pin_clearances, K),
                             rigidity_comparison(model, part1))


# --------------------------------------------------------------------------- compliance breakdown
def breakdown_at(g, T: float, steps: int = 8) -> dict[str, float]:
    """Output angle (rad) per family of the clearance- and error-free reducer ``g`` at torque ``T`` (N·mm),
    reached in ``steps`` warm-started load steps."""
    r = QuasiStaticSolver(g, tol_f=1e-8).torsion(np.linspace(0.0, T, steps + 1)[1:])
    if not r.ok:
        raise SolverError(f"no equilibrium of the clearance-free reducer at {T:g} N·mm "
                          f"({L.STATUS_REASONS.get(r.failure, r.failure)})")
    return compliance_breakdown(g, None, r.q[-1], T)


@dataclass
class ComplianceComparison:
    """``table``: the output angle per family and model (arcsec), their totals and secant rigidities;
    ``columns``: the models (name -> angles per family, rad); ``reductions`` / ``sources``: how the
    design's compliance elements reach the 20-DOF contacts (None for a rigid chain)."""

    table: pd.DataFrame
    families: pd.DataFrame
    columns: list[str]
    torque: float               # N·mm
    reductions: pd.DataFrame | None = None
    sources: pd.DataFrame | None = None

    def to_frame(self) -> pd.DataFrame:
        return self.table

    def plot(self):
        from ...plotting.stiffness import plot_compliance_breakdown

        df = self.families
        return plot_compliance_breakdown(list(df["element"]), {name: df[f"{name} (arcsec)"] for name in self.columns})

    def summary(self) -> dict:
        out = {"torque_Nm": float(units.from_base(self.torque, "N*m")), "breakdown": frame_records(self.table)}
        if self.reductions is not None:
            out["reductions"] = frame_records(self.reductions)
        return out


def compliance_comparison(g, T: float, rigid=None, stiffness=None) -> ComplianceComparison:
    """Output angle per compliance family at ``T`` (N·mm): the 20-DOF reducer ``g``, the same with doc 000's
    rigid chain (``rigid``: its geometry) and the torsion-angle model (``stiffness`` = (model, modifications))."""
    cols = {"20-DOF, compliance chain": breakdown_at(g, T)}
    if rigid is not None:
        cols["20-DOF, doc 000's rigid chain"] = breakdown_at(rigid, T)
    if stiffness is not None:
        rs, mods = stiffness
        fam = rs.evaluate(T, *mods).families()
        cols["doc 004 model"] = {k: float(v[0]) for k, v in fam.items()}
    rows = []
    for f, label in FAMILIES.items():
        if any(f in c for c in cols.values()):
            rows.append({"family": f, "element": label,
                         **{f"{name} (arcsec)": _arcsec(c[f]) if f in c else np.nan for name, c in cols.items()}})
    df = pd.DataFrame(rows)
    totals = {name: sum(c.values()) for name, c in cols.items()}
    total_row = {"family": "total", "element": "θ at the output",
                 **{f"{name} (arcsec)": _arcsec(t) for name, t in totals.items()}}
    rig_row = {"family": "T/θ", "element": "secant rigidity (N·m/arcmin)",
               **{f"{name} (arcsec)": float(units.from_base(T / t, "N*m/arcmin")) for name, t in totals.items()}}
    table = pd.concat([df, pd.DataFrame([total_row, rig_row])], ignore_index=True)
    ch = g.chain
    red = src = None
    if ch is not None:
        red = ch.to_frame()
        src = pd.DataFrame({"family": list(ch.elements.sources), "element as built": list(ch.elements.sources.values())})
    return ComplianceComparison(table, df, list(cols), T, red, src)
