"""Integrity of result files: checksums written with every file and verified on every load.

Two layers, so that no single damaged byte of a file is read back as different data:

* every numeric variable is stored with HDF5's Fletcher-32 filter (both the netCDF4 and the
  h5netcdf engine write it; the HDF5 library verifies it when the data are read, so a changed byte of
  an array makes the read fail instead of returning other numbers);
* what Fletcher-32 does not cover -- the global attributes (status, message, the JSON texts of
  stats, options and the model description), each variable's name, dimensions, shape, type and
  attributes, and the values of the text variables (the coordinate labels) -- is hashed per item
  (SHA-256) into the global attribute ``checksums``; :func:`verify` recomputes the hashes after the
  load and names the first item that differs.

The module works on :class:`xarray.Dataset` objects only; :mod:`ancfdae._resultfile` calls it.
"""
from __future__ import annotations

import hashlib
import json
import math

import numpy as np

__all__ = ["CHECKSUM_ATTR", "encoding", "checksums", "verify"]

#: Global attribute holding the JSON ``{item: sha256 prefix}`` of :func:`checksums`.
CHECKSUM_ATTR = "checksums"
_HEX = 24          # hex digits kept per item (96 bits: a chance collision is out of reach)
_CHUNK_BYTES = 1 << 20     # HDF5 chunks of up to 1 MiB (its default chunk cache; the limit is 4 GiB)


def _numeric(dtype) -> bool:
    return np.dtype(dtype).kind in "biuf"


def encoding(ds) -> dict:
    """The ``encoding`` for ``Dataset.to_netcdf``: Fletcher-32 on every numeric variable.

    Text variables are left out: HDF5 applies no filter to variable-length strings (netCDF4 ignores
    the request, h5netcdf refuses it); :func:`checksums` covers them.
    """
    # one chunk per variable (up to _CHUNK_BYTES per chunk): the default chunking of a filtered variable
    # splits a 16 MB array into many small chunks, each with its own index entry and checksum
    out = {}
    for name, var in ds.variables.items():
        if _numeric(var.dtype):
            out[name] = {"fletcher32": True, "chunksizes": _chunks(var.shape, var.dtype.itemsize)}
    return out


def _chunks(shape, itemsize) -> tuple:
    """Whole rows per chunk, as many as fit in _CHUNK_BYTES (at least one entry along every axis)."""
    shape = tuple(max(1, int(n)) for n in shape)
    if not shape:
        return ()
    row = itemsize * int(np.prod(shape[1:], dtype=np.int64))
    return (max(1, min(shape[0], _CHUNK_BYTES // max(row, 1))),) + shape[1:]


def _plain(value):
    """A JSON-stable form of an attribute value as written and as read back (numpy types, NaN)."""
    if isinstance(value, np.ndarray):
        return [_plain(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        return "nan" if math.isnan(value) else repr(value)
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    return value


def _kind(dtype) -> str:
    dtype = np.dtype(dtype)
    return "text" if dtype.kind in "OUS" else f"{dtype.kind}{dtype.itemsize}"


def _hash(obj) -> str:
    text = json.dumps(obj, sort_keys=True, ensure_ascii=True)
    return hashlib.sha256(text.encode()).hexdigest()[:_HEX]


def checksums(ds) -> dict:
    """``{item: hash}`` of every global attribute (``"attribute NAME"``) and every variable's layout.

    A variable's item (``"variable NAME"``) hashes its dimensions, shape, type and attributes, and
    for text variables their values (numeric values are Fletcher-32's job). The attribute
    :data:`CHECKSUM_ATTR` itself is left out.
    """
    out = {}
    for key, value in ds.attrs.items():
        if key != CHECKSUM_ATTR:
            out[f"attribute {key}"] = _hash([key, _plain(value)])
    for name, var in ds.variables.items():
        entry = {"dims": list(var.dims), "shape": list(var.shape), "kind": _kind(var.dtype),
                 "attrs": {k: _plain(v) for k, v in var.attrs.items()}}
        if not _numeric(var.dtype):
            entry["values"] = [str(v) for v in np.asarray(var.values).ravel().tolist()]
        out[f"variable {name}"] = _hash([name, entry])
    return out


def verify(ds, path) -> str | None:
    """What is wrong with the loaded dataset ``ds`` of file ``path``, or None when every check holds.

    Checks that every numeric variable carries Fletcher-32 (the data were verified while loading)
    and that the per-item hashes of :func:`checksums` match the stored ones; the message names the
    first item that does not.
    """
    stored_text = ds.attrs.get(CHECKSUM_ATTR)
    if not isinstance(stored_text, str):
        return f"the attribute {CHECKSUM_ATTR!r} (the checksums of attributes and layout) is missing"
    try:
        stored = json.loads(stored_text)
    except ValueError:
        stored = None
    if not isinstance(stored, dict):
        return f"the attribute {CHECKSUM_ATTR!r} is damaged (not a JSON object)"
    for name, var in ds.variables.items():
        if _numeric(var.dtype) and not var.encoding.get("fletcher32"):
            return f"variable {name!r} carries no Fletcher-32 checksum"
    now = checksums(ds)
    for item in sorted(set(stored) | set(now)):
        kind, _, name = item.partition(" ")
        if item not in now:
            return f"{kind} {name!r} is missing (it was written)"
        if item not in stored:
            return f"{kind} {name!r} was not written by ancfdae (it has no stored checksum)"
        if stored[item] != now[item]:
            return f"{kind} {name!r} does not match its stored checksum"
    return None
