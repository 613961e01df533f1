"""How the engine is compiled (numba): the two decorators every compiled function uses.

``kernel`` is for the helpers that never allocate: the law, the right-hand sides, the steppers,
the event functions, the driver's inner loop. They only read and write arrays their caller owns,
so they are compiled without numba's reference counting (NRT). With it, every array argument is
incref'd and decref'd at every call, each a call into the runtime with an atomic update: that was
30 of the 38 ns of one right-hand side and more than half the time of a trajectory (a
Hunt-Crossley run 97 -> 41 us, a stiff atlas point 174 -> 65 us, results unchanged). Numba refuses
to compile an allocation in such a function (and in every function it calls that does not say
otherwise), so the flag cannot hide a leak. It does let a kernel return an array it was given, and
that must never happen: the reference-counted caller would release a reference the kernel never
took and free the array under its owner. Kernels return scalars and tuples of scalars only
(``tests/test_integrate.py`` checks every compiled overload).

``allocating`` is for the few functions that create arrays (the run loops and their growing
buffers, the Radau workspace): reference counted, as numba does by default. Both cache the
machine code on disk (``cache=True``): the first-ever call compiles, later processes load.

Both compile a function for calls from compiled code only, unless it says ``python=True``: numba
otherwise wraps every compiled function for calls from Python too (unboxing each argument, boxing
the result), and generating and optimising a wrapper for each of the engine's ~80 compiled
functions took about 1.5 s of the first-ever compile (one process: 26.6 -> 25.2 s, medians of 3
cold runs; numba's C-callable wrappers, never used here, are off for all). A function without the
wrapper must never be called from Python: numba does not check, the call crashes. So every
function Python code calls (the entries ``run`` and ``run_block``, what a module lists in
``__all__``, what the oracle and the tests call) says ``python=True``, and
``tests/test_integrate.py`` finds every call from Python in the package, tests, benchmarks and
studies and checks that its target has the wrapper.
"""

from __future__ import annotations

import numba

__all__ = ["kernel", "allocating"]


def _compiler(reference_counted: bool):
    def decorate(function=None, *, python: bool = False, inline: str = "never", nogil: bool = False):
        compile_ = numba.njit(cache=True, _nrt=reference_counted, inline=inline, nogil=nogil,
                              no_cpython_wrapper=not python, no_cfunc_wrapper=True)
        return compile_ if function is None else compile_(function)
    return decorate


#: ``@kernel``, ``@kernel(inline="always")``, ``@kernel(python=True)``: a compiled helper that
#: allocates nothing.
kernel = _compiler(reference_counted=False)
#: ``@allocating``, ``@allocating(python=True, nogil=True)``: a compiled function that creates arrays.
allocating = _compiler(reference_counted=True)
