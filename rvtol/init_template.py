"""``rvtol init [DIR]``: a first study that runs as written — a commented study file and its spec table.

The template is a real (small) tolerance stack: the axial gap of a shaft between two bearings in a
housing, plus the height of a gauge pin in a V-groove to show units through formulas.  Every key it
uses is explained where it stands; ``rvtol docs writing-a-study`` covers every key a study takes.
"""
from __future__ import annotations

from pathlib import Path

from .errors import InputError

STUDY = '''\
# A first rvtol study, written by `rvtol init`.  Run it:   rvtol run study.toml
# Check it without running:                              rvtol check study.toml
# Every key a study takes:                               rvtol docs writing-a-study

[study]
name = "my_first_study"              # the report goes to reports/my_first_study/
title = "Axial gap of the output shaft"
description = "A template: replace the parts in spec.csv and the formulas below with your own."
spec = "spec.csv"                    # the tolerance spec: one row per dimension (or a TOML file of [[factor]])

[model]
kind = "formula"                     # outputs written as formulas of the spec's factors
units = "checked"                    # (default) factors carry their units into the formulas: mm and um may be
                                     # mixed, sin/cos/tan get radians whatever unit an angle is given in, and
                                     # adding a length to an angle is an error at load time

[[model.output]]
name = "gap"
formula = "housing_depth - bearing_a - spacer - bearing_b"
unit = "mm"                          # the unit of the result (converted from the formula's units)
display_unit = "um"                  # the unit the report shows
description = "axial play of the shaft between the bearings"

[[model.output]]
name = "pin_height"                  # a gauge pin in a V-groove: the pin's top above the groove's vertex
formula = "pin_d / 2 * (1 + 1 / sin(groove_angle / 2))"
unit = "mm"                          # groove_angle is in degrees in spec.csv: sin() gets radians all the same

[[requirement]]
name = "axial play"
output = "gap"
lower = 100                          # in `unit` below
upper = 550
unit = "um"
min_yield = 0.9973                   # demonstrated at 95 % confidence (the one-sided lower bound must reach it)

[[requirement]]
name = "pin height"
output = "pin_height"
lower = 3.05
upper = 3.09
unit = "mm"
min_cpk = 1.33                       # and/or a minimum Cpk (judged on its lower confidence bound)

[sampling]
n = 5000                             # Monte Carlo samples (rvtol run --n N overrides)
method = "lhs"                       # random | lhs | sobol
seed = 1                             # the same seed gives the same result, bit for bit

[execution]
executor = "serial"                  # serial | process (every core) | dask

[report]
pdf = false                          # true: report.pdf beside report.html (needs WeasyPrint's Pango)

[[analysis]]
kind = "stack_conventions"           # worst case, RSS and the Monte Carlo side by side

[[analysis]]
kind = "local_sensitivity"           # which tolerance drives each output (five-point derivatives)
'''

SPEC = '''\
#spec,my_first_spec
#description,"Template spec written by rvtol init: one row per dimension"
# Columns: name (the factor's name in formulas), nominal and tolerance (drawing notation: ±0.05, +0.1/-0,
# 24.95..25.05, max 0.02, an ISO 286 class such as H7 with the nominal in its own column, or "25 H7" in one
# tolerance cell), distribution (normal at ±3σ unless said: uniform, triangular, truncnorm, ...), unit, source.
# A tolerance written as deviations needs its nominal: write 0 for a factor that is itself a deviation.
name,part,feature,nominal,tolerance,distribution,unit,source
housing_depth,housing,bearing seat depth,60,±0.05,normal,mm,drawing H-100
bearing_a,bearing A,width,18,+0/-0.12,normal,mm,bearing catalogue
spacer,spacer,length,23.8,±0.05,normal,mm,drawing S-200
bearing_b,bearing B,width,18,+0/-0.12,normal,mm,bearing catalogue
pin_d,gauge pin,diameter,2.54,±0.002,normal,mm,gauge pin class ZZ
groove_angle,V-block,groove angle,90,±0.1,normal,deg,drawing V-300
'''

FILES = {"study.toml": STUDY, "spec.csv": SPEC}


def write_template(folder: str | Path) -> list[Path]:
    """Write the template into ``folder`` (made if absent); refuse to overwrite a file."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise InputError("exists and is not a folder", file=str(folder), key="DIR")
    clash = [n for n in FILES if (folder / n).exists()]
    if clash:
        raise InputError(f"{', '.join(clash)} exist{'s' if len(clash) == 1 else ''} already: rvtol init writes a new "
                         "study only into a folder without one", file=str(folder), key="DIR")
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for name, text in FILES.items():
        (folder / name).write_text(text, encoding="utf-8")
        out.append(folder / name)
    return out
