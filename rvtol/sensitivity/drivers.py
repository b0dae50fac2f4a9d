"""The drawing tolerances that drive an output, from the Monte Carlo samples alone (first-order indices).

The first-order index S1 of every factor (:func:`rvtol.sensitivity.given_data.given_data`, the
correlation ratio with Kelley's bias correction) summed over the factors of one drawing callout
(:func:`rvtol.callouts.callout_of`): the share of the output's variance the tolerance explains
on its own.  The estimates are summed unclipped (each is unbiased; clipped at 0 the 40 copies of a
family would add 40 positive halves of their noise) and only over the factors the output can depend
on where the model knows its structure (:func:`rvtol.model.dependencies`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..callouts import callout_of
from ..model import dependencies
from .given_data import default_classes, given_data


@dataclass
class Driver:
    tolerance: str
    s1: float            # summed first-order index of its factors
    factors: list[str]
    noise: float = 0.0   # the standard error of that sum where the tolerance has no effect (its estimates' noise)

    @property
    def significant(self) -> bool:
        """Its share stands out of its estimation noise (more than 3 standard errors)."""
        return self.s1 > 3.0 * self.noise


def first_order_drivers(mc, model, spec, outputs, seed) -> dict[str, list[Driver]]:
    """Per output, its drawing tolerances ranked by summed first-order index (none below 50 good samples)."""
    ok = mc.ok
    if ok.sum() < 50:
        return {}
    res = given_data(model, spec, mc.samples, mc.Y, outputs=outputs, seed=seed, num_resamples=0)   # S1 alone
    n = int(ok.sum())
    M = default_classes(n)
    se1 = math.sqrt(2.0 * (M - 1)) / n      # one null estimate's standard error (M classes; Kelley-corrected η²)
    group = {f.name: callout_of(f) for f in spec.factors}
    deps = dependencies(model)
    out = {}
    for o in outputs:
        fr = res.for_output(o)
        sums: dict[str, list] = {}
        for name, s in zip(fr["factor"], fr["S1"]):
            if deps is not None and name not in deps.get(o, ()):
                continue              # cannot move this output: its estimate is noise
            g = sums.setdefault(group[name], [0.0, []])
            g[0] += float(s)          # the bias-corrected estimates are summed as they are (clipping each at 0
            g[1].append(name)         # would add the positive half of the noise of every factor of a family)
        ranked = sorted(sums.items(), key=lambda kv: -kv[1][0])
        out[o] = [Driver(t, max(v[0], 0.0), v[1], se1 * math.sqrt(len(v[1]))) for t, v in ranked]
    return out
