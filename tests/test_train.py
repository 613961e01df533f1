"""Trains of impacts as a map (phaseimpact.train): REFERENCE.md §7's impulsive limit, the energy
balance of a periodic orbit, and fixed points against long iteration."""

import math

import numpy as np
import pytest
from _cli import run

from phaseimpact import seed_parameters
from phaseimpact.integrate import scales
from phaseimpact.train import impact_train, lyapunov_exponent, map_fixed_point, orbit_diagram

SEED = seed_parameters(v=1.0)


def impulsive(p, period, e=1.0):
    """REFERENCE.md §7: in (omega x2, x2dot) the map is z -> R(omega T)(D z + b); its fixed point
    (I - R D)^-1 R b and multipliers eig(R D), back in (x2, x2dot)."""
    omega, mu = math.sqrt(p.Kb / p.M2), p.M1 / (p.M1 + p.M2)
    c, s = math.cos(omega * period), math.sin(omega * period)
    R, D = np.array([[c, s], [-s, c]]), np.diag([1.0, 1.0 - (1 + e) * mu])
    z = np.linalg.solve(np.eye(2) - R @ D, R @ np.array([0.0, (1 + e) * mu * p.v]))
    return np.array([z[0] / omega, z[1]]), np.sort(np.linalg.eigvals(R @ D).real), omega


def limit_error(stiffening):
    """Elastic contact (abrate, e = 1) on a linear plate, the contact made short by a stiffer K:
    the distance of the map's fixed point and multipliers from the impulsive map, and the contact
    time over the plate period."""
    p = SEED.replace(Km=0.0, Kb=SEED.Kb / 100, K=SEED.K * stiffening)
    s = scales(p)
    period = 0.37 * s.plate_period
    fp = map_fixed_point(p, "abrate", period)
    z, multipliers, omega = impulsive(p, period)
    assert fp.converged and fp.stable
    scaled = np.array([omega, 1.0])  # compare in (omega x2, x2dot)
    error_z = np.linalg.norm((fp.plate - z) * scaled) / np.linalg.norm(z * scaled)
    error_m = np.max(np.abs(np.sort(fp.multipliers.real) - multipliers))
    return error_z, error_m, s.contact_time / s.plate_period, fp


def test_the_map_tends_to_the_impulsive_limit():
    """The errors are of the order of the contact time over the plate period and shrink with it."""
    coarse = limit_error(100.0)
    fine = limit_error(1e4)
    for error_z, error_m, ratio, fp in (coarse, fine):
        assert error_z < 3 * ratio and error_m < 3 * ratio
        mu = SEED.M1 / (SEED.M1 + SEED.M2)
        assert abs(np.prod(fp.multipliers).real - (1 - 2 * mu)) < 3 * ratio  # det R D = 1 - (1 + e) mu
        assert abs(np.prod(fp.multipliers).imag) < 1e-9
    shrink = coarse[2] / fine[2]
    assert coarse[0] / fine[0] == pytest.approx(shrink, rel=0.5)


def test_the_fixed_point_is_where_long_iteration_goes_and_balances_its_energy():
    """A stable period-1 orbit attracts the iteration from rest; on it the plate's energy repeats, so
    what each projectile leaves behind, M1 (v^2 - v_out^2) / 2, is what its contact dissipated."""
    p = SEED.replace(kappa=3e9)
    period = 3e-3
    fp = map_fixed_point(p, "hunt-crossley", period)
    assert fp.converged and fp.stable and max(abs(fp.multipliers)) < 1
    long = impact_train(p, "hunt-crossley", period, 400, rtol=1e-12)
    scale = np.array([p.hertz_indentation, p.v])
    assert np.max(np.abs(long.plate[-1] - fp.plate) / scale) < 1e-8
    at = impact_train(p, "hunt-crossley", period, 1, plate=fp.plate, rtol=1e-12)
    assert at.energy_in[0] == pytest.approx(at.dissipated_energy[0], rel=1e-6)


def test_the_lyapunov_exponent_of_a_stable_orbit_is_its_largest_multiplier():
    p = SEED.replace(kappa=3e9)
    fp = map_fixed_point(p, "hunt-crossley", 3e-3)
    # on the orbit the Jacobian repeats: (1/n) log |J^n w| -> log of the spectral radius, with an error
    # of (log of J's non-normality) / n
    lam = lyapunov_exponent(p, "hunt-crossley", 3e-3, plate=fp.plate, iterations=400)
    assert lam == pytest.approx(math.log(max(abs(fp.multipliers))), abs=0.02)


def test_the_orbit_diagram_does_not_depend_on_the_threads():
    p = SEED.replace(kappa=3e9)
    values = np.linspace(2e-3, 3.5e-3, 4)
    one = orbit_diagram(p, "hunt-crossley", "T", values, transients=20, samples=5, n_jobs=1)
    two = orbit_diagram(p, "hunt-crossley", "T", values, transients=20, samples=5, n_jobs=2)
    assert np.array_equal(one.plate, two.plate) and np.array_equal(one.distinct, two.distinct)
    assert one.plate.shape == (4, 5, 2)


def test_bad_input_is_refused_before_any_work():
    with pytest.raises(ValueError, match="period = -1"):
        impact_train(SEED, "abrate", -1, 3)
    with pytest.raises(ValueError, match="impacts = 0"):
        impact_train(SEED, "abrate", 1e-3, 0)
    with pytest.raises(ValueError, match="param = 'M1'"):
        orbit_diagram(SEED, "abrate", "M1", [1.0])
    code, _, err = run(["orbit-diagram", "--law", "abrate", "--axis", "v=1:2:3"])
    assert code == 2 and "--period" in err
    code, _, err = run(["train", "--law", "abrate", "--period", "0"])
    assert code == 2 and "period" in err
