"""From measured parts to each reducer: per-unit prediction and selective assembly.

* :mod:`~rvtol.production.measured_parts` — measured parts as CSV files (one file per part family,
  one row per serial number, feature columns named as in the drawing spec, a measurement
  uncertainty per column) and the kit list of each reducer; :func:`load_measured_units`;
* :mod:`~rvtol.production.per_unit` — each kitted reducer predicted from its measured parts (the
  unmeasured factors sampled from the spec), with intervals and a per-unit verdict
  (:func:`predict_units`, :func:`samples_to_demonstrate`);
* :mod:`~rvtol.production.per_serial` — each reducer's end-of-line test updating its own prediction by Bayes'
  rule (:func:`read_end_of_line`, :func:`update_serials`);
* :mod:`~rvtol.production.selective` — grading into classes, matching rules and stock simulated
  inside the Monte Carlo (:func:`assemble`, :func:`take_from_stock`, :func:`optimise_limits`);
* :mod:`~rvtol.production.analyses` — the study analyses ``per_unit_prediction``,
  ``per_serial_update`` and ``selective_assembly``.

::

    from rvtol.mc import Evaluator
    from rvtol.production import FamilySource, load_measured_units, predict_units

    units = load_measured_units(spec, "kits.csv", [FamilySource(Path("cranks.csv"), ("crank_1", "crank_2"))])
    pred = predict_units(model, spec, units, n=1109, evaluator=Evaluator(), requirements=reqs, seed=1)
    print(pred.unit_frame())
"""
from .measured_parts import FamilySource, MeasuredUnits, load_measured_units, read_kit_list, read_part_family
from .per_serial import EndOfLine, SerialUpdates, read_end_of_line, update_serials
from .per_unit import UnitPredictions, predict_units, samples_to_demonstrate, unit_design
from .selective import (Classes, ClassToClassRule, GradedPart, Supply, TargetRule, assemble, optimise_limits,
                        take_from_stock)

__all__ = ["FamilySource", "MeasuredUnits", "load_measured_units", "read_kit_list", "read_part_family",
           "EndOfLine", "SerialUpdates", "read_end_of_line", "update_serials", "UnitPredictions", "predict_units", "samples_to_demonstrate", "unit_design",
           "Classes", "ClassToClassRule", "GradedPart", "Supply", "TargetRule", "assemble", "optimise_limits",
           "take_from_stock"]
