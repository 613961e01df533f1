"""Digests and checks of what HDF5's own checksums leave out: ``text_sha256`` (the text attributes),
``data_sha256`` (each dataset's contents, in pieces so that a checkpoint hashes again only what it
wrote), the chunk index (:func:`_check_storage`), and the fingerprint of a sweep's extras."""

from __future__ import annotations

import hashlib
import itertools
import json

import h5py
import numpy as np

from ._common import (
    _DATA_DIGEST,
    _DIGEST_PIECE,
    _IN_PROGRESS,
    _TEXT_DIGEST,
    _attr_str,
    _Damaged,
    _json,
    _netcdf_writer,
    _short,
)


def _digest(tree) -> str:
    """A fingerprint of ``SweepResult.extras`` (a checkpoint rewrites the file when they change)."""
    h = hashlib.sha256()

    def walk(obj, key):
        h.update(key.encode())
        if isinstance(obj, dict):
            for k in sorted(obj, key=str):
                walk(obj[k], f"{key}/{k}")
        elif isinstance(obj, np.ndarray):
            h.update(f"{obj.dtype.str}{obj.shape}".encode())
            h.update(np.ascontiguousarray(obj).tobytes())
        else:
            h.update(_json(obj).encode())

    walk(tree, "")
    return h.hexdigest()


# ------------------------------------------------------------------------------------------------
# Writing whole files


def _texts_digest(f) -> str:
    """SHA-256 of the text attributes :func:`load` reads: the root's (but the digests') and those of
    ``/extras`` (object path, name, value)."""
    h = hashlib.sha256()

    def add(name, node):
        # not netCDF's reserved attributes (_NCProperties): the library's; not the data digests, which a
        # checkpoint rewrites in place (they protect themselves: a changed one matches no data)
        for key in sorted(node.attrs):
            value = node.attrs[key] if key not in (_TEXT_DIGEST, _DATA_DIGEST) and not key.startswith("_") else None
            if isinstance(value, bytes):  # netCDF4 (xarray's re-save) writes texts as fixed-length bytes
                value = value.decode("utf-8", "replace")
            if isinstance(value, str):
                h.update(json.dumps([name, key, value]).encode())

    add("/", f)
    if "extras" in f:
        add("extras", f["extras"])
        f["extras"].visititems(add)
    return h.hexdigest()


def _piece_digests(data: np.ndarray) -> list:
    """SHA-256 of each :data:`_DIGEST_PIECE` elements of ``data`` in C order (its bytes as stored)."""
    flat = np.ascontiguousarray(data).reshape(-1)
    if flat.dtype.kind not in "biufc":  # text: its characters, not the addresses of Python objects
        flat = np.array([_json(x.decode() if isinstance(x, bytes) else x) for x in flat.tolist()], dtype=str)
    else:  # the values, whatever the byte order a writer chose (xarray's copy may store big-endian)
        flat = flat.astype(flat.dtype.newbyteorder("<"), copy=False)
    return [hashlib.sha256(flat[i:i + _DIGEST_PIECE].tobytes()).digest()
            for i in range(0, max(flat.size, 1), _DIGEST_PIECE)]


def _little_endian(dtype) -> np.dtype:
    dtype = np.dtype(dtype)
    return dtype.newbyteorder("<") if dtype.kind in "biufc" else dtype


def _dataset_digest(dtype, shape, pieces) -> str:
    """A dataset's digest: of its type, shape and the digests of its pieces; whatever its chunks or filters."""
    h = hashlib.sha256(_json([_little_endian(dtype).str, list(shape)]).encode())
    for piece in pieces:
        h.update(piece)
    return h.hexdigest()


def _file_pieces(f) -> dict:
    """``{path: (dtype, shape, piece digests)}`` of every dataset of the open file ``f`` (each is read whole)."""
    found = {}

    def visit(name, node):
        if isinstance(node, h5py.Dataset):
            found[name] = (node.dtype, node.shape, _piece_digests(node[()]))

    f.visititems(visit)
    return found


def _digests_text(pieces: dict) -> str:
    digests = {name: _dataset_digest(*entry) for name, entry in pieces.items()}
    return json.dumps(digests, sort_keys=True, separators=(",", ":")).ljust(len(_IN_PROGRESS))


def _stored_digests(f) -> dict | None:
    """The digests :data:`_DATA_DIGEST` holds; None where the file has none to check against (written before
    data digests, or killed while a checkpoint wrote in place)."""
    if _DATA_DIGEST not in f.attrs:
        return None
    value = f.attrs[_DATA_DIGEST]
    try:
        stored = json.loads(value.decode("ascii") if isinstance(value, bytes) else value)
    except (TypeError, ValueError, AttributeError):
        stored = None
    if stored == json.loads(_IN_PROGRESS):
        return None
    if not (isinstance(stored, dict) and all(isinstance(v, str) for v in stored.values())):
        raise _Damaged(f"attribute {_DATA_DIGEST} = {_short(value)} is out of range; allowed: the SHA-256 digests "
                       "of the datasets")
    return stored


def _check_data_digests(f) -> None:
    """Every dataset's contents against :data:`_DATA_DIGEST`, where the file has it. Not in a copy that
    another netCDF writer made (xarray's ``to_netcdf``): it carries the attribute over, but a subset or a
    re-encoding is not the data it was computed from; such a copy is checked by its content alone."""
    stored = _stored_digests(f)
    if stored is None or _netcdf_writer(f) is not None:
        return
    pieces = _file_pieces(f)
    for name in sorted(set(stored) | set(pieces)):
        if name not in pieces:
            raise _Damaged(f"variable {name} is missing")
        if name not in stored:
            raise _Damaged(f"variable {name} has no SHA-256 digest in {_DATA_DIGEST} (it was added after the file "
                           "was written)")
        if stored[name] != _dataset_digest(*pieces[name]):
            # checksum: a reader may catch a checkpoint writing in place; read again, as for Fletcher-32
            raise _Damaged(f"variable {name}: its contents do not match their SHA-256 digest {_DATA_DIGEST} (the "
                           "file's bytes were changed after it was written)", checksum=True)


def _check_metadata(f, *, data: bool = True) -> None:
    """The parts of the metadata that HDF5's own checksums leave out: the text attributes (against
    :data:`_TEXT_DIGEST`, where the file has one); with ``data``, the chunk index of every checksummed
    dataset and every dataset's contents (against :data:`_DATA_DIGEST`, where the file has it)."""
    if _TEXT_DIGEST in f.attrs and _attr_str(f, _TEXT_DIGEST) != _texts_digest(f):
        raise _Damaged("its text attributes (case, law, settings, ...) do not match their SHA-256 digest "
                       f"{_TEXT_DIGEST} (the file's bytes were changed)")
    if data:
        _check_storage(f)
        _check_data_digests(f)


def _check_storage(f) -> None:
    """Each chunk of each checksummed dataset is found by its coordinates where HDF5's index says, whole,
    filtered, inside the file and apart from every other chunk. The index (a v1 B-tree) has no checksum:
    a changed key or address would read another dataset's chunk, or nothing, as this one's data."""
    end = f.id.get_filesize()
    spans = []

    def visit(name, node):
        if not isinstance(node, h5py.Dataset) or node.chunks is None or node.size == 0 or not node.fletcher32:
            return
        size = int(np.prod(node.chunks)) * node.dtype.itemsize + 4  # the data and its Fletcher-32 sum
        listed = []
        node.id.chunk_iter(listed.append)  # the chunks found by walking the index
        corners = list(itertools.product(*(range(0, n, c) for n, c in zip(node.shape, node.chunks, strict=True))))
        if sorted(tuple(info.chunk_offset) for info in listed) != corners:
            raise _Damaged(f"variable {name}: its chunk index does not list each chunk once")
        for info in listed:
            try:  # and found by looking each up, as a read does (which compares every field of the keys)
                mask, raw = node.id.read_direct_chunk(info.chunk_offset)
            except (OSError, RuntimeError, ValueError):
                mask, raw = None, b""
            if (info.filter_mask != 0 or info.size != size or mask != 0 or len(raw) != size
                    or info.byte_offset + info.size > end):
                raise _Damaged(f"variable {name}: the index entry of its chunk at {tuple(info.chunk_offset)} is "
                               "damaged")
            spans.append((info.byte_offset, info.size, name))

    f.visititems(visit)
    spans.sort()
    for (a, size, name), (b, _, other) in zip(spans, spans[1:], strict=False):
        if a + size > b:
            raise _Damaged(f"variables {name} and {other}: chunks overlap in the file (a damaged chunk index)")


def _verified(read):
    """``read(f)`` of a kind new in schema 5 as a registry reader ``(f, version)``: the result, then the
    check of the file's digests and chunk index."""
    def read_checked(f, version: int):
        result = read(f)
        _check_metadata(f)
        return result

    return read_checked
