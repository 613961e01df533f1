"""The closed-form flight (integrate/flight.py) against scipy's DOP853 on the flight's own
equations, and its test that no event can happen any more against a dense scan."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from phaseimpact import seed_parameters, simulate
from phaseimpact.integrate import flight
from phaseimpact.model.laws import as_law
from phaseimpact.model.rhs import pack

SEED = seed_parameters(v=1.0, kappa=3e9)
TARGETS = {
    "duffing (seed plate)": SEED,
    "strong membrane": SEED.replace(Km=SEED.Km * 1e4),  # m = b A^2 / (2 omega^2) near its bound 1/2
    "harmonic": SEED.replace(Km=0.0),
    "membrane only": SEED.replace(Kb=0.0),
    "free": SEED.replace(target="free"),
    "rigid": SEED.replace(target="rigid"),
}


def integration_state(x1, x2, v1, v2, t=0.0):
    return np.array([x1, x2, v1, v2, 0.25, t])


def closed_form(params, u0, times):
    c = pack(params, as_law("hunt-crossley"))
    F = np.zeros((7, 6))
    flight.coefficients(c, u0, u0[5], F)
    out = np.empty(6)
    rows = []
    for t in times:
        flight.state_at(c, F, u0, u0[5], t, out)
        rows.append(out.copy())
    return np.array(rows)


def reference(params, u0, times):
    """The flight's ODE by scipy's DOP853 at rtol 1e-13."""
    springs = params.target == "plate"
    kb, km = (params.Kb, params.Km) if springs else (0.0, 0.0)

    def f(_t, y):
        accel = 0.0 if params.target == "rigid" else -(kb * y[1] + km * y[1] ** 3) / params.M2
        return [y[2], y[3], 0.0, accel]

    sol = solve_ivp(f, (times[0], times[-1]), u0[:4], method="DOP853", rtol=1e-13, atol=1e-20, t_eval=times)
    return sol.y.T


@pytest.mark.parametrize("name", list(TARGETS))
@pytest.mark.parametrize("start", [(-1e-5, 4e-5, -0.3, 0.7), (-2e-6, -1.3e-4, 0.2, 1e-3), (0.0, 0.0, 0.1, 0.0)])
def test_flight_closed_form_agrees_with_dop853(name, start):
    params = TARGETS[name]
    if params.target == "rigid":
        start = (start[0], 0.0, start[2], 0.0)
    u0 = integration_state(*start, t=1e-4)
    period = params.target_period if np.isfinite(params.target_period) else 1e-3
    times = 1e-4 + np.linspace(0.0, 3.0 * period, 41)
    exact = closed_form(params, u0, times)
    ref = reference(params, u0, times)
    scale = np.array([params.hertz_indentation, params.hertz_indentation, params.v, params.v])
    assert np.max(np.abs(exact[:, :4] - ref) / scale) < 1e-10
    assert np.all(exact[:, 4] == 0.25)  # no contact work in flight
    np.testing.assert_array_equal(exact[:, 5], times)


def test_flight_conserves_the_target_energy_over_many_periods():
    """Over a thousand periods only the rounding of the growing elliptic argument is left
    (about 1e-16 of it, which is some 7e3 there)."""
    params = TARGETS["strong membrane"]
    u0 = integration_state(-1e-5, 4e-5, -0.3, 0.7)
    times = np.linspace(0.0, 1e3 * params.target_period, 2001)
    states = closed_form(params, u0, times)
    x2, v2 = states[:, 1], states[:, 3]
    energy = 0.5 * params.M2 * v2**2 + 0.5 * params.Kb * x2**2 + 0.25 * params.Km * x2**4
    assert np.max(np.abs(energy / energy[0] - 1)) < 1e-10


@pytest.mark.parametrize("name", ["duffing (seed plate)", "strong membrane", "harmonic", "free", "rigid"])
def test_unreachable_means_no_event_can_follow(name):
    """Where the test says no event can happen, a dense scan of the next periods finds
    ``delta < 0`` and ``deltadot < 0`` throughout; just short of its bounds it says no."""
    params = TARGETS[name]
    c = pack(params, as_law("hunt-crossley"))

    def unreachable(u):
        F = np.zeros((7, 6))
        flight.coefficients(c, u, u[5], F)
        return flight.unreachable(F, u)

    x2, v2 = (0.0, 0.0) if params.target == "rigid" else (6e-5, -0.4)
    period = params.target_period if np.isfinite(params.target_period) else 1e-3
    # receding beyond the reach and faster than the target can move
    for v1 in (-0.5, -2.0, -9.0):
        u0 = integration_state(-2e-3, x2, v1, v2)
        if params.target == "free":
            u0[3] = v1 + 0.1
        if unreachable(u0):
            states = closed_form(params, u0, np.linspace(0.0, 4.0 * period, 4001))
            assert np.all(states[:, 0] - states[:, 1] < 0)
            assert np.all(states[:, 2] - states[:, 3] < 0)
    # approaching, or within reach: never claimed
    assert not unreachable(integration_state(-2e-3, x2, 0.1, v2))
    if params.target == "plate":
        assert not unreachable(integration_state(-1e-6, x2, -9.0, v2))
        slow = integration_state(-2e-3, x2, -1e-3, v2)
        assert not unreachable(slow)


def test_long_flight_is_one_step_once_nothing_can_happen():
    """A rebound run to a far horizon without stopping when settled: the flight after the last
    separation is one step, and the state at the horizon is that of the closed form."""
    short = simulate(SEED, "hunt-crossley", 2e-3, stop_when_settled=False)
    far = simulate(SEED, "hunt-crossley", 2.0, stop_when_settled=False)
    assert far.nsteps == short.nsteps
    assert far.event_kind.tolist() == short.event_kind.tolist()
    u_sep = np.append(far.event_y[far.event_kind == 1][-1], far.event_t[far.event_kind == 1][-1])
    expected = closed_form(SEED, u_sep, [2.0])[0]
    np.testing.assert_allclose(far.final_state[:4], expected[:4], rtol=1e-12, atol=1e-18)


@pytest.mark.parametrize("name", ["duffing (seed plate)", "strong membrane", "harmonic", "membrane only"])
def test_next_centre_is_the_targets_next_pass_through_zero(name):
    """Flight steps end where the target passes its centre: x2 is zero there and keeps one sign
    before it (so x2dot is monotone within a step)."""
    params = TARGETS[name]
    c = pack(params, as_law("hunt-crossley"))
    u0 = integration_state(-1e-5, 4e-5, -0.3, 0.7, t=1e-4)
    F = np.zeros((7, 6))
    flight.coefficients(c, u0, u0[5], F)
    s, out = u0[5], np.empty(6)
    for _ in range(5):
        centre = flight.next_centre(F, s)
        flight.state_at(c, F, u0, u0[5], centre, out)
        assert abs(out[1]) < 1e-12 * params.hertz_indentation
        between = closed_form(params, u0, np.linspace(s, centre, 400)[1:-1])
        assert np.all(between[:, 1] > 0) or np.all(between[:, 1] < 0)
        s = centre


def test_a_grazing_extremum_in_flight_is_not_stepped_over():
    """Seed case at 8.45 m/s near a grazing (an extremum of delta in flight crossing zero): the
    sixth extremum is a smooth function of kappa across its root. A flight step holding the
    minimum of delta and the next contact, with deltadot crossing zero twice in it, skipped the
    minimum and jumped from -1e-7 to +7e-6."""
    from phaseimpact.continuation.transition import delta_extremum

    root = 7.70688062e9
    below, above = (delta_extremum(seed_parameters(v=8.45041368, kappa=root * f), "hunt-crossley", 6)
                    for f in (0.999, 1.001))
    assert below < 0 < above
    assert 0.5 < -below / above < 2.0
