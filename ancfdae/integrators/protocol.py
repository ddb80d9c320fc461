"""The stepper protocol: what a time stepper offers the driver, and what one step returns.

An integrator of ancfdae is a *stepper*: it advances the state of a Model (``ancfdae.problem``)
one step at a time. Everything around the steps -- validation of the arguments, the consistent
initial acceleration, output times, monitors, hooks, model events (BE3D's director update),
failure handling and the :class:`~ancfdae.result.Result` -- belongs to one driver loop
(:func:`ancfdae.integrators.driver.integrate`), so that our integrators and a user's own behave
alike. This module holds only the contract between the two: :class:`Stepper` (what the driver
calls), :class:`StepOutcome` (what a step returns) and :class:`Quadrature` (a step's own rule, for
monitors). The base classes that implement it are :class:`~ancfdae.integrators.Integrator` (every
stepper), :class:`~ancfdae.integrators.FixedStepIntegrator` (the uniform grid) and
:class:`~ancfdae.integrators.NewtonStepper` (a Newton solve per step).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple, Protocol, runtime_checkable

import numpy as np

from ancfdae.problem import Model

__all__ = ["Quadrature", "StepOutcome", "Stepper"]


class Quadrature(NamedTuple):
    """A quadrature rule over one step, for monitors that integrate over it.

    Attributes
    ----------
    t : ndarray, shape (m,)
        Node times (in the step, ends included where the rule has them).
    q, v : ndarray, shape (m, n_dof)
        Coordinates and velocities at the nodes (rows).
    w : ndarray, shape (m,)
        Weights; they sum to the step size.
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    w: np.ndarray


@dataclass(frozen=True)
class StepOutcome:
    """What one step returns: the one outcome type of the stepper layer.

    Attributes
    ----------
    ok : bool
        False when the step failed; then only ``message`` is meaningful.
    t : float
        Time reached. A fixed-step method may leave it unset: its base puts the outcome at the
        grid time.
    q, v, a : ndarray, shape (n_dof,)
        The new state (``a`` is the method's acceleration at ``t``).
    quadrature : Quadrature or None
        The step's own quadrature rule, when the method has one worth using (Lobatto IIIA).
    message : str
        Why the step failed (empty on success).
    lam : ndarray, shape (n_constraints,), or None
        A constrained model only (capability ``"constraints"``): the method's own multipliers at ``t``
        (what it carries into the next step). The driver reports multipliers recomputed from ``(t, q, v)``.
    """

    ok: bool
    t: float = float("nan")
    q: np.ndarray | None = None
    v: np.ndarray | None = None
    a: np.ndarray | None = None
    quadrature: Quadrature | None = None
    message: str = ""
    lam: np.ndarray | None = None

    @classmethod
    def failure(cls, message: str) -> StepOutcome:
        """A failed step with its reason.

        Parameters
        ----------
        message : str
            Why the step failed.

        Returns
        -------
        StepOutcome
            ``ok`` False.
        """
        return cls(ok=False, message=str(message))


@runtime_checkable
class Stepper(Protocol):
    """What the driver calls, in this order: ``initialize``, then ``step`` and ``accept`` per step.

    Attributes
    ----------
    name : str
        The label stored in ``Result.method``.
    fixed_step : bool
        True when the constructor takes a step size ``h``.
    h : float or None
        The step size of a fixed-step method.
    handles_constraints : bool, optional
        True when the stepper integrates models with the ``"constraints"`` capability
        (:class:`ancfdae.problem.ConstrainedModel`): it adds ``G^T lam`` to the residual and imposes the
        constraints itself, takes the consistent multipliers as ``initialize(..., lam0=...)`` and returns
        its own in ``StepOutcome.lam``. The driver refuses a constrained model for a stepper without it
        (absent means False), and passes ``lam0`` only to steppers that declare it.
    t : float
        The current time (after ``initialize``).
    q, v, a : ndarray
        The current state.
    stats : dict
        Work counters since ``initialize``, at least ``steps``; the driver adds its own keys
        (``model_events``, ``restarts``, ``wall_time``, ``cpu_time``) and never overwrites these.

    Notes
    -----
    Optional: ``steps_until(t_stop, max_count) -> (outcome, taken)``. When nothing needs the state
    between output times (``t_eval`` given, no monitor, no hook, no model event), the driver calls it
    instead of ``step``: the stepper takes up to ``max_count`` steps, stopping after the first whose end
    reaches ``t_stop`` (the next output time, as the driver tests it, or the end of the run); it
    accepts all but the last itself (``taken`` of them) and returns the last one's outcome (or the
    failure of the step after the accepted ones) for the driver to check and accept. The Newmark family
    runs them as one compiled call (:mod:`ancfdae.integrators._alpha_steps`). Optional as well, then preferred:
    ``steps_sampling(t_out, t_end, max_count) -> (outcome, taken, samples)``, the same across the coming output
    times ``t_out``, with ``samples = (t, q, v, a, lam)`` (rows, or None) at those its accepted steps ended on,
    recorded as the driver would (the Newmark family on a compiled System: :mod:`ancfdae.integrators._index3_steps`).
    """

    name: str
    fixed_step: bool
    h: float | None
    t: float
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray

    @property
    def stats(self) -> dict:
        """Work counters since ``initialize``."""
        ...

    def initialize(self, model: Model, t0: float, q0: np.ndarray, v0: np.ndarray, a0: np.ndarray,
                   t_bound: float, *, want_quadrature: bool = False) -> None:
        """Take the model to evaluate, the initial state (``a0`` consistent) and the end of the run.

        A stepper with ``handles_constraints`` also takes the keyword ``lam0`` (the consistent multipliers).
        """
        ...

    def step(self) -> StepOutcome:
        """Advance one step from the current state without changing it."""
        ...

    def accept(self, outcome: StepOutcome) -> None:
        """Make a successful step's state the current one."""
        ...

    def interpolate(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q, v, a)`` at ``t`` inside the last step."""
        ...

    def restart(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, model: Model) -> None:
        """Continue from a state a model event changed, evaluating ``model`` (bound to the new event state)."""
        ...

    def options(self) -> dict:
        """The options as a JSON-able dict (stored in the Result)."""
        ...
