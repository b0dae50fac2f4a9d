"""The extremes of the TE curve over one output revolution, refined from a rotation sweep (issue 24).

Δθ_er, the peak-to-peak TE, is max − min of the continuous curve Δθ_ca(θ_c) over one output revolution.
A sweep knows the curve at its positions only, and the largest and smallest of those lie below and above
the curve's own extremes — by up to 0.2″ at 36 positions per crank revolution and 2″ at 12 for the TE
study's spec reducers (``studies/transmission_error.md`` §5).  :func:`te_extremes` finds the curve's
extremes, to ``tol_te``, from the sweep and a few more equilibria between its positions.

**Why a local refinement of the sampled extremes is not enough.**  The TE of a reducer with clearances is
not a band-limited curve: the loaded pins take over from one another once per pin pitch (every 9.2° of
crank angle for z_c = 39), each time with a kink of the curve, and the smallest TE (the largest wind-up)
sits at such a kink between two smooth branches — a V of slopes up to ≈ 0.3″ per degree of crank.  The
largest TE is a rounded peak.  A sweep brackets a V only where it has a position on each flank near the
bottom; around the extreme there are competing Vs (the neighbouring pin pitches and crank revolutions,
within tenths of an arcsecond), so the sampled extreme need not lie next to the curve's: at 36 positions
per crank revolution the curve's minimum was next to the 2nd or 3rd smallest sampled minimum in 19 of 80
cases, at 12 next to the 21st.  Refining the sampled extreme (Brent or parabolic steps) finds *a* local
extreme, not the global one.

**What is refined: every interval that could hold a larger extreme** (branch and bound, in
:func:`._kernels.qs_extreme`).  Over an interval [θ_k, θ_k+1] of width w the curve's slope is taken to be at
most S = κ·c, c the steepest chord |ΔTE|/Δθ of the interval and its two neighbours; through both ends,
such a curve stays above (TE_k + TE_k+1)/2 − S·w/2 (:func:`._kernels.interval_bounds`; for the largest TE,
the same with the sign turned).  Every interval whose bound is beyond the best value found (less
``tol_te``) is halved and its midpoint's equilibrium solved, from the mean of its ends' equilibria; level by
level until no bound is: the result is then the curve's extreme within ``tol_te`` and the solver's
tolerance, *if* the slope bound holds.  When it holds:

* a kink between straight branches: the neighbouring chords are the branch slopes, κ ≥ 1;
* a smooth stretch: the chord of an interval is the slope at a point of it; the bound fails only where
  the slope peaks inside an interval above κ times every neighbouring chord.  For a sinusoid of order n
  sampled N times per revolution (w = 2π/N) the worst case (the peak on an interval's end) has chord /
  peak slope = sin(nw)/(nw): κ = π/2 (:data:`KAPPA`) covers every order with ≥ 4 positions per period,
  n ≤ N/4 — the sweep must *resolve* the curve's orders, not only sample them above Nyquist (at n = N/2
  the samples can all sit on zeros).  This is the band-limited part of the argument; the kinks are
  resolved by the halving itself, which brings positions onto both flanks of every V that could matter.

What it cannot see: a feature narrower than an interval and steeper than κ times its neighbours (a spike
between two positions).  The spec reducers have none at 8 or more positions per crank revolution — checked
against sweeps of 144 positions per crank revolution refined the same way: the extremes of 100 spec
samples agree within 4e-6″ from 8, 9, 12, 18 and 36 positions (``tests/test_transmission_extremes.py``
checks spec samples against a dense sweep and a fine local sweep at each extreme).

Cost: the intervals whose bound reaches beyond the best extreme are those of the flanks of the competing
Vs; at the TE study's 36 positions per crank revolution ≈ 60 equilibria per extreme (+5 % of the
sweep), at 12 ≈ 130, each from a guess between two solved neighbours (≈ 3.5 Newton iterations at the
first halvings, 1–2 at the last).  The coarser the sweep, the more of it the refinement redoes.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ... import units
from ...errors import InputError
from . import layout as L
from .quasistatic import QuasiStaticSolver, SweepResult

#: slope bound over an interval in units of its steepest neighbouring chord (module doc: a sinusoid with
#: at least 4 positions per period)
KAPPA = 0.5 * math.pi
#: tolerance on each extreme (rad): 1e-5″, a tenth of the TE an equilibrium's own force tolerance can
#: move (< 1e-4″ at tol_f = 1e-5 N, ``tests/test_transmission_resolution.py``)
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
    status: int               # kernel status (0 = ok; codes in :mod:`.layout`)

    @property
    def ok(self) -> bool:
        return self.status == L.ST_OK

    @property
    def pp(self) -> float:
        """Δθ_er = max − min of the curve (rad)."""
        return self.te_max - self.te_min


def te_extremes(solver: QuasiStaticSolver, sweep: SweepResult, kappa: float = KAPPA,
                tol_te: float = TOL_TE) -> Extremes:
    """The extremes of the TE curve of ``solver``'s reducer, refined from ``sweep``: a full output revolution
    of :meth:`.QuasiStaticSolver.rotation` (positions uniform over [0, 2π), one carrier torque), all
    converged.  ``kappa`` and ``tol_te``: the slope bound and tolerance of the module doc."""
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
        out.append(solver.kernels.qs_extreme(sign, th, q, 0.0, float(sweep.torque[0]), np.zeros(L.NDOF), solver.prm,
                                             e.err, e.pin_err, e.disc_h, solver.pin_cs, t.kind, t.idx, t.k0, t.pw,
                                             t.gap, t.ser, t.tab, solver.xs, solver.tol_f, solver.maxit,
                                             solver.maxstep, float(kappa), float(tol_te), MAX_LEVELS))
    (st_hi, th_hi, te_hi, n_hi, it_hi), (st_lo, th_lo, te_lo, n_lo, it_lo) = out
    return Extremes(float(te_hi), float(th_hi), float(te_lo), float(th_lo), int(n_hi + n_lo), int(it_hi + it_lo),
                    int(st_hi if st_hi != L.ST_OK else st_lo))
