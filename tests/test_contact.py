"""Contact mechanics: Hertz scales, the contact of a peak force and validity (REFERENCE §4).

Expected values come from REFERENCE §4 (printed digits), from the closed forms of Hertz impact
re-derived here or checked against a numerical integration of ``m delta'' = -K delta^1.5``, and from
the issue's own estimates for sand on a gelcoat (contact about 0.3 µs, peak pressure near 1 GPa,
about ten times the gelcoat's compressive strength).
"""

from __future__ import annotations

import math

import pytest
from scipy.integrate import solve_ivp

from phaseimpact import seed_parameters
from phaseimpact.case import load_case, seed_case
from phaseimpact.model.contact import CONTACT_RATIO_LIMIT, hertz_contact, hertz_scales, validity, validity_for_force
from phaseimpact.parameters import FIRST_YIELD_FACTOR, STEEL, Parameters

# ---------------------------------------------------------------------------------------------
# Hertz closed forms (REFERENCE §4)
# ---------------------------------------------------------------------------------------------

def _numerical_hertz(m: float, K: float, v: float) -> tuple[float, float]:
    """Contact time and largest indentation of m delta'' = -K delta^1.5 from delta = 0, delta' = v,
    integrated to the turning point (time-symmetric: T = 2 t_max)."""
    def turning(t, y):
        return y[1]
    turning.terminal, turning.direction = True, -1
    t_scale = (m / K) ** 0.4 * v ** -0.2  # Hertz time scale
    sol = solve_ivp(lambda t, y: [y[1], -K / m * max(y[0], 0.0) ** 1.5], (0, 10 * t_scale), [0.0, v],
                    events=turning, rtol=1e-12, atol=[1e-16 * v * t_scale, 1e-16 * v], method="DOP853")
    return 2 * sol.t_events[0][0], sol.y_events[0][0][0]


def test_seed_projectile_on_rigid_target_reference_section_4():
    """REFERENCE §4: seed projectile at 1 m/s on a rigid target: delta_max = 4.69617e-5 m, T = 1.38221e-4 s."""
    p = seed_parameters(target="rigid")
    s = hertz_scales(p)
    assert f"{s['indentation']:.5e}" == "4.69617e-05"
    assert f"{s['contact_time']:.5e}" == "1.38221e-04"
    # T = 3.218065... (m^2/(K^2 v))^(1/5) with m = M1 (REFERENCE §4)
    assert s["contact_time"] == pytest.approx(3.218065 * (p.M1**2 / (p.K**2 * p.v)) ** 0.2, rel=3e-7)
    assert s["plate_period"] == math.inf
    assert s["peak_force"] == pytest.approx(p.K * s["indentation"] ** 1.5, rel=1e-14)


def test_seed_plate_period():
    """REFERENCE §4: target period 2 pi sqrt(M2/Kb) about 1.0e-3 s for the seed."""
    p = seed_parameters()
    assert hertz_scales(p)["plate_period"] == pytest.approx(2 * math.pi * math.sqrt(p.M2 / p.Kb), rel=1e-14)
    assert 0.95e-3 < hertz_scales(p)["plate_period"] < 1.05e-3


def test_sand_grain_on_rigid_target_matches_integration():
    """Issue 12 §6: a 100 µm quartz grain at 90 m/s on a rigid target: contact ~1e-7 s; the closed
    forms agree with a direct integration of the Hertz impact to 1e-8."""
    p = load_case("sand-gelcoat").parameters(target="rigid")
    s = hertz_scales(p)
    assert 1e-7 < s["contact_time"] < 1e-6
    T, delta = _numerical_hertz(p.M1, p.K, p.v)
    assert s["contact_time"] == pytest.approx(T, rel=1e-8)
    assert s["indentation"] == pytest.approx(delta, rel=1e-8)


def test_contact_radius_and_pressure_are_hertz():
    """Johnson 1985 eq. 4.22-4.24: a0 = sqrt(R delta), p0 = 3F/(2 pi a0^2) = (2/pi) E* a0/R, with
    E* = 1/eta from the materials (REFERENCE §2, eq. 4)."""
    case = load_case("sand-gelcoat")
    p = case.parameters()
    s = hertz_scales(p)
    R = case.geometry.R1 * case.geometry.R2 / (case.geometry.R1 + case.geometry.R2)
    e_star = 1 / ((1 - case.projectile.nu**2) / case.projectile.E + (1 - case.plate.nu**2) / case.plate.E)
    assert s["contact_radius"] == pytest.approx(math.sqrt(R * s["indentation"]), rel=1e-12)
    assert s["peak_pressure"] == pytest.approx(2 / math.pi * e_star * s["contact_radius"] / R, rel=1e-12)
    again = hertz_contact(s["peak_force"], p)  # a = (3 F R / (4 E*))^(1/3) gives the same contact
    assert again["contact_radius"] == pytest.approx(s["contact_radius"], rel=1e-12)
    assert again["peak_pressure"] == pytest.approx(s["peak_pressure"], rel=1e-12)
    assert hertz_contact(0.0, p) == {"contact_radius": 0.0, "peak_pressure": 0.0}


def test_sand_on_gelcoat_numbers_of_the_issue():
    """Issue 12 'Why': sand on gelcoat at 90 m/s: contact about 0.3 µs, p0 near 1 GPa, about ten
    times the gelcoat's compressive strength (IEA-15-240-RWT Xc = 87 MPa)."""
    case = load_case("sand-gelcoat")
    s = hertz_scales(case.parameters(), case.plate)
    assert 0.2e-6 < s["contact_time"] < 0.5e-6
    assert 0.5e9 < s["peak_pressure"] < 2e9
    assert 5 < s["peak_pressure"] / case.plate.yield_strength < 20
    assert s["first_yield_pressure"] == FIRST_YIELD_FACTOR * 8.7e7


def test_scales_without_radius_leave_pressure_out():
    p = Parameters(M1=0.26, M2=0.31, K=2.2e10, Kb=1.2e7, Km=1.7e11)
    s = hertz_scales(p)
    assert s["contact_radius"] is None and s["peak_pressure"] is None and s["contact_time"] > 0
    with pytest.raises(ValueError, match="R = None"):
        validity(p, STEEL)


# ---------------------------------------------------------------------------------------------
# Validity
# ---------------------------------------------------------------------------------------------

def test_validity_sand_on_gelcoat_is_out_of_range():
    case = load_case("sand-gelcoat")
    verdict = validity(case.parameters(), case.plate, case.projectile)
    assert verdict != "ok"
    assert "exceeds 1.6 x yield strength 8.7e+07 Pa of the target" in verdict and "Johnson" in verdict
    assert verdict.endswith("elastic Hertz contact is out of its range")


def test_validity_seed_is_ok():
    """The seed gives no yield strength; its contact radius is about 0.05 R (REFERENCE §2 geometry)."""
    case = seed_case()
    assert validity(case.parameters(), case.plate, case.projectile) == "ok"


def test_validity_flags_a_soft_coating_by_geometry():
    """Sand on the PU coating: no yield strength, but the contact radius is about R (Hertz needs a << R)."""
    case = load_case("sand-lep")
    verdict = validity(case.parameters(), case.plate)
    assert "Hertz needs a << R" in verdict and "yield" not in verdict
    assert hertz_scales(case.parameters())["contact_radius"] > CONTACT_RATIO_LIMIT * case.geometry.R1


def test_validity_for_force_threshold():
    """p0 = 3F/(2 pi a^2) with a = (3FR/(4E*))^(1/3), so p0^3 ∝ F: the force at p0 = 1.6 Y is exact,
    and the verdict flips across it (seed geometry, plate yield strength 250 MPa assumed)."""
    case = seed_case().with_settings(["plate.yield_strength=2.5e8"])
    p = case.parameters()
    e_star = 3 * p.K / (4 * math.sqrt(p.R))
    p_limit = FIRST_YIELD_FACTOR * 2.5e8
    f_limit = (p_limit * 2 * math.pi / 3) ** 3 * (3 * p.R / (4 * e_star)) ** 2  # from p0^3 = (3/(2 pi))^3 F (4E*/3R)^2
    assert hertz_contact(f_limit, p)["peak_pressure"] == pytest.approx(p_limit, rel=1e-12)
    assert validity_for_force(0.99 * f_limit, p, case.plate) == "ok"
    assert "yield strength 2.5e+08 Pa of the target" in validity_for_force(1.01 * f_limit, p, case.plate)
    assert validity_for_force(0.0, p, case.plate) == "ok"
    # The seed at 1 m/s is far beyond first yield of such a steel (p0 ≈ 3 GPa).
    assert validity(p, case.plate) != "ok"
    with pytest.raises(ValueError, match="force = -1.0"):
        validity_for_force(-1.0, p, case.plate)


def test_validity_checks_the_projectile_too():
    """A hailstone (ice, compressive strength 5.9 MPa) crushes long before elastic Hertz contact ends."""
    case = load_case("hail-laminate")
    verdict = validity(case.parameters(), case.plate, case.projectile)
    assert "of the projectile" in verdict
    assert "of the projectile" not in validity(case.parameters(), case.plate)
