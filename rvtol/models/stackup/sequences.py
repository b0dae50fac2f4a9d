"""The same factor samples through several assembly sequences, side by side.

:func:`sequence_models` builds the stack-up model of each sequence; :func:`compare_sequences` evaluates
them on the study's Monte Carlo samples and returns a :class:`SequenceComparison`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ...records import frame_records
from ...stats import percentile_ci
from ...units import label
from .model import StackupModel


@dataclass
class SequenceComparison:
    """The same factor samples through several assembly sequences (display units)."""

    sequences: list[str]
    outputs: dict[str, list]  # sequence -> Quantities
    Y: dict[str, np.ndarray]  # sequence -> (n, m) display units
    shown: list[str] = field(default_factory=list)          # the outputs the figure shows
    descriptions: dict[str, str] = field(default_factory=dict)

    def names(self, seq: str) -> list[str]:
        return [q.name for q in self.outputs[seq]]

    def common_outputs(self) -> list[str]:
        first = self.names(self.sequences[0])
        return [n for n in first if all(n in self.names(s) for s in self.sequences)]

    def column(self, seq: str, name: str) -> np.ndarray:
        return self.Y[seq][:, self.names(seq).index(name)]

    def unit(self, name: str) -> str:
        for s in self.sequences:
            if name in self.names(s):
                return self.outputs[s][self.names(s).index(name)].shown_unit
        raise KeyError(name)

    def to_frame(self) -> pd.DataFrame:
        allnames = list(dict.fromkeys(n for s in self.sequences for n in self.names(s)))
        rows = []
        for n in allnames:
            for s in self.sequences:
                if n not in self.names(s):
                    continue
                y = self.column(s, n)
                y = np.sort(y[np.isfinite(y)])
                rows.append({"output": n, "unit": label(self.unit(n)), "sequence": s, "mean": y.mean(),
                             "std": y.std(ddof=1), "P99.73": percentile_ci(y, 0.9973)[0], "max": y[-1],
                             "failed": int(len(self.column(s, n)) - len(y))})
        return pd.DataFrame(rows)

    def assemblability(self) -> pd.DataFrame:
        """Share of the samples with margin ≥ 0 where a clearance fit closes the loop (empty: none does)."""
        allnames = dict.fromkeys(n for s in self.sequences for n in self.names(s))
        margins = [n for n in allnames if n.endswith(".margin")]
        rows = []
        for s in self.sequences:
            for n in margins:
                if n in self.names(s):
                    y = self.column(s, n)
                    rows.append({"sequence": s, "closing fit": n.split("_misfit")[0],
                                 "share assemblable (margin ≥ 0) %": 100.0 * np.mean(y[np.isfinite(y)] >= 0)})
        return pd.DataFrame(rows)

    def plot(self, outputs=None):
        from ...plotting.stackup import sequence_histograms

        return sequence_histograms(self, outputs if outputs is not None else (self.shown or None))

    def summary(self) -> dict:
        return {"sequences": self.sequences, "statistics": frame_records(self.to_frame())}


def sequence_models(m: StackupModel, sequences) -> dict[str, StackupModel]:
    """``m``'s assembly through each sequence, with its factors, rotation, backend and float modes."""
    return {s: StackupModel(m.assembly, s, m.inputs, m.input_units, m.rotation, m.backend,
                            {k: v for k, v in m.float_modes.items()}) for s in sequences}


def compare_sequences(models: dict[str, StackupModel], X, evaluate, shown=None) -> SequenceComparison:
    """Every sequence's model on the factor rows ``X`` (paired comparison); ``shown``: the outputs to plot."""
    Y, outs = {}, {}
    for s, model in models.items():
        ev = evaluate(model, X, f"sequence {s}")
        Y[s] = np.column_stack([q.to_display(ev.Y[:, j]) for j, q in enumerate(model.outputs)])
        outs[s] = list(model.outputs)
    asm = next(iter(models.values())).assembly
    return SequenceComparison(list(models), outs, Y, list(shown or []),
                              {s: asm.sequences[s].description for s in models})
