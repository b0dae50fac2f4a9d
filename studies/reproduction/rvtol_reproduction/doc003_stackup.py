"""Doc 003 (6-DOF deviation stack-up): the shaft–hole example's printed figures and the planar zone's formulas.

:func:`shaft_hole_figures` sets each printed figure (key = what it is compared with: ``max_clearance``,
``e_norm``, ``eps_norm``, ``tilt``) against rvtol's worst case (WC: the fit's largest clearance with the
shaft pushed to the wall) and the Monte Carlo (mean, P99.73, max); the verdict of :mod:`.printed` is
applied to each reading.  :func:`planar_record` sets the document's printed planar-zone formulas (its
box ``|Δw| ≤ Δt, |Δα| ≤ 2Δt/L1, |Δβ| ≤ 2Δt/W1`` and moments) against their derivation
(:class:`rvtol.models.stackup.domains.ParallelPlaneZone`), with the reason for each difference.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from rvtol.plugin import ParallelPlaneZone, StackupModel, frame_records, stats, units

from .printed import PrintedFigures

COMPARE = ("max_clearance", "e_norm", "eps_norm", "tilt")
DIMENSION = {"max_clearance": "length", "e_norm": "length", "eps_norm": "angle", "tilt": "angle"}


# --------------------------------------------------------------------------- the planar zone's printed formulas
def doc_box(zone: ParallelPlaneZone) -> np.ndarray:
    """The document's printed bounds ``|Δw| ≤ Δt, |Δα| ≤ 2Δt/L1, |Δβ| ≤ 2Δt/W1`` (L1 = L, W1 = W), on all
    six DOFs."""
    hw = np.zeros(6)
    hw[[2, 3, 4]] = [zone.dt, 2.0 * zone.dt / zone.L, 2.0 * zone.dt / zone.W]
    return hw


def planar_record(zone: ParallelPlaneZone) -> pd.DataFrame:
    """Where the document's printed planar-zone moments differ from the derivation, and why."""
    dt, L, W = zone.dt, zone.L, zone.W
    box = zone.box()
    Pu, Pb = zone.cov("uniform"), zone.box_cov()
    rows = [
        ("mean Δw", dt / 2, zone.centre, zone.centre,
         "equal only if w is measured from the lower zone limit (t1 = 0); the zone centre is (t1+t2)/2"),
        ("mean Δα", dt / (2 * L), 0.0, 0.0, "0 by the symmetry Δα → −Δα of the zone; the printed value has no basis"),
        ("mean Δβ", dt / (2 * W), 0.0, 0.0, "0 by the symmetry Δβ → −Δβ of the zone; the printed value has no basis"),
        ("bound |Δw|", dt, box[2], box[2], "printed Δt is the whole zone width; measured from the mid-plane it is Δt/2"),
        ("bound |Δα|", 2 * dt / L, box[3], box[3],
         "printed 2Δt/L1: twice the tilt that keeps the face inside Δt; also α (about x) tilts along W, not L"),
        ("bound |Δβ|", 2 * dt / W, box[4], box[4],
         "printed 2Δt/W1: twice the tilt that keeps the face inside Δt; β (about y) tilts along L"),
        ("σ²(Δw)", dt**2 / 12, Pb[2, 2], Pu[2, 2],
         "printed = uniform on the box (Δt²/12); the exact domain gives Δt²/40 (the octahedron is 1/6 of its box)"),
        ("σ²(Δα)", dt**2 / (3 * L**2), Pb[3, 3], Pu[3, 3],
         "printed = uniform on |Δα| ≤ Δt/L1, half the printed bound; the right lever for α is W"),
        ("σ²(Δβ)", dt**2 / (3 * W**2), Pb[4, 4], Pu[4, 4],
         "printed = uniform on |Δβ| ≤ Δt/W1, half the printed bound; the right lever for β is L"),
        ("σ34 = cov(Δw, Δα)", float("nan"), 0.0, 0.0,
         "printed non-zero 'from the constraints'; the constraints make w and α dependent but uncorrelated "
         "(symmetric in α → −α), so σ34 = 0"),
        ("σ35 = cov(Δw, Δβ)", float("nan"), 0.0, 0.0, "as σ34: 0 by symmetry"),
    ]
    return pd.DataFrame(rows, columns=["quantity", "document (printed formula)", "box (derived)",
                                       "exact domain (derived)", "why they differ"])


@dataclass
class PlanarZoneRecord:
    """A parallel-plane zone: the printed formulas against the derivation, and samples for the figure."""

    zone: ParallelPlaneZone
    record: pd.DataFrame
    samples: np.ndarray

    def plot(self):
        """The library's picture of the zone (samples, exact domain, its box) with the document's printed box."""
        from rvtol.plugin import COLORS, planar_domain

        fig = planar_domain(self.zone, self.samples)
        ax = fig.axes[0]
        db = doc_box(self.zone)
        bw, ba = db[2], db[3] * self.zone.W / 2
        ax.plot(np.array([bw, -bw, -bw, bw, bw]) * 1e3, np.array([ba, ba, -ba, -ba, ba]) * 1e3, color=COLORS["limit"],
                ls="--", label="document's printed box")
        ax.legend(fontsize=7, loc="upper right")
        return fig

    def summary(self) -> dict:
        return {"record": frame_records(self.record)}


# --------------------------------------------------------------------------- the shaft–hole example
def worst_case_inputs(model: StackupModel, fit, spec) -> np.ndarray:
    """Nominal factors with the fit's sizes at the band ends that give the largest clearance."""
    x = spec.nominal_base()
    asm = model.assembly
    for side in ("base", "mate"):
        feat = asm.features[getattr(fit, side)]
        if feat.size and feat.size in spec.names:
            lo, hi = spec.factor(feat.size).band
            v = hi if (side == fit.hole) else lo
            x[spec.index(feat.size)] = units.to_base(v, spec.factor(feat.size).unit)
    return x


@dataclass
class ShaftHoleFigures:
    """``table``: per printed figure rvtol's readings (WC, MC mean, P99.73, max) and the verdict;
    ``planar``: the planar zone's record (None: no zone given)."""

    table: pd.DataFrame
    max_clearance: float           # mm
    fit: object
    printed: PrintedFigures
    planar: PlanarZoneRecord | None = None

    def to_frame(self) -> pd.DataFrame:
        return self.table

    def summary(self) -> dict:
        out = {"max_clearance_mm": self.max_clearance, "figures": frame_records(self.table),
               "printed_file": {"path": self.printed.path, "sha256": self.printed.sha256}}
        if self.planar is not None:
            out["planar_zone"] = self.planar.summary()
        return out

    def plot(self):
        """The report's figure: the planar zone's samples, exact domain, box and printed formulas (an error when
        no zone was given — the clearance figures are a table)."""
        if self.planar is None:
            raise ValueError("no planar zone was compared: no figure (the clearance figures are a table)")
        return self.planar.plot()


def shaft_hole_figures(m: StackupModel, spec, mc, fit, kc: str, figures, printed: PrintedFigures,
                       planar: ParallelPlaneZone | None = None, seed: int | None = None) -> ShaftHoleFigures:
    """Each of ``figures`` (printed) against rvtol's readings for the clearance ``fit`` and the KC ``kc``;
    ``planar``: a parallel-plane zone whose printed formulas are compared too (``seed``: its figure's
    samples)."""
    x = worst_case_inputs(m, fit, spec)
    cmax = float(m.clearance(fit, x[None])[0])
    a1 = fit.float_factors[0]
    if a1 in spec.names:
        x[spec.index(a1)] = 1.0
    wc = {}
    for mode in ("worst_offset", "worst_tilt"):
        mm = StackupModel(m.assembly, m.sequence.name, m.inputs, m.input_units, m.rotation, m.backend, {fit.name: mode})
        y = mm.evaluate(x[None])[0]
        for j, q in enumerate(mm.outputs):
            wc[q.name] = max(wc.get(q.name, -np.inf), float(y[j]))
    rows = []
    for fig in figures:
        if fig.key == "max_clearance":
            vals = {"WC": units.from_base(cmax, fig.unit)}
        else:
            name = f"{kc}.{fig.key}"
            q = m.output(name)
            y = units.convert(mc.column(name), q.shown_unit, fig.unit)
            y = np.sort(y[np.isfinite(y)])
            vals = {"WC": units.from_base(wc[name], fig.unit), "MC mean": float(y.mean()),
                    "MC P99.73": stats.percentile_ci(y, 0.9973)[0], "MC max": float(y[-1])}
        verdicts = {k: fig.verdict(v) for k, v in vals.items()}
        best = next((lev for lev in ("yes", "partly") if lev in verdicts.values()), "no")
        which = [k for k, v in verdicts.items() if v == best]
        rows.append({"figure": fig.label, "printed": fig.value, "unit": units.label(fig.unit),
                     **{f"rvtol {k}": v for k, v in vals.items()},
                     "reproduced": f"{best} ({', '.join(which)})" if best != "no" else "no", "why": fig.why})
    rec = None
    if planar is not None:
        rec = PlanarZoneRecord(planar, planar_record(planar), planar.sample(3000, "uniform", seed=seed))
    return ShaftHoleFigures(pd.DataFrame(rows), cmax, fit, printed, rec)
