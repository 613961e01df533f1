"""Environment variables that phaseimpact reads, checked before anything else reads them.

``SOURCE_DATE_EPOCH`` (reproducible builds: the ``created`` time of an archive) is also read by
NumPy's f2py when SciPy imports it, and a value that is not an integer crashes that import with a
traceback from inside NumPy. Set but empty (what ``VAR=$(git log ...)`` leaves outside a git
checkout) means unset, as the reproducible-builds specification says: the package removes it from
the environment on import (:func:`unset_empty`). A malformed value is hidden while the package imports its dependencies
(:func:`hide_bad_source_date_epoch`, :func:`restore_source_date_epoch`), so that phaseimpact's own
check refuses it with a message: the command line at once, an archive when it is written.

``NUMBA_NUM_THREADS`` is read by numba: 0 fails deep inside its first parallel call and a
non-integer is replaced by a warning with a traceback in it; the command line refuses both
(:func:`numba_num_threads`), and an empty one is unset too.

``PHASEIMPACT_GPU_CALLS`` (0 or 1) is read when the GPU kernel is first built
(:mod:`phaseimpact.cuda`'s call policy): :func:`gpu_calls_kept` checks it, the command line before
any work and ``backend="cuda"`` before any run.
"""

from __future__ import annotations

import os
import re

__all__ = ["EPOCH_MAX", "source_date_epoch", "hide_bad_source_date_epoch", "restore_source_date_epoch",
           "numba_num_threads", "unset_empty", "gpu_calls_kept", "GPU_CALLS_VARIABLE"]

VARIABLE = "SOURCE_DATE_EPOCH"
THREADS_VARIABLE = "NUMBA_NUM_THREADS"
#: ``1`` or unset (the default) keeps the engine's calls calls on the GPU; ``0`` leaves NVVM's
#: inlining as numba sets it up (:mod:`phaseimpact.cuda`).
GPU_CALLS_VARIABLE = "PHASEIMPACT_GPU_CALLS"
#: The last second a timestamp can hold (9999-12-31T23:59:59 UTC), s since 1970.
EPOCH_MAX = 253_402_300_799


def source_date_epoch() -> int | None:
    """``SOURCE_DATE_EPOCH`` as seconds since 1970-01-01 UTC, or None when it is not set.

    Raises
    ------
    ValueError
        Naming the variable, its value and the allowed range (digits only, as ``date +%s`` prints).
    """
    text = os.environ.get(VARIABLE, "").strip()
    if not text:
        return None
    if not re.fullmatch(r"[0-9]+", text) or int(text) > EPOCH_MAX:
        raise ValueError(f"{VARIABLE} = {text!r} is out of range; allowed: an integer number of seconds since "
                         f"1970-01-01 UTC, 0 <= {VARIABLE} <= {EPOCH_MAX} (the year 9999), as 'date +%s' prints "
                         "it, or unset")
    return int(text)


def unset_empty() -> None:
    """Remove ``SOURCE_DATE_EPOCH`` and ``NUMBA_NUM_THREADS`` when set but empty: unset, for NumPy, numba
    and child processes too (NumPy's f2py crashes on an empty one, numba warns)."""
    for name in (VARIABLE, THREADS_VARIABLE):
        if name in os.environ and not os.environ[name].strip():
            del os.environ[name]


def hide_bad_source_date_epoch() -> str | None:
    """Remove a bad ``SOURCE_DATE_EPOCH`` from the environment and return it (None if fine)."""
    try:
        source_date_epoch()
    except ValueError:
        return os.environ.pop(VARIABLE)
    return None


def restore_source_date_epoch(value: str | None) -> None:
    """Put back what :func:`hide_bad_source_date_epoch` removed."""
    if value is not None:
        os.environ[VARIABLE] = value


def numba_num_threads() -> int | None:
    """``NUMBA_NUM_THREADS`` (numba's thread pool), or None when it is not set (empty means unset).

    Raises
    ------
    ValueError
        Naming the variable, its value and the allowed range.
    """
    text = os.environ.get(THREADS_VARIABLE, "").strip()
    if not text:
        return None
    if not re.fullmatch(r"[0-9]+", text) or int(text) < 1:
        cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
        raise ValueError(f"{THREADS_VARIABLE} = {text!r} is out of range; allowed: an integer >= 1 (threads of "
                         f"numba's pool; this machine has {cores} cores), or unset")
    return int(text)


def gpu_calls_kept() -> bool:
    """``PHASEIMPACT_GPU_CALLS``: True unless it is ``0``.

    Raises
    ------
    ValueError
        Naming the variable, its value and the allowed range (0 or 1).
    """
    value = os.environ.get(GPU_CALLS_VARIABLE, "")
    if value not in ("", "0", "1"):
        raise ValueError(f"{GPU_CALLS_VARIABLE} = {value!r} is out of range; allowed: 0 or 1")
    return value != "0"
