"""Law conformance over the registry: every registered law (with every option) runs through the
same checks, so a new law is tested the moment it is registered (DESIGN principle 1)."""

import math

import numpy as np
import pytest

from phaseimpact import ContactLaw, seed_parameters, simulate
from phaseimpact._oracle import compare, oracle
from phaseimpact.checks import damping_number, with_damping_number
from phaseimpact.model import REGISTRY, jacobian, law_variants, pack
from phaseimpact.model.laws import STUCK, contact_force, contact_potential, force_partials
from phaseimpact.model.rhs import energy

VARIANTS = law_variants()
IDS = [law.label() for law in VARIANTS]
#: limiting_pressure: read by the plastic law (thornton) only, which yields well below 1 m/s with it
SEED = seed_parameters(v=1.0, kappa=3e9, limiting_pressure=2e9)
#: Every law damped as Hunt-Crossley is at SEED (the same dimensionless damping number), not with one
#: kappa for all: kappa = 3e9 N s/m^1.5 would overdamp Kuwabara-Kono by four orders of magnitude.
A_SEED = damping_number(SEED, "hunt-crossley")


def case_for(law):
    """SEED with the law's kappa for the damping number of Hunt-Crossley at SEED (SEED itself for
    the laws whose damping term is kappa delta^alpha deltadot)."""
    law = law if isinstance(law, ContactLaw) else ContactLaw(law)
    if law.entry.damping_power(SEED.alpha) == 1 + SEED.alpha:
        return SEED
    return with_damping_number(SEED, law, A_SEED)


def test_every_registered_law_has_variants():
    assert {law.name for law in VARIANTS} == set(REGISTRY)


@pytest.mark.parametrize("law", VARIANTS, ids=IDS)
def test_partials_match_finite_differences(law):
    """force_partials against central differences of contact_force, in contact, both slip signs."""
    c = pack(case_for(law), law)
    K, damping, alpha = c[2], c[5], c[6]
    for delta, deltadot in ((3e-5, 0.4), (2e-5, -0.3), (-1e-5, -0.2)):
        for mode in (1, -1) if law.is_filippov else (1,):
            if law.is_filippov and np.sign(deltadot) != mode:
                continue
            p_delta, p_rate = force_partials(law.code, delta, deltadot, mode, K, damping, alpha)
            hd, hr = 1e-6 * abs(delta), 1e-6 * abs(deltadot)
            fd_delta = (contact_force(law.code, delta + hd, deltadot, mode, K, damping, alpha)
                        - contact_force(law.code, delta - hd, deltadot, mode, K, damping, alpha)) / (2 * hd)
            fd_rate = (contact_force(law.code, delta, deltadot + hr, mode, K, damping, alpha)
                       - contact_force(law.code, delta, deltadot - hr, mode, K, damping, alpha)) / (2 * hr)
            scale = abs(K * abs(delta) ** alpha / abs(delta)) + 1.0
            assert p_delta == pytest.approx(fd_delta, rel=1e-6, abs=1e-9 * scale)
            assert p_rate == pytest.approx(fd_rate, rel=1e-6, abs=1e-9 * scale)


@pytest.mark.parametrize("law", VARIANTS, ids=IDS)
def test_jacobian_matches_finite_differences(law):
    y = np.array([3e-5, 1e-5, 0.6, 0.2, 0.0])
    mode = 1
    J = jacobian(y, SEED, law, mode)
    c = pack(SEED, law)
    from phaseimpact.model.rhs import rhs

    def f(state):
        out = np.empty(5)
        rhs(law.code, c, np.append(state, 0.0), mode, out)
        return out[:4]

    for j in range(4):
        h = 1e-7 * max(abs(y[j]), 1e-5)
        e = np.zeros(4)
        e[j] = h
        fd = (f(y[:4] + e) - f(y[:4] - e)) / (2 * h)
        np.testing.assert_allclose(J[:, j], fd, rtol=1e-5, atol=1e-6 * np.max(np.abs(J)))


def test_stuck_jacobian_is_the_pair_on_the_springs():
    y = np.array([3e-5, 1e-5, 0.1, 0.1, 0.0])
    J = jacobian(y, SEED, "paper", STUCK)
    rate = SEED.Kb + 3 * SEED.Km * y[1] ** 2
    assert J[2, 1] == J[3, 1] == pytest.approx(-rate / (SEED.M1 + SEED.M2))


@pytest.mark.parametrize("law", VARIANTS, ids=IDS)
def test_work_energy_balance(law):
    """docs/physics.md §4: E_mech(0) - E_mech(t) = W - (U(t) - U(0)), W the integrated contact work
    (a state of its own) and U the contact potential (zero for paper)."""
    tr = simulate(case_for(law), law, 4e-3, rtol=1e-12)
    c = pack(case_for(law), law)
    y0, y1 = tr.initial_state, tr.final_state
    potential_change = (contact_potential(law.code, y1[0] - y1[1], c[2], c[6])
                        - contact_potential(law.code, y0[0] - y0[1], c[2], c[6]))
    scale = 0.5 * SEED.M1 * SEED.v**2
    assert tr.dissipated_energy == pytest.approx(tr.loop_area - potential_change, abs=1e-9 * scale)
    assert tr.dissipated_energy == pytest.approx(energy(law.code, c, y0) - energy(law.code, c, y1), abs=1e-15)


@pytest.mark.parametrize("law", VARIANTS, ids=IDS)
def test_momentum_is_conserved_without_target_springs(law):
    p = case_for(law).replace(target="free")
    tr = simulate(p, law, 1e-3, rtol=1e-12)
    momentum = p.M1 * tr.final_state[2] + p.M2 * tr.final_state[3]
    assert momentum == pytest.approx(p.M1 * p.v, rel=1e-10)


@pytest.mark.parametrize("law", [law for law in VARIANTS if not law.entry.memory],
                         ids=[law.label() for law in VARIANTS if not law.entry.memory])
def test_engine_matches_the_scipy_oracle(law):
    """Same event sequence (coincident events may swap), times and max force within 1e-9. (The oracle
    has no law memory: Thornton's law is checked against its closed forms and a scipy run restarted
    at the turning point, tests/test_thornton.py.)"""
    agreement = compare(simulate(case_for(law), law, 4e-3, rtol=1e-12), oracle(case_for(law), law, 4e-3, rtol=1e-12),
                        4e-3)
    assert agreement.agrees, agreement.detail()


def test_damping_has_one_source():
    flores = ContactLaw("flores", restitution=0.5)
    assert not flores.reads("kappa") and flores.reads("restitution")
    assert not ContactLaw("abrate").reads("kappa")
    assert ContactLaw("paper").reads("kappa")
    assert not ContactLaw("hunt-crossley", restitution=0.5).reads("kappa")
    with pytest.raises(ValueError, match="restitution"):
        ContactLaw("paper", restitution=0.5)
    with pytest.raises(ValueError, match="contact"):
        ContactLaw("hunt-crossley", contact="unilateral")
    # results of a restitution law do not move with Parameters.kappa
    a = simulate(SEED.replace(kappa=0.0), flores, 2e-3)
    b = simulate(SEED.replace(kappa=1e12), flores, 2e-3)
    assert a.max_force == b.max_force


def test_paper_unilateral_is_zero_in_tension_printed_is_not():
    printed, unilateral = ContactLaw("paper"), ContactLaw("paper", contact="unilateral")
    c = pack(SEED, printed)
    assert contact_force(unilateral.code, -1e-5, -0.1, -1, c[2], c[5], c[6]) == 0.0
    assert contact_force(printed.code, -1e-5, -0.1, -1, c[2], c[5], c[6]) == pytest.approx(
        -(c[2] - 0.1 * c[5]) * 1e-5**1.5)
    assert not math.isnan(contact_force(printed.code, 0.0, 0.0, 2, c[2], c[5], c[6]))
