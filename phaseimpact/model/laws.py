r"""Contact laws, each defined once (seed eq. 2 and 8; docs/physics.md §3).

A law is one :class:`LawEntry` in :data:`REGISTRY`: its kernel form, its flags (unilateral,
Filippov, runaway guard), its options, and the name, unit and exponent of its damping parameter.
Nothing outside this module names a law: the kernels read the law's flags from its kernel code
(:attr:`ContactLaw.code`, bits :data:`FILIPPOV`, :data:`UNILATERAL`, :data:`CLAMP`,
:data:`MEMORY`) and its runaway guard from the packed coefficients; the command line, archives
and plots take names and units from the entry. The kernels of :mod:`phaseimpact.model.forms`
(compiled with numba, callable from Python too) give the contact force ``P(delta, deltadot)``, its
partial derivatives and the contact potential; the right-hand side, the Jacobian, the event
functions and the energy ledger (:mod:`phaseimpact.model.rhs`) are composed from them, so a law's
physics lives in these two modules only.

==========================  ===============================================================
``abrate``                  ``K delta^alpha`` for ``delta > 0``, else 0 (eq. 2);
                            ``bilateral=True``: ``K |delta|^alpha sgn(delta)`` (seed Fig. 3)
``hunt-crossley``           ``(K + kappa deltadot) delta^alpha`` for ``delta > 0``;
                            ``clamp=True`` keeps ``P >= 0``
``hunt-crossley-approx``,   Hunt-Crossley form with ``kappa = chi(e) K / v`` from a
``lankarani-nikravesh``,    coefficient of restitution ``e`` (the damping's only source)
``flores``, ``gonthier``
``kuwabara-kono``           ``K delta^alpha + gamma delta^(alpha-1) deltadot`` for ``delta > 0``
                            (viscoelastic spheres, Kuwabara & Kono 1987; ``gamma`` set by
                            ``kappa``, N s/m^alpha); ``clamp=True`` keeps ``P >= 0``
``paper``                   ``(K + kappa deltadot) |delta|^alpha sgn(deltadot)`` (eq. 8):
                            a Filippov system. ``contact="printed"`` (default) reads
                            ``|delta|`` literally, so the law also acts in tension;
                            ``contact="unilateral"`` sets ``P = 0`` for ``delta <= 0``
``thornton``                elastic-perfectly plastic sphere (Thornton 1997): Hertz to the
                            yield indentation, then linear at the limiting pressure ``p_y``;
                            unloading on Hertz with an enlarged radius (a law with memory)
==========================  ===============================================================

Modes (``paper``): ``+1``/``-1`` while slipping with that sign of ``deltadot``, ``STUCK`` (0)
while ``deltadot = 0`` holds, ``PLAIN`` (2) reads ``sgn(deltadot)`` literally (what a fixed-step
method sees). Every other law runs in mode ``+1``.

Adding a law
------------
A law of your own needs no edit of the package: :func:`phaseimpact.define_law` takes plain
Python functions and compiles them (:mod:`phaseimpact.model.userlaw`). To ship a law with the
package:

1. Give its force a kernel form (in :mod:`phaseimpact.model.forms`): a new constant next to
   :data:`ELASTIC` ... :data:`THORNTON` (below :data:`NATIVE`; :data:`FORM_MASK` leaves room for
   15 shipped forms) and its entry in :data:`FORMS` (its name, and the memory slots its kernels
   keep), or reuse a form whose force it shares (the restitution laws reuse
   :data:`HUNT_CROSSLEY`). :func:`register` refuses a form missing from :data:`FORMS`, and the
   kernels give NaN for a form without a branch: a law is never computed with another law's
   force.
2. Write the form's branch (in :mod:`phaseimpact.model.forms`) in :func:`contact_force` (its
   body ``_contact_force``, which also takes the ``sqrt(|delta|)`` a regularised phase has),
   :func:`force_partials` (exact partial derivatives, zero where ``P`` is 0) and, if its elastic
   term has a potential, :func:`contact_potential` (a Filippov law has none; a Filippov form
   also gives its force at rest in :func:`stick_bound`: the stick holds while the required force
   stays within it). A branch reads the flags from ``code``: :data:`UNILATERAL` (the kernels
   already return 0 for ``delta <= 0``), :data:`CLAMP` (``P >= 0``), and the sign factor of a
   :data:`FILIPPOV` law from ``mode``. A law with memory (:data:`MEMORY`, set from
   :attr:`LawEntry.memory`) writes its branch in :func:`force_of` (its body
   :func:`force_of_root`), :func:`partials_of` and
   :func:`remember` instead, reading its state from the packed coefficients (its dent, if any,
   at ``DENT_``).
   **Inlining rule:** the branch calls an out-of-line kernel of the form's own
   (``_kuwabara_kono_force``, ``_thornton``), never writes the physics inline: the dispatchers
   :func:`contact_force` and :func:`force_partials` stay one line per form, each kernel is
   compiled once, and every law's physics sits in one place. (Speed does not ask for more: LLVM
   inlines the two dispatchers into ``rhs_values`` (``forceinline``) and calls the law's kernel;
   ``rhs_values`` stays a call from the DOP853 stages, where inlined into every stage it ran
   slower and compiled longer: see the CHANGELOG.) Only the first laws' one-line forms are inline.
3. :func:`register` a :class:`LawEntry` (every field by keyword): name, form, damping source
   (``"kappa"``, ``"restitution"`` or None), the flags, the options it allows (``"clamp"``,
   ``"bilateral"``, ``"contact"``), the damping's exponent ``damping_power(alpha)`` (its unit is
   ``N s/m^damping_power``), its own coefficients and memory, and a description.
4. Check it: ``phaseimpact check-law NAME`` and ``pytest tests/test_laws.py``: the conformance
   suite (:func:`phaseimpact.checks.check_law`; partials against finite differences, the energy
   ledger, momentum, agreement with scipy and with the oracle, :mod:`phaseimpact._oracle`) runs
   on every variant of :func:`law_variants`, so the new law is in it once registered. Add a test
   module of its own against a known answer (a closed form or a published series:
   ``tests/test_kuwabara_kono.py``, ``tests/test_thornton.py``).
5. Document it: its row in the table above, docs/physics.md §3 (the force, its potential or why
   it has none), docs/commands.md (the ``--law`` list and what it takes), the CHANGELOG's
   "Unreleased" section; a law with memory or a new coefficient also docs/physics.md §4 (the
   energy ledger) and the parameters it reads (:meth:`ContactLaw.coefficients`).

The engine's compiled cache is keyed on a digest of these sources: the next run recompiles.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

from ..parameters import Parameters, is_number, require, require_choice
from .forms import (
    CLAMP,
    ELASTIC,
    FILIPPOV,
    FORMS,
    HUNT_CROSSLEY,
    KUWABARA_KONO,
    MEMORY,
    PAPER,
    THORNTON,
    UNILATERAL,
    make_code,
)

__all__ = [
    "LawEntry", "REGISTRY", "LAWS", "CONTACT_READINGS", "ContactLaw", "as_law", "law_variants", "register",
    "RUNAWAY_ENERGY_FACTOR", "GUARD_ENERGY_FACTOR",
]

CONTACT_READINGS = ("printed", "unilateral")
OPTIONS = ("bilateral", "clamp", "contact")

#: Energy growth, relative to the run's initial energy, that ends a run as a runaway: eq. 8 as
#: printed feeds the motion without bound once the projectile is in tension. Every other law can
#: only gain energy in an anti-damped slip that ends at the separation (the unilateral reading) or
#: through numerical trouble, so it gets a wide guard instead: the run reaches its rebound.
RUNAWAY_ENERGY_FACTOR = 2.0
GUARD_ENERGY_FACTOR = 100.0



def _number_text(x: float) -> str:
    return f"{x:g}"


def _hertz_damping_power(alpha: float) -> float:
    """The default :attr:`LawEntry.damping_power`: ``1 + alpha``, the damping coefficient of
    ``(K + kappa deltadot) delta^alpha`` being in N s/m^(1 + alpha).

    Parameters
    ----------
    alpha : float
        The contact exponent (1.5 for Hertz).

    Returns
    -------
    float
        The exponent ``p`` of the damping coefficient's unit N s/m^p.

    Examples
    --------
    >>> from phaseimpact.model import REGISTRY
    >>> REGISTRY["hunt-crossley"].damping_power(1.5)
    2.5
    """
    return 1.0 + alpha


@dataclass(frozen=True, kw_only=True)
class LawEntry:
    """A registered contact law: everything the package knows about it (every field by keyword).

    Attributes
    ----------
    name : str
    form : int
        Kernel form, one of :data:`FORMS` (:data:`ELASTIC`, :data:`HUNT_CROSSLEY`, :data:`PAPER`,
        :data:`KUWABARA_KONO`, :data:`THORNTON`, or :data:`NATIVE` for a user law).
    damping : {None, "kappa", "restitution"}
        The law's one source of damping: the parameter ``kappa``, a coefficient of
        restitution, or none.
    filippov : bool
        The law's sign factor needs stick/slip modes (``paper``).
    unilateral : bool
        The law acts only while ``delta > 0`` (before options).
    conservative : bool
        The elastic term has a potential (docs/physics.md §4 energy ledger).
    chi : callable or None
        Damping factor ``chi(e)`` of a restitution law, ``kappa = chi(e) K / v``.
    description : str
    options : tuple of str
        Options of :class:`ContactLaw` the law allows: ``"bilateral"`` (a unilateral law that can
        also pull), ``"clamp"`` (``P >= 0``), ``"contact"`` (a Filippov law's reading of
        ``|delta|``).
    damping_name : str
        The damping coefficient's symbol in messages (set with ``kappa`` whatever its name).
    damping_power : callable
        ``alpha -> p``: the damping coefficient is in N s/m^p (``1 + alpha`` for
        ``(K + kappa deltadot) delta^alpha``).
    inverse : bool
        ``restitution=e`` may replace ``kappa`` through the exact inverse
        (:func:`phaseimpact.model.restitution.kappa_for_restitution`; ``hunt-crossley``).
    runaway_factor : float
        Energy growth that ends a run of the law's bilateral reading as a runaway
        (:data:`RUNAWAY_ENERGY_FACTOR` for eq. 8 as printed; unilateral readings get
        :data:`GUARD_ENERGY_FACTOR`).
    native : object
        A user law's compiled functions (:mod:`phaseimpact.model.userlaw`); None when shipped.
    unit : str or None
        A user law's own unit text for its damping coefficient (default from ``damping_power``).
    coefficients : callable or None
        ``params -> tuple`` of the law's own coefficients (at most :data:`N_LAW`), packed at
        :data:`LAW_`; it raises ``ValueError`` when ``params`` lack what the law needs.
    memory : int
        Slots of state the law keeps over a run (at most :data:`N_MEMORY`, at :data:`MEMORY_`,
        0 at the start), updated by :func:`remember` at each extremum of ``delta``: the number its
        form's memory branch keeps (:data:`FORMS`); sets the law's flag :data:`MEMORY`.
    plastic : bool
        The contact yields (Thornton): pressure, contact radius and validity are read from the
        elastic-plastic model (:func:`phaseimpact.model.contact.plastic_contact`), not from Hertz.

    Examples
    --------
    >>> from phaseimpact.model import REGISTRY
    >>> entry = REGISTRY["kuwabara-kono"]
    >>> entry.damping, entry.damping_name, entry.options, entry.shipped
    ('kappa', 'gamma', ('clamp',), True)
    >>> entry.damping_power(1.5), entry.damping_unit(1.5)
    (1.5, 'N s/m^1.5')
    """

    name: str
    form: int
    damping: str | None
    filippov: bool
    unilateral: bool
    conservative: bool
    chi: object = None
    description: str = ""
    options: tuple = ()
    damping_name: str = "kappa"
    damping_power: object = field(default=_hertz_damping_power)
    inverse: bool = False
    runaway_factor: float = GUARD_ENERGY_FACTOR
    native: object = None
    unit: str | None = None
    coefficients: object = None
    memory: int = 0
    plastic: bool = False

    @property
    def shipped(self) -> bool:
        return self.native is None

    def damping_unit(self, alpha: float) -> str:
        """The damping coefficient's unit, e.g. ``N s/m^2.5`` (a user law's own, if it gave one).

        Parameters
        ----------
        alpha : float
            The contact exponent (1.5 for Hertz): the unit is N s/m^``damping_power(alpha)``.

        Returns
        -------
        str
            The unit as text for messages and plots (``N s/m^p``).

        Examples
        --------
        >>> from phaseimpact.model import REGISTRY
        >>> REGISTRY["hunt-crossley"].damping_unit(1.5), REGISTRY["kuwabara-kono"].damping_unit(1.5)
        ('N s/m^2.5', 'N s/m^1.5')
        """
        if self.unit is not None:
            return self.unit
        return f"N s/m^{_number_text(self.damping_power(alpha))}"

    def damping_udunits(self, alpha: float) -> str:
        """The same in UDUNITS (archives), e.g. ``N s m-2.5``.

        Parameters
        ----------
        alpha : float
            The contact exponent (1.5 for Hertz).

        Returns
        -------
        str
            The unit in UDUNITS syntax (``N s m-p``), or a user law's own unit text unchanged.

        Examples
        --------
        >>> from phaseimpact.model import REGISTRY
        >>> REGISTRY["hunt-crossley"].damping_udunits(1.5)
        'N s m-2.5'
        """
        if self.unit is not None:
            return self.unit
        return f"N s m-{_number_text(self.damping_power(alpha))}"


REGISTRY: dict[str, LawEntry] = {}


def register(entry: LawEntry) -> LawEntry:
    """Add ``entry`` to :data:`REGISTRY` (replacing a user law of the same name).

    Parameters
    ----------
    entry : LawEntry
        The law; its :attr:`~LawEntry.name` is the key (an entry already there under that name is
        replaced, and :func:`as_law`'s cache of named laws is cleared).

    Returns
    -------
    LawEntry
        ``entry`` itself.

    Examples
    --------
    A shipped law's form under a new name (example only: removed again at the end, so that the
    registry stays the package's):

    >>> from phaseimpact.model import REGISTRY, ContactLaw
    >>> from phaseimpact.model.forms import HUNT_CROSSLEY
    >>> from phaseimpact.model.laws import LawEntry, register
    >>> entry = register(LawEntry(name="example-hc", form=HUNT_CROSSLEY, damping="kappa", filippov=False,
    ...                           unilateral=True, conservative=True, description="Hunt-Crossley under another name"))
    >>> ContactLaw("example-hc").code == ContactLaw("hunt-crossley").code
    True
    >>> del REGISTRY["example-hc"]

    Raises
    ------
    ValueError
        For a form the kernels have no branch for (not in :data:`FORMS`), or a
        :attr:`~LawEntry.memory` other than the one its form's memory branch keeps.
    """
    form = FORMS.get(entry.form)
    if form is None:
        raise ValueError(f"law {entry.name!r}: form = {entry.form!r} has no kernels (a branch in contact_force and "
                         "force_partials, phaseimpact/model/forms.py); allowed: "
                         + ", ".join(f"{code} ({name})" for code, (name, _) in FORMS.items()))
    if entry.memory != form[1]:
        raise ValueError(f"law {entry.name!r}: memory = {entry.memory!r}, but the kernels of form {form[0]} keep "
                         f"{form[1]} slot{'' if form[1] == 1 else 's'} of memory")
    REGISTRY[entry.name] = entry
    if "_named_law" in globals():
        _named_law.cache_clear()
    return entry


register(LawEntry(name="abrate", form=ELASTIC, damping=None, filippov=False, unilateral=True, conservative=True,
                  options=("bilateral",), description="Hertz contact, no damping (seed eq. 2)"))
register(LawEntry(name="paper", form=PAPER, damping="kappa", filippov=True, unilateral=False, conservative=False,
                  options=("contact",), runaway_factor=RUNAWAY_ENERGY_FACTOR,
                  description="eq. 8: (K + kappa deltadot) |delta|^alpha sgn(deltadot)"))
register(LawEntry(name="hunt-crossley", form=HUNT_CROSSLEY, damping="kappa", filippov=False, unilateral=True,
                  conservative=True, options=("clamp",), inverse=True,
                  description="(K + kappa deltadot) delta^alpha for delta > 0"))
for _name, _chi, _text in (
    ("hunt-crossley-approx", lambda e: 1.5 * (1 - e), "chi = 3(1-e)/2"),
    ("lankarani-nikravesh", lambda e: 0.75 * (1 - e * e), "chi = 3(1-e^2)/4"),
    ("flores", lambda e: 1.6 * (1 - e) / e, "chi = 8(1-e)/(5e)"),
    ("gonthier", lambda e: (1 - e * e) / e, "chi = (1-e^2)/e"),
):
    register(LawEntry(name=_name, form=HUNT_CROSSLEY, damping="restitution", filippov=False, unilateral=True,
                      conservative=True, chi=_chi, options=("clamp",),
                      description=f"K delta^alpha (1 + chi deltadot / v), {_text}"))
register(LawEntry(name="kuwabara-kono", form=KUWABARA_KONO, damping="kappa", filippov=False, unilateral=True,
                  conservative=True, options=("clamp",), damping_name="gamma", damping_power=lambda alpha: alpha,
                  description="K delta^alpha + gamma delta^(alpha-1) deltadot for delta > 0 (viscoelastic spheres)"))


def _thornton_coefficients(params: Parameters) -> tuple:
    """``(p_y, R)``: the limiting contact pressure and the effective radius."""
    if params.limiting_pressure is None:
        raise ValueError("law 'thornton' needs the limiting contact pressure p_y: give the case a yield_strength "
                         "(p_y = 1.6 Y of the weaker body) or Parameters(limiting_pressure=...)")
    if params.R is None:
        raise ValueError("law 'thornton' needs the effective radius R: derive the parameters from a case, or give "
                         "Parameters(R=...)")
    require("alpha", params.alpha, "1.5 for law 'thornton' (Hertz loading and unloading)", params.alpha == 1.5)
    return params.limiting_pressure, params.R


register(LawEntry(name="thornton", form=THORNTON, damping=None, filippov=False, unilateral=True, conservative=False,
                  coefficients=_thornton_coefficients, memory=3, plastic=True,
                  description="elastic-perfectly plastic sphere (Thornton 1997): Hertz to the yield indentation, then "
                              "linear at the limiting pressure p_y; Hertz unloading with the enlarged radius"))

#: The shipped laws (user laws join :data:`REGISTRY` only).
LAWS = tuple(REGISTRY)


@dataclass(frozen=True)
class ContactLaw:
    """A registered law with its options.

    Attributes
    ----------
    name : str
        One of :data:`LAWS`, or a user law's name (:func:`phaseimpact.define_law`).
    restitution : float or None
        Coefficient of restitution ``e`` in (0, 1]: required by the restitution laws (their
        only damping); for a law with an exact inverse (``hunt-crossley``) it *replaces*
        ``kappa`` (:func:`phaseimpact.model.restitution.kappa_for_restitution`), and ``kappa`` is
        then not read. Not allowed for other laws.
    bilateral : bool
        Laws with the ``bilateral`` option (``abrate``): the contact also pulls
        (``K |delta|^alpha sgn(delta)``).
    clamp : bool
        Laws with the ``clamp`` option (Hunt-Crossley family, Kuwabara-Kono): ``P >= 0`` (no
        adhesion at the end of contact).
    contact : {"printed", "unilateral"}
        Laws with the ``contact`` option (``paper``): the reading of ``|delta|^alpha``
        (docs/physics.md §3).

    Raises
    ------
    ValueError
        For an unknown law name or ``contact`` reading, a restitution out of range or not read by
        the law (or missing where the law needs one), or an option the law does not allow.

    Examples
    --------
    >>> from phaseimpact.model import ContactLaw
    >>> law = ContactLaw("hunt-crossley", clamp=True)
    >>> law.label(), law.is_unilateral, law.damping_source
    ('hunt-crossley clamp', True, 'kappa')
    >>> ContactLaw("flores", restitution=0.8).damping_source
    'restitution'
    >>> ContactLaw("abrate", clamp=True)
    Traceback (most recent call last):
        ...
    ValueError: clamp = True is only allowed for laws 'hunt-crossley', ..., not 'abrate'
    """

    name: str = "paper"
    restitution: float | None = None
    bilateral: bool = False
    clamp: bool = False
    contact: str = "printed"

    def __post_init__(self):
        require_choice("law", self.name, tuple(REGISTRY))
        require_choice("contact", self.contact, CONTACT_READINGS)
        entry = self.entry
        if self.restitution is not None:
            e = self.restitution
            require("restitution", e, "a number with 1e-6 <= e <= 1",
                    is_number(e) and math.isfinite(e) and 1e-6 <= e <= 1)
            object.__setattr__(self, "restitution", float(e))
            if entry.damping != "restitution" and not entry.inverse:
                allowed = [n for n, x in REGISTRY.items() if x.damping == "restitution" or x.inverse]
                raise ValueError(f"restitution = {e!r} is not read by law {self.name!r}; allowed with "
                                 + ", ".join(allowed))
        elif entry.damping == "restitution":
            raise ValueError(f"law {self.name!r} needs a restitution coefficient (restitution in [1e-6, 1])")
        for option, given in (("bilateral", self.bilateral), ("clamp", self.clamp),
                              ("contact", self.contact != "printed")):
            if given and option not in entry.options:
                allowed = [n for n, x in REGISTRY.items() if option in x.options]
                value = f"contact = {self.contact!r}" if option == "contact" else f"{option} = True"
                raise ValueError(f"{value} is only allowed for law{'s' if len(allowed) > 1 else ''} "
                                 f"{', '.join(repr(n) for n in allowed)}, not {self.name!r}")

    @property
    def entry(self) -> LawEntry:
        return REGISTRY[self.name]

    @property
    def flags(self) -> int:
        """The kernel flags of this law with its options."""
        entry = self.entry
        flags = FILIPPOV if entry.filippov else 0
        if (entry.unilateral and not self.bilateral) or (entry.filippov and self.contact == "unilateral"):
            flags |= UNILATERAL
        if self.clamp:
            flags |= CLAMP
        if entry.memory:
            flags |= MEMORY
        return flags

    @property
    def code(self) -> int:
        """Kernel code of this law with its options (flags, form, a user law's function); kept
        until the law's entry is replaced (a user law defined again)."""
        entry = REGISTRY[self.name]
        cached = self.__dict__.get("_code")
        if cached is not None and cached[0] is entry:
            return cached[1]
        code = make_code(entry.form, self.flags, 0 if entry.native is None else entry.native.address)
        object.__setattr__(self, "_code", (entry, code))
        return code

    def __getstate__(self):
        state = dict(self.__dict__)
        state.pop("_code", None)  # holds the entry (functions, a user law's compiled code): not pickled
        entry = REGISTRY.get(self.name)
        if entry is not None and entry.native is not None:  # a worker process defines the user law again
            state["_recipe"] = entry.native.recipe(self.name)
        return state

    def __setstate__(self, state):
        state = dict(state)
        state.pop("_recipe", None)  # its unpickling defined the user law in this process already
        self.__dict__.update(state)

    @property
    def source(self) -> str | None:
        """A user law's source digest (its functions and law file; recorded in its archives), None
        for a shipped law."""
        native = self.entry.native
        return None if native is None else native.identity

    @property
    def is_filippov(self) -> bool:
        return self.entry.filippov

    @property
    def is_unilateral(self) -> bool:
        return bool(self.flags & UNILATERAL)

    @property
    def is_conservative(self) -> bool:
        return self.entry.conservative

    def coefficients(self, params: Parameters) -> tuple:
        """The law's own packed coefficients for ``params`` (:attr:`LawEntry.coefficients`).

        Parameters
        ----------
        params : Parameters
            The model's parameters.

        Returns
        -------
        tuple of float
            At most :data:`N_LAW` numbers, packed at :data:`LAW_` (``thornton``: the limiting
            pressure ``p_y``, Pa, and the effective radius ``R``, m); empty for a law without
            coefficients of its own.

        Raises
        ------
        ValueError
            When ``params`` lack what the law needs (``thornton`` without a limiting pressure).

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.model import ContactLaw
        >>> ContactLaw("hunt-crossley").coefficients(seed_parameters())
        ()
        >>> p_y, R = ContactLaw("thornton").coefficients(seed_parameters(limiting_pressure=2e9))
        >>> print(f"{p_y:.3g} Pa, {R:.4g} m")
        2e+09 Pa, 0.02 m
        """
        own = self.entry.coefficients
        return () if own is None else tuple(float(x) for x in own(params))

    @property
    def runaway_factor(self) -> float:
        """Energy growth (relative to the start) that ends a run as a runaway."""
        return GUARD_ENERGY_FACTOR if self.is_unilateral else self.entry.runaway_factor

    @property
    def damping_source(self) -> str | None:
        """``"kappa"``, ``"restitution"`` or None: the one parameter that sets the damping."""
        if self.restitution is not None:
            return "restitution"
        return self.entry.damping

    def damping_unit(self, alpha: float) -> str:
        """Unit of the damping coefficient set by ``kappa`` (e.g. ``N s/m^2.5``).

        Parameters
        ----------
        alpha : float
            The contact exponent (1.5 for Hertz).

        Returns
        -------
        str
            The unit as text (:meth:`LawEntry.damping_unit`).

        Examples
        --------
        >>> from phaseimpact.model import ContactLaw
        >>> ContactLaw("paper").damping_unit(1.5), ContactLaw("kuwabara-kono").damping_unit(1.5)
        ('N s/m^2.5', 'N s/m^1.5')
        """
        return self.entry.damping_unit(alpha)

    def reads(self, name: str) -> bool:
        """Whether a parameter named ``name`` changes this law's results (``kappa`` is read only
        by laws whose damping comes from it).

        Parameters
        ----------
        name : str
            A parameter's name (``"kappa"``, ``"restitution"``, ``"v"``, ...).

        Returns
        -------
        bool
            False only for ``kappa`` or ``restitution`` when the law's damping does not come from
            it; True for every other name.

        Examples
        --------
        >>> from phaseimpact.model import ContactLaw
        >>> ContactLaw("hunt-crossley").reads("kappa"), ContactLaw("abrate").reads("kappa")
        (True, False)
        >>> law = ContactLaw("flores", restitution=0.8)
        >>> law.reads("kappa"), law.reads("restitution"), law.reads("v")
        (False, True, True)
        """
        if name == "kappa":
            return self.damping_source == "kappa"
        if name == "restitution":
            return self.damping_source == "restitution"
        return True

    def kappa(self, params: Parameters) -> float:
        """Effective damping coefficient (N s/m^damping_power) of this law for ``params``.

        Parameters
        ----------
        params : Parameters
            The model's parameters: ``kappa`` is read by a law damped by it; a restitution law
            reads ``K`` (N/m^alpha) and ``v`` (m/s) for ``kappa = chi(e) K / v``.

        Returns
        -------
        float
            ``params.kappa``, the restitution's damping coefficient (``hunt-crossley`` with a
            restitution: the exact inverse), or 0.0 for an undamped law.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.model import ContactLaw
        >>> p = seed_parameters(v=1.0, kappa=1e9)
        >>> ContactLaw("hunt-crossley").kappa(p), ContactLaw("abrate").kappa(p)
        (1000000000.0, 0.0)
        >>> print(f"{ContactLaw('hunt-crossley', restitution=0.8).kappa(p):.4g} N s/m^2.5")
        8.119e+09 N s/m^2.5
        """
        source = self.damping_source
        if source is None:
            return 0.0
        if source == "kappa":
            return float(params.kappa)
        if self.entry.chi is not None:
            return float(self.entry.chi(self.restitution) * params.K / params.v)
        from .restitution import kappa_for_restitution  # the exact inverse (hunt-crossley)
        return kappa_for_restitution(self.restitution, params)

    def label(self) -> str:
        """Short description with options, for results and archives.

        Returns
        -------
        str
            The name, then the options that differ from the defaults (``paper``: always its
            ``contact`` reading), e.g. ``"hunt-crossley clamp e=0.8"``.

        Examples
        --------
        >>> from phaseimpact.model import ContactLaw
        >>> ContactLaw("paper").label()
        'paper contact=printed'
        >>> ContactLaw("hunt-crossley", restitution=0.8, clamp=True).label()
        'hunt-crossley clamp e=0.8'
        """
        parts = [self.name]
        if "contact" in self.entry.options:
            parts.append(f"contact={self.contact}")
        if self.bilateral:
            parts.append("bilateral")
        if self.clamp:
            parts.append("clamp")
        if self.restitution is not None:
            parts.append(f"e={self.restitution:g}")
        return " ".join(parts)

    def as_dict(self) -> dict:
        """The law and its options as a plain dict (for JSON and archives).

        Returns
        -------
        dict
            ``{"name", "restitution", "bilateral", "clamp", "contact"}``: the fields, None for no
            restitution; ``ContactLaw(**law.as_dict())`` gives the law back.

        Examples
        --------
        >>> from phaseimpact.model import ContactLaw
        >>> ContactLaw("hunt-crossley", clamp=True).as_dict()
        {'name': 'hunt-crossley', 'restitution': None, 'bilateral': False, 'clamp': True, 'contact': 'printed'}
        """
        return {"name": self.name, "restitution": self.restitution, "bilateral": self.bilateral,
                "clamp": self.clamp, "contact": self.contact}


def as_law(law) -> ContactLaw:
    """Accept a :class:`ContactLaw` or a law name.

    Parameters
    ----------
    law : ContactLaw or str
        A law, or the name of a registered law (:data:`REGISTRY`) with its default options.

    Returns
    -------
    ContactLaw
        ``law`` itself, or the named law (one object per name, cached).

    Raises
    ------
    ValueError
        For a name that is not registered (the message lists the registered ones).

    Examples
    --------
    >>> from phaseimpact.model import ContactLaw, as_law
    >>> as_law("hunt-crossley")
    ContactLaw(name='hunt-crossley', restitution=None, bilateral=False, clamp=False, contact='printed')
    >>> law = ContactLaw("paper", contact="unilateral")
    >>> as_law(law) is law, as_law("paper") is as_law("paper")
    (True, True)
    >>> as_law("hertz")
    Traceback (most recent call last):
        ...
    ValueError: law = 'hertz' is out of range; allowed: one of abrate, paper, hunt-crossley, ...
    """
    if isinstance(law, ContactLaw):
        return law
    if isinstance(law, str) and law in REGISTRY:
        return _named_law(law)
    return ContactLaw(law)  # raises the usual error


@functools.cache
def _named_law(name: str) -> ContactLaw:
    return ContactLaw(name)


def law_variants(names=None) -> list[ContactLaw]:
    """Every registered law (or those of ``names``) with every option it allows (for conformance
    tests).

    Parameters
    ----------
    names : collection of str, optional
        The laws to take; default: every law of :data:`REGISTRY` (user laws included).

    Returns
    -------
    list of ContactLaw
        Per law, in the registry's order: the law with its defaults, then one variant per option
        (``bilateral=True``, ``clamp=True``, ``contact="unilateral"``); a restitution law with
        ``restitution=0.6``.

    Examples
    --------
    >>> from phaseimpact.model import law_variants
    >>> [law.label() for law in law_variants(["abrate", "hunt-crossley", "flores"])]
    ['abrate', 'abrate bilateral', 'hunt-crossley', 'hunt-crossley clamp', 'flores e=0.6', 'flores clamp e=0.6']
    """
    variants = []
    for entry in REGISTRY.values():
        if names is not None and entry.name not in names:
            continue
        e = 0.6 if entry.damping == "restitution" else None
        variants.append(ContactLaw(entry.name, restitution=e))
        if "bilateral" in entry.options:
            variants.append(ContactLaw(entry.name, bilateral=True))
        if "clamp" in entry.options:
            variants.append(ContactLaw(entry.name, restitution=e, clamp=True))
        if "contact" in entry.options:
            variants.append(ContactLaw(entry.name, contact="unilateral"))
    return variants
