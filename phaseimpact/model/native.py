"""The call of a user law's compiled function from the engine's kernels (numba; imported when
the engine is first compiled, see :class:`phaseimpact.model.laws._NativeGlobals`).

A user law (:mod:`.userlaw`) is compiled on its own as a C-callable function
``f(which, delta, deltadot, mode, K, damping, alpha) -> float``; its address travels in the law's
kernel code (:attr:`phaseimpact.model.laws.ContactLaw.code`), and :func:`call_native` calls it
through that address. The engine itself is compiled once, whatever laws a user brings: its
machine code holds an indirect call, not the law.
"""

from __future__ import annotations

import ctypes

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

__all__ = ["call_native", "call_native_compiled", "SIGNATURE", "CTYPES_SIGNATURE", "slot_load", "slot_store"]

#: The C signature of a user law's compiled function.
SIGNATURE = types.float64(types.int64, types.float64, types.float64, types.int64, types.float64, types.float64,
                          types.float64)
CTYPES_SIGNATURE = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_int64, ctypes.c_double, ctypes.c_double,
                                    ctypes.c_int64, ctypes.c_double, ctypes.c_double, ctypes.c_double)


def call_native(address, which, delta, deltadot, mode, K, damping, alpha):
    """``which`` of the user law at ``address`` (from Python: through ctypes)."""
    return CTYPES_SIGNATURE(int(address))(int(which), float(delta), float(deltadot), int(mode), float(K),
                                          float(damping), float(alpha))


@intrinsic
def _call(typingctx, address, which, delta, deltadot, mode, K, damping, alpha):
    signature = types.float64(types.int64, *SIGNATURE.args)

    def codegen(context, builder, sig, args):
        function_type = ir.FunctionType(ir.DoubleType(), [ir.IntType(64), ir.DoubleType(), ir.DoubleType(),
                                                          ir.IntType(64), ir.DoubleType(), ir.DoubleType(),
                                                          ir.DoubleType()])
        pointer = builder.inttoptr(args[0], function_type.as_pointer())
        return builder.call(pointer, args[1:])

    return signature, codegen


@njit
def call_native_compiled(address, which, delta, deltadot, mode, K, damping, alpha):
    """:func:`call_native` in compiled code: an indirect call through ``address``."""
    return _call(np.int64(address), np.int64(which), np.float64(delta), np.float64(deltadot), np.int64(mode),
                 np.float64(K), np.float64(damping), np.float64(alpha))


@intrinsic
def slot_load(typingctx, address, index):
    """Compiled code only: the float64 at ``address`` + ``index`` (a user law's fault record,
    :class:`phaseimpact.model.userlaw.NativeLaw`)."""
    def codegen(context, builder, sig, args):
        pointer = builder.inttoptr(args[0], ir.DoubleType().as_pointer())
        return builder.load(builder.gep(pointer, [args[1]]))

    return types.float64(types.int64, types.int64), codegen


@intrinsic
def slot_store(typingctx, address, index, value):
    """Compiled code only: store ``value`` as the float64 at ``address`` + ``index``."""
    def codegen(context, builder, sig, args):
        pointer = builder.inttoptr(args[0], ir.DoubleType().as_pointer())
        builder.store(args[2], builder.gep(pointer, [args[1]]))
        return context.get_dummy_value()

    return types.void(types.int64, types.int64, types.float64), codegen
