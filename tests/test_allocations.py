"""The per-point path allocates nothing: many runs go through the driver's per-point kernels in a
workspace the host makes once per thread and chunk (``batch.run_batch``, handed to ``driver.run_block``),
counted with numba's runtime allocation statistics; a run whose stick points overflow the chunk's
rows is run again on the full path."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np

from phaseimpact import seed_parameters, simulate
from phaseimpact.integrate import api
from phaseimpact.integrate.batch import pack_batch, run_batch

# numba counts its allocations only when NUMBA_NRT_STATS is set as its runtime starts: a process of its own
COUNT = r"""
import json
import numpy as np
from numba.core.runtime import rtsys
from phaseimpact import seed_parameters, simulate, simulate_many
from phaseimpact.integrate import batch

def allocations(n, threads):
    cases = [seed_parameters(v=1.0, kappa=k) for k in np.geomspace(1e9, 1e13, n)]
    before = rtsys.get_allocation_stats().alloc
    columns = simulate_many(cases, "paper", n_threads=threads)
    return rtsys.get_allocation_stats().alloc - before, int(columns.stick_count.max())

simulate_many([seed_parameters(v=1.0)], "paper", n_threads=2)  # the engine loaded (or compiled) first
before = rtsys.get_allocation_stats().alloc
simulate(seed_parameters(v=1.0), "paper")
trajectory = rtsys.get_allocation_stats().alloc - before
print(json.dumps({"chunks": [len(batch.pack_chunks(10_000, threaded)) for threaded in (False, True)],
                  "trajectory": trajectory, "one": allocations(1, 1),
                  "many": allocations(10_000, 1), "many_two_threads": allocations(10_000, 2)}))
"""


def test_a_sweep_makes_no_numba_allocation():
    """10 000 runs in chunks (batch.pack_chunks), in one thread or two, make no numba allocation at
    all: each thread's workspace is one numpy buffer the host makes per chunk, and run_block (a
    kernel: no reference counting) takes it and the batch without numba's runtime (the driver of
    issue 36 made 32 per thread and chunk: the workspace's 22 arrays and the 10 it was handed; the
    one before it ~21 per run). One trajectory does allocate (its workspace and logs): the counter
    counts."""
    env = dict(os.environ, NUMBA_NRT_STATS="1")
    out = subprocess.run([sys.executable, "-c", COUNT], env=env, capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-3000:]
    counts = json.loads(out.stdout.strip().splitlines()[-1])
    assert min(counts["chunks"]) > 1  # the sweep spans several chunks
    many, most_sticks = counts["many"]
    assert most_sticks <= 32  # no run overflowed its stick rows (that run would go the full path)
    assert counts["trajectory"] > 0
    assert counts["one"][0] == many == counts["many_two_threads"][0] == 0


def test_a_run_that_overflows_its_stick_rows_gives_the_full_path_result():
    """Capacity 1 for a run with four stick phases (seed case, v = 7 m/s, kappa = 4.16865e11): the
    run is flagged (its count above the capacity) and run again on the full path (event log), and
    its columns equal both a roomy batch and ``simulate`` bit for bit."""
    p = seed_parameters(v=7.0, kappa=4.16865e11)
    batch = pack_batch([p], "paper", None, 1e-10)
    tight = run_batch(batch, rtol=1e-10, capacity=1)
    roomy = run_batch(batch, rtol=1e-10, capacity=32)
    alone = simulate(p, "paper")
    t, delta, dwell = alone.stick_points()
    assert len(t) == tight.stick_count[0] == roomy.stick_count[0] == 4
    for columns in (tight, roomy):
        np.testing.assert_array_equal(columns.stick_t, t)
        np.testing.assert_array_equal(columns.stick_delta, delta)
        np.testing.assert_array_equal(columns.stick_dwell, dwell)
        np.testing.assert_array_equal(columns.max_force, [alone.max_force])
        np.testing.assert_array_equal(columns.t_stop, [alone.t_stop])


SEARCH = r"""
import json
import numpy as np
from numba.core.runtime import rtsys
from phaseimpact import seed_parameters
from phaseimpact.continuation import delta_extremum, first_stick_margin
from phaseimpact.maps.impact import ModelImpactMap

p = seed_parameters(v=1.0)
hc = seed_parameters(v=1.0, kappa=1e9)
imap = ModelImpactMap(seed_parameters(kappa=3e9), "hunt-crossley", 3e-3)

def allocations(n):
    before = rtsys.get_allocation_stats().alloc
    margins = [first_stick_margin(p.replace(kappa=k)) for k in np.geomspace(1e12, 2e12, n)]
    extrema = [delta_extremum(hc.replace(kappa=k), "hunt-crossley", 1) for k in np.geomspace(1e8, 1e10, n)]
    states = [imap((x2, 0.0)) for x2 in np.linspace(0.0, 1e-6, n)]
    assert all(np.isfinite(margins)) and all(np.isfinite(extrema)) and all(np.isfinite(states).ravel())
    return rtsys.get_allocation_stats().alloc - before

first_stick_margin(p.replace(kappa=1e12))  # the engine loaded (or compiled) and this thread's workspace made
allocations(1)
print(json.dumps({"one": allocations(1), "many": allocations(40)}))
"""


def test_critical_search_and_impact_map_points_allocate_nothing_per_point():
    """The points of a kappa_c search (the first stick's margin), of a grazing search (an extremum
    of delta) and impact-map steps run in this thread's held workspace (api.summary_run): 40
    points of each make as many numba allocations as one (none per point; the full path with its
    event log made ~21 per run)."""
    env = dict(os.environ, NUMBA_NRT_STATS="1")
    out = subprocess.run([sys.executable, "-c", SEARCH], env=env, capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-3000:]
    counts = json.loads(out.stdout.strip().splitlines()[-1])
    assert counts["many"] == counts["one"]
    assert counts["one"] < 10


def test_summary_run_gives_simulate_numbers():
    """summary_run (the held workspace, no event log, no stick points kept) gives simulate's
    summary vector and final state bit for bit: a run with four stick phases, a run stopped at its
    first stick, a run of a unilateral law from a given state stopped at a reversal."""
    cases = [(seed_parameters(v=7.0, kappa=4.16865e11), "paper", None, {}),
             (seed_parameters(v=1.0, kappa=1.5e12), "paper", None, {"stop_on": "stick"}),
             (seed_parameters(v=1.0, kappa=1e9), "hunt-crossley", 1e-2,
              {"stop_on": ("reversal", 2), "stop_when_settled": False, "initial": (1e-6, 1e-6, 1.0, 0.01)})]
    for params, law, t_end, options in cases:
        alone = simulate(params, law, t_end, **options)
        summary, final = api.summary_run(params, law, t_end, **options)
        np.testing.assert_array_equal(summary, alone.summary)
        np.testing.assert_array_equal(final, alone.final_state)
    assert alone.stop_reason == "asked" and summary[api.d.S_REASON] == api.d.ASKED_STOP
    assert api.summary_run(cases[0][0], "paper")[0][api.d.S_N_STICK] == 4


def test_the_workspace_members_tile_one_buffer():
    """record.carve's views (every member, Radau's too; the controller ``W_STIFF`` is Radau's own) lie
    in one buffer of workspace_size numbers without overlapping, Radau's complex members 16-byte
    aligned as an array of their own is; the buffer comes zeroed (radau5.clear's state, empty
    counters)."""
    from phaseimpact.integrate import radau5, record

    def members(ws):
        for member in ws:
            yield from (members(member) if isinstance(member, tuple) else [member])

    def address(a):
        return a.__array_interface__["data"][0]

    for n_coef, capacity in ((12, 0), (12, 3), (25, 32)):
        without = record.workspace(n_coef, capacity, None)  # W_RADAU None: only its controller, W_STIFF
        assert without[record.W_RADAU] is None and without[record.W_STIFF].shape == (radau5.N_CTL,)
        ws = record.workspace(n_coef, capacity, True)  # W_STIFF is then the controller of W_RADAU's tuple
        assert address(ws[record.W_STIFF]) == address(ws[record.W_RADAU][radau5.CTL])
        views = sorted(members(ws[:record.W_STIFF] + ws[record.W_RADAU:]), key=address)
        starts = [a.__array_interface__["data"][0] for a in views]
        ends = [start + a.nbytes for start, a in zip(starts, views, strict=True)]
        assert all(end <= start for end, start in zip(ends, starts[1:], strict=False))  # no overlap
        assert ends[-1] - starts[0] <= 8 * record.workspace_size(n_coef, capacity)
        assert record.workspace_size(n_coef, capacity) % 2 == 0
        assert all(start % 16 == 0 for start, a in zip(starts, views, strict=True) if a.dtype == np.complex128)
        assert all(not a.any() for a in views)
        assert len(views) == 22 and {a.dtype for a in views} == {np.dtype(t) for t in (float, np.int64, bool, complex)}
        # the y rows where a host reads a run's state (record.Y_AT)
        base = min(a.__array_interface__["data"][0] for a in members(ws))
        assert ws[record.W_Y].__array_interface__["data"][0] - base == 8 * record.Y_AT



def _run_in_buffers(batch, capacity: int, fill: float):
    """run_block over the whole batch (the engine with the stiff solver) in a workspace and outputs
    full of ``fill``: (summaries, counts, each run's first stick points)."""
    from phaseimpact.integrate import driver as d
    from phaseimpact.integrate.batch import MAX_EVENTS, MAX_STEPS, _stiff_after
    from phaseimpact.integrate.record import workspace_size

    n = len(batch)
    summary, st = np.full((n, d.N_SUMMARY), fill), np.full((3, n, capacity), fill)
    count = np.full(n, -7, np.int64)
    work = np.full(workspace_size(batch.C.shape[1], capacity), fill)
    d.run_block(batch.law.code, (batch.C, batch.Y0, batch.t_end, batch.atol, batch.max_step),
                (1e-10, True, np.int64(-1), np.int64(0), MAX_STEPS, MAX_EVENTS, _stiff_after(True)),
                np.array([[0, n, 1]]), np.zeros(1, np.int64), (summary, st[0], st[1], st[2], count), work, True)
    kept = np.arange(capacity) < np.minimum(count, capacity)[:, None]
    return summary, count, [st[j][kept] for j in range(3)]


def test_a_run_reads_nothing_its_workspace_or_outputs_held_before():
    """The per-point path sets every number of its workspace that it reads, and every output number
    its callers read (the summaries, the counts, the first stick points): run_block in buffers
    poisoned with NaN, 1e300 or -3 gives the results of zeroed ones, for a law of each kind, with
    the stiff solver in the workspace. The GPU's workspaces and outputs are made on the device
    uninitialised (phaseimpact.cuda.run_batch_cuda) because of this."""
    laws = {"paper": {}, "hunt-crossley": {}, "abrate": {}, "thornton": {"limiting_pressure": 2e9}}
    for law, extra in laws.items():
        base = seed_parameters(**extra)
        batch = pack_batch([base.replace(kappa=k, v=v) for k in np.geomspace(1e8, 1e15, 6) for v in (0.3, 6.35, 13.0)],
                           law, None, 1e-10)
        zeroed = _run_in_buffers(batch, 1, 0.0)  # room for one stick point: paper's second ones overflow
        assert np.all(zeroed[1] >= 0) and (law != "paper" or zeroed[1].max() == 2)
        for fill in (np.nan, 1e300, -3.0):
            summary, count, points = _run_in_buffers(batch, 1, fill)
            np.testing.assert_array_equal(summary, zeroed[0], err_msg=f"{law}, buffers full of {fill}")
            np.testing.assert_array_equal(count, zeroed[1])
            for ours, reference in zip(points, zeroed[2], strict=True):
                np.testing.assert_array_equal(ours, reference)
