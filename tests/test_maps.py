"""The analyses of phaseimpact.maps over maps a user writes: the Hénon map of the guide of
phaseimpact/maps/base.py (read from the guide and run as written) and the logistic map, whose fixed
points, multipliers, period doubling, fold and Lyapunov exponents have closed forms computed here,
independently of the code under test."""

import math
import textwrap

import numpy as np
import pytest

from phaseimpact.maps import (
    AffineMap,
    ImpactMap,
    attracting_orbit_of,
    base,
    continue_bifurcation,
    continue_orbit,
    find_basins,
    fixed_point,
    iterate,
    lyapunov,
    sample_attractor,
)


def guide_example() -> type:
    """The guide's Hénon map (phaseimpact/maps/base.py), executed as written there."""
    code = textwrap.dedent(base.__doc__.split("::\n", 1)[1].split("\nThen ", 1)[0])
    namespace = {"ImpactMap": ImpactMap, "np": np}
    exec(compile(code, "guide of phaseimpact/maps/base.py", "exec"), namespace)
    return namespace["Henon"]


Henon = guide_example()


class HenonByDifferences(Henon):
    """The same map without its derivative: the Jacobian by central differences."""

    derivative = ImpactMap.derivative

    def at(self, name, value):
        return HenonByDifferences(**{"a": self.a, "b": self.b, name: value})


class Logistic(ImpactMap):
    parameters = ("r",)
    scale = np.array([1.0])

    def __init__(self, r):
        self.r = r

    def __call__(self, state):
        return self.r * state * (1 - state)

    def derivative(self, state):
        return np.array([[self.r * (1 - 2 * state[0])]])

    def at(self, name, value):
        return Logistic(value)

    @property
    def origin(self):
        return np.array([0.3])  # 0 is a fixed point


def henon_fixed_point(a, b, sign=1.0):
    """Closed form: x = (-(1 - b) +- sqrt((1 - b)^2 + 4a)) / 2a, y = b x; the multipliers solve
    lambda^2 + 2 a x lambda - b = 0."""
    x = (-(1 - b) + sign * math.sqrt((1 - b) ** 2 + 4 * a)) / (2 * a)
    root = np.sqrt(complex(a * a * x * x + b))
    return np.array([x, b * x]), sorted([-a * x + root, -a * x - root], key=lambda m: m.real)


@pytest.mark.parametrize("cls", [Henon, HenonByDifferences])
def test_a_users_map_has_its_closed_form_fixed_point_and_multipliers(cls):
    fp = fixed_point(cls(), guess=(0.6, 0.2))
    state, multipliers = henon_fixed_point(1.4, 0.3)
    assert fp.converged and not fp.stable
    np.testing.assert_allclose(fp.plate, state, rtol=1e-12)
    found = sorted(fp.multipliers, key=lambda m: m.real)
    np.testing.assert_allclose(found, multipliers, rtol=1e-7 if cls is HenonByDifferences else 1e-12)
    assert (fp.jacobian_accuracy == 0.0) == (cls is Henon)


def test_exact_and_finite_difference_jacobians_of_p_k_agree():
    J, accuracy = Henon().jacobian((0.3, 0.1), k=3)
    J_fd, accuracy_fd = HenonByDifferences().jacobian((0.3, 0.1), k=3)
    assert accuracy == 0.0 and 0 < accuracy_fd < 1e-6
    np.testing.assert_allclose(J_fd, J, rtol=1e-7, atol=1e-9)


def test_the_period_doubling_of_the_henon_map_is_located_where_theory_puts_it():
    """The fixed point's multiplier passes -1 at a = 3 (1 - b)^2 / 4 (0.3675 for b = 0.3)."""
    branch = continue_orbit(Henon(a=0.2), "a", 0.2, 0.5)
    assert branch.message == "reached the end of the range"
    assert [p.kind for p in branch.points] == ["period-doubling"]
    point = branch.points[0]
    assert abs(point.value - 3 * 0.7**2 / 4) < 1e-9 and point.bracket < 1e-9
    assert branch.stable[0] and not branch.stable[-1]
    # a period-2 orbit exists just past it and none just before (the doubling's birth)
    assert fixed_point(Henon(a=0.38), k=2, guess=point.plate + 0.05).converged
    assert branch.contacts.shape == (len(branch.values), 0)  # the Hénon map has no structure


def test_the_fold_of_the_henon_map_is_where_its_two_fixed_points_meet():
    """The two fixed points meet at a = -(1 - b)^2 / 4: the branch turns back there."""
    branch = continue_orbit(Henon(a=0.0), "a", 0.0, -0.3, max_points=60)
    folds = [p for p in branch.points if p.kind == "fold"]
    assert len(folds) == 1 and folds[0].turning
    assert abs(folds[0].value - (-(0.7**2) / 4)) < 1e-9
    assert branch.values.min() > -(0.7**2) / 4  # no fixed point beyond the fold


def test_the_period_doubling_curve_follows_the_closed_form_in_b():
    m = Henon(a=0.2, b=0.3)
    branch = continue_orbit(m, "a", 0.2, 0.5)
    curve = continue_bifurcation(m, branch, branch.points[0], "b", [0.3, 0.29, 0.28])
    assert curve.message == "followed over the whole grid"
    np.testing.assert_allclose(curve.values, [3 * (1 - b) ** 2 / 4 for b in (0.3, 0.29, 0.28)], atol=1e-8)


def test_lyapunov_exponents_of_the_logistic_map():
    """r = 4: log 2 (Ulam and von Neumann's conjugacy to the tent map); r = 2.5: the stable fixed
    point 1 - 1/r with the multiplier 2 - r, so log |2 - r|."""
    assert abs(lyapunov(Logistic(4.0), state=[0.3], iterations=100_000, transients=0) - math.log(2)) < 0.01
    assert abs(lyapunov(Logistic(2.5), iterations=200) - math.log(0.5)) < 1e-6


def test_orbit_diagram_counts_the_period_doubling_cascade():
    """The logistic map doubles at r = 3, 1 + sqrt(6) = 3.449 and 3.544: periods 1, 2, 4 between."""
    d = sample_attractor(Logistic(3.0), "r", [2.9, 3.3, 3.5], transients=3000, samples=16)
    assert d.distinct.tolist() == [1, 2, 4]
    np.testing.assert_allclose(d.plate[0, -1], [1 - 1 / 2.9], rtol=1e-9)
    assert np.isnan(d.peak_force).all()  # nothing observed


def test_attracting_orbit_of_the_logistic_map_is_its_period_two_orbit():
    """r = 3.2: the period-2 orbit's points solve r^2 x^2 - r (r + 1) x + r + 1 = 0."""
    r = 3.2
    orbit = attracting_orbit_of(Logistic(r), iterate(Logistic(r), [0.3], 60)[40:])
    points = np.roots([r * r, -r * (r + 1), r + 1])
    assert orbit.period_k == 2 and min(abs(points - orbit.plate[0])) < 1e-10


class Bistable(ImpactMap):
    """(x, y) -> (1.5 x - 0.5 x^3, y / 2): x = +-1 attract (slope 0), x = 0 repels (slope 1.5)."""

    scale = np.array([1.0, 1.0])

    def __call__(self, state):
        x, y = state
        return np.array([1.5 * x - 0.5 * x**3, 0.5 * y])


def test_basins_of_a_bistable_map_split_at_its_repelling_fixed_point():
    b = find_basins(Bistable(), [-0.5, -0.1, 0.2, 0.7], [0.0, 1.0], iterations=400)
    assert [a.plate.round(12).tolist() for a in b.attractors] == [[[-1.0, 0.0]], [[1.0, 0.0]]]
    assert b.labels.tolist() == [[0, 0, 1, 1], [0, 0, 1, 1]] and math.isnan(b.period)


def test_an_affine_map_has_its_closed_form_fixed_point():
    A, c = np.array([[0.2, -0.9], [0.9, 0.2]]), np.array([1.0, -2.0])
    fp = fixed_point(AffineMap(A, c))
    np.testing.assert_allclose(fp.plate, np.linalg.solve(np.eye(2) - A, c), rtol=1e-12)
    np.testing.assert_allclose(sorted(abs(fp.multipliers)), [math.hypot(0.2, 0.9)] * 2, rtol=1e-12)


@pytest.mark.parametrize(("call", "message"), [
    (lambda: continue_orbit(Henon(), "c", 0.2, 0.5), "param = 'c' is out of range; allowed: one of a, b"),
    (lambda: continue_orbit(Henon(), "a", 0.2, 0.2), "stop = 0.2 is out of range; allowed: stop != start"),
    (lambda: continue_orbit(Henon(), "a", 0.2, math.inf), "stop = inf is out of range; allowed: a finite number"),
    (lambda: fixed_point(Henon(), k=0), "k = 0 is out of range; allowed: an integer, 1 <= k <= 64"),
    (lambda: lyapunov(Henon(), iterations=0), "iterations = 0 is out of range"),
    (lambda: find_basins(Logistic(3.0), [0.1], [0.2]), "imap of dimension 1 is out of range"),
    (lambda: sample_attractor(Bistable(), "r", [1.0]), "param = 'r' is out of range; allowed: one of "),
    (lambda: Bistable().at("r", 1.0), "name = 'r' is out of range; allowed: one of the map's parameters (none)"),
    (lambda: attracting_orbit_of(Henon(), [[0.1, 0.2]]), "samples of shape (1, 2) are out of range"),
])
def test_a_users_map_gets_the_same_input_checks(call, message):
    with pytest.raises(ValueError) as error:
        call()
    assert message in str(error.value)


def test_a_map_without_a_call_says_what_it_lacks():
    class Empty(ImpactMap):
        scale = np.array([1.0])

    with pytest.raises(NotImplementedError, match="does not define __call__"):
        fixed_point(Empty())


def test_the_generic_analyses_import_nothing_of_the_model():
    """base, orbit_diagram, basins and continuation work over any map: they import neither the engine
    nor the model, nor the model's map (read from the sources)."""
    import ast
    from pathlib import Path

    folder = Path(__file__).resolve().parents[1] / "phaseimpact" / "maps"
    for name in ("base", "orbit_diagram", "basins", "continuation"):
        tree = ast.parse((folder / f"{name}.py").read_text())
        imported = {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
        imported |= {alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names}
        assert not {m for m in imported if m and m.split(".")[0] in ("integrate", "model", "impact",
                                                                      "impact_analyses")}, (name, imported)
        assert not any("phaseimpact.integrate" in m or "phaseimpact.model" in m for m in imported if m), name
