"""Transitions of the long-time behaviour (docs/physics.md §5): kappa_c, kappa_2, grazing, their
two-parameter continuation and the refined boundaries of an atlas."""

import math

import numpy as np
import pytest

from phaseimpact import ContactLaw, seed_parameters, simulate
from phaseimpact.case import load_case
from phaseimpact.continuation import (
    atlas,
    closed_form_kappa_c,
    critical_curve,
    critical_damping,
    delta_extremum,
    first_stick_margin,
    grazing_transitions,
    locate_kappa_2,
    refine_boundaries,
    transitions,
)
from phaseimpact.continuation.grazing import contact_count

SEED = seed_parameters(v=1.0)


@pytest.fixture(scope="module")
def critical():
    return critical_damping(SEED, "paper", with_kappa_2=True)


@pytest.mark.parametrize("v", [1.0, 13.0])
def test_kappa_c_against_the_closed_form(v):
    """docs/physics.md §5: the closed form gives kappa_c to a fraction of a percent."""
    p = seed_parameters(v=v)
    found = critical_damping(p, "paper")
    assert found.status == "success"
    assert found.kappa_c == pytest.approx(closed_form_kappa_c(p), rel=0.0025)


@pytest.mark.parametrize("v", [1.0, 13.0])
def test_kappa_c_at_the_default_tolerance_is_converged(v):
    """kappa_c with the integrator at its default rtol 1e-10 against rtol 1e-13: with the contact
    regularised the first stick's state is accurate to 8e-11 (v = 1) and 3e-10 (v = 13) in
    kappa_c; the plain integration was off by 7e-10 at v = 1."""
    p = seed_parameters(v=v)
    default = critical_damping(p, "paper").kappa_c
    converged = critical_damping(p, "paper", kappa_rtol=1e-10, rtol=1e-13).kappa_c
    assert default == pytest.approx(converged, rel=5e-10)


def test_kappa_c_is_the_root_of_the_margin_and_the_count_changes_there(critical):
    kc = critical.kappa_c
    assert first_stick_margin(SEED.replace(kappa=kc * (1 - 1e-9)), "paper") > 0
    assert first_stick_margin(SEED.replace(kappa=kc * (1 + 1e-9)), "paper") < 0
    below = simulate(SEED.replace(kappa=kc * (1 - 1e-6)), "paper")
    above = simulate(SEED.replace(kappa=kc * (1 + 1e-4)), "paper")
    assert below.outcome == "permanent-stick" and below.n_stick == 1
    assert above.n_stick == 42 and above.outcome == "ratchet-escape"


def test_closed_form_is_exact_for_a_slow_plate():
    """docs/physics.md §5: exact in the limit of a slow plate (plate period >> contact time): lowering
    the plate's stiffness a hundredfold brings the located kappa_c to the closed form."""
    gaps = []
    for scale in (1.0, 1e-2, 1e-4):
        p = SEED.replace(Kb=SEED.Kb * scale, Km=SEED.Km * scale)
        gaps.append(abs(critical_damping(p, "paper").kappa_c / closed_form_kappa_c(p) - 1))
    assert gaps[0] > gaps[1] > gaps[2]
    assert gaps[2] < 2e-4


def test_printed_and_unilateral_readings_share_kappa_c():
    """Both readings are identical while delta > 0: same kappa_c; they differ after the escape."""
    printed = critical_damping(SEED, ContactLaw("paper")).kappa_c
    unilateral = critical_damping(SEED, ContactLaw("paper", contact="unilateral")).kappa_c
    assert unilateral == pytest.approx(printed, rel=1e-12)


#: Known answers of the issue's independent scipy code (issue 42, item 2), quoted to 5 digits:
#: compared at 2e-5, half a unit of their last digit.
KAPPA_C_R1_2MM_V1, KAPPA_C_R1_1MM_V100 = 9.2946e17, 3.0957e18


def test_kappa_c_beyond_the_old_range_of_damping_numbers():
    """R1 = 2 mm at 1 m/s: the root lies at 1.35 times the old range's end (damping number 1e8),
    inside the inputs' kappa <= 1e18; the search reaches it, and single runs either side agree
    (a permanent stick just below, an escape above)."""
    p = load_case("seed").parameters(R1=0.002)
    assert KAPPA_C_R1_2MM_V1 > 1e8 * p.K / p.v
    found = critical_damping(p, "paper")
    assert found.status == "success", found.message
    assert found.kappa_c == pytest.approx(KAPPA_C_R1_2MM_V1, rel=2e-5)
    assert simulate(p.replace(kappa=0.99 * KAPPA_C_R1_2MM_V1), "paper").outcome == "permanent-stick"
    assert simulate(p.replace(kappa=9.6e17), "paper").outcome == "ratchet-escape"


def test_a_root_beyond_the_inputs_limit_is_reported_as_a_search_not_a_claim():
    """R1 = 1 mm at 100 m/s: the root (3.0957e18) lies beyond kappa <= 1e18; the search says how far
    it looked, and the closed form, which is not bound by the inputs, finds the root."""
    p = load_case("seed").parameters(R1=0.001, v=100.0)
    found = critical_damping(p, "paper")
    assert found.status == "not-found" and found.kappa_c is None
    assert "no root of the first stick's margin up to kappa = 1e+18" in found.message
    assert found.search_range[1] == 1e18 and found.margins[1] > 0
    assert "never breaks" not in found.message
    assert closed_form_kappa_c(p) == pytest.approx(KAPPA_C_R1_1MM_V100, rel=2e-5)
    assert "3.0957e+18" in found.message


def test_not_found_gives_null_and_both_margins():
    rigid = critical_damping(SEED.replace(target="rigid"), "paper")
    assert rigid.status == "not-found" and rigid.kappa_c is None
    assert "no root of the first stick's margin up to kappa = 1e+18" in rigid.message
    assert "without springs" in rigid.message and rigid.margins == (1.0, 1.0)
    narrow = critical_damping(SEED, "paper", kappa_min=1e9, kappa_max=1e10)
    assert narrow.status == "not-found" and narrow.kappa_c is None
    assert all(m > 0 for m in narrow.margins)


def test_kappa_c_of_named_cases_without_failure():
    for name in ("seed", "sand-gelcoat", "hail-laminate"):
        case = load_case(name)
        found = critical_damping(case.parameters(), "paper")
        assert found.status in ("success", "not-found"), (name, found.message)


def test_kappa_2_is_where_exactly_two_stick_phases_start(critical):
    k2 = critical.kappa_2
    assert k2 > critical.kappa_c
    assert simulate(SEED.replace(kappa=k2 * (1 + 1e-7)), "paper").n_stick == 2
    assert simulate(SEED.replace(kappa=k2 * (1 - 1e-7)), "paper").n_stick > 2
    for factor in (1.01, 1.1, 1.3):
        assert simulate(SEED.replace(kappa=k2 * factor), "paper").n_stick == 2
    counts = [row["n_stick"] for row in critical.n_staircase if not row["cut"] and row["n_stick"] is not None]
    assert counts == sorted(counts, reverse=True)  # a staircase down to 2
    assert counts[-1] == 2 and counts[0] > 100


def test_kappa_2_from_an_independent_bisection(critical):
    again = locate_kappa_2(SEED, "paper", critical.kappa_c * (1 + 1e-12), samples=0).kappa_2
    assert again == pytest.approx(critical.kappa_2, rel=1e-7)


def test_adding_sliding_exponents(critical):
    """docs/physics.md §5: slip speed ~ eps^(3/2), spacing of the new stick points ~ eps^2."""
    from phaseimpact.continuation import adding_sliding_exponents
    ex = adding_sliding_exponents(SEED, "paper", critical.kappa_c)
    assert ex["slip_speed_exponent"] == pytest.approx(1.5, abs=0.1)
    assert ex["stick_offset_exponent"] == pytest.approx(2.0, abs=0.1)


@pytest.fixture(scope="module")
def grazing():
    return grazing_transitions(SEED, "hunt-crossley", 1e8, 1e13)


def test_grazing_values_of_hunt_crossley(grazing):
    """The seed case's contact count changes several times, including a three-contact window
    between 1e10 and 1e11; each value is a root of a smooth extremum of delta."""
    assert len(grazing) >= 3
    assert all(t.kind == "grazing" and t.count_below != t.count_above for t in grazing)
    window = [t for t in grazing if 1e10 < t.kappa < 1e11]
    assert [(t.count_below, t.count_above) for t in window][:2] == [(2, 3), (3, 2)]
    for t in grazing:
        lo = delta_extremum(SEED.replace(kappa=t.kappa * (1 - 1e-8)), "hunt-crossley", t.extremum)
        hi = delta_extremum(SEED.replace(kappa=t.kappa * (1 + 1e-8)), "hunt-crossley", t.extremum)
        assert (lo > 0) != (hi > 0)
        assert max(abs(lo), abs(hi)) < 1e-6 * SEED.hertz_indentation


def test_grazing_against_bisection_on_the_count(grazing):
    """Independent: bisection on the contact count (coarser) brackets each located value."""
    for t in grazing:
        lo, hi = t.kappa * (1 - 1e-4), t.kappa * (1 + 1e-4)
        n_lo, n_hi = contact_count(SEED.replace(kappa=lo), "hunt-crossley"), contact_count(
            SEED.replace(kappa=hi), "hunt-crossley")
        assert (n_lo, n_hi) == (t.count_below, t.count_above)
        for _ in range(12):
            mid = math.sqrt(lo * hi)
            if contact_count(SEED.replace(kappa=mid), "hunt-crossley") == n_lo:
                lo = mid
            else:
                hi = mid
        assert lo <= t.kappa * (1 + 1e-9) and hi >= t.kappa * (1 - 1e-9)


def test_transitions_of_paper():
    out = transitions(SEED, "paper", 1e9, 1e13)
    assert [t.kind for t in out] == ["adding-sliding", "staircase-end"]
    assert out[0].count_below == 1 and out[1].count_above == 2 and out[1].count_below > 2


def test_continued_kappa_c_matches_independent_solves():
    speeds = [0.7, 1.0, 2.0, 5.0, 13.0]
    curve = critical_curve(SEED, "paper", "v", speeds)
    asked = curve.requested
    assert list(curve.values[asked]) == speeds
    for v, kappa in zip(curve.values[asked], curve.kappa[asked], strict=True):
        independent = critical_damping(seed_parameters(v=float(v)), "paper").kappa_c
        assert kappa == pytest.approx(independent, rel=1e-8)
    assert np.all(np.abs(curve.kappa / curve.closed_form - 1) < 0.0025)


def test_continuation_over_a_geometry_quantity():
    case = load_case("seed")
    curve = critical_curve(case, "paper", "R1", [0.01, 0.015, 0.02])
    at_seed = critical_damping(case.parameters(), "paper").kappa_c
    assert curve.kappa[curve.values == 0.02][0] == pytest.approx(at_seed, rel=1e-8)


def test_continued_grazing_matches_independent_solves(grazing):
    first = grazing[0]
    speeds = [1.0, 1.05, 1.1]
    curve = critical_curve(SEED, "hunt-crossley", "v", speeds, what="grazing", kappa_start=first.kappa,
                           contact_index=first.extremum)
    for v, kappa in zip(curve.values[curve.requested], curve.kappa[curve.requested], strict=True):
        p = seed_parameters(v=float(v))
        lo = delta_extremum(p.replace(kappa=kappa * (1 - 1e-7)), "hunt-crossley", first.extremum)
        hi = delta_extremum(p.replace(kappa=kappa * (1 + 1e-7)), "hunt-crossley", first.extremum)
        assert (lo > 0) != (hi > 0)


def test_refined_atlas_boundary_agrees_with_the_continued_curve():
    result = atlas(SEED, "paper", {"kappa": np.geomspace(1e11, 1e13, 9), "v": np.linspace(0.5, 13, 4)})
    boundaries = refine_boundaries(result, "kappa", refine_rtol=1e-8)
    assert len(boundaries) == 4
    curve = critical_curve(SEED, "paper", "v", boundaries.points[:, 1])
    np.testing.assert_allclose(boundaries.points[:, 0], curve.kappa[curve.requested], rtol=1e-8)
