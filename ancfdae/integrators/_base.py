"""The shared fixed-step stepper: a Newton solve per step on a uniform time grid.

:class:`FixedStepIntegrator` implements the :class:`~.protocol.Integrator` protocol for the
one-step methods (Lobatto IIIA, the Newmark family): the time grid ``t0 + k h`` (the last step
shortened to end exactly at the end of the run), the Newton solver and its residual floor, the
work counters, and one private ``_step_impl`` that a method implements. The run loop is the
driver's (:mod:`.driver`).
"""
from __future__ import annotations

from abc import abstractmethod

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

from ancfdae import _validate as V
from ancfdae._scale import ROUNDOFF as SCALE_ROUNDOFF, force_scale
from ancfdae.integrators._newton import NewtonOptions, NewtonSolver, NewtonStats
from ancfdae.integrators.driver import GRID_TOL, check_model
from ancfdae.integrators.protocol import Integrator, StepOutcome
from ancfdae.problem import Model

__all__ = ["FixedStepIntegrator"]

#: Newton's residual floor is ROUNDOFF * eps * max|K| * max(1, max|q|): the round-off level of
#: elastic forces (measured 4e-7 N = 1.0 eps max|K| on the 25-element BE2D pendulum, spikes to 10x).
ROUNDOFF = 10.0


class FixedStepIntegrator(Integrator):
    """Base of the fixed-step integrators.

    Parameters
    ----------
    model : Model
        Anything implementing :class:`ancfdae.problem.Model`.
    h : float
        Step size (> 0). The last step is shortened to end exactly at the end of the run.
    newton : NewtonOptions or dict, optional
        Options of the Newton solver (dict: keyword arguments of :class:`NewtonOptions`). With
        ``atol=None`` (the default) the absolute tolerance is derived from the problem at
        :meth:`initialize`: ``ROUNDOFF * eps * force_scale(model, t0, q0, v0, a0)`` with
        ``ROUNDOFF`` and ``force_scale`` of :mod:`ancfdae._scale` (stiffness times coordinates,
        damping times velocities, inertia times accelerations, and the load).

    Notes
    -----
    After a model event (:meth:`restart`) the method carries on from the changed state with its
    Newton iteration matrix and the acceleration of the step (no history to drop).
    """

    name = "fixed-step"
    order = 0
    fixed_step = True

    def __init__(self, model: Model, h: float, *, newton: NewtonOptions | dict | None = None) -> None:
        self.n_dof = check_model(model)
        super().__init__(model, V.positive("h", h))
        if newton is None:
            newton = NewtonOptions()
        elif isinstance(newton, dict):
            newton = NewtonOptions(**newton)
        elif not isinstance(newton, NewtonOptions):
            raise TypeError(f"`newton` must be a NewtonOptions or a dict, got {type(newton).__name__}.")
        self.newton = NewtonSolver(newton)
        self._h_matrix = None
        self.n_steps = self._n_res = self._n_jac = 0

    def options(self) -> dict:
        """The integrator's options as a JSON-able dict (stored in the Result)."""
        o = self.newton.options
        return {"h": self.h, "newton": {"tol": o.tol, "atol": o.atol, "max_iter": o.max_iter,
                                        "jacobian": o.jacobian, "contraction": o.contraction}}

    # -- counting wrappers around the model ----------------------------------------------------
    def _residual(self, t, q, v, a):
        self._n_res += 1
        return self.model.residual(t, q, v, a)

    def _jacobian(self, t, q, v, a):
        self._n_jac += 1
        return self.model.jacobian(t, q, v, a)

    def _set_floor(self, blocks, q):
        """Set Newton's residual floor from the stiffness just evaluated (see ROUNDOFF)."""
        K = blocks.K
        kmax = float(np.max(np.abs(K.data), initial=0.0)) if sp.issparse(K) else float(np.max(np.abs(K)))
        floor = ROUNDOFF * np.finfo(float).eps * kmax * max(1.0, float(np.max(np.abs(q))))
        self.newton.residual_floor = max(self.newton.residual_floor, floor)

    # -- protocol ------------------------------------------------------------------------------
    def initialize(self, t0: float, q0: ArrayLike, v0: ArrayLike, a0: ArrayLike, t_bound: float) -> None:
        """Take the initial state; reset the grid, the Newton solver and the counters."""
        super().initialize(t0, np.array(q0, dtype=float), np.array(v0, dtype=float),
                           np.array(a0, dtype=float), t_bound)
        self.t0 = self.t
        self._n_res = self._n_jac = self.n_steps = 0
        self.newton.invalidate()
        self.newton.stats = NewtonStats()
        self.newton.residual_floor = 0.0
        # A fixed atol in newtons is the whole load of a micro-fibre and below round-off for a
        # 100 m beam: derive it from the problem's own force scale (the floor of _set_floor then
        # follows the configuration as the Jacobian is re-evaluated).
        self.newton.scaled_atol = 0.0
        if self.newton.options.atol is None:
            self.newton.scaled_atol = SCALE_ROUNDOFF * np.finfo(float).eps * force_scale(
                self.model, self.t, self.q, self.v, self.a)
        self._init_impl()

    def _init_impl(self) -> None:
        """Method-specific set-up after the initial state is known."""

    def step(self) -> StepOutcome:
        """One step on the grid ``t0 + k h``; the state is unchanged until :meth:`accept`."""
        t_new = self.t0 + (self.n_steps + 1) * self.h
        if t_new >= self.t_bound - GRID_TOL * self.h:
            t_new = self.t_bound
        h = t_new - self.t
        if self._h_matrix is None or abs(h - self._h_matrix) > 1e-8 * self.h:
            self.newton.invalidate()  # iteration-matrix coefficients depend on h
            self._h_matrix = h
        ok, info = self._step_impl(self.t, h)
        if not ok:
            return StepOutcome.failure(f"step to {t_new:.9g}: {info}")
        q, v, a, quad = info
        return StepOutcome(ok=True, t=t_new, q=q, v=v, a=a, quadrature=quad)

    def accept(self, outcome: StepOutcome) -> None:
        super().accept(outcome)
        self.n_steps += 1

    def restart(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, model: Model | None = None) -> None:
        """Carry on from a state changed by a model event (grid and Newton matrix kept)."""
        prev = self.previous
        super().restart(t, q, v, a, model)
        self.previous = prev   # outputs inside the finished step were taken before the event

    @abstractmethod
    def _step_impl(self, t, h):
        """Return ``(True, (q, v, a, quadrature or None))`` or ``(False, reason)``; must not change the state."""

    @property
    def stats(self) -> dict:
        """Work counters since :meth:`initialize`."""
        ns = self.newton.stats
        return {"steps": self.n_steps, "newton_iterations": ns.iterations, "newton_solves": ns.solves,
                "failed_solves": ns.failed_solves, "retries": ns.retries,
                "residual_evals": self._n_res, "jacobian_evals": self._n_jac,
                "factorizations": ns.factorizations}
