"""Two sub-ppm tails with closed forms, by every OpenTURNS method; disagreements flagged, the reference right.

Radius of a centred position deviation: x, y ~ N(0, σ) independent, r = √(x² + y²) is Rayleigh,
P(r > L) = exp(−L²/(2σ²)) (the χ distribution with 2 degrees of freedom); L = σ√(2 ln 2·10⁶) gives
exactly 0.50 ppm.  Every direction of u-space fails alike (a circle of design points): FORM sees one
point (Φ(−β) = 0.036 ppm, 14× too low), SORM's Breitung formula is undefined (curvature −1/β),
importance sampling about one point misses the rest of the circle while its standard error says
nothing; directional sampling is exact for a domain outside a sphere, subset simulation unbiased.

Uniform + triangular stack: u ~ U(−c, c), t ~ Tri(−c, 0, c) (mode 0), y = u + t ≤ 2c.  Near the top,
with v = c − u ∈ [0, 2c] (density 1/(2c)) and w = c − t ∈ [0, c] (density w/c²),
P(y > 2c − s) = ∫₀ˢ (w/c²)(s − w)/(2c) dw = (s/c)³/12 for s ≤ c.  With c = 0.1 mm and the limit
0.1979 mm (s/c = 0.021): 0.021³/12 = 0.77175 ppm.  FORM linearises a limit state curved by the two
bounded margins' transforms (2.1 ppm); SORM, importance sampling, subset and directional sampling hold
the exact value."""
import math

import pytest

from rvtol.distributions import Distribution
from rvtol.model import LinearModel, Quantity
from rvtol.models.formula.model import FormulaModel
from rvtol.spec import Factor, ToleranceSpec
from rvtol.stacking import tail_probability
from rvtol.stacking.tail import APPROXIMATIONS

SIGMA = 0.01
L_RADIUS = SIGMA * math.sqrt(2 * math.log(2e6))
C, L_CONV = 0.1, 0.1979


def radius_case():
    spec = ToleranceSpec("r", tuple(Factor(n, "mm", Distribution.make("normal", mean=0.0, sigma=SIGMA)) for n in "xy"))
    return spec, FormulaModel.from_spec(spec, {"r": ("hypot(x, y)", "mm")})


def convolution_case():
    spec = ToleranceSpec("c", (Factor("u", "mm", Distribution.make("uniform", lower=-C, upper=C)),
                               Factor("t", "mm", Distribution.make("triangular", lower=-C, upper=C, mode=0.0))))
    return spec, LinearModel(spec.names, ["mm", "mm"], [Quantity("y", "mm")], [[1.0, 1.0]])


def test_the_radius_tail():
    exact = math.exp(-L_RADIUS ** 2 / (2 * SIGMA ** 2))
    assert exact == pytest.approx(0.5e-6, rel=1e-12)
    spec, m = radius_case()
    est = tail_probability(m, spec, "r", L_RADIUS, "upper", seed=3)
    # FORM finds a point of the circle (the kink at the origin does not stop it): β = L/σ, Φ(−β) far too low
    assert est.beta == pytest.approx(L_RADIUS / SIGMA, rel=1e-5) and est.pf_form < 0.1 * exact
    assert est.get("SORM").pf is None or abs(est.get("SORM").pf - exact) > 0.5 * exact   # undefined / wrong
    for name in ("subset", "directional"):
        e = est.get(name)
        assert abs(e.pf - exact) < 4 * e.se + 1e-9 * exact, (name, e.pf, e.se)
    assert est.reference == "directional" and est.pf_reference == pytest.approx(exact, rel=1e-3)
    # importance sampling about one design point: low, and flagged against the global samplers; FORM flagged too
    imp = est.get("importance sampling")
    assert imp.pf < 0.5 * exact
    assert any(d.startswith("importance sampling") and "directional" in d for d in est.disagreements)
    assert any(d.startswith("FORM") for d in est.disagreements)


def test_the_uniform_plus_triangular_tail():
    exact = ((2 * C - L_CONV) / C) ** 3 / 12
    assert 1e6 * exact == pytest.approx(0.77175, rel=1e-6)
    spec, m = convolution_case()
    est = tail_probability(m, spec, "y", L_CONV, "upper", seed=3)
    assert est.pf_form > 2 * exact and any(d.startswith("FORM") for d in est.disagreements)
    assert est.get("SORM").pf == pytest.approx(exact, rel=0.05)
    for name in ("importance sampling", "subset", "directional"):
        e = est.get(name)
        assert abs(e.pf - exact) < 4 * e.se, (name, e.pf, e.se)
    ref = est.get(est.reference)
    assert est.reference not in APPROXIMATIONS and abs(ref.pf - exact) < 4 * ref.se
