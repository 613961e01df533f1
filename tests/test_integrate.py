"""Verification of the integrators against closed forms and invariants.

Sources: REFERENCE §4 (undamped Hertz impact on a rigid wall / two free masses; Hunt-Crossley
restitution; energy conservation with kappa = 0; loop area = energy lost), REFERENCE §3
(restitution laws; RK4 chatter on eq. 8), and the order of classic RK4. Expected values are
closed forms evaluated here (scipy.special.gamma; a 60-digit bisection for the restitution) or
the exact integrator at a much tighter tolerance than the quantity under test.
"""

from __future__ import annotations

import math
from decimal import Decimal, localcontext

import numpy as np
import pytest
from scipy.special import gamma

from phaseimpact import ContactLaw, seed_parameters, simulate
from phaseimpact.quantities import impact_quantities

#: tau = sqrt(pi) Gamma(7/5) / Gamma(9/10) (REFERENCE §4).
TAU = math.sqrt(math.pi) * gamma(7 / 5) / gamma(9 / 10)
CHI = {  # REFERENCE §3
    "hunt-crossley-approx": lambda e: 3 * (1 - e) / 2,
    "lankarani-nikravesh": lambda e: 3 * (1 - e**2) / 4,
    "flores": lambda e: 8 * (1 - e) / (5 * e),
    "gonthier": lambda e: (1 - e**2) / e,
}


def exact_restitution(a: float) -> float:
    """Root e in (0, 1] of 1 - e a = (1 + a) exp(-a (1 + e)) (REFERENCE §4), 60-digit bisection."""
    with localcontext() as ctx:
        ctx.prec = 60
        A = Decimal(a)
        lo, hi = Decimal(0), Decimal(1)
        for _ in range(190):
            mid = (lo + hi) / 2
            if 1 - mid * A - (1 + A) * (-(A * (1 + mid))).exp() > 0:
                lo = mid
            else:
                hi = mid
        return float((lo + hi) / 2)


def impact_energy(p) -> float:
    return 0.5 * p.M1 * p.v**2


def hertz_closed_form(m, K, v):
    """REFERENCE §4: delta_max = (5 m v^2 / (4K))^(2/5), T = 2 tau delta_max / v."""
    delta_max = (5 * m * v**2 / (4 * K)) ** 0.4
    return delta_max, 2 * TAU * delta_max / v


# ---------------------------------------------------------------------------------------------
# Undamped Hertz impact (REFERENCE §4)
# ---------------------------------------------------------------------------------------------

def test_tau_constant():
    """REFERENCE §4: tau = 1.4716376..., T = 3.218065... (m^2/(K^2 v))^(1/5)."""
    assert TAU == pytest.approx(1.4716376, abs=1e-7)
    assert 2 * TAU * 1.25**0.4 == pytest.approx(3.218065, abs=1e-6)


@pytest.mark.parametrize("target", ["rigid", "free"])
@pytest.mark.parametrize("v", [0.1, 1.0, 13.0])
@pytest.mark.parametrize("masses", [{}, {"M1": 1.0, "M2": 0.5}, {"M1": 0.01, "M2": 3.0}],
                         ids=["seed", "M1=1,M2=0.5", "M1=0.01,M2=3"])
def test_hertz_impact_closed_form(target, v, masses):
    """REFERENCE §4: delta_max and T within 1e-8 relative (reduced mass and relative speed for
    two free masses); elastic, so restitution 1 to 1e-8."""
    p = seed_parameters(v, target=target, **masses)
    m = p.M1 if target == "rigid" else p.M1 * p.M2 / (p.M1 + p.M2)
    delta_max, T = hertz_closed_form(m, p.K, v)
    tr = simulate(p, "abrate", t_end=1.0)
    q = impact_quantities(tr)
    assert tr.status == "success"
    assert q.max_indentation == pytest.approx(delta_max, rel=1e-8)
    assert q.contact_duration == pytest.approx(T, rel=1e-8)
    assert q.restitution == pytest.approx(1.0, abs=1e-8)


def test_seed_printed_hertz_numbers():
    """REFERENCE §4: seed projectile on a rigid wall at 1 m/s, delta_max = 4.69617e-5 m,
    T = 1.38221e-4 s (closed form and integration, to the printed digits)."""
    p = seed_parameters(1.0, target="rigid")
    delta_max, T = hertz_closed_form(p.M1, p.K, 1.0)
    assert (f"{delta_max:.5e}", f"{T:.5e}") == ("4.69617e-05", "1.38221e-04")
    q = impact_quantities(simulate(p, "abrate", t_end=1.0))
    assert (f"{q.max_indentation:.5e}", f"{q.contact_duration:.5e}") == ("4.69617e-05", "1.38221e-04")


# ---------------------------------------------------------------------------------------------
# Damped impact: Hunt-Crossley restitution (REFERENCE §4) and restitution laws (REFERENCE §3)
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("target", ["free", "rigid"])
@pytest.mark.parametrize("a", [1e-3, 1e-2, 0.1, 0.5, 1.0, 2.0, 5.0])
def test_hunt_crossley_restitution_lambert_w(target, a):
    """REFERENCE §4: e solves 1 - e a = (1+a) exp(-a(1+e)), a = kappa v / K, independent of the
    mass; measured restitution within 1e-8 (free target: relative coordinates)."""
    base = seed_parameters(13.0 if a > 1 else 1.0, target=target)
    p = base.replace(kappa=a * base.K / base.v)
    q = impact_quantities(simulate(p, "hunt-crossley", t_end=1.0))
    assert q.restitution == pytest.approx(exact_restitution(a), abs=1e-8)


@pytest.mark.parametrize("name", sorted(CHI))
@pytest.mark.parametrize("e", [0.1, 0.5, 0.9])
def test_restitution_laws_on_free_target(name, e):
    """REFERENCE §3-4: P = K d^a (1 + chi deltadot / v0) is Hunt-Crossley with a = chi(e), so the
    measured restitution is the Lambert-W value at a = chi(e) (not e itself), to 1e-8."""
    p = seed_parameters(1.0, target="free")
    q = impact_quantities(simulate(p, ContactLaw(name, restitution=e), t_end=1.0))
    assert q.restitution == pytest.approx(exact_restitution(CHI[name](e)), abs=1e-8)


@pytest.mark.parametrize("v", [1.0, 13.0])
@pytest.mark.parametrize("e", [0.05, 0.3, 0.7, 0.95, 0.99])
def test_exact_inverse_restitution(e, v):
    """ContactLaw("hunt-crossley", restitution=e) uses the exact inverse: measured e to 1e-8."""
    p = seed_parameters(v, target="free")
    q = impact_quantities(simulate(p, ContactLaw("hunt-crossley", restitution=e), t_end=1.0))
    assert q.restitution == pytest.approx(e, abs=1e-8)


# ---------------------------------------------------------------------------------------------
# Invariants: energy conservation (kappa = 0) and loop area = energy lost (REFERENCE §4)
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize(("law", "v"), [
    (ContactLaw("abrate"), 1.0),
    (ContactLaw("abrate"), 13.0),
    (ContactLaw("abrate", bilateral=True), 1.0),
    (ContactLaw("abrate", bilateral=True), 13.0),
], ids=["unilateral-1", "unilateral-13", "bilateral-1", "bilateral-13"])
def test_energy_conserved_without_damping(law, v):
    """REFERENCE §4: kappa = 0 conserves the total energy; plate target, 0.01 s (about ten
    target periods and up to ~80 contacts), to 1e-9 of the impact energy at rtol 1e-12
    (the drift is about 10 rtol per contact; contacts restart from a fresh step to the root)."""
    p = seed_parameters(v)
    tr = simulate(p, law, t_end=0.01, stop_when_settled=False, rtol=1e-12)
    q = impact_quantities(tr)
    assert tr.status == "success" and tr.t_stop == pytest.approx(0.01, rel=1e-12)
    assert len(tr.events_of("contact")) >= 2  # more than the first impact was integrated
    assert abs(q.dissipated_energy) / impact_energy(p) < 1e-9


@pytest.mark.parametrize("target", ["free", "rigid"])
@pytest.mark.parametrize("kappa", [1e8, 1e9, 1e10, 1e11])
@pytest.mark.parametrize("v", [1.0, 13.0])
def test_loop_area_equals_dissipated_energy_single_impact(target, kappa, v):
    """REFERENCE §4: with damping, the loop area (integral of P d delta) equals the energy lost,
    to 1e-6 relative; the run ends at separation (out of contact)."""
    p = seed_parameters(v, target=target, kappa=kappa)
    tr = simulate(p, "hunt-crossley", t_end=1.0)
    q = impact_quantities(tr)
    assert tr.status == "success" and q.contact_duration is not None
    assert 0 < q.dissipated_energy < impact_energy(p)
    assert q.loop_area == pytest.approx(q.dissipated_energy, rel=1e-6)


@pytest.mark.parametrize("kappa", [1e8, 1e9, 3e9, 1e10])
@pytest.mark.parametrize("v", [1.0, 13.0])
def test_loop_area_equals_dissipated_energy_plate(kappa, v):
    """REFERENCE §4 on the plate: the run settles with the projectile out of reach (out of
    contact, delta < 0) after one or more impacts; loop area = energy lost to 1e-6."""
    p = seed_parameters(v, kappa=kappa)
    tr = simulate(p, "hunt-crossley", t_end=0.01)
    q = impact_quantities(tr)
    assert tr.status == "success" and tr.settled
    assert tr.final_state[0] - tr.final_state[1] < 0
    assert 0 < q.dissipated_energy < impact_energy(p)
    assert q.loop_area == pytest.approx(q.dissipated_energy, rel=1e-6)


# ---------------------------------------------------------------------------------------------
# RK4 (the seed's method)
# ---------------------------------------------------------------------------------------------

def _scaled_error(state, ref, p):
    """Largest error of (x1, x2, x1dot, x2dot), positions over the largest |x|, velocities over v."""
    length = max(abs(ref[0]), abs(ref[1]))
    return max(np.max(np.abs(state[:2] - ref[:2])) / length, np.max(np.abs(state[2:4] - ref[2:4])) / p.v)


def _rk4_errors(p, law, t_end, steps, ref_rtol):
    ref = simulate(p, law, t_end, rtol=ref_rtol, stop_when_settled=False)
    assert ref.status == "success"
    errors = []
    for h in steps:
        tr = simulate(p, law, t_end, integrator="rk4", step=h)
        assert tr.status == "success" and tr.nsteps == round(t_end / h)
        errors.append(_scaled_error(tr.final_state, ref.final_state, p))
    return np.array(errors)


def test_rk4_fourth_order_on_a_smooth_case():
    """Classic RK4 is fourth order on a smooth right-hand side: log2(err(h)/err(h/2)) in [3.5, 4.5].

    Bilateral abrate with alpha = 3 makes P = K delta^3 a polynomial (smooth through delta = 0;
    K = 1e18 N/m^3 gives contacts of ~6e-5 s, two of them in 2e-4 s). The reference is the exact
    integrator at rtol 1e-13 (at 1e-12 its own error, ~4e-12, spoils the last ratio).
    """
    p = seed_parameters(alpha=3.0, K=1e18)
    errors = _rk4_errors(p, ContactLaw("abrate", bilateral=True), 2e-4, [4e-7, 2e-7, 1e-7, 5e-8], 1e-13)
    orders = np.log2(errors[:-1] / errors[1:])
    assert np.all((3.5 <= orders) & (orders <= 4.5)), orders


def test_rk4_convergence_with_hertz_kink():
    """The seed's bilateral Hertz law P = K |delta|^1.5 sgn(delta) is only C^1 at delta = 0, which
    the run starts on (eq. 6) and crosses at separation: each such step has a local error
    O(h^2.5) (Simpson's rule on |t|^1.5), so the RK4 order is not 4 there (observed step-to-step
    orders 3.2, 1.8, 3.5). Still: errors decrease monotonically and the mean order over 4e-7 ->
    5e-8 is at least 2.5. Reference: exact integrator at rtol 1e-12 (error ~3e-12 << 4e-10)."""
    p = seed_parameters()
    steps = [4e-7, 2e-7, 1e-7, 5e-8]
    errors = _rk4_errors(p, ContactLaw("abrate", bilateral=True), 2e-4, steps, 1e-12)
    assert np.all(np.diff(errors) < 0), errors
    assert np.log2(errors[0] / errors[-1]) / np.log2(steps[0] / steps[-1]) >= 2.5


def test_rk4_paper_law_approaches_exact_stick():
    """REFERENCE §3: RK4 on eq. 8 chatters across deltadot = 0 with an amplitude that shrinks with
    the step; the event-driven run sticks at ~5.4e-5 s with delta frozen at delta*. At t = 2e-4 s
    the RK4 indentation approaches delta*: errors strictly decrease over h = 4e-7, 1e-7, 2.5e-8
    (roughly in proportion to h), and the smallest is below 1e-2 relative."""
    p = seed_parameters(kappa=1e9)
    exact = simulate(p, "paper", t_end=2e-4, stop_when_settled=False)
    sticks = exact.events_of("stick")
    assert exact.status == "success" and sticks
    assert 4e-5 < sticks[0].t < 7e-5
    delta_star = sticks[0].delta
    final_delta = exact.final_state[0] - exact.final_state[1]
    assert final_delta == pytest.approx(delta_star, rel=1e-12)  # still stuck at t_end
    errors = []
    for h in (4e-7, 1e-7, 2.5e-8):
        tr = simulate(p, "paper", t_end=2e-4, integrator="rk4", step=h)
        assert tr.status == "success"
        errors.append(abs(tr.final_state[0] - tr.final_state[1] - delta_star) / delta_star)
    assert errors[0] > errors[1] > errors[2], errors
    assert errors[-1] < 1e-2
    assert errors[0] / errors[1] > 2 and errors[1] / errors[2] > 2


# ---------------------------------------------------------------------------------------------
# Output selection
# ---------------------------------------------------------------------------------------------

def _options(integrator):
    return {"integrator": integrator, **({"step": 5e-7} if integrator == "rk4" else {})}


@pytest.mark.parametrize("integrator", ["exact", "rk4"])
def test_summary_keeps_no_samples(integrator):
    tr = simulate(seed_parameters(kappa=1e9), "hunt-crossley", 2e-4, save="summary", **_options(integrator))
    assert len(tr.t) == 0 and tr.y.shape == (0, 5) and len(tr.force) == 0
    assert tr.events and math.isfinite(tr.max_force)


@pytest.mark.parametrize("law", ["abrate", "hunt-crossley", "paper", ContactLaw("abrate", bilateral=True)])
@pytest.mark.parametrize("integrator", ["exact", "rk4"])
def test_steps_are_ordered_and_end_at_final_state(law, integrator):
    """save="steps": times start at 0, never decrease, end at t_stop with final_state; samples
    that share a time (coincident events, e.g. an abrate reversal is also a force peak) are equal."""
    tr = simulate(seed_parameters(kappa=1e9), law, 0.002, save="steps", **_options(integrator))
    assert tr.t[0] == 0.0
    assert np.all(np.diff(tr.t) >= 0)
    tied = np.flatnonzero(np.diff(tr.t) == 0)
    assert np.array_equal(tr.y[tied], tr.y[tied + 1])
    assert tr.t[-1] == pytest.approx(tr.t_stop, rel=1e-12)
    assert np.array_equal(tr.y[-1], tr.final_state)
    assert len(tr.t) == len(tr.y) == len(tr.force) == len(tr.mode)


@pytest.mark.parametrize("integrator", ["exact", "rk4"])
def test_time_grid_is_kept_exactly(integrator):
    times = np.linspace(0.0, 0.002, 41)
    tr = simulate(seed_parameters(kappa=1e9), "paper", 0.002, save=times, **_options(integrator))
    assert np.array_equal(tr.t, times)
    assert np.allclose(tr.y[-1], tr.final_state, rtol=1e-12, atol=0)
    assert tr.y[0][2] == 1.0 and np.all(tr.y[0][[0, 1, 3, 4]] == 0)  # seed eq. 6


@pytest.mark.parametrize("law", ["abrate", "hunt-crossley", "paper"])
def test_summary_and_steps_agree(law):
    """The same problem saved two ways gives the same extremes and final state."""
    p = seed_parameters(kappa=1e9)
    a = simulate(p, law, 0.01, save="summary", stop_when_settled=False)
    b = simulate(p, law, 0.01, save="steps", stop_when_settled=False)
    assert a.max_force == pytest.approx(b.max_force, rel=1e-12)
    assert a.max_indentation == pytest.approx(b.max_indentation, rel=1e-12)
    assert np.allclose(a.final_state, b.final_state, rtol=1e-12, atol=0)
    assert b.max_force >= np.max(b.force)


# ---------------------------------------------------------------------------------------------
# Failures are reported, never NaN
# ---------------------------------------------------------------------------------------------

def _assert_finite(tr):
    assert np.all(np.isfinite(tr.final_state))
    assert math.isfinite(tr.max_force) and math.isfinite(tr.max_indentation)
    assert np.all(np.isfinite(tr.y)) and np.all(np.isfinite(tr.force))
    q = impact_quantities(tr)
    assert math.isfinite(q.dissipated_energy) and math.isfinite(q.loop_area)


@pytest.mark.parametrize("save", ["summary", "steps"])
def test_paper_runaway_is_reported(save):
    """REFERENCE §3: eq. 8 with kappa = 3e12 (|deltadot| > K/kappa ~ 7 mm/s on the way out feeds
    the slip) runs away; the run ends with status "runaway", a message, and finite numbers."""
    tr = simulate(seed_parameters(kappa=3e12), "paper", t_end=0.01, save=save)
    assert tr.status == "runaway" and not tr.ok
    assert tr.message and tr.t_stop < 0.01
    assert tr.events_of("runaway")
    _assert_finite(tr)


def test_rk4_paper_runaway_is_reported():
    """REFERENCE §3: the runaway 'must be detected and reported, never left to overflow into NaN'."""
    tr = simulate(seed_parameters(kappa=3e12), "paper", t_end=0.01, integrator="rk4", step=1e-7)
    assert tr.status in ("runaway", "non-finite") and tr.message
    _assert_finite(tr)


def test_too_many_steps_is_reported():
    tr = simulate(seed_parameters(), "abrate", t_end=0.01, max_steps=5)
    assert tr.status == "too-many-steps" and tr.message and tr.t_stop < 0.01
    assert tr.nsteps == 5
    _assert_finite(tr)


# ---------------------------------------------------------------------------------------------
# Bad input
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize(("kwargs", "named"), [
    (dict(t_end=0.0), "t_end"), (dict(t_end=-1e-3), "t_end"), (dict(t_end=float("nan")), "t_end"),
    (dict(t_end=float("inf")), "t_end"), (dict(t_end="0.01"), "t_end"),
    (dict(integrator="euler"), "integrator"), (dict(integrator="RK4"), "integrator"),
    (dict(rtol=0.0), "rtol"), (dict(rtol=1e-16), "rtol"), (dict(rtol=1.0), "rtol"),
    (dict(rtol=-1e-8), "rtol"), (dict(rtol=float("nan")), "rtol"),
    (dict(integrator="rk4", step=0.0), "step"), (dict(integrator="rk4", step=-1e-7), "step"),
    (dict(integrator="rk4", step=float("nan")), "step"), (dict(integrator="rk4", step=float("inf")), "step"),
    (dict(method="Euler"), "method"), (dict(save="everything"), "save"),
    (dict(save=[0.0, 2e-4, 1e-4]), "save"),
])
def test_simulate_bad_input(kwargs, named):
    """Invalid options raise ValueError naming the parameter."""
    kwargs = {"t_end": 1e-3, **kwargs}
    with pytest.raises(ValueError, match=named):
        simulate(seed_parameters(), "abrate", **kwargs)
