"""The uniform time grid of the fixed-step methods, without any solver.

:class:`FixedStepIntegrator` steps on ``t0 + k h`` (the last step shortened to end exactly at the end
of the run) and hands each step to the method's one ``_step_impl(t, h) -> StepOutcome``. An explicit
method needs nothing else (symplectic Euler in ``docs/own_integrator.md``); the implicit ones add a
Newton solve per step through :class:`~ancfdae.integrators.newton_stepper.NewtonStepper`.
"""
from __future__ import annotations

from abc import abstractmethod
from dataclasses import replace

import numpy as np

from ancfdae import _validate as validate
from ancfdae.integrators.driver import GRID_TOL
from ancfdae.integrators.integrator import Integrator
from ancfdae.integrators.protocol import StepOutcome
from ancfdae.problem import Model

__all__ = ["FixedStepIntegrator"]


class FixedStepIntegrator(Integrator):
    """Base of the fixed-step methods: the grid, the step counter and the counted model are the base's.

    A subclass sets ``name`` and ``order`` and implements ``_step_impl(t, h)``: one step of size
    ``h`` from the current state ``(self.t, self.q, self.v, self.a)`` (``t == self.t``), returning
    ``StepOutcome(ok=True, t=t + h, q=..., v=..., a=...)`` or ``StepOutcome.failure(reason)``,
    without changing the state. It evaluates ``self.model`` (counted) and may build a
    :class:`~ancfdae.integrators.Quadrature` when ``self.want_quadrature``.

    Parameters
    ----------
    model : Model
        Anything implementing :class:`ancfdae.problem.Model`.
    h : float
        Step size (> 0). The last step is shortened to end exactly at the end of the run.

    Notes
    -----
    After a model event (:meth:`restart`) the method carries on from the changed state on the same
    grid; the previous state is kept, because outputs inside the finished step were taken before
    the event.
    """

    fixed_step = True

    def __init__(self, model: Model, h: float) -> None:
        super().__init__(model, validate.positive("h", h))

    def next_time(self) -> float:
        """The end of the next step: ``t0 + (n_steps + 1) h``, or the end of the run if that is within reach.

        Returns
        -------
        float
            A grid time (computed from ``t0``, so round-off does not accumulate over the steps).
        """
        t_new = self.t0 + (self.n_steps + 1) * self.h
        if t_new >= self.t_bound - GRID_TOL * self.h:
            t_new = self.t_bound
        return t_new

    def step(self) -> StepOutcome:
        """One step to :meth:`next_time` by ``_step_impl``; the state is unchanged until :meth:`accept`.

        Returns
        -------
        StepOutcome
            At the grid time; a failure says which step failed.
        """
        t_new = self.next_time()
        out = self._step_impl(self.t, t_new - self.t)
        if not out.ok:
            return StepOutcome.failure(f"step to {t_new:.9g}: {out.message}")
        if out.t != t_new:      # the grid's time, not t + h rounded (nor an unset t)
            out = replace(out, t=t_new)
        return out

    @abstractmethod
    def _step_impl(self, t: float, h: float) -> StepOutcome:
        """One step of size ``h`` from the current state at ``t``; must not change the state."""

    def restart(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, model: Model) -> None:
        """Carry on from a state changed by a model event (same grid; the previous state kept).

        Parameters
        ----------
        t, q, v, a, model
            As for :meth:`Integrator.restart`.
        """
        previous = self.previous
        super().restart(t, q, v, a, model)
        self.previous = previous   # outputs inside the finished step were taken before the event
