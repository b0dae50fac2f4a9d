"""Tolerance specification: factors, their distributions, correlation, requirements (:mod:`.factors`, read by
:mod:`.read` with the input forms of :mod:`.forms` and the geometric tolerancing of :mod:`.gdt`; :mod:`.requirements`).

File format (``data/specs/*.toml``)::

    [spec]
    name = "rv80e_lost_motion"
    description = "..."

    [[factor]]
    name = "dr_p"              # any name; the model decides which names it knows
    unit = "um"                # the unit every number of this factor is written in
    dist = "normal"            # see rvtol.distributions
    mean = 3.0
    tolerance = 1.0            # band ±T/2 read at sigma_level (3 by default)
    nominal = 3.0              # optional: nominal value for local sensitivity (default: the mean)
    part = "pin housing"       # optional: the drawing (part) the feature belongs to
    feature = "pin-groove circle ⌀153 js3"   # optional: the drawing feature and its callout
    group = "pin gear"         # optional: for group-wise sensitivity and allocation (default: the part)
    source = "..."             # optional: where the number comes from

    [[factor]]                 # drawing notation (rvtol.inputs.notation) instead of numbers:
    name = "bore"
    nominal = 25               # optional when the text has it ("25 H7")
    tolerance = "H7"           # "+0.10/-0.00", "±0.05", "5%", "24.95..25.05", "max 0.02", "H7/g6",
                               # "±0.05 Cpk 1.33 k 0.25", "1.000\" ±0.002\"", ...
    dist = "normal"            # optional (normal): the kind read over the drawing's band; any
                               # distribution key (sigma, shift, shape, ...) refines it
    unit = "mm"                # optional when the text has one ("25 H7" is in mm)
    direction = -1             # optional: the factor's sign/coefficient in a 1-D stack

    [[factor]]                 # ISO 2768 general tolerances (rvtol.inputs.iso2768)
    name = "flange_angle"
    unit = "deg"
    nominal = 30
    tolerance = "ISO 2768-m"   # an angle: ISO 2768-1 Table 3, by the length of its shorter side
    shorter_side = 35          # mm (required for an angle); broken_edge = true: a chamfer height or
                               # an external radius, Table 2 (a length)

    [[factor]]                 # a circular position zone: two coordinates of one zone
    name = "hole.x"            # (and a second factor "hole.y" with the same zone and tolerance)
    unit = "mm"
    tolerance = "⌀0.05"        # the zone's diameter: each coordinate normal, the radius Rayleigh
    zone = "hole"              # with 99.73 % inside the zone (rvtol.inputs.notation)

    [[factor]]                 # measured values (rvtol.inputs.measured)
    name = "bore_measured"
    unit = "mm"
    dist = "measured"
    data = "cmm/bores.csv"     # relative to this file; column = "bore", sheet = "CMM"
    method = "fit"             # fit (AIC-ranked families) | empirical | kde; measurement_sigma = 0.001
    tolerance = "25 H7"        # optional: the drawing's worst-case limits

A factor written in drawing notation keeps the drawing's worst-case limits (``Factor.limits``):
its tolerance band (:attr:`Factor.band`: worst case, five-point steps, allocation) is the
drawing's even when a process spec shifts the mean (``Cpk 1.33 k 0.25``).

A spec may also be a table (``.csv``/``.tsv``/``.xlsx``, :mod:`rvtol.inputs.table_spec`): one row
per factor, the same keys as columns; :func:`load_spec` reads either.

    [[factor]]                 # a FAMILY: N exchangeable features (40 pins, 40 pin grooves, ...)
    name = "pins[k].diameter_in_lot"   # the name holds "[k]" once
    multiplicity = 40          # -> N independent, identically distributed factors
    ...                        #    "pins[1].diameter_in_lot" ... "pins[40].diameter_in_lot"

A family table stands for ``multiplicity`` factors with the same distribution, drawn independently
(each copy is its own column of the sample; the copies are uncorrelated unless a
``[[correlation]]`` names them one by one).  ``[k]`` is replaced by ``[1]`` … ``[N]``; each copy
remembers its family (``Factor.family``) so a report can show the family as one row "×N"
(``ToleranceSpec.to_frame(families=True)``).  A name with ``[k]`` needs ``multiplicity`` and
``multiplicity`` needs a name with ``[k]``.

    [[correlation]]            # optional Gaussian copula, a pair or a block
    factors = ["a", "b"]
    matrix = [[1.0, 0.6], [0.6, 1.0]]

Requirements (in a study or ``data/requirements/*.toml``)::

    [[requirement]]
    output = "lost_motion"
    upper = 1.0
    unit = "arcmin"            # default: the output's display unit
    min_yield = 0.9973         # and/or min_cpk = 1.33; neither: yield >= 0.9973 (DEFAULT_MIN_YIELD); in (0, 1):
                               # 1 itself cannot be demonstrated by a finite sample and is refused
    confidence = 0.95          # of the bound the verdict uses
    basis = "lower_bound"      # pass on the lower confidence bound (default) or the "estimate"
    bound = "one-sided"        # the bound: one-sided at `confidence` (default), or "two-sided": the
                               # lower end of the two-sided interval (a (1 + confidence)/2 one-sided bound)
    interval = "clopper-pearson"   # yield interval: "clopper-pearson" (exact) or "wilson"
    cpk_method = "normal"      # the Cpk min_cpk judges: "normal" (normal theory, Bissell's bound) or
                               # "percentile" (ISO 22514-2 from the 0.135/50/99.865 % points, bootstrap bound)
    reading = "..."            # optional: how the figure is read (the maker's definition the output follows)
    source = "..."             # optional: where the limit comes from
    status = "assumed"         # optional: "confirmed" (read in the source), "recalled" (remembered, not
                               # read), "assumed" (an engineering assumption, its reasoning in `source`)

A requirement on a **population statistic** — a catalogue's typical (central) value, not a limit every
unit must meet — names it (``statistic = "median"`` or ``"mean"``) and the band it must lie in
(``lower``/``upper``); it takes no ``min_yield``/``min_cpk``.  It is judged on the statistic's confidence
interval (each end a one-sided bound at ``confidence``, or the two-sided interval with ``bound =
"two-sided"``): PASS when the interval lies inside the band, FAIL when it lies outside, UNDECIDED between
(:func:`rvtol.verdict.judge_statistic`)::

    [[requirement]]
    output = "torsion.torsional_rigidity"
    statistic = "median"
    lower = 156.8
    upper = 235.2
    unit = "N*m/arcmin"
"""
from .factors import Factor, ToleranceSpec
from .gdt import DatumShift, datum_shifts, zone_bonus
from .read import (TABLE_SUFFIXES, factor_from_params, factors_from_params, load_spec, load_table_spec, merge_specs,
                   spec_from_table)
from .requirements import (YIELD_INTERVALS, Requirement, load_requirements, read_requirements_file,
                           requirements_from_tables)

__all__ = ["DatumShift", "Factor", "Requirement", "TABLE_SUFFIXES", "ToleranceSpec", "YIELD_INTERVALS", "datum_shifts",
           "factor_from_params", "factors_from_params", "load_requirements", "load_spec", "load_table_spec",
           "merge_specs", "read_requirements_file", "requirements_from_tables", "spec_from_table", "zone_bonus"]
