"""Doc 000 (20-DOF transmission error, RV-80E): the sensitivity classes and printed sensitivities.

::

    [[analysis]]
    kind = "transmission_error_reproduction"
    printed = "../data/reproduction/doc000_transmission_error.toml"
    # and every key of transmission_error_sensitivity (factors, magnitudes, percent, title, key)

The study analysis ``transmission_error_sensitivity``
(:class:`rvtol.models.transmission.analyses.TESensitivity`) with the
document beside it: each factor's class as the document states it against
rvtol's class, and the two sensitivities it prints against rvtol's
five-point values over the same e range (verdicts by :mod:`.printed`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..models.transmission.analyses import TESensitivity
from .printed import load_printed

#: printed sensitivities: figure key -> factor
SENSITIVITIES = {"S_E_c": "E_c", "S_delta_b": "delta_b"}


class TEReproduction(TESensitivity):
    kind = "transmission_error_sensitivity"

    def read_printed(self, params, study) -> None:
        self.printed = load_printed(params.path_value("printed", Path(study.file).parent))
        self.printed.require(SENSITIVITIES)

    def document_class(self, factor: str) -> str | None:
        f = self.printed.figures.get(f"class_{factor}")
        return "—" if f is None else f.value

    def printed_table(self, fr: pd.DataFrame) -> pd.DataFrame:
        rows = []
        for key, name in SENSITIVITIES.items():
            g = fr[fr["factor"] == name]
            if g.empty:
                continue
            fig = self.printed[key]
            lo, hi = fig.value
            s = g["S"].to_numpy()
            rows.append({"factor": name, "printed S [arcsec/µm]": fig.text,
                         "rvtol S min [arcsec/µm]": np.nanmin(s), "rvtol S max [arcsec/µm]": np.nanmax(s),
                         "rvtol S at e = 1 µm": float(np.interp(1.0, g["magnitude"], s)),
                         "rvtol / printed (mean)": np.nanmean(s) / (0.5 * (lo + hi)),
                         "reproduced": fig.verdict(float(np.nanmean(s)))})
        return pd.DataFrame(rows)
