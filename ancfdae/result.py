"""The result of a simulation (design.md Sect. 6).

Imitates scipy's ``OdeResult``: the front door never raises on a failed
integration; it returns a :class:`Result` whose ``status`` says what happened
and which keeps every output sample up to the failure.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["Result"]

_STATUSES = ("success", "failed")


def _jsonable(obj):
    """Convert numpy scalars (and containers of them) to plain Python for json."""
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return obj


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

    # -- persistence ------------------------------------------------------------------------
    def save(self, path) -> Path:
        """Write to ``path`` (``.npz`` added if missing): arrays plus JSON metadata.

        Arrays go into the npz archive; status, message, stats, options and
        scalar monitor entries into one JSON string stored in it as
        ``"metadata"``, so a single file holds everything.
        """
        path = Path(path)
        if path.suffix != ".npz":
            path = path.with_name(path.name + ".npz")
        arrays = {"t": self.t, "q": self.q, "v": self.v, "a": self.a}
        scalars: dict = {}
        for key, arr in self.model_state.items():
            arrays[f"state/{key}"] = arr
        for name, log in self.monitors.items():
            if "/" in name:
                raise ValueError(f"monitor names must not contain '/', got {name!r}.")
            scalars[name] = {}
            for key, value in log.items():
                if isinstance(value, np.ndarray):
                    arrays[f"monitor/{name}/{key}"] = value
                else:
                    scalars[name][key] = value
        meta = {
            "format": "ancfdae.Result/1",
            "status": self.status,
            "message": self.message,
            "stats": self.stats,
            "t_fail": self.t_fail,
            "method": self.method,
            "options": self.options,
            "monitor_scalars": scalars,
        }
        arrays["metadata"] = np.array(json.dumps(_jsonable(meta)))
        np.savez_compressed(path, **arrays)
        return path

    @classmethod
    def load(cls, path) -> "Result":
        """Read a file written by :meth:`save`."""
        with np.load(Path(path), allow_pickle=False) as data:
            meta = json.loads(str(data["metadata"]))
            if meta.get("format") != "ancfdae.Result/1":
                raise ValueError(f"{path} is not an ancfdae Result file (format {meta.get('format')!r}).")
            monitors = {name: dict(vals) for name, vals in meta["monitor_scalars"].items()}
            state = {key.split("/", 1)[1]: data[key] for key in data.files if key.startswith("state/")}
            for key in data.files:
                if key.startswith("monitor/"):
                    _, name, entry = key.split("/", 2)
                    monitors.setdefault(name, {})[entry] = data[key]
            return cls(t=data["t"], q=data["q"], v=data["v"], a=data["a"], status=meta["status"],
                       message=meta["message"], stats=meta["stats"], monitors=monitors,
                       t_fail=meta["t_fail"], method=meta["method"], options=meta["options"],
                       model_state=state)
