"""The GPU backend (``backend="cuda"``): one CUDA thread per point of a batch, each running
:func:`.integrate.driver.run_point_into`, the per-point kernel of the CPU threads, compiled by numba's CUDA
target from the same source (numba compiles the engine's ``@njit`` functions a CUDA kernel calls
as device functions; no second copy of any kernel).

A launch allocates every thread's workspace at once: one row per point of a float64 array, each
row the buffer a CPU thread's block runs in (:func:`.integrate.record.workspace_size` numbers), and
a thread runs in the views :func:`.integrate.record.carve` makes of its row. The inputs go to the
device once, the outputs come back once; the workspaces stay there.
This module is host code and the CUDA kernel (not cached on disk): no CPU kernel module imports it,
so it is not part of the CPU engine's cache digest (:func:`._jit.engine_sources`).

Without a usable GPU, :func:`unavailable` says what is missing (one line) and the callers refuse
before any work. numba's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1``) runs the kernel in Python
threads; it calls the engine as Python, so it needs ``NUMBA_DISABLE_JIT=1`` too (the compiled
kernels have no entry from Python): the tests run it so, on small grids.
"""

from __future__ import annotations

import functools

import numba
import numpy as np

from .integrate.record import Y_AT, Y_STATE, workspace_size

try:  # a module global: the simulator swaps it for its own in the kernel's globals
    from numba import cuda
except ImportError as missing:  # a numba built without its CUDA target
    cuda, _MISSING = None, missing

__all__ = ["unavailable", "check", "run_batch_cuda", "THREADS_PER_BLOCK"]

#: Threads of a block. The per-point kernel is long and holds many registers: small blocks keep
#: the multiprocessors' register files from limiting the blocks resident at once.
THREADS_PER_BLOCK = 64


def unavailable() -> str | None:
    """None when the CUDA backend can run here, else one line naming CUDA and what is missing."""
    if cuda is None:
        return f"CUDA is not usable: numba {numba.__version__} has no CUDA target ({_MISSING})"
    if numba.config.ENABLE_CUDASIM:
        if not numba.config.DISABLE_JIT:
            return ("CUDA is not usable: numba's CUDA simulator (NUMBA_ENABLE_CUDASIM=1) runs the engine as "
                    "Python and needs NUMBA_DISABLE_JIT=1 as well")
        return None
    from numba.cuda.cudadrv.driver import driver

    if not driver.is_available:
        # numba's message, first sentence only ("CUDA driver library cannot be found.")
        why = " ".join((driver.initialization_error or "unknown error").split()).split(". ")[0].rstrip(".")
        return f"CUDA is not usable: no working CUDA driver ({why})"
    from numba.cuda.cudadrv import nvvm

    if not nvvm.is_available():
        return "CUDA is not usable: no NVVM (the CUDA toolkit's compiler library) to compile the kernels with"
    if len(cuda.gpus) == 0:
        return "CUDA is not usable: the CUDA driver finds no device"
    return None


def check(law) -> None:
    """Refuse the CUDA backend before any work: a user law (a Python function, which a GPU
    cannot call), or no usable GPU (:func:`unavailable`). ValueError, one line."""
    if law.entry.native is not None:
        raise ValueError(f"backend = 'cuda' cannot run the user law {law.name!r}: its Python function cannot run "
                         "on a GPU; allowed: a built-in law (phaseimpact laws), or backend 'threads'")
    why = unavailable()
    if why is not None:
        raise ValueError(f"backend = 'cuda': {why}")


@functools.cache
def _device_min_max() -> None:
    """``max`` and ``min`` of 2 to 4 numbers on the CUDA target. numba's own (an overload taking
    ``*args``) does not compile as a device function (its arity is lost: "2 argument types given,
    but function takes 1"); these keep its order of comparisons (Python's: the first of equal
    values; a NaN only where it comes first), so results are those of the CPU's."""
    from numba import types
    from numba.extending import overload, register_jitable

    def numbers(*values):
        return all(isinstance(v, (types.Number, types.Boolean)) for v in values)

    # one overload per arity: the device compile checks the implementation's argument count
    # against the call's (``*args`` counts as one argument there)
    def define(builtin, later):
        @overload(builtin, target="cuda")
        def two(a, b):
            if numbers(a, b):
                return lambda a, b: b if later(b, a) else a

        @overload(builtin, target="cuda")
        def three(a, b, c):
            if numbers(a, b, c):
                def three_(a, b, c):
                    first = b if later(b, a) else a
                    return c if later(c, first) else first
                return three_

        @overload(builtin, target="cuda")
        def four(a, b, c, d):
            if numbers(a, b, c, d):
                def four_(a, b, c, d):
                    first = b if later(b, a) else a
                    second = c if later(c, first) else first
                    return d if later(d, second) else second
                return four_

    define(max, register_jitable(inline="always")(lambda x, y: x > y))
    define(min, register_jitable(inline="always")(lambda x, y: x < y))


@functools.cache
def _kernel():
    """The CUDA kernel (compiled on first launch): thread ``i`` runs point ``i`` in row ``i`` of
    ``work`` (:func:`workspaces`)."""
    from .integrate.driver import run_point_into
    from .integrate.record import carve

    _device_min_max()

    @cuda.jit
    def points(code, batch, options, outputs, work):
        i = cuda.grid(1)
        if i < batch[0].shape[0]:
            ws = carve(work[i], batch[0].shape[1], outputs[1].shape[1], True)  # with Radau
            run_point_into(code, ws, batch, options, i, outputs)

    return points


def workspaces(n: int, n_coef: int, capacity: int) -> np.ndarray:
    """One workspace row per point (a host array, zeros), as a CPU thread's block gets one."""
    return np.zeros((n, workspace_size(n_coef, capacity)))


def run_batch_cuda(code: int, batch: tuple, options: tuple, outputs: tuple, final_states=None) -> None:
    """Run every point of ``batch`` (the tuple ``integrate.driver.B_*``) on the GPU, one thread each, and fill
    ``outputs`` (the tuple ``integrate.driver.O_*``) as :func:`.integrate.driver.run_block` does; and
    ``final_states`` (n x 5, optional) with each run's state ``(x1, x2, x1dot, x2dot, W)`` at its end (row
    ``Y_STATE`` of its workspace, what :func:`.integrate.api.summary_run` returns). Call :func:`unavailable`
    first."""
    from numba import cuda

    n = batch[0].shape[0]
    work = cuda.to_device(workspaces(n, batch[0].shape[1], outputs[1].shape[1]))
    device_batch = tuple(cuda.to_device(np.ascontiguousarray(a)) for a in batch)
    device_outputs = tuple(cuda.to_device(a) for a in outputs)
    blocks = (n + THREADS_PER_BLOCK - 1) // THREADS_PER_BLOCK
    _kernel()[blocks, THREADS_PER_BLOCK](np.int64(code), device_batch, options, device_outputs, work)
    cuda.synchronize()
    for host, device in zip(outputs, device_outputs, strict=True):
        device.copy_to_host(host)
    if final_states is not None:
        at = Y_AT + 5 * Y_STATE
        final_states[...] = work.copy_to_host()[:, at:at + 5]
