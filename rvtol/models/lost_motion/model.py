"""Geometric lost motion of an RV reducer (doc 001: ../shared/seeds/001_411b7d611462c065.txt).

A fast **screening estimate**: the zero-load geometric play of the reducer, as
a linear function of the part errors.  What a sign-off judges is the maker's
lost motion on the hysteresis curve (mid-points within ±3 % of rated torque,
elastic deflection included, ``../shared/REFERENCE.md``): the torsion curve of
the 20-DOF model (:mod:`rvtol.models.torsion_curve`); the analysis
``lost_motion_screening`` shows the two side by side.

Three contributions, K = 180·60/π turning radians into arcmin; each a stage
angle (at its own member) times the ratio that refers it to the output::

    Δφ_t = Δφ12 · w12 + Δφ34 · w34 + Δφ_b · w_b

The formula has two **modes** (``[model] mode``):

``document`` — doc 001 as printed (the reproduction of doc 001 uses it)
-------------------------------------------------------------------------
::

    j    = −E_w / cos α + 2 Δa tan α + ΔF_r tan α          (circumferential backlash, mm)
    Δφ12 = 2 j / d1                                          (at the input shaft; w12 = 1/i)
    Δφ34 = Δr_c / (a z_c) + Δr_p / (a z_c √(1 − K1²)) + Σ_i (∂Δφ34/∂ξ_i) ξ_i      (w34 = 1)
    Δφ_b = Δ / (K r)        (K ≈ 1.5 "by vector analysis", from the design)      (w_b = 1)

``consistent`` — every coefficient derived from the kinematics (the default)
-------------------------------------------------------------------------------
Each coefficient is the zero-load, flank-to-flank play of the reducer with the
input locked, which is what the 20-DOF torsion curve's backlash measures;
``tests/models/lost_motion/test_lost_motion_modes.py`` holds them to the 20-DOF model's backlash
rates, factor by factor.  Kinematics (doc 000's nominal motion,
:mod:`rvtol.models.reducer_20dof.geometry`; pins fixed, carrier = output θ_c):
the sun turns θ_s = i θ_c with i = 1 + z_p z_pl / z_s; a crank (planet) turns
θ_p − θ_c = −(z_s/z_pl)(θ_s − θ_c) relative to the carrier (external mesh on
the carrier as arm); a disc spins with the carrier and its eccentric direction
follows the crank, and the pin gear ties the two: spin = −θ_p / z_c.

* **Involute stage, through the reducer** (w12 = 1/i).  The sun–planet mesh
  with circumferential backlash j (reference circle of the sun) lets the
  pair move by ``r_s(θ_s − θ_c) + r_pl(θ_p − θ_c) ∈ [−j/2, j/2]``.  Input
  locked (θ_s = 0) and the second stage rigid (θ_p − θ_c = −z_p θ_c):
  ``θ_c = −s / (r_s + z_p r_pl) = −s / (r_s i)``, so the output play is
  ``(2 j / d1) / i`` exactly: doc 001's Δφ12/i.  The backlash itself
  (ISO/TR 10064-2): the normal backlash of a centre-distance error is
  ``j_bn = 2 Δa sin α_w`` (α_w: operating pressure angle, from the profile
  shifts), the circular backlash on the reference circle ``j = j_bn / cos α``;
  so ``j = −E_w / cos α + 2 Δa sin α_w / cos α + ΔF_r sin α_w / cos α``
  (the runout read as doc 001 reads it, a centre-distance increase of
  ΔF_r/2 at the worst position).  Without profile shift α_w = α and this is
  the document's formula.
* **Cycloid stage** (at the disc, relative to the pins; w34 = i_b).  With the
  disc centre held by its cams (eccentric angle fixed) the disc can spin
  until a pin closes.  Pin k at angle φ from the eccentric direction touches
  along a normal through the pitch point (Willis), at the arm
  ``l = a z_c sin φ / S``, ``S = √(1 − 2 K1 cos φ + K1²)``, largest (= a z_c)
  at ``cos φ0 = K1`` (Li Lixing; doc 004, :mod:`rvtol.models.stiffness.cycloid_contact`).
  The normal gaps the part errors open at pin k: an equidistant modification
  Δr_c (the profile moved along its normal into the disc) opens Δr_c at
  every pin; a pin-circle radius error Δr_p (pins moved outward) opens
  ``Δr_p (n·e_r) = Δr_p (1 − K1 cos φ)/S``.  The disc spins
  ``min_k gap_k / l_k`` to first contact: ``Δr_c / (a z_c)`` and
  ``Δr_p min_φ (1 − K1 cos φ)/(a z_c sin φ) = Δr_p √(1 − K1²)/(a z_c)``
  (the minimum at cos φ = K1).  The pins on the other side limit the
  opposite spin alike, so flank to flank::

      Δφ34 = 2 (Δr_c + √(1 − K1²) Δr_p) / (a z_c)  + Σ_i (∂Δφ34/∂ξ_i) ξ_i

  — doc 004's angular backlash ``2 n0 / r_c'`` with ``n0 = Δr − √(1−K1²) ΔR``.
  Doc 001 prints the one-sided spin for Δr_c, and divides by √(1 − K1²)
  where the first-contact pin multiplies by it.  Δr_c, Δr_p and the ξ's are
  part dimensions (per side); a pin-roller undersize ξ opens ξ at every pin,
  like Δr_c (``derivative = "cycloid_radius"``).
* **Crank bearings** (at the disc, relative to the carrier; w_b = i_b).  Each
  disc hangs on three cams 120° apart on the crank circle r (the crank axes
  sit on the operating centre distance a').  With radial internal clearance
  Δ (ISO 5753: total radial free movement, the 20-DOF's Δ = 2δ_b) a disc
  rotation ψ with translation u moves cam i by ``u + ψ r t_i``; all three
  stay inside their free-play circles of radius Δ/2 for ``|ψ| r ≤ Δ/2`` at
  most (u = 0: since ``Σ t_i = 0`` any u pushes one of them further), so the
  disc turns ``Δ / r`` flank to flank: ``K = 1`` (not doc 001's 1.5).
  With unequal clearances a translation evens them out: to first order the
  disc turns ``2·mean(δ_b)/r``.
* **Disc to output** ``i_b = (1 − 1/i) z_c / z_p``.  A spin play δ of a disc
  relative to the pins (or a rotation ψ relative to the carrier) at locked
  input: spin = θ_c + ψ = −θ_p / z_c + δ with θ_p = (1 + z_s/z_pl) θ_c gives
  ``θ_c = (δ − ψ) z_c / (z_p + z_s/z_pl) = i_b (δ − ψ)``: the eccentric
  follows the output through the locked first stage and takes back
  ``1 − i_b`` (3.7 % for the RV-80E) of the disc's play.  Doc 001 omits it.

Which mode for what: ``document`` reproduces doc 001 (the study
``lost_motion_doc_example`` sets it); ``consistent`` is the default for every
other study, because its rates are the kinematics of the reducer — they agree
with rvtol's 20-DOF model (within 0.4 % per factor on the RV-80E, the pin
positions being discrete) and with doc 004's backlash — while the document's
are off by −48 % (Δr_c), +35 % (Δr_p) and −31 % (Δ) on the same reducer.

:func:`analytic` gives the mean ± T/2 per stage and in total — in document
mode *as written* (means added, tolerances by RSS, T_Δφ12 = √D(j)·K/d1 with
D(j) built from each factor's band read as ±3σ) — beside the σ of the same
linear model with the factors' own distributions (6σ is the band a Monte
Carlo reproduces).  For the cycloid and bearing terms the two agree; for the
involute stage the printed tolerance formula is 12× narrower than 6σ (it drops
the factor 2 of the mean formula and reads √D as the whole band) — the report
shows both.

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
α_w                 (derived)                              inv α_w = inv α + 2 tan α (x_s + x_pl)/(z_s + z_pl)
                                                           (``sun/planet.profile_shift``, 0 if absent;
                                                           α_w = α without ``planet.teeth``)
d1                  ``sun.pitch_diameter``                 ``sun.module`` × ``sun.teeth``
i                   ``reducer.ratio``                      —
a                   ``cycloid.eccentricity``               —
z_c                 ``cycloid.teeth``                      —
z_p                 ``pin.count``                          z_c + 1
K1                  ``cycloid.short_amplitude_coefficient`` a · ``pin.count`` / ``pin.circle_radius``
r                   ``crank_bearing.centre_radius``        operating centre distance a' =
                                                           m (z_s + z_pl)/2 · cos α / cos α_w
K                   ``crank_bearing.clearance_coefficient`` document mode: required; consistent: 1 (derived)
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
from ...model_kind import ModelKind
from ...options import option
from ...params import Params
from ...stats import rss
from ..reducer_20dof.geometry import involute, inverse_involute

#: the document's 180·60/π: arcmin per radian
ARCMIN_PER_RAD = 180.0 * 60.0 / math.pi

#: ``document``: doc 001 as printed; ``consistent``: coefficients from the kinematics (module docstring)
MODES = ("consistent", "document")
DEFAULT_MODE = "consistent"

FACTORS = {
    "E_w": "tooth-thickness deviation of the involute stage (band E_wi…E_ws)",
    "Delta_a": "centre-distance error of the involute stage",
    "Delta_F_r": "radial runout of the involute stage",
    "Delta_r_c": "cycloid radius error: equidistant modification of the profile (per side)",
    "Delta_r_p": "pin-wheel (pin-circle) radius error",
    "Delta_b": "crank-bearing radial internal clearance Δ",
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
    """The design numbers the lost-motion formulas need (base units: mm, rad) and the formula's mode.

    ``working_pressure_angle`` (α_w) and ``pins`` (z_p) default to α and z_c + 1; ``bearing_K`` is
    doc 001's K, used in document mode only (the consistent mode derives K = 1).
    """

    pressure_angle: float
    pitch_diameter: float
    ratio: float
    eccentricity: float
    cycloid_teeth: float
    K1: float
    bearing_radius: float
    bearing_K: float = 1.0
    mode: str = DEFAULT_MODE
    working_pressure_angle: float | None = None
    pins: float | None = None
    origins: dict = field(default_factory=dict, compare=False)  # symbol -> design key or derivation

    def __post_init__(self):
        if self.mode not in MODES:
            raise SpecError(f"unknown mode {self.mode!r} (expected one of: {', '.join(MODES)})", key="mode")
        checks = {"d1": self.pitch_diameter, "i": self.ratio, "a": self.eccentricity, "z_c": self.cycloid_teeth,
                  "r": self.bearing_radius, "K": self.bearing_K, "z_p": self.z_p}
        for sym, v in checks.items():
            if not v > 0:
                raise SpecError(f"{sym} must be > 0, got {v}", key=self.origins.get(sym, sym))
        if not self.ratio > 1:
            raise SpecError(f"i must be > 1, got {self.ratio}", key=self.origins.get("i", "i"))
        for sym, v in (("α", self.pressure_angle), ("α_w", self.alpha_w)):
            if not 0 < v < math.pi / 2:
                raise SpecError(f"{sym} must lie in (0°, 90°)", key=self.origins.get(sym, sym))
        if not 0 <= self.K1 < 1:
            raise SpecError(f"K1 must lie in [0, 1), got {self.K1:.4g}", key=self.origins.get("K1", "K1"))

    @property
    def alpha_w(self) -> float:
        return self.pressure_angle if self.working_pressure_angle is None else self.working_pressure_angle

    @property
    def z_p(self) -> float:
        return self.cycloid_teeth + 1.0 if self.pins is None else self.pins

    @property
    def disc_to_output(self) -> float:
        """``i_b = (1 − 1/i) z_c / z_p``: output rotation per disc rotation (relative to pins or carrier)."""
        return (1.0 - 1.0 / self.ratio) * self.cycloid_teeth / self.z_p

    @property
    def to_output(self) -> dict[str, float]:
        """Per stage, the factor that refers its angle to the output (document: 1/i, 1, 1)."""
        ib = self.disc_to_output if self.mode == "consistent" else 1.0
        return {"involute_stage": 1.0 / self.ratio, "cycloid_stage": ib, "crank_bearing": ib}

    @classmethod
    def from_design(cls, design, mode: str = DEFAULT_MODE) -> "LostMotionGeometry":
        if mode not in MODES:
            raise InputError(f"unknown mode {mode!r} (expected one of: {', '.join(MODES)})", key="mode")
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

        has = lambda *keys: all(k in design for k in keys)  # noqa: E731

        def d1():
            return (float(design["sun.module"]) * float(design["sun.teeth"]),
                    "sun.module × sun.teeth (reference pitch diameter)")

        def k1():
            a = float(design["cycloid.eccentricity"])
            return (a * float(design["pin.count"]) / float(design["pin.circle_radius"]),
                    "cycloid.eccentricity × pin.count / pin.circle_radius")

        def working_angle():
            alpha = float(design["sun.pressure_angle"])
            if not has("sun.teeth", "planet.teeth") or not 0 < alpha < math.pi / 2:
                return alpha, "= α (no planet.teeth in the design)"
            x = float(design.get("sun.profile_shift", 0.0)) + float(design.get("planet.profile_shift", 0.0))
            z = float(design["sun.teeth"]) + float(design["planet.teeth"])
            inv_w = involute(alpha) + 2.0 * math.tan(alpha) * x / z
            if not inv_w > 0:
                raise SpecError("profile shifts give a non-positive operating pressure angle", file=design.file,
                                key="planet.profile_shift")
            return inverse_involute(inv_w), "inv α_w = inv α + 2 tan α (x_s + x_pl)/(z_s + z_pl) (profile shifts)"

        alpha_w, alpha_w_how = working_angle() if "sun.pressure_angle" in design else (None, "")

        def centre_distance():
            m, z = float(design["sun.module"]), float(design["sun.teeth"]) + float(design["planet.teeth"])
            alpha = float(design["sun.pressure_angle"])
            return (m * z / 2 * math.cos(alpha) / math.cos(alpha_w),
                    "operating centre distance a' = sun.module × (sun.teeth + planet.teeth)/2 · cos α/cos α_w "
                    "(the crank axes are the planet axes)")

        need_d1 = "sun.pitch_diameter" not in design and not has("sun.module", "sun.teeth")
        need_r = "crank_bearing.centre_radius" not in design and not has("sun.module", "sun.teeth", "planet.teeth")
        need_k1 = "cycloid.short_amplitude_coefficient" not in design and not has("pin.count", "pin.circle_radius")
        try:
            if mode == "document":
                K = get("K", "crank_bearing.clearance_coefficient")
            else:
                K = 1.0
                origins["K"] = "1: three bearings 120° apart (derived; consistent mode)"
            z_p = None
            if "pin.count" in design:
                z_p = get("z_p", "pin.count")
            else:
                origins["z_p"] = "z_c + 1"
            if alpha_w is not None:
                origins["α_w"] = alpha_w_how
            return cls(
                pressure_angle=get("α", "sun.pressure_angle"),
                pitch_diameter=get("d1", "sun.pitch_diameter", None if need_d1 else d1),
                ratio=get("i", "reducer.ratio"),
                eccentricity=get("a", "cycloid.eccentricity"),
                cycloid_teeth=get("z_c", "cycloid.teeth"),
                K1=get("K1", "cycloid.short_amplitude_coefficient", None if need_k1 else k1),
                bearing_radius=get("r", "crank_bearing.centre_radius", None if need_r else centre_distance),
                bearing_K=K, mode=mode, working_pressure_angle=alpha_w, pins=z_p,
                origins=origins,
            )
        except SpecError as exc:
            raise exc.located(file=design.file) from None

    # -- linear coefficients (rad per mm) ----------------------------------------
    def coefficients(self, extra: dict[str, float] | None = None) -> dict[str, dict[str, float]]:
        """∂(stage angle)/∂(factor) in rad/mm, each stage at its own member (module docstring);
        ``extra``: ξ name -> ∂Δφ34/∂ξ.  Multiply by :attr:`to_output` for the output."""
        ca, d1 = math.cos(self.pressure_angle), self.pitch_diameter
        az = self.eccentricity * self.cycloid_teeth
        root = math.sqrt(1.0 - self.K1**2)
        if self.mode == "document":
            ta = math.tan(self.pressure_angle)
            inv = {"E_w": -2.0 / (d1 * ca), "Delta_a": 4.0 * ta / d1, "Delta_F_r": 2.0 * ta / d1}
            cyc = {"Delta_r_c": 1.0 / az, "Delta_r_p": 1.0 / (az * root)}
            brg = 1.0 / (self.bearing_K * self.bearing_radius)
        else:
            sw = math.sin(self.alpha_w)
            inv = {"E_w": -2.0 / (d1 * ca), "Delta_a": 4.0 * sw / (d1 * ca), "Delta_F_r": 2.0 * sw / (d1 * ca)}
            cyc = {"Delta_r_c": 2.0 / az, "Delta_r_p": 2.0 * root / az}
            brg = 1.0 / self.bearing_radius
        cyc.update(extra or {})
        return {"involute_stage": inv, "cycloid_stage": cyc, "crank_bearing": {"Delta_b": brg}}

    def output_coefficients(self, extra: dict[str, float] | None = None) -> dict[str, float]:
        """∂Δφ_t/∂(factor) at the output, rad/mm (the rates the 20-DOF backlash is compared with)."""
        w = self.to_output
        return {n: c * w[s] for s, cs in self.coefficients(extra).items() for n, c in cs.items()}

    def to_frame(self) -> pd.DataFrame:
        consistent = self.mode == "consistent"
        rows = [("α", "pressure angle", self.pressure_angle, "deg"),
                ("α_w", "operating pressure angle" + ("" if consistent else " (not used by the document)"),
                 self.alpha_w, "deg"),
                ("d1", "sun pitch diameter", self.pitch_diameter, "mm"),
                ("i", "overall ratio", self.ratio, "1"),
                ("a", "eccentricity", self.eccentricity, "mm"),
                ("z_c", "cycloid teeth", self.cycloid_teeth, "1"),
                ("z_p", "pins", self.z_p, "1"),
                ("K1", "short-amplitude coefficient", self.K1, "1"),
                ("r", "crank-bearing centre radius", self.bearing_radius, "mm"),
                ("K", "clearance coefficient", self.bearing_K, "1"),
                ("i_b", "disc to output, (1 − 1/i) z_c/z_p" + ("" if consistent else " (the document uses 1)"),
                 self.disc_to_output, "1")]
        return pd.DataFrame([{"symbol": s, "parameter": p, "value": float(units.from_base(v, u)),
                              "unit": units.label(u), "from": self.origins.get(s, "")} for s, p, v, u in rows])


# --------------------------------------------------------------------------- the Model
class LostMotionModel(Model):
    """Per-sample geometric lost motion: total and the three stage angles (rad; shown in arcmin).

    ``inputs``: the spec's factor names (each known, see module docstring);
    ``nominal``: base values of known factors the spec does not name;
    ``extra``: ξ name -> ∂Δφ34/∂ξ in rad/mm; ``extra_like``: ξ name -> the factor it acts like
    (``Delta_r_c`` / ``Delta_r_p``) where the study said so (used to translate ξ to other models).
    """

    def __init__(self, geometry: LostMotionGeometry, inputs, nominal: dict[str, float] | None = None,
                 extra: dict[str, float] | None = None, extra_sources: dict[str, str] | None = None,
                 extra_like: dict[str, str] | None = None):
        self.geometry = geometry
        self.extra = dict(extra or {})
        self.extra_sources = dict(extra_sources or {})
        self.extra_like = dict(extra_like or {})
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
        self.coef = geometry.coefficients(self.extra)
        self.outputs = (
            Quantity("lost_motion", "rad", "arcmin", f"total geometric lost motion at the output "
                                                     f"(doc 001, {geometry.mode} mode)"),
            Quantity("involute_stage", "rad", "arcmin", "Δφ12, involute stage at the input shaft"),
            Quantity("cycloid_stage", "rad", "arcmin", "Δφ34, cycloid stage (disc relative to the pins)"),
            Quantity("crank_bearing", "rad", "arcmin", "Δφ_b, crank-bearing clearance (disc relative to the carrier)"),
        )

    @property
    def mode(self) -> str:
        return self.geometry.mode

    def _column(self, X, name):
        if name in self.inputs:
            return X[:, self.inputs.index(name)]
        return np.full(len(X), self.nominal[name])

    def dependencies(self) -> dict[str, frozenset[str]]:
        """Each stage angle depends on its own factors (:meth:`LostMotionGeometry.coefficients`); the total on all."""
        coef = self.geometry.coefficients(self.extra)
        deps = {s: frozenset(n for n in coef[s] if n in self.inputs) for s in STAGES}
        return {"lost_motion": frozenset(self.inputs), **deps}

    def evaluate(self, X):
        X = self.check_input(X)
        w = self.geometry.to_output
        stages = []
        for s in STAGES:
            y = np.zeros(len(X))
            for name, c in self.coef[s].items():
                y = y + c * self._column(X, name)
            stages.append(y)
        total = sum(w[s] * y for s, y in zip(STAGES, stages))
        return np.column_stack([total, *stages])


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
    """Mean and tolerance per stage and in total, and σ of the linear model (arcmin).

    Columns: ``stage``, ``to_output`` (1/i for the involute stage; i_b or 1 for the others),
    ``mean``, ``T_doc`` (tolerance by the document's formulas as written; document mode only, NaN
    in consistent mode), ``sigma`` (from the factors' own σ), ``T_6sigma`` = 6σ.  The total row
    refers every stage to the output (means added, tolerances and σ by RSS).
    """
    g, K, m = geometry, ARCMIN_PER_RAD, moments
    coef = geometry.coefficients(extra)
    w = geometry.to_output
    rows = []
    for s in STAGES:
        c = coef[s]
        mean = K * sum(v * m[n].mean for n, v in c.items())
        sigma = K * rss([v * m[n].std for n, v in c.items()])
        if g.mode != "document":
            T = math.nan
        elif s == "involute_stage":
            # as written: D(j) = Σ (coefficient × T/6)²; T = √D K/d1
            ca, ta = math.cos(g.pressure_angle), math.tan(g.pressure_angle)
            D_j = (m["E_w"].band / (6 * ca)) ** 2 + (2 * m["Delta_a"].band / 2 * ta / 3) ** 2 + \
                (m["Delta_F_r"].band / 2 * ta / 3) ** 2
            T = math.sqrt(D_j) * K / g.pitch_diameter
        else:   # ξ terms: ∂Δφ34/∂ξ · T_ξ in the RSS
            T = K * rss([v * m[n].band for n, v in c.items()])
        rows.append((s, w[s], mean, T, sigma))
    frame = pd.DataFrame(rows, columns=["stage", "to_output", "mean", "T_doc", "sigma"])
    frame["T_6sigma"] = 6.0 * frame["sigma"]
    wt = frame["to_output"]
    total = {"stage": "lost_motion", "to_output": 1.0, "mean": float((frame["mean"] * wt).sum()),
             "T_doc": rss(frame["T_doc"] * wt), "sigma": rss(frame["sigma"] * wt)}
    total["T_6sigma"] = 6.0 * total["sigma"]
    return pd.concat([frame, pd.DataFrame([total])], ignore_index=True)


# --------------------------------------------------------------------------- study factory
@dataclass
class Options:
    """The keys of ``[model] kind = "lost_motion"``."""

    mode: str = option(DEFAULT_MODE, "every coefficient from the kinematics (consistent), or doc 001 as printed",
                       choices=MODES)
    cycloid_factor: list[Params] = option([], "further factors of the cycloid stage, each [[model.cycloid_factor]] "
                                              'with factor, derivative ("cycloid_radius" | "pin_radius" | {value, '
                                              'unit = "arcmin/um"}) and source')
    nominal: Params | None = option(None, "factor -> nominal value (mm or {value, unit}) of the model's own factors "
                                          "the spec does not give")


def build(o: Options, design, spec, error) -> LostMotionModel:
    """``[model] kind = "lost_motion"``: ``mode`` = "consistent" (default) | "document"; geometry from
    the design; optional ``[model.nominal]`` and ``[[model.cycloid_factor]]`` (``factor``,
    ``derivative`` = "cycloid_radius" | "pin_radius" | {value, unit = "arcmin/um"}, ``source``).
    A "…_radius" derivative takes the mode's coefficient of Δr_c / Δr_p; an explicit value is
    ∂Δφ34/∂ξ at the disc (referred to the output like the rest of the cycloid stage)."""
    if design is None:
        raise error(None, "the lost-motion model needs a design (study.design)")
    geometry = LostMotionGeometry.from_design(design, o.mode)
    base = geometry.coefficients()["cycloid_stage"]
    extra, sources, like = {}, {}, {}
    tables = o.cycloid_factor
    declared = {v for t in tables if isinstance(v := t.data.get("factor"), str)}   # a non-text one: refused below
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
            kind = t.str("derivative", choices=tuple(DERIVATIVE_LIKE))
            extra[name] = base[DERIVATIVE_LIKE[kind]]
            like[name] = DERIVATIVE_LIKE[kind]
        else:
            extra[name] = t.quantity("derivative", "arcmin/mm")
        sources[name] = t.str("source")
        t.finish()
    nom = o.nominal if o.nominal is not None else Params({})
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
    return LostMotionModel(geometry, spec.names, nominal, extra, sources, like)


from_study = ModelKind(Options, build, "doc 001's per-stage statistical geometric lost motion")
