"""Continuation, critical damping and the asymptotic-point machinery (REFERENCE §5)."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from phaseimpact import seed_parameters, simulate
from phaseimpact.analysis import classify_outcome, find_asymptotic_points, fixed_points
from phaseimpact.continuation import (
    _first_stick_margin,
    critical_damping,
    evaluate_point,
    locate_transition,
    sweep,
)
from phaseimpact.model import ContactLaw

PAPER = ContactLaw("paper")


def pitchfork_count(mu, mu_c=1.0):
    """Distinct rest points reached by x' = (mu - mu_c) x - x^3 from x0 = +-1.

    Known answer: one rest point (0) for mu <= mu_c, two (+-sqrt(mu - mu_c)) above. Each
    trajectory's end point is polished by Newton on the right-hand side, so the count is exact
    however close mu is to mu_c.
    """
    r = mu - mu_c
    ends = []
    for x0 in (-1.0, 1.0):
        sol = solve_ivp(lambda t, x: r * x - x**3, (0, 50.0), [x0], rtol=1e-10, atol=1e-12)
        x = sol.y[0, -1]
        for _ in range(200):
            step = (r * x - x**3) / (r - 3 * x * x)
            x -= step
            if abs(step) <= 1e-15:
                break
        ends.append(x)
    return len({round(x, 12) for x in ends})


def test_pitchfork_normal_form_critical_value():
    """A system with a known answer: the count changes 1 -> 2 at mu_c = 1, found to 1e-6."""
    found = locate_transition(pitchfork_count, 0.5, 2.0, rtol=1e-7, log=False)
    assert abs(found.value - 1.0) <= 1e-6
    assert (found.n_below, found.n_above) == (1, 2)


def test_pitchfork_with_indicator():
    """Brent on a continuous indicator (-(mu - mu_c)) gives the same value, confirmed by counts."""
    found = locate_transition(pitchfork_count, 0.5, 2.0, rtol=1e-7, indicator=lambda mu: 1.0 - mu)
    assert found.method == "brent"
    assert abs(found.value - 1.0) <= 1e-6


def test_paper_one_point_below_and_two_above_kappa_c():
    """Seed claim 7 / REFERENCE §5: one asymptotic point well below kappa_c, two (or more) just above."""
    p = seed_parameters()
    result = critical_damping(p, PAPER, bracket=(1e12, 2e12))
    assert result.status == "success", result.message
    kc = result.kappa_c
    assert 1e12 < kc < 2e12
    assert result.bracket[1] / result.bracket[0] - 1 <= 1.01e-6
    assert evaluate_point(p.replace(kappa=1e9), PAPER, 0.01).n_asymptotic == 1
    assert evaluate_point(p.replace(kappa=kc / 2), PAPER, 0.01).n_asymptotic == 1
    assert evaluate_point(p.replace(kappa=kc * 1.001), PAPER, 0.01).n_asymptotic >= 2
    # The re-check at a tighter integration tolerance moves it by far less than the bracket.
    assert result.shift < 1e-7


def test_kappa_c_from_count_bisection_matches_stick_margin():
    """Two independent routes: bisection on the count of stick points and Brent on the first
    stick's analytic margin (REFERENCE §3) agree to the requested 1e-6."""
    p = seed_parameters()

    def count(kappa):
        return evaluate_point(p.replace(kappa=kappa), PAPER, 0.01).n_asymptotic

    by_count = locate_transition(count, 1.4e12, 1.6e12, rtol=1e-6)
    by_margin = locate_transition(count, 1.4e12, 1.6e12, rtol=1e-6,
                                  indicator=lambda k: _first_stick_margin(p.replace(kappa=k), PAPER, 0.01, 1e-10))
    assert by_count.method == "bisection" and by_margin.method == "brent"
    assert abs(by_count.value / by_margin.value - 1) <= 2e-6


def test_sweep_brackets_the_refined_value():
    """The sweep's first 1 -> 2 change brackets the refined kappa_c."""
    p = seed_parameters()
    kappas = np.geomspace(1e11, 1e13, 12)
    result = sweep(p, PAPER, kappas)
    i = result.first_split()
    assert i is not None
    kc = critical_damping(p, PAPER, bracket=(kappas[i], kappas[i + 1])).kappa_c
    assert kappas[i] <= kc <= kappas[i + 1]
    assert np.all(result.n_asymptotic[: i + 1] == 1)


def test_sweep_independent_of_jobs():
    """Results do not depend on the number of jobs (bit-identical)."""
    p = seed_parameters()
    kappas = np.geomspace(1e9, 1e14, 20)
    one = sweep(p, PAPER, kappas, n_jobs=1)
    two = sweep(p, PAPER, kappas, n_jobs=2)
    assert np.array_equal(one.n_asymptotic, two.n_asymptotic)
    assert np.array_equal(one.max_force, two.max_force)
    assert all(np.array_equal(a, b) for a, b in zip(one.points, two.points, strict=True))


@pytest.mark.slow
def test_dask_local_cluster_matches_jobs_1():
    """The Dask backend on a loopback dask.distributed cluster gives the --jobs 1 numbers."""
    distributed = pytest.importorskip("dask.distributed")
    p = seed_parameters()
    kappas = np.geomspace(1e9, 1e14, 10)
    reference = sweep(p, PAPER, kappas, n_jobs=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        on_dask = sweep(p, PAPER, kappas, backend="dask", scheduler=cluster.scheduler_address)
    assert np.array_equal(reference.n_asymptotic, on_dask.n_asymptotic)
    assert np.array_equal(reference.max_force, on_dask.max_force)


def test_stick_points_are_event_exact():
    """An event-driven run's stick point sits exactly at deltadot = 0 with the stick event's delta."""
    tr = simulate(seed_parameters(kappa=1e9), PAPER, 0.01)
    points = find_asymptotic_points(tr)
    stick = tr.events_of("stick")[0]
    assert len(points) == 1 and points.method == "events"
    assert points.points[0, 0] == stick.delta and points.points[0, 1] == 0.0
    assert math.isclose(points.dwell[0], 0.01 - stick.t, rel_tol=1e-12)
    assert classify_outcome(tr, points).kind == "stick"


def test_distance_method_on_rk4_finds_the_same_stick_point():
    """The seed's RK4 output (no events) with a distance tolerance finds the exact stick point."""
    p = seed_parameters(kappa=1e9)
    exact = find_asymptotic_points(simulate(p, PAPER, 0.002))
    rk4 = find_asymptotic_points(simulate(p, PAPER, 0.002, integrator="rk4", step=2e-8, save="steps", every=5),
                                 tol=1e-3)
    assert len(rk4) == 1 and rk4.method == "distance"
    assert abs(rk4.points[0, 0] / exact.points[0, 0] - 1) < 1e-2


def test_outcomes_are_classified():
    """Rebound for Hunt-Crossley, stick for paper, runaway for the negative-damping branch."""
    p = seed_parameters()
    assert classify_outcome(simulate(p.replace(kappa=1e9), "hunt-crossley", 0.01)).kind == "rebound"
    assert classify_outcome(simulate(p.replace(kappa=1e9), PAPER, 0.01)).kind == "stick"
    runaway = simulate(p.replace(kappa=3e12), PAPER, 0.01)
    assert classify_outcome(runaway).kind == "runaway"
    assert np.all(np.isfinite(runaway.final_state))
    bounded = simulate(p, ContactLaw("abrate", bilateral=True), 0.002)
    assert classify_outcome(bounded).kind == "bounded-oscillation"
    rest = simulate(seed_parameters(kappa=1e9, target="rigid"), PAPER, 0.01)
    assert classify_outcome(rest).kind == "rest"


def test_fixed_points_are_sets_where_they_should_be():
    """The stick set of paper and the separated states of a unilateral law are reported as sets;
    the bilateral Hertz law has an isolated equilibrium at the origin."""
    p = seed_parameters()
    (paper_set,) = fixed_points(p, PAPER)
    assert "stick set" in paper_set.description
    (separated,) = fixed_points(p, "abrate")
    assert "separated" in separated.description and np.all(separated.members[:, 0] <= separated.members[:, 1])
    (origin,) = fixed_points(p, ContactLaw("abrate", bilateral=True))
    assert np.allclose(origin.state, 0.0, atol=1e-12)
    # Undamped: target oscillation eigenvalues are +-i sqrt(Kb/M2) (no contact stiffness at delta = 0).
    omega = math.sqrt(p.Kb / p.M2)
    assert np.any(np.isclose(np.abs(origin.eigenvalues.imag), omega, rtol=1e-4))
    assert origin.stability == "neutral"


def test_phase_portrait_family_from_states_and_speeds():
    """A family from given states (a grid in the relative plane) and from impact speeds, in one
    call; every member starts where asked and carries its events."""
    from phaseimpact.analysis import plane_coordinates
    from phaseimpact.continuation import phase_portrait

    p = seed_parameters(kappa=1e9)
    states = [(d, 0.0, v, 0.0) for d in (0.0, 1e-5) for v in (0.5, 1.0)]
    family = phase_portrait(p, PAPER, states=states, t_end=0.001, n_jobs=2)
    assert len(family) == 4
    for state, tr in zip(states, family, strict=True):
        assert np.array_equal(tr.y[0, :4], state)
        delta, deltadot = plane_coordinates(tr.y, ("delta", "deltadot"))
        assert delta[0] == state[0] and deltadot[0] == state[2]
        assert tr.events_of("stick")  # each one sticks in the relative plane
    by_speed = phase_portrait(p, PAPER, speeds=[0.5, 1.0, 2.0], t_end=0.001)
    first_stick = [tr.events_of("stick")[0].delta for tr in by_speed]
    assert first_stick == sorted(first_stick)  # faster impacts stick deeper


def test_count_up_to_two_equals_the_full_count():
    """The early-stopping count (stop at the second stick once it has lasted min_dwell) agrees with
    the full run's count, capped at two, on both sides of kappa_c and far from it."""
    from phaseimpact.continuation import count_up_to

    p = seed_parameters()
    for kappa in [1e9, 1e11, 1.4994e12, 1.49943e12, 1.5e12, 3e12, 1e13]:
        full = evaluate_point(p.replace(kappa=kappa), PAPER, 0.01).n_asymptotic
        assert count_up_to(p.replace(kappa=kappa), PAPER, 0.01, 2) == min(full, 2), kappa


def test_sweep_numbers_do_not_depend_on_chunking():
    """Chunks follow n_jobs; a point's numbers must not: a 40-point sweep (chunks of 16) equals
    each point integrated alone, bit for bit."""
    from phaseimpact import simulate_batch

    p = seed_parameters()
    kappas = np.geomspace(1e10, 1e13, 40)
    result = sweep(p, PAPER, kappas, n_jobs=1)
    for i in (0, 17, 39):
        (alone,) = simulate_batch([p.replace(kappa=float(kappas[i]))], PAPER, 0.01)
        assert result.max_force[i] == alone.max_force
