"""Doc 001's screening estimate beside the 20-DOF torsion curve: the factor bridge and the backlash rates.

A sign-off judges the maker's figures on the hysteresis curve (lost motion at
±p % of rated torque, backlash at zero torque, rigidity b/a; ``../shared/
REFERENCE.md``), i.e. :class:`rvtol.models.torsion_curve.model.TorsionCurveModel`.  Doc 001's formula
(:mod:`rvtol.models.lost_motion.model`) is a fast screening estimate of the
geometric part.  To set the two side by side on the *same* reducers, one
sample's factors must drive both models; this module translates them.

**Doc 001 → 20-DOF** (per sample, linear; every 20-DOF name exists in
:mod:`rvtol.models.reducer_20dof.factors`):

========================  ===============================================  ==========================================
doc 001 factor            20-DOF factors                                   why
========================  ===============================================  ==========================================
``Delta_b`` (Δ)           ``delta_b[j,i] = Δ/2``, all six bearings          Δ is the radial internal clearance (total
                                                                           free movement); δ_b the free-play radius
``Delta_r_c``             ``delta_pin`` += Δr_c                            an equidistant modification opens Δr_c
                                                                           along the normal at every pin
ξ like ``Delta_r_c``      ``delta_pin`` += ξ                               e.g. a pin-roller undersize: the same gap
``Delta_r_p``             ``R_pin[k]`` = Δr_p for every pin k              the pin circle is the pins' mean radial
                                                                           position (+ outward)
ξ like ``Delta_r_p``      ``R_pin[k]`` += ξ
``E_w``, ``Delta_a``,     none: the 20-DOF's sun–planet mesh is            the involute play is in series with the
``Delta_F_r``             bilateral (no backlash)                          rest: added at the output as Δφ12/i
ξ with a given value      none                                             listed as not seen by the torsion curve
========================  ===============================================  ==========================================

**20-DOF → doc 001** (first order; what doc 001's one-number-per-family
formula can see of a 20-DOF sample):

* ``Delta_b`` = 2·min_j mean_i δ_b[j,i]: with unequal clearances a disc's
  translation evens out its three bearings, so to first order it turns
  2·mean(δ_b)/r (:mod:`rvtol.models.lost_motion.model`); the disc with less
  play ends the output's play (``delta_b`` as a group: the Table 3 pattern);
* ``Delta_r_c`` = the pin normal clearance (``delta_pin`` + ``delta_th``, and
  the mean over the pins of per-pin ones);
* ``Delta_r_p`` = mean_k ``R_pin[k]`` (the zeroth harmonic of the radial pin
  positions);
* anything else (cam, hole and carrier errors, harmonic patterns, …) is not
  in doc 001's formula: listed as unseen.

**Backlash rates** (:func:`backlash_rates`): central finite differences of the
20-DOF torsion curve's backlash (and lost motion) per doc-001 factor, from a
reference state with clearances (δ_b = 2 µm on all six bearings, 2 µm pin
clearance) so that each step is clearance-dominated; the consistent mode's
coefficients are held to them (``tests/models/lost_motion/test_lost_motion_modes.py``).

A model that is neither a :class:`LostMotionModel` nor a
:class:`rvtol.models.torsion_curve.model.TorsionCurveModel` can still be screened: it implements
``screening_inputs(X) -> {"lost_motion": (names, X_lm), "torsion_curve":
(names, X_tc)}`` (base units, one row per row of ``X``).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ...errors import InputError
from ..lost_motion.model import FACTORS, LostMotionGeometry, LostMotionModel
from ..torsion_curve.model import CAMS, TorsionCurveModel
from ..reducer_20dof.factors import TABLE3_DELTA_B
INVOLUTE = ("E_w", "Delta_a", "Delta_F_r")
#: reference state and step of the finite differences (mm): clearance-dominated, first order
RATE_REFERENCE = 0.002
RATE_STEP = 0.001
#: doc 001's K for the crank bearings where a design does not give it (doc 001, section 3)
DOC001_K = 1.5


def pin_names(z_b: int) -> tuple[str, ...]:
    return tuple(f"R_pin[{k}]" for k in range(1, z_b + 1))


@dataclass
class ScreeningInputs:
    """One set of samples in both vocabularies (base units)."""

    lm_names: tuple[str, ...]
    X_lm: np.ndarray
    tc_names: tuple[str, ...]
    X_tc: np.ndarray
    unseen_by_tc: tuple[str, ...] = ()     # doc-001 factors without a 20-DOF counterpart (the involute
                                           # ones excepted: their play is added in series at the output)
    unseen_by_lm: tuple[str, ...] = ()     # 20-DOF factors doc 001's formula does not have
    extra: dict = field(default_factory=dict)        # ξ -> ∂Δφ34/∂ξ of the screening model
    extra_like: dict = field(default_factory=dict)   # ξ -> "Delta_r_c" | "Delta_r_p"


# --------------------------------------------------------------------------- doc 001 -> 20-DOF
def lost_motion_to_torsion_curve(model: LostMotionModel, z_b: int, X) -> ScreeningInputs:
    """Rows of the lost-motion model's inputs → 20-DOF inputs (module table); nominals included."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    pins = pin_names(z_b)
    tc = CAMS + ("delta_pin",) + pins
    col = {n: X[:, model.inputs.index(n)] if n in model.inputs else np.full(len(X), model.nominal[n])
           for n in model.nominal}
    gap = np.zeros(len(X))
    radial = np.zeros(len(X))
    unseen = []
    for n in col:
        like = "Delta_r_c" if n == "Delta_r_c" else "Delta_r_p" if n == "Delta_r_p" else model.extra_like.get(n)
        if like == "Delta_r_c":
            gap = gap + col[n]
        elif like == "Delta_r_p":
            radial = radial + col[n]
        elif n in INVOLUTE or n == "Delta_b":
            continue
        elif n in model.inputs or model.nominal[n] != 0.0:
            unseen.append(n)
    X_tc = np.column_stack([np.repeat(0.5 * col["Delta_b"][:, None], len(CAMS), axis=1), gap[:, None],
                            np.repeat(radial[:, None], z_b, axis=1)])
    return ScreeningInputs(model.inputs, X, tc, X_tc, tuple(unseen), (), dict(model.extra), dict(model.extra_like))


# --------------------------------------------------------------------------- 20-DOF -> doc 001
def torsion_curve_to_lost_motion(model: TorsionCurveModel, X) -> ScreeningInputs:
    """Rows of the torsion-curve model's inputs → doc 001's ``Delta_b``, ``Delta_r_c``, ``Delta_r_p``."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    n, z_b = len(X), model.geometry.z_b
    cams = np.zeros((n, 2, 3))
    gap = np.zeros(n)
    radial = np.zeros(n)
    unseen = []
    for name, b, x in zip(model.inputs, model.factors.bindings, X.T):
        if b.base == "delta_b":
            if b.index:
                cams[:, b.index[0], b.index[1]] += x
            else:
                cams += x[:, None, None] * np.asarray(TABLE3_DELTA_B)[None]
        elif b.base in ("delta_pin", "delta_th"):
            gap += x / z_b if b.index else x
        elif b.base == "R_pin" and b.index:
            radial += x / z_b
        else:
            unseen.append(name)
    Delta_b = 2.0 * cams.mean(axis=2).min(axis=1)
    X_lm = np.column_stack([Delta_b, gap, radial])
    return ScreeningInputs(("Delta_b", "Delta_r_c", "Delta_r_p"), X_lm, model.inputs, X, (), tuple(unseen))


def screening_inputs(model, X, z_b: int) -> ScreeningInputs:
    """Both vocabularies for the rows ``X`` of ``model``'s inputs (``z_b`` pins; module docstring)."""
    if isinstance(model, LostMotionModel):
        return lost_motion_to_torsion_curve(model, z_b, X)
    if isinstance(model, TorsionCurveModel):
        return torsion_curve_to_lost_motion(model, X)
    own = getattr(model, "screening_inputs", None)
    if own is None:
        raise InputError(f"{type(model).__name__} gives neither doc 001's nor the 20-DOF's inputs "
                         "(it needs a screening_inputs(X) method)")
    d = own(X)
    (ln, Xl), (tn, Xt) = d["lost_motion"], d["torsion_curve"]
    return ScreeningInputs(tuple(ln), np.asarray(Xl, float), tuple(tn), np.asarray(Xt, float))


def screening_models(geometry: LostMotionGeometry, inputs: ScreeningInputs) -> dict[str, LostMotionModel]:
    """Doc 001's model in both modes for these inputs (``geometry`` in either mode; document K of the
    design, else doc 001's 1.5)."""
    out = {}
    for mode in ("document", "consistent"):
        g = geometry
        if g.mode != mode:
            K = geometry.bearing_K if geometry.mode == "document" else DOC001_K
            g = replace(geometry, mode=mode, bearing_K=K if mode == "document" else 1.0)
        base = g.coefficients()["cycloid_stage"]
        extra = {n: base[inputs.extra_like[n]] if n in inputs.extra_like else v for n, v in inputs.extra.items()}
        unknown = [n for n in inputs.lm_names if n not in FACTORS and n not in extra]
        if unknown:
            raise InputError(f"not a doc-001 factor: {', '.join(unknown)}", key="factor")
        out[mode] = LostMotionModel(g, inputs.lm_names, extra=extra, extra_like=inputs.extra_like)
    return out


# --------------------------------------------------------------------------- 20-DOF backlash rates
def rate_directions(z_b: int) -> dict[str, dict[str, float]]:
    """Per doc-001 factor, the 20-DOF factors one unit of it moves (module table)."""
    return {"Delta_b": {n: 0.5 for n in CAMS}, "Delta_r_c": {"delta_pin": 1.0},
            "Delta_r_p": {n: 1.0 for n in pin_names(z_b)}}


def backlash_rates(geometry, *, percent: float = 3.0, reference: float = RATE_REFERENCE,
                   step: float = RATE_STEP, evaluate=None) -> dict[str, dict[str, float]]:
    """d(backlash)/d(factor) and d(lost motion)/d(factor) of the 20-DOF torsion curve (rad/mm at the output).

    Central differences ``± step`` around ``reference`` clearance on the six crank bearings and the
    pins; ``evaluate(model, X)`` returns ``(Y, status)`` (default: the model's own evaluation; an
    analysis passes its ``ctx.evaluator``).
    """
    dirs = rate_directions(geometry.z_b)
    names = CAMS + ("delta_pin",) + pin_names(geometry.z_b)
    model = TorsionCurveModel(geometry, names, percent=percent)
    x0 = np.zeros(len(names))
    x0[:len(CAMS) + 1] = reference
    rows = []
    for d in dirs.values():
        v = np.zeros(len(names))
        for n, w in d.items():
            v[names.index(n)] = w
        rows += [x0 + step * v, x0 - step * v]
    Y, status = model.evaluate_with_status(np.array(rows)) if evaluate is None else evaluate(model, np.array(rows))
    if np.any(np.asarray(status) != 0):
        raise InputError("the 20-DOF torsion curve failed at the reference state of the backlash rates")
    i_lm, i_bl = [q.name for q in model.outputs].index("lost_motion"), [q.name for q in model.outputs].index("backlash")
    out = {}
    for k, f in enumerate(dirs):
        yp, ym = Y[2 * k], Y[2 * k + 1]
        out[f] = {"backlash": (yp[i_bl] - ym[i_bl]) / (2 * step), "lost_motion": (yp[i_lm] - ym[i_lm]) / (2 * step)}
    return out
