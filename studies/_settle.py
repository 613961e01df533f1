"""Regenerated files replace the committed ones only when their content differs beyond a tolerance.

Another machine (another NumPy, SciPy, numba, CPU or BLAS) reproduces the studies' numbers to their
last bits only, so ``make reproduce`` writes each study's files into a staging folder and then
:func:`settle` moves into ``figures/`` only those that differ from the file already there by more
than what last-bit differences make; the others are dropped and the committed bytes stay (a clean
checkout stays clean). What is "the same within tolerance" (:func:`equivalent`):

- HDF5 archives: the same groups, datasets, shapes, dtypes and attributes; floating-point values
  within ``RTOL`` relative, or ``RTOL`` times the dataset's largest magnitude (values near zero),
  NaN where NaN; integers, strings and references equal; texts with numbers as for tables;
  attributes named ``*digest`` or ``*sha256``, ``created`` and ``history`` are not compared (they follow the
  data, or say when, not what).
- Values that a study declares sensitive to last-bit differences: an archive whose attribute
  ``last_bit_sensitive`` names datasets (separated by spaces) and ``last_bit_mask`` a boolean dataset
  whose shape is their leading shape (why: ``last_bit_reason``) has those datasets compared only
  where neither archive's mask is true; the mask itself is compared exactly unless it is among the
  names (a mask the run estimates, which last bits move as well). Where only masked values differ,
  the figures the archive names in ``drawn_in`` (paths under the target folder, drawn from those
  values) keep their committed files too.
- Tables and other texts (``.md``, ``.txt``, ``.json``, ``.csv``): equal apart from numbers, each
  within ``RTOL`` relative, or printed with the same digits and one unit of the last apart (a
  rounding flip).
- PNG figures: the same size, no channel of any pixel more than ``PIXEL_LEVELS`` of 255 apart. A PDF
  beside a PNG of the same name is the same drawing: it is kept or replaced with its PNG.
- Anything else: equal bytes.
"""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

import numpy as np

#: Relative tolerance of archived and printed numbers (last-bit differences are about 1e-16; the
#: largest measured between two machines was 1e-10).
RTOL = 1e-9
#: Largest difference of a PNG's channel, in levels of 255, that still counts as the same figure.
PIXEL_LEVELS = 2
TEXT_SUFFIXES = (".md", ".txt", ".json", ".csv")
#: Attributes that are not compared: digests follow the data compared, ``created`` and ``history`` say when.
_UNCOMPARED = re.compile(r"(.*digest|.*sha256|created|history)")
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _last_digit(text: str) -> tuple[int, float]:
    """Decimals of a printed number and the value of one unit of its last digit."""
    mantissa, _, exponent = text.lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    return decimals, 10.0 ** (int(exponent or 0) - decimals)


def _numbers_close(old: str, new: str) -> bool:
    """Within ``RTOL`` relative, or printed alike and one unit of the last digit apart (a rounding flip)."""
    a, b = float(old), float(new)
    if a == b or abs(a - b) <= RTOL * abs(a):
        return True
    if not any(mark in old.lower() for mark in ".e"):
        return False  # a count: no rounding to flip
    (decimals, unit), (new_decimals, _) = _last_digit(old), _last_digit(new)
    alike = decimals == new_decimals and ("e" in old.lower()) == ("e" in new.lower())
    return alike and abs(a - b) <= unit * (1 + 1e-9)


def texts_equivalent(old: str, new: str) -> bool:
    """Equal apart from numbers, each within ``RTOL``, or printed alike and one unit of its last digit apart."""
    if _NUMBER.sub("#", old) != _NUMBER.sub("#", new):
        return False
    return all(_numbers_close(a, b) for a, b in zip(_NUMBER.findall(old), _NUMBER.findall(new), strict=True))


def arrays_equivalent(old, new) -> bool:
    """Same shape and dtype; floats within ``RTOL`` (relative, or of the largest magnitude), else equal."""
    old, new = np.asarray(old), np.asarray(new)
    if old.shape != new.shape or old.dtype != new.dtype:
        return False
    if old.dtype.kind in "fc":
        finite = np.isfinite(old)
        scale = float(np.max(np.abs(old[finite]))) if finite.any() else 0.0
        return bool(np.allclose(new, old, rtol=RTOL, atol=RTOL * scale, equal_nan=True))
    if old.dtype.kind == "O":
        return all(_values_equivalent(a, b) for a, b in zip(old.ravel(), new.ravel(), strict=True))
    return bool(np.array_equal(old, new))


def _values_equivalent(old, new) -> bool:
    if isinstance(old, bytes) and isinstance(new, bytes):
        old, new = old.decode("utf-8", "replace"), new.decode("utf-8", "replace")
    if isinstance(old, str) and isinstance(new, str):
        return texts_equivalent(old, new)
    if type(old).__name__ == "Reference" or type(new).__name__ == "Reference":
        return str(old) == str(new)  # resolved to names by the caller where it matters
    if isinstance(old, (np.ndarray, list, tuple, float, int, np.generic)):
        return arrays_equivalent(old, new)
    return old == new


def _declared(f, name: str) -> str:
    value = f.attrs.get(name, "")
    return value.decode() if isinstance(value, bytes) else str(value)


def _unmasked(old, new) -> tuple[tuple[str, ...], np.ndarray | None]:
    """The declared last-bit-sensitive datasets and where neither archive's mask marks them (None
    where the declaration does not hold: a mask missing, not boolean or not their leading shape)."""
    sensitive, mask = tuple(_declared(new, "last_bit_sensitive").split()), _declared(new, "last_bit_mask")
    if not sensitive or not all(name in f for f in (old, new) for name in (*sensitive, mask)):
        return (), None
    masks = old[mask][()], new[mask][()]
    shape = masks[0].shape
    if any(m.dtype != bool or m.shape != shape for m in masks) or any(
            f[name].shape[:len(shape)] != shape for f in (old, new) for name in sensitive):
        return (), None
    return sensitive, ~(masks[0] | masks[1])


def _h5_equivalent(old_path: Path, new_path: Path, masked: bool = True) -> bool:
    """Equivalent archives; ``masked``: the declared last-bit-sensitive values are not compared."""
    import h5py

    def resolve(f, value):
        """References as the names of what they point at (their addresses differ between files)."""
        if isinstance(value, h5py.Reference):
            return f[value].name if value else None
        if isinstance(value, np.ndarray) and value.dtype.names:  # e.g. REFERENCE_LIST: (reference, index)
            return [tuple(resolve(f, field) for field in row) for row in value.ravel()]
        if isinstance(value, np.ndarray) and value.dtype.kind == "O":
            return [resolve(f, v) for v in value.ravel()]
        return value

    def attributes(f, obj):
        return {name: resolve(f, obj.attrs[name]) for name in obj.attrs if not _UNCOMPARED.fullmatch(name)}

    def tree(f):
        items = {"/": f}
        f.visititems(lambda name, obj: items.__setitem__(name, obj))
        return items

    with h5py.File(old_path, "r") as old, h5py.File(new_path, "r") as new:
        a, b = tree(old), tree(new)
        if a.keys() != b.keys():
            return False
        sensitive, unmasked = _unmasked(old, new) if masked else ((), None)
        for name, obj in a.items():
            other = b[name]
            if isinstance(obj, h5py.Dataset) != isinstance(other, h5py.Dataset):
                return False
            old_attrs, new_attrs = attributes(old, obj), attributes(new, other)
            if old_attrs.keys() != new_attrs.keys():
                return False
            if not all(_values_equivalent(old_attrs[k], new_attrs[k]) for k in old_attrs):
                return False
            if isinstance(obj, h5py.Dataset):
                if obj.dtype.kind == "O" or h5py.check_dtype(ref=obj.dtype):
                    if not _values_equivalent(np.asarray(resolve(old, obj[()]), dtype=object),
                                              np.asarray(resolve(new, other[()]), dtype=object)):
                        return False
                elif name in sensitive:
                    if not arrays_equivalent(obj[()][unmasked], other[()][unmasked]):
                        return False
                elif not arrays_equivalent(obj[()], other[()]):
                    return False
    return True


def _drawn_in(path: Path) -> list[str]:
    """The figures an archive says are drawn from its last-bit-sensitive values (``drawn_in``)."""
    import h5py

    try:
        with h5py.File(path, "r") as f:
            return _declared(f, "drawn_in").split() if _declared(f, "last_bit_sensitive") else []
    except OSError:
        return []


def _png_equivalent(old_path: Path, new_path: Path) -> bool:
    from matplotlib.image import imread

    old, new = imread(old_path), imread(new_path)
    if old.shape != new.shape:
        return False
    return float(np.max(np.abs(old.astype(float) - new.astype(float)), initial=0.0)) <= PIXEL_LEVELS / 255 + 1e-6


def equivalent(old_path, new_path) -> bool:
    """Whether ``new_path`` has the content of ``old_path`` within the tolerance (module docstring)."""
    old_path, new_path = Path(old_path), Path(new_path)
    if old_path.read_bytes() == new_path.read_bytes():
        return True
    suffix = old_path.suffix.lower()
    try:
        if suffix == ".h5":
            return _h5_equivalent(old_path, new_path)
        if suffix == ".png":
            return _png_equivalent(old_path, new_path)
        if suffix in TEXT_SUFFIXES:
            return texts_equivalent(old_path.read_text(encoding="utf-8"), new_path.read_text(encoding="utf-8"))
    except (OSError, ValueError, UnicodeDecodeError):
        return False  # unreadable as its kind: replaced, so the new file is what stays
    return False


def settle(staging, target) -> list[str]:
    """Move the files under ``staging`` into ``target`` where they differ from the file there beyond the
    tolerance (or it is missing); drop the others. Returns the replaced files, relative to ``target``."""
    staging, target = Path(staging), Path(target)
    staged = sorted(p for p in staging.rglob("*") if p.is_file())
    replace = {}
    kept_drawings = []
    for path in staged:
        relative = path.relative_to(staging)
        if path.suffix.lower() == ".pdf" and path.with_suffix(".png") in staged:
            continue  # decided with its PNG below
        old = target / relative
        replace[relative] = not old.exists() or not equivalent(old, path)
        if not replace[relative] and path.suffix.lower() == ".h5" and not _h5_equivalent(old, path, masked=False):
            kept_drawings.extend(Path(name) for name in _drawn_in(path))  # only its sensitive values moved
    for relative in kept_drawings:
        if relative in replace and (target / relative).exists():
            replace[relative] = False
    for path in staged:
        relative = path.relative_to(staging)
        if path.suffix.lower() == ".pdf" and path.with_suffix(".png") in staged:
            png = relative.with_suffix(".png")
            replace[relative] = replace[png] or not (target / relative).exists()
    changed = []
    for relative, new in sorted(replace.items()):
        if new:
            (target / relative).parent.mkdir(parents=True, exist_ok=True)
            shutil.move(os.fspath(staging / relative), os.fspath(target / relative))
            changed.append(relative.as_posix())
    shutil.rmtree(staging, ignore_errors=True)
    return changed


__all__ = ["RTOL", "PIXEL_LEVELS", "equivalent", "settle", "texts_equivalent", "arrays_equivalent"]
