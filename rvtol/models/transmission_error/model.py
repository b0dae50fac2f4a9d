"""``TransmissionErrorModel``: the 20-DOF model as a :class:`rvtol.model.Model` over error factors.

Inputs are error factors (names and Table 3 patterns in :mod:`rvtol.models.reducer_20dof.factors`);
each row is one reducer, run over one full output revolution, either
quasi-static (prescribed input angle + light load torque: the test-rig TE
measurement; default) or Newmark-β at constant input speed (doc 000's method).
Outputs:

=====================  ========================================================  =======
``te_pp``              Δθ_er: peak-to-peak of Δθ_ca = θ_ca − θ_c over the rev.   arcsec
``te_mean``            mean Δθ_ca (elastic wind-up under the load torque)         arcsec
``pin_force_max``      largest cycloid–pin force over the revolution             N
``bearing_force_max``  largest cycloid–crank (needle) bearing force              N
``loaded_pins_min``    fewest pins carrying load on one disc                     1
``loaded_pins_mean``   mean number of loaded pins per disc                       1
``te_pp_rig``          with a test rig (``rig``): Δθ_er of the TE the rig reads  arcsec
                       (the reducer's plus its measurement chain, :mod:`.rig`)
=====================  ========================================================  =======

With a rig description (``rig``, :func:`.rig.load_rig`) the model also takes the measurement chain's inputs
(:data:`.rig.INPUTS`: the eccentricity of the output and input encoders' graduations, mm) and gives
``te_pp_rig``; :meth:`TransmissionErrorModel.run` then holds both curves (``TEResult.te_rig``).

Δθ_er is max − min of Δθ_ca; the document writes max|Δθ_ca| − min|Δθ_ca|,
which is the same while Δθ_ca keeps its sign (it does under load: the
wind-up dominates).  Quasi-static, max and min are the continuous curve's,
refined between the sweep's positions to 1e-5″ (:mod:`.extremes`); the other
outputs are those of the sweep's positions.  Newmark: the time steps' (tens
of thousands per revolution).  Failed rows (no convergence, lost contact, negative
clearance) get a status code with its reason, never numbers.

:meth:`TransmissionErrorModel.run` gives one reducer in full: the TE curve,
its order spectrum (orders per output revolution) and the forces per position;
:meth:`TransmissionErrorModel.order_table` names the error families expected
at each large order (:mod:`.orders`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ... import units
from ...design import Design
from ...errors import InputError
from ...model import STATUS_NONFINITE, Model, Quantity
from ...model_kind import ModelKind, existing
from ...options import option
from ..reducer_20dof import _kernels as K
from ..reducer_20dof import layout as L
from ..reducer_20dof.factors import ErrorFactors, ErrorState, negative_clearance
from ..reducer_20dof.geometry import RVGeometry, geometry_from_design
from ..reducer_20dof.newmark import NewmarkSolver
from ..reducer_20dof.quasistatic import MIN_PER_CRANK_REV, ContactSolveOptions, QuasiStaticSolver, SweepResult
from .extremes import Extremes, te_extremes
from .orders import order_spectrum, order_table, positions_for_order
from .rig import INPUTS as RIG_INPUTS
from .rig import Rig, load_rig, measurement_terms

MODES = ("quasistatic", "newmark")
DEFAULT_PER_CRANK_REV = 36

OUTPUTS = (
    Quantity("te_pp", "rad", "arcsec", "transmission error peak-to-peak Δθ_er over one output revolution"),
    Quantity("te_mean", "rad", "arcsec", "mean transmission error (elastic wind-up under the load torque)"),
    Quantity("pin_force_max", "N", "N", "largest cycloid–pin contact force"),
    Quantity("bearing_force_max", "N", "N", "largest cycloid–crank bearing force"),
    Quantity("loaded_pins_min", "1", "1", "fewest loaded pins on one disc"),
    Quantity("loaded_pins_mean", "1", "1", "mean number of loaded pins per disc"),
)
RIG_OUTPUT = Quantity("te_pp_rig", "rad", "arcsec", "TE peak-to-peak the test rig reads (reducer + measurement chain)")


@dataclass
class TEResult:
    """One reducer over one output revolution (TE in arcsec)."""

    mode: str
    theta_c: np.ndarray       # nominal carrier angle (rad)
    te: np.ndarray            # Δθ_ca (arcsec)
    sweep: SweepResult
    status: int
    reason: str
    factors: dict
    extremes: Extremes | None = None    # quasi-static: the curve's extremes between the positions (rad)
    te_rig: np.ndarray | None = None    # with a test rig: the TE it reads (arcsec), :mod:`.rig`
    extremes_rig: Extremes | None = None
    rig_terms: np.ndarray | None = None  # the measurement chain's rows (order, cos, sin) in rad

    @property
    def ok(self) -> bool:
        return self.status == 0

    @property
    def te_pp(self) -> float:
        """Δθ_er (arcsec): of the continuous curve (quasi-static), of the time steps (Newmark)."""
        if self.extremes is not None:
            return float(units.from_base(self.extremes.pp, "arcsec"))
        return float(self.te.max() - self.te.min())

    @property
    def te_pp_rig(self) -> float:
        """Δθ_er of the TE the rig reads (arcsec), NaN without a rig."""
        if self.extremes_rig is None:
            return float("nan")
        return float(units.from_base(self.extremes_rig.pp, "arcsec"))

    def spectrum(self, rig: bool = False) -> pd.DataFrame:
        """Order spectrum of the reducer's TE, or (``rig``) of the TE the rig reads where the model has a rig."""
        k, a = order_spectrum(self.te_rig if rig and self.te_rig is not None else self.te)
        return pd.DataFrame({"order [1/rev]": k, "amplitude [arcsec]": a})

    def top_orders(self, n: int = 8) -> pd.DataFrame:
        s = self.spectrum().iloc[1:]
        return s.sort_values("amplitude [arcsec]", ascending=False).head(n).reset_index(drop=True)

    def to_frame(self) -> pd.DataFrame:
        return self.sweep.to_frame()

    def plot(self, ax=None):
        from ...plotting.transmission import te_curve

        return te_curve(self, ax=ax)


class TransmissionErrorModel(Model):
    """Transmission error of one RV reducer per row of error factors (see module docstring).

    ``load_torque`` (N·mm, resisting) defaults to ``load_fraction`` (3 %) of the
    rated torque; ``per_crank_rev`` positions per crank revolution
    (quasi-static), or ``max_order``: the highest order of the TE spectrum the output needs, which
    sets ``per_crank_rev`` (:func:`.orders.positions_for_order`; give one of the two);
    ``output_speed`` (rad/s), ``steps_per_crank_rev`` and
    ``settle_periods`` for Newmark; ``harmonic`` of the Table 3 tooth patterns.
    """

    status_reasons = {**Model.status_reasons, **L.STATUS_REASONS,
                      L.ST_BAD_CLEARANCE: "negative bearing clearance in the sample (clearances must be >= 0)"}

    def __init__(self, design: Design | RVGeometry, inputs=(), mode: str = "quasistatic", *,
                 load_torque: float | None = None, load_fraction: float = 0.03, per_crank_rev: int | None = None,
                 max_order: int | None = None, harmonic: int = 2, output_speed: float = 15 * 2 * math.pi / 60,
                 steps_per_crank_rev: int | None = None, settle_periods: float = 50.0, centrifugal: bool = True,
                 tol_f: float = 1e-5, maxit: int = 200, compliance_chain: bool = True, rig: Rig | None = None):
        if mode not in MODES:
            raise InputError(f"unknown mode {mode!r} (expected one of: {', '.join(MODES)})", key="mode")
        self.geometry = design if isinstance(design, RVGeometry) else geometry_from_design(design, compliance_chain)
        self.mode = mode
        names = list(inputs)
        self.rig = rig
        rig_names = [n for n in names if n in RIG_INPUTS]
        if rig_names and rig is None:
            raise InputError(f"input {rig_names[0]!r} is a test rig's (the model needs rig = \"…\")", key="factor")
        if rig is not None and mode != "quasistatic":
            raise InputError("a test rig's measurement chain is modelled for the quasi-static TE only", key="rig")
        self._err_cols = np.array([k for k, n in enumerate(names) if n not in RIG_INPUTS], dtype=int)
        self._rig_cols = {n: k for k, n in enumerate(names) if n in RIG_INPUTS}
        self.factors = ErrorFactors([n for n in names if n not in RIG_INPUTS], self.geometry.z_b, harmonic)
        self.inputs = tuple(names)
        err_units = dict(zip(self.factors.names, self.factors.units))
        self.input_units = tuple(err_units.get(n, "mm") for n in names)
        self.outputs = OUTPUTS + ((RIG_OUTPUT,) if rig is not None else ())
        if load_torque is None:
            if not 0.0 < load_fraction <= 2.0:
                raise InputError(f"load_fraction must lie in (0, 2], got {load_fraction}", key="load_fraction")
            load_torque = load_fraction * self.geometry.rated_torque
        if not load_torque > 0:
            raise InputError(f"load torque must be > 0, got {load_torque}", key="load_torque")
        if max_order is not None:
            if per_crank_rev is not None:
                raise InputError("give per_crank_rev or max_order, not both (max_order sets per_crank_rev)",
                                 key="max_order")
            per_crank_rev = positions_for_order(int(max_order), self.geometry.z_b)
        per_crank_rev = DEFAULT_PER_CRANK_REV if per_crank_rev is None else per_crank_rev
        if per_crank_rev < MIN_PER_CRANK_REV:
            raise InputError(f"per_crank_rev must be >= {MIN_PER_CRANK_REV} (positions per crank revolution), "
                             f"got {per_crank_rev}", key="per_crank_rev")
        self.load_torque = float(load_torque)
        self.per_crank_rev = int(per_crank_rev)
        self.max_order = None if max_order is None else int(max_order)
        self.solver_options = dict(tol_f=float(tol_f), maxit=int(maxit))
        self.dynamic_options = dict(output_speed=float(output_speed), steps_per_crank_rev=steps_per_crank_rev,
                                    settle_periods=float(settle_periods), centrifugal=bool(centrifugal))
        if mode == "newmark":
            self.geometry.mass_matrix()  # raises early if the design has no inertia data

    def variant(self, inputs=None, mode: str | None = None) -> "TransmissionErrorModel":
        """The same reducer and options with other inputs and/or another solver."""
        return TransmissionErrorModel(self.geometry, self.inputs if inputs is None else inputs, mode or self.mode,
                                      load_torque=self.load_torque, per_crank_rev=self.per_crank_rev,
                                      harmonic=self.factors.harmonic, **self.dynamic_options, **self.solver_options,
                                      rig=self.rig)

    def dependencies(self) -> dict[str, frozenset[str]] | None:
        """Without a rig: every output on every input.  With one: the reducer's own outputs do not read the
        measurement chain's inputs (:data:`.rig.INPUTS`); ``te_pp_rig`` reads all."""
        if self.rig is None:
            return None
        own = frozenset(n for n in self.inputs if n not in RIG_INPUTS)
        return {**{q.name: own for q in OUTPUTS}, RIG_OUTPUT.name: frozenset(self.inputs)}

    # -- one reducer ------------------------------------------------------------------------
    def state(self, x) -> ErrorState:
        """The error state of a row ``x`` of the model's inputs."""
        return self.factors.state(np.asarray(x, dtype=float)[self._err_cols])

    def rig_terms(self, x) -> np.ndarray:
        """The measurement chain's TE terms (rows ``(n, a, b)``, rad) of a row ``x`` (none without a rig)."""
        if self.rig is None:
            return np.zeros((0, 3))
        x = np.asarray(x, dtype=float)
        v = {n: float(x[k]) for n, k in self._rig_cols.items()}
        g = lambda n: v.get(n, 0.0)  # noqa: E731
        return self.rig.terms(self.geometry.ratio, (g(RIG_INPUTS[0]), g(RIG_INPUTS[1])),
                              (g(RIG_INPUTS[2]), g(RIG_INPUTS[3])))

    def _sweep(self, st: ErrorState, terms=None) -> tuple[SweepResult, Extremes | None, Extremes | None]:
        """The revolution and, quasi-static, its TE extremes refined between the positions (:mod:`.extremes`), and
        those of the TE a rig reads with the measurement chain's ``terms`` (:mod:`.rig`; None without a rig)."""
        if self.mode == "quasistatic":
            solver = QuasiStaticSolver(self.geometry, st, **self.solver_options)
            r = solver.rotation(self.load_torque, self.per_crank_rev)
            if not r.ok:
                return r, None, None
            ext = te_extremes(solver, r)
            rig = None
            if terms is not None:
                rig = te_extremes(solver, r, meas=terms) if len(terms) else ext
            return r, ext, rig
        return NewmarkSolver(self.geometry, st, load_torque=self.load_torque, **self.dynamic_options,
                             **self.solver_options).run(), None, None

    def _row(self, x) -> tuple[np.ndarray, int, SweepResult | None, Extremes | None, Extremes | None]:
        y = np.full(len(self.outputs), np.nan)
        if not np.all(np.isfinite(x)):
            return y, STATUS_NONFINITE, None, None, None
        st = self.state(x)
        if negative_clearance(st):
            return y, L.ST_BAD_CLEARANCE, None, None, None
        terms = self.rig_terms(x) if self.rig is not None else None
        r, ext, ext_rig = self._sweep(st, terms)
        if not r.ok:
            return y, r.failure, r, None, None
        for e in (ext, ext_rig):
            if e is not None and not e.ok:
                return y, e.status, r, ext, ext_rig
        te = r.te
        rec = r.rec
        npins = rec[:, [K.R_NPIN0, K.R_NPIN1]]
        pp = ext.pp if ext is not None else te.max() - te.min()
        y[:len(OUTPUTS)] = (pp, te.mean(), rec[:, K.R_PIN_MAX].max(), rec[:, K.R_CAM_MAX].max(), npins.min(),
                            npins.mean())
        if ext_rig is not None:
            y[len(OUTPUTS)] = ext_rig.pp
        return y, 0, r, ext, ext_rig

    def evaluate_with_status(self, X):
        X = self.check_input(X)
        Y = np.full((X.shape[0], len(self.outputs)), np.nan)
        status = np.zeros(X.shape[0], np.int16)
        for n, x in enumerate(X):
            Y[n], status[n], *_ = self._row(x)
        return Y, status

    def evaluate(self, X):
        return self.evaluate_with_status(X)[0]

    def order_table(self, result: TEResult, top: int = 12, min_fraction: float = 0.01,
                    rig: bool = False, orders=()) -> pd.DataFrame:
        """The largest orders of ``result``'s TE (``rig``: of the TE the rig reads), each with the error families
        expected there (:mod:`.orders`; the measurement chain's terms among them); ``orders``: listed too,
        whatever their size."""
        x = [result.factors[n] for n in self.factors.names]
        use_rig = rig and result.te_rig is not None
        chain = result.rig_terms if use_rig else None
        return order_table(result.te_rig if use_rig else result.te, self.geometry, self.factors.bindings, x, top,
                           min_fraction, measurement=chain, orders=orders)

    def run(self, values: dict | np.ndarray | None = None) -> TEResult:
        """One reducer in full. ``values``: ``{factor: value in base units}`` (missing: 0) or a row."""
        if values is None:
            x = np.zeros(len(self.inputs))
        elif isinstance(values, dict):
            unknown = sorted(set(values) - set(self.inputs))
            if unknown:
                raise InputError(f"unknown factor name {unknown[0]!r} (model inputs: {', '.join(self.inputs)})",
                                 key="factor")
            x = np.array([float(values.get(n, 0.0)) for n in self.inputs])
        else:
            x = np.asarray(values, dtype=float).reshape(len(self.inputs))
        y, status, r, ext, ext_rig = self._row(x)
        reason = self.status_reasons.get(status, "") if status else ""
        if r is None:
            return TEResult(self.mode, np.zeros(0), np.zeros(0), None, status, reason, dict(zip(self.inputs, x)))
        te = units.from_base(r.te, "arcsec")
        terms = self.rig_terms(x) if self.rig is not None else None
        te_rig = None if terms is None else units.from_base(r.te + measurement_terms(terms, r.theta_c), "arcsec")
        return TEResult(self.mode, r.theta_c, te, r, status, reason, dict(zip(self.inputs, x)), ext, te_rig,
                        ext_rig, terms)


@dataclass
class Options(ContactSolveOptions):
    """The keys of ``[model] kind = "transmission_error"``."""

    mode: str = option("quasistatic", "quasi-static sweep of static equilibria, or Newmark-β dynamics", choices=MODES)
    load_torque: float | None = option(None, "the output load torque (default: load_fraction × rated)", unit="N*m",
                                       positive=True)
    load_fraction: float = option(0.03, "the load torque as a fraction of rated torque, when load_torque is not "
                                        "given", positive=True, max=2.0)
    per_crank_rev: int | None = option(None, "positions per crank revolution (default 36, or what max_order needs)",
                                       min=MIN_PER_CRANK_REV)
    max_order: int | None = option(None, "the highest order of the TE spectrum the study needs: the fewest positions "
                                         "that resolve it (rvtol.models.transmission_error.orders.positions_for_order)",
                                   min=1)
    output_speed: float = option(15 * 2 * math.pi / 60, "the output speed of the dynamic run (default 15 rpm)",
                                 unit="rpm", positive=True)
    steps_per_crank_rev: int | None = option(None, "Newmark time steps per crank revolution (default: automatic)",
                                             min=4)
    settle_periods: float = option(50.0, "periods of the lowest mode run before the dynamic TE is recorded (transients "
                                          "decay)", nonnegative=True)
    centrifugal: bool = option(True, "the discs' centrifugal force m_d e ω_p² in the dynamics")
    rig: Path | None = option(None, "a test rig's description (rvtol.models.transmission_error.rig): the measurement "
                                    "chain's inputs and the output te_pp_rig")

    def complete(self, study, error):
        if self.per_crank_rev is not None and self.max_order is not None:
            raise error("max_order", "give per_crank_rev or max_order, not both (max_order sets per_crank_rev)")


def build(o: Options, design: Design | None, spec, error) -> TransmissionErrorModel:
    if design is None:
        raise error("kind", "the transmission-error model needs [study] design = ...")
    rig = None
    if o.rig is not None:
        try:
            rig = load_rig(existing(o.rig, "rig", error))
        except InputError as exc:
            raise exc.located(file=str(o.rig)) from None
    return TransmissionErrorModel(design, spec.names, o.mode, load_torque=o.load_torque,
                                  load_fraction=o.load_fraction, per_crank_rev=o.per_crank_rev,
                                  max_order=o.max_order, harmonic=o.harmonic, output_speed=o.output_speed,
                                  steps_per_crank_rev=o.steps_per_crank_rev, settle_periods=o.settle_periods,
                                  centrifugal=o.centrifugal, tol_f=o.tol_force, maxit=o.max_iterations,
                                  compliance_chain=o.compliance_chain, rig=rig)


from_study = ModelKind(Options, build, "the 20-DOF transmission error over one output revolution (quasi-static "
                                       "or Newmark-β)")
