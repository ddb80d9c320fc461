"""Run records of a study in one NetCDF4 file: one group per record, readable by plain xarray.

A *record* is a dict of what a study keeps of one run: arrays (time series,
tip positions), scalars (CPU time, status, message) and nested dicts of
either (an energy log, work counters). :func:`save_records` writes a list of
them; :func:`load_records` gives the same list back, arrays bit for bit. The
file opens without ancfdae: ``xarray.open_datatree(path)`` shows one group
``record_0000, record_0001, ...`` per record, each array a variable named
by its key path (``energy.total``), the scalars in the JSON attribute
``scalars``.
"""
from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from ._resultfile import ENGINE, ResultFileError, _jsonable

__all__ = ["save_records", "load_records", "RECORDS_FORMAT"]

#: Format tag of a records file (root attribute ``format``).
RECORDS_FORMAT = "ancfdae.Records/1"


def _split(record: dict, prefix: str, arrays: dict, scalars: dict) -> None:
    for key, value in record.items():
        if not isinstance(key, str) or "." in key or "/" in key:
            raise ValueError(f"record keys must be strings without '.' or '/', got {key!r}.")
        name = prefix + key
        if isinstance(value, dict):
            sub: dict = {}
            scalars[key] = sub
            _split(value, name + ".", arrays, sub)
            if not sub:
                del scalars[key]
            if not value:
                scalars[key] = {}
        elif isinstance(value, np.ndarray) and value.dtype.kind in "fiub":
            arrays[name] = value
        else:
            scalars[key] = _jsonable(value)


def _dataset(record: dict):
    import xarray as xr
    arrays: dict = {}
    scalars: dict = {}
    _split(record, "", arrays, scalars)
    data = {name: ([f"{name}_dim{k}" for k in range(a.ndim)], a) for name, a in arrays.items()}
    return xr.Dataset(data, attrs={"scalars": json.dumps(scalars, allow_nan=True),
                                   "arrays": json.dumps(sorted(arrays))})


def save_records(records: list[dict], path: str | os.PathLike, engine: str = ENGINE) -> Path:
    """Write run records to one NetCDF4 file.

    Parameters
    ----------
    records : list of dict
        Keys are strings; values are numeric numpy arrays, JSON-able scalars
        or lists, or dicts of the same (nested to any depth).
    path : str or path-like
        The file (``.nc`` added unless it ends in .nc, .nc4 or .h5);
        replaced if it exists.
    engine : {"netcdf4", "h5netcdf"}
        xarray's writer.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    import xarray as xr
    path = Path(path)
    if path.suffix not in (".nc", ".nc4", ".h5"):
        path = path.with_name(path.name + ".nc")
    if not isinstance(records, (list, tuple)) or not all(isinstance(r, dict) for r in records):
        raise TypeError(f"`records` must be a list of dicts, got {type(records).__name__}.")
    datasets = [_dataset(r) for r in records]   # validate all before touching the file
    xr.Dataset(attrs={"format": RECORDS_FORMAT, "count": len(records)}).to_netcdf(path, mode="w", engine=engine)
    for i, ds in enumerate(datasets):
        ds.to_netcdf(path, mode="a", group=f"record_{i:04d}", engine=engine)
    return path


def _set(tree: dict, dotted: str, value: Any) -> None:
    *parents, leaf = dotted.split(".")
    for p in parents:
        node = tree.get(p)
        if not isinstance(node, dict):
            node = tree[p] = {}
        tree = node
    tree[leaf] = value


def load_records(path: str | os.PathLike) -> list[dict]:
    """Read the records written by :func:`save_records`.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    list of dict
        The records, arrays bit for bit; tuples come back as lists.

    Raises
    ------
    ResultFileError
        Naming the file, if it is missing, not NetCDF4 or not a records file.
    """
    import xarray as xr
    path = Path(path)
    if not path.is_file():
        raise ResultFileError(f"{path}: no such records file.")
    try:
        with xr.open_dataset(path, engine=ENGINE) as root:
            fmt, count = root.attrs.get("format"), root.attrs.get("count")
    except Exception as exc:
        raise ResultFileError(f"{path}: not a readable NetCDF4/HDF5 file ({type(exc).__name__}: {exc}).") from exc
    if fmt != RECORDS_FORMAT:
        raise ResultFileError(f"{path}: not an ancfdae records file (attribute 'format' is {fmt!r}, expected "
                              f"{RECORDS_FORMAT!r}).")
    records = []
    for i in range(int(count)):
        try:
            with xr.open_dataset(path, group=f"record_{i:04d}", engine=ENGINE) as ds:
                ds.load()
                record = json.loads(ds.attrs["scalars"])
                for name in json.loads(ds.attrs["arrays"]):
                    _set(record, name, ds[name].values)
        except Exception as exc:
            raise ResultFileError(f"{path}: damaged records file: record {i} of {count} "
                                  f"({type(exc).__name__}: {exc}).") from exc
        records.append(record)
    return records
