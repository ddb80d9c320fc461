"""Drift of the position and velocity constraints of a constrained model (:class:`ConstraintMonitor`)."""
from __future__ import annotations

from typing import Any

import numpy as np

from ancfdae.monitors.base import Monitor
from ancfdae.problem import capabilities

__all__ = ["ConstraintMonitor"]


class ConstraintMonitor(Monitor):
    """Drift of the position and velocity constraints of a constrained model, at every output time.

    Logs ``position`` = ``max|g(t, q)|`` and ``velocity`` = ``max|G v + g_t|`` at the output times, and
    ``step_position``/``step_velocity``: their largest values over the steps that ended since the
    previous output. Output times inside a step hold interpolated states (the integrator's interpolant
    does not satisfy ``g = 0`` exactly); the step values measure the method itself. Scalars
    ``max_position`` and ``max_velocity`` over the run (step ends and outputs).

    Parameters
    ----------
    name : str
        Key in ``Result.monitors``.
    """

    def __init__(self, name: str = "constraints") -> None:
        self.name = str(name)

    def start(self, model: Any, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        if "constraints" not in capabilities(model):
            raise TypeError(f"ConstraintMonitor needs a model with the 'constraints' capability; "
                            f"{type(model).__name__} has none.")
        self.model = model
        self._rows: list[tuple] = []
        self._step = self._drift(t, q, v)
        self._max = self._step

    def _drift(self, t, q, v):
        g = self.model.constraints(t, q)
        g_t, _ = self.model.constraint_rates(t, q, v)
        gv = self.model.constraint_jacobian(t, q) @ v + g_t
        return float(np.max(np.abs(g), initial=0.0)), float(np.max(np.abs(gv), initial=0.0))

    def advance(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, nodes: tuple | None = None) -> None:
        d = self._drift(t, q, v)
        self._step = (max(self._step[0], d[0]), max(self._step[1], d[1]))

    def sample(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        d = self._drift(t, q, v)
        self._rows.append(d + self._step)
        self._max = (max(self._max[0], d[0], self._step[0]), max(self._max[1], d[1], self._step[1]))
        self._step = (0.0, 0.0)

    def log(self) -> dict:
        rows = np.array(self._rows, dtype=float).reshape(-1, 4)
        out = {k: rows[:, i].copy() for i, k in enumerate(("position", "velocity", "step_position",
                                                            "step_velocity"))}
        out.update(max_position=self._max[0], max_velocity=self._max[1])
        return out
