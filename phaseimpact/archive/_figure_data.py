"""The data behind a study's figure, written to HDF5 (:func:`save_h5`): the studies' plain
``{name: (array, units)}`` files in ``figures/data/``, beside the figures :mod:`phaseimpact.plotting`
draws; public as ``phaseimpact.archive.save_h5``.
"""

from __future__ import annotations

import numpy as np

from .._atomic import atomic_path

__all__ = ["save_h5"]


def save_h5(path, datasets: dict, attrs: dict | None = None):
    """Write ``{name: (array, units)}`` to HDF5 ``path`` atomically (temp file, then ``os.replace``).

    Names may contain ``/`` for groups; ``attrs`` go on the root (strings or numbers).

    Parameters
    ----------
    path : str or path-like
        The file to write.
    datasets : dict
        ``{name: (array, units)}``; strings are stored as bytes, arrays of more than 64 elements
        gzip-compressed; ``units`` becomes each dataset's attribute.
    attrs : dict, optional
        Root attributes.

    Returns
    -------
    str or path-like
        ``path``.

    Raises
    ------
    ValueError
        For a path that cannot be written or another process writing it.

    Examples
    --------
    >>> import os, tempfile
    >>> import h5py, numpy as np
    >>> from phaseimpact.archive import save_h5
    >>> path = save_h5(os.path.join(tempfile.mkdtemp(), "data.h5"),
    ...                {"t": (np.linspace(0, 1e-3, 5), "s"), "runs/law": (["paper", "abrate"], "1")},
    ...                {"case": "seed"})
    >>> with h5py.File(path) as f:
    ...     print(sorted(f), f["t"].attrs["units"], f["runs/law"][()].tolist(), f.attrs["case"])
    ['runs', 't'] s [b'paper', b'abrate'] seed
    """
    import h5py

    with atomic_path(path) as tmp, h5py.File(tmp, "w") as f:
        for key, value in (attrs or {}).items():
            f.attrs[key] = value
        for name, (data, units) in datasets.items():
            arr = np.asarray(data)
            if arr.dtype == object or arr.dtype.kind == "U":
                arr = arr.astype("S")
            ds = f.create_dataset(name, data=arr, compression="gzip" if arr.size > 64 else None)
            ds.attrs["units"] = units
    return path
