"""Result files: NetCDF4/HDF5 through xarray, readable without ancfdae.

Layout of a file (format ``ancfdae.Result/3``)
----------------------------------------------
Dimensions ``time`` (outputs) and ``dof`` (free coordinates), with the
coordinates ``time``, ``node`` (node index of each coordinate) and
``coordinate`` (its name, e.g. ``x``, ``y'``, ``theta``). Variables ``q``,
``v``, ``a`` ``(time, dof)``; each monitor array as ``monitor.NAME.KEY``
(first dimension ``time`` when it has one entry per output; attributes
``monitor`` and ``key`` hold the exact names); each array of
``Result.model_state`` as ``state.KEY`` (attribute ``state``). Global attributes: ``format``,
``status``, ``message``, ``method``, ``t_fail``, the JSON texts ``stats``,
``options``, ``monitor_scalars`` and ``model`` (the beam description), and
readable copies ``element``, ``formulation``, ``material``, ``section``,
``loads``, ``unit_system``; the mesh also as the variables ``reference_nodes``
``(mesh_node, space)`` and ``element_nodes`` ``(element, element_node)``.

Integrity (new in format 3)
---------------------------
Every numeric variable carries HDF5's Fletcher-32 checksum and the global attribute
``checksums`` hashes the attributes, the layout and the text variables
(:mod:`ancfdae._filecheck`); on load the dimensions are also checked against the stored beam
description (``n_dof``, the coordinate labels, the mesh). A damaged file raises
:class:`ResultFileError` naming the file and the variable or attribute, never loads other values.
Files are written to a temporary name in the target folder and renamed, so a killed writer leaves
no half file under the final name. Format-2 files (no checksums) are still read. Cost, measured
(``python benchmarks/result_checksums.py 10000 200 5``, medians of interleaved runs on the shared
machine): for 10,000 outputs x 200 coordinates, write 1.22 s against 0.48 s without checksums,
read 1.13 s against 0.58 s, 4.8 % larger (chunks of 1 MiB); for 200 x 50, 1.5 and 1.4 times.

Engine
------
netCDF4 (the Unidata library's bindings) is the default. Measured on the
shared 2-core machine (``python benchmarks/result_io.py N_OUT N_DOF REPEATS``,
medians of interleaved runs, write = ``Result.save``, read = open + load +
``Result``): for 10,000 outputs x 200 coordinates (q, v, a: 48 MB of float64)
netCDF4 wrote in 0.019-0.033 s and read in 0.023-0.045 s, h5netcdf (through
h5py) in 0.062-0.104 s and 0.049-0.096 s; for 200 x 50, 0.018/0.013 s against
0.083/0.085 s. Files are of equal size (48.3 MB, uncompressed) and both
engines round-trip bit-exact. ``engine="h5netcdf"`` still writes (if h5netcdf
and h5py are installed), and files of either engine read with the other.
"""
from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np

from . import _filecheck

__all__ = ["ResultFileError", "FORMAT", "ENGINE", "FIELDS", "describe_model", "to_dataset", "from_dataset", "write",
           "read"]

#: Format tag written into every result file.
FORMAT = "ancfdae.Result/3"
#: Earlier formats still read: format 2 is format 3 without the checksums.
_LEGACY = ("ancfdae.Result/2",)
#: xarray engine used to write (see the module docstring for the measurement).
ENGINE = "netcdf4"
#: The fields of a result, as :func:`to_dataset` takes them and :func:`from_dataset` returns them
#: (the attributes of :class:`ancfdae.Result`, which this module does not import: it reads and
#: writes fields, and ``Result.load`` builds the object).
FIELDS = ("t", "q", "v", "a", "status", "message", "stats", "monitors", "t_fail", "method", "options",
          "model_state", "model", "lam")
_SUFFIXES = (".nc", ".nc4", ".h5")
_UNITS = ("The model's consistent unit system (the studies use SI: m, s, kg); coordinate units per `dof`: "
          "positions length, slope coordinates 1, theta rad.")


class ResultFileError(ValueError):
    """A file is not a readable ancfdae result: damaged, truncated, foreign or of an old format."""


def _jsonable(obj):
    """Convert numpy scalars and arrays (also inside containers) to plain Python for json."""
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return obj


def _dump(obj, what: str = "value") -> str:
    # allow_nan keeps NaN/inf statistics (e.g. a drift of an empty run); json reads them back.
    try:
        return json.dumps(_jsonable(obj), allow_nan=True)
    except TypeError as exc:
        raise ValueError(f"Result.{what} must be JSON-able to be saved: {exc}.") from None


def describe_model(model) -> dict:
    """``model.describe()`` plus ``"dof_labels"`` from ``model.dof_labels()``, or ``{}``.

    Both methods are optional for a model; a model with neither gives an
    empty dict and its result file labels the coordinates ``q0, q1, ...``.
    """
    describe = getattr(model, "describe", None)
    record = dict(describe()) if callable(describe) else {}
    labels = getattr(model, "dof_labels", None)
    if callable(labels):
        node, coordinate = labels()
        record["dof_labels"] = {"node": [int(i) for i in node], "coordinate": [str(c) for c in coordinate]}
    return record


def _dof_labels(fields) -> tuple[np.ndarray, np.ndarray]:
    n = fields["q"].shape[1]
    labels = fields["model"].get("dof_labels") if fields["model"] else None
    if labels is not None and len(labels["node"]) == n:
        return np.asarray(labels["node"], dtype=np.int64), np.asarray(labels["coordinate"], dtype=str)
    return np.full(n, -1, dtype=np.int64), np.array([f"q{i}" for i in range(n)], dtype=str)


def _array_var(name, value, n_t):
    """(dims, data) of an array variable; its first axis is ``time`` when it has one entry per output."""
    value = np.asarray(value)
    dims = [f"{name}_dim{k}" for k in range(value.ndim)]
    if value.ndim and value.shape[0] == n_t:
        dims[0] = "time"
    return tuple(dims), value


def _var_name(name: str, taken) -> str:
    """A NetCDF variable name ('/' is the group separator); the true names live in its attributes."""
    name = name.replace("/", "_")
    while name in taken:
        name += "_"
    return name


def to_dataset(fields):
    """The :class:`xarray.Dataset` of a result's fields (what :meth:`Result.save` writes).

    Parameters
    ----------
    fields : mapping
        ``{name: value}`` for every name of :data:`FIELDS`, as held by a
        :class:`ancfdae.Result` (arrays time-major, ``stats``, ``options``
        and ``model`` JSON-able).

    Returns
    -------
    xarray.Dataset
    """
    import xarray as xr     # imported on first use: it adds 1.5-2 s to `import ancfdae` (measured)
    n_t = fields["t"].size
    node, coord = _dof_labels(fields)
    data = {name: (("time", "dof"), fields[name]) for name in ("q", "v", "a")}
    lam = fields.get("lam")
    if lam is not None and lam.shape[1] > 0:    # a constrained model's multipliers
        data["lam"] = (("time", "constraint"), lam, {"long_name": "multipliers (reactions -G^T lam)"})
    scalars: dict = {}
    for name, log in fields["monitors"].items():
        scalars[name] = {}
        for key, value in log.items():
            if isinstance(value, np.ndarray):
                var = _var_name(f"monitor.{name}.{key}", data)
                data[var] = _array_var(var, value, n_t) + ({"monitor": name, "key": key},)
            else:
                scalars[name][key] = value
    for key, value in fields["model_state"].items():
        var = _var_name(f"state.{key}", data)
        data[var] = _array_var(var, value, n_t) + ({"state": key},)
    model = dict(fields["model"] or {})
    model.pop("dof_labels", None)
    t_fail = fields["t_fail"]
    attrs = {
        "format": FORMAT, "status": fields["status"], "message": fields["message"], "method": fields["method"],
        "t_fail": math.nan if t_fail is None else float(t_fail),
        "stats": _dump(fields["stats"], "stats"), "options": _dump(fields["options"], "options"),
        "monitor_scalars": _dump(scalars, "monitors"), "model": _dump(model, "model"), "unit_system": _UNITS,
    }
    for key in ("formulation",):
        if key in model:
            attrs[key] = str(model[key])
    for key in ("element", "material", "section", "loads"):
        if key in model:
            attrs[key] = _dump(model[key])
    if "nodes" in model:    # the mesh as arrays too, for readers that do not parse the JSON description
        data["reference_nodes"] = (("mesh_node", "space"), np.asarray(model["nodes"], dtype=float),
                                   {"long_name": "reference positions of the nodes (the dof coordinate 'node')"})
        data["element_nodes"] = (("element", "element_node"), np.asarray(model["element_nodes"], dtype=np.int64),
                                 {"long_name": "nodes of each element (3-node elements: start, end, middle)"})
    ds = xr.Dataset(data, coords={"time": ("time", fields["t"]), "node": ("dof", node),
                                  "coordinate": ("dof", coord)}, attrs=attrs)
    ds["time"].attrs["long_name"] = "output time"
    for name, long in (("q", "coordinates"), ("v", "velocities"), ("a", "accelerations")):
        ds[name].attrs["long_name"] = long
    ds.attrs[_filecheck.CHECKSUM_ATTR] = json.dumps(_filecheck.checksums(ds), sort_keys=True)
    return ds


def _path(path) -> Path:
    path = Path(path)
    return path if path.suffix in _SUFFIXES else path.with_name(path.name + ".nc")


def write(path, fields, engine: str = ENGINE) -> Path:
    """Write a result's ``fields`` (see :func:`to_dataset`) to ``path``, atomically.

    ``.nc`` is added unless ``path`` ends in .nc, .nc4 or .h5. The file is written under a
    temporary name in the same folder and renamed over ``path`` once complete.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    ValueError
        If the folder of ``path`` does not exist or is not writable, or ``path`` is a folder.
    """
    path = _path(path)
    folder = path.parent
    if not folder.is_dir():
        raise ValueError(f"`path` must be in an existing folder, got {str(path)!r}: the folder {str(folder)!r} "
                         + ("is a file." if folder.exists() else "does not exist (create it first)."))
    if path.is_dir():
        raise ValueError(f"`path` must name a file, got {str(path)!r}, which is a folder.")
    if not os.access(folder, os.W_OK):
        raise ValueError(f"`path` must be in a writable folder, got {str(path)!r}.")
    ds = to_dataset(fields)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        # Strings as variable-length UTF-8; floats uncompressed (bit for bit) with Fletcher-32 checksums.
        ds.to_netcdf(tmp, engine=engine, format="NETCDF4", encoding=_filecheck.encoding(ds))
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def _require(ds, name, path):
    if name not in ds.variables:
        raise ResultFileError(f"{path}: damaged ancfdae result file: variable {name!r} is missing.")
    return ds[name].values


def _loads(ds, key, path):
    try:
        return json.loads(ds.attrs[key])
    except KeyError:
        raise ResultFileError(f"{path}: damaged ancfdae result file: attribute {key!r} is missing.") from None
    except (TypeError, ValueError) as exc:
        raise ResultFileError(f"{path}: damaged ancfdae result file: attribute {key!r} is not JSON ({exc}).") from None


def _check_dimensions(ds, arrays, model, path):
    """Raise ResultFileError when the arrays' dimensions disagree with each other or the beam description."""
    shape = arrays["q"].shape
    for name in ("v", "a"):
        if arrays[name].shape != shape:
            raise ResultFileError(f"{path}: damaged ancfdae result file: variable {name!r} has shape "
                                  f"{arrays[name].shape}, variable 'q' {shape}.")
    n_dof = model.get("n_dof") if isinstance(model, dict) else None
    if n_dof is not None and len(shape) == 2 and shape[1] != n_dof:
        raise ResultFileError(f"{path}: damaged ancfdae result file: variable 'q' has {shape[1]} coordinates "
                              f"per output (dimension 'dof'), the stored beam description n_dof = {n_dof}.")
    for var, key in (("reference_nodes", "nodes"), ("element_nodes", "element_nodes")):
        if var in ds.variables and isinstance(model, dict) and key in model:
            want = np.shape(model[key])
            if ds[var].shape != want:
                raise ResultFileError(f"{path}: damaged ancfdae result file: variable {var!r} has shape "
                                      f"{ds[var].shape}, the stored beam description {want}.")


def from_dataset(ds, path="<dataset>") -> dict:
    """The fields of a result from a dataset of :func:`to_dataset` (in memory).

    Parameters
    ----------
    ds : xarray.Dataset
    path : str or path-like
        Names the source in error messages.

    Returns
    -------
    dict
        ``{name: value}`` for every name of :data:`FIELDS`, to be checked
        and held by :class:`ancfdae.Result`.

    Raises
    ------
    ResultFileError
        If a variable or attribute is missing or malformed.
    """
    if ds.attrs.get("format") not in (FORMAT, *_LEGACY):
        raise ResultFileError(f"{path}: not an ancfdae result file (attribute 'format' is "
                              f"{ds.attrs.get('format')!r}, expected {FORMAT!r}).")
    t = _require(ds, "time", path)
    arrays = {name: _require(ds, name, path) for name in ("q", "v", "a")}
    monitors = {name: dict(log) for name, log in _loads(ds, "monitor_scalars", path).items()}
    state = {}
    for name in ds.data_vars:
        attrs = ds[name].attrs
        if "monitor" in attrs and "key" in attrs:
            monitors.setdefault(str(attrs["monitor"]), {})[str(attrs["key"])] = ds[name].values
        elif "state" in attrs:
            state[str(attrs["state"])] = ds[name].values
    model = _loads(ds, "model", path)
    _check_dimensions(ds, arrays, model, path)
    if model and "node" in ds.coords:
        model["dof_labels"] = {"node": ds["node"].values.tolist(), "coordinate": ds["coordinate"].values.tolist()}
    t_fail = float(ds.attrs.get("t_fail", math.nan))
    return dict(t=t, q=arrays["q"], v=arrays["v"], a=arrays["a"], status=str(ds.attrs.get("status")),
                message=str(ds.attrs.get("message", "")), stats=_loads(ds, "stats", path), monitors=monitors,
                t_fail=None if math.isnan(t_fail) else t_fail, method=str(ds.attrs.get("method", "")),
                options=_loads(ds, "options", path), model_state=state, model=model,
                lam=ds["lam"].values if "lam" in ds.variables else None)


def read(path) -> dict:
    """The fields of the result file ``path`` written by :func:`write` (see :func:`from_dataset`).

    Raises
    ------
    ResultFileError
        Naming the file: missing, not NetCDF4/HDF5 (or truncated), an old
        ``.npz`` result, or a NetCDF file that is not an ancfdae result.
    """
    import xarray as xr     # on first use, as in to_dataset
    path = Path(path)
    if not path.is_file():
        raise ResultFileError(f"{path}: no such result file.")
    with open(path, "rb") as fh:
        magic = fh.read(8)
    if magic.startswith(b"PK"):
        raise ResultFileError(f"{path}: a zip archive, e.g. the .npz result format of ancfdae 0.1, which is no "
                              "longer read (numpy.load still opens it); results are NetCDF4 files now.")
    if magic != b"\x89HDF\r\n\x1a\n":
        raise ResultFileError(f"{path}: not a NetCDF4/HDF5 file (it does not start with the HDF5 signature).")
    try:
        ds = xr.open_dataset(path, engine=ENGINE)
    except Exception as exc:   # the HDF5 library raises OSError, KeyError, ValueError... on damaged files
        raise ResultFileError(f"{path}: damaged or truncated NetCDF4/HDF5 file ({type(exc).__name__}: {exc}).") \
            from exc
    with ds:
        for name in list(ds.variables):
            try:
                ds.variables[name].load()      # the HDF5 library verifies Fletcher-32 here
            except Exception as exc:  # noqa: BLE001 - any failure to read a variable is damage
                raise ResultFileError(f"{path}: damaged ancfdae result file: variable {name!r} cannot be read "
                                      f"(its data fail their checksum or are truncated: {type(exc).__name__}: "
                                      f"{exc}).") from exc
        if _filecheck.CHECKSUM_ATTR in ds.attrs or ds.attrs.get("format") == FORMAT:
            problem = _filecheck.verify(ds, path)
            if problem:
                raise ResultFileError(f"{path}: damaged ancfdae result file: {problem}.")
        elif any(var.encoding.get("fletcher32") for var in ds.variables.values()):
            raise ResultFileError(f"{path}: damaged ancfdae result file: its variables carry the checksums of "
                                  f"format {FORMAT!r} but the attribute {_filecheck.CHECKSUM_ATTR!r} is missing.")
        try:
            return from_dataset(ds, path)
        except ResultFileError:
            raise
        except Exception as exc:  # noqa: BLE001 - malformed content that passed the checks (a format-2 file)
            raise ResultFileError(f"{path}: damaged ancfdae result file ({type(exc).__name__}: {exc}).") from exc
