"""What the stiffness sections say: their prose and the layout of each result of :mod:`.breakdown`.

``layout(result, options) -> list of blocks`` (:mod:`rvtol.blocks`), named by
:mod:`rvtol.models.stiffness.analyses`.
"""
from __future__ import annotations

from ... import units
from ...blocks import Figure, Table, Text, figure_png

HEADER = ("All figures at the output torque T = {torque:g} N·m (input locked), per disc T_c = {disc:.1f} N·m; the "
          "design's profile modifications Δr_p = {dr:g} µm, ΔR_p = {dR:g} µm unless stated.")
BREAKDOWN = ("{head} Equivalent torsional rigidity T/θ_Σ = {rigidity:.1f} N·m/arcmin. With doc 004's literal θ3 "
             "(tangential bearing deflection only) θ3 would be {theta3:.2f} arcsec.")
CONTACT = ("Loaded pins {pins}, largest force {force:.1f} N, F_max at the largest arm {ref:.1f} N, elastic cycloid "
           "rotation {beta:.2f} arcsec; equilibrium residual {residual:.1e}.")
#: the title of the stiffness_breakdown analysis' second section
CONTACT_TITLE = "Cycloid–pin load distribution (doc 004's iterative contact solution)"


def header(res) -> str:
    """The sentence every stiffness section opens with: the torque and the modifications."""
    return HEADER.format(torque=units.from_base(res.torque, "N*m"), disc=units.from_base(res.disc_torque, "N*m"),
                         dr=res.modifications[0] * 1e3, dR=res.modifications[1] * 1e3)


def angles(res, o, head: str | None = None, caption: str = "Torsion-angle components at the output") -> list:
    return [Text(BREAKDOWN.format(head=head or header(res), rigidity=res.rigidity, theta3=res.tangential_theta3)),
            Table(res.components, caption, "{:.4g}"),
            Figure(figure_png(res.plot()), "Components of the elastic torsion angle (rvtol)"),
            Table(res.versus_torque, "Components against the output torque", "{:.4g}")]


def contact(res, o) -> list:
    cs = res.contact
    return [Text(CONTACT.format(pins=int(cs.contacts[0]), force=cs.max_force[0], ref=cs.F_ref[0],
                                beta=units.from_base(cs.beta[0], "arcsec"), residual=cs.equilibrium_residual()[0])),
            Table(res.pins, "Pins on the loaded side: clearance, force and single-pair stiffness k_b", "{:.4g}"),
            Figure(figure_png(res.plot()), "Pin forces and initial clearances"),
            Table(res.versus_torque, "Largest pin force and contact pairs against the torque", "{:.4g}")]
