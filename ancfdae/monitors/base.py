"""The monitor protocol: what the driver calls on a monitor during a run (see the package docstring)."""
from __future__ import annotations

from typing import Any

import numpy as np



__all__ = ["Monitor"]


class Monitor:
    """Base class: no-op hooks; subclasses set ``name`` and override what they need."""

    name = "monitor"

    def start(self, model: Any, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        """Begin a run: the model and the initial state.

        Parameters
        ----------
        model : Model
        t : float
        q, v, a : ndarray, shape (n_dof,)
        """
        self.model = model

    def advance(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, nodes: tuple | None = None) -> None:
        """Account for one accepted step ending at ``t``.

        Parameters
        ----------
        t : float
        q, v, a : ndarray, shape (n_dof,)
            State at the end of the step.
        nodes : Quadrature, optional
            ``(t, q, v, w)``: the step's quadrature (node times, coordinates
            and velocities as rows, weights summing to the step size).
        """

    def rebind(self, model: Any) -> None:
        """Use ``model`` (bound to a new event state) from now on.

        Parameters
        ----------
        model : Model
        """
        self.model = model

    def sample(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        """Record the state at an output time (inside the last advanced step).

        Parameters
        ----------
        t : float
        q, v, a : ndarray, shape (n_dof,)
        """

    def log(self) -> dict:
        """The recorded data: arrays with one entry per output time, and scalars.

        Returns
        -------
        dict
            Stored as ``Result.monitors[name]``.
        """
        return {}

    def stop_reason(self) -> str | None:
        """A message when the monitor asks the run to end, else None.

        Returns
        -------
        str or None
        """
        return None
