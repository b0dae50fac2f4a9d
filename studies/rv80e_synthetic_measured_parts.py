"""Regenerate the SYNTHETIC measured parts of the RV-80E in data/measurements/rv80e_parts_synthetic/ (issue 16).

They are NOT measurements of any reducer.  Each reducer's "true" parts are one sample of the drawing spec
(data/products/rv80e/tolerances.toml, with its correlations: the two discs of a reducer are a stack-ground
pair) drawn from the sub-stream ``synthetic_parts`` of SEED; a "measured" value is the true value plus a
normal measurement error of the stated standard uncertainty u (same sub-stream).  Magnitudes (2-lobe
amplitudes, forms) are written as the magnitude of the reading; the phase of a 2-lobe pattern gets the
uncertainty u_A / A (rad) its amplitude's reading gives (capped at the 104° of a uniform phase).

The inspection plan (what is measured, with which u) is INSPECTION below; everything else (per-groove
residuals, pins within their lot, bearings, gears, widths, hole and cam sizes) is not measured and the
per-unit prediction samples it from the spec.  The uncertainties are estimates: a CMM for positions
(MPE ≈ 0.5 µm → u ≈ 0.3 µm), a gear-measuring machine for the cycloid profile, a pin-set mean of 40
micrometer readings for the pin lot, a clearance gauge at needle fitting.

    PYTHONPATH=. python studies/rv80e_synthetic_measured_parts.py          # about a second
"""
from __future__ import annotations

import csv
import math
from pathlib import Path

from rvtol import units
from rvtol.sampling import sample, substream, substream_seed
from rvtol.spec import load_spec

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "data/products/rv80e/tolerances.toml"
OUT = ROOT / "data/measurements/rv80e_parts_synthetic"
SEED = 20260516
REDUCERS = 8
SPARES = {"crankshafts": 1, "discs": 1}            # part sets made but not (yet) in a kit (3 cranks, a disc pair)


def _cmm(features, u):
    return {f: u for f in features}


def _position(prefix):
    return [f"{prefix}.position.{c}" for c in ("x1", "y1", "x2", "y2")]


#: family -> (file stem, slots, {feature column: u in the factor's unit; None: a phase, u per part}, serial prefix)
INSPECTION = {
    "housings": ("synthetic_housings", ["housing"], {
        "pin_circle.radius": 0.3, "pin_groove.diameter": 0.3,
        "pin_grooves.radial_harmonic": 0.3, "pin_grooves.radial_harmonic_phase": None,
        "pin_grooves.cumulative_pitch": 0.3, "pin_grooves.cumulative_pitch_phase": None,
        **_cmm([f"main_raceways.coaxiality.{c}" for c in ("x1", "y1", "x2", "y2")], 0.3)}, "H"),
    "pin_sets": ("synthetic_pin_sets", ["pins"], {"diameter_lot": 0.1}, "P"),
    "discs": ("synthetic_cycloid_discs", ["disc_1", "disc_2"], {
        "profile.equidistance_mod": 0.3, "profile.moved_distance_mod": 0.3,
        "profile.form": 0.3, "profile.form_phase": None,
        "profile.cumulative_pitch": 0.3, "profile.cumulative_pitch_phase": None,
        **{k: 0.3 for i in (1, 2, 3) for k in _position(f"crank_hole_{i}")},
        **{f"crank_hole_{i}.form": 0.2 for i in (1, 2, 3)}}, "D"),
    "crankshafts": ("synthetic_crankshafts", ["crank_1", "crank_2", "crank_3"], {
        **{k: 0.3 for j in (1, 2) for k in _position(f"cam_{j}")},
        **{f"cam_{j}.form": 0.2 for j in (1, 2)}}, "C"),
    "carriers": ("synthetic_carriers", ["carrier"], {
        **{k: 0.3 for i in (1, 2, 3) for k in _position(f"crank_bore_{i}")},
        **_cmm([f"main_raceways.runout.{c}" for c in ("x1", "y1", "x2", "y2")], 0.3)}, "K"),
    "needle_sets": ("synthetic_needle_sets", [f"needles.disc_{j}.crank_{i}" for j in (1, 2) for i in (1, 2, 3)],
                    {"clearance": 0.5}, "N"),
}
#: families whose parts are exchangeable between slots and reducers (no correlation in the spec): shuffled in the kits
SHUFFLED = ("crankshafts", "needle_sets")
#: phase column -> its amplitude column (the phase's uncertainty follows from the amplitude reading)
PHASES = {"pin_grooves.radial_harmonic_phase": "pin_grooves.radial_harmonic",
          "pin_grooves.cumulative_pitch_phase": "pin_grooves.cumulative_pitch",
          "profile.form_phase": "profile.form", "profile.cumulative_pitch_phase": "profile.cumulative_pitch"}
HEADER = ["SYNTHETIC measured parts of the RV-80E (issue 16) -- NOT measurements of any reducer.",
          "True values: samples of data/products/rv80e/tolerances.toml (sub-stream synthetic_parts of seed {seed});",
          "measured = true + normal error of the standard uncertainty u in the uncertainty row / the .u columns.",
          "Regenerate: PYTHONPATH=. python studies/rv80e_synthetic_measured_parts.py"]


def _name(slot: str, column: str) -> str:
    return f"{slot}{column}" if column.startswith("[") else f"{slot}.{column}"


def main(write: bool = True, out: Path = OUT, seed: int = SEED, reducers: int = REDUCERS, serial_prefix: str = "RV80E-S"):
    """Write the part families and the kit list (``write``) and return ``(spec, reducers, truth)``: each kitted
    reducer's true factor values ``[reducers, k]`` (base units) — its sample of the spec, with the true values of
    the parts the kit list gave it (exchangeable parts come from another sample) — for the end-of-line records
    (studies/rv80e_synthetic_end_of_line.py)."""
    spec = load_spec(SPEC)
    n_units = reducers
    n_parts = {fam: n_units + SPARES.get(fam, 0) for fam in INSPECTION}
    draws = max(n_parts.values())
    truth = sample(spec, draws, "random", substream_seed(seed, "synthetic_parts")).values   # base units
    noise = substream(seed, "synthetic_parts", 1)
    if write:
        out.mkdir(parents=True, exist_ok=True)
    kits = {r: {} for r in range(n_units)}
    origin = {}                                      # serial -> (its sample, its slot, its family's columns)
    for fam, (stem, slots, plan, prefix) in INSPECTION.items():
        cols = list(plan)
        units_ = {c: spec.factor(_name(slots[0], c)).unit for c in cols}
        with_u_col = [c for c in cols if plan[c] is None]
        header = ["serial"] + [f"{c} [{units_[c]}]" for c in cols] + [f"{c}.u [{units_[c]}]" for c in with_u_col]
        rows = [["uncertainty"] + [("" if plan[c] is None else f"{plan[c]:g}") for c in cols] + [""] * len(with_u_col)]
        serial = 0
        for r in range(n_parts[fam]):                # part set r: the parts of sample r (a kit, or a spare set)
            for s in slots:
                serial += 1
                sn = f"{prefix}-{serial:04d}"
                values, us = {}, {}
                for c in cols:
                    f = spec.factor(_name(s, c))
                    x = float(units.from_base(truth[r, spec.index(f.name)], f.unit))
                    if plan[c] is None:
                        a = spec.factor(_name(s, PHASES[c]))
                        amp = float(units.from_base(truth[r, spec.index(a.name)], a.unit))
                        u = us[c] = min(math.degrees(plan[PHASES[c]] / max(amp, 1e-9)), 360 / math.sqrt(12))
                    else:
                        u = plan[c]
                    m = x + u * noise.standard_normal()
                    values[c] = abs(m) if f.dist.one_sided else m
                rows.append([sn] + [f"{values[c]:.3f}" for c in cols] + [f"{us[c]:.1f}" for c in with_u_col])
                origin[sn] = (r, s, cols)
                if r < n_units:
                    kits[r][s] = sn
        write and _write(out / f"{stem}.csv", seed, header, rows, [f"family {fam}: slots {', '.join(slots)}; "
                                                   f"{n_parts[fam] - n_units} spare part set(s) not in a kit"
                                                   if n_parts[fam] > n_units else f"family {fam}: slots "
                                                   f"{', '.join(slots)}"])
    for fam in SHUFFLED:                             # exchangeable parts: the fitter takes any from stock
        _, ss, _, _ = INSPECTION[fam]
        used = [kits[r][s] for r in range(n_units) for s in ss]
        order = noise.permutation(len(used))
        for i, (r, s) in enumerate((r, s) for r in range(n_units) for s in ss):
            kits[r][s] = used[order[i]]
    slots = [s for (_, ss, _, _) in INSPECTION.values() for s in ss]
    names = [f"{serial_prefix}{r + 1:03d}" for r in range(n_units)]
    if write:
        _write(out / "synthetic_kits.csv", seed, ["reducer"] + slots,
               [[names[r]] + [kits[r][s] for s in slots] for r in range(n_units)],
               ["kit list: which serial parts form which reducer"])
        print(f"wrote {n_units} kits and {len(INSPECTION)} part families to {out}")
    true = truth[:n_units].copy()
    for r in range(n_units):
        for s, sn in kits[r].items():
            r0, s0, cols = origin[sn]
            for c in cols:
                true[r, spec.index(_name(s, c))] = truth[r0, spec.index(_name(s0, c))]
    return spec, names, true


def _write(path: Path, seed: int, header, rows, extra) -> None:
    with path.open("w", newline="", encoding="utf-8") as fh:
        for line in HEADER + extra:
            fh.write(f"# {line.format(seed=seed)}\n")
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(header)
        w.writerows(rows)


if __name__ == "__main__":
    main()
