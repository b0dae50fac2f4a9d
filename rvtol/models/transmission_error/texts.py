"""What the transmission-error sections say: their prose and the layout of :mod:`.curve` and :mod:`.sensitivity`.

``layout(result, options) -> list of blocks`` (:mod:`rvtol.blocks`), named by
:mod:`rvtol.models.transmission_error.analyses`.
"""
from __future__ import annotations

from ...blocks import Figure, Table, Text, figure_png
from .sensitivity import HIGH_FRACTION, NEGLIGIBLE_FRACTION

CURVE = ("Configuration: {how}. Load torque {load:.4g} N·m resisting ({share:.3g} % of rated), {per_rev} positions per "
         "crank revolution ({per_out} per output revolution) for the quasi-static sweep; its Δθ_er is the curve's, from "
         "its largest and smallest values refined between the positions (marked).")
SPECTRUM = ("Order spectrum of the {mode} TE (orders per output revolution; {z_b} = crank rotation relative to the "
            "carrier, {z_c} = absolute crank/eccentric rotation; {mesh})")
ORDERS = ("Largest orders of the TE spectrum (≥ 1 % of the largest) and the error families expected there: active "
          "families (non-zero factors) whose orders contain it, or, where none does, products of two families' base "
          "orders (z_b = {z_b}, z_c = {z_c}, Z = z_b·z_c = {Z}; derivation in rvtol/models/transmission_error/orders.py)")

SENSITIVITY = ("As in the document: each factor of Table 3 in turn has magnitude e (with the Table 3 phase angles and "
               "patterns), every other error is zero; the five points span ±{percent:g} % of e and S is the five-point "
               "central derivative of Δθ_er (peak-to-peak TE over one output revolution, quasi-static, light load) — "
               "in arcsec per µm. The band around each curve spans the one-sided five-point derivatives at the ends "
               "of the interval.")
RANKING = ("Ranking by mean |S| over e; rvtol class: high ≥ {high:g} S_ref, negligible < {negligible:g} S_ref, low "
           "between, where S_ref = {s_ref:.3g} arcsec/µm is 1 µm of arc at the disc pitch radius z_c·e")
LINEARITY = "Linearity: Δθ_er(2e) / Δθ_er(e) (2 for a factor whose effect is proportional to its magnitude)"


def mesh_order_note(mesh: int, n: int) -> str:
    """Where the pin-mesh order shows in the spectrum of ``n`` positions per revolution (it aliases above n/2)."""
    if mesh <= n // 2:
        return f"{mesh} = pin mesh"
    alias = abs(mesh - n * round(mesh / n))
    return (f"the pin-mesh order {mesh} lies above the highest resolved order {n // 2} of {n} positions per "
            f"revolution and shows aliased at order {alias}")


ON_RIG = ("The TE the test rig ({rig}) reads, Δθ_er {pp:.4g}″: its largest orders, the measurement chain's (order 1: "
          "output encoder; order i: input encoder) named first")


def curve(res, o) -> list:
    m, g = res.model, res.model.geometry
    blocks = [Text(CURVE.format(how=res.how, load=m.load_torque / 1e3, share=100 * m.load_torque / g.rated_torque,
                                per_rev=m.per_crank_rev, per_out=m.per_crank_rev * g.z_b)),
              Table(res.factors, "Factor values of this reducer" + ("" if res.stage is None else
                                                                    f" (inputs of model {res.stage!r})"))]
    blocks += [Text(f"{mode}: the solver failed ({r.reason}).") for mode, r in res.failed.items()]
    good = res.good
    if not good:
        return blocks
    first = next(iter(good.values()))
    return blocks + [
        Table(res.solvers, "Transmission error and peak forces over one output revolution"),
        Figure(figure_png(res.plot("te")), "Transmission error Δθ_ca = θ_ca − θ_c over one output revolution"),
        Figure(figure_png(res.plot("spectrum")), SPECTRUM.format(mode=first.mode, z_b=g.z_b, z_c=g.z_c,
                                                                 mesh=mesh_order_note(g.z_c * g.z_b, first.te.size))),
        Table(res.attributed, ORDERS.format(z_b=g.z_b, z_c=g.z_c, Z=g.z_b * g.z_c), "{:.4g}"),
        Table(res.families(), "Error families and their base orders per output revolution"),
    ] + ([] if res.on_rig is None else [
        Table(res.on_rig, ON_RIG.format(rig=m.rig.name, pp=first.te_pp_rig), "{:.4g}")])


def ranking_caption(s_ref: float) -> str:
    return RANKING.format(high=HIGH_FRACTION, negligible=NEGLIGIBLE_FRACTION, s_ref=s_ref)


def sensitivity(res, o, ranking=None, classes: str = "rvtol's class") -> list:
    """The sensitivity section; ``ranking``: the ranking as shown (default the result's), coloured by ``classes``."""
    from ... import units

    unit = res.frame["S_unit"].iloc[0]
    rank = res.ranking if ranking is None else ranking
    blocks = [Text(SENSITIVITY.format(percent=res.percent)),
              Table(res.table(), f"Five-point sensitivity S of Δθ_er [{units.label(unit)}] against the magnitude e",
                    "{:.3g}"),
              Figure(figure_png(res.plot("S")), "Sensitivity of Δθ_er against e (Table 3 factors)"),
              Figure(figure_png(res.plot("te")), "Δθ_er at the centre of each stencil against e"),
              Table(rank, ranking_caption(res.s_ref), "{:.4g}"),
              Figure(figure_png(res.plot("ranking", rank)), f"Sensitivity ranking (log scale), coloured by {classes}")]
    return blocks


def linearity_and_notes(res) -> list:
    blocks = [Table(res.linearity_table(), LINEARITY, "{:.3g}")] if len(res.linearity) else []
    return blocks + [Text("Note: " + n) for n in res.notes]


def te_sensitivity(res, o) -> list:
    return sensitivity(res, o) + linearity_and_notes(res)
