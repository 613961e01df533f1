"""Sweeps and atlases: the same numbers whatever the jobs, backend or chunking; the same numbers
as single runs; axes the law does not read refused before any work."""

import importlib

import numpy as np
import pytest

from phaseimpact import ContactLaw, seed_parameters, simulate
from phaseimpact.case import load_case
from phaseimpact.continuation import Axis, atlas, parse_axis, sweep
from phaseimpact.continuation.grid import Grid
from phaseimpact.integrate.batch import pack_batch

sweep_module = importlib.import_module("phaseimpact.continuation.sweep")  # the name is the function

SEED = seed_parameters(v=1.0)
KAPPA_C = 1.4994185342868816e12
KAPPAS = np.geomspace(1e9, 1e14, 24)


def _same(a, b):
    assert np.array_equal(a.status, b.status) and np.array_equal(a.outcome, b.outcome)
    for name, values in a.values.items():
        assert np.array_equal(values, b.values[name], equal_nan=values.dtype.kind == "f"), name
    order_a, order_b = np.lexsort((a.stick_t, a.stick_point)), np.lexsort((b.stick_t, b.stick_point))
    assert np.array_equal(a.stick_delta[order_a], b.stick_delta[order_b])


@pytest.fixture(scope="module")
def reference():
    return sweep(SEED, "paper", KAPPAS, n_jobs=1)


def test_threads_do_not_change_any_number(reference):
    _same(reference, sweep(SEED, "paper", KAPPAS, n_jobs=2))


def test_chunking_does_not_change_any_number(reference, monkeypatch):
    monkeypatch.setattr(sweep_module, "CHUNK_THREADS", 5)
    calls = []
    _same(reference, sweep(SEED, "paper", KAPPAS, on_chunk=lambda r: calls.append(1)))
    assert len(calls) == 5


@pytest.mark.slow
def test_processes_and_dask_do_not_change_any_number(reference):
    _same(reference, sweep(SEED, "paper", KAPPAS, n_jobs=2, backend="loky"))
    _same(reference, sweep(SEED, "paper", KAPPAS, n_jobs=2, backend="dask"))


@pytest.mark.slow
def test_a_dask_client_of_four_workers_keeps_them_all_busy():
    """A Client the caller holds (left open), --jobs -1 = every worker thread, chunks from the
    cluster's size (8 chunks of 256 points here), the engine loaded on each worker first; the
    numbers unchanged."""
    distributed = pytest.importorskip("distributed")
    from phaseimpact.cli import MAX_DASK_TASKS
    from phaseimpact.continuation import _parallel

    assert MAX_DASK_TASKS == _parallel.MAX_DASK_TASKS
    cluster = distributed.LocalCluster(n_workers=4, threads_per_worker=1, processes=False, dashboard_address=None)
    with cluster, distributed.Client(cluster) as client:
        assert _parallel.tasks_in_flight(-1, client) == 4
        kappas = np.geomspace(1e9, 1e14, 2048)
        with distributed.get_task_stream(client) as stream:
            result = sweep(SEED, "paper", kappas, n_jobs=-1, backend="dask", scheduler=client)
        _same(sweep(SEED, "paper", kappas, n_jobs=2), result)
        workers = {task["worker"] for task in stream.data if "_run_task" in task["key"]}
        assert len(workers) == 4, workers
        assert client.status == "running"  # not closed: it is the caller's
    with pytest.raises(ValueError, match="jobs = 0 is out of range; allowed: an integer 1..100000"):
        sweep(SEED, "paper", KAPPAS, n_jobs=0, backend="dask")
    with pytest.raises(ValueError, match="scheduler = 3"):
        sweep(SEED, "paper", KAPPAS, backend="dask", scheduler=3)


@pytest.mark.parametrize("contact", ["printed", "unilateral"])
def test_near_kappa_c_window_sweep_equals_simulate(contact):
    """The window where the old batch loop and simulate disagreed (62/20 against 42/6)."""
    law = ContactLaw("paper", contact=contact)
    kappas = KAPPA_C * (1 + np.array([1e-4, 2e-4, 1e-6 * 1.5, 3e-5]))
    result = sweep(SEED, law, kappas)
    for i, k in enumerate(kappas):
        tr = simulate(SEED.replace(kappa=float(k)), law)
        assert result.n_stick[i] == tr.n_stick
        assert result.outcome_names()[i] == tr.outcome
        assert np.array_equal(result.t_run[i], np.float64(tr.t_run if tr.t_run is not None else np.nan),
                              equal_nan=True)
    assert list(result.n_stick[:2]) == [42, 6]


@pytest.mark.parametrize("target", ["plate", "rigid", "free", "infinite"])
@pytest.mark.parametrize("law", [ContactLaw("hunt-crossley"), ContactLaw("flores", restitution=0.8)],
                         ids=["kappa", "restitution"])
def test_an_atlas_over_v_packs_each_point_as_simulate_does(target, law):
    """The grid packs kappa and v axes on columns: bit for bit the per-point packing (pack_batch, as
    simulate's), the tolerances and horizons included. numpy's power differs from Python's in the
    last bit for ~5 % of the values: the indentation's power on arrays gave 475 of 3000 points other
    tolerances, and the horizon of a target without springs, scaled from the base case, 1573."""
    base = seed_parameters(target=target)
    v = np.sort(np.random.default_rng(3).uniform(0.5, 12.0, 3000))
    kappa = [] if law.damping_source == "restitution" else [Axis("kappa", np.array([3e9, 3e11]))]
    grid = Grid(base, law, (*kappa, Axis("v", v)))
    n = int(np.prod(grid.shape))
    columns = grid.batch(np.arange(n), None, 1e-10)
    per_point = pack_batch([grid.parameters_at(grid.point_values(i)) for i in range(n)], law, None, 1e-10)
    for name in ("C", "Y0", "t_end", "atol", "max_step"):
        np.testing.assert_array_equal(getattr(columns, name), getattr(per_point, name), err_msg=name)


def test_axes_the_law_does_not_read_are_refused():
    for law in (ContactLaw("flores", restitution=0.5), ContactLaw("abrate"),
                ContactLaw("hunt-crossley", restitution=0.5)):
        with pytest.raises(ValueError, match="not read by law"):
            sweep(SEED, law, KAPPAS)


@pytest.mark.parametrize("kwargs, name", [
    ({"rtol": 5.0}, "rtol"), ({"t_end": -1.0}, "t_end"), ({"n_jobs": 0}, "jobs"), ({"backend": "mpi"}, "backend"),
    ({"scheduler": "tcp://x:1"}, "scheduler"),
])
def test_bad_sweep_options_are_refused(kwargs, name):
    with pytest.raises(ValueError, match=name):
        sweep(SEED, "paper", KAPPAS, **kwargs)


def test_atlas_over_a_material_quantity_matches_single_runs():
    case = load_case("seed")
    result = atlas(case, "paper", [parse_axis("kappa=1e11:1e13:3:log"), parse_axis("plate.E=1e11:2.1e11:2")])
    assert result.shape == (3, 2)
    for flat in range(6):
        point = result.grid.point_values(flat)
        tr = simulate(case.parameters(**point), "paper")
        assert result.n_stick[flat] == tr.n_stick and result.max_force[flat] == tr.max_force


@pytest.mark.parametrize("text, message", [
    ("kappa=1:0:x", "kappa"), ("kappa=1e9:1e12", "kappa"), ("v=0:1:3:log", "v"), ("=1:2:3", "axis"),
])
def test_bad_axes_are_refused(text, message):
    with pytest.raises(ValueError, match=message):
        parse_axis(text)


def test_unknown_axis_is_refused():
    with pytest.raises(ValueError, match="foo"):
        atlas(SEED, "paper", [parse_axis("foo=1:2:3")])
