"""Whether a new result may replace an archive (:func:`same_work`, :func:`check_overwrite`: the one
rule of every command that writes one) and the resume protocol of the resumable commands
(:func:`open_for_resume`)."""

from __future__ import annotations

import json
import math
import os

import numpy as np

from ..model import ContactLaw
from ..parameters import Parameters
from ._checkpoint import Checkpoint
from ._common import DamagedArchiveError, _attr_str, _json, _json_attr, _Refusal, _same_number
from ._files import _reading, _retrying
from ._io import describe, load
from ._registry import REGISTRY


def _axis_text(name, values) -> str:
    values = np.asarray(values, dtype=float).ravel()
    if not values.size:
        return f"{name}: empty"
    # the spacing too: a log and a linear axis with the same ends and NUM must not print alike
    spacing = ""
    if values.size > 2:
        steps = np.diff(values)
        if np.all(values > 0) and np.allclose(np.diff(np.log(values)), np.log(values[1] / values[0]), rtol=1e-9):
            spacing = ", log spaced"
        elif np.allclose(steps, steps[0], rtol=1e-9):
            spacing = ", linear"
        else:
            spacing = ", listed"
    # repr digits: a difference in the 11th digit must show in the message
    return f"{name}: {len(values)} values from {float(values[0])!r} to {float(values[-1])!r}{spacing}"


def _t_end_text(t_end) -> str:
    """``t_end`` as a reader knows it: NaN or None in an archive means each run until it settles."""
    if t_end is None or (isinstance(t_end, float) and math.isnan(t_end)):
        return "none (each run until its outcome settles)"
    return f"{float(t_end)!r} s"


def same_work(held: dict, kind: str, law: ContactLaw, params: Parameters, axes: dict, t_end, rtol) -> list[str]:
    """What differs between an archive's :func:`describe` and the work asked for (empty: the same).

    Parameters
    ----------
    held : dict
        :func:`describe` of the archive.
    kind : str
        One of :data:`KINDS`.
    law : ContactLaw
        The law asked for.
    params : Parameters
        The base case's parameters asked for.
    axes : dict
        ``{name: values}`` asked for, in order.
    t_end : float or None
        The horizon asked for, s (None or NaN: each run until its outcome settles).
    rtol : float
        The integrator tolerance asked for.

    Returns
    -------
    list of str
        One phrase per difference (kind, law, a user law's source, parameters, axes, ``t_end``,
        ``rtol``), each with both values.

    Examples
    --------
    >>> import os, tempfile
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.archive import describe, same_work, save
    >>> from phaseimpact.continuation import sweep
    >>> s = sweep(seed_parameters(), "paper", [1e9, 1e13])
    >>> held = describe(save(s, os.path.join(tempfile.mkdtemp(), "s.nc")))
    >>> same_work(held, "sweep", s.law, seed_parameters(), {"kappa": s.kappa}, None, 1e-10)
    []
    >>> same_work(held, "sweep", s.law, seed_parameters(), {"kappa": s.kappa}, None, 1e-9)
    ['rtol 1e-10 (asked 1e-09)']
    """
    differences = []
    if held["kind"] != kind:
        differences.append(f"kind {held['kind']!r}, not {kind!r}")
    if held["law"] != law.as_dict():
        differences.append(f"law {held['law']}, not {law.as_dict()}")
    elif held.get("law_source") != law.source:
        held_source = held.get("law_source") or "not recorded"
        differences.append(f"law {law.name!r}: its source changed (the archive's was {held_source}, now "
                           f"{law.source or 'a shipped law'}): the law file or functions were edited")
    asked = json.loads(_json(params.as_dict()))
    if held["parameters"] != asked:
        changed = sorted(k for k in set(asked) | set(held["parameters"])
                         if held["parameters"].get(k) != asked.get(k))
        differences.append("parameters " + ", ".join(
            f"{k} = {held['parameters'].get(k)!r} (asked {asked.get(k)!r})" for k in changed))
    if list(held["axes"]) != list(axes) or not all(
            np.array_equal(np.asarray(held["axes"][k], dtype=float), np.asarray(v, dtype=float))
            for k, v in axes.items()):
        differences.append("axes " + ", ".join(_axis_text(k, v) for k, v in held["axes"].items())
                           + " (asked " + ", ".join(_axis_text(k, v) for k, v in axes.items()) + ")")
    if not _same_number(held["t_end"], t_end):
        differences.append(f"t_end {_t_end_text(held['t_end'])} (asked {_t_end_text(t_end)})")
    if not _same_number(held["rtol"], rtol):
        differences.append(f"rtol {held['rtol']!r} (asked {rtol!r})")
    return differences


def check_overwrite(path, kind: str, law: ContactLaw, params: Parameters, axes: dict, t_end, rtol, *,
                    force: bool = False, name: str = "out", settings: dict | None = None) -> None:
    """Refuse (``ValueError``) to replace ``path`` unless it is missing, or an archive of the same work
    (kind, law, parameters, axis values, ``t_end``, ``rtol`` and ``settings``), or ``force`` is set.

    The one rule of every command that writes an archive (``--out`` of ``sweep``, ``atlas``,
    ``critical-curve``, ``simulate``, ``transitions``; ``--archive`` of ``train``, ``orbit-diagram``,
    ``map-continuation``, ``basins``).

    Parameters
    ----------
    path : str or path-like
        The file a command would write.
    kind, law, params, axes, t_end, rtol
        The work asked for, as for :func:`same_work`. A critical curve's ``axes`` are the values asked
        for (the archive also holds its continuation's intermediate steps).
    force : bool, default False
        Allow any replacement (the command line's ``--force``).
    name : str, default "out"
        How the message names ``path`` (the command line's option).
    settings : dict, optional
        Compared too where given: a train result's, a run's or a transition search's settings as
        :func:`save` stores them (``period``, ``impacts``, ``rtol``, ``kappa_min``, ...), or a critical
        curve's ``{"what": ...}``.

    Raises
    ------
    ValueError
        For an existing file that is not an archive, a damaged archive, or an archive of other
        work (the message lists the differences).

    Examples
    --------
    >>> import os, tempfile
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.archive import check_overwrite, save
    >>> from phaseimpact.continuation import sweep
    >>> s = sweep(seed_parameters(), "paper", [1e9, 1e13])
    >>> path = save(s, os.path.join(tempfile.mkdtemp(), "s.nc"))
    >>> check_overwrite(path, "sweep", s.law, seed_parameters(), {"kappa": s.kappa}, None, 1e-10)
    >>> check_overwrite(path, "sweep", s.law, seed_parameters(), {"kappa": s.kappa}, None, 1e-9)
    Traceback (most recent call last):
    ...
    ValueError: out = '...s.nc' holds other work (rtol 1e-10 (asked 1e-09)); refusing to overwrite it ...
    """
    path = os.fspath(path)
    if force or not os.path.exists(path):
        return
    try:
        held = describe(path)
        if held["kind"] == kind and settings is not None:
            held_settings = _retrying(_stored_settings, path)
            if kind == "critical-curve":
                curve = load(path)
                held["axes"] = {curve.param: np.asarray(curve.values)[np.asarray(curve.requested, dtype=bool)]}
    except _Refusal as error:  # an archive of a user law not defined here: not comparable, not damaged
        raise ValueError(f"{name} = {path!r} exists and cannot be compared ({error}); refusing to overwrite it "
                         "(choose another path, or add --force to replace it)") from None
    except DamagedArchiveError as error:
        raise ValueError(f"{name} = {path!r} exists and is a damaged phaseimpact archive ({error.reason}); refusing "
                         "to overwrite it (choose another path, or add --force to replace it)") from None
    except ValueError:
        raise ValueError(f"{name} = {path!r} exists and is not a phaseimpact archive; refusing to overwrite it "
                         "(choose another path, or add --force to replace it)") from None
    differences = same_work(held, kind, law, params, axes, t_end, rtol)
    if held["kind"] == kind and settings is not None:
        asked = json.loads(_json(settings))
        differences += [f"{key} {held_settings.get(key)!r} (asked {asked.get(key)!r})"
                        for key in sorted(set(asked) | set(held_settings)) if held_settings.get(key) != asked.get(key)]
    if differences:
        raise ValueError(f"{name} = {path!r} holds other work ({'; '.join(differences)}); refusing to overwrite it "
                         "(choose another path, or add --force to replace it)")


def _stored_settings(path: str) -> dict:
    """What identifies an archive's work beyond :func:`describe`: a train result's settings, a curve's ``what``."""
    with _reading(path) as f:
        if _attr_str(f, "kind") == "critical-curve":
            return {"what": _attr_str(f, "what")} if "what" in f.attrs else {}
        return _json_attr(f, "settings", dict) if "settings" in f.attrs else {}


def open_for_resume(path, kind: str, law: ContactLaw, params: Parameters, axes: dict, t_end, rtol, *,
                    resume: bool, force: bool = False, name: str = "out") -> tuple:
    """Open ``path`` for a grid's work: the archive's result to complete (``resume``) after checking that
    it holds the same work, or the overwrite rule (:func:`check_overwrite`); and the :class:`Checkpoint`
    that writes the new points in place.

    The resume protocol of every resumable command (``sweep``, ``atlas``: the kinds whose record is
    ``resumable``), in one call, before any work. Call it holding ``path``'s write lock
    (:func:`phaseimpact._atomic.exclusive`), as the work that follows writes the file.

    Parameters
    ----------
    path : str or path-like
        The archive to complete or write.
    kind, law, params, axes, t_end, rtol
        The work asked for, as for :func:`same_work` (``kind``: ``"sweep"`` or ``"atlas"``).
    resume : bool
        Complete the archive at ``path`` (missing: start it).
    force : bool, default False
        Replace any file (ignored by a resume, which replaces nothing).
    name : str, default "out"
        How the messages name ``path`` (the command line's option).

    Returns
    -------
    previous : SweepResult or None
        The archive's result (``previous=`` of :func:`~phaseimpact.continuation.atlas`); None when
        there is none to complete.
    checkpoint : Checkpoint
        The ``on_chunk`` that writes the points as they are computed.

    Raises
    ------
    ValueError
        With ``resume``: an archive of a kind that cannot be resumed, or of other work (the message
        lists the differences); without: what :func:`check_overwrite` refuses. A damaged or foreign
        file either way.

    Examples
    --------
    >>> import os, tempfile
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.archive import open_for_resume, save
    >>> from phaseimpact.continuation import sweep
    >>> s = sweep(seed_parameters(), "paper", [1e9, 1e13])
    >>> path = save(s, os.path.join(tempfile.mkdtemp(), "s.nc"))
    >>> previous, checkpoint = open_for_resume(path, "sweep", s.law, seed_parameters(), {"kappa": s.kappa}, None,
    ...                                        1e-10, resume=True)
    >>> int(previous.done.sum()), checkpoint.path == path
    (2, True)
    >>> open_for_resume(path, "sweep", s.law, seed_parameters(), {"kappa": s.kappa}, None, 1e-9, resume=True)
    Traceback (most recent call last):
    ...
    ValueError: resume: out = '...s.nc' holds other work (rtol 1e-10 (asked 1e-09)); give the options it was ...
    """
    path = os.fspath(path)
    previous = None
    if os.path.exists(path) and resume:
        held = describe(path)
        resumable = [record.name for record in REGISTRY.values() if record.resumable]
        if held["kind"] not in resumable:
            raise ValueError(f"{name} = {path!r} is a {held['kind']} archive, not a sweep or atlas: --resume cannot "
                             f"complete it (choose another --{name}, or drop --resume and add --force)")
        differences = same_work(held, kind, law, params, axes, t_end, rtol)
        if differences:
            raise ValueError(f"resume: {name} = {path!r} holds other work ({'; '.join(differences)}); "
                             "give the options it was computed with, or drop --resume")
        previous = load(path)
    elif os.path.exists(path):
        check_overwrite(path, kind, law, params, axes, t_end, rtol, force=force, name=name)
    return previous, Checkpoint(path, force=force)  # writes only the new points, in place
