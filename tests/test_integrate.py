"""The driver: known answers (docs/physics.md §4), solver order, compiled vs uncompiled vs oracle,
statuses instead of NaN, argument checks."""

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
from scipy.special import gamma

from phaseimpact import ContactLaw, scales, seed_parameters, simulate, simulate_many
from phaseimpact._oracle import oracle
from phaseimpact.integrate import batch
from phaseimpact.model import hunt_crossley_restitution

SEED = seed_parameters(v=1.0)
TAU = math.sqrt(math.pi) * gamma(7 / 5) / gamma(9 / 10)


def test_hertz_closed_forms_on_a_rigid_target():
    """docs/physics.md §4: delta_max = 4.69617e-5 m and T = 1.38221e-4 s for the seed ball at 1 m/s."""
    tr = simulate(SEED.replace(target="rigid"), "abrate", rtol=1e-12)
    assert tr.outcome == "rebound"
    assert tr.max_indentation == pytest.approx(4.69617e-5, rel=1e-5)
    assert tr.contact_duration == pytest.approx(1.38221e-4, rel=1e-5)
    m, K, v = SEED.M1, SEED.K, SEED.v
    assert tr.max_indentation == pytest.approx((5 * m * v**2 / (4 * K)) ** 0.4, rel=1e-10)
    assert tr.contact_duration == pytest.approx(2 * TAU * (5 * m * v**2 / (4 * K)) ** 0.4 / v, rel=1e-9)
    assert tr.restitution == pytest.approx(1.0, abs=1e-10)


def test_hertz_closed_forms_at_the_sand_scale():
    """A 100 um quartz grain at 90 m/s: the same code at contact times of ~1e-7 s."""
    p = seed_parameters(v=90.0, R1=50e-6, projectile_E=94.5e9, projectile_nu=0.074, projectile_rho=2650.0,
                        target="rigid")
    tr = simulate(p, "abrate", rtol=1e-12)
    expected = 2 * TAU * p.hertz_indentation / p.v
    assert 1e-8 < expected < 1e-6
    assert tr.contact_duration == pytest.approx(expected, rel=1e-8)
    assert tr.max_indentation == pytest.approx(p.hertz_indentation, rel=1e-9)


@pytest.mark.parametrize("a", [0.01, 0.3, 2.0, 30.0])
def test_hunt_crossley_restitution_is_lambert_w(a):
    """docs/physics.md §4: e = (1 + W0(-(1+a) e^-(1+a)))/a on a rigid wall, whatever K and the mass."""
    p = SEED.replace(target="rigid", kappa=a * SEED.K / SEED.v)
    tr = simulate(p, "hunt-crossley", rtol=1e-12)
    assert tr.restitution == pytest.approx(float(hunt_crossley_restitution(a)), rel=1e-8)


def test_paper_loses_the_plastic_energy_at_any_kappa():
    """docs/physics.md §4: below kappa_c the first compression ends in a permanent stick, a perfectly
    plastic impact losing about m v^2/2 (m the reduced mass), for every kappa including 0."""
    plastic = 0.5 * SEED.reduced_mass * SEED.v**2
    for kappa in (0.0, 1e9, 1e11):
        tr = simulate(SEED.replace(kappa=kappa), "paper")
        assert tr.outcome == "permanent-stick" and tr.n_stick == 1
        assert tr.dissipated_energy == pytest.approx(plastic, rel=0.01)


def test_energy_from_the_runs_own_initial_state():
    """Undamped abrate started at (0, 0, 0.5, 0) dissipates nothing (not eq. 6's energy)."""
    tr = simulate(SEED, "abrate", initial=(0.0, 0.0, 0.5, 0.0), rtol=1e-12)
    assert abs(tr.dissipated_energy) < 1e-10 * 0.5 * SEED.M1 * 0.25


def test_rk4_is_fourth_order_on_a_smooth_phase():
    """Within the first compression the right-hand side is smooth: halving the step divides the
    RK4 error by 16 (the seed's method, on the same driver)."""
    p = SEED.replace(target="rigid")
    t_end, start = 4e-5, (2e-5, 0.0, 0.8, 0.0)  # inside the contact: |delta|^1.5 is smooth there
    exact = simulate(p, "abrate", t_end, rtol=1e-13, initial=start).final_state
    errors = []
    for step in (2e-6, 1e-6, 5e-7):
        tr = simulate(p, "abrate", t_end, integrator="rk4", step=step, initial=start)
        errors.append(abs(tr.final_state[0] - exact[0]))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 14) & (ratios < 18)), ratios


def test_rk4_chatters_on_eq8_where_the_exact_driver_sticks():
    tr = simulate(SEED.replace(kappa=1e9), "paper", 2e-3, integrator="rk4", step=1e-7, save="steps")
    exact = simulate(SEED.replace(kappa=1e9), "paper", 2e-3)
    # the relative velocity flips sign step after step instead of holding zero
    late = tr.deltadot[tr.t > 1e-3]
    assert np.count_nonzero(np.diff(np.sign(late))) > 100
    assert exact.n_stick == 1 and exact.outcome == "permanent-stick"


def test_compiled_and_uncompiled_driver_agree():
    """The same source run by the Python interpreter (NUMBA_DISABLE_JIT=1) gives the same run."""
    code = ("import json; from phaseimpact import seed_parameters, simulate;"
            "t = simulate(seed_parameters(v=1.0, kappa=1.5e12), 'paper', 3e-3);"
            "print(json.dumps([t.max_force, t.n_stick, list(t.event_t), list(t.final_state)]))")
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    plain = json.loads(out.stdout)
    tr = simulate(seed_parameters(v=1.0, kappa=1.5e12), "paper", 3e-3)
    assert plain[1] == tr.n_stick
    assert plain[0] == pytest.approx(tr.max_force, rel=1e-12)
    np.testing.assert_allclose(plain[2], tr.event_t, rtol=1e-12)
    np.testing.assert_allclose(plain[3], tr.final_state, rtol=1e-9, atol=1e-18)


KAPPA_C = 1.4994185342868816e12  # v = 1 m/s, printed reading (checked in test_transitions)


@pytest.mark.parametrize("contact", ["printed", "unilateral"])
def test_near_kappa_c_engine_and_oracle_agree(contact):
    """N and T_run just above kappa_c from two engines (docs/physics.md §5's ratchet and escape)."""
    law = ContactLaw("paper", contact=contact)
    for eps, n_expected in ((3e-5, 510), (1e-4, 42), (2e-4, 6)):
        p = SEED.replace(kappa=KAPPA_C * (1 + eps))
        tr = simulate(p, law, rtol=1e-12)
        ref = oracle(p, law, rtol=1e-12)
        assert tr.n_stick == ref.kinds.count("stick") == n_expected
        t_sep = ref.of("separation")[0][0]
        # T_run is ill-conditioned near kappa_c (relative sensitivity ~ 1/eps to the damping): two
        # integrators at rtol 1e-12 agree to about 1e-12/eps
        assert tr.t_run == pytest.approx(t_sep, rel=max(1e-8, 3e-11 / eps))
        assert tr.outcome == "ratchet-escape"
        assert tr.stop_reason == ("runaway" if contact == "printed" else "settled")


def test_many_runs_equal_single_runs_and_do_not_depend_on_threads():
    kappas = KAPPA_C * (1 + np.array([-1e-3, 1e-4, 2e-4, 5e-5, 1e-3, 0.5]))  # two runs past the buffer
    params = [SEED.replace(kappa=float(k)) for k in kappas]
    one = simulate_many(params, "paper", n_threads=1)
    two = simulate_many(params, "paper", n_threads=2)
    for name in ("max_force", "t_run", "n_stick", "dissipated_energy"):
        np.testing.assert_array_equal(one.values[name], two.values[name])
    np.testing.assert_array_equal(one.stick_delta, two.stick_delta)
    for i, p in enumerate(params):
        tr = simulate(p, "paper")
        assert tr.n_stick == one.n_stick[i] and tr.max_force == one.max_force[i]
        assert (tr.t_run or math.nan) == pytest.approx(one.t_run[i], nan_ok=True)
        np.testing.assert_array_equal(tr.stick_points()[1], one.sticks_of(i)[1])
    assert one.n_stick[1] == 42 and len(one.sticks_of(1)[0]) == 42  # more than the 32-point buffer
    assert one.n_stick[3] > 42 and len(one.stick_t) == one.n_stick.sum()


def test_many_runs_in_chunks_of_growing_size_equal_one_chunk():
    """simulate_many in threads packs its cases in chunks that start small and double (each packed
    while the one before runs): 4000 cases in chunks of 1024, 2048 and 928 give the columns of one
    thread's single chunk bit for bit, the stick points of runs past the 32-point buffer in the
    first and the last chunk included."""
    kappas = np.geomspace(1e9, 1e13, 4000)
    kappas[[100, 3990]] = KAPPA_C * (1 + 1e-4)  # 42 stick phases each
    params = [SEED.replace(kappa=float(k)) for k in kappas]
    assert [len(range(4000)[part]) for part in batch.pack_chunks(4000, True)] == [1024, 2048, 928]
    one, two = simulate_many(params, "paper", n_threads=1), simulate_many(params, "paper", n_threads=2)
    for name in ("status", "outcome", "stop_reason", "stick_count", "stick_t", "stick_delta", "stick_dwell"):
        np.testing.assert_array_equal(getattr(one, name), getattr(two, name))
    for name, column in one.values.items():
        np.testing.assert_array_equal(column, two.values[name])
    assert one.n_stick[100] == one.n_stick[3990] == 42 and len(one.stick_t) == one.n_stick.sum()
    np.testing.assert_array_equal(two.sticks_of(3990)[0], simulate(params[3990], "paper").stick_points()[0])


@pytest.mark.parametrize("n", [1, 1023, 1024, 1025, 8000, 20_000])
def test_pack_chunks_cover_every_case_once_in_order(n):
    for threaded in (False, True):
        parts = batch.pack_chunks(n, threaded)
        sizes = [part.stop - part.start for part in parts]
        assert parts[0].start == 0 and parts[-1].stop == n
        assert all(a.stop == b.start for a, b in zip(parts[:-1], parts[1:], strict=True))
        assert max(sizes) <= batch.PACK_CHUNK and min(sizes) >= 1
        assert sizes[0] == min(n, batch.FIRST_PACK_CHUNK if threaded else batch.PACK_CHUNK)
        assert all(b == min(2 * a, batch.PACK_CHUNK) for a, b in zip(sizes[:-2], sizes[1:-1], strict=True))


def test_horizon_cut_is_reported():
    tr = simulate(SEED.replace(kappa=KAPPA_C * (1 + 1e-4)), "paper", 5e-3)
    assert tr.cut and tr.outcome == "bounded" and tr.n_stick < 42
    assert "horizon" in tr.message


def test_default_horizon_comes_from_the_case():
    s = scales(SEED)
    assert s.plate_period == pytest.approx(2 * math.pi * math.sqrt(SEED.M2 / SEED.Kb))
    tr = simulate(SEED.replace(target="rigid", kappa=1e9), "hunt-crossley")
    assert tr.settled and tr.t_stop < 1e-3


@pytest.mark.parametrize("kwargs, name", [
    ({"t_end": -1.0}, "t_end"), ({"t_end": math.nan}, "t_end"), ({"rtol": 5.0}, "rtol"),
    ({"rtol": 1e-15}, "rtol"), ({"integrator": "euler"}, "integrator"), ({"save": "all"}, "save"),
    ({"initial": (0, 0, 1)}, "initial"), ({"stop_on": "bounce"}, "stop_on"),
    ({"integrator": "rk4", "step": 1e-15, "t_end": 1.0}, "step"),
])
def test_bad_arguments_are_refused_before_work(kwargs, name):
    with pytest.raises(ValueError, match=name):
        simulate(SEED, "paper", **kwargs)


def test_numpy_scalars_are_welcome():
    tr = simulate(SEED, "paper", np.float32(2e-3), rtol=np.float32(1e-8))
    assert tr.ok and isinstance(tr.t_end, float)


@pytest.mark.parametrize("v, kappa", [(1e-3, 0.0), (1e3, 1e12), (1.0, 1e17), (13.0, 1e8)])
def test_extreme_cases_end_with_a_status_not_nan(v, kappa):
    for law in ("paper", "hunt-crossley", ContactLaw("paper", contact="unilateral")):
        tr = simulate(seed_parameters(v=v, kappa=kappa), law)
        assert tr.status in ("success", "step-size-collapse", "too-many-steps", "non-finite")
        assert np.all(np.isfinite(tr.final_state)) and math.isfinite(tr.max_force)
        assert tr.message


@pytest.mark.parametrize("kappa", np.geomspace(1e13, 1e14, 5))
def test_stick_counts_do_not_depend_on_the_tolerance(kappa):
    """Stiff damping: the stuck pair's stick-break function switches branch where the pair passes
    its centre; a step over both that switch and the break missed the break (N flipped 2/3/4 with
    rtol). The run now restarts at the centre."""
    counts = {simulate(seed_parameters(v=1.0, kappa=float(kappa)), "paper", rtol=r).n_stick
              for r in (1e-8, 1e-10, 1e-12)}
    assert counts == {2}


def test_unrolled_dop853_is_scipys_tableau():
    """The committed straight-line step is what the generator writes from scipy's tableau today."""
    from phaseimpact.integrate import _dop853_codegen

    assert _dop853_codegen.TARGET.read_text() == _dop853_codegen.generate_source()


@pytest.mark.parametrize("law", ["hunt-crossley", "paper", ContactLaw("paper", contact="unilateral"), "abrate"])
def test_regularised_contact_agrees_with_the_plain_integration(law):
    """Contact phases of the Hertz law run in w = sqrt(delta), dt = w ds; an exponent a hair off
    3/2 runs the same physics in plain time (its force differs by about 1e-12 relative)."""
    p = SEED.replace(kappa=2e12 if law != "hunt-crossley" else 3e9)
    regularised = simulate(p, law, 2e-3, rtol=1e-12)
    plain = simulate(p.replace(alpha=1.5 * (1 + 1e-13)), law, 2e-3, rtol=1e-12)
    assert regularised.nsteps < plain.nsteps
    # the same events (a reversal and a force peak at one instant may come in either order); the
    # time of a flat force maximum is the ill-conditioned one (relative 1e-7 here)
    assert sorted(regularised.event_kind) == sorted(plain.event_kind)
    np.testing.assert_allclose(np.sort(regularised.event_t), np.sort(plain.event_t), rtol=1e-6, atol=1e-13)
    assert regularised.max_force == pytest.approx(plain.max_force, rel=1e-9)
    np.testing.assert_allclose(regularised.final_state[:4], plain.final_state[:4], rtol=1e-7, atol=1e-12)
    # the work W is a quadrature outside the step control (as in CVODES): compared on the impact energy
    impact_energy = 0.5 * p.M1 * p.v**2
    assert abs(regularised.final_state[4] - plain.final_state[4]) < 1e-9 * impact_energy


def test_a_horizon_on_an_event_ends_there():
    """A run whose horizon is exactly the time of the event that changes its phase (found by a
    first run, as the staircase study does) stops there with a status, not an exception: the
    phase that would start there has no time left for a first step (it divided by zero)."""
    from phaseimpact.continuation import critical_damping

    kappa_c = critical_damping(SEED, "paper").kappa_c
    for eps in (8.545432152652092e-06, 2.080083823051906e-05, 5.0632298444724275e-05, 3e-4):
        p = SEED.replace(kappa=kappa_c * (1 + eps))
        first = simulate(p, "paper", rtol=1e-13, atol=1e-22, stop_on=("stick", 2))
        t0 = first.events_of("slip")[0].t
        t1 = next(e.t for e in first.events if e.t > t0 and e.kind in ("stick", "reversal"))
        tr = simulate(p, "paper", t1, rtol=1e-13, atol=1e-22, save=np.linspace(t0, t1, 41)[1:-1])
        assert tr.ok and tr.t_stop == pytest.approx(t1, rel=1e-12) and len(tr.t) == 39


STIFF_CREEP = seed_parameters(v=6.35, kappa=1.6e14)  # the inward slip creeps, damped at ~5e6 /s


def test_a_stiff_creep_goes_on_with_radau_and_matches_the_oracle():
    """Far above kappa_c the inward slip is a creep held by the damper: DOP853 sits at its
    stability limit there, Radau IIA takes over. Both agree with the oracle (scipy's DOP853 at rtol
    1e-13; scipy's Radau agrees with it to 1e-10 at rtol 1e-11 to 3e-13, but at 1e-13, its floor,
    its escape time moves by 2e-7 and its second stick depth by 2e-11)."""
    ref = oracle(STIFF_CREEP, "paper", rtol=1e-13)
    stiff = simulate(STIFF_CREEP, "paper")
    explicit = simulate(STIFF_CREEP, "paper", stiff=False)
    assert stiff.integrator.startswith("exact[DOP853+Radau5") and explicit.integrator.startswith("exact[DOP853,")
    assert stiff.nsteps < explicit.nsteps / 1.5  # 777 against 1381 steps
    for tr in (stiff, explicit):
        assert [e.kind for e in tr.events] == ref.kinds
        assert tr.outcome == "ratchet-escape"
        ref_sticks = [s[0] - s[1] for _, s in ref.of("stick")]
        np.testing.assert_allclose(tr.stick_points()[1], ref_sticks, rtol=1e-9)
        # stick breaks are transversal; the stick times end a creep that comes slowly to rest
        np.testing.assert_allclose(tr.events_of("slip")[-1].t, ref.of("slip")[-1][0], rtol=1e-9)
        # the anti-damped escape amplifies what came before: 6e-9 at rtol 1e-10 for either method
        np.testing.assert_allclose(tr.events_of("runaway")[0].t, ref.of("runaway")[0][0], rtol=2e-8)


def test_radau_converges_with_the_tolerance():
    """The second stick depth (the end of the creep, integrated by Radau) approaches the oracle's
    as rtol falls: the internal tolerance 0.01 rtol^(2/3) delivers rtol. (Not monotone at loose
    tolerances: at 1e-7 the creep's deltadot, controlled relative to itself, lands at 5e-11.)"""
    ref = [s[0] - s[1] for _, s in oracle(STIFF_CREEP, "paper", rtol=1e-13).of("stick")][1]
    rtols = (1e-7, 1e-9, 1e-11)
    errors = [abs(simulate(STIFF_CREEP, "paper", rtol=r).stick_points()[1][1] / ref - 1) for r in rtols]
    assert all(error < rtol for error, rtol in zip(errors, rtols, strict=True))
    assert errors[2] < errors[1] / 10


def test_the_stiff_switch_keeps_the_columns():
    """Over an atlas-like spread of damping and speed, runs with Radau for stiff stretches and runs
    with DOP853 throughout give the same classes and counts, and the same numbers to ~1e-8."""
    points = [SEED.replace(kappa=float(k), v=float(v)) for k in np.geomspace(1e10, 1e15, 6) for v in (0.4, 2.0, 9.0)]
    stiff = simulate_many(points, "paper")
    explicit = simulate_many(points, "paper", stiff=False)
    np.testing.assert_array_equal(stiff.outcome, explicit.outcome)
    np.testing.assert_array_equal(stiff.n_stick, explicit.n_stick)
    assert np.sum(stiff.values["nsteps"]) < 0.75 * np.sum(explicit.values["nsteps"])  # 6986 against 10559
    np.testing.assert_allclose(stiff.stick_delta, explicit.stick_delta, rtol=1e-8)
    for name in ("max_force", "dissipated_energy", "t_run", "first_stick_delta"):
        np.testing.assert_allclose(stiff.values[name], explicit.values[name], rtol=1e-7, equal_nan=True)


@pytest.fixture
def radau_not_met(monkeypatch):
    """This process as at its start: no run has turned stiff, the engine runs without Radau."""
    from phaseimpact.integrate import api

    monkeypatch.setattr(api._Radau, "met", False)
    return api._Radau


def test_radaus_steps_are_called_only_through_the_member_an_engine_without_them_has_as_none():
    """Radau's steps (the functions that hold its Newton iterations and factorisations) take the
    workspace's ``W_RADAU``, None in an engine without them: a call with ``W_STIFF`` (the tuple every
    run carries for the stiffness watch) would compile them into every first command again, with
    nothing failing. Read from the source (ast): each call's ``stiff`` argument is ``ws[W_RADAU]``."""
    import ast
    import inspect
    from pathlib import Path

    from phaseimpact.integrate import radau5

    steps = ("enter", "attempt", "fixed_step", "dense_coefficients")
    position = {name: list(inspect.signature(getattr(radau5, name).py_func).parameters).index("stiff")
                for name in steps}
    calls = []
    for path in sorted((Path(radau5.__file__).parent).glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in steps \
                    and isinstance(node.func.value, ast.Name) and node.func.value.id == "radau5":
                calls.append((path.name, node.func.attr, ast.unparse(node.args[position[node.func.attr]])))
    assert {name for _, name, _ in calls} == set(steps)  # the scan finds every one
    assert all(stiff == "ws[W_RADAU]" for _, _, stiff in calls), calls


def test_an_engine_without_radau_stops_where_the_run_turns_stiff(radau_not_met):
    """driver.run with ``radau`` None (the engine compiled without its stiff solver) stops with
    NEEDS_RADAU where the creep turns stiff, before the run with Radau ends; simulate then runs it
    again with Radau, and from then on this process runs with it (api.radau_marker)."""
    from phaseimpact.integrate import api
    from phaseimpact.integrate import driver as d
    from phaseimpact.model.laws import as_law
    from phaseimpact.model.rhs import pack

    law = as_law("paper")
    s = scales(STIFF_CREEP)
    args = (law.code, pack(STIFF_CREEP, law), api._initial(STIFF_CREEP, None), api._atol(STIFF_CREEP, 1e-10, None),
            s.horizon, s.max_step, (1e-10, True, -1, 0, api.MAX_STEPS, api.MAX_EVENTS, api._stiff_after(True)),
            d.SAVE_SUMMARY, np.empty(0))
    without, with_radau = d.run(*args, None)[0], d.run(*args, True)[0]
    assert without[d.S_STATUS] == d.NEEDS_RADAU and with_radau[d.S_STATUS] == d.SUCCESS
    assert 0 < without[d.S_T_STOP] < with_radau[d.S_T_STOP]
    assert api.radau_marker(api._stiff_after(True)) is None
    tr = simulate(STIFF_CREEP, "paper")
    assert tr.status == "success" and tr.nsteps == with_radau[d.S_NSTEPS] and tr.t_stop == with_radau[d.S_T_STOP]
    assert radau_not_met.met is True and api.radau_marker(api._stiff_after(True)) is True
    assert api.radau_marker(api._stiff_after(False)) is None  # DOP853 throughout never needs it


def test_a_stiff_run_is_remembered_by_the_processes_that_share_the_cache(tmp_path, monkeypatch):
    """After a run turned stiff, a new process with the same cache starts with the engine with Radau
    (the file api.RADAU_MET_FILE in the cache): the driver is not compiled twice on one machine.
    Without a cache, or with one no longer writable, only the process itself remembers."""
    from types import SimpleNamespace

    from phaseimpact.integrate import api

    on = api._stiff_after(True)
    monkeypatch.setattr(api, "cache_info", lambda: SimpleNamespace(path=tmp_path))
    monkeypatch.setattr(api._Radau, "met", None)  # a process that has not looked yet
    assert api.radau_marker(on) is None and not (tmp_path / api.RADAU_MET_FILE).exists()
    api.radau_needed()
    assert api.radau_marker(on) is True and (tmp_path / api.RADAU_MET_FILE).exists()
    monkeypatch.setattr(api._Radau, "met", None)  # the next process
    assert api.radau_marker(on) is True and api.radau_marker(api._stiff_after(False)) is None
    monkeypatch.setattr(api, "cache_info", lambda: SimpleNamespace(path=None))
    monkeypatch.setattr(api._Radau, "met", None)
    assert api.radau_marker(on) is None
    api.radau_needed()
    assert api.radau_marker(on) is True
    # a cache that can no longer be written (here: removed): this process alone remembers, no error
    monkeypatch.setattr(api, "cache_info", lambda: SimpleNamespace(path=tmp_path / "removed"))
    monkeypatch.setattr(api._Radau, "met", None)
    assert api.radau_marker(on) is None
    api.radau_needed()
    assert api.radau_marker(on) is True and not (tmp_path / "removed").exists()


@pytest.mark.parametrize("n_threads", [1, 2])
def test_runs_without_radau_give_the_bits_of_runs_with_it(radau_not_met, n_threads):
    """A batch whose runs partly turn stiff, run first without Radau (its stiff runs again with it)
    and then with Radau from the start: the same columns, bit for bit; a non-stiff trajectory alike."""
    points = [SEED.replace(kappa=float(k), v=float(v)) for k in np.geomspace(1e10, 1e15, 6) for v in (0.4, 9.0)]
    first = simulate_many(points, "paper", n_threads=n_threads)
    assert radau_not_met.met is True  # some of them turned stiff
    again = simulate_many(points, "paper", n_threads=n_threads)
    assert set(first.values) == set(again.values)
    for name, column in first.values.items():
        np.testing.assert_array_equal(np.asarray(column), np.asarray(again.values[name]), err_msg=name)
    np.testing.assert_array_equal(first.stick_delta, again.stick_delta)
    with_radau = simulate(SEED.replace(kappa=3e9), "hunt-crossley", 2e-3, save="steps")
    radau_not_met.met = False
    without = simulate(SEED.replace(kappa=3e9), "hunt-crossley", 2e-3, save="steps")
    np.testing.assert_array_equal(without.y, with_radau.y)
    np.testing.assert_array_equal(without.summary, with_radau.summary)


def test_stiff_must_be_a_bool():
    with pytest.raises(ValueError, match="stiff"):
        simulate(SEED, "paper", stiff="yes")


def test_a_step_to_a_root_that_cannot_converge_is_a_failure_not_a_state():
    """Radau's step to an event's root (no error control) splits into pieces when Newton fails;
    if nothing converges it raises the workspace's failure flag (the driver then ends the run with
    step-size-collapse) instead of handing back a state."""
    from phaseimpact.integrate import radau5
    from phaseimpact.model.laws import as_law
    from phaseimpact.model.rhs import pack, rhs_integration

    law = as_law("paper")
    c = pack(STIFF_CREEP, law)
    u = np.array([2e-3, 0.0, 0.1, 0.0, 0.0, 0.0])
    fu = np.empty(6)
    rhs_integration(law.code, c, u, 1, 1, fu)
    atol = np.full(6, 1e-14)
    atol[4] = np.inf
    stiff = radau5.workspace(np.int64(5))
    radau5.enter(law.code, c, 1, 1, u, fu, 1e-10, atol, stiff)
    good, f_good = np.empty(6), np.empty(6)
    radau5.fixed_step(law.code, c, 1, 1, 0.0, 1e-4, stiff, (u, fu, good, f_good))
    assert not radau5.failed(stiff[radau5.CTL]) and np.all(np.isfinite(good)) and good[5] > 0
    broken = u.copy()
    broken[2] = np.nan
    radau5.fixed_step(law.code, c, 1, 1, 0.0, 1e-4, stiff, (broken, fu, good, f_good))
    assert radau5.failed(stiff[radau5.CTL])


def test_engine_kernels_are_compiled_without_reference_counting():
    """Every compiled function of the engine is declared through ``phaseimpact._jit``, and only the
    few that create arrays keep numba's reference counting: a plain ``numba.njit`` on a helper would
    bring back an incref and a decref of every array argument at every call (more than half the
    time of a trajectory). Each also sets ``forceinline`` (true or false): numba lets a function that
    leaves it unset inherit it from the caller it is first compiled in, so what LLVM inlines would
    depend on the order of compilation."""
    from numba.core.registry import CPUDispatcher

    from phaseimpact.integrate import (
        _dop853_stages,
        dop853,
        driver,
        elliptic,
        events,
        flight,
        logs,
        phase,
        radau5,
        record,
        rk4,
        rootfind,
        spacing,
        step,
    )
    from phaseimpact.model import forms, laws
    from phaseimpact.model import rhs as rhs_module

    counted = set()
    for module in (forms, laws, rhs_module, events, _dop853_stages, dop853, radau5, record, phase, rootfind, logs,
                   step, driver, rk4, elliptic, flight, spacing):
        for name, obj in vars(module).items():
            if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == module.__name__:
                assert "_nrt" in obj.targetoptions, f"{module.__name__}.{name} is not declared through _jit"
                assert obj.targetoptions.get("forceinline") in (True, False), f"{module.__name__}.{name}"
                if obj.targetoptions["_nrt"]:
                    counted.add(name)
    assert counted == {"run", "run_rk4", "grow", "new_logs", "workspace"}


def test_kernels_that_take_the_workspace_are_inlined():
    """A kernel that takes a run's workspace (``ws``, a tuple of 22 arrays passed by value: 174 to
    202 LLVM parameters a call, which numba's ``linkonce_odr`` linkage keeps LLVM from trimming) is
    ``forceinline``, so that the root finders and the event handling do not copy it at every call.
    The exceptions run a few times per run: the entries, the loop, its start and end, and
    ``advance``, which keeps its steps in a loop of its own."""
    import inspect

    from numba.core.registry import CPUDispatcher

    from phaseimpact.integrate import driver, logs, phase, rootfind, step

    called_per_run = {"_set_options", "open_logs", "_start", "_loop", "summarize", "run_point", "run_point_into",
                      "run_held", "advance"}
    takes_ws, not_inlined = set(), set()
    for module in (driver, logs, phase, rootfind, step):
        for name, obj in vars(module).items():
            if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == module.__name__ \
                    and "ws" in inspect.signature(obj.py_func).parameters:
                takes_ws.add(name)
                if not obj.targetoptions["forceinline"]:
                    not_inlined.add(name)
    assert {"brent", "locate", "restart", "record_events", "log_event"} <= takes_ws  # the scan finds them
    assert not_inlined == called_per_run


def _python_calls_of_compiled_functions():
    """Every call of a compiled function from Python code (not from a compiled function) in the
    package, tests, benchmarks and studies: ``(where, dispatcher)``, names resolved through each
    file's imports."""
    import ast
    import importlib
    from pathlib import Path

    from numba.core.registry import CPUDispatcher

    root = Path(__file__).resolve().parents[1]
    modules = {}
    for path in (root / "phaseimpact").rglob("*.py"):
        name = ".".join(path.relative_to(root).with_suffix("").parts).removesuffix(".__init__")
        modules[name] = importlib.import_module(name)

    def compiled(module_name, attr):
        obj = getattr(modules.get(module_name), attr, None)
        return obj if isinstance(obj, CPUDispatcher) else None

    def is_compiled_function(node):
        # cuda.jit: the GPU kernel (phaseimpact/cuda.py), which numba compiles with what it calls
        return any(ast.unparse(d).startswith(("kernel", "allocating", "cuda.jit")) for d in node.decorator_list)

    calls = []
    for folder in ("phaseimpact", "tests", "benchmarks", "studies"):
        for path in (root / folder).rglob("*.py"):
            package = ".".join(path.relative_to(root).parts[:-1])
            tree = ast.parse(path.read_text())
            aliases = {}  # local name -> a module's name, or (module name, attribute)
            for node in ast.walk(tree):
                if isinstance(node, ast.Import):
                    for a in node.names:
                        aliases[a.asname or a.name] = a.name
                elif isinstance(node, ast.ImportFrom):
                    base = node.module or ""
                    if node.level:  # relative: the package's first parts, then the module
                        parts = package.split(".")
                        base = ".".join(parts[:len(parts) - node.level + 1] + ([base] if base else []))
                    for a in node.names:
                        full = f"{base}.{a.name}"
                        aliases[a.asname or a.name] = full if full in modules else (base, a.name)

            def visit(node, in_compiled, path=path, aliases=aliases):
                if isinstance(node, ast.FunctionDef):
                    in_compiled = is_compiled_function(node)
                if isinstance(node, ast.Call) and not in_compiled:
                    target, f = None, node.func
                    if isinstance(f, ast.Name) and isinstance(aliases.get(f.id), tuple):
                        target = compiled(*aliases[f.id])
                    elif isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) \
                            and isinstance(aliases.get(f.value.id), str):
                        target = compiled(aliases[f.value.id], f.attr)
                    if target is not None:
                        calls.append((f"{path.relative_to(root)}:{node.lineno}", target))
                for child in ast.iter_child_nodes(node):
                    visit(child, in_compiled)

            visit(tree, False)
    return calls, modules


def test_compiled_functions_called_from_python_have_a_python_entry():
    """A compiled function without numba's CPython wrapper (``phaseimpact._jit``: all but
    ``python=True``) crashes the interpreter when Python calls it: every call from Python code,
    and every compiled function a module exports, must reach one with the wrapper."""
    from numba.core.registry import CPUDispatcher

    calls, modules = _python_calls_of_compiled_functions()
    assert len(calls) > 40  # the scan sees the calls (the oracle, the tests, the api)
    missing = sorted({where + " " + target.py_func.__qualname__ for where, target in calls
                      if target.targetoptions.get("no_cpython_wrapper")})
    assert not missing, missing
    for name, module in modules.items():
        for exported in getattr(module, "__all__", ()):
            obj = getattr(module, exported)
            if isinstance(obj, CPUDispatcher):
                assert not obj.targetoptions.get("no_cpython_wrapper"), f"{name}.{exported}"


def test_a_division_by_zero_in_the_engine_gives_ieee_values_not_an_exception():
    """The engine is compiled with numba's error_model "numpy" (phaseimpact._jit), the GPU's: a
    float division by zero gives inf or NaN, which a run reports as a status, where numba's default
    raises ZeroDivisionError out of the compiled code. Here the projectile's rate -w P / M1 with
    M1 = 0 in a regularised contact (w > 0, P > 0)."""
    from phaseimpact.model import pack
    from phaseimpact.model.forms import M1_
    from phaseimpact.model.rhs import rhs_values

    law = ContactLaw("hunt-crossley")
    c = pack(seed_parameters(v=1.0, kappa=3e9), law)
    c[M1_] = 0.0
    rates = rhs_values(law.code, c, 1e-3, 0.0, 0.3, 0.0, 1, 1)
    assert rates[6] > 0 and rates[2] == -math.inf


NAN_RATE_RUN = """
from phaseimpact import seed_parameters
from phaseimpact.integrate import api, driver as d
from phaseimpact.model import as_law
from phaseimpact.model.forms import M2_
law = as_law("hunt-crossley")
c, atol, y0, scales = api._packed(seed_parameters(v=1.0, kappa=3e9), law, 1e-10)  # simulate's inputs
c = c.copy()
c[M2_] = 0.0  # the target's rate (P - spring) / M2 is 0/0 at the contact's start: NaN
stiff = api._stiff_after(True)
out = d.run(law.code, c, y0, atol, 2e-3, scales.max_step, (1e-10, True, -1, 0, 100_000, api.MAX_EVENTS, stiff),
            d.SAVE_SUMMARY, api._NO_TIMES, api.radau_marker(stiff))
print(d.STATUSES[int(out[0][d.S_STATUS])])
"""


def test_a_nan_rate_ends_the_run_with_a_status_not_a_hang():
    """A NaN rate at a phase's start makes scipy's initial-step rule give a NaN step. The step loops
    tested ``h < 10 ulp`` for a collapse, which is False for NaN, and spun forever without counting a
    step (found with the target's mass zeroed: ZeroDivisionError under numba's default error model,
    a hang under the engine's "numpy" one). Run in a process of its own, so that a hang fails the
    test instead of stopping the suite."""
    out = subprocess.run([sys.executable, "-c", NAN_RATE_RUN], capture_output=True, text=True, timeout=240)
    assert out.returncode == 0, out.stderr[-3000:]
    assert out.stdout.split()[-1] == "step-size-collapse"


def test_no_kernel_returns_an_array():
    """A kernel (compiled without reference counting) that returned an array to a counting caller
    would have it freed under its owner (memory corruption): every compiled overload of every
    kernel returns scalars or tuples of scalars. Read from numba's cache index after one call of
    each entry (the overloads themselves stay in the callers' machine code)."""
    from numba.core import types
    from numba.core.registry import CPUDispatcher

    from phaseimpact.integrate import (
        _dop853_stages,
        dop853,
        driver,
        events,
        logs,
        phase,
        radau5,
        record,
        rk4,
        rootfind,
        step,
    )
    from phaseimpact.model import laws
    from phaseimpact.model import rhs as rhs_module

    p = SEED.replace(kappa=3e9)
    simulate(p, "hunt-crossley", 2e-3, save="steps")
    simulate(p, "paper", None, stop_on="slip")
    simulate(p, "paper", 2e-4, integrator="rk4")
    simulate_many([p, p.replace(kappa=1e12)], "paper", n_threads=2)

    def holds_array(t):
        return isinstance(t, types.Array) or (isinstance(t, types.BaseTuple) and any(map(holds_array, t.types)))

    def return_types(dispatcher):  # numba internals: the cache index lists each overload's argument types
        index = dispatcher._cache._cache_file._load_index()
        return [dispatcher._cache.load_overload(key[0], dispatcher.targetctx).signature.return_type for key in index]

    assert any(holds_array(t) for t in return_types(logs.grow))  # the check sees an array return
    checked = 0
    for module in (laws, rhs_module, events, _dop853_stages, dop853, radau5, record, phase, rootfind, logs, step,
                   driver, rk4):
        for name, obj in vars(module).items():
            if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == module.__name__ \
                    and not obj.targetoptions["_nrt"]:
                for returned in return_types(obj):
                    assert not holds_array(returned), f"{module.__name__}.{name} returns {returned}"
                    checked += 1
    assert checked >= 50  # every kernel the runs above compiled
