"""Regenerate the SYNTHETIC serial batch of the per-serial study (data/measurements/rv80e_serials_synthetic/).

NOT measurements of any reducer: a batch with a known truth, to show what the end-of-line update does
(studies/rv80e_per_serial.toml, studies/production.md §8).

* **Parts and kits** — eight reducers RV80E-T001…T008, drawn and "measured" exactly as the production study's
  synthetic parts (studies/rv80e_synthetic_measured_parts.py: the drawing spec's sample per reducer, readings =
  truth + normal error of the inspection plan's u), from the seed SEED below.  The crankshafts are written a
  second time as the inspection room would send them: a QIF 3.0 MeasurementResults document in mm
  (``synthetic_crankshafts.qif``, each reading with its ``combinedUncertainty``) with its mapping file
  (``synthetic_crankshafts_qif_map.csv``); the study reads the QIF file.
* **End-of-line records** (``synthetic_end_of_line.csv``) — each reducer's true factor values (its parts' truth;
  the factors outside the drawing spec — the study's process spread — from the study's spec, sub-stream
  ``synthetic_eol`` of SEED) through the study's own model: lost motion, backlash and rigidity b/a of its hysteresis
  test on every reducer, TE peak-to-peak on the first four only (a TE run is not every unit's test), each plus a
  normal error of the rig's uncertainty U_RIG (ESTIMATES, not a rig's data sheet: an output encoder of ±1″ class
  and the zero-torque readings' repeatability for the angles; the torque cell's 0.5 % and the angle span's
  reading for b/a; a TE rig's ±2″).
* **End-of-line curves** (``curves/<reducer>.csv``) — each reducer's hysteresis test as the rig records it: the
  20-DOF torsion stage's curve at its true factors (input locked, 0 → +T → −T → 0, with friction: the loop the
  model reads its figures from), each angle plus a normal error of U_CURVE (an output encoder's ±1″ class: an
  ESTIMATE) — torque, angle, sigma; what ``curves`` in the study reads by the maker's definitions.
* **The truth** (``synthetic_truth.csv``) — every output the study shows, at each reducer's true factors,
  without rig error: what the posterior intervals can be checked against, which no real batch has.

    PYTHONPATH=. python studies/rv80e_synthetic_serials.py        # about a minute (the model's first call compiles)
"""
from __future__ import annotations

import csv
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import make_inspection_fixtures as fixtures  # noqa: E402
import rv80e_synthetic_measured_parts as parts  # noqa: E402
from rvtol.sampling import sample, substream, substream_seed  # noqa: E402
from rvtol.study import load_study  # noqa: E402

ROOT = HERE.parent
OUT = ROOT / "data/measurements/rv80e_serials_synthetic"
PRODUCT = HERE / "rv80e_production.toml"    # the sign-off's product without its build: the per-serial study's model
SEED = 20261129
REDUCERS = 8
#: the rig's standard uncertainty (k = 1) per reading, in the output's display unit — ESTIMATES (module docstring)
U_RIG = {"reducer.lost_motion": 0.02, "reducer.backlash": 0.02, "torsion.torsional_rigidity": 2.0, "te.te_pp": 1.0}
#: the outputs of the per-serial study (studies/rv80e_per_serial.toml: the requirements' and the readings' outputs —
#: the reducer's figures read by the rig's software, the 20-DOF loop's (torsion.*) read from the curves —, the rigidity
#: the customer's incoming test reads, 50-100 % of rated torque)
OUTPUTS = ["reducer.lost_motion", "reducer.backlash", "torsion.lost_motion", "torsion.backlash",
           "torsion.torsional_rigidity", "torsion.rigidity_50_100",
           "te.te_pp", "disc_location.disc_1.tilt", "disc_location.disc_2.tilt", "stackup.crank_1_axis.tilt",
           "stackup.crank_2_axis.tilt", "stackup.crank_3_axis.tilt", "pin_preload.pin_drag_max"]
U_CURVE = 0.5                      # arcsec: standard uncertainty of each angle of a recorded hysteresis curve (ESTIMATE)
TE_UNITS = 4                       # the reducers whose end-of-line test includes a TE run
HEADER = "SYNTHETIC end-of-line batch of the RV-80E -- NOT measurements of any reducer (seed {seed})"


def crankshafts_as_qif(csv_path: Path) -> None:
    """The crankshaft family's CSV as a QIF 3.0 document in mm (each reading with its u) and its mapping."""
    rows = [r for r in csv.reader(csv_path.open(encoding="utf-8")) if r and not r[0].startswith("#")]
    header, u_row, body = rows[0], rows[1], rows[2:]
    features = [h.split(" [")[0] for h in header[1:]]
    names = [f.upper().replace(".", "_") for f in features]
    chars = tuple((n, "LinearCoordinate", "mm", 0.0, 0.010) for n in names)
    qif_parts = [(r[0], [(float(v) / 1000.0, float(u) / 1000.0) for v, u in zip(r[1:], u_row[1:])]) for r in body]
    doc = fixtures.qif_document(chars, qif_parts, linear_units=(("mm", 0.001),))
    (OUT / "synthetic_crankshafts.qif").write_bytes(doc)
    with (OUT / "synthetic_crankshafts_qif_map.csv").open("w", encoding="utf-8", newline="") as fh:
        fh.write("# synthetic_crankshafts.qif -> the crankshaft's features (u: each value's combinedUncertainty)\n")
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["characteristic", "feature", "reading", "u [um]"])
        w.writerows([n, f, "value", ""] for n, f in zip(names, features))


def write_curves(model, X, names, rng) -> None:
    """Each reducer's hysteresis curve (module docstring) from the composed model's torsion stage."""
    from rvtol import units

    env, _ = model.environment(X)
    stage = next(st for st in model.stages if st.name == "torsion")
    Xs = model.stage_matrix(stage, env, len(X))
    folder = OUT / "curves"
    folder.mkdir(exist_ok=True)
    for r, name in enumerate(names):
        c = stage.model.curve(Xs[r])
        if not c.ok:
            raise SystemExit(f"{name}: the torsion curve failed ({c.reason})")
        angle = units.from_base(c.angle, "arcsec") + U_CURVE * rng.standard_normal(c.angle.size)
        with (folder / f"{name}.csv").open("w", encoding="utf-8", newline="") as fh:
            fh.write(f"# {HEADER.format(seed=SEED)}\n# hysteresis test of {name}: the 20-DOF torsion stage at the "
                     f"reducer's true factors, each angle + N(0, {U_CURVE} arcsec) (studies/rv80e_synthetic_serials.py)\n")
            w = csv.writer(fh, lineterminator="\n")
            w.writerow(["torque [N*m]", "angle [arcsec]", "sigma [arcsec]"])
            w.writerows([f"{t:.4f}", f"{a:.4f}", f"{U_CURVE:g}"] for t, a in zip(units.from_base(c.torque, "N*m"), angle))


def main() -> None:
    spec0, names, true = parts.main(out=OUT, seed=SEED, reducers=REDUCERS, serial_prefix="RV80E-T")
    crankshafts_as_qif(OUT / "synthetic_crankshafts.csv")
    study = load_study(PRODUCT, progress=False)
    spec = study.spec
    X = sample(spec, REDUCERS, "random", substream_seed(SEED, "synthetic_eol")).values
    for j, f in enumerate(spec0.names):
        X[:, spec.index(f)] = true[:, j]
    model = study.model.restricted(OUTPUTS)
    Y = model.evaluate(X)
    shown = {q.name: q.to_display(Y[:, j]) for j, q in enumerate(model.outputs)}
    rng = substream(SEED, "synthetic_eol", 1)
    reads = list(U_RIG)
    with (OUT / "synthetic_end_of_line.csv").open("w", encoding="utf-8", newline="") as fh:
        fh.write(f"# {HEADER.format(seed=SEED)}\n# reading = the model at the reducer's true factors + N(0, u) "
                 "(u: the rig's ESTIMATED standard uncertainty, studies/rv80e_synthetic_serials.py); TE on the first "
                 f"{TE_UNITS} reducers only\n")
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["reducer"] + [f"{q} [{model.output(q).shown_unit}]" for q in reads])
        w.writerow(["uncertainty"] + [f"{U_RIG[q]:g}" for q in reads])
        for r, name in enumerate(names):
            cells = [f"{shown[q][r] + U_RIG[q] * rng.standard_normal():.4f}" for q in reads]
            if r >= TE_UNITS:
                cells[reads.index("te.te_pp")] = ""
            w.writerow([name] + cells)
    write_curves(study.model, X, names, rng)
    with (OUT / "synthetic_truth.csv").open("w", encoding="utf-8", newline="") as fh:
        fh.write(f"# {HEADER.format(seed=SEED)}\n# the TRUTH of every output at each reducer's true factors (no rig "
                 "error): for checking the per-serial posterior, which no real batch can\n")
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["reducer"] + [f"{q.name} [{q.shown_unit}]" for q in model.outputs])
        w.writerows([name] + [f"{shown[q.name][r]:.6g}" for q in model.outputs] for r, name in enumerate(names))
    print(f"wrote {REDUCERS} reducers' parts, QIF crankshafts, end-of-line records and truth to {OUT}")


if __name__ == "__main__":
    main()
