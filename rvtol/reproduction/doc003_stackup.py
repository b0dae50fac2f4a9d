"""Doc 003 (6-DOF deviation stack-up): the shaft–hole example's printed figures against rvtol.

::

    [[analysis]]
    kind = "stackup_shaft_hole"
    printed = "../data/reproduction/doc003_stackup.toml"
    fit = "fit"                 # a clearance fit of the study's assembly
    kc = "shaft_axis"           # the KC whose ‖e‖, ‖ε‖ and tilt are compared

Each figure (key = what it is compared with: ``max_clearance``, ``e_norm``,
``eps_norm``, ``tilt``) is set against rvtol's worst case (WC: the fit's
largest clearance with the shaft pushed to the wall) and the Monte Carlo
(mean, P99.73, max); the verdict of :mod:`.printed` is applied to each reading.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from .. import units
from ..analysis import Analysis
from ..errors import SpecError
from ..models.stackup.analyses import need_stackup
from ..models.stackup.model import StackupModel
from ..report.sections import Section, frame_records
from ..stats import percentile_ci
from ..units import label
from .printed import RULE, load_printed

COMPARE = ("max_clearance", "e_norm", "eps_norm", "tilt")
DIMENSION = {"max_clearance": "length", "e_norm": "length", "eps_norm": "angle", "tilt": "angle"}


class StackupShaftHole(Analysis):
    def setup(self, params, study):
        m = self.model = need_stackup(params, study)
        self.printed = load_printed(params.path_value("printed", Path(study.file).parent))
        fits = [f for f in m.assembly.fits.values() if f.is_clearance]
        self.fit = m.assembly.fits.get(params.str("fit", fits[0].name if fits else ""))
        if self.fit is None or not self.fit.is_clearance:
            raise params.error("fit", "name a clearance fit of the assembly")
        self.kc = params.str("kc", m.kcs[0].name)
        if self.kc not in {k.name for k in m.kcs}:
            raise params.error("kc", f"unknown KC {self.kc!r}")
        self.figures = []
        for key, fig in self.printed.figures.items():
            if key not in COMPARE:
                raise SpecError(f"unknown comparison (expected one of: {', '.join(COMPARE)})",
                                file=self.printed.path, key=f"figure.{key}")
            if key != "max_clearance" and f"{self.kc}.{key}" not in m.output_names:
                raise params.error("kc", f"the model has no output {self.kc}.{key}")
            if units.dimension(fig.unit) != DIMENSION[key]:
                raise SpecError(f"expected a {DIMENSION[key]} unit, got {fig.unit!r}", file=self.printed.path,
                                key=f"figure.{key}.unit")
            self.figures.append(fig)
        if not self.figures:
            raise SpecError("no figures", file=self.printed.path, key="figure")

    def worst_case_inputs(self, spec) -> np.ndarray:
        """Nominal factors with the fit's sizes at the band ends that give the largest clearance."""
        x = spec.nominal_base()
        asm = self.model.assembly
        for side in ("base", "mate"):
            feat = asm.features[getattr(self.fit, side)]
            if feat.size and feat.size in spec.names:
                lo, hi = spec.factor(feat.size).band
                v = hi if (side == self.fit.hole) else lo
                x[spec.index(feat.size)] = units.to_base(v, spec.factor(feat.size).unit)
        return x

    def run(self, ctx) -> Section:
        m, spec = self.model, ctx.spec
        x = self.worst_case_inputs(spec)
        cmax = float(m.clearance(self.fit, x[None])[0])
        a1 = self.fit.float_factors[0]
        if a1 in spec.names:
            x[spec.index(a1)] = 1.0
        wc = {}
        for mode in ("worst_offset", "worst_tilt"):
            mm = StackupModel(m.assembly, m.sequence.name, m.inputs, m.input_units, m.rotation, m.backend,
                              {self.fit.name: mode})
            y = mm.evaluate(x[None])[0]
            for j, q in enumerate(mm.outputs):
                wc[q.name] = max(wc.get(q.name, -np.inf), float(y[j]))
        rows = []
        for fig in self.figures:
            if fig.key == "max_clearance":
                vals = {"WC": units.from_base(cmax, fig.unit)}
            else:
                name = f"{self.kc}.{fig.key}"
                q = m.output(name)
                y = units.convert(ctx.mc.column(name), q.shown_unit, fig.unit)
                y = np.sort(y[np.isfinite(y)])
                vals = {"WC": units.from_base(wc[name], fig.unit), "MC mean": float(y.mean()),
                        "MC P99.73": percentile_ci(y, 0.9973)[0], "MC max": float(y[-1])}
            verdicts = {k: fig.verdict(v) for k, v in vals.items()}
            best = next((lev for lev in ("yes", "partly") if lev in verdicts.values()), "no")
            which = [k for k, v in verdicts.items() if v == best]
            rows.append({"figure": fig.label, "printed": fig.value, "unit": label(fig.unit),
                         **{f"rvtol {k}": v for k, v in vals.items()},
                         "reproduced": f"{best} ({', '.join(which)})" if best != "no" else "no", "why": fig.why})
        df = pd.DataFrame(rows)
        sec = Section("stackup_shaft_hole", "Stack-up: doc 003 shaft–hole example — printed figures against rvtol")
        sec.add_text(f"Fit {self.fit.name!r}: largest clearance over the size bands {cmax:.4g} mm, engagement "
                     f"{self.fit.length:g} mm. WC = the model at that clearance with the shaft pushed to the wall "
                     "(both ends one side, or opposite sides; the larger output). 'reproduced' is judged for each "
                     f"reading (the readings it holds for in brackets): {RULE}")
        sec.add_table(df, caption="Printed figures and what rvtol computes", float_format="{:.4g}")
        sec.summary = {"max_clearance_mm": cmax, "figures": frame_records(df),
                       "printed_file": {"path": self.printed.path, "sha256": self.printed.sha256}}
        return sec
