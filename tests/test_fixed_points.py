"""The equilibria of eq. 1 (``analysis.fixed_points``, ``phaseimpact fixed-points``; issue 22 item 6).

Oracles are closed forms from the equations (docs/physics.md §3, §5), never the finder's output:
at rest ``M1 x1'' + M2 x2'' = -S(x2)`` forces ``x2 = 0`` on a plate, so the separated set of a
unilateral law is the half-line ``delta <= 0`` with the plate's linearisation ``±i sqrt(Kb/M2)``
and a free projectile's zero pair; ``paper``'s stuck pair at rest needs no force, so every
``delta*`` is an equilibrium whose sliding flow swings at ``±i sqrt(Kb/(M1+M2))``; a bilateral
law rests only at ``delta = 0``, and with ``alpha = 1`` it is the two-mass chain of normal modes.
Members are checked against eq. 1 with each law written out at rest, and the claimed stability of
the sets against the engine's trajectories started beside them.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from _cli import run

from phaseimpact.analysis import STABILITY_LABELS, _stability, fixed_points
from phaseimpact.model import ContactLaw, law_variants
from phaseimpact.parameters import seed_parameters

# docs/physics.md §2, the seed case's table (a known answer, not computed here)
SEED_M1, SEED_M2, SEED_KB = 0.263056, 0.308269, 1.20830e7


def spectrum(values):
    """Eigenvalues in a canonical order, for comparison with a closed form."""
    return np.array(sorted(np.asarray(values, dtype=complex), key=lambda z: (round(z.imag, 6), round(z.real, 6))))


def assert_spectrum(found, expected, scale):
    found, expected = spectrum(found), spectrum(expected)
    assert found.shape == expected.shape, (found, expected)
    np.testing.assert_allclose(found, expected, rtol=0, atol=1e-9 * scale)


def force_at_rest(law, params, delta, x2, stuck):
    """Contact force at ``deltadot = 0`` as docs/physics.md §3 writes each law: Hertz ``K delta^alpha``
    while ``delta > 0`` for the unilateral laws (their damping term is ``kappa deltadot`` times it),
    ``K |delta|^alpha sgn(delta)`` bilateral; ``paper`` stuck: the stick force ``M1/(M1+M2) S(x2)``."""
    if stuck:
        return params.M1 / (params.M1 + params.M2) * spring(params, x2)
    if law.bilateral:
        return params.K * np.abs(delta) ** params.alpha * np.sign(delta)
    return np.where(delta > 0, params.K * np.maximum(delta, 0.0) ** params.alpha, 0.0)


def spring(params, x2):
    """``S(x2) = Kb x2 + Km x2^3`` on a plate, none on a rigid or free target."""
    return (params.Kb + params.Km * x2**2) * x2 if params.target == "plate" else 0.0 * x2


def accelerations(members, params, law, stuck):
    """``(x1'', x2'')`` at ``members`` from eq. 1 written out here (a rigid target is held)."""
    delta, x2 = members[:, 0] - members[:, 1], members[:, 1]
    force = force_at_rest(law, params, delta, x2, stuck)
    target = 0.0 * x2 if params.target == "rigid" else (force - spring(params, x2)) / params.M2
    return -force / params.M1, target


def by_name(found):
    return {e.name: e for e in found}


def expected_sets(law):
    """What eq. 1 and the law's printed form say (docs/physics.md §3), written out per variant."""
    if law.name == "paper":
        return {"separated", "stuck"} if law.contact == "unilateral" else {"stuck"}
    return {"rest"} if law.bilateral else {"separated"}


@pytest.mark.parametrize("law", law_variants(), ids=lambda law: law.label())
@pytest.mark.parametrize("target", ["plate", "rigid", "free"])
def test_the_sets_of_every_law_are_equilibria_of_eq_1(law, target):
    params = seed_parameters(v=1.0, kappa=1e9, target=target, limiting_pressure=2e9)  # p_y: thornton's
    found = fixed_points(params, law)
    assert {e.name for e in found} == expected_sets(law)
    assert len(found) == len(expected_sets(law))
    s = params.hertz_indentation
    for e in found:
        assert e.stability in STABILITY_LABELS
        assert e.members.shape[1] == 4 and len(e.members) >= 1
        assert np.all(e.members[:, 2:] == 0), "an equilibrium is at rest"
        if target != "free":
            assert np.all(e.members[:, 1] == 0), "the target at its static equilibrium x2 = 0"
        else:
            assert len(set(e.members[:, 1])) > 1, "a free target rests anywhere: the set spans x2"
        delta = e.members[:, 0] - e.members[:, 1]
        a1, a2 = accelerations(e.members, params, law, e.name == "stuck")
        scale = params.K * s**params.alpha / min(params.M1, params.M2)  # an acceleration in contact
        np.testing.assert_allclose(np.concatenate([a1, a2]), 0.0, atol=1e-12 * scale)
        if e.name == "separated":
            assert e.conditions["delta"] == "<= 0" and np.all(delta <= 0) and np.any(delta < 0)
            # the set ends at delta = 0: just inside contact the law pushes
            a1, _ = accelerations(np.array([[s, 0.0, 0.0, 0.0]]), params, law, False)
            assert a1[0] < 0
        elif e.name == "stuck":
            unilateral = law.contact == "unilateral"
            assert e.conditions["delta"] == ("> 0" if unilateral else "any")
            assert np.all(delta > 0) if unilateral else (np.any(delta < 0) and np.any(delta > 0))
            # the stick holds: M1/(M1+M2) |S(x2)| <= K |delta*|^alpha (a free or rigid target has no S)
            required = np.abs(force_at_rest(law, params, delta, e.members[:, 1], True))
            assert np.all(required <= params.K * np.abs(delta) ** params.alpha)
        else:
            assert e.conditions["delta"] == "= 0" and np.all(delta == 0)
        assert e.dimension == (0 if e.name == "rest" else 1) + (target == "free")
        assert e.kind == ("point" if e.dimension == 0 else "set")


@pytest.mark.parametrize("law", ["abrate", "hunt-crossley", ContactLaw("hunt-crossley", clamp=True),
                                 ContactLaw("flores", restitution=0.5), ContactLaw("paper", contact="unilateral")],
                         ids=str)
def test_separated_set_on_a_plate_has_the_plates_frequency_and_a_free_projectile(law):
    params = seed_parameters(v=1.0, kappa=3e9)
    separated = by_name(fixed_points(params, law))["separated"]
    omega = math.sqrt(SEED_KB / SEED_M2)  # the plate alone: M2 x2'' = -Kb x2 (linearised S)
    assert separated.coordinates == ("x1", "x2", "x1dot", "x2dot")
    assert_spectrum(separated.eigenvalues, [0, 0, 1j * omega, -1j * omega], omega * 1e4)  # table: 6 digits
    assert separated.stability == "non-hyperbolic"  # the projectile's zero pair


def test_plates_static_equilibrium_with_a_bilateral_contact():
    law = ContactLaw("abrate", bilateral=True)
    params = seed_parameters(v=1.0)
    (rest,) = fixed_points(params, law)
    assert rest.kind == "point" and rest.dimension == 0
    np.testing.assert_array_equal(rest.state, 0.0)
    # Hertz (alpha = 3/2): the contact stiffness alpha K |delta|^(1/2) is 0 at delta = 0, so the
    # projectile is free to first order and the plate swings alone
    omega = math.sqrt(params.Kb / params.M2)
    assert_spectrum(rest.eigenvalues, [0, 0, 1j * omega, -1j * omega], omega)
    assert rest.stability == "non-hyperbolic"
    # alpha = 1: the chain M1 -K- M2 -Kb- wall; M1 M2 w^4 - (M1 (K + Kb) + M2 K) w^2 + K Kb = 0
    linear = params.replace(alpha=1.0)
    M1, M2, K, Kb = linear.M1, linear.M2, linear.K, linear.Kb
    b = M1 * (K + Kb) + M2 * K
    roots = np.roots([M1 * M2, -b, K * Kb])
    (rest,) = fixed_points(linear, law)
    omegas = np.sqrt(roots.real)
    assert_spectrum(rest.eigenvalues, np.concatenate([1j * omegas, -1j * omegas]), omegas.max())
    assert rest.stability == "centre"


def test_rigid_and_free_targets():
    law = ContactLaw("abrate", bilateral=True)
    rigid = seed_parameters(v=1.0, target="rigid", alpha=1.0)
    (rest,) = fixed_points(rigid, law)
    assert rest.coordinates == ("x1", "x1dot")  # x2 is held, not a coordinate
    omega = math.sqrt(rigid.K / rigid.M1)  # M1 x1'' = -K x1
    assert_spectrum(rest.eigenvalues, [1j * omega, -1j * omega], omega)
    assert rest.stability == "centre"
    free = seed_parameters(v=1.0, target="free", alpha=1.0)
    (rest,) = fixed_points(free, law)
    assert rest.kind == "set" and rest.dimension == 1  # translations of the pair
    omega = math.sqrt(free.K * (1 / free.M1 + 1 / free.M2))  # relative motion, reduced mass
    assert_spectrum(rest.eigenvalues, [0, 0, 1j * omega, -1j * omega], omega)
    (separated,) = fixed_points(seed_parameters(v=1.0, target="rigid"), "abrate")
    assert_spectrum(separated.eigenvalues, [0, 0], 1.0)
    (stuck,) = fixed_points(seed_parameters(v=1.0, target="rigid"), "paper")
    assert stuck.coordinates == ("x1",) and spectrum_is_zero(stuck)
    (stuck,) = fixed_points(seed_parameters(v=1.0, target="free"), "paper")
    assert stuck.coordinates == ("x1", "x2", "v") and spectrum_is_zero(stuck)


def spectrum_is_zero(e) -> bool:
    return bool(np.all(e.eigenvalues == 0)) and e.stability == "non-hyperbolic"


@pytest.mark.parametrize("contact", ["printed", "unilateral"])
def test_stuck_set_of_paper_swings_as_one_body(contact):
    params = seed_parameters(v=1.0, kappa=1.5e12)
    stuck = by_name(fixed_points(params, ContactLaw("paper", contact=contact)))["stuck"]
    # the sliding flow on x1dot = x2dot = v: x1' = v, x2' = v, (M1 + M2) v' = -Kb x2 (linearised S)
    omega = math.sqrt(SEED_KB / (SEED_M1 + SEED_M2))
    assert stuck.coordinates == ("x1", "x2", "v")
    assert_spectrum(stuck.eigenvalues, [0, 1j * omega, -1j * omega], omega * 1e4)
    assert stuck.stability == "non-hyperbolic"


def test_damping_and_speed_move_no_equilibrium():
    for law in ("paper", "hunt-crossley"):
        a = fixed_points(seed_parameters(v=1.0, kappa=0.0), law)
        b = fixed_points(seed_parameters(v=7.0, kappa=2e12), law)
        for x, y in zip(a, b, strict=True):
            assert (x.name, x.conditions, x.dimension) == (y.name, y.conditions, y.dimension)
            np.testing.assert_allclose(spectrum(x.eigenvalues), spectrum(y.eigenvalues), rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize(("eigenvalues", "label"), [
    ([-1, -2 + 3j, -2 - 3j], "stable"),
    ([1e-3, -5, -5], "unstable"),
    ([2j, -2j, 5j, -5j], "centre"),
    ([0, 2j, -2j], "non-hyperbolic"),
    ([-1, 2j, -2j], "non-hyperbolic"),
    ([0, 0], "non-hyperbolic"),
])
def test_stability_labels_of_linearisations(eigenvalues, label):
    assert _stability(np.array(eigenvalues, dtype=complex)) == label


def test_the_sets_are_stable_as_the_notes_say():
    """Started beside a member, the engine's trajectory stays beside the set (and a member stays put)."""
    from phaseimpact.integrate import simulate

    params = seed_parameters(v=1.0, kappa=1e9)
    s = params.hertz_indentation
    horizon = 10 * params.target_period
    # a member of the separated set does not move
    tr = simulate(params, "abrate", horizon, initial=[-s, 0.0, 0.0, 0.0], save="steps")
    np.testing.assert_array_equal(tr.y[-1, :4], [-s, 0.0, 0.0, 0.0])
    # a stuck pair at rest, kicked as one body: it swings at sqrt(Kb/(M1+M2)) and stays stuck
    kick = 1e-3  # m/s: swing 1.6e-7 m, far inside x_break for delta* = s
    tr = simulate(params, "paper", horizon, initial=[s, 0.0, kick, kick], save="steps")
    delta = tr.y[:, 0] - tr.y[:, 1]
    assert np.max(np.abs(delta - s)) <= 1e-9 * s
    assert np.max(np.abs(tr.y[:, 1])) <= 1.01 * kick / math.sqrt(params.Kb / (params.M1 + params.M2))
    # a small slip stops in finite time at a nearby delta*
    tr = simulate(params, "paper", horizon, initial=[s, 0.0, 2 * kick, kick], save="steps")
    t_stick, d_stick, _ = tr.stick_points()
    assert len(t_stick) >= 1 and t_stick[0] < 1e-3 * params.target_period
    assert abs(d_stick[-1] - s) <= 1e-3 * s




def _no_constant(name):
    raise AssertionError(f"JSON holds {name}: numbers must be finite or null")


def test_cli_fixed_points_json_and_text():
    code, out, err = run(["fixed-points", "--law", "abrate", "--json"])
    assert code == 0, err
    doc = json.loads(out, parse_constant=_no_constant)
    assert doc["law"] == "abrate" and doc["target"] == "plate"
    (separated,) = doc["equilibria"]
    assert separated["name"] == "separated" and separated["kind"] == "set" and separated["dimension"] == 1
    assert separated["conditions"] == {"x1dot": "= 0", "x2dot": "= 0", "x2": "= 0", "delta": "<= 0"}
    omega = math.sqrt(SEED_KB / SEED_M2)
    imag = sorted(z["im"] for z in separated["eigenvalues"])
    np.testing.assert_allclose(imag, [-omega, 0, 0, omega], rtol=1e-5, atol=1e-6)
    assert all(z["re"] == 0 for z in separated["eigenvalues"])
    assert separated["stability"] == "non-hyperbolic"

    code, out, err = run(["fixed-points", "--contact", "unilateral", "--target", "rigid", "--kappa", "1e10"])
    assert code == 0, err
    assert "separated: set of dimension 1" in out and "stuck: set of dimension 1" in out
    assert "in (x1, x1dot)" in out and "in (x1)" in out


@pytest.mark.parametrize(("argv", "names"), [
    (["--law", "abrate", "--contact", "printed"], "contact"),
    (["--v", "-1"], "v"),
    (["--target", "moon"], "target"),
    (["--law", "flores"], "restitution"),
    (["--law", "abrate", "--kappa", "1e9"], "kappa"),
    (["--set", "nope=1"], "nope"),
])
def test_cli_fixed_points_refuses_bad_input(argv, names):
    code, out, err = run(["fixed-points", *argv])
    assert code == 2, (argv, out, err)
    assert names in err and "Traceback" not in err and out == ""
