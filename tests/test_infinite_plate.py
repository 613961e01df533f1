"""The infinite-plate target (docs/physics.md §8): the load point moves with ``P / c``.

Known answers come from outside the code under test: an independent scipy integration of
``M1 x1'' = -P, x2' = P / c``, the rigid-wall Hertz contact time, Zener's scaling.
"""

import json
import math

import numpy as np
import pytest
from _cli import run
from _registry import restored_registry
from scipy.integrate import solve_ivp
from scipy.special import gamma

from phaseimpact import ContactLaw, define_law, seed_parameters, simulate
from phaseimpact.model import law_variants
from phaseimpact.parameters import Parameters


def hertz_on_dashpot(M1, K, c, v):
    """``M1 x1'' = -K delta^(3/2)``, ``c x2' = K delta^(3/2)`` by scipy: (restitution, max force,
    energy radiated ``∫ P^2 / c dt``)."""
    def rates(t, z):
        x1, v1, x2, _ = z
        P = K * max(x1 - x2, 0.0) ** 1.5
        return [v1, -P / M1, P / c, P * P / c]

    def separation(t, z):
        return z[0] - z[2]

    def force_peak(t, z):  # dP/dt = 0: deltadot = v1 - P / c = 0
        return z[1] - K * max(z[0] - z[2], 0.0) ** 1.5 / c

    separation.terminal, separation.direction = True, -1
    scale = (M1 * v * v / K) ** 0.4 / v
    s = solve_ivp(rates, [scale * 1e-9, 100 * scale], [v * scale * 1e-9, v, 0.0, 0.0], method="DOP853",
                  rtol=1e-13, atol=1e-30, events=(separation, force_peak))
    x1, _, x2, _ = s.y_events[1][0]
    end = s.y_events[0][0]
    return -end[1] / v, K * (x1 - x2) ** 1.5, end[3]


def infinite(v=1.0, **changes):
    return seed_parameters(v=v, target="infinite", **changes)


def test_the_seed_plate_is_a_dashpot_of_zeners_impedance():
    p = infinite()
    D = 2.1e11 * 0.005**3 / (12 * (1 - 0.3**2))  # steel, h = 5 mm
    assert p.impedance == pytest.approx(8 * math.sqrt(D * 7850.0 * 0.005), rel=1e-14)
    assert p.reduced_mass == p.M1  # the load point has no mass
    with pytest.raises(ValueError, match="impedance"):
        Parameters(M1=0.26, M2=0.31, K=2.2e10, Kb=1.2e7, Km=1.7e11, target="infinite")


@pytest.mark.parametrize("v", [1.0, 13.0])
def test_hertz_against_an_independent_integration(v):
    p = infinite(v)
    r = simulate(p, "abrate", 2e-3)
    e, peak, radiated = hertz_on_dashpot(p.M1, p.K, p.impedance, v)
    assert r.status == "success" and r.n_contacts == 1
    assert r.restitution == pytest.approx(e, rel=1e-8)
    assert r.max_force == pytest.approx(peak, rel=1e-8)
    # W is the work on the projectile: the elastic contact gives its work back, the plate keeps what it radiated
    assert r.final_state[4] == pytest.approx(radiated, rel=1e-8)


@pytest.mark.parametrize("law", [law for law in law_variants() if law.name != "thornton"]
                         + [ContactLaw("thornton")], ids=str)
def test_the_energy_ledger_closes(law):
    """``M1 v^2/2 - M1 x1dot^2/2 = W - U`` (``U`` the Hertz potential of the conservative laws)."""
    p = infinite(1.0, kappa=3e9, limiting_pressure=2e9)
    r = simulate(p, law, 2e-3)
    assert r.status == "success", r.message
    x1, x2, v1, _, work = r.final_state
    potential = p.K * max(x1 - x2, 0.0) ** 2.5 / 2.5 if law.name in ("abrate", "hunt-crossley") else 0.0
    impact_energy = 0.5 * p.M1 * p.v**2
    assert abs(impact_energy - 0.5 * p.M1 * v1**2 - work - potential) <= 1e-10 * impact_energy


@pytest.mark.parametrize("law", [*law_variants()], ids=str)
def test_every_shipped_law_runs_against_it(law):
    for kappa in (0.0, 3e9):
        r = simulate(infinite(1.0, kappa=kappa, limiting_pressure=2e9), law, 2e-3)
        assert r.status == "success", r.message
        assert np.isfinite(r.final_state).all() and math.isfinite(r.max_force) and r.max_force > 0
        assert r.restitution is None or 0.0 <= r.restitution <= 1.0


def test_a_user_law_runs_against_it():
    """The load point's equation reads the law's partials: a user law gives them (as here) or its force
    must be defined on both sides of ``delta = 0`` for the central differences."""
    def kk_force(delta, deltadot, K, gamma, alpha):
        return max((K * delta + gamma * deltadot) * math.sqrt(delta), 0.0)

    def kk_partials(delta, deltadot, K, gamma, alpha):
        root = math.sqrt(delta)
        if K * delta + gamma * deltadot <= 0:
            return 0.0, 0.0
        return K * 1.5 * root + gamma * deltadot * 0.5 * root / delta, gamma * root

    with restored_registry():
        define_law("user-kk-infinite", kk_force, partials=kk_partials, damping=("gamma", None), damping_power=1.5)
        p = infinite(1.0, kappa=2e4)
        mine = simulate(p, "user-kk-infinite", 2e-3, rtol=1e-12)
        shipped = simulate(p, ContactLaw("kuwabara-kono", clamp=True), 2e-3, rtol=1e-12)
    assert mine.status == "success"
    assert mine.restitution == pytest.approx(shipped.restitution, rel=1e-9)
    assert mine.max_force == pytest.approx(shipped.max_force, rel=1e-9)


def test_paper_sticks_for_good_and_radiates_the_rest():
    """Stuck, the pair decelerates on the dashpot (``M1 x1'' = -c x1dot``): the force needed, ``c x1dot``,
    only decreases, so the stick holds; the projectile's energy is radiated to the end."""
    p = infinite(1.0, kappa=3e9)
    r = simulate(p, "paper", 2e-3, stop_when_settled=False)
    assert r.status == "success"
    kinds = [e.kind for e in r.events]
    assert "stick" in kinds and "slip" not in kinds and "separation" not in kinds
    stick = r.events[kinds.index("stick")]
    v_stick = stick.state[2]
    assert stick.state[3] == v_stick
    t_left = r.t_stop - stick.t
    assert t_left > 10 * p.M1 / p.impedance  # followed for ten decay times
    x1, x2, v1, v2, work = r.final_state
    assert v1 == pytest.approx(v_stick * math.exp(-p.impedance / p.M1 * t_left), rel=1e-6)
    assert v2 == v1 and x1 - x2 == pytest.approx(stick.delta, rel=1e-12)
    assert work == pytest.approx(0.5 * p.M1 * (p.v**2 - v1**2), rel=1e-10)


def test_a_huge_impedance_is_a_rigid_wall():
    """``lambda -> 0``: ``e -> 1`` and the rigid-wall Hertz contact time ``2 tau delta_max / v``,
    ``tau = sqrt(pi) Gamma(7/5) / Gamma(9/10)`` (``2 tau = 2.9432...``; ``delta_max = (5 M1 v^2/(4K))^(2/5)``)."""
    p = infinite(1.0)
    p = p.replace(impedance=p.impedance * 1e8)  # lambda = 2.5e-8
    r = simulate(p, "abrate", 2e-3)
    tau = math.sqrt(math.pi) * gamma(1.4) / gamma(0.9)
    delta_max = (5 * p.M1 * p.v**2 / (4 * p.K)) ** 0.4
    assert 2 * tau == pytest.approx(2.9432, abs=1e-4)
    assert r.restitution == pytest.approx(1.0, abs=1e-6)
    assert r.contact_duration == pytest.approx(2 * tau * delta_max / p.v, rel=1e-6)


def test_restitution_depends_on_zeners_lambda_alone():
    """``lambda = M1^(3/5) v^(1/5) K^(2/5) / c``: scale M1, v, K and c so that it stays the same."""
    p = infinite(1.0)
    M1, v, K = p.M1 * 1e-3, 7.0, p.K * 3.0
    c = p.impedance * (M1 / p.M1) ** 0.6 * (v / p.v) ** 0.2 * (K / p.K) ** 0.4
    q = p.replace(M1=M1, v=v, K=K, impedance=c)
    e_p = simulate(p, "abrate", 2e-3).restitution
    e_q = simulate(q, "abrate", 2e-3).restitution
    assert e_q == pytest.approx(e_p, rel=1e-9)
    assert 0.0 < e_p < 0.05  # the seed's lambda = 2.49: Zener's curve is near 0 there
    e_other = simulate(p.replace(impedance=p.impedance * 10), "abrate", 2e-3).restitution  # lambda / 10
    assert e_other > e_p + 0.1


def test_simulate_and_params_on_the_command_line():
    code, out, err = run(["simulate", "--target", "infinite", "--v", "1", "--law", "abrate", "--json"])
    assert code == 0, err
    result = json.loads(out)
    p = infinite(1.0)
    e, peak, radiated = hertz_on_dashpot(p.M1, p.K, p.impedance, 1.0)
    assert result["target"] == "infinite" and result["status"] == "success"
    assert result["restitution"] == pytest.approx(e, rel=1e-8)
    assert result["max_force"] == pytest.approx(peak, rel=1e-8)
    assert result["loop_area"] == pytest.approx(radiated, rel=1e-8)
    code, out, err = run(["simulate", "--target", "infinite", "--law", "paper", "--kappa", "1e9"])
    assert code == 0, err
    assert "on an infinite target (seed)" in out and "permanent-stick" in out
    code, out, err = run(["params", "--target", "infinite", "--json"])
    assert code == 0, err
    params = json.loads(out)
    assert params["target"] == "infinite" and params["regime"] == "wave-controlled"
    assert params["regime_warning"] is None  # the infinite plate is the wave-controlled model
    assert params["plate_impedance"] == pytest.approx(infinite().impedance, rel=1e-14)
    assert params["zener_lambda"] == pytest.approx(
        infinite().M1**0.6 * infinite().K**0.4 / infinite().impedance, rel=1e-12)
    assert params["hertz_mass"] == infinite().M1


def test_params_warns_for_an_infinite_target_out_of_its_regime():
    """A 5 cm steel ball (4.1 kg) on the seed plate (1.23 kg): M1/M_p = 3.3 > 2, quasi-static."""
    code, out, err = run(["params", "--target", "infinite", "--set", "R1=0.05", "--json"])
    assert code == 0, err
    params = json.loads(out)
    assert params["regime"] == "quasi-static"
    assert "the infinite plate (target infinite) is out of its range; the spring-mass plate is the model" \
        in params["regime_warning"]


def test_a_case_file_names_the_infinite_target(tmp_path):
    case = tmp_path / "wave.toml"
    case.write_text("[projectile]\nE = 2.1e11\nnu = 0.3\nrho = 7850.0\n[plate]\nE = 2.1e11\nnu = 0.3\nrho = 7850.0\n"
                    "[geometry]\na = 0.1\nh = 0.005\nR1 = 0.02\nR2 = 2e3\n"
                    '[impact]\nv = 1.0\ntarget = "infinite"\nlaw = "abrate"\n')
    code, out, err = run(["simulate", "--case", case, "--json"])
    assert code == 0, err
    assert json.loads(out)["restitution"] == pytest.approx(hertz_on_dashpot(*(lambda p: (
        p.M1, p.K, p.impedance, 1.0))(infinite(1.0)))[0], rel=1e-8)


@pytest.mark.parametrize("kappa", [1e9, 1e12, 4.83337e14, 1e15])
def test_every_paper_impact_on_it_ends_in_a_stick(kappa):
    """At the ``deltadot = 0`` that ends the compression the pair needs ``c x2dot = P(delta, 0+)``, the
    stick bound itself, and then less: the stick holds for every damping (at 4.8e14 the integrated
    ``c x2dot`` once came out above the bound by rounding, and the slip went on unlogged)."""
    p = infinite(1.0, kappa=kappa)
    r = simulate(p, "paper", 2e-3, stop_when_settled=False)
    kinds = [e.kind for e in r.events]
    assert r.status == "success" and kinds[-1] == "stick" and "separation" not in kinds, kinds
    stick = r.events[-1]
    bound = p.K * stick.delta**1.5
    assert p.impedance * stick.state[3] == pytest.approx(bound, rel=1e-6)
