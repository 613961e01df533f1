"""simulate_many's packing on columns (batch._pack) against simulate's per-case packing, bit for bit."""

import numpy as np
import pytest
from _registry import restored_registry

from phaseimpact import define_law, seed_parameters
from phaseimpact.integrate import api
from phaseimpact.integrate.batch import pack_batch
from phaseimpact.model import REGISTRY, ContactLaw
from phaseimpact.model.rhs import pack

LAWS = [ContactLaw("paper"), ContactLaw("hunt-crossley"), ContactLaw("hunt-crossley", restitution=0.8),
        ContactLaw("lankarani-nikravesh", restitution=0.7), ContactLaw("flores", restitution=0.9),
        ContactLaw("abrate"), ContactLaw("thornton")]


def varied_cases(n: int = 60) -> list:
    """Every target, several exponents, springs with and without a period, speeds and masses."""
    rng = np.random.default_rng(7)
    plate, infinite = seed_parameters(limiting_pressure=2e9), seed_parameters(target="infinite", limiting_pressure=2e9)
    cases = []
    for i in range(n):
        target = ("plate", "rigid", "free", "infinite")[i % 4]
        cases.append((infinite if target == "infinite" else plate).replace(
            target=target, kappa=float(10 ** rng.uniform(6, 13)), v=float(rng.uniform(0.2, 13.0)),
            alpha=float(rng.choice([1.0, 1.5, 2.0])), M1=float(rng.uniform(0.05, 1.0)),
            Kb=float(rng.choice([0.0, 1e7, 3e7])), Km=float(rng.choice([0.0, 1.7e11]))))
    return cases


def per_case(cases, law, t_end, rtol, initial):
    """The rows simulate() packs for each case (rhs.pack, scales, _atol, _initial, check_t_end)."""
    rows = []
    for p in cases:
        s = api.scales(p)
        rows.append((pack(p, law), api._initial(p, initial), s.horizon if t_end is None else api.check_t_end(
            t_end, s.contact_time), api._atol(p, rtol, None), s.max_step))
    return [np.array(column) for column in zip(*rows, strict=True)]


@pytest.fixture(scope="module", autouse=True)
def _user_law_leaves_with_the_module():
    """Later tests enumerate the registry (test_laws' variants, test_precompile's fingerprint)."""
    with restored_registry():
        yield


def user_law() -> ContactLaw:
    name = "pack-test-kk"
    if name not in REGISTRY:
        define_law(name, lambda d, dd, K, k, a: (K + k * dd) * d ** a)
    return ContactLaw(name)


@pytest.mark.parametrize("law", LAWS + ["user"], ids=lambda law: law if isinstance(law, str) else law.label())
@pytest.mark.parametrize("t_end, initial", [(None, None), (2e-3, None), (None, (1e-6, 0.0, 1.5, -0.25)),
                                            (7, [0, 0, 2, 0])])
def test_columns_equal_the_per_case_packing_bit_for_bit(law, t_end, initial):
    law = user_law() if law == "user" else law
    cases = varied_cases()
    if law.name == "thornton":  # Hertz only
        cases = [p.replace(alpha=1.5) for p in cases]
    batch = pack_batch(cases, law, t_end, 1e-10, initial)
    expected = per_case(cases, law, t_end, 1e-10, initial)
    for name, want in zip(("C", "Y0", "t_end", "atol", "max_step"), expected, strict=True):
        got = getattr(batch, name)
        assert got.shape == want.shape and got.dtype == want.dtype, name
        assert np.array_equal(got, want), name


def test_a_horizon_too_short_names_the_first_case_it_is_too_short_for():
    slow, fast = seed_parameters(v=0.2), seed_parameters(v=13.0)  # the slow impact lasts longer
    t_end = 1e-13 * api.scales(slow).contact_time * 0.5
    assert t_end >= 1e-13 * api.scales(fast).contact_time  # long enough for the first case only
    with pytest.raises(ValueError, match="t_end") as caught:
        pack_batch([fast, fast, slow], "paper", t_end, 1e-10)
    with pytest.raises(ValueError) as per_case_error:
        api.check_t_end(t_end, api.scales(slow).contact_time)
    assert str(caught.value) == str(per_case_error.value)


def test_a_case_the_law_cannot_pack_is_refused_by_the_law():
    cases = [seed_parameters(limiting_pressure=2e9), seed_parameters()]  # thornton needs p_y
    with pytest.raises(ValueError, match=r"params_seq\[1\]: law 'thornton' needs the limiting contact pressure"):
        pack_batch(cases, "thornton", None, 1e-10)
