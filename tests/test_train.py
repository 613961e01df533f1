"""Trains of impacts as a map (phaseimpact.train): REFERENCE.md §7's impulsive limit, the energy
balance of a periodic orbit, and fixed points against long iteration."""

import json
import math

import numpy as np
import pytest
from _cli import run

from phaseimpact import seed_parameters
from phaseimpact.integrate import scales
from phaseimpact.train import (
    attracting_orbit,
    basins,
    continue_map_bifurcation,
    continue_map_orbit,
    impact_train,
    lyapunov_exponent,
    map_fixed_point,
    map_jacobian,
    orbit_diagram,
)

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


#: studies/train.py's value of T just above half a plate period: a stable period-1 orbit whose slowest
#: multiplier is about -0.96 (the study's 200 dropped impacts leave its 40 samples distinct).
NEAR_HALF = 0.5040100250626567


def test_a_slowly_converging_period_1_orbit_is_found_by_converging_to_it():
    """The count of distinct samples calls the orbit irregular (all 40 distinct); the orbit Newton's
    method finds from the last sample is period 1 and stable, and a long iteration (an independent
    route: 1000 impacts, |mu|^800 ~ 1e-13) ends on it."""
    p = SEED.replace(kappa=3e9)
    T = NEAR_HALF * scales(p).plate_period
    diagram = orbit_diagram(p, "hunt-crossley", "T", [T], transients=200, samples=40)
    assert diagram.distinct[0] == 40  # what the count alone says
    orbit = attracting_orbit(p, "hunt-crossley", T, diagram.plate[0])
    assert orbit is not None and orbit.period_k == 1 and orbit.stable
    assert -0.99 < min(orbit.multipliers.real) < -0.9 and max(abs(orbit.multipliers)) < 1
    long = impact_train(p, "hunt-crossley", T, 1000)
    scale = np.array([p.hertz_indentation, p.v])
    assert np.max(np.abs(long.plate[-1] - orbit.plate) / scale) < 1e-6


def test_a_period_2_attractor_is_period_2_and_a_far_transient_is_none():
    """At one plate period the train from rest settles on a period-2 orbit (studies/train.py);
    samples from the first impacts from rest, still far from any orbit, are no orbit."""
    p = SEED.replace(kappa=3e9)
    T = PLATE_PERIOD
    train = impact_train(p, "hunt-crossley", T, 240)
    orbit = attracting_orbit(p, "hunt-crossley", T, train.plate[200:])
    assert orbit is not None and orbit.period_k == 2 and orbit.stable
    assert attracting_orbit(p, "hunt-crossley", T, train.plate[:6], max_period=2) is None
    with pytest.raises(ValueError, match="max_period = 0"):
        attracting_orbit(p, "hunt-crossley", T, train.plate[:6], max_period=0)


def test_the_default_lyapunov_exponent_waits_for_the_slowest_multiplier():
    """Near half a plate period (multiplier -0.963) a fixed 200 impacts from the default start are 3 %
    off log |mu|; the default transients, chosen from the multiplier, bring it within 1e-6."""
    p = SEED.replace(kappa=3e9)
    T = NEAR_HALF * scales(p).plate_period
    fp = map_fixed_point(p, "hunt-crossley", T, guess=impact_train(p, "hunt-crossley", T, 240).plate[-1])
    expected = math.log(max(abs(fp.multipliers)))
    assert lyapunov_exponent(p, "hunt-crossley", T) == pytest.approx(expected, rel=1e-6)
    fixed = lyapunov_exponent(p, "hunt-crossley", T, transients=0)
    assert abs(fixed / expected - 1) > 0.01  # what a fixed count gives
    with pytest.raises(ValueError, match="transients = -1"):
        lyapunov_exponent(p, "hunt-crossley", T, transients=-1)


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


# ---------------------------------------------------------------- continuation, bifurcations, basins

HC = "hunt-crossley"
CASE = SEED.replace(kappa=3e9)  # studies/train.py's case
PLATE_PERIOD = scales(CASE).plate_period


def test_the_continued_impulsive_branch_has_the_analytic_multipliers_and_no_bifurcation():
    """REFERENCE.md §7's affine map: its multipliers satisfy (1 + mu1)(1 + mu2) = (1 + d)(1 + cos wT) and
    (1 - mu1)(1 - mu2) = (1 + d)(1 - cos wT), d = det R D, never negative: a multiplier touches -1 or +1
    (at wT = pi, 2 pi) without crossing, so the analytic map has no bifurcation; the branch followed
    between those values carries its multipliers and reports none."""
    p = SEED.replace(Km=0.0, Kb=SEED.Kb / 100, K=SEED.K * 1e4)
    s = scales(p)
    branch = continue_map_orbit(p, "abrate", "T", 0.3 * s.plate_period, 0.45 * s.plate_period,
                                step=0.03 * s.plate_period)
    assert branch.message == "reached the end of the range" and len(branch.values) >= 6
    assert branch.points == []
    ratio = s.contact_time / s.plate_period
    for value, multipliers in zip(branch.values, branch.multipliers, strict=True):
        _, analytic, _ = impulsive(p, value)
        assert np.max(np.abs(np.sort(multipliers.real) - analytic)) < 3 * ratio


@pytest.fixture(scope="module")
def small_branch():
    """The small-amplitude period-1 orbit just below one plate period, followed down in T."""
    return continue_map_orbit(CASE, HC, "T", 0.99 * PLATE_PERIOD, 0.975 * PLATE_PERIOD, step=0.003 * PLATE_PERIOD)


def test_a_located_period_doubling_gives_birth_to_a_period_2_orbit(small_branch):
    """Just below the located T a stable period-2 orbit exists apart from the (now unstable) period-1
    orbit; just above, the period-2 search collapses onto the period-1 orbit."""
    (pd,) = small_branch.points
    assert pd.kind == "period-doubling" and round(pd.value / PLATE_PERIOD, 4) == 0.9830  # studies/train_bifurcations
    assert np.min(np.abs(pd.multipliers + 1)) < 1e-6 and pd.bracket < 1e-9 * PLATE_PERIOD
    assert small_branch.stable[0] and not small_branch.stable[-1]
    J, _ = map_jacobian(CASE, HC, pd.value, pd.plate)
    w, vectors = np.linalg.eig(J)
    v = vectors[:, np.argmin(np.abs(w + 1))].real
    scale = np.array([CASE.hertz_indentation, CASE.v])
    kick = pd.plate + 0.03 * v / np.linalg.norm(v / scale)  # along the flip direction
    distance = {}
    for side in (-1, 1):
        T = pd.value * (1 + side * 1e-3)
        start = impact_train(CASE, HC, T, 300, plate=kick).plate[-1]
        two = map_fixed_point(CASE, HC, T, k=2, guess=start)
        one = map_fixed_point(CASE, HC, T, guess=pd.plate)
        assert two.converged and one.converged
        assert one.stable == (side > 0)
        distance[side] = np.max(np.abs(two.plate - one.plate) / scale)
        if side < 0:
            assert two.stable
    assert distance[-1] > 0.05 and distance[1] < 1e-9


@pytest.fixture(scope="module")
def large_branch():
    """The large-amplitude period-1 orbit, followed up in T into its fold."""
    return continue_map_orbit(CASE, HC, "T", 0.9 * PLATE_PERIOD, 0.98 * PLATE_PERIOD, step=0.005 * PLATE_PERIOD)


def test_a_located_fold_is_where_the_branch_turns(large_branch):
    folds = [p for p in large_branch.points if p.kind == "fold"]
    assert len(folds) == 1
    fold = folds[0]
    assert fold.turning and np.min(np.abs(fold.multipliers - 1)) < 1e-6
    assert round(fold.value / PLATE_PERIOD, 4) == 0.9695  # studies/train_bifurcations.py
    turn = int(np.argmax(large_branch.values))
    # the fold lies beyond every point of the branch, by less than the branch's curvature allows over
    # one step on either side of the turn
    gap = fold.value - large_branch.values[turn]
    assert 0 <= gap < 1e-4 * PLATE_PERIOD
    assert large_branch.stable[:turn].all() and not large_branch.stable[turn + 1:].any()
    # past the fold no period-1 orbit is near
    past = map_fixed_point(CASE, HC, fold.value * (1 + 1e-4), guess=fold.plate)
    assert not past.converged or np.max(np.abs(past.plate - fold.plate) / np.array([CASE.hertz_indentation, 1])) > 1


def test_the_period_doubling_is_followed_in_kappa(small_branch):
    """Each point of the curve is a period-doubling (a multiplier at -1) and agrees with a fresh
    one-parameter location at that kappa."""
    (pd,) = small_branch.points
    curve = continue_map_bifurcation(CASE, HC, small_branch, pd, "kappa", [3e9, 2.5e9, 2e9])
    assert curve.message == "followed over the whole grid" and np.all(np.isfinite(curve.values))
    assert np.max(np.abs(np.abs(curve.multipliers + 1).min(axis=1))) < 1e-6
    assert curve.values[0] == pytest.approx(pd.value, rel=1e-9)
    assert np.all(np.diff(curve.values) > 0)  # less damping: the doubling moves up towards the multiple
    assert round(curve.values[-1] / PLATE_PERIOD, 3) == 0.988  # studies/train_bifurcations.py
    fresh = continue_map_orbit(CASE.replace(kappa=2e9), HC, "T", 0.995 * PLATE_PERIOD, 0.98 * PLATE_PERIOD,
                               step=0.003 * PLATE_PERIOD)
    (again,) = [p for p in fresh.points if p.kind == "period-doubling"]
    assert again.value == pytest.approx(curve.values[-1], rel=1e-9)


def test_one_attractor_has_one_basin_over_the_whole_grid():
    """At 0.4 plate periods (studies/train.py: period-1 orbits only there) every state goes to the
    period-1 orbit of map_fixed_point."""
    grid = np.linspace(-2e-4, 2e-4, 3)
    period = 0.4 * PLATE_PERIOD
    b = basins(CASE, HC, period, grid, grid * 6e3, n_jobs=2)
    assert len(b.attractors) == 1 and b.attractors[0].period == 1 and np.all(b.labels == 0)
    assert b.attractors[0].count == 9 and b.not_converged == 0 == b.no_map
    fp = map_fixed_point(CASE, HC, period)
    scale = np.array([CASE.hertz_indentation, CASE.v])
    assert np.max(np.abs(b.attractors[0].plate[0] - fp.plate) / scale) < 1e-5


def test_coexisting_attractors_each_hold_their_basin():
    """At one plate period the small period-1 orbit (2 contacts an impact) coexists with a large
    period-2 orbit: both are found, and trains started in each basin end on their attractor."""
    xs = np.linspace(-60e-6, 60e-6, 4)
    vs = np.linspace(-0.3, 0.3, 3)
    one = basins(CASE, HC, PLATE_PERIOD, xs, vs, n_jobs=1)
    two = basins(CASE, HC, PLATE_PERIOD, xs, vs, n_jobs=2)
    assert np.array_equal(one.labels, two.labels) and np.array_equal(one.impacts, two.impacts)
    periods = sorted(a.period for a in one.attractors)
    assert periods[:2] == [1, 2], periods
    scale = np.array([CASE.hertz_indentation, CASE.v])
    for index, attractor in enumerate(one.attractors):
        fp = map_fixed_point(CASE, HC, PLATE_PERIOD, k=attractor.period, guess=attractor.plate[0])
        assert fp.converged and fp.stable
        assert np.max(np.abs(fp.plate - attractor.plate[0]) / scale) < 1e-5
        i, j = np.argwhere(one.labels == index)[0]
        train = impact_train(CASE, HC, PLATE_PERIOD, 400, plate=(xs[j], vs[i]))
        end = train.plate[-attractor.period:]
        assert min(np.max(np.abs(np.roll(end, s, axis=0) - attractor.plate) / scale)
                   for s in range(attractor.period)) < 1e-5


def test_bad_continuation_and_basin_input_is_refused():
    with pytest.raises(ValueError, match="stop = 0.001 is out of range"):
        continue_map_orbit(CASE, HC, "T", 1e-3, 1e-3)
    with pytest.raises(ValueError, match="start = -1"):
        continue_map_orbit(CASE, HC, "T", -1, 1e-3)
    with pytest.raises(ValueError, match="period = None"):
        continue_map_orbit(CASE, HC, "v", 1.0, 2.0)
    with pytest.raises(ValueError, match="step = 1"):
        continue_map_orbit(CASE, HC, "T", 1e-3, 2e-3, step=1)
    with pytest.raises(ValueError, match="tol = 0.1"):
        basins(CASE, HC, 1e-3, [0.0], [0.0], tol=0.1)
    with pytest.raises(ValueError, match="x2dot_values"):
        basins(CASE, HC, 1e-3, [0.0], [])
    code, _, err = run(["map-continuation", "--law", HC, "--axis", "kappa=1e9:2e9:5"])
    assert code == 2 and "period" in err
    code, _, err = run(["basins", "--law", HC, "--period", "1e-3", "--grid", "0"])
    assert code == 2 and "grid = '0'" in err


# ------------------------------------------------------------------------------------------------
# Text output of the train commands: no nan or inf (issue 37)
# ------------------------------------------------------------------------------------------------

def _numbers_in(text):
    return [w for line in text.splitlines() for w in line.split() if w.lower().strip(",;()") in ("nan", "inf")]


def test_train_table_says_undefined_for_a_restitution_without_separation():
    """paper sticks for good at kappa = 3e9: no separation, so no restitution (simulate says 'undefined')."""
    code, out, _ = run(["train", "--law", "paper", "--kappa", "3e9", "--period", "3e-3", "--impacts", "2"])
    assert code == 0 and not _numbers_in(out), out
    rows = [line.split() for line in out.splitlines() if line.split() and line.split()[0] in ("0", "1")]
    assert len(rows) == 2 and all(row[-1] == "undefined" for row in rows), out


@pytest.mark.parametrize("target", ["rigid", "free"])
def test_train_header_of_a_target_without_springs_has_no_plate_period(target):
    code, out, _ = run(["train", "--law", HC, "--kappa", "3e9", "--period", "3e-3", "--impacts", "2",
                        "--target", target])
    assert code == 0 and not _numbers_in(out), out
    assert f"(no plate period: a {target} target)" in out.splitlines()[0]


def test_train_period_shorter_than_the_contact_time_is_warned_about():
    code, out, err = run(["train", "--law", HC, "--kappa", "3e9", "--period", "1e-12", "--impacts", "2"])
    assert code == 0 and not _numbers_in(out), out
    assert err.strip().splitlines() == [
        "phaseimpact: warning: period = 1e-12 s is shorter than the contact time 0.000108 s (Hertz): each projectile "
        "arrives while the last is still in contact, whose restitution is then undefined"]
    _, _, err = run(["train", "--law", HC, "--kappa", "3e9", "--period", "3e-3", "--impacts", "2"])
    assert "warning" not in err


def test_failed_runs_of_a_train_print_undefined(monkeypatch):
    """A user law returning NaN failed every run: the table printed 'nan' in each column."""
    import phaseimpact.train as train_module

    def failed_train(params, law, period, impacts, **kwargs):
        nan = np.full(impacts, np.nan)
        return train_module.ImpactTrain(period, np.vstack([[0.0, 0.0], np.full((impacts, 2), np.nan)]), nan, nan,
                                        nan, nan, np.zeros(impacts, int), np.append(0.0, nan),
                                        np.zeros(impacts, bool), ["step-size-collapse"] * impacts)

    monkeypatch.setattr(train_module, "impact_train", failed_train)
    code, out, err = run(["train", "--law", HC, "--kappa", "3e9", "--period", "3e-3", "--impacts", "3"])
    assert code == 1 and "3 run(s) of the train failed (step-size-collapse)" in err
    assert not _numbers_in(out) and out.count("undefined") == 3 * 6 - 3, out  # row 0: the plate at rest


def test_map_continuation_calls_an_unnarrowed_bracket_not_located():
    """kappa from 0 to 1e18 in 3 values: the corrector fails at once, and the bifurcations' brackets are the
    whole first step (5e16): they were printed as found 'at kappa = 0'."""
    args = ["map-continuation", "--law", HC, "--kappa", "3e9", "--axis", "kappa=0:1e18:3", "--period", "1e-3"]
    code, out, _ = run(args)
    assert code == 0
    lines = [line for line in out.splitlines()[1:] if line.strip()]
    assert lines and all("not located: between kappa = 0 and the next point" in line for line in lines), out
    code, out, _ = run([*args, "--json"])
    points = json.loads(out)["points"]
    assert points and not any(point["located"] for point in points)


def test_map_continuation_located_points_stay_located():
    code, out, _ = run(["map-continuation", "--law", HC, "--kappa", "3e9", "--axis", "T=0.99e-3:0.975e-3:4",
                        "--json"])
    points = json.loads(out)["points"]
    assert code == 0 and points and all(point["located"] for point in points)
    assert all(point["bracket"] < 1e-6 for point in points)
