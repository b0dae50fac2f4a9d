"""The measurement chain of a transmission-error test rig (issue 23 item 5): what the rig's encoders add to the
reducer's own TE, and where the once- and twice-per-revolution content of a measured TE comes from.

A rig measures ``TE_m = θ_out,read − θ_in,read / i`` with an angle encoder on the output flange and one on the
input; the 20-DOF model gives the reducer's own ``Δθ_ca = θ_ca − θ_s/i``.  The encoders read the angles with
errors that depend on how their graduations sit on the shafts they measure:

**An eccentric graduation read by one head.**  A graduation (scale ring or disc) of radius ``r`` whose centre
lies at ``e = (e_x, e_y)`` from the shaft's rotation axis (in the shaft's frame at its zero angle) turns with
the shaft; after a turn by φ its centre is at ``R(φ) e``.  A fixed read head at the angle ψ_h, radius r, reads
the graduation that passes it: in the graduation's own frame the head sits at
``arg(r u(ψ_h) − R(φ) e) − φ``; to first order in ``|e|/r`` the reading is::

    φ_read = φ + |e|/r · sin(φ + β − ψ_h),       β = atan2(e_y, e_x)
           = φ + (e_x sin φ + e_y cos φ)/r          (head at ψ_h = 0)

(HEIDENHAIN, *Position encoders for servo drives* / *Angle encoders*: the measuring error of an eccentric
graduation is ``Δφ = ±412 e/D`` arcsec with e in µm and D the graduation diameter in mm — the same ``e/r``
rad; "the equation … is also valid for radial deviation of the bearing if e is replaced with the eccentricity,
half of the radial deviation").  Two heads 180° apart, averaged, cancel it (the term turns sign with ψ_h + π):
``read_heads = 2`` gives no first-order error.  ``tests/models/transmission_error/test_rig.py`` holds the formula to the
exact geometry.

**Output side — orders 1 (and only 1) per output revolution.**  The output encoder's graduation turns once per
output revolution; its eccentricity about the carrier's rotation axis is the sum of carrier-fixed vectors:

* the **output-flange eccentricity** — the flange pilot (spigot) the rig centres its graduation on, against
  the carrier's datum C: a drawing tolerance of the product (``carrier.output_pilot.position.{x,y}``);
* the **main-bearing (carrier) runout** — the carrier turns about its main raceways, whose axis lies at
  ``m(z)`` from datum C (``carrier.main_raceways.runout.*``, the axis end points at z = ±21 mm): everything
  centred on C, the pilot included, orbits the rotation axis with radius |m(z)| at the pilot's plane z_f
  (extrapolated linearly along the raceway axis): ``−m(z_f)``;
* the rig's own **centring** of the graduation on the pilot (a rig tolerance).

So a ring centred by its fit on the pilot (``centring = "pilot"``) is eccentric by ``e_out = p − m(z_f) + c_rig``.
A ring centred with a dial indicator on its own periphery while the reducer turns (``centring = "indicated"``,
the usual way to mount a modular ring) is centred on the *rotation axis* itself: the pilot's eccentricity and
the main-bearing runout are indicated away, and ``e_out = c_rig``, the residual the indicator leaves (half its
TIR).  Adding the pilot's eccentricity to an indicated ring counts it twice.  The TE term is
``(e_x sin θ + e_y cos θ)/r_out`` at order 1 with one head; the study's mapping gives ``e_out`` as the rig's
``centring`` says (:attr:`Encoder.centring`).
Mounted on its own bearing and coupled to the flange (``mounting = "coupled"``: an encoder with an integral
bearing and a homokinetic coupling), the graduation turns about the encoder's own axis and the flange's orbit
goes into the coupling: no first-order term (the coupling's own kinematic error is not modelled).  The same
runout acts on the mechanism itself: the carrier-fixed part ``m`` moves the three crank bores together (the
20-DOF ``E_ca``, from the stack-up), the housing-fixed part of the main raceways is ``A_c``; there the
two discs, 180° apart, cancel it to first order and it shows at 2·z_b and at orders z_b − z_c = 1, 2 only
through their interaction with housing-fixed errors (:mod:`.orders`).  A fixed offset of the rotation axis
from the read head's circle (the housing's main raceways against the rig) gives a constant reading error:
no TE.

**Input side — order i per output revolution.**  The input encoder's graduation, eccentric by ``e_in`` about
the input shaft's axis, reads the input angle θ_s = i θ_c with ``(e_x sin θ_s + e_y cos θ_s)/r_in``; the TE
divides the input angle by the ratio: a term ``−(e_x sin iθ + e_y cos iθ)/(i r_in)`` at order i (81 for the
RV-80E: next to the pin-mesh order z_b = 40's second multiple).  Divided by the ratio, it is small.

**Order 2.**  No first-order source above turns twice per output revolution.  A graduation tilted on its
shaft by β reads ``φ + (β²/4) sin 2(φ + ψ)`` (the projection of a tilted circle; the same as a Hooke joint at
angle β) — for β = 1 mrad, 0.05″: left out.  The model's order 2 comes from the mechanism: the rectified
beat of housing-fixed (order z_c) and carrier-fixed (order z_b) errors through the two discs' dead bands
gives |z_b − z_c| = 1 and 2 (:mod:`.orders`).

A rig description (``data/rigs/*.toml``) holds the rig's parameters in a ``[rig]`` table and its tolerances as
``[[factor]]`` tables (a spec a study adds to its own, ``[study] spec = [product, rig]``)::

    [rig]
    name = "…"
    [rig.output_encoder]
    graduation_diameter = { value = 200, unit = "mm", range = [150, 250], source = "…" }   # range: optional
    read_heads = { value = 1, unit = "1", source = "…" }
    mounting = { value = "flange", unit = "1", source = "…" }     # or "coupled"
    centring = { value = "indicated", unit = "1", source = "…" }  # or "pilot"; optional, default "indicated"
    [rig.input_encoder]
    graduation_diameter = …
    read_heads = …

The transmission-error model (``[model] rig = "…"``) then takes the eccentricity vectors as inputs
(:data:`INPUTS`, mm; a study maps them from the drawing and rig factors) and adds the output ``te_pp_rig``:
the peak-to-peak of the TE the rig reads, refined like Δθ_er (:func:`.extremes.te_extremes` with the terms).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ... import units
from ...errors import InputError, SpecError
from ...params import Params, check_number, read_toml

#: the measurement chain's inputs of the TE model (mm): the output graduation's eccentricity about the
#: carrier's rotation axis (carrier frame at θ_c = 0), the input graduation's about the input shaft's axis
INPUTS = ("rig.output_eccentricity.x", "rig.output_eccentricity.y", "rig.input_eccentricity.x",
          "rig.input_eccentricity.y")
MOUNTINGS = ("flange", "coupled")
#: how a flange-mounted graduation is centred: on the rotation axis with a dial indicator, or by its fit on the pilot
CENTRINGS = ("indicated", "pilot")


@dataclass(frozen=True)
class Encoder:
    """One encoder of the rig: graduation radius (mm), read heads (1 or 2), how it is mounted and centred, and the
    range of graduation radii the rig's assumption spans (mm; None: the radius is a fact of the rig)."""

    radius: float
    heads: int
    mounting: str = "flange"
    centring: str = "indicated"
    radius_range: tuple[float, float] | None = None

    @property
    def reads_eccentricity(self) -> bool:
        """A first-order eccentricity error: one head on a graduation that turns with the measured shaft."""
        return self.heads == 1 and self.mounting == "flange"


@dataclass(frozen=True)
class Rig:
    """A TE test rig's measurement chain (module doc)."""

    name: str
    output: Encoder
    input: Encoder
    file: str | None = None
    sha256: str | None = None

    def terms(self, ratio: float, e_out=(0.0, 0.0), e_in=(0.0, 0.0)) -> np.ndarray:
        """Rows ``(n, a, b)`` of ``TE_m − Δθ_ca = Σ a cos(n θ_c) + b sin(n θ_c)`` (rad) for the eccentricities
        ``e_out``, ``e_in`` (mm; module doc)."""
        rows = []
        if self.output.reads_eccentricity and (e_out[0] != 0.0 or e_out[1] != 0.0):
            rows.append((1.0, e_out[1] / self.output.radius, e_out[0] / self.output.radius))
        if self.input.reads_eccentricity and (e_in[0] != 0.0 or e_in[1] != 0.0):
            k = 1.0 / (ratio * self.input.radius)
            rows.append((float(ratio), -e_in[1] * k, -e_in[0] * k))
        return np.array(rows, dtype=float).reshape(-1, 3)

    def to_frame(self):
        import pandas as pd

        rows = []
        for side, enc in (("output", self.output), ("input", self.input)):
            span = "" if enc.radius_range is None else f"{2 * enc.radius_range[0]:g}–{2 * enc.radius_range[1]:g}"
            rows.append({"encoder": side, "graduation diameter (mm)": 2.0 * enc.radius,
                         "assumed range (mm)": span, "read heads": enc.heads, "mounting": enc.mounting,
                         "centring": enc.centring,
                         "first-order eccentricity error": "yes" if enc.reads_eccentricity else "no"})
        return pd.DataFrame(rows)


def measurement_terms(terms: np.ndarray, theta) -> np.ndarray:
    """The chain's TE terms (rad) at the carrier angles ``theta``."""
    theta = np.asarray(theta, dtype=float)
    out = np.zeros(theta.shape)
    for n, a, b in np.asarray(terms, dtype=float).reshape(-1, 3):
        out += a * np.cos(n * theta) + b * np.sin(n * theta)
    return out


def _entry(t: Params, name: str, default=None):
    """``(value, unit, range)`` of an entry written ``{ value = …, unit = "…", source = "…", note = "…",
    range = [low, high] }`` (the source is required: every number of a rig says where it comes from; the range,
    optional, is the span an assumed value stands for).  ``default``: ``(value, unit)`` of an entry left out."""
    if default is not None and name not in t:
        return (*default, None)
    v = t.raw(name)
    if not isinstance(v, dict):
        raise t.error(name, "expected { value = …, unit = \"…\", source = \"…\" }")
    sub = Params(v, file=t.file, key=t.path(name))
    value = sub.raw("value")
    unit = sub.str("unit", "1")
    sub.str("source")
    sub.str("note", "")
    span = sub.floats("range", None, length=2) if "range" in v else None
    if span is not None and not span[0] <= value <= span[1]:
        raise sub.error("range", f"expected [low, high] around the value {value!r}, got {span}")
    sub.finish()
    return value, unit, span


def _encoder(p: Params, side: str) -> Encoder:
    t = p.sub(f"{side}_encoder")
    d, unit, span = _entry(t, "graduation_diameter")
    try:
        base = units.require_dimension(units.canonical(unit), "length")
        d = float(units.to_base(check_number(d, t.error, "graduation_diameter", positive=True), base))
        span = None if span is None else tuple(float(units.to_base(x, base)) for x in span)
    except InputError as exc:
        raise t.error("graduation_diameter", exc.reason) from None
    heads, _, _ = _entry(t, "read_heads")
    if isinstance(heads, bool) or heads not in (1, 2):
        raise t.error("read_heads", f"must be 1 or 2 (one head, or two diametral heads averaged), got {heads!r}")
    mounting, _, _ = _entry(t, "mounting")
    if mounting not in MOUNTINGS:
        raise t.error("mounting", f"must be one of {', '.join(MOUNTINGS)}, got {mounting!r}")
    centring, _, _ = _entry(t, "centring", ("indicated", "1"))
    if centring not in CENTRINGS:
        raise t.error("centring", f"must be one of {', '.join(CENTRINGS)}, got {centring!r}")
    t.finish()
    return Encoder(0.5 * d, int(heads), str(mounting), str(centring),
                   None if span is None else (0.5 * span[0], 0.5 * span[1]))


def load_rig(path: str | Path) -> Rig:
    """A rig description (module doc); bad input is a one-line error naming the file and key."""
    data, sha = read_toml(path)
    root = Params(data, file=str(path))
    if "rig" not in root:
        raise SpecError("a rig description needs a [rig] table", file=str(path), key="rig")
    head = root.sub("rig")
    name = head.str("name", Path(path).stem)
    head.str("description", "")
    out, inp = _encoder(head, "output"), _encoder(head, "input")
    head.finish()
    for k in ("spec", "factor", "correlation"):          # the rig's tolerances: the spec part of the file
        root.raw(k, None)
    root.finish()
    return Rig(name, out, inp, str(path), sha)
