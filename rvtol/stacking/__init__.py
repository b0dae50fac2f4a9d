"""Tolerance stack-up conventions beside the Monte Carlo, for any :class:`rvtol.model.Model` — every one of rvtol's.

=======================================  ===============================================================
module                                   what it gives
=======================================  ===============================================================
:mod:`rvtol.stacking.conventions`        worst case, RSS, MRSS (Bender, handbook, a given factor), the
                                         distributions' statistical stack, 6σ static and dynamic RSS (and
                                         the 1.5σ-shift convention); position zones as discs
:mod:`rvtol.stacking.slopes`             one-sided slopes of a kinked output (the side that hurts)
:mod:`rvtol.stacking.second_order`       the second-order moments of a curved output and its Pearson tails
:mod:`rvtol.stacking.worst_case`         the true extreme of a non-linear output over the bands (bounded
                                         optimisation, corners)
:mod:`rvtol.stacking.chain_conventions`  worst case, RSS and loop-method signs of a deviation chain's key
                                         characteristics (the stack-up model's ``stackup_linear``)
:mod:`rvtol.stacking.tail`               sub-ppm tail probabilities: FORM (β, Φ(−β)) and importance
                                         sampling about the most probable failure point
:mod:`rvtol.stacking.beside_monte_carlo` a study's conventions and tails beside its Monte Carlo (one result each)
:mod:`rvtol.stacking.analyses`           the study analyses ``stack_conventions`` and ``tail_probability``
                                         (laid out by :mod:`rvtol.stacking.texts`)
=======================================  ===============================================================

::

    sc = stack_conventions(spec, gradient_base, y0_base, output="gap", out_unit="um", out_base_unit="mm")
    sc.frame                                           # convention, low, high, half_width, sigma, source
    wc = true_worst_case(model, spec, "gap", evaluate)  # wc.low, wc.high, wc.x_low, wc.x_high
    est = tail_probability(model, spec, "gap", limit=120, side="upper", seed=1)
    est.estimates, est.reference, est.disagreements           # FORM, SORM, …, subset; the best; the flags
"""
from .conventions import StackConventions, handbook_mrss_factor, stack_conventions
from .tail import TailEstimate, tail_probability
from .worst_case import WorstCase, true_worst_case

__all__ = ["StackConventions", "TailEstimate", "WorstCase", "handbook_mrss_factor", "stack_conventions",
           "tail_probability", "true_worst_case"]
