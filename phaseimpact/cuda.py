"""The GPU backend (``backend="cuda"``): one CUDA thread per point of a batch, each running
:func:`.integrate.driver.run_point_into`, the per-point kernel of the CPU threads, compiled by numba's CUDA
target from the same source (numba compiles the engine's ``@njit`` functions a CUDA kernel calls
as device functions; no second copy of any kernel).

A launch allocates every thread's workspace at once, on the device: one row per point of a float64
array, each row the buffer a CPU thread's block runs in (:func:`.integrate.record.workspace_size`
numbers), and a thread runs in the views :func:`.integrate.record.carve` makes of its row. The
inputs go to the device once, the outputs come back once; the workspaces stay there.
This module is host code and the CUDA kernel (not cached on disk): no CPU kernel module imports it,
so it is not part of the CPU engine's cache digest (:func:`._jit.engine_sources`).

**The engine's calls stay calls on the GPU.** numba hands NVVM one module per compiled function and
a copy of it for every function that calls it (3172 modules, 62.6 MB of IR, for the kernel's 156
functions), and numba's own CUDA target marks every device function ``alwaysinline`` (its
``inline="never"`` read as true; numba-cuda fixed that, but leaves the inlining to NVVM): NVVM put
the whole engine into the kernel, 461 000 lines of PTX, in most of a five-minute compile for sm_90
on this project's 2-core machine (``benchmarks/results/gpu_compile.md``); on an H200 machine the
first launch had not finished after 559 s (``benchmarks/results/gpu.md``). So
before NVVM, :func:`_install_call_policy` passes each module once and marks ``noinline`` the
functions the CPU engine compiles as calls (those without ``forceinline``: the entries, the run
loop, the step, the event and stiff-solver kernels), leaving NVVM to inline the small kernels of
the hot path as the CPU does (``benchmarks/gpu_compile.py`` times both). The arithmetic is the
same, up to where NVVM fuses a multiply and an add (``fma``, on by default), which it can do across
an inlined call and not across a kept one: last bits. What the calls cost on a GPU has not been
timed. This hooks numba's private
``nvvm.compile_ir`` (``llvm_to_ptx`` in numba 0.59; the same in numba-cuda); ``PHASEIMPACT_GPU_CALLS=0``
leaves numba as it is, and a numba without either gets one warning and numba's own compile.

Without a usable GPU, :func:`unavailable` says what is missing (one line) and the callers refuse
before any work. numba's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1``) runs the kernel in Python
threads; it calls the engine as Python, so it needs ``NUMBA_DISABLE_JIT=1`` too (the compiled
kernels have no entry from Python): the tests run it so, on small grids.
"""

from __future__ import annotations

import functools
import re
import sys
import warnings

import numba
import numpy as np

from ._environment import GPU_CALLS_VARIABLE, gpu_calls_kept
from .integrate.record import Y_AT, Y_STATE, workspace_size

try:  # a module global: the simulator swaps it for its own in the kernel's globals
    from numba import cuda
except ImportError as missing:  # a numba built without its CUDA target
    cuda, _MISSING = None, missing

__all__ = ["unavailable", "check", "run_batch_cuda", "THREADS_PER_BLOCK", "NVVM_ENTRIES"]

#: Threads of a block. The per-point kernel is long and holds many registers: small blocks keep
#: the multiprocessors' register files from limiting the blocks resident at once.
THREADS_PER_BLOCK = 64
#: numba's function that hands the IR to NVVM: ``compile_ir`` from numba 0.60 (and in numba-cuda),
#: ``llvm_to_ptx`` in numba 0.59 (the same arguments: the modules' IR and NVVM's options).
NVVM_ENTRIES = ("compile_ir", "llvm_to_ptx")


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
    cannot call), ``PHASEIMPACT_GPU_CALLS`` out of range, or no usable GPU (:func:`unavailable`).
    ValueError, one line."""
    gpu_calls_kept()
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


def engine_calls() -> frozenset:
    """The dotted names (``module.qualname``) of the engine's compiled functions that the CPU keeps
    as calls: every numba dispatcher a ``phaseimpact`` module defines without ``forceinline``."""
    names = set()
    for module_name, module in list(sys.modules.items()):
        if module_name.split(".")[0] != __name__.split(".")[0] or module is None:
            continue
        for value in list(vars(module).values()):
            options, py_func = getattr(value, "targetoptions", None), getattr(value, "py_func", None)
            if isinstance(options, dict) and py_func is not None and py_func.__module__ == module_name \
                    and not options.get("forceinline"):
                names.add(f"{module_name}.{py_func.__qualname__}")
    return frozenset(names)


def _demangled(symbol: str) -> str:
    """The dotted name in numba's Itanium-style symbol ``_ZN<len><part>...``, up to its ABI tags."""
    parts, i = [], 3
    while i < len(symbol) and symbol[i].isdigit():
        j = i
        while j < len(symbol) and symbol[j].isdigit():
            j += 1
        length = int(symbol[i:j])
        parts.append(symbol[j:j + length])
        i = j + length
    return ".".join(parts)


_SYMBOL = re.compile(r'@"?(_ZN[0-9A-Za-z_$]+)')


def keep_calls(module_ir: str, calls: frozenset) -> str:
    """``module_ir`` (one module's LLVM IR, as numba prints it) with the functions named in ``calls``
    (:func:`engine_calls`) defined ``noinline`` and declared without ``alwaysinline``; every other
    line as it was."""
    lines = module_ir.split("\n")
    for k, line in enumerate(lines):
        is_definition = line.startswith("define ")
        if not (is_definition or line.startswith("declare ")):
            continue
        symbol = _SYMBOL.search(line)
        if symbol is None or _demangled(symbol.group(1)) not in calls:
            continue
        head = line.rstrip()
        opens_body = head.endswith("{")
        if opens_body:
            head = head[:-1].rstrip()
        head = head.replace(" alwaysinline", "")
        if is_definition and not head.endswith(" noinline"):
            head += " noinline"
        lines[k] = head + (" {" if opens_body else "")
    return "\n".join(lines)


def nvvm_entry(nvvm) -> str | None:
    """The name of numba's function that hands the IR to NVVM (:data:`NVVM_ENTRIES`), or None."""
    return next((name for name in NVVM_ENTRIES if callable(getattr(nvvm, name, None))), None)


@functools.cache
def _install_call_policy() -> None:
    """Wrap numba's NVVM entry (module docstring): each module once, the engine's calls
    ``noinline``. Once per process; nothing where ``PHASEIMPACT_GPU_CALLS=0``."""
    if not gpu_calls_kept() or numba.config.ENABLE_CUDASIM:
        return
    from numba.cuda.cudadrv import nvvm

    name = nvvm_entry(nvvm)
    if name is None:
        warnings.warn(f"phaseimpact: numba {numba.__version__}'s CUDA target has none of "
                      f"nvvm.{', nvvm.'.join(NVVM_ENTRIES)}; the GPU kernel is compiled numba's own way, every call "
                      f"inlined (set {GPU_CALLS_VARIABLE}=0 to choose this without the warning)", RuntimeWarning,
                      stacklevel=3)
        return
    original, calls = getattr(nvvm, name), engine_calls()

    def to_nvvm(llvmir, **options):
        modules = [llvmir] if isinstance(llvmir, str) else llvmir
        return original([keep_calls(m, calls) for m in dict.fromkeys(modules)], **options)

    setattr(nvvm, name, to_nvvm)


#: Where a run's final state ``(x1, x2, x1dot, x2dot, W)`` is in its workspace (row ``Y_STATE``).
FINAL_AT = Y_AT + 5 * Y_STATE


@functools.cache
def _kernel():
    """The CUDA kernel (compiled on first launch): thread ``i`` runs point ``i`` in row ``i`` of
    ``work``, and copies its final state to row ``i`` of ``final`` where ``final`` has one."""
    from .integrate.driver import run_point_into
    from .integrate.record import carve

    _device_min_max()
    _install_call_policy()

    @cuda.jit
    def points(code, batch, options, outputs, work, final):
        i = cuda.grid(1)
        if i < batch[0].shape[0]:
            ws = carve(work[i], batch[0].shape[1], outputs[1].shape[1], True)  # with Radau
            run_point_into(code, ws, batch, options, i, outputs)
            if i < final.shape[0]:
                for k in range(5):
                    final[i, k] = work[i, FINAL_AT + k]

    return points


def run_batch_cuda(code: int, batch: tuple, options: tuple, outputs: tuple, final_states=None) -> None:
    """Run every point of ``batch`` (the tuple ``integrate.driver.B_*``) on the GPU, one thread each, and fill
    ``outputs`` (the tuple ``integrate.driver.O_*``) as :func:`.integrate.driver.run_block` does; and
    ``final_states`` (n x 5, optional) with each run's state ``(x1, x2, x1dot, x2dot, W)`` at its end (row
    ``Y_STATE`` of its workspace, what :func:`.integrate.api.summary_run` returns). Call :func:`unavailable`
    first."""
    from numba import cuda

    n = batch[0].shape[0]
    # made on the device, never sent: a run sets every number of its workspace it reads, and every
    # output number its caller reads (tests/test_allocations.py runs the CPU in poisoned buffers);
    # a launch of 262144 points would otherwise send 1.5 GB of zeros and 0.24 GB of outputs
    work = cuda.device_array((n, workspace_size(batch[0].shape[1], outputs[1].shape[1])))
    device_batch = tuple(cuda.to_device(np.ascontiguousarray(a)) for a in batch)
    device_outputs = tuple(cuda.device_array_like(a) for a in outputs)
    final = cuda.device_array((0 if final_states is None else n, 5))  # 5 numbers a run back, not its workspace
    blocks = (n + THREADS_PER_BLOCK - 1) // THREADS_PER_BLOCK
    _kernel()[blocks, THREADS_PER_BLOCK](np.int64(code), device_batch, options, device_outputs, work, final)
    cuda.synchronize()
    for host, device in zip(outputs, device_outputs, strict=True):
        device.copy_to_host(host)
    if final_states is not None:
        final_states[...] = final.copy_to_host()
