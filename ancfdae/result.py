"""The result of a simulation.

Imitates scipy's ``OdeResult``: the front door never raises on a failed
integration; it returns a :class:`Result` whose ``status`` says what happened
and which keeps every output sample up to the failure.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING
from pathlib import Path

import numpy as np

from . import _resultfile
from ._resultfile import ResultFileError

if TYPE_CHECKING:
    import xarray

__all__ = ["Result", "ResultFileError"]

_STATUSES = ("success", "failed")


@dataclass
class Result:
    """Time-major output of a simulation.

    Attributes
    ----------
    t : ndarray, shape (n_out,)
        Output times actually reached (a failed run stops early).
    q, v, a : ndarray, shape (n_out, n_dof)
        Coordinates, velocities and accelerations at ``t``. For the
        generalized-alpha family ``a`` is the algorithmic acceleration.
    status : {"success", "failed"}
    message : str
        What happened; on failure it says when and why.
    stats : dict
        Work counters (steps, Newton iterations, residual and Jacobian
        evaluations, factorisations, ...), integer or float values.
    monitors : dict
        ``{monitor name: {key: ndarray of length n_out or scalar}}``.
    t_fail : float or None
        Start time of the step that failed (None on success).
    method : str
        Name of the integrator.
    options : dict
        The integrator's options (JSON-able), for the record.
    model_state : dict
        The model's event state at ``t`` (models with the ``"step_events"`` capability):
        ``{name: ndarray of shape (n_out, ...)}``, e.g. BE3D's ``"directors"``, shape
        ``(n_out, n_nodes, 3)``. Empty for models without event state.
    model : dict
        JSON-able description of the model (``model.describe()`` when it has
        one, plus ``"dof_labels"``: ``{"node": [...], "coordinate": [...]}``);
        empty when the model does not describe itself.
    lam : ndarray, shape (n_out, n_constraints)
        A constrained model's multipliers at ``t`` (the reaction forces are ``-G^T lam``), recomputed
        from ``(t, q, v)`` by the KKT system; shape ``(n_out, 0)`` for a model without constraints.
        The rows' labels are ``model["system"]["constraint_labels"]`` for an :class:`ancfdae.System`.
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    status: str = "success"
    message: str = ""
    stats: dict = field(default_factory=dict)
    monitors: dict = field(default_factory=dict)
    t_fail: float | None = None
    method: str = ""
    options: dict = field(default_factory=dict)
    model_state: dict = field(default_factory=dict)
    model: dict = field(default_factory=dict)
    lam: np.ndarray | None = None

    def __post_init__(self):
        if self.status not in _STATUSES:
            raise ValueError(f"`status` must be one of {list(_STATUSES)}, got {self.status!r}.")
        self.t = np.asarray(self.t, dtype=float).reshape(-1)
        n = self.t.shape[0]
        for name in ("q", "v", "a"):
            arr = np.asarray(getattr(self, name), dtype=float)
            if arr.ndim == 1 and n == 0:
                arr = arr.reshape(0, 0)
            if arr.ndim != 2 or arr.shape[0] != n:
                raise ValueError(f"`{name}` must have shape ({n}, n_dof) to match `t`, got {arr.shape}.")
            setattr(self, name, arr)
        lam = np.zeros((n, 0)) if self.lam is None else np.asarray(self.lam, dtype=float)
        if lam.ndim != 2 or lam.shape[0] != n:
            raise ValueError(f"`lam` must have shape ({n}, n_constraints) to match `t`, got {lam.shape}.")
        self.lam = lam
        state = {}
        for key, arr in dict(self.model_state or {}).items():
            arr = np.asarray(arr, dtype=float)
            if arr.ndim < 1 or arr.shape[0] != n:
                raise ValueError(f"`model_state[{key!r}]` must have {n} rows (one per output time), "
                                 f"got shape {arr.shape}.")
            state[str(key)] = arr
        self.model_state = state

    @property
    def success(self) -> bool:
        """True when the integration reached the end of the time span."""
        return self.status == "success"

    def __repr__(self) -> str:
        n_dof = self.q.shape[1] if self.q.ndim == 2 else 0
        span = f"[{self.t[0]:g}, {self.t[-1]:g}]" if self.t.size else "[]"
        return (f"Result(method={self.method!r}, status={self.status!r}, n_out={self.t.size}, "
                f"n_dof={n_dof}, t={span}, message={self.message!r})")

    # -- persistence: the result-file module reads and writes the fields; the object is built here
    def _fields(self) -> dict:
        """``{name: value}`` of every field (no copies), as :mod:`ancfdae._resultfile` takes them."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def to_xarray(self) -> "xarray.Dataset":
        """The result as a labelled :class:`xarray.Dataset` (what :meth:`save` writes).

        Dimensions ``time`` and ``dof`` with the coordinates ``node`` and
        ``coordinate`` (e.g. ``x``, ``y'``, ``theta``) when the model described
        itself; monitors and ``model_state`` arrays as variables; status,
        message, stats, options and the model description as attributes.
        """
        return _resultfile.to_dataset(self._fields())

    def save(self, path: str | os.PathLike, engine: str = _resultfile.ENGINE) -> Path:
        """Write a self-describing NetCDF4/HDF5 file, readable by plain xarray or h5py.

        Parameters
        ----------
        path : str or path-like
            ``.nc`` is appended unless it ends in ``.nc``, ``.nc4`` or ``.h5``.
        engine : {"netcdf4", "h5netcdf"}
            xarray's writer; netCDF4 by default (measured 2-4 times faster
            than h5netcdf with equal file sizes; see :mod:`ancfdae._resultfile`).

        Returns
        -------
        pathlib.Path
            The file written. Arrays round-trip bit for bit.
        """
        return _resultfile.write(path, self._fields(), engine)

    @classmethod
    def load(cls, path: str | os.PathLike) -> "Result":
        """Read a file written by :meth:`save`.

        Raises
        ------
        ResultFileError
            (a ValueError) naming the file and what is wrong with it: missing,
            not NetCDF4/HDF5, truncated or damaged, an old ``.npz`` result, or
            not an ancfdae result.
        """
        stored = _resultfile.read(path)
        try:
            return cls(**stored)
        except ValueError as exc:   # the fields read, but do not make a Result (e.g. q of the wrong length)
            raise ResultFileError(f"{Path(path)}: damaged ancfdae result file: {exc}") from None
