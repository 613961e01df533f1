"""The Hertz/Johnson half-space constant of the contact time (docs/physics.md §4, Johnson 1985 §11.4).

A mass ``m`` hitting a half-space at ``v`` with ``P = K delta^(3/2)`` obeys ``m delta'' = -K delta^(3/2)``;
energy gives ``delta'^2 = v^2 (1 - (delta/delta_max)^(5/2))``, so the contact lasts
``T = 2 (delta_max / v) int_0^1 dxi / sqrt(1 - xi^(5/2)) = 2 tau delta_max / v``. The oracle here is that
integral done by scipy's ``quad`` (sharing nothing with the code's closed form through Gamma functions),
and the simulated contact of Abrate's law on a rigid target.
"""

import math

import pytest
from scipy.integrate import quad

import phaseimpact as pi
from phaseimpact.integrate.api import hertz_contact_time, scales
from phaseimpact.model.contact import hertz_scales

#: 2 tau, quoted in issue 23 and (as tau = 1.4716376...) in docs/physics.md §4.
TWO_TAU_QUOTED = 2.943275


def two_tau_by_quadrature(alpha: float = 1.5) -> float:
    # the integrand's end singularity ~ (1 - xi)^(-1/2) is integrable; quad's algebraic weight takes it exactly
    n = alpha + 1

    def smooth(xi):  # 1/sqrt(1 - xi^n) = (1 - xi)^(-1/2) * sqrt((1 - xi) / (1 - xi^n))
        return math.sqrt((1 - xi) / (1 - xi**n)) if xi < 1 else math.sqrt(1 / n)

    value, err = quad(smooth, 0.0, 1.0, weight="alg", wvar=(0.0, -0.5), epsabs=1e-15, epsrel=1e-14)
    assert err < 1e-12
    return 2 * value


def test_half_space_constant_by_quadrature():
    two_tau = two_tau_by_quadrature()
    assert two_tau == pytest.approx(TWO_TAU_QUOTED, abs=5e-7)  # the quoted digits
    # the plain integrand, no weight: a cross-check of the rewriting above
    plain, _ = quad(lambda xi: 1 / math.sqrt(1 - xi**2.5), 0.0, 1.0, limit=200)
    assert 2 * plain == pytest.approx(two_tau, rel=1e-7)


def test_code_uses_the_half_space_constant():
    two_tau = two_tau_by_quadrature()
    # hertz_contact_time(alpha, delta_max, v) = 2 tau delta_max / v: with delta_max = v = 1 it is 2 tau
    assert hertz_contact_time(1.5, 1.0, 1.0) == pytest.approx(two_tau, rel=1e-12)
    for target in ("rigid", "plate"):
        p = pi.seed_parameters(v=3.0).replace(target=target)
        m = p.M1 if target == "rigid" else p.M1 * p.M2 / (p.M1 + p.M2)
        delta_max = (5 * m * p.v**2 / (4 * p.K)) ** 0.4  # energy: m v^2/2 = 2/5 K delta_max^(5/2)
        expected = two_tau * delta_max / p.v
        assert scales(p).contact_time == pytest.approx(expected, rel=1e-12), target
        assert hertz_scales(p)["contact_time"] == pytest.approx(expected, rel=1e-12), target
    # docs/physics.md §4's T = 3.218065... (m^2 / (K^2 v))^(1/5): 2 tau (5/4)^(2/5)
    assert two_tau * 1.25**0.4 == pytest.approx(3.218065, abs=5e-7)


@pytest.mark.parametrize("v", [0.3, 1.0, 13.0])
def test_simulated_hertz_contact_lasts_two_tau_delta_max_over_v(v):
    """Abrate's undamped law on a rigid target: one contact of 2 tau delta_max / v, delta_max from energy."""
    p = pi.seed_parameters(v=v).replace(target="rigid")
    tr = pi.simulate(p, "abrate", rtol=1e-12)
    assert tr.n_contacts == 1
    delta_max = (5 * p.M1 * v**2 / (4 * p.K)) ** 0.4
    assert tr.max_indentation == pytest.approx(delta_max, rel=1e-9)
    separation = next(e for e in tr.events if e.kind == "separation")
    assert separation.t == pytest.approx(two_tau_by_quadrature() * delta_max / v, rel=1e-9)
