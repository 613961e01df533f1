"""The helper threads of threaded chunks (phaseimpact.integrate.helper_threads): kept from one chunk
to the next, never shared by two chunks at once, alive after a failure, forgotten by a fork."""

from __future__ import annotations

import os
import queue
import threading

import numpy as np
import pytest

from phaseimpact import seed_parameters
from phaseimpact.integrate import batch as batches
from phaseimpact.integrate import helper_threads
from phaseimpact.integrate.batch import pack_batch, run_batch
from phaseimpact.model import as_law


def _chunk(n: int = 64):
    cases = [seed_parameters(v=1.0, kappa=k) for k in np.geomspace(1e9, 1e11, n)]
    return pack_batch(cases, as_law("hunt-crossley"), None, 1e-10)


def _threads_running_blocks(monkeypatch) -> set:
    """The threads (other than this one) that run driver.run_block from now on."""
    real, seen, caller = batches.d.run_block, set(), threading.get_ident()

    def recording(*args):
        if threading.get_ident() != caller:
            seen.add(threading.get_ident())
        real(*args)

    monkeypatch.setattr(batches.d, "run_block", recording)
    return seen


def test_a_later_chunk_runs_on_the_helpers_of_the_one_before(monkeypatch):
    batch = _chunk()
    seen = _threads_running_blocks(monkeypatch)
    first = run_batch(batch, rtol=1e-10, n_threads=3)
    helpers_of_first = set(seen)
    seen.clear()
    second = run_batch(batch, rtol=1e-10, n_threads=3)
    assert len(helpers_of_first) == 2 and seen == helpers_of_first  # no thread started for the second
    assert np.array_equal(first.values["max_force"], second.values["max_force"])


def test_chunks_at_the_same_time_take_helpers_of_their_own():
    a, b = helper_threads.take(2), helper_threads.take(3)
    assert len({id(h) for h in a + b}) == 5
    helper_threads.give_back(a + b)
    again = helper_threads.take(5)
    assert {id(h) for h in again} == {id(h) for h in a + b}  # the idle ones, no new thread
    helper_threads.give_back(again)


def test_a_helper_reports_what_its_function_raised_and_serves_the_next_one():
    (helper,) = helper_threads.take(1)
    done = queue.SimpleQueue()

    def failing():
        raise RuntimeError("in the helper")

    helper.run(failing, done)
    failure = done.get(timeout=10)
    assert isinstance(failure, RuntimeError) and str(failure) == "in the helper"
    ran = []
    helper.run(lambda: ran.append(threading.get_ident()), done)
    assert done.get(timeout=10) is None and ran and ran[0] != threading.get_ident()
    helper_threads.give_back([helper])


def test_a_chunk_after_a_helper_failed_runs_on_every_thread(monkeypatch):
    """A helper whose block raised is raised by the caller, and the next chunk still runs in all its
    threads (the helper was given back alive)."""
    batch = _chunk()
    real = batches.d.run_block
    caller = threading.get_ident()
    fail = [True]

    def failing_off_the_caller(*args):
        if threading.get_ident() != caller and fail[0]:
            raise RuntimeError("a helper failed")
        real(*args)

    monkeypatch.setattr(batches.d, "run_block", failing_off_the_caller)
    with pytest.raises(RuntimeError, match="a helper failed"):
        run_batch(batch, rtol=1e-10, n_threads=2)
    fail[0] = False
    seen = _threads_running_blocks(monkeypatch)
    columns = run_batch(batch, rtol=1e-10, n_threads=2)
    assert len(seen) == 1 and np.all(columns.status == batches.d.SUCCESS)


@pytest.mark.skipif(not hasattr(os, "fork"), reason="no fork on this platform")
def test_a_forked_child_starts_helpers_of_its_own():
    helper_threads.give_back(helper_threads.take(2))  # idle helpers in the parent
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: its parent's idle helpers are threads it does not have
        try:
            os.write(write, bytes([len(helper_threads._idle)]))
            (helper,) = helper_threads.take(1)
            done = queue.SimpleQueue()
            helper.run(lambda: None, done)
            os.write(write, bytes([done.get(timeout=10) is None]))
        finally:
            os._exit(0)
    os.close(write)
    said = b""
    while chunk := os.read(read, 2):  # until the child's end closes the pipe
        said += chunk
    os.waitpid(pid, 0)
    os.close(read)
    assert said == bytes([0, 1])  # no idle helper inherited; a new one ran
