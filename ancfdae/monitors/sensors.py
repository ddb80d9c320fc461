"""Point histories and user quantities along a run (:class:`PointSensor`, :class:`Probe`)."""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ancfdae import _validate as validate
from ancfdae.monitors.base import Monitor

__all__ = ["PointSensor", "Probe"]


class PointSensor(Monitor):
    """Position and velocity of a point of the beam axis at the output times.

    Parameters
    ----------
    s : float, optional
        Reference arc length of the point; uses ``model.position(q, s)``.
        The velocity is then ``position(q + v, s) - position(q, s)``, exact
        because ANCF positions are affine in the coordinates (``r = S(s) e``
        with the fixed coordinates filled in, chapter Eq. 54).
    function : callable, optional
        ``function(q) -> position`` for models without ``position``; its
        velocity is logged only when ``velocity_function(q, v)`` is given.
    name : str, optional
        Key in ``Result.monitors`` (default ``"point@s"`` or ``"point"``).
    velocity_function : callable, optional
    """

    def __init__(self, s: float | None = None, *, function: Callable | None = None, name: str | None = None,
                 velocity_function: Callable | None = None) -> None:
        if (s is None) == (function is None):
            raise ValueError("PointSensor needs exactly one of `s` (arc length) or `function`, "
                             f"got s={s!r}, function={function!r}.")
        if s is not None:
            s = validate.nonnegative("s", s)
        if function is not None and not callable(function):
            raise ValueError(f"`function` must be callable, got {function!r}.")
        if velocity_function is not None and not callable(velocity_function):
            raise ValueError(f"`velocity_function` must be callable, got {velocity_function!r}.")
        self.s, self.function, self.velocity_function = s, function, velocity_function
        self.name = name if name is not None else (f"point@{s:g}" if s is not None else "point")

    def start(self, model: Any, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        if self.s is not None and not callable(getattr(model, "position", None)):
            raise TypeError(f"PointSensor(s=...) needs `model.position(q, s)`; {type(model).__name__} has "
                            "none: pass `function=` instead.")
        self.model = model
        self._pos, self._vel = [], []
        # A beam's axis point is r(s) = P expand(q) with P fixed: build P once, not at every output (rebuilding
        # it cost ~30 % of a profiled IDA run on B2). Other models keep model.position.
        self._P = None
        if self.s is not None and callable(getattr(model, "point_matrix", None)) \
                and callable(getattr(model, "expand", None)):
            self._P = model.point_matrix(self.s)

    def _position(self, q: np.ndarray) -> np.ndarray:
        if self._P is None:
            return np.asarray(self.model.position(q, self.s), dtype=float)
        return self._P @ self.model.expand(q)

    def sample(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        if self.s is not None:
            p = self._position(q)
            self._pos.append(p)
            self._vel.append(self._position(q + v) - p)
        else:
            self._pos.append(np.atleast_1d(np.asarray(self.function(q), dtype=float)))
            if self.velocity_function is not None:
                self._vel.append(np.atleast_1d(np.asarray(self.velocity_function(q, v), dtype=float)))

    def log(self) -> dict:
        out = {"position": np.array(self._pos)}
        if self._vel:
            out["velocity"] = np.array(self._vel)
        if self.s is not None:
            out["s"] = self.s
        return out


class Probe(Monitor):
    """Any quantity logged at the output times.

    Parameters
    ----------
    name : str
        Key in ``Result.monitors``.
    function : callable
        ``function(t, q, v, a) -> array``, logged as ``"value"``: numbers of the same shape at every
        output time (a changed shape ends the run as failed, naming the probe). Non-finite values
        are logged as they are (a probe may report "undefined" as NaN).
    """

    def __init__(self, name: str, function: Callable) -> None:
        if not callable(function):
            raise ValueError(f"`function` must be callable, got {function!r}.")
        self.name, self.function = str(name), function

    def start(self, model: Any, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        self.model = model
        self._rows = []

    def sample(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        value = self.function(t, q, v, a)
        try:
            row = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"Probe {self.name!r}: `function` returned {value!r:.80} at t = {t:.9g}, not numbers "
                             "(an array of floats)") from None
        if self._rows and row.shape != self._rows[0].shape:
            raise ValueError(f"Probe {self.name!r}: `function` returned shape {row.shape} at t = {t:.9g}, "
                             f"{self._rows[0].shape} before; its value must keep its shape")
        self._rows.append(row)

    def log(self) -> dict:
        return {"value": np.array(self._rows)}
