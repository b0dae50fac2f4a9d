"""Geometric lost motion of an RV reducer (doc 001: ../shared/seeds/001_411b7d611462c065.txt).

Three contributions, each a linear function of the part errors, K = 180·60/π
turning radians into arcmin:

* **involute stage** (sun–planet backlash, seen at the input shaft)::

      j  = −E_w / cos α + 2 Δa tan α + ΔF_r tan α          (circumferential backlash, mm)
      Δφ12 = 2 j / d1                                        (rad; d1: sun pitch diameter)

  E_w is the tooth-thickness deviation, sampled in its band [E_wi, E_ws];
  the document's mean j̄1 = −(E_ws + E_wi)/(2 cos α) is its mean.
* **cycloid stage** (a: eccentricity, z_c: cycloid teeth, K1 = a·z_p/r_p the
  short-amplitude coefficient)::

      Δφ34 = Δr_c / (a z_c) + Δr_p / (a z_c √(1 − K1²)) + Σ_i (∂Δφ34/∂ξ_i) ξ_i

  with further error factors ξ_i and their partial derivatives given in the
  study (``[[model.cycloid_factor]]``);
* **crank bearing clearance** Δ (r: radius of the crank-bearing centre circle,
  K ≈ 1.5 the clearance-to-circumferential-displacement coefficient)::

      Δφ_b = Δ / (K r)

* **total** at the output: Δφ_t = Δφ12 / i + Δφ34 + Δφ_b (i: overall ratio).

The :class:`LostMotionModel` evaluates these per sample (outputs in rad,
reported in arcmin).  :func:`analytic` gives the document's mean ± T/2 per
stage and in total *as written* — means added, tolerances by RSS, with
T_Δφ12 = √D(j)·K/d1 and D(j) built from each factor's band read as ±3σ —
beside the σ that follows from the same linear model and the factors' own
distributions (6σ is the band the Monte Carlo should reproduce).  For the
cycloid and bearing terms the two agree; for the involute stage the printed
tolerance formula is 12× narrower than 6σ (it drops the factor 2 of the mean
formula and reads √D as the whole band) — the report shows both.

Factor names the model knows (all lengths): ``E_w``, ``Delta_a``,
``Delta_F_r``, ``Delta_r_c``, ``Delta_r_p``, ``Delta_b``, plus the ξ names of
``[[model.cycloid_factor]]``.  Factors the spec does not name stay at their
``[model.nominal]`` value (default 0).

Geometry from the design (base units), each either given or derived by
standard gear geometry:

==================  =====================================  ==========================================
symbol              design key                             if absent
==================  =====================================  ==========================================
α                   ``sun.pressure_angle``                 —
d1                  ``sun.pitch_diameter``                 ``sun.module`` × ``sun.teeth``
i                   ``reducer.ratio``                      —
a                   ``cycloid.eccentricity``               —
z_c                 ``cycloid.teeth``                      —
K1                  ``cycloid.short_amplitude_coefficient`` a · ``pin.count`` / ``pin.circle_radius``
r                   ``crank_bearing.centre_radius``        ``sun.module`` × (``sun.teeth`` + ``planet.teeth``)/2
K                   ``crank_bearing.clearance_coefficient`` —
==================  =====================================  ==========================================
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ... import units
from ...errors import InputError, SpecError, did_you_mean
from ...model import Model, Quantity

#: the document's 180·60/π: arcmin per radian
ARCMIN_PER_RAD = 180.0 * 60.0 / math.pi

FACTORS = {
    "E_w": "tooth-thickness deviation of the involute stage (band E_wi…E_ws)",
    "Delta_a": "centre-distance error of the involute stage",
    "Delta_F_r": "radial runout of the involute stage",
    "Delta_r_c": "cycloid radius error (profile clearance)",
    "Delta_r_p": "pin-wheel radius error",
    "Delta_b": "crank-bearing radial clearance Δ",
}
STAGES = ("involute_stage", "cycloid_stage", "crank_bearing")
DERIVATIVE_LIKE = {"cycloid_radius": "Delta_r_c", "pin_radius": "Delta_r_p"}


@dataclass(frozen=True)
class GeometryParam:
    symbol: str
    value: float  # base units
    unit: str     # display unit
    origin: str   # design key, or how it was derived


@dataclass(frozen=True)
class LostMotionGeometry:
    """The design numbers the lost-motion formulas need (base units: mm, rad)."""

    pressure_angle: float
    pitch_diameter: float
    ratio: float
    eccentricity: float
    cycloid_teeth: float
    K1: float
    bearing_radius: float
    bearing_K: float
    origins: dict = field(default_factory=dict, compare=False)  # symbol -> design key or derivation

    def __post_init__(self):
        checks = {"d1": self.pitch_diameter, "i": self.ratio, "a": self.eccentricity, "z_c": self.cycloid_teeth,
                  "r": self.bearing_radius, "K": self.bearing_K}
        for sym, v in checks.items():
            if not v > 0:
                raise SpecError(f"{sym} must be > 0, got {v}", key=self.origins.get(sym, sym))
        if not 0 < self.pressure_angle < math.pi / 2:
            raise SpecError("pressure angle must lie in (0°, 90°)", key=self.origins.get("α", "α"))
        if not 0 <= self.K1 < 1:
            raise SpecError(f"K1 must lie in [0, 1), got {self.K1:.4g}", key=self.origins.get("K1", "K1"))

    @classmethod
    def from_design(cls, design) -> "LostMotionGeometry":
        origins = {}

        def get(sym, key, alt=None):
            if key in design:
                origins[sym] = key
                return float(design[key])
            if alt is not None:
                value, how = alt()
                origins[sym] = how
                return value
            raise SpecError("missing design parameter for the lost-motion model", file=design.file, key=key)

        def d1():
            return (float(design["sun.module"]) * float(design["sun.teeth"]),
                    "sun.module × sun.teeth (reference pitch diameter)")

        def k1():
            a = float(design["cycloid.eccentricity"])
            return (a * float(design["pin.count"]) / float(design["pin.circle_radius"]),
                    "cycloid.eccentricity × pin.count / pin.circle_radius")

        def centre_distance():
            return (float(design["sun.module"]) * (float(design["sun.teeth"]) + float(design["planet.teeth"])) / 2,
                    "sun.module × (sun.teeth + planet.teeth) / 2 (crank axes on the sun–planet centre distance)")

        has = lambda *keys: all(k in design for k in keys)  # noqa: E731
        need_d1 = "sun.pitch_diameter" not in design and not has("sun.module", "sun.teeth")
        need_r = "crank_bearing.centre_radius" not in design and not has("sun.module", "sun.teeth", "planet.teeth")
        need_k1 = "cycloid.short_amplitude_coefficient" not in design and not has("pin.count", "pin.circle_radius")
        try:
            return cls(
                pressure_angle=get("α", "sun.pressure_angle"),
                pitch_diameter=get("d1", "sun.pitch_diameter", None if need_d1 else d1),
                ratio=get("i", "reducer.ratio"),
                eccentricity=get("a", "cycloid.eccentricity"),
                cycloid_teeth=get("z_c", "cycloid.teeth"),
                K1=get("K1", "cycloid.short_amplitude_coefficient", None if need_k1 else k1),
                bearing_radius=get("r", "crank_bearing.centre_radius", None if need_r else centre_distance),
                bearing_K=get("K", "crank_bearing.clearance_coefficient"),
                origins=origins,
            )
        except SpecError as exc:
            raise exc.located(file=design.file) from None

    # -- linear coefficients (rad per mm) ----------------------------------------
    def coefficients(self, extra: dict[str, float] | None = None) -> dict[str, dict[str, float]]:
        """∂(stage angle)/∂(factor) in rad/mm; the involute stage at the input shaft."""
        ca, ta, d1 = math.cos(self.pressure_angle), math.tan(self.pressure_angle), self.pitch_diameter
        az = self.eccentricity * self.cycloid_teeth
        cyc = {"Delta_r_c": 1.0 / az, "Delta_r_p": 1.0 / (az * math.sqrt(1.0 - self.K1**2))}
        cyc.update(extra or {})
        return {
            "involute_stage": {"E_w": -2.0 / (d1 * ca), "Delta_a": 4.0 * ta / d1, "Delta_F_r": 2.0 * ta / d1},
            "cycloid_stage": cyc,
            "crank_bearing": {"Delta_b": 1.0 / (self.bearing_K * self.bearing_radius)},
        }

    def to_frame(self) -> pd.DataFrame:
        rows = [("α", "pressure angle", self.pressure_angle, "deg"),
                ("d1", "sun pitch diameter", self.pitch_diameter, "mm"),
                ("i", "overall ratio", self.ratio, "1"),
                ("a", "eccentricity", self.eccentricity, "mm"),
                ("z_c", "cycloid teeth", self.cycloid_teeth, "1"),
                ("K1", "short-amplitude coefficient", self.K1, "1"),
                ("r", "crank-bearing centre radius", self.bearing_radius, "mm"),
                ("K", "clearance coefficient", self.bearing_K, "1")]
        return pd.DataFrame([{"symbol": s, "parameter": p, "value": float(units.from_base(v, u)),
                              "unit": units.label(u), "from": self.origins.get(s, "")} for s, p, v, u in rows])


# --------------------------------------------------------------------------- the Model
class LostMotionModel(Model):
    """Per-sample geometric lost motion: total and the three stage angles (rad; shown in arcmin).

    ``inputs``: the spec's factor names (each known, see module docstring);
    ``nominal``: base values of known factors the spec does not name;
    ``extra``: ξ name -> ∂Δφ34/∂ξ in rad/mm.
    """

    def __init__(self, geometry: LostMotionGeometry, inputs, nominal: dict[str, float] | None = None,
                 extra: dict[str, float] | None = None, extra_sources: dict[str, str] | None = None):
        self.geometry = geometry
        self.extra = dict(extra or {})
        self.extra_sources = dict(extra_sources or {})
        self.inputs = tuple(inputs)
        self.input_units = ("mm",) * len(self.inputs)
        known = set(FACTORS) | set(self.extra)
        for n in self.inputs:
            if n not in known:
                raise InputError(f"unknown factor name {n!r}{did_you_mean(n, sorted(known))} for the lost-motion "
                                 f"model (known: "
                                 f"{', '.join(sorted(known))})", key="factor")
        self.nominal = {n: 0.0 for n in known}
        self.nominal.update(nominal or {})
        self.outputs = (
            Quantity("lost_motion", "rad", "arcmin", "total geometric lost motion at the output"),
            Quantity("involute_stage", "rad", "arcmin", "Δφ12, involute stage at the input shaft"),
            Quantity("cycloid_stage", "rad", "arcmin", "Δφ34, cycloid stage"),
            Quantity("crank_bearing", "rad", "arcmin", "Δφ_b, crank-bearing clearance"),
        )

    def _column(self, X, name):
        if name in self.inputs:
            return X[:, self.inputs.index(name)]
        return np.full(len(X), self.nominal[name])

    def evaluate(self, X):
        X = self.check_input(X)
        g = self.geometry
        c = lambda n: self._column(X, n)  # noqa: E731
        alpha, az = g.pressure_angle, g.eccentricity * g.cycloid_teeth
        j = -c("E_w") / math.cos(alpha) + 2.0 * c("Delta_a") * math.tan(alpha) + c("Delta_F_r") * math.tan(alpha)
        phi12 = 2.0 * j / g.pitch_diameter
        phi34 = c("Delta_r_c") / az + c("Delta_r_p") / (az * math.sqrt(1.0 - g.K1**2))
        for name, d in self.extra.items():
            phi34 = phi34 + d * c(name)
        phib = c("Delta_b") / (g.bearing_K * g.bearing_radius)
        total = phi12 / g.ratio + phi34 + phib
        return np.column_stack([total, phi12, phi34, phib])


# --------------------------------------------------------------------------- analytic mean ± T/2
@dataclass(frozen=True)
class FactorMoments:
    mean: float   # mm
    std: float    # mm
    band: float   # tolerance T (mm), read as ±3σ by the document


def factor_moments(spec, model: LostMotionModel) -> dict[str, FactorMoments]:
    """Mean, σ and tolerance T (base units) of every known factor; fixed ones have σ = T = 0."""
    out = {n: FactorMoments(v, 0.0, 0.0) for n, v in model.nominal.items()}
    for f in spec.factors:
        to = lambda v: float(units.to_base(v, f.unit))  # noqa: E731
        out[f.name] = FactorMoments(to(f.dist.mean), to(f.dist.std), to(f.dist.tolerance))
    return out


def analytic(geometry: LostMotionGeometry, moments: dict[str, FactorMoments],
             extra: dict[str, float] | None = None) -> pd.DataFrame:
    """The document's mean and tolerance per stage and in total, and σ of the linear model (arcmin).

    Columns: ``stage``, ``to_output`` (1/i for the involute stage), ``mean``,
    ``T_doc`` (tolerance by the document's formulas as written), ``sigma``
    (from the factors' own σ), ``T_6sigma`` = 6σ.  The total row refers
    every stage to the output (means added, tolerances and σ by RSS).
    """
    g, K = geometry, ARCMIN_PER_RAD
    m = moments
    ca, ta = math.cos(g.pressure_angle), math.tan(g.pressure_angle)
    coef = geometry.coefficients(extra)
    # involute stage, as written: j̄ = Σ j̄_k; D(j) = Σ (coefficient × T/6)²; mean = 2 j̄ K/d1; T = √D K/d1
    j_mean = -m["E_w"].mean / ca + 2 * m["Delta_a"].mean * ta + m["Delta_F_r"].mean * ta
    D_j = (m["E_w"].band / (6 * ca)) ** 2 + (2 * m["Delta_a"].band / 2 * ta / 3) ** 2 + \
        (m["Delta_F_r"].band / 2 * ta / 3) ** 2
    rows = [("involute_stage", 1.0 / g.ratio, 2 * j_mean * K / g.pitch_diameter,
             math.sqrt(D_j) * K / g.pitch_diameter)]
    # cycloid stage, as written (ξ terms: ∂Δφ34/∂ξ · T_ξ in the RSS; their means added as in the model)
    cyc = coef["cycloid_stage"]
    mean34 = K * sum(cyc[n] * m[n].mean for n in cyc)
    T34 = K * math.sqrt(sum((cyc[n] * m[n].band) ** 2 for n in cyc))
    rows.append(("cycloid_stage", 1.0, mean34, T34))
    kb = coef["crank_bearing"]["Delta_b"]
    rows.append(("crank_bearing", 1.0, K * kb * m["Delta_b"].mean, K * kb * m["Delta_b"].band))
    frame = pd.DataFrame(rows, columns=["stage", "to_output", "mean", "T_doc"])
    frame["sigma"] = [K * math.sqrt(sum((c * m[n].std) ** 2 for n, c in coef[s].items())) for s in STAGES]
    frame["T_6sigma"] = 6.0 * frame["sigma"]
    w = frame["to_output"]
    total = {"stage": "lost_motion", "to_output": 1.0, "mean": float((frame["mean"] * w).sum()),
             "T_doc": float(np.sqrt(((frame["T_doc"] * w) ** 2).sum())),
             "sigma": float(np.sqrt(((frame["sigma"] * w) ** 2).sum()))}
    total["T_6sigma"] = 6.0 * total["sigma"]
    return pd.concat([frame, pd.DataFrame([total])], ignore_index=True)


# --------------------------------------------------------------------------- study factory
def from_study(params, design, spec) -> LostMotionModel:
    """``[model] kind = "lost_motion"``: geometry from the design; optional ``[model.nominal]`` and
    ``[[model.cycloid_factor]]`` (``factor``, ``derivative`` = "cycloid_radius" | "pin_radius" |
    {value, unit = "arcmin/um"}, ``source``)."""
    if design is None:
        raise params.error(None, "the lost-motion model needs a design (study.design)")
    geometry = LostMotionGeometry.from_design(design)
    base = geometry.coefficients()["cycloid_stage"]
    extra, sources = {}, {}
    tables = params.tables("cycloid_factor")
    declared = {t.data.get("factor") for t in tables}
    # spec factors no table declares: a ξ name close to one of them is a typo (blame this table, not the spec)
    undeclared = [n for n in spec.names if n not in FACTORS and n not in declared]
    for t in tables:
        name = t.str("factor")
        if name in FACTORS or name in extra:
            raise t.error("factor", f"{name!r} is already a factor of the model")
        hint = did_you_mean(name, undeclared) if name not in spec.names else ""
        if hint:
            raise t.error("factor", f"the spec has no factor {name!r}{hint} (spec factors the model does not know: "
                                    f"{', '.join(undeclared)})")
        raw = t.raw("derivative")
        if isinstance(raw, str):
            like = t.str("derivative", choices=tuple(DERIVATIVE_LIKE))
            extra[name] = base[DERIVATIVE_LIKE[like]]
        else:
            extra[name] = t.quantity("derivative", "arcmin/mm")
        sources[name] = t.str("source")
        t.finish()
    nom = params.sub("nominal", {})
    nominal = {}
    for k in list(nom.keys()):
        if k not in FACTORS and k not in extra:
            known = ", ".join(sorted(set(FACTORS) | set(extra)))
            raise nom.error(k, f"unknown factor name {k!r}{did_you_mean(k, set(FACTORS) | set(extra))} "
                               f"(known: {known})")
        if k in spec.names:
            raise nom.error(k, f"{k!r} is a factor of the spec: its nominal comes from there")
        nominal[k] = nom.quantity(k, "mm")
    nom.finish()
    params.finish()
    return LostMotionModel(geometry, spec.names, nominal, extra, sources)
