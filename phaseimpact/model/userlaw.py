r"""Your own contact law from Python: :func:`define_law`.

A user law is plain Python: a force function ``force(delta, deltadot, K, damping, alpha)``
(N; ``delta`` m, ``deltadot`` m/s, ``K`` the contact stiffness, ``damping`` the coefficient set
with ``kappa``, ``alpha`` the exponent), and optionally its partial derivatives
``partials(...) -> (dP/ddelta, dP/ddeltadot)`` and the potential of its elastic term
``potential(delta, K, alpha)`` (J). numba compiles them into one C-callable function (about a
second); the engine calls it through its address, carried in the law's kernel code
(:mod:`phaseimpact.model.native`), so the engine itself is not recompiled for a new law.

Example (the Kuwabara-Kono law written by hand)::

    import math
    import phaseimpact

    def force(delta, deltadot, K, gamma, alpha):
        return (K * delta + gamma * deltadot) * math.sqrt(delta)

    phaseimpact.define_law("my-kk", force, damping=("gamma", "N s m-1.5"), damping_power=1.5)
    phaseimpact.simulate(phaseimpact.seed_parameters(kappa=1e5), "my-kk")

A unilateral law (the default) acts only while ``delta > 0``: the engine never calls its force
at ``delta <= 0`` (:func:`define_law` checks that the function gives 0 there anyway when asked
with ``delta = 0``).

A Filippov law (``filippov=True``, like ``paper``, eq. 8) gives the force's magnitude
``g(delta, deltadot)``; the engine multiplies it by the sign factor ``sgn(deltadot)`` (the slip's
direction, and the stick/slip modes of docs/physics.md §5) and sticks while the force that keeps
the bodies together stays within ``|g(delta, 0)|``. ``paper`` itself, as a user law::

    def force(delta, deltadot, K, kappa, alpha):
        return (K + kappa * deltadot) * abs(delta) ** alpha

    phaseimpact.define_law("my-paper", force, filippov=True, unilateral=False)
"""

from __future__ import annotations

import contextlib
import hashlib
import inspect
import math
import os
import re
import stat
import sys
import types
from dataclasses import dataclass, field

from .forms import (
    D_DELTA,
    D_RATE,
    FORCE,
    NATIVE,
    PLAIN,
    POTENTIAL,
)
from .laws import (
    GUARD_ENERGY_FACTOR,
    LAWS,
    REGISTRY,
    RUNAWAY_ENERGY_FACTOR,
    LawEntry,
    register,
)

__all__ = ["define_law", "load_law_file", "UserLawError"]

_ARGUMENTS = {"force": 5, "partials": 5, "potential": 3}
_SAMPLES = ((1e-6, 0.5), (1e-5, -0.3), (2e-5, 1.0), (1e-7, 0.0))  # (delta, deltadot), seed-like scales

# A user law's fault record (NativeLaw.record), written by its compiled function: the first call
# that raised or gave a non-finite value (its kind and arguments), whether a signal stopped the
# law, and a count of calls between two looks for a signal.
(REC_FAULT, REC_WHICH, REC_DELTA, REC_DELTADOT, REC_MODE, REC_K, REC_DAMPING, REC_ALPHA, REC_STOP,
 REC_CALLS, REC_VALUE) = range(11)
N_RECORD = 11
NO_FAULT, RAISED, NOT_A_NUMBER, INFINITE, BEYOND_RANGE = 0, 1, 2, 3, 4
#: The largest force magnitude a user law may return, N: far above any physical contact force, and
#: far below the float range that a force times masses, steps and tolerances must stay in (a force of
#: 1e300 N is finite, but the run's step size collapsed on it with no word of the law).
FORCE_LIMIT = 1e100
#: Calls of a user law between two looks for Ctrl-C or SIGTERM (a ``poll``, about 0.3 us): a law
#: whose every call is slow still stops within a fraction of a second.
POLL_CALLS = 64
_FUNCTION_NAMES = {FORCE: "force", D_DELTA: "partials", D_RATE: "partials", POTENTIAL: "potential"}
_ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


class UserLawError(ValueError):
    """A user law that the engine cannot run (wrong signature, NaN force, ...): the message says
    what to fix.

    A :class:`ValueError`: code that catches bad input in general catches it too.

    Examples
    --------
    >>> from phaseimpact import define_law
    >>> from phaseimpact.model.userlaw import UserLawError
    >>> try:
    ...     define_law("example-bad", lambda delta: delta)
    ... except UserLawError as exc:
    ...     print(exc)
    force <lambda>(delta) has the wrong signature; allowed: force(delta, deltadot, K, damping, alpha)
    >>> issubclass(UserLawError, ValueError)
    True
    """


@dataclass(frozen=True)
class NativeLaw:
    """A user law's compiled function (kept alive here: the engine calls its address).

    ``identity``: a digest of its source (the functions', the values of the globals they read, and
    the bytes of the law file that defined it), recorded in every archive of its work.
    ``path``: that law file, or None. ``definition``: the arguments of :func:`define_law`, for a
    worker process that has to define the law again. ``record``: the fault record its compiled
    function writes (``REC_*``).
    """

    address: int
    cfunc: object
    identity: str
    functions: dict
    record: object = field(repr=False)
    path: str | None = None
    definition: dict = field(default_factory=dict, repr=False)

    def reset(self) -> None:
        """Clear the record before a run."""
        self.record[:] = 0.0

    @property
    def stopped(self) -> bool:
        """A signal (Ctrl-C, SIGTERM) arrived while the law ran: it returned NaN from then on."""
        return self.record[REC_STOP] != 0.0

    @property
    def faulted(self) -> bool:
        """A call raised or gave a non-finite value since the last :meth:`reset`."""
        return self.record[REC_FAULT] != NO_FAULT

    def fault(self, name: str) -> str:
        """One line on the recorded fault: the law, the function, what it did and where."""
        r = self.record
        which = int(r[REC_WHICH])
        delta, deltadot, K, damping, alpha = (float(r[i]) for i in (REC_DELTA, REC_DELTADOT, REC_K, REC_DAMPING,
                                                                     REC_ALPHA))
        label = _FUNCTION_NAMES.get(which, "force")
        kind = int(r[REC_FAULT])
        if kind == RAISED:
            what = "raised an exception"
            function = self.functions.get(label) or self.functions["force"]
            args = (delta, K, alpha) if label == "potential" else (delta, deltadot, K, damping, alpha)
            try:  # the same call in Python names the exception (numba's except clause cannot)
                function(*args)
            except Exception as exc:  # noqa: BLE001 (the user's code: report whatever it raised)
                what = f"raised {type(exc).__name__}" + (f" ({exc})" if str(exc) else "")
        elif kind == BEYOND_RANGE:
            what = f"returned {float(r[REC_VALUE]):.6g} N, beyond the finite physical range |P| <= {FORCE_LIMIT:g} N,"
        else:
            what = "returned nan" if kind == NOT_A_NUMBER else "returned an infinity"
        return f"law {name!r}: its {label} {what} at delta = {delta:.6g} m (deltadot = {deltadot:.6g} m/s)"

    def recipe(self, name: str) -> DefinedWhereUnpickled:
        """What a worker process needs to define the law again (:func:`ensure_defined`): an object
        whose unpickling defines it there, before the :class:`ContactLaw` carrying it is restored."""
        if self.path is not None:
            return DefinedWhereUnpickled(("file", name, self.path, self.identity))
        return DefinedWhereUnpickled(("python", name, self.definition, self.identity))


class DefinedWhereUnpickled:
    """A user law's recipe that defines the law in the process that unpickles it (its
    ``__reduce__`` calls :func:`ensure_defined`), so that the law table never imports this module."""

    def __init__(self, recipe: tuple):
        self.recipe = recipe

    def __reduce__(self):
        return (_define_and_keep, (self.recipe,))


def _define_and_keep(recipe: tuple) -> DefinedWhereUnpickled:
    ensure_defined(recipe)
    return DefinedWhereUnpickled(recipe)


def _check_signature(name: str, function) -> None:
    if function is None:
        return
    if not (inspect.isfunction(function) or inspect.isfunction(getattr(function, "py_func", None))):
        # numba compiles functions only: a class, a callable object or a builtin would fail in numba
        kind = "a callable object" if callable(function) else "not a function"
        raise UserLawError(f"{name} = {function!r} is {kind}; allowed: a Python function (def or lambda) of "
                           f"{_ARGUMENTS[name]} numbers")
    try:
        parameters = inspect.signature(function).parameters.values()
    except (TypeError, ValueError):
        raise UserLawError(f"{name} = {function!r} has no readable signature; allowed: a plain Python "
                           "function") from None
    positional = [p for p in parameters if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    required = [p for p in positional if p.default is p.empty]
    if any(p.kind == p.VAR_POSITIONAL for p in parameters):
        return
    wanted = _ARGUMENTS[name]
    if not (len(required) <= wanted <= len(positional)):
        args = "(delta, deltadot, K, damping, alpha)" if wanted == 5 else "(delta, K, alpha)"
        raise UserLawError(f"{name} {getattr(function, '__name__', '')}{inspect.signature(function)} has the wrong "
                           f"signature; allowed: {name}{args}")


def _python_value(name, function, args):
    try:
        value = function(*args)
    except Exception as exc:  # noqa: BLE001 (the user's code: report whatever it raised)
        raise UserLawError(f"{name}{args} raised {type(exc).__name__}: {exc}") from None
    values = value if name == "partials" else (value,)
    if name == "partials" and not (isinstance(value, tuple) and len(value) == 2):
        raise UserLawError(f"partials{args} returned {value!r}; allowed: a tuple (dP/ddelta, dP/ddeltadot)")
    for v in values:
        try:
            f = float(v)
        except (TypeError, ValueError):
            raise UserLawError(f"{name}{args} returned {value!r}; allowed: a float") from None
        if not math.isfinite(f):
            raise UserLawError(f"{name}{args} returned {value!r}: the {name} must be finite for delta > 0 "
                               "(a NaN or an infinity would stop every run)")
    return value


def _validate(name, force, partials, potential, unilateral, K, damping, alpha):
    for label, function in (("force", force), ("partials", partials), ("potential", potential)):
        _check_signature(label, function)
    for delta, deltadot in _SAMPLES:
        args = (delta, deltadot, K, damping, alpha)
        _python_value("force", force, args)
        if partials is not None:
            _python_value("partials", partials, args)
        if potential is not None:
            _python_value("potential", potential, (delta, K, alpha))
    if unilateral:
        at_zero = float(force(0.0, -0.5, K, damping, alpha))
        if at_zero != 0.0:
            raise UserLawError(f"law {name!r}: force(0, -0.5, ...) = {at_zero!r}, not 0: a unilateral law's force "
                               "must vanish at the separation delta = 0 (pass unilateral=False for a law that also "
                               "acts in tension)")


def _source_digest(*functions, file_digest: str = "") -> str:
    """A digest of what numba compiles: each function's source, the values of the constants it
    reads from globals or a closure (numba freezes them) and the functions it calls, and the
    bytes of the law file (``file_digest``) that defined them."""
    digest = hashlib.sha256(file_digest.encode())
    seen = set()

    def add(f):
        f = getattr(f, "py_func", f)  # a numba dispatcher: its Python function
        if id(f) in seen or not inspect.isfunction(f):
            return
        seen.add(id(f))
        try:
            digest.update(inspect.getsource(f).encode())
        except (OSError, TypeError):
            digest.update(f.__code__.co_code + repr(f.__code__.co_consts).encode())
        cells = zip(f.__code__.co_freevars, (c.cell_contents for c in f.__closure__ or ()), strict=False)
        read = [(n, f.__globals__[n]) for n in f.__code__.co_names if n in f.__globals__]
        for name, value in (*cells, *read):
            if isinstance(value, (bool, int, float, complex, str, bytes, tuple)):
                digest.update(f"{name}={value!r};".encode())
            else:
                add(value)

    for f in functions:
        if f is None:
            digest.update(b"-")
        else:
            add(f)
    return digest.hexdigest()[:16]


def _compile(force, partials, potential, filippov, record) -> tuple:
    """One C-callable function ``(which, delta, deltadot, mode, K, damping, alpha)`` for the law
    (a Filippov law's: with the sign factor of ``mode``, as ``paper``'s kernel); returns it and
    its address.

    The user's code runs inside a ``try``: an exception, or a NaN or an infinity, is written to
    ``record`` (the first one) and the call returns NaN, which fails the run (the engine cannot
    step over it); the caller names the fault (:meth:`NativeLaw.fault`). Without it numba printed
    a traceback for every call and the run went on with a force of 0. Every :data:`POLL_CALLS`
    calls the function looks for Ctrl-C or SIGTERM (a slow law's calls fill seconds between two
    looks of the engine); once one arrived, it returns NaN without calling the user's code, so
    that the run ends at once and Python raises the signal's ``KeyboardInterrupt``.
    """
    import numba

    from .._signals import interrupted
    from .native import SIGNATURE, slot_load, slot_store

    try:
        f = numba.njit(force)
        dp = numba.njit(partials) if partials is not None else None
        pot = numba.njit(potential) if potential is not None else None
        has_partials, has_potential = dp is not None, pot is not None

        @numba.njit
        def unsigned(which, delta, deltadot, K, damping, alpha):
            if which == 0:
                return f(delta, deltadot, K, damping, alpha)
            if which == 3:
                return pot(delta, K, alpha) if has_potential else 0.0
            if has_partials:
                pair = dp(delta, deltadot, K, damping, alpha)
                return pair[0] if which == 1 else pair[1]
            # central differences (a law without partials)
            if which == 1:
                h = 1e-6 * abs(delta) + 1e-15
                return (f(delta + h, deltadot, K, damping, alpha) - f(delta - h, deltadot, K, damping, alpha)) / (2 * h)
            h = 1e-6 * abs(deltadot) + 1e-12
            return (f(delta, deltadot + h, K, damping, alpha) - f(delta, deltadot - h, K, damping, alpha)) / (2 * h)

        plain = PLAIN
        at = record.ctypes.data  # the record's address: kept alive by the NativeLaw

        def law(which, delta, deltadot, mode, K, damping, alpha):
            calls = slot_load(at, REC_CALLS) + 1.0
            if calls >= POLL_CALLS:
                calls = 0.0
                if interrupted():
                    slot_store(at, REC_STOP, 1.0)
            slot_store(at, REC_CALLS, calls)
            if slot_load(at, REC_STOP) != 0.0:
                return math.nan
            fault = NO_FAULT
            try:
                value = float(unsigned(which, delta, deltadot, K, damping, alpha))
            except Exception:  # noqa: BLE001 (the user's code: whatever it raised ends the run)
                value = math.nan
                fault = RAISED
            if fault == NO_FAULT and not math.isfinite(value):
                fault = NOT_A_NUMBER if math.isnan(value) else INFINITE
            elif fault == NO_FAULT and which == 0 and abs(value) > FORCE_LIMIT:
                fault = BEYOND_RANGE
            if fault != NO_FAULT:
                if slot_load(at, REC_FAULT) == NO_FAULT:
                    slot_store(at, REC_WHICH, float(which))
                    slot_store(at, REC_DELTA, delta)
                    slot_store(at, REC_DELTADOT, deltadot)
                    slot_store(at, REC_MODE, float(mode))
                    slot_store(at, REC_K, K)
                    slot_store(at, REC_DAMPING, damping)
                    slot_store(at, REC_ALPHA, alpha)
                    slot_store(at, REC_VALUE, value)
                    slot_store(at, REC_FAULT, float(fault))
                return math.nan
            if not filippov or which == 3:
                return value
            if mode == plain:  # the sign read literally (fixed-step methods)
                return value if deltadot > 0 else (-value if deltadot < 0 else 0.0)
            return value * mode  # +-1 slipping, 0 stuck (the stuck force is not the law's)

        if not has_partials:
            dp = f  # typed but never called
        if not has_potential:
            pot = f
        compiled = numba.cfunc(SIGNATURE)(law)
    except numba.core.errors.NumbaError as exc:
        first = _ANSI.sub("", str(exc)).strip().splitlines()
        detail = next((line for line in first if "rror" in line or "Untyped" in line or "Unknown" in line),
                      first[0] if first else "")
        raise UserLawError("numba cannot compile the law's functions (plain arithmetic and the math module "
                           f"compile; Python objects do not): {detail.strip()}") from None
    return compiled, compiled.address


def define_law(name: str, force, *, partials=None, potential=None, unilateral: bool = True,
               filippov: bool = False, damping=("kappa", None), damping_power=None, clamp_option: bool = False,
               description: str = "") -> LawEntry:
    """Register a contact law of your own; it then runs wherever a shipped law does.

    Parameters
    ----------
    name : str
        The law's name (``simulate(params, name)``, ``--law name``); not a shipped law's.
    force : function ``(delta, deltadot, K, damping, alpha) -> float``
        The contact force P (N, positive pushing the bodies apart); of a Filippov law, its
        magnitude (the engine applies the sign factor). Plain arithmetic and :mod:`math`: numba
        compiles it.
    partials : function ``(delta, deltadot, K, damping, alpha) -> (float, float)``, optional
        ``(dP/ddelta, dP/ddeltadot)``; default: central differences of ``force``.
    potential : function ``(delta, K, alpha) -> float``, optional
        Potential of the elastic term (J), for the energy ledger; default: none (the law is then
        not conservative: its whole contact work counts as dissipated).
    unilateral : bool
        The law acts only while ``delta > 0`` (its force must be 0 at ``delta = 0``).
    filippov : bool
        The force is ``force(...) sgn(deltadot)``, with stick and slip (like ``paper``): the
        stick holds while the force that keeps the bodies together is within
        ``|force(delta, 0, ...)|``. Such a law has no potential.
    damping : (str, str or None)
        The damping coefficient's symbol and unit (set with ``kappa``); the unit defaults to
        ``N s/m^damping_power``.
    damping_power : float or None
        The damping coefficient is in N s/m^damping_power; default ``1 + alpha``.
    clamp_option : bool
        Whether ``clamp=True`` is allowed (not implemented for user laws: the force function
        clamps itself).
    description : str
        One line for ``phaseimpact laws`` and archives; default: the force function's module
        and name.

    Returns
    -------
    LawEntry
        The registered entry (:data:`~phaseimpact.model.laws.REGISTRY`), of form ``NATIVE`` with
        the compiled function; a law defined again under the same name replaces the earlier one.

    Raises
    ------
    UserLawError
        For a name that is empty, has spaces or is a shipped law's; ``clamp_option=True``; a
        ``damping``, ``damping_power`` or ``filippov`` out of range; a ``potential`` with
        ``filippov=True``; a function with the wrong signature, or one that raises or gives a
        non-finite or non-number value at sample points in contact; a unilateral law whose force
        is not 0 at ``delta = 0``; functions numba cannot compile. Nothing is registered then.

    Examples
    --------
    The Kuwabara-Kono law written by hand runs as the shipped one does (the law is removed
    again at the end, as this is only an example):

    >>> import math
    >>> from phaseimpact import define_law, seed_parameters, simulate
    >>> from phaseimpact.model import REGISTRY
    >>> def force(delta, deltadot, K, gamma, alpha):
    ...     return (K * delta + gamma * deltadot) * math.sqrt(delta)
    >>> entry = define_law("example-kk", force, damping=("gamma", None), damping_power=1.5)
    >>> entry.name, entry.damping_unit(1.5), entry.conservative
    ('example-kk', 'N s/m^1.5', False)
    >>> for name in ("example-kk", "kuwabara-kono"):
    ...     tr = simulate(seed_parameters(v=1.0, kappa=1e5), name)
    ...     print(f"{name}: {tr.outcome}, {tr.max_force:.4g} N, e = {tr.restitution:.3f}")
    example-kk: rebound, 4452 N, e = 0.806
    kuwabara-kono: rebound, 4452 N, e = 0.806
    >>> del REGISTRY["example-kk"]
    >>> define_law("paper", force)
    Traceback (most recent call last):
        ...
    phaseimpact.model.userlaw.UserLawError: name = 'paper' is a shipped law's; allowed: a new name
    """
    definition = {"force": force, "partials": partials, "potential": potential, "unilateral": unilateral,
                  "filippov": filippov, "damping": damping, "damping_power": damping_power,
                  "clamp_option": clamp_option, "description": description}
    return _define(name, definition)


# The law file being run (load_law_file): (path, digest of its bytes), read by define_law.
_LOADING: list[tuple[str, str]] = []


def _define(name: str, definition: dict, identity: str | None = None) -> LawEntry:
    """:func:`define_law` with its arguments as a dict; ``identity``: the source digest a worker
    process is told (it may not see the functions' source), else computed here."""
    force, partials, potential = definition["force"], definition["partials"], definition["potential"]
    unilateral, filippov, damping = definition["unilateral"], definition["filippov"], definition["damping"]
    damping_power, description = definition["damping_power"], definition["description"]
    if not isinstance(name, str) or not name or any(ch.isspace() for ch in name):
        raise UserLawError(f"name = {name!r} is out of range; allowed: a non-empty name without spaces")
    if name in LAWS:
        raise UserLawError(f"name = {name!r} is a shipped law's; allowed: a new name")
    if definition["clamp_option"]:
        raise UserLawError("clamp_option = True is not available for user laws: write max(P, 0) in the force")
    if not (isinstance(damping, tuple) and len(damping) == 2 and isinstance(damping[0], str)):
        raise UserLawError(f"damping = {damping!r} is out of range; allowed: (symbol, unit or None)")
    if damping_power is not None and not (isinstance(damping_power, (int, float)) and math.isfinite(damping_power)):
        raise UserLawError(f"damping_power = {damping_power!r} is out of range; allowed: a finite number or None")
    for label, flag in (("unilateral", unilateral), ("filippov", filippov)):
        if not isinstance(flag, bool):
            raise UserLawError(f"{label} = {flag!r} is out of range; allowed: True or False")
    if not isinstance(description, str) or "\n" in description or "\r" in description:
        raise UserLawError(f"description = {description!r} is out of range; allowed: one line of text")
    if filippov and potential is not None:
        raise UserLawError("potential is not allowed with filippov = True: the elastic term of a Filippov law "
                           "acts like friction (docs/physics.md §4), it has no potential")
    _validate(name, force, partials, potential, unilateral, 1e9, 1e5, 1.5)
    import numpy as np

    path, file_digest = _LOADING[-1] if _LOADING else (None, "")
    record = np.zeros(N_RECORD)
    compiled, address = _compile(force, partials, potential, filippov, record)
    native = NativeLaw(address, compiled,
                       identity or _source_digest(force, partials, potential, file_digest=file_digest),
                       {"force": force, "partials": partials, "potential": potential}, record, path, definition)
    power = (lambda alpha: 1.0 + alpha) if damping_power is None else (lambda alpha, p=float(damping_power): p)
    entry = LawEntry(name=name, form=NATIVE, damping="kappa", filippov=filippov, unilateral=unilateral,
                     conservative=potential is not None,
                     description=description or f"user law ({getattr(force, '__module__', '')}."
                                                f"{getattr(force, '__name__', 'force')})",
                     damping_name=damping[0], damping_power=power, native=native,
                     runaway_factor=RUNAWAY_ENERGY_FACTOR if filippov else GUARD_ENERGY_FACTOR,
                     unit=None if damping[1] is None else str(damping[1]))
    return register(entry)


def load_law_file(path) -> list[str]:
    """Run a Python file that defines laws (``--law-file``); return the names it registered.

    Parameters
    ----------
    path : str or os.PathLike
        A Python file that calls :func:`phaseimpact.define_law` (it runs as a module of its own).

    Returns
    -------
    list of str
        The names of the laws the file registered or replaced, in the registry's order.

    Raises
    ------
    UserLawError
        If the file does not exist, fails when run (the message names the exception), or
        defines no law.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from phaseimpact.model import REGISTRY
    >>> from phaseimpact.model.userlaw import load_law_file
    >>> path = os.path.join(tempfile.mkdtemp(), "laws.py")
    >>> with open(path, "w") as f:
    ...     print("import phaseimpact", file=f)
    ...     print("def force(delta, deltadot, K, kappa, alpha): return K * delta**alpha", file=f)
    ...     print("phaseimpact.define_law('example-file-law', force)", file=f)
    >>> load_law_file(path)
    ['example-file-law']
    >>> del REGISTRY["example-file-law"]  # an example only: the registry as before
    >>> load_law_file(os.path.join(os.path.dirname(path), "missing.py"))
    Traceback (most recent call last):
        ...
    phaseimpact.model.userlaw.UserLawError: law file '.../missing.py' does not exist
    """
    if not isinstance(path, (str, os.PathLike)):
        raise UserLawError(f"law file {path!r} is out of range; allowed: a path (str or os.PathLike)")
    path = os.fspath(path)
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise UserLawError(f"law file {path!r} does not exist") from None
    except OSError as exc:
        raise UserLawError(f"law file {path!r} cannot be read: {exc.strerror or exc}") from None
    if stat.S_ISDIR(mode):
        raise UserLawError(f"law file {path!r} is a folder; allowed: a Python file")
    if not stat.S_ISREG(mode):
        kind = "a FIFO (named pipe)" if stat.S_ISFIFO(mode) else "not a regular file (a socket or device)"
        raise UserLawError(f"law file {path!r} is {kind}; allowed: a Python file")
    try:
        with open(path, "rb") as f:
            source = f.read()
    except OSError as exc:
        raise UserLawError(f"law file {path!r} cannot be read: {exc.strerror or exc}") from None
    absolute = os.path.abspath(path)
    file_digest = hashlib.sha256(source).hexdigest()
    loaded = _LOADED.get(absolute)
    if loaded is not None and loaded[0] == file_digest and all(REGISTRY.get(n) is e for n, e in loaded[1].items()):
        return list(loaded[1])  # the same bytes, already run: the laws as they are (no second compile)
    before = dict(REGISTRY)
    module_name = "phaseimpact_user_law_" + hashlib.sha1(absolute.encode()).hexdigest()[:12]
    module = types.ModuleType(module_name)  # any file name: the bytes read above run as a module
    module.__file__ = absolute
    sys.modules[module_name] = module
    _LOADING.append((absolute, file_digest))
    def refuse_exit(status=0):  # os._exit would end the process with its status before any message
        raise SystemExit(status)

    exit_now, os._exit = os._exit, refuse_exit
    try:
        # what the file prints goes to stderr: stdout holds the command's output (--json)
        with contextlib.redirect_stdout(sys.stderr):
            exec(compile(source, absolute, "exec"), module.__dict__)  # noqa: S102 (the user's own law file)
    except UserLawError as exc:  # define_law's own message names the law; the file is named too
        if path in str(exc):
            raise
        raise UserLawError(f"law file {path!r}: {exc}") from None
    except SystemExit as exc:
        raise UserLawError(f"law file {path!r} exited (status {exc.code!r}) while it was run (sys.exit or "
                           "os._exit); allowed: a file that only defines laws (remove the exit)") from None
    except Exception as exc:  # noqa: BLE001 (the user's file)
        raise UserLawError(f"law file {path!r} failed: {type(exc).__name__}: {exc}") from None
    finally:
        os._exit = exit_now
        _LOADING.pop()
    added = [n for n, e in REGISTRY.items() if before.get(n) is not e]
    if not added:
        raise UserLawError(f"law file {path!r} defines no law; it should call phaseimpact.define_law(...)")
    _LOADED[absolute] = (file_digest, {n: REGISTRY[n] for n in added})
    return added


#: Law files run in this process: ``{absolute path: (digest of its bytes, {name: entry})}``.
_LOADED: dict = {}


def ensure_defined(recipe: tuple) -> None:
    """Define a user law in this process as :meth:`NativeLaw.recipe` describes it, unless a law of
    the same identity is already registered (a worker process unpickling a :class:`ContactLaw`).

    Raises
    ------
    UserLawError
        If the law file no longer holds the law that was run (edited, or gone).
    """
    def defined(name, identity):
        entry = REGISTRY.get(name)
        return entry is not None and entry.native is not None and entry.native.identity == identity

    if recipe[0] == "file":
        _, name, path, identity = recipe
        if not defined(name, identity):
            load_law_file(path)
            if not defined(name, identity):
                raise UserLawError(f"law {name!r}: law file {path!r} changed since the work began (its source "
                                   "differs); run the work again")
        return
    _, name, definition, identity = recipe
    if not defined(name, identity):
        _define(name, definition, identity)


def single_law(names: list, path, option: str) -> str:
    """The law of a law file that defines exactly one (chosen when no law is named); else refuse,
    naming the laws it defines."""
    if len(names) == 1:
        return names[0]
    raise UserLawError(f"law file {os.fspath(path)!r} defines {len(names)} laws ({', '.join(names)}); allowed: one of "
                       f"them named with {option}")
