"""Helper threads kept from one threaded chunk to the next (:func:`.batch._run_block`).

A threaded chunk runs in its caller and ``n - 1`` helper threads. Starting and joining fresh
threads for every chunk cost the caller a tenth of a millisecond or so a helper, one after the
other, where a sweep's chunk at 16 threads is some 8 ms of work (4096 runs of about 30 us shared
by 16 threads). One chunk of 32 runs in 16 threads took 3.29 ms with helpers started for it and
1.29 ms with helpers kept (``benchmarks/scale.py``'s second table, on 2 cores). So a helper does
not end with its chunk: it waits to be handed the next block, and a new one is started only when
no idle helper is left.

Helpers are taken for one chunk and given back at its end, so callers in several threads of a
process never share one. They are daemon threads: one that waits for work holds nothing, and a
process may end with idle helpers. A forked child has none of its parent's threads, and forgets them.
"""

from __future__ import annotations

import os
import queue
import threading

__all__ = ["Helper", "take", "give_back"]


class Helper:
    """A thread that runs the functions it is handed, one at a time, and reports each one's end."""

    def __init__(self):
        self._inbox = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._serve, name="phaseimpact-run", daemon=True)
        self._thread.start()

    def run(self, function, done: queue.SimpleQueue) -> None:
        """Call ``function()`` in this thread; then put None, or what it raised, into ``done``."""
        self._inbox.put((function, done))

    def _serve(self) -> None:
        while True:
            function, done = self._inbox.get()
            try:
                function()
            except BaseException as failure:  # raised in the caller's thread (batch._run_block)
                done.put(failure)
            else:
                done.put(None)
            del function  # nothing of a finished chunk stays referenced while this helper waits


_idle: list[Helper] = []
_lock = threading.Lock()


def take(n: int) -> list[Helper]:
    """``n`` helpers for one chunk: idle ones first, new ones for the rest."""
    with _lock:
        taken = [_idle.pop() for _ in range(min(n, len(_idle)))]
    return taken + [Helper() for _ in range(n - len(taken))]


def give_back(helpers: list[Helper]) -> None:
    """Helpers whose chunk has ended (each reported its end), for the next chunk."""
    with _lock:
        _idle.extend(helpers)


def _forget_after_fork() -> None:
    global _lock
    _idle.clear()  # their threads exist only in the parent
    _lock = threading.Lock()  # another thread may have held it at the fork


os.register_at_fork(after_in_child=_forget_after_fork)
