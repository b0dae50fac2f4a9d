"""The extremes of the TE curve over one output revolution, refined from a rotation sweep (issue 24).

Δθ_er, the peak-to-peak TE, is max − min of the continuous curve Δθ_ca(θ_c) over one output revolution.
A sweep knows the curve at its positions only, and the largest and smallest of those lie inside the
curve's own extremes: their peak-to-peak reads 0.15″ low on average and up to 0.83″ at the TE study's 36
positions per crank revolution, 0.55″ and 2.3″ at 12 (200 spec samples against a dense reference,
``studies/transmission_error.md`` §5).
:func:`te_extremes` finds the curve's extremes, to :data:`TOL_TE`, from the sweep and a few hundred
equilibria between its positions.

**The curve is not band-limited.**  The loaded pins take over from one another several times per pin pitch
(9.2° of crank angle for z_c = 39, two discs), each time with a kink of the curve: the TE of a reducer
with clearances is a smooth envelope (orders 1, 2, 40, 78, 80 …) with a saw-tooth of kinks on it, and
its extremes sit at kinks — the smallest TE (the largest wind-up) at the bottom of a V whose flanks
rise ≈ 0.3″ per degree of crank, the largest TE at a rounded top or at a small peak where a pin
engages.  Around the extreme lie competing ones within tenths of an arcsecond (the neighbouring pin
pitches and crank revolutions): at 36 positions per crank revolution the curve's extreme lay next to the
2nd or 3rd most extreme sampled one, not the first, for 19 of the 80 extremes of 40 spec reducers, at 12
up to the 28th.  Refining the sampled
extreme (Brent or parabolic steps from its neighbours) finds *a* local extreme, not the global one.

**What is refined: every interval that could hold a larger extreme** (branch and bound,
:func:`rvtol.models.reducer_20dof._kernels.qs_extreme`).  Over an interval [θ_k, θ_k+1] of width w the curve's slope
is taken to be at most S = κ·c, c the steepest chord |ΔTE|/Δθ of the interval and its two neighbours; through both
ends, such a curve stays above (TE_k + TE_k+1)/2 − S·w/2 (:func:`rvtol.models.reducer_20dof._kernels.interval_bound`;
for the largest TE the same with the sign turned).  Every interval whose bound lies beyond the best value found (by
more than ``tol_te``) is halved and its midpoint's equilibrium solved, level by level, until no bound does: the result
is then the curve's extreme within ``tol_te`` and the solver's tolerance — *if* the slope bound holds.  When it does:

* a smooth stretch: an interval's chord is the slope at one of its points; the bound fails only where the
  slope peaks inside an interval above κ times every neighbouring chord.  For a sinusoid of order n
  sampled N times per revolution the worst case (the peak on an interval's end) has chord / peak slope =
  sin(2πn/N)/(2πn/N): κ = π/2 covers every order with at least 4 positions per period — the sweep must
  *resolve* the orders of the envelope, not only sample them above Nyquist (at 2 per period the samples
  can all sit on zeros);
* a kink between straight branches: the neighbouring chords are the branch slopes, κ ≥ 1;
* a kink *inside* an interval whose chords average over several branches of the saw-tooth: its slope
  can be several times any chord around it, and a small peak (a pin engaging near the top of the
  envelope, ≈ 0.1″ above the chord between two positions) can hide there.  At 36 positions per crank
  revolution π/2 missed the largest TE of 2 of 600 spec samples (by 0.017″ and 0.007″; the refinement
  needed κ = 1.6 and 2.05 to find them); from 12 positions none (the envelope's own chords, 3× longer,
  leave room for the saw-tooth).  :data:`KAPPA` = 3 keeps 1.5× the largest κ found necessary.

What it cannot see: a feature narrower than an interval and steeper than κ times its neighbours.  With
κ = 3 the extremes of 600 spec samples from 36 and from 12 positions per crank revolution agree with a
reference from 288 positions (refined with κ = 3 or 4) within 2.2e-6″
(``studies/benchmarks/bench_transmission.py`` repeats the check on 24 or 100 samples).

Cost: the intervals whose bound reaches beyond the best are those of the competing Vs and tops: ≈ 340
equilibria per reducer from 36 positions per crank revolution (2.5 Newton iterations each: +21 % over the
1440 of the sweep), ≈ 750 from 12 (3.4 iterations each, more than the 12-position sweep itself); each
from a guess interpolated between its neighbours.  The coarser the sweep, the more of it the refinement
redoes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ... import units
from ...errors import InputError
from ..reducer_20dof import layout as L
from ..reducer_20dof.quasistatic import QuasiStaticSolver, SweepResult

#: slope bound over an interval in units of its steepest neighbouring chord (module doc: π/2 for a
#: sinusoid with at least 4 positions per period; a pin's kink inside an interval needed up to 2.05)
KAPPA = 3.0
#: tolerance on each extreme (rad): 1e-5″, a tenth of the TE an equilibrium's own force tolerance can
#: move (< 1e-4″ at tol_f = 1e-5 N, ``tests/models/transmission_error/test_transmission_resolution.py``)
TOL_TE = units.to_base(1e-5, "arcsec")
#: halvings after which an interval still admitting a larger extreme makes the result unresolved (an interval
#: of a sweep of 8 positions per crank revolution is then 2^-60 of it: far below the solver's resolution)
MAX_LEVELS = 60


@dataclass(frozen=True)
class Extremes:
    """Largest and smallest Δθ_ca over one output revolution and where (rad), with the work it took."""

    te_max: float
    theta_max: float
    te_min: float
    theta_min: float
    evaluations: int          # equilibria solved besides the sweep's
    iterations: int           # their Newton iterations
    status: int               # kernel status (0 = ok; codes in :mod:`rvtol.models.reducer_20dof.layout`)

    @property
    def ok(self) -> bool:
        return self.status == L.ST_OK

    @property
    def pp(self) -> float:
        """Δθ_er = max − min of the curve (rad)."""
        return self.te_max - self.te_min


def te_extremes(solver: QuasiStaticSolver, sweep: SweepResult, kappa: float = KAPPA,
                tol_te: float = TOL_TE, meas=None) -> Extremes:
    """The extremes of the TE curve of ``solver``'s reducer, refined from ``sweep``: a full output revolution of
    :meth:`~rvtol.models.reducer_20dof.quasistatic.QuasiStaticSolver.rotation` (positions uniform over [0, 2π), one
    carrier torque), all converged.  ``kappa`` and ``tol_te``: the slope bound and tolerance of the module doc.
    ``meas``: rows ``(n, a, b)`` of a test rig's measurement chain added to the curve (:mod:`.rig`): the extremes of
    the TE the rig reads."""
    th = sweep.theta_c
    n = th.size
    if n < 3 or not sweep.ok:
        raise InputError("refining the TE extremes needs a converged sweep of at least 3 positions")
    if not (th[0] == 0.0 and np.allclose(np.diff(th), 2.0 * np.pi / n, rtol=1e-9, atol=0.0)
            and np.all(sweep.torque == sweep.torque[0])):
        raise InputError("refining the TE extremes needs one output revolution at uniform positions and one torque")
    if not (kappa >= 1.0 and tol_te > 0.0):
        raise InputError(f"the slope bound must be >= 1 and the tolerance > 0, got {kappa}, {tol_te}")
    e, t = solver.errors, solver.table
    q = np.ascontiguousarray(sweep.q)
    out = []
    for sign in (-1.0, 1.0):
        args = (sign, th, q, 0.0, float(sweep.torque[0]), np.zeros(L.NDOF), solver.prm, e.err, e.pin_err, e.disc_h,
                solver.pin_cs, t.kind, t.idx, t.k0, t.pw, t.gap, t.ser, t.tab, solver.xs, solver.tol_f, solver.maxit,
                solver.maxstep, float(kappa), float(tol_te), MAX_LEVELS)
        if meas is None or len(meas) == 0:
            out.append(solver.kernels.qs_extreme(*args))
        else:
            out.append(solver.kernels.qs_extreme_curve(*args, np.ascontiguousarray(meas, dtype=float).reshape(-1, 3)))
    (st_hi, th_hi, te_hi, n_hi, it_hi), (st_lo, th_lo, te_lo, n_lo, it_lo) = out
    return Extremes(float(te_hi), float(th_hi), float(te_lo), float(th_lo), int(n_hi + n_lo), int(it_hi + it_lo),
                    int(st_hi if st_hi != L.ST_OK else st_lo))
