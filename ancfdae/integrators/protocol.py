"""The integrator protocol: what a time stepper implements, and what the driver does for it.

An integrator of ancfdae is a *stepper*: it advances the state of a Model (``ancfdae.problem``)
one step at a time. Everything around the steps -- validation of the arguments, the consistent
initial acceleration, output times, monitors, hooks, model events (BE3D's director update),
failure handling and the :class:`~ancfdae.result.Result` -- belongs to one driver loop
(:func:`ancfdae.simulate`), so that our integrators and a user's own behave alike.

A stepper implements

``initialize(t0, q0, v0, a0, t_bound)``
    take the initial state (``a0`` is the consistent acceleration the driver computed) and the
    end of the run; no step is taken yet;
``step() -> StepOutcome``
    advance one step from the current state. On success the outcome carries the new state
    (and, optionally, the step's quadrature nodes for monitors that integrate over the step);
    on failure ``ok`` is False, ``message`` says why, and the stepper's state is unchanged;
``interpolate(t) -> (q, v, a)``
    the state at a time inside the last step (default: quintic Hermite through ``(q, v, a)`` at
    the step's ends; a stepper with its own dense output overrides it);
``accept(outcome)``
    make a successful step's state the current one (the driver calls it; the base class keeps
    the previous state for :meth:`interpolate`);
``restart(t, q, v, a, model)``
    continue from a state that a model event changed (the driver passes the model bound to the
    event's new state); multistep methods drop their history. ``a`` is an acceleration
    recomputed consistently with the new state when the class sets ``consistent_restart = True``
    (IDA), else the step's own (one-step methods carry on);
``stats`` and ``options()``
    counters since ``initialize`` and the options as a JSON-able dict (both stored in the Result).

Class attributes: ``name`` (the key of :data:`ancfdae.METHODS` or a user's label), ``order``
(the classical order, or None), ``fixed_step`` (True when the constructor takes the step
size ``h``) and ``consistent_restart``.

Before ``initialize`` the driver sets two attributes: ``model`` (the model bound to the run's
initial event state; a stepper must evaluate ``self.model``, never a model it kept elsewhere) and
``want_quadrature`` (True when monitors will use the step's quadrature; a stepper may skip
building it otherwise). The driver also checks the model's declared capabilities
(:func:`ancfdae.problem.capabilities`); a stepper uses a fast path only when it is declared.
:meth:`Integrator.run` runs a constructed stepper through the same driver.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from ancfdae.problem import Model

if TYPE_CHECKING:                       # the result module imports the integrators
    from ancfdae.result import Result

__all__ = ["Quadrature", "StepOutcome", "Integrator"]


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
    """What one call of :meth:`Integrator.step` returns.

    Attributes
    ----------
    ok : bool
        False when the step failed; then only ``message`` is meaningful.
    t : float
        Time reached.
    q, v, a : ndarray, shape (n_dof,)
        The new state (``a`` is the method's acceleration at ``t``).
    quadrature : Quadrature or None
        The step's own quadrature rule, when the method has one worth using (Lobatto IIIA).
    message : str
        Why the step failed (empty on success).
    """

    ok: bool
    t: float = float("nan")
    q: np.ndarray | None = None
    v: np.ndarray | None = None
    a: np.ndarray | None = None
    quadrature: Quadrature | None = None
    message: str = ""

    @classmethod
    def failure(cls, message: str) -> "StepOutcome":
        """A failed step with its reason."""
        return cls(ok=False, message=str(message))


class Integrator(ABC):
    """Base class of the steppers; see the module docstring for the protocol.

    Subclasses set ``name``, ``order`` and ``fixed_step``, take ``model`` as the first argument
    of their constructor (and ``h`` as the second when ``fixed_step``), and implement
    :meth:`step`. The base class keeps the current state (``t, q, v, a``) and the previous one,
    and provides :meth:`initialize`, :meth:`interpolate` and :meth:`restart`.

    Parameters
    ----------
    model : Model
        The equations of motion.
    h : float, optional
        Step size of a fixed-step method (None for adaptive ones).
    """

    name: str = "integrator"
    order: int | None = None
    fixed_step: bool = True
    consistent_restart: bool = False
    want_quadrature: bool = False

    def __init__(self, model: Model, h: float | None = None) -> None:
        self.model = model
        self.h = h

    # -- state ---------------------------------------------------------------------------
    def initialize(self, t0: float, q0: np.ndarray, v0: np.ndarray, a0: np.ndarray,
                   t_bound: float) -> None:
        """Take the initial state and the end time of the run."""
        self.t, self.q, self.v, self.a = float(t0), q0, v0, a0
        self.t_bound = float(t_bound)
        self.previous = None

    def accept(self, outcome: StepOutcome) -> None:
        """Make ``outcome`` the current state (the driver calls this after a successful step)."""
        self.previous = (self.t, self.q, self.v, self.a)
        self.t, self.q, self.v, self.a = outcome.t, outcome.q, outcome.v, outcome.a

    @abstractmethod
    def step(self) -> StepOutcome:
        """Advance one step from the current state; must not change the state."""

    def interpolate(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """State at ``t`` inside the last step (quintic Hermite through both ends)."""
        from ancfdae.integrators._hermite import hermite5  # noqa: PLC0415 - small helper module
        t0, q0, v0, a0 = self.previous
        return hermite5(t0, (q0, v0, a0), self.t, (self.q, self.v, self.a), t)

    def restart(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, model: Model | None = None) -> None:
        """Continue from a state changed by a model event (history is dropped)."""
        if model is not None:
            self.model = model
        self.t, self.q, self.v, self.a = float(t), q, v, a
        self.previous = None

    # -- records -------------------------------------------------------------------------
    @property
    def stats(self) -> dict:
        """Work counters since :meth:`initialize` (at least ``steps``)."""
        return {}

    def options(self) -> dict:
        """The integrator's options as a JSON-able dict."""
        return {"h": self.h} if self.fixed_step else {}

    def run(self, t_span: tuple[float, float], **kwargs: Any) -> Result:
        """Integrate ``self.model`` over ``t_span`` through the driver.

        Keyword arguments are those of :func:`ancfdae.simulate` without ``method``, ``h`` and the
        integrator's options (``t_eval, monitors, hooks, q0, v0, state0, max_steps, progress``).
        """
        from ancfdae.integrators.driver import integrate  # noqa: PLC0415 - the driver imports this module
        return integrate(self, self.model, t_span, **kwargs)
