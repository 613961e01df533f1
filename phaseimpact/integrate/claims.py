"""Tasks shared by the threads of a chunk, claimed in compiled code: one counter that every thread
advances atomically (:func:`claim`), so that a thread takes its next task without the GIL, without
Python between two tasks and without a lock.

numba has no atomic operation for the CPU; :func:`claim` is LLVM's ``atomicrmw add`` on an element
of an int64 array (an intrinsic, through numba's public ``numba.extending.intrinsic``: no address
in the machine code, so the disk cache stays valid). Uncompiled (``NUMBA_DISABLE_JIT=1``) a lock
stands in for it.
"""

from __future__ import annotations

import threading

from llvmlite import ir
from numba import types
from numba.core import cgutils, config
from numba.extending import intrinsic

__all__ = ["claim"]


@intrinsic
def claim(typingctx, counter, count):
    """Compiled code only: ``counter[0] += count`` in one atomic step; the value before. ``count`` 1
    claims the next task; a count of at least the number of tasks claims all those left (the value
    before is the first of them) and leaves none for the other threads."""
    if not (isinstance(counter, types.Array) and counter.dtype == types.int64 and counter.ndim == 1
            and isinstance(count, types.Integer)):
        return None

    def codegen(context, builder, sig, args):
        array = context.make_array(sig.args[0])(context, builder, args[0])
        first = cgutils.get_item_pointer(context, builder, sig.args[0], array, [ir.Constant(ir.IntType(64), 0)])
        amount = context.cast(builder, args[1], sig.args[1], types.int64)
        return builder.atomic_rmw("add", first, amount, "seq_cst")

    return types.int64(counter, count), codegen


if config.DISABLE_JIT:
    _lock = threading.Lock()

    def claim(counter, count):  # noqa: F811  uncompiled: threads hold the GIL between bytecodes, not across these
        with _lock:
            before = int(counter[0])
            counter[0] = before + count
        return before
