r"""The contact laws' kernel forms: each form's force, its partial derivatives, its potential, its
force at rest (a Filippov form) and its memory branch (a law with memory), compiled with numba
and callable from Python too. A law of :data:`~phaseimpact.model.laws.REGISTRY` names its form
(:attr:`~phaseimpact.model.laws.LawEntry.form`); the kernels read the law's flags from its kernel
code (bits :data:`FILIPPOV`, :data:`UNILATERAL`, :data:`CLAMP`, :data:`MEMORY`). The right-hand
side, the Jacobian, the event functions and the energy ledger (:mod:`phaseimpact.model.rhs`) are
composed from them. How to add a form: the guide of :mod:`phaseimpact.model.laws` ("Adding a law";
its inlining rule holds here).

Examples
--------
Hertz's force ``K delta^(3/2)`` of ``abrate`` at ``delta = 10 um``, ``K = 1e10 N/m^1.5``:

>>> from phaseimpact.model import ContactLaw
>>> from phaseimpact.model.forms import contact_force
>>> print(f"{contact_force(ContactLaw('abrate').code, 1e-5, 0.0, 1, 1e10, 0.0, 1.5):.6g} N")
316.228 N

The engine's compiled cache is keyed on a digest of these sources: the next run recompiles.
"""

from __future__ import annotations

import math
import types as _types

from .._jit import kernel

__all__ = [
    "contact_force", "force_partials", "contact_potential", "stick_bound", "hertz_power", "is_filippov",
    "is_unilateral", "has_memory", "contact_gap", "dent_depth", "remember", "force_of", "partials_of", "potential_of",
    "STUCK", "PLAIN",
]

# A kernel code is an integer (the compiled loop reads no strings): its low bits are the law's
# flags, the next bits its form (which branch of the kernels computes the force) and, for a user
# law, the bits above FORM the address of its compiled function (phaseimpact.model.userlaw; a
# user-space address has at most 48 bits, so the code stays within int64).
FILIPPOV, UNILATERAL, CLAMP, MEMORY = 1, 2, 4, 8
FORM_SHIFT, FORM_BITS = 4, 4
FORM_MASK, ADDRESS_SHIFT = (1 << FORM_BITS) - 1, FORM_SHIFT + FORM_BITS
ELASTIC, HUNT_CROSSLEY, PAPER, KUWABARA_KONO, THORNTON = 0, 1, 2, 3, 4
NATIVE = FORM_MASK  # the last form: the shipped ones take 5, 6, ... below it
#: The forms the kernels below have a branch for, by name, with the memory slots each form's memory
#: branch keeps (:attr:`LawEntry.memory`). :func:`register` refuses a law of any other form, and
#: the kernels give NaN for one: a form without its own branch never computes another law's force.
FORMS = {ELASTIC: ("ELASTIC", 0), HUNT_CROSSLEY: ("HUNT_CROSSLEY", 0), PAPER: ("PAPER", 0),
         KUWABARA_KONO: ("KUWABARA_KONO", 0), THORNTON: ("THORNTON", 3), NATIVE: ("NATIVE", 0)}
# What a user law's compiled function returns (its first argument).
FORCE, D_DELTA, D_RATE, POTENTIAL = 0, 1, 2, 3
STUCK, PLAIN = 0, 2
#: The sign factor a Filippov law's force at rest is read with (its magnitude: the stick bound).
STUCK_SIGN = 1

# The packed coefficients of one run (:func:`phaseimpact.model.rhs.pack`): the model's parameters,
# the law's own coefficients (LAW_, N_LAW of them) and its memory (MEMORY_, N_MEMORY slots: what a
# law keeps over a run, e.g. Thornton's largest indentation; 0 at the start, updated only by
# :func:`remember`, in the run's own copy). Every law with memory keeps its residual indentation
# (its dent, 0 if it leaves none) in the last slot, DENT_: the contact events read it there
# (:func:`contact_gap`, :func:`dent_depth`). IMPEDANCE_, last (so that the slots before it keep their
# places): the infinite plate's point impedance, N s/m, 0 for every other target.
M1_, M2_, K_, KB_, KM_, DAMP_, ALPHA_, SPRINGS_, RIGID_, GUARD_ = range(10)
LAW_, N_LAW = 10, 2
MEMORY_, N_MEMORY = LAW_ + N_LAW, 3
DENT_ = MEMORY_ + N_MEMORY - 1
IMPEDANCE_ = MEMORY_ + N_MEMORY
N_COEF = IMPEDANCE_ + 1


def make_code(form: int, flags: int, address: int = 0) -> int:
    """The kernel code of a law of ``form`` with ``flags`` (and a user law's function ``address``)."""
    return (address << ADDRESS_SHIFT) | (form << FORM_SHIFT) | flags


@kernel(python=True, forceinline=True)
def hertz_power(ad, alpha):
    """``ad**alpha`` for ``ad >= 0``; Hertz's 3/2 as the cheaper ``ad*sqrt(ad)``."""
    return _hertz_power(ad, alpha, -1.0)


@kernel(forceinline=True)
def _hertz_power(ad, alpha, root):
    """:func:`hertz_power` with ``root``, ``sqrt(ad)`` where the caller has it (a regularised phase:
    ``|w|``, the same number: ``sqrt(w*w) == |w|`` in binary floating point), else -1: the square
    root is on the critical path of every stage of a step."""
    if alpha == 1.5:
        return ad * (root if root >= 0 else math.sqrt(ad))
    return ad**alpha


@kernel(forceinline=True)
def _root(ad, alpha):
    """``ad**(alpha - 1)`` for ``ad >= 0``; ``sqrt(ad)`` for Hertz's 3/2."""
    if alpha == 1.5:
        return math.sqrt(ad)
    return ad ** (alpha - 1.0)


@kernel
def _sign(x):
    return 1.0 if x > 0 else (-1.0 if x < 0 else 0.0)


@kernel(python=True, forceinline=True)
def is_filippov(code):
    """Whether the law's sign factor needs stick/slip modes (flag :data:`FILIPPOV`)."""
    return (code & FILIPPOV) != 0


@kernel(python=True, forceinline=True)
def is_unilateral(code):
    """Whether the law acts only while ``delta > 0`` (flag :data:`UNILATERAL`)."""
    return (code & UNILATERAL) != 0


class _NativeGlobals(dict):
    """Globals of :func:`_native`: its one outside name, the call of a user law's compiled
    function, is imported when numba first compiles it (it needs numba; the commands that
    integrate nothing never import numba)."""

    def __missing__(self, key):
        if key != "call_native":
            raise KeyError(key)
        from .native import call_native_compiled

        self[key] = call_native_compiled
        return call_native_compiled


def _native_py(address, which, delta, deltadot, mode, K, damping, alpha):
    return call_native(address, which, delta, deltadot, mode, K, damping, alpha)  # noqa: F821 (_NativeGlobals)


#: A user law's compiled function at ``address``: ``which`` of FORCE, D_DELTA, D_RATE, POTENTIAL.
#: (Callers pass ``int(WHICH)``: a bare constant is typed as a literal, one more compile each.)
_native = kernel(_types.FunctionType(
    _native_py.__code__, _NativeGlobals(__name__=__name__, __builtins__=__builtins__), "_native"))


@kernel
def _kuwabara_kono_force(code, delta, deltadot, K, damping, alpha):
    force = (K * delta + damping * deltadot) * _root(delta, alpha)
    return max(force, 0.0) if (code & CLAMP) != 0 else force


@kernel
def _kuwabara_kono_partials(code, delta, deltadot, K, damping, alpha, stiffness):
    ad = abs(delta)
    root = _root(ad, alpha)
    if (code & CLAMP) != 0 and K * ad + damping * deltadot <= 0:
        return 0.0, 0.0
    return K * stiffness + damping * deltadot * (alpha - 1.0) * root / ad, damping * root


@kernel
def _native_partials(code, delta, deltadot, mode, K, damping, alpha):
    address = code >> ADDRESS_SHIFT
    return (_native(address, int(D_DELTA), delta, deltadot, mode, K, damping, alpha),
            _native(address, int(D_RATE), delta, deltadot, mode, K, damping, alpha))


# The branches of the laws added after the first ones call out-of-line kernels (the inlining rule
# of the laws module's guide): one line per form here, each law's physics in its own kernel. The
# two dispatchers are inlined into the right-hand side (LLVM's heuristics called them: a call at
# every evaluation), their laws' kernels stay calls.
@kernel(python=True, forceinline=True)
def contact_force(code, delta, deltadot, mode, K, damping, alpha):
    """Contact force ``P`` (N, positive pushing the bodies apart) while slipping or free.

    ``mode`` is ignored except by ``paper`` (sign factor); the stuck force of ``paper`` is not a
    function of ``(delta, deltadot)`` and comes from :func:`phaseimpact.model.rhs.stick_force`.
    """
    return _contact_force(code, delta, -1.0, deltadot, mode, K, damping, alpha)


@kernel(forceinline=True)
def _contact_force(code, delta, root, deltadot, mode, K, damping, alpha):
    """:func:`contact_force` with ``root``, ``sqrt(|delta|)`` where the caller has it, else -1
    (:func:`_hertz_power`)."""
    unilateral = (code & UNILATERAL) != 0
    if unilateral and delta <= 0:
        return 0.0
    form = (code >> FORM_SHIFT) & FORM_MASK
    if form == ELASTIC:
        if unilateral:
            return K * _hertz_power(delta, alpha, root)
        return K * _hertz_power(abs(delta), alpha, root) * _sign(delta)
    if form == HUNT_CROSSLEY:
        force = (K + damping * deltadot) * _hertz_power(delta, alpha, root)
        return max(force, 0.0) if (code & CLAMP) != 0 else force
    if form == KUWABARA_KONO:
        return _kuwabara_kono_force(code, delta, deltadot, K, damping, alpha)
    if form == NATIVE:
        return _native(code >> ADDRESS_SHIFT, int(FORCE), delta, deltadot, mode, K, damping, alpha)
    if form == PAPER:  # eq. 8
        sign = _sign(deltadot) if mode == PLAIN else float(mode)
        return (K + damping * deltadot) * _hertz_power(abs(delta), alpha, root) * sign
    return math.nan  # a form without a branch here (register refuses it): never another law's force


@kernel(python=True, forceinline=True)
def force_partials(code, delta, deltadot, mode, K, damping, alpha):
    """``(dP/ddelta, dP/ddeltadot)`` of :func:`contact_force` (exact; zero where ``P`` is 0).

    At ``delta = 0`` the Hertz stiffness ``alpha K |delta|^(alpha-1)`` is exactly zero for
    ``alpha > 1``, which a finite difference would blur.
    """
    ad = abs(delta)
    stiffness = alpha * hertz_power(ad, alpha) / ad if ad > 0 else 0.0  # d|delta|^alpha / d|delta|
    if (code & UNILATERAL) != 0 and delta <= 0:
        return 0.0, 0.0
    form = (code >> FORM_SHIFT) & FORM_MASK
    if form == ELASTIC:
        return K * stiffness, 0.0
    if form == HUNT_CROSSLEY:
        if (code & CLAMP) != 0 and K + damping * deltadot <= 0:
            return 0.0, 0.0
        return (K + damping * deltadot) * stiffness, damping * hertz_power(ad, alpha)
    if form == KUWABARA_KONO:
        return _kuwabara_kono_partials(code, delta, deltadot, K, damping, alpha, stiffness)
    if form == NATIVE:
        return _native_partials(code, delta, deltadot, mode, K, damping, alpha)
    if form == PAPER:
        sign = _sign(deltadot) if mode == PLAIN else float(mode)
        return sign * (K + damping * deltadot) * stiffness * _sign(delta), sign * damping * hertz_power(ad, alpha)
    return math.nan, math.nan


@kernel(python=True)
def contact_potential(code, delta, K, alpha):
    """Potential of the elastic term, ``K |delta|^(alpha+1)/(alpha+1)`` (J), for the forms whose
    elastic term is ``K delta^alpha``; 0 for a Filippov law (``paper``), whose elastic term acts like
    friction; a user law's own potential (0 if it gives none); NaN for any other form (a law with
    memory: :func:`potential_of`)."""
    if (code & FILIPPOV) != 0:
        return 0.0
    if (code & UNILATERAL) != 0 and delta <= 0:
        return 0.0
    form = (code >> FORM_SHIFT) & FORM_MASK
    if form == NATIVE:
        return _native(code >> ADDRESS_SHIFT, int(POTENTIAL), delta, 0.0, int(PLAIN), K, 0.0, alpha)
    if form == ELASTIC or form == HUNT_CROSSLEY or form == KUWABARA_KONO:
        ad = abs(delta)
        return K * ad * hertz_power(ad, alpha) / (alpha + 1.0)
    return math.nan


@kernel(python=True, forceinline=True)
def has_memory(code):
    """Whether the law keeps state over a run (flag :data:`MEMORY`, set from :attr:`LawEntry.memory`)."""
    return (code & MEMORY) != 0


@kernel(python=True, forceinline=True)
def contact_gap(code, c, x1, x2):
    """How far the bodies at ``x1``, ``x2`` are from touching (m): the indentation ``x1 - x2``, or for
    a law with memory ``x1 - (x2 + delta_p)``, past the residual indentation ``delta_p`` of its dent:
    a projectile inside its plastic dent feels no force (the dent is state, not contact), so its
    contact starts and ends where the force does (0 before the first yield). Written as the
    separation places ``x1`` (``x2 + delta_p``, :func:`~phaseimpact.integrate.events.transition`) so
    that the gap there is exactly 0 and the next phase takes its side from ``deltadot``: as
    ``(x1 - x2) - delta_p`` its rounding left it +-1 ulp, and a restart just inside the force
    separated again at once, without end (issue 42)."""
    if has_memory(code):
        return x1 - (x2 + c[DENT_])
    return x1 - x2


@kernel(python=True, forceinline=True)
def dent_depth(code, c):
    """The residual indentation ``delta_p`` of a law with memory, m (0 for other laws, and before the
    first yield): where :func:`contact_gap` is zero."""
    return c[DENT_] if has_memory(code) else 0.0


@kernel
def _thornton_yield(c):
    """``(E*, delta_y, F_y)``: the contact modulus ``3 K / (4 sqrt(R))`` and the indentation and force
    where the Hertz peak pressure reaches the limiting pressure ``p_y`` (Thornton 1997, eq. 4-6)."""
    K, p_y, R = c[K_], c[LAW_], c[LAW_ + 1]
    e_star = 0.75 * K / math.sqrt(R)
    delta_y = R * (0.5 * math.pi * p_y / e_star) ** 2
    return e_star, delta_y, K * delta_y * math.sqrt(delta_y)


@kernel
def _thornton(c, delta):
    """Thornton's force and its stiffness dP/ddelta at ``delta > 0``: on the unloading curve
    below the largest indentation so far (memory), else Hertz loading up to ``delta_y`` and a
    linear rise at the limiting pressure beyond (``dP = pi p_y R ddelta``)."""
    if delta < c[MEMORY_]:
        depth = delta - c[DENT_]
        if depth <= 0:
            return 0.0, 0.0
        root = math.sqrt(depth)
        return c[MEMORY_ + 1] * depth * root, 1.5 * c[MEMORY_ + 1] * root
    _, delta_y, f_y = _thornton_yield(c)
    if delta <= delta_y:
        root = math.sqrt(delta)
        return c[K_] * delta * root, 1.5 * c[K_] * root
    slope = math.pi * c[LAW_] * c[LAW_ + 1]
    return f_y + slope * (delta - delta_y), slope


@kernel
def _thornton_remember(c, delta):
    """Thornton's memory update at an extremum ``delta``: a new largest indentation ``delta_max``
    fixes the unloading curve, Hertz with the radius ``R_p`` enlarged by the plastic flow,
    ``P = K_p (delta - delta_p)^(3/2)`` with ``K_p = 4/3 E* sqrt(R_p)``, through
    ``(delta_max, P_max)``: ``R_p = 4 E* a_p^3 / (3 P_max)``, ``a_p^2 = (2 P_max + F_y) / (2 pi p_y)``
    (Thornton 1997, eq. 11-13); ``delta_p`` is the residual indentation. Below ``delta_y`` it is
    Hertz itself (``K_p = K``, ``delta_p = 0``)."""
    if delta <= c[MEMORY_]:
        return False
    e_star, delta_y, f_y = _thornton_yield(c)
    c[MEMORY_] = delta
    if delta <= delta_y:
        c[MEMORY_ + 1] = c[K_]
        c[DENT_] = 0.0
        return True
    p_y = c[LAW_]
    f_max = f_y + math.pi * p_y * c[LAW_ + 1] * (delta - delta_y)
    a_p = math.sqrt((2.0 * f_max + f_y) / (2.0 * math.pi * p_y))
    k_p = 4.0 / 3.0 * e_star * math.sqrt(4.0 * e_star * a_p**3 / (3.0 * f_max))
    c[MEMORY_ + 1] = k_p
    c[DENT_] = delta - (f_max / k_p) ** (2.0 / 3.0)
    return True


@kernel(python=True)
def remember(code, c, delta):
    """A law's memory update at an extremum ``delta`` of the indentation (event ``REVERSAL``), in
    the run's own coefficients ``c``; True if the memory changed (the run then restarts there, on
    the law's new branch). False for a law without memory (or a form without a memory branch,
    whose force is NaN: :func:`force_of`)."""
    if not has_memory(code):
        return False
    if (code >> FORM_SHIFT) & FORM_MASK == THORNTON:
        return _thornton_remember(c, delta)
    return False


@kernel(python=True, forceinline=True)
def force_of(code, c, delta, deltadot, mode):
    """The contact force of a run with packed coefficients ``c`` (what the engine calls): the
    law's :func:`contact_force`, or a law with memory read from ``c`` (its form's memory branch;
    NaN for a form without one)."""
    return force_of_root(code, c, delta, -1.0, deltadot, mode)


@kernel(forceinline=True)
def force_of_root(code, c, delta, root, deltadot, mode):
    """:func:`force_of` given ``root = sqrt(|delta|)`` (-1 where the caller does not have it): a
    regularised phase's ``|w|`` saves the Hertz term its square root."""
    if has_memory(code):
        if (code >> FORM_SHIFT) & FORM_MASK == THORNTON:
            return _thornton(c, delta)[0] if delta > 0 else 0.0
        return math.nan
    return _contact_force(code, delta, root, deltadot, mode, c[K_], c[DAMP_], c[ALPHA_])


@kernel(python=True, forceinline=True)
def partials_of(code, c, delta, deltadot, mode):
    """``(dP/ddelta, dP/ddeltadot)`` of :func:`force_of`."""
    if has_memory(code):
        if (code >> FORM_SHIFT) & FORM_MASK == THORNTON:
            return (_thornton(c, delta)[1] if delta > 0 else 0.0), 0.0
        return math.nan, math.nan
    return force_partials(code, delta, deltadot, mode, c[K_], c[DAMP_], c[ALPHA_])


@kernel(python=True)
def potential_of(code, c, delta):
    """:func:`contact_potential` of a run (0 for a law with memory: its elastic energy depends on
    the path, and its whole contact work counts in the ledger)."""
    if has_memory(code):
        return 0.0
    return contact_potential(code, delta, c[K_], c[ALPHA_])


@kernel(python=True, forceinline=True)  # read at every step of a stick (the stick-break event)
def stick_bound(code, delta, K, damping, alpha):
    """The largest force a stuck Filippov contact gives at ``delta`` (N): ``|P(delta, 0)|``, the
    law's force at rest (``paper``: its elastic term ``K |delta|^alpha``). The stick holds while
    the force that keeps the bodies together stays within it (docs/physics.md §5); NaN for a form
    that is not Filippov."""
    if (code & UNILATERAL) != 0 and delta <= 0:
        return 0.0
    form = (code >> FORM_SHIFT) & FORM_MASK
    if form == NATIVE:
        return abs(_native(code >> ADDRESS_SHIFT, int(FORCE), delta, 0.0, int(STUCK_SIGN), K, damping, alpha))
    if form == PAPER:
        return K * hertz_power(abs(delta), alpha)
    return math.nan

