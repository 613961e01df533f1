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
"""

from __future__ import annotations

import functools

import numba

__all__ = ["kernel", "allocating"]

#: ``@kernel`` or ``@kernel(inline="always")``: a compiled helper that allocates nothing.
kernel = functools.partial(numba.njit, cache=True, _nrt=False)
#: ``@allocating`` or ``@allocating(nogil=True)``: a compiled function that creates arrays.
allocating = functools.partial(numba.njit, cache=True, _nrt=True)
