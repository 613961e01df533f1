"""The Python API validates its arguments before any work: a wrong type is a ``TypeError``, a value
out of range a ``ValueError``, each naming the argument (issue 24, the API rows of
``audits/inputs-2026-11.md``); a fuzz throws random types and magnitudes at the public functions."""

import importlib
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from phaseimpact import ContactLaw, kappa_for_restitution, scales, seed_parameters, simulate, simulate_many
from phaseimpact.case import seed_case
from phaseimpact.continuation import Axis, atlas, critical_damping, parse_axis, sweep, transitions
from phaseimpact.continuation.transition import SamplingWarning, check_samples
from phaseimpact.quantities import impact_quantities

SEED = seed_parameters()
sweep_module = importlib.import_module("phaseimpact.continuation.sweep")  # the package's name is the function


@pytest.fixture
def no_work(monkeypatch):
    """Any chunk of a sweep fails the test: the refusal must come before any work."""
    def forbidden(*args, **kwargs):
        raise AssertionError("work started before the input was refused")

    monkeypatch.setattr(sweep_module, "run_chunks", forbidden)


# ---------------------------------------------------------------------------------------------
# Each row of the audit
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize(("call", "error", "name"), [
    (lambda: seed_parameters(v=1e300), ValueError, "v = 1e+300"),
    (lambda: seed_parameters(R1=1e308), ValueError, "R1 = 1e+308"),
    (lambda: seed_parameters(kappa=1e30), ValueError, "kappa = 1e+30"),
    (lambda: simulate(SEED, "paper", 1e-3, save=[-1e-4, 5e-4]), ValueError, "save"),
    (lambda: simulate(SEED, "paper", 1e-3, save=[1e-4, 5e-3]), ValueError, "save"),
    (lambda: simulate(SEED, "paper", stop_when_settled="no"), ValueError, "stop_when_settled"),
    (lambda: simulate(SEED, "paper", max_steps=0), ValueError, "max_steps"),
    (lambda: simulate(SEED, "paper", max_steps=-5), ValueError, "max_steps"),
    (lambda: simulate(SEED, "paper", max_steps="10"), ValueError, "max_steps"),
    (lambda: simulate(SEED, "paper", stop_on=("stick", 1, 2)), ValueError, "stop_on"),
    (lambda: simulate(SEED, "paper", initial="abcd"), ValueError, "initial"),
    (lambda: simulate(SEED, "paper", 1e-308), ValueError, "t_end = 1e-308"),
    (lambda: simulate("seed", "paper"), TypeError, "params"),
    (lambda: impact_quantities(None), TypeError, "trajectory"),
    (lambda: impact_quantities("x"), TypeError, "trajectory"),
    (lambda: critical_damping("seed"), TypeError, "params"),
    (lambda: simulate_many([1, 2]), TypeError, "params_seq[0]"),
    (lambda: simulate_many(SEED), TypeError, "params_seq"),
    (lambda: simulate_many([SEED], stop_when_settled="no"), ValueError, "stop_when_settled"),
    (lambda: scales("x"), TypeError, "params"),
    (lambda: sweep(SEED, "paper", ["1e9", "1e10"]), TypeError, "axis kappa"),
    (lambda: sweep(SEED, "paper", [1e9, 1e30]), ValueError, "kappa = 1e+30"),
    (lambda: sweep(SEED, "paper", (k for k in (1e9, 1e10))), TypeError, "axis kappa"),
    (lambda: sweep(SEED, "paper", [1e9, 1e10], previous="x"), TypeError, "previous"),
    (lambda: sweep(SEED, "paper", [1e9, 1e10], on_chunk=5), TypeError, "on_chunk"),
    (lambda: sweep(SEED, "paper", [1e9, 1e9]), ValueError, "distinct"),
    (lambda: atlas(SEED, "paper", [("kappa", [1e9, 1e10])]), TypeError, "axis"),
    (lambda: atlas(SEED, "paper", "kappa=1e9:1e10:3"), TypeError, "axes"),
    (lambda: atlas(SEED, "paper", {"v": [1.0, 0.0, 2.0]}), ValueError, "v = 0.0"),
    (lambda: atlas(SEED, "paper", {"R1": [0.01, 0.02]}), ValueError, "needs a Case base"),
    (lambda: atlas(seed_case(), "paper", {"plate.yield_strength": [1e7, 1e8]}), ValueError, "not read"),
    (lambda: atlas(seed_case(), "paper", {"R1": [0.01, 1e308]}), ValueError, "R1 = 1e+308"),
    (lambda: parse_axis(5), TypeError, "axis"),
    (lambda: transitions(SEED, "hunt-crossley", 1e9, 1e12, num=0), ValueError, "num = 0"),
    (lambda: transitions(SEED, "abrate", 1e9, 1e12), ValueError, "does not read kappa"),
    (lambda: transitions(SEED, "hunt-crossley", 1e-300, 1e13), ValueError, "per decade"),
    (lambda: transitions(SEED, "hunt-crossley", 1e9, 1e30), ValueError, "kappa_max = 1e+30"),
    (lambda: critical_damping(SEED, kappa_max=1e-3), ValueError, "default kappa_min"),
    (lambda: kappa_for_restitution(SEED, 0.5), TypeError, "kappa_for_restitution(e, params)"),
    (lambda: kappa_for_restitution(2.0, "x"), TypeError, "params"),
])
def test_bad_api_input_is_refused_naming_the_argument(call, error, name, no_work):
    with pytest.raises(error) as info:
        call()
    assert name in str(info.value)
    assert "allowed" in str(info.value) or "needs" in str(info.value)


def test_zero_dimensional_arrays_are_scalars():
    """Audit: ``seed_parameters(v=np.array(1.0))`` was refused as out of range."""
    p = seed_parameters(v=np.array(2.0), R1=np.array(0.01))
    assert p.v == 2.0 and type(p.v) is float
    tr = simulate(p, "paper", np.array(1e-4), rtol=np.array(1e-8))
    assert tr.ok and tr.t_end == 1e-4
    with pytest.raises(ValueError, match="v = array"):
        seed_parameters(v=np.array([1.0, 2.0]))


def test_save_times_at_the_ends_of_the_run_are_kept():
    tr = simulate(SEED, "paper", 1e-3, save=[0.0, 5e-4, 1e-3])
    np.testing.assert_array_equal(tr.t, [0.0, 5e-4, 1e-3])


def test_the_shortest_horizon_follows_the_contact_time():
    contact = scales(SEED).contact_time
    assert simulate(SEED, "paper", 2e-13 * contact).ok
    with pytest.raises(ValueError, match=r"t_end = .* allowed: a finite number >= "):
        simulate(SEED, "paper", 0.5e-13 * contact)


def test_the_grid_checks_every_value_not_only_the_corners():
    """The middle value 0 of a v axis was found only inside the compiled run (ZeroDivisionError)."""
    with pytest.raises(ValueError, match="axis v holds v = 0.0"):
        atlas(SEED, "paper", {"v": [1.0, 0.0, 2.0]})
    with pytest.raises(ValueError, match="nu = 0.7"):
        atlas(seed_case(), "paper", {"plate.nu": [0.3, 0.7, 0.2]})


def test_restitution_attainable_by_a_law():
    from phaseimpact.model.laws import REGISTRY
    from phaseimpact.model.restitution import attainable_restitution, check_attainable

    lowest, _ = attainable_restitution(REGISTRY["lankarani-nikravesh"].chi)
    assert 0.6 < lowest < 0.7  # chi <= 3/4: the damping number of e = 0.66 at most
    with pytest.raises(ValueError, match=r"restitution = 1e-06 .* allowed: 0.66\d* <= restitution <= 1"):
        check_attainable(ContactLaw("lankarani-nikravesh", restitution=1e-6))
    check_attainable(ContactLaw("flores", restitution=1e-6))  # chi unbounded: anything goes
    check_attainable(ContactLaw("hunt-crossley", restitution=1e-6))  # the exact inverse


def test_sampling_density_refused_or_warned():
    assert check_samples(96, 1e9, 1e13) == 96
    with pytest.raises(ValueError, match="span 313 decades.*samples >= 1252"):
        check_samples(96, 1e-300, 1e13, names=("kappa-min", "kappa-max", "samples"))
    with pytest.warns(SamplingWarning, match="per decade"):
        transitions(SEED, "hunt-crossley", 1e9, 1e10, num=8)


# ---------------------------------------------------------------------------------------------
# Fuzz: random types and magnitudes into the public functions
# ---------------------------------------------------------------------------------------------

MAGNITUDES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 1e-308, 1e-300, 1e-13, 1e-6, 1.0, 13.0, 1e4, 1e12, 1e18, 1e300, -1.0]),
    st.integers(-10**30, 10**30),
)
ODD = st.sampled_from([None, "1", "", "seed", True, [1.0, 2.0], (), {}, object(), np.array(1.0), np.array([1.0]),
                       np.float32(2.0), np.int64(3), b"1", 1j])
VALUES = st.one_of(MAGNITUDES, ODD)
FIELDS = ("v", "kappa", "R1", "a", "h", "R2", "plate_E", "projectile_rho", "plate_nu", "plate_yield_strength",
          "M1", "alpha", "target", "membrane")


def _calls(value, other):
    """One public call per entry, each with ``value`` in one argument (cheap when it is valid)."""
    cheap = 1e-4  # s: a horizon that keeps a valid run short
    return [
        lambda: seed_parameters(**{other: value}),
        lambda: seed_parameters(v=value),
        lambda: simulate(SEED, "paper", value),
        lambda: simulate(SEED, value, cheap),
        lambda: simulate(SEED, "paper", cheap, rtol=value),
        lambda: simulate(SEED, "paper", cheap, save=value),
        lambda: simulate(SEED, "paper", cheap, initial=value),
        lambda: simulate(SEED, "paper", cheap, stop_on=value),
        lambda: simulate(SEED, "paper", cheap, max_steps=value),
        lambda: simulate(SEED, "paper", cheap, stop_when_settled=value),
        lambda: simulate_many(value, "paper", cheap),
        lambda: simulate_many([SEED], "paper", value),
        lambda: scales(value),
        lambda: impact_quantities(value),
        lambda: critical_damping(value),
        lambda: critical_damping(SEED, "paper", kappa_min=value, kappa_max=1e13),
        lambda: transitions(SEED, "hunt-crossley", value, 1e10, num=8),
        lambda: check_samples(value, 1e9, 1e10),  # transitions' own check (a valid num would mean minutes of work)
        lambda: sweep(SEED, "paper", value, t_end=cheap),
        lambda: sweep(SEED, "paper", [value], t_end=cheap),
        lambda: sweep(SEED, "paper", [1e9], t_end=value),
        lambda: atlas(SEED, "paper", value, t_end=cheap),
        lambda: atlas(SEED, "paper", {"v": [value]}, t_end=cheap),
        lambda: atlas(seed_case(), "paper", {other.replace("_", ".", 1) if other.startswith("p") else other:
                                             [value]}, t_end=cheap),
        lambda: parse_axis(value),
        lambda: Axis.make("kappa", value),
        lambda: kappa_for_restitution(value, SEED),
        lambda: ContactLaw("flores", restitution=value),
        lambda: seed_case().with_settings({"R1": value}),
    ]


CALLS = len(_calls(None, "v"))


@settings(max_examples=300, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(value=VALUES, other=st.sampled_from(FIELDS), which=st.integers(0, CALLS - 1))
def test_random_api_input_gives_a_result_or_a_named_error(value, other, which):
    """Only a ValueError or TypeError with a message (naming what it refuses), or a result."""
    call = _calls(value, other)[which]
    try:
        call()
    except (ValueError, TypeError) as error:
        message = str(error)
        assert message and ("=" in message or "allowed" in message), (which, value, message)
    except SamplingWarning:  # pragma: no cover - warnings are not errors here
        pass


def test_fuzz_reaches_every_call():
    assert CALLS >= 25 and math.isfinite(CALLS)


def test_a_garbled_scheduler_reply_is_reported_as_no_answer(monkeypatch):
    """Audit: an unreachable scheduler was reported through "MemoryError: Unable to allocate 3.07 EiB"."""
    import asyncio

    from phaseimpact.continuation._parallel import check_scheduler

    def garbled(coroutine):
        coroutine.close()
        raise MemoryError("Unable to allocate 3.07 EiB for an array")

    monkeypatch.setattr(asyncio, "run", garbled)
    with pytest.raises(ValueError) as info:
        check_scheduler("tcp://10.255.255.1:8786")
    assert "no answer within 5 s" in str(info.value) and "EiB" not in str(info.value)


@pytest.mark.parametrize(("call", "error", "name"), [  # audits/inputs-2026-11b.md: api-*-none, api-plane-bad
    (lambda: importlib.import_module("phaseimpact.archive").load(None), TypeError, "path = None"),
    (lambda: importlib.import_module("phaseimpact.archive").describe(None), TypeError, "path = None"),
    (lambda: importlib.import_module("phaseimpact.case").load_case(None), TypeError, "name_or_path = None"),
    (lambda: importlib.import_module("phaseimpact.model.contact").hertz_scales(None, None), TypeError, "params"),
    (lambda: importlib.import_module("phaseimpact.model.contact").hertz_scales(SEED, 3.0), TypeError, "plate_material"),
    (lambda: importlib.import_module("phaseimpact.model.contact").validity(None, None, None, None), TypeError,
     "params"),
    (lambda: importlib.import_module("phaseimpact.analysis").find_asymptotic_points(None), TypeError, "trajectory"),
    (lambda: importlib.import_module("phaseimpact.analysis").plane_coordinates(np.zeros((5, 3)),
                                                                               ("delta", "deltadot")),
     ValueError, "y has shape (5, 3)"),
])
def test_none_and_misshapen_arguments_are_named(call, error, name):
    with pytest.raises(error) as raised:
        call()
    assert name in str(raised.value) and type(raised.value) is error


@pytest.mark.parametrize("n_threads", [1, 2])
def test_simulate_many_reads_each_case_s_own_coefficients_once(monkeypatch, n_threads):
    """The up-front check of what the law needs hands its values to the packing (chunks packed as
    they run): thornton's coefficients are read once a case, not twice."""
    real, calls = ContactLaw.coefficients, []

    def counted(self, params):
        calls.append(params)
        return real(self, params)

    monkeypatch.setattr(ContactLaw, "coefficients", counted)
    cases = [SEED.replace(limiting_pressure=2e9, kappa=k) for k in np.geomspace(1e9, 1e11, 1500)]
    columns = simulate_many(cases, "thornton", n_threads=n_threads)
    assert len(calls) == len(cases) and np.all(columns.status == 0)  # 0: success


def test_a_case_the_law_cannot_run_is_refused_before_any_chunk_runs(monkeypatch):
    """simulate_many packs its chunks as they run (in threads the first has 1024 cases): a case
    without what the law needs, past the first chunk, is refused before any run, named by its index."""
    from phaseimpact.integrate import batch

    def no_run(*args, **kwargs):
        raise AssertionError("a chunk ran")

    monkeypatch.setattr(batch, "run_batch", no_run)
    cases = [SEED.replace(limiting_pressure=2e9)] * 1500 + [SEED]
    with pytest.raises(ValueError, match=r"params_seq\[1500\]: law 'thornton' needs the limiting contact pressure"):
        simulate_many(cases, "thornton", n_threads=2)
