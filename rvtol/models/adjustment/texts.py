"""What the adjustment section says: its prose and the layout of an :class:`.assessment.AdjustmentAssessment`.

``layout(result, options) -> list of blocks`` (:mod:`rvtol.blocks`), named by
:mod:`rvtol.models.adjustment.analyses`.
"""
from __future__ import annotations

from ... import units
from ...blocks import Figure, Table, Text, figure_png

DESCRIBE = ("{title}. State x = KC angular errors ({states}) relative to the datum; x(k+1) = A x(k) + B u(k) + F(k) "
            "w(k), A = I (rigid), B = F (an adjustment acts like the part's error), y(k) = C(k) x(k) + v(k) measures "
            "the KC installed at step k. Adjustments u(k) = −K(k) x̂(k) are applied after the part of step k is "
            "installed and measured (x̂: Kalman estimate; exact without noise). K(k) from the backward Riccati "
            "recursion with P(N) = Q(N) = Q·C(N)ᵀC(N), no stage cost; R(k) = {adjustable:g} on adjustable KCs and "
            "{locked:g} elsewhere; Q → ∞ is computed exactly as the terminal constraint C(N) x(N) = 0 with least "
            "effort. Study model: Q = {Q}{off}.")
SWEEP = ("Final KC error (RSS of the final observations) and adjustment effort against the accuracy weight Q: the gain "
         "per unit of Q falls as Q grows (diminishing returns). The Monte Carlo batch includes the spec's measurement "
         "noise, which the adjustment cannot remove: it sets the floor of its RMS final error at large Q")


def describe(m) -> str:
    d = m.description
    return DESCRIBE.format(title=d.title, states=", ".join(d.state_names()), adjustable=d.effort_adjustable,
                           locked=d.effort_locked, Q=units.number_label(m.accuracy),
                           off="" if m.adjust else ", adjustment switched off")


def adjustment(res, o) -> list:
    m, d = res.model, res.model.description
    Q = units.number_label(m.accuracy)
    example = ", ".join(f"{n} = {units.from_base(v, 'mrad'):g}" for n, v in zip(m.w_names, res.part_errors))
    blocks = [Text(describe(m)),
              Table(res.F, "F: part errors (columns, in installation order) to KC errors δ (rows) [rad/rad]", "{:.3g}",
                    index=True),
              Table(res.steps, f"Assembly steps; every other KC has effort weight R = {d.effort_locked:g}"),
              Table(res.example.to_frame(), f"Example assembly (part errors {example} mrad): final KC errors and "
                                            "adjustment effort per accuracy weight Q", "{:.4g}"),
              Figure(figure_png(res.example.plot()), "Example assembly: KC errors after each step with the optimal "
                                                     "adjustment (solid) and without adjustment (dashed)")]
    if res.batch is not None:
        blocks += [Figure(figure_png(res.batch.plot()), f"Monte Carlo batch of the study's spec: RMS KC error after "
                                                        f"each step, Q = {Q}"),
                   Table(res.batch.to_frame(), "Monte Carlo batch: RMS KC error after each step", "{:.3g}")]
    return blocks + [
        Figure(figure_png(res.sweep.plot()), SWEEP),
        Table(res.marginal, "Diminishing returns: final error reduction per decade of Q", "{:.3g}"),
        Table(res.linear_map, f"Linear map at Q = {Q}: final KC error per unit part error [rad/rad]", "{:.4f}",
              index=True),
    ]
