"""What a stack-up model is built of: its assembly graph, flows, fits, dimensions and sequences, as tables.

:func:`assembly_overview` returns an :class:`AssemblyOverview` (``plot()``: the assembly graph).
"""
from __future__ import annotations

from dataclasses import dataclass

import pandas as pd

from ... import units
from ...records import frame_records
from ...units import label
from .model import StackupModel


@dataclass
class AssemblyOverview:
    """``flows``: the deviation flows (doc 003 types f1–f5); ``fits``, ``dimensions`` (with their sources),
    ``sequences``: one row each."""

    model: StackupModel
    flows: pd.DataFrame
    fits: pd.DataFrame
    dimensions: pd.DataFrame
    sequences: pd.DataFrame

    def to_frame(self) -> pd.DataFrame:
        return self.fits

    def plot(self):
        from ...plotting.stackup import assembly_graph

        return assembly_graph(self.model.assembly, self.model.sequence)

    def summary(self) -> dict:
        m = self.model
        return {"assembly": m.assembly.name, "sequence": m.sequence.name, "flows": frame_records(self.flows),
                "fits": frame_records(self.fits), "dimensions": frame_records(self.dimensions)}


def assembly_overview(m: StackupModel) -> AssemblyOverview:
    asm, seq = m.assembly, m.sequence
    fits = pd.DataFrame([{
        "fit": f.name, "type": f.type, "base": f.base, "mate": f.mate,
        "clearance [µm]": None if f.clearance is None else f.clearance * 1e3,
        "length [mm]": f.length, "float": m.float_modes.get(f.name, "—") if f.is_clearance else "—",
        "role": "locates" if f.name in seq.locating else "closes (misfit KC)", "description": f.description}
        for f in asm.fits.values()])
    dims = pd.DataFrame([{"dimension": d.name, "value": units.from_base(d.value, d.unit), "unit": label(d.unit),
                          "source": d.source, "note": d.note} for d in asm.dimensions.values()])
    seqs = pd.DataFrame([{"sequence": s.name, "order": " → ".join([asm.ground] + [p for p, _ in s.steps]),
                          "locating fits": ", ".join(f for _, f in s.steps),
                          "closing fits": ", ".join(f.name for f in asm.closing_fits(s)),
                          "description": s.description} for s in asm.sequences.values()])
    return AssemblyOverview(m, asm.flows(seq), fits, dims, seqs)
