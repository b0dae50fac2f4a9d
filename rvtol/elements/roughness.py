"""Normal contact stiffness of rough surfaces: the Greenwood–Williamson asperity model.

J. A. Greenwood, J. B. P. Williamson, *Contact of nominally flat surfaces*, Proc. R. Soc. Lond. A 295 (1966)
300–319; K. L. Johnson, *Contact Mechanics*, CUP 1985, §13.2.  Two rough surfaces are replaced by one rough
surface of the combined rms roughness ``σ = √(σ1² + σ2²)`` against a smooth rigid flat.  Its summits have
the same radius ``β`` and Gaussian heights (standard deviation ``σ``, the summit heights taken as the
surface heights, as GW do), ``η`` summits per unit area; each touching summit is a Hertz contact with the
reduced modulus ``E*``.  At separation ``d`` (flat to the summits' mean plane) the nominal pressure and the
normal stiffness per unit area are::

    p(d)   = η (4/3) E* β^(1/2) ∫_d^∞ (z − d)^(3/2) φ(z) dz
    k_n(d) = dp/d(−d) = η 2 E* β^(1/2) ∫_d^∞ (z − d)^(1/2) φ(z) dz,        φ = N(0, σ²)

(MPa, MPa/mm).  The **layer compliance** of a contact carrying the nominal pressure ``p`` over an area ``A``
is ``1/(k_n A)`` (mm/N): a thin elastic layer in series with the bulk (Hertz, the pin-in-hole solution, a
bolted interface).

**Parameters from a drawing.**  A drawing gives the arithmetic mean roughness ``Ra``; for a Gaussian
profile ``σ = √(π/2) Ra ≈ 1.25 Ra``.  GW observed ``σ β η`` between 0.03 and 0.05 for many engineering
surfaces (their §4): with a summit radius ``β`` this fixes ``η = 0.04 / (σ β)``.  ``β`` of ground steel is
a few tens of µm (GW's Table 1: 10–50 µm for ground and lapped metals): an estimate the design states.
The model is elastic: where the mean summit pressure exceeds the hardness (plasticity index
``ψ = (E*/H) √(σ/β)`` > 1) summits yield and the layer is stiffer than computed (an upper bound of the
compliance).

Units: mm, N, MPa.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from scipy import integrate, optimize

from . import _checks

#: GW's σβη, middle of their observed range 0.03–0.05
SIGMA_BETA_ETA = 0.04


def sigma_from_ra(ra):
    """rms height (mm) of a Gaussian profile of arithmetic mean roughness ``ra`` (mm): ``√(π/2) Ra``."""
    return math.sqrt(0.5 * math.pi) * float(_checks.positive("Ra", ra))


@dataclass(frozen=True)
class GreenwoodWilliamson:
    """Combined rms height ``sigma`` (mm), summit radius ``beta`` (mm), summit density ``eta`` (1/mm², default
    ``SIGMA_BETA_ETA/(σβ)``), reduced modulus ``E_star`` (MPa)."""

    sigma: float
    beta: float
    E_star: float
    eta: float | None = None

    def __post_init__(self):
        _checks.positive("sigma", self.sigma)
        _checks.positive("beta", self.beta)
        _checks.positive("E_star", self.E_star)
        if self.eta is None:
            object.__setattr__(self, "eta", SIGMA_BETA_ETA / (self.sigma * self.beta))
        _checks.positive("eta", self.eta)

    @classmethod
    def from_ra(cls, ra1, ra2, beta, E_star):
        """Two surfaces of roughness ``ra1``, ``ra2`` (mm): ``σ = √(σ1² + σ2²)``."""
        return cls(math.hypot(sigma_from_ra(ra1), sigma_from_ra(ra2)), beta, E_star)

    def _integral(self, d, power):
        s = self.sigma
        f = lambda z: (z - d) ** power * math.exp(-0.5 * (z / s) ** 2) / (s * math.sqrt(2 * math.pi))  # noqa: E731
        return integrate.quad(f, d, d + 12.0 * s + max(0.0, -d), epsabs=0.0, epsrel=1e-10, limit=200)[0]

    def pressure(self, d) -> float:
        """Nominal pressure (MPa) at separation ``d`` (mm)."""
        return self.eta * 4.0 / 3.0 * self.E_star * math.sqrt(self.beta) * self._integral(float(d), 1.5)

    def stiffness(self, d) -> float:
        """Normal stiffness per unit area ``−dp/dd`` (MPa/mm) at separation ``d``."""
        return self.eta * 2.0 * self.E_star * math.sqrt(self.beta) * self._integral(float(d), 0.5)

    def separation(self, p) -> float:
        """Separation ``d`` (mm) at which the nominal pressure is ``p`` (MPa)."""
        p = float(_checks.positive("p", p))
        g = lambda d: math.log(self.pressure(d)) - math.log(p)  # noqa: E731
        lo, hi = -3.0 * self.sigma, 6.0 * self.sigma
        while g(lo) < 0:
            lo -= 3.0 * self.sigma
        while g(hi) > 0:
            hi += 3.0 * self.sigma
        return optimize.brentq(g, lo, hi, xtol=1e-14 * self.sigma, rtol=1e-12)

    def stiffness_at_pressure(self, p) -> float:
        """Normal stiffness per unit area (MPa/mm) at the nominal pressure ``p`` (MPa)."""
        return self.stiffness(self.separation(p))

    def layer_compliance(self, p, area) -> float:
        """Compliance (mm/N) of the rough layer of a contact of nominal area ``area`` (mm²) at pressure ``p``."""
        return 1.0 / (self.stiffness_at_pressure(p) * float(_checks.positive("area", area)))

    def plasticity_index(self, hardness) -> float:
        """GW's ``ψ = (E*/H) √(σ/β)``: below ~0.6 elastic, above ~1 the summits yield."""
        return self.E_star / float(hardness) * math.sqrt(self.sigma / self.beta)
