"""``PinRingPreloadModel``: the discs in their pin ring as the maker judges them — the no-load preload over a full
output revolution (``kind = "pin_ring_preload"``; issue 39).

A maker does not ask that no pin touch the disc at zero torque (a built pin set has a scatter of a micrometre or
two per pin about its fitted clearance: some pins touch in about half the reducers, studies/build.md §3); he asks
how tight the ring is where they do — the preload the interfering pins carry and the drag it adds to the no-load
running torque, over a whole turn of the output (every pin meets every part of the disc's profile once a crank
revolution, the ring's and the profile's patterns move against each other once an output revolution).

The reducer here is the 20-DOF model's (:mod:`rvtol.models.reducer_20dof`), turned by its input through one output
revolution **with no load on the output** (:meth:`~rvtol.models.reducer_20dof.quasistatic.QuasiStaticSolver.rotation`
at zero torque): each disc is located by its three crank eccentrics through their needle rows (with each row's
clearance), the cranks by their tapered-roller pairs, the carrier by the main bearing, and the output turns freely
(the carrier finds its own angle). A pin whose normal clearance the disc's place closes is compressed; the elastic
equilibrium spreads that interference over the pin contacts and everything in series and in parallel with them
(the contact laws and the compliance chain of the design: Palmgren's line-contact law of the pin–flank contact,
the pin in its groove, the needle rows, the crank supports, the carrier). Per position the model reads:

* the largest pin contact force — the **preload** (N; zero where no pin is closed);
* the **interference** of the most loaded pin — its contact's approach beyond its clearance, the overlap the
  rigid parts would have (the pin contact's deflection with everything in series with it, µm);
* the **pin drag** — the friction torque the preloaded pins put on the output as it turns: the disc rolls about
  the pitch point P (its instantaneous centre relative to the pin ring: the eccentric turns at −z_c times the disc's
  rate), so the disc's point at pin k's contact moves tangentially by λ_k = |PC| per radian of the output, and the
  free pin between flank and groove rolls on one and slides on the other (its moment balance makes the two tangential
  forces equal): it dissipates μ_pin F_k λ_k per radian, T_pins = μ_pin Σ F_k λ_k (first order in μ: the equilibria
  are frictionless; μ_pin the design's boundary coefficient, :mod:`rvtol.models.reducer_20dof.friction`);
* the **no-load torque** — the pins' drag plus the needle rows' and the crank supports' moments μ P d/2 (the same
  module's estimates; the preloaded pairs drag with no load at all), each turning z_b radians per output radian,
  referred to the input (÷ i). Churning, seals and the main bearing are not modelled: it is a lower bound of
  what a test stand reads.

Outputs (the largest over the revolution): ``preload_max`` (N), ``interference_max`` (mm → µm),
``pin_drag_max`` (N·mm → N·m, at the output), ``no_load_torque_max`` (N·mm → N·m, at the input), ``preloaded_pins_max``
(the most pins preloaded at one position, both discs). A reducer whose pins all keep clearance has zeros.

The disc's tilt is not here (the 20-DOF model is planar): a tilted disc's two faces meet a pin at approaches
that differ by b·tilt across its width b; the preload read here is that of the mid-plane (a line contact's
force follows its mean approach while the whole length is in contact).
"""
from __future__ import annotations

import numpy as np

from ...design import Design
from ...errors import InputError
from ...model import STATUS_NONFINITE, Model, Quantity
from ..reducer_20dof import _kernels as K
from ..reducer_20dof import layout as L
from ..reducer_20dof.factors import ErrorFactors, negative_clearance
from ..reducer_20dof.friction import crank_support_p0
from ..reducer_20dof.geometry import RVGeometry, geometry_from_design
from ..reducer_20dof.quasistatic import MIN_PER_CRANK_REV, QuasiStaticSolver, SweepResult
from ._kernels import noload_contacts

#: positions per crank revolution of the no-load sweep (the TE sweep's default is 36, the sign-off's 24)
DEFAULT_PER_CRANK_REV = 12

OUTPUTS = (
    Quantity("preload_max", "N", "N", "largest pin contact force with no load on the output, over one output "
                                      "revolution (the pins' preload; 0: every pin keeps clearance)"),
    Quantity("interference_max", "mm", "um", "the most loaded pin's approach beyond its clearance at no load (the "
                                             "overlap of the rigid parts, taken up elastically)"),
    Quantity("pin_drag_max", "N*mm", "N*m", "largest friction torque of the preloaded pins at the output over the "
                                            "revolution (the no-load running torque the pin preload adds)"),
    Quantity("no_load_torque_max", "N*mm", "N*m", "largest no-load friction torque referred to the input: pins, "
                                                  "needle rows and the preloaded crank supports (no churning, no seals)"),
    Quantity("preloaded_pins_max", "1", "1", "most pins carrying a preload at one position (both discs)"),
)


class PinRingPreloadModel(Model):
    """The no-load preload of the pin ring over one output revolution (module docstring); the inputs are the 20-DOF
    model's error factors (a study maps them as for the torsion curve: ``same_inputs_as``)."""

    status_reasons = {**Model.status_reasons, **L.STATUS_REASONS,
                      L.ST_BAD_CLEARANCE: "negative bearing clearance in the sample (clearances must be >= 0)"}

    def __init__(self, design: Design | RVGeometry, inputs, *, per_crank_rev: int = DEFAULT_PER_CRANK_REV,
                 harmonic: int = 2, tol_f: float = 1e-5, maxit: int = 200, compliance_chain: bool = True):
        self.geometry = design if isinstance(design, RVGeometry) else geometry_from_design(design, compliance_chain)
        if self.geometry.friction is None:
            raise InputError("the pin drag needs the design's [friction] coefficients", key="friction")
        if per_crank_rev < MIN_PER_CRANK_REV:
            raise InputError(f"per_crank_rev must be >= {MIN_PER_CRANK_REV}, got {per_crank_rev}", key="per_crank_rev")
        self.inputs = tuple(inputs)
        self.factors = ErrorFactors(list(self.inputs), self.geometry.z_b, harmonic)
        self.input_units = tuple(self.factors.units)
        self.outputs = OUTPUTS
        self.per_crank_rev = int(per_crank_rev)
        self.solver_options = dict(tol_f=float(tol_f), maxit=int(maxit))

    def solver(self, x) -> QuasiStaticSolver:
        """The quasi-static solver of the reducer of row ``x`` (with the design's friction)."""
        return QuasiStaticSolver(self.geometry, self.factors.state(np.asarray(x, dtype=float)), **self.solver_options)

    def sweep(self, x) -> tuple[QuasiStaticSolver, SweepResult]:
        """The no-load revolution of the reducer of row ``x``."""
        s = self.solver(x)
        return s, s.rotation(0.0, self.per_crank_rev)

    def contacts(self, solver: QuasiStaticSolver, r: SweepResult, kernel=noload_contacts) -> dict[str, np.ndarray]:
        """At every equilibrium of ``r``: the pins' forces, approaches ``G q + offset`` (mm, > 0: compressed) and the
        distance λ = |PC| from the pitch point to the contact point (mm), ``[positions, N_DISC·z_b]``, and the needle
        rows' and crank supports' resultants (:mod:`._kernels`)."""
        t, e, g = solver.table, solver.errors, self.geometry
        n, m = r.theta_c.size, L.N_DISC * g.z_b
        out = {k: np.zeros((n, m)) for k in ("force", "approach", "cos", "sin")}
        out["cams"], out["cranks"] = np.zeros((n, L.N_DISC * L.N_CRANK)), np.zeros((n, L.N_CRANK))
        kernel(np.ascontiguousarray(r.theta_c), np.ascontiguousarray(r.q), solver.prm, e.err, e.pin_err, e.disc_h,
               solver.pin_cs, t.kind, t.idx, t.k0, t.pw, t.gap, t.ser, t.tab, float(g.ecc), out["force"],
               out["approach"], out["cos"], out["sin"], out["cams"], out["cranks"])
        pe = g.z_b * g.ecc                                         # |O P|: the pitch point on the eccentric
        out["lam"] = -pe * out["cos"] + np.sqrt(g.r_pin_circle ** 2 - (pe * out["sin"]) ** 2) - g.r_pin
        return out

    def drag(self, c: dict[str, np.ndarray], preload=None) -> tuple[np.ndarray, np.ndarray]:
        """``(pins, total)`` per position: the friction torque at the output (N·mm) of the contacts ``c``
        (:meth:`contacts`) as the unloaded reducer turns (module docstring). The disc rolls about the pitch point P,
        so pin k slides by λ_k per radian of the output (at the flank or in its groove: the free pin rolls on one,
        slides on the other) against μ_pin F_k; each eccentric and each crank turns by z_b radians against its disc
        and the carrier (the crank's rate relative to the carrier, (i − 1) z_s/z_p = z_b) against the bearing moments
        μ P d/2 (the needle row's radial load; the crank resultant plus the preload's equivalent load P0:
        :mod:`rvtol.models.reducer_20dof.friction`'s estimates; each crank's P0 from its own ``preload``, N, where
        given)."""
        fr, zb = self.geometry.friction, self.geometry.z_b
        pins = fr.pin * np.sum(np.maximum(c["force"], 0.0) * c["lam"], axis=1)
        bearings = zb * (fr.needle * 0.5 * fr.needle_bore * np.abs(c["cams"]).sum(axis=1)
                         + fr.crank_support * 0.5 * fr.crank_support_bore
                         * (np.abs(c["cranks"]) + crank_support_p0(fr, preload)).sum(axis=1))
        return pins, pins + bearings

    def _row(self, x) -> tuple[np.ndarray, int]:
        y = np.full(len(self.outputs), np.nan)
        if not np.all(np.isfinite(x)):
            return y, STATUS_NONFINITE
        s = self.solver(x)
        if negative_clearance(s.errors):
            return y, L.ST_BAD_CLEARANCE
        r = s.rotation(0.0, self.per_crank_rev)
        if not r.ok:
            return y, r.failure
        c = self.contacts(s, r)
        pins, total = self.drag(c, s.errors.preload)
        p = int(np.argmax(r.rec[:, K.R_PIN_MAX]))
        loaded = r.rec[p, K.R_PIN_MAX] > 0.0
        interference = max(float(c["approach"][p].max()), 0.0) if loaded else 0.0
        npins = r.rec[:, K.R_NPIN0] + r.rec[:, K.R_NPIN1]
        y[:] = (r.rec[p, K.R_PIN_MAX], interference, pins.max(), total.max() / self.geometry.ratio, npins.max())
        return y, 0

    def evaluate_with_status(self, X):
        X = self.check_input(X)
        Y = np.full((X.shape[0], len(self.outputs)), np.nan)
        status = np.zeros(X.shape[0], np.int16)
        for n, x in enumerate(X):
            Y[n], status[n] = self._row(x)
        return Y, status

    def evaluate(self, X):
        return self.evaluate_with_status(X)[0]
