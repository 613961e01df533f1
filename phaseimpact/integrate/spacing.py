"""The gap from a float to the next one up, in plain arithmetic: ``np.nextafter`` has no CUDA
device version, and the step-size floors of the steppers need this gap on both targets."""

from __future__ import annotations

import math

from .._jit import kernel

__all__ = ["ulp_above"]

#: The smallest subnormal double, the gap between any two subnormals.
_SMALLEST = 5e-324


@kernel(forceinline=True, python=True)
def ulp_above(s):
    """``np.nextafter(s, inf) - s`` for a finite ``s``, bit for bit (``tests/test_cuda.py``)."""
    if s == 0.0:  # frexp gives no exponent for zero
        return _SMALLEST
    mantissa, exponent = math.frexp(s)
    if mantissa == -0.5:  # a negative power of two: the next number up has the finer spacing below it
        exponent -= 1
    return max(math.ldexp(1.0, exponent - 53), _SMALLEST)
