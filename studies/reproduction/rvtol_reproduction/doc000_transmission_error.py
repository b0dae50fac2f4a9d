"""Doc 000 (20-DOF transmission error, RV-80E): the sensitivity classes and printed sensitivities.

:func:`te_against_document` sets the document beside rvtol's five-point sensitivities of Δθ_er
(:func:`rvtol.models.transmission_error.sensitivity.te_sensitivity`): each factor's class as the document
states it against rvtol's class, and the two sensitivities it prints against rvtol's five-point values
over the same e range (verdicts by :mod:`.printed`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from rvtol.plugin import TESensitivityResult, frame_records

from .printed import PrintedFigures

#: printed sensitivities: figure key -> factor
SENSITIVITIES = {"S_E_c": "E_c", "S_delta_b": "delta_b"}


def document_class(printed: PrintedFigures, factor: str) -> str:
    """The document's class of a factor ("—": it gives none)."""
    f = printed.figures.get(f"class_{factor}")
    return "—" if f is None else f.value


def document_ranking(rank: pd.DataFrame, printed: PrintedFigures) -> pd.DataFrame:
    """rvtol's ranking with the document's class beside rvtol's and whether they agree."""
    d = rank.copy()
    doc = [document_class(printed, f) for f in d["factor"]]
    d.insert(list(d.columns).index("rvtol class"), "document class", doc)
    d["agrees"] = np.where(d["document class"] == "—", "—",
                           np.where(d["document class"] == d["rvtol class"], "yes", "no"))
    return d


def printed_sensitivities(fr: pd.DataFrame, printed: PrintedFigures) -> pd.DataFrame:
    """The printed sensitivities beside rvtol's five-point values over the same e range."""
    rows = []
    for key, name in SENSITIVITIES.items():
        g = fr[fr["factor"] == name]
        if g.empty:
            continue
        fig = printed[key]
        lo, hi = fig.value
        s = g["S"].to_numpy()
        rows.append({"factor": name, "printed S [arcsec/µm]": fig.text,
                     "rvtol S min [arcsec/µm]": np.nanmin(s), "rvtol S max [arcsec/µm]": np.nanmax(s),
                     "rvtol S at e = 1 µm": float(np.interp(1.0, g["magnitude"], s)),
                     "rvtol / printed (mean)": np.nanmean(s) / (0.5 * (lo + hi)),
                     "reproduced": fig.verdict(float(np.nanmean(s)))})
    return pd.DataFrame(rows)


@dataclass
class TEDocumentComparison:
    """``sensitivity``: rvtol's result; ``ranking``: with the document's classes; ``printed``: the printed
    sensitivities against rvtol's."""

    sensitivity: TESensitivityResult
    ranking: pd.DataFrame
    printed: pd.DataFrame

    def to_frame(self) -> pd.DataFrame:
        return self.printed

    def summary(self) -> dict:
        s = self.sensitivity
        return {"percent": s.percent, "magnitudes_um": list(s.magnitudes), "curve": frame_records(s.frame),
                "ranking": frame_records(self.ranking), "printed": frame_records(self.printed),
                "linearity": frame_records(s.linearity)}


def te_against_document(result: TESensitivityResult, printed: PrintedFigures) -> TEDocumentComparison:
    return TEDocumentComparison(result, document_ranking(result.ranking, printed),
                                printed_sensitivities(result.frame, printed))
