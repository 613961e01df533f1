"""The tolerance keywords renamed after 0.2.0 (issue 41): ``rtol`` is the integrator's tolerance everywhere,
as in :func:`~phaseimpact.simulate`; a bracket's tolerance has its own name (``kappa_rtol``,
``refine_rtol``). For one release the old spellings are refused with a pointer, so that an old call
fails instead of running with a tolerance it did not mean. Drop this module in the release after.
"""

import functools


def renamed_tolerances(bracket: str | None):
    """Refuse ``integrator_rtol=``, and ``rtol=`` without ``bracket=`` (its old meaning), with the new names.

    Parameters
    ----------
    bracket : str or None
        The new name of the keyword that ``rtol`` used to be (None: ``rtol`` kept its meaning).

    Examples
    --------
    >>> @renamed_tolerances("kappa_rtol")
    ... def locate(*, kappa_rtol=1e-10, rtol=1e-10):
    ...     return kappa_rtol, rtol
    >>> locate(kappa_rtol=1e-8, rtol=1e-12)
    (1e-08, 1e-12)
    >>> locate(rtol=1e-8)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    TypeError: locate(): rtol= now means the integrator's tolerance (it was the bracket's, now kappa_rtol=): ...
    """
    def wrap(function):
        name = function.__name__

        @functools.wraps(function)
        def checked(*args, **kwargs):
            if "integrator_rtol" in kwargs:
                raise TypeError(f"{name}(): integrator_rtol= is renamed rtol= (the integrator's tolerance, as in "
                                "simulate)" + (f"; the bracket's tolerance is {bracket}=" if bracket else ""))
            if bracket and "rtol" in kwargs and bracket not in kwargs:
                raise TypeError(f"{name}(): rtol= now means the integrator's tolerance (it was the bracket's, now "
                                f"{bracket}=): give {bracket}= too, or only {bracket}= for the bracket (rtol= alone "
                                "is refused in this release so that an older call does not silently change meaning)")
            return function(*args, **kwargs)

        return checked

    return wrap
