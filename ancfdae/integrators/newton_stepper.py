"""The implicit fixed-step methods' share: one Newton solve per step, its tolerances passed per solve.

:class:`NewtonStepper` adds to the grid of :class:`~ancfdae.integrators.FixedStepIntegrator` a
(modified) Newton solver (:mod:`ancfdae.integrators._newton`) and its two absolute levels, both
arguments of every solve, never fields of the solver:

* the absolute tolerance, fixed per run: ``NewtonOptions.residual_atol`` as given, or derived once
  from the initial state's force scale (:func:`ancfdae._scale.absolute_tolerance`);
* the residual's round-off floor: the method's Jacobian callback returns it with the matrix
  (:meth:`NewtonStepper.floor_of`, from the stiffness it evaluated), the solver applies it from that
  iteration on and returns the floor in effect, and :meth:`NewtonStepper._solve` carries it into the
  next solve as the stepper's own state (reset by ``initialize``).

How a new floor updates the one in effect is the class attribute ``FLOOR_UPDATE``, chosen by
measurement: ``"max"`` (a running maximum over the run) for Lobatto IIIA and the Newmark family,
``"replace"`` (the floor of the latest Jacobian) for the energy-momentum method. Each is what the
method did before the floor became an argument, and the other one moved the quick studies'
numbers: for the fixed-step methods only at round-off level (the latest-Jacobian floor changed
flying2d's eps_T by 1e-13 to 5e-11 relative), so the running maximum stays to keep results bit for
bit; for energy-momentum a running maximum is worse, since a floor kept from stiffer states stops
Newton early (flying3d's SQ3D run: energy balance at the end of the load 1.3e-13 J instead of
1.4e-15 J; the energy study's BE2D run: drift 1.0e-15 instead of 2.1e-15 J). Tests pin both.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae._scale import STIFFNESS_ROUNDOFF, absolute_tolerance, roundoff_floor
from ancfdae.integrators._newton import NewtonSolver
from ancfdae.integrators._newton_records import NewtonOptions, NewtonOutcome, NewtonStats
from ancfdae.integrators.fixed_step import FixedStepIntegrator
from ancfdae.integrators.protocol import StepOutcome
from ancfdae.problem import Model

__all__ = ["NewtonStepper"]


def newton_options(newton: NewtonOptions | dict | None) -> NewtonOptions:
    """``newton`` as NewtonOptions (a dict: its keyword arguments; None: the defaults)."""
    if newton is None:
        return NewtonOptions()
    if isinstance(newton, dict):
        return NewtonOptions(**newton)
    if not isinstance(newton, NewtonOptions):
        raise TypeError(f"`newton` must be a NewtonOptions or a dict, got {type(newton).__name__}.")
    return newton


class NewtonStepper(FixedStepIntegrator):
    """Base of the implicit fixed-step integrators: a Newton solve per step on the uniform grid.

    A subclass builds the step's residual and Jacobian callbacks in ``_step_impl`` and calls
    :meth:`_solve`; its Jacobian callback returns ``(matrix, floor)`` with
    ``floor = self.floor_of(K, q)`` of the stiffness it evaluated.

    Parameters
    ----------
    model, h
        As for :class:`FixedStepIntegrator`: the equations of motion and the step size.
    newton : NewtonOptions or dict, optional
        Options of the Newton solver (dict: keyword arguments of :class:`NewtonOptions`). With
        ``residual_atol=None`` (the default) the absolute tolerance is derived from the problem at
        :meth:`initialize`: ``ATOL_ROUNDOFF * eps * force_scale(model, t0, q0, v0, a0)``
        (:mod:`ancfdae._scale`: stiffness times coordinates, damping times velocities, inertia
        times accelerations, and the load).

    Attributes
    ----------
    newton : NewtonSolver
        The solver (its factorisation is reused across steps by modified Newton).
    """

    #: factor of :func:`ancfdae._scale.roundoff_floor` for this family's stiffness
    FLOOR_ROUNDOFF = STIFFNESS_ROUNDOFF
    #: how a Jacobian's floor updates the one in effect (module docstring): a running maximum
    FLOOR_UPDATE = "max"

    def __init__(self, model: Model, h: float, *, newton: NewtonOptions | dict | None = None) -> None:
        super().__init__(model, h)
        self.newton = NewtonSolver(newton_options(newton))

    def options(self) -> dict:
        """The integrator's options as a JSON-able dict (stored in the Result).

        Returns
        -------
        dict
            ``h`` and the Newton options.
        """
        o = self.newton.options
        return {"h": self.h, "newton": {"tol": o.tol, "residual_atol": o.residual_atol, "max_iter": o.max_iter,
                                        "jacobian": o.jacobian, "contraction": o.contraction}}

    def _setup(self) -> None:
        """A fresh solver, the run's absolute tolerance and no floor yet."""
        self.newton.invalidate()
        self.newton.stats = NewtonStats()
        self._h_matrix = None      # the step size the cached matrix was built for
        self._floor = 0.0          # the residual's round-off floor, carried over the run (module docstring)
        # A fixed tolerance in newtons is the whole load of a micro-fibre and below round-off for a
        # 100 m beam: derive it from the problem's own force scale.
        given = self.newton.options.residual_atol
        self._atol = absolute_tolerance(self.model, self.t, self.q, self.v, self.a) if given is None else given

    def step(self) -> StepOutcome:
        """One grid step; the Newton matrix is dropped first when the step size changed.

        Returns
        -------
        StepOutcome
            At the grid time, or the failure with its reason.
        """
        h = self.next_time() - self.t
        if self._h_matrix is None or abs(h - self._h_matrix) > 1e-8 * self.h:
            self.newton.invalidate()  # iteration-matrix coefficients depend on h
            self._h_matrix = h
        return super().step()

    def floor_of(self, K: sp.spmatrix | np.ndarray, q: np.ndarray) -> float:
        """The residual's round-off floor for the stiffness ``K`` evaluated at ``q``.

        Parameters
        ----------
        K : sparse matrix or ndarray
            The stiffness (or whatever plays its part in the method's residual).
        q : ndarray
            Where it was evaluated.

        Returns
        -------
        float
            ``FLOOR_ROUNDOFF * eps * max|K| * max(1, max|q|)``.
        """
        return roundoff_floor(self.FLOOR_ROUNDOFF, K, q)

    def _solve(self, residual, jacobian, x0, iterate=None, accept=None) -> NewtonOutcome:
        """Newton with the run's absolute tolerance and the floor carried from the earlier solves.

        ``jacobian(x)`` returns ``(matrix, self.floor_of(K, q))``; ``iterate``: the compiled iteration
        (see :meth:`NewtonSolver.solve`), or None; ``accept``: the solver's test after the residual's (ditto).
        The outcome has ``x``,
        ``converged``, ``iterations``, ``residual_norm``, ``message`` and ``floor``.
        """
        out = self.newton.solve(residual, jacobian, x0, residual_atol=self._atol, floor=self._floor,
                                floor_update=self.FLOOR_UPDATE, iterate=iterate, accept=accept)
        self._floor = out.floor
        return out

    @property
    def stats(self) -> dict:
        """Work counters since :meth:`initialize`: steps, the solver's, and the model's evaluations."""
        # The model's evaluations are the proxy's (a residual_stages call of m stages is m
        # residuals); the solver counts its callbacks, which may evaluate several at once.
        return {"steps": self.n_steps, **self.newton.stats.as_stats(), **self.model.counts()}
