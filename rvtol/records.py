"""Tables as JSON-able records (for ``summary.json`` and result ``summary()`` methods)."""
from __future__ import annotations

import numpy as np
import pandas as pd


def frame_records(df: pd.DataFrame) -> list[dict]:
    """A DataFrame as JSON-able records (NaN -> None), for ``Section.summary``."""
    out = []
    for rec in df.reset_index(drop=df.index.name is None).to_dict(orient="records"):
        clean = {}
        for k, v in rec.items():
            if isinstance(v, (np.floating, float)):
                v = None if not np.isfinite(v) else float(v)
            elif isinstance(v, np.integer):
                v = int(v)
            elif isinstance(v, np.bool_):
                v = bool(v)
            clean[str(k)] = v
        out.append(clean)
    return out
