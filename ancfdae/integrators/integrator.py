"""The base of every stepper: what each of them would otherwise repeat.

Imitates scipy's ``OdeSolver`` (``step`` in the base, ``_step_impl`` in the method): the base takes
the model of the run and the initial state in :meth:`Integrator.initialize`, wraps the model in a
counting proxy (:class:`~ancfdae.integrators._counting.CountingModel`) once, keeps the current and
the previous state, counts the accepted steps, interpolates inside the last step and reports the
counters. A method adds its own set-up (``_setup``) and its step: ``step`` for an adaptive method
(IDA), ``_step_impl(t, h)`` on the uniform grid of
:class:`~ancfdae.integrators.fixed_step.FixedStepIntegrator`.

:meth:`Integrator.run` hands the stepper to the driver; this module stands above the driver (which
needs only :mod:`.protocol`), so the import has no circle.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, Any

import numpy as np

from ancfdae.integrators._counting import CountingModel
from ancfdae.integrators._hermite import hermite5
from ancfdae.integrators.driver import check_model, integrate
from ancfdae.integrators.protocol import StepOutcome
from ancfdae.problem import Model

if TYPE_CHECKING:                       # only for the annotation of run
    from ancfdae.result import Result

__all__ = ["Integrator"]


class Integrator(ABC):
    """Base class of the steppers (:class:`ancfdae.integrators.protocol.Stepper`).

    Subclasses set ``name``, ``order`` and ``fixed_step``, take ``model`` as the first argument of
    their constructor (and ``h`` as the second when ``fixed_step``), and implement :meth:`step`
    (fixed-step methods implement ``_step_impl`` of
    :class:`~ancfdae.integrators.FixedStepIntegrator` instead).

    Parameters
    ----------
    model : Model
        The equations of motion (what :meth:`run` integrates; the driver may hand
        :meth:`initialize` a model bound to an event state).
    h : float, optional
        Step size of a fixed-step method (None for adaptive ones).

    Attributes
    ----------
    model : CountingModel
        The model the steps evaluate: the run's model (from :meth:`initialize`, rebound by
        :meth:`restart`) behind a proxy that counts residual, Jacobian and potential evaluations.
        Always evaluate ``self.model``, never a model kept elsewhere.
    want_quadrature : bool
        True when monitors will use the step's :class:`~ancfdae.integrators.Quadrature`; a method
        may skip building it otherwise.
    t, q, v, a : float, ndarray
        The current state; ``previous`` is the state before the last accepted step (or None).
    t0, t_bound : float
        Start and end of the run.
    n_steps : int
        Steps accepted since :meth:`initialize`.
    lam : ndarray or None
        The current multipliers of a constrained model (from ``initialize(..., lam0=...)``, then each
        accepted ``StepOutcome.lam``); None otherwise.
    """

    name: str = "integrator"
    order: int | None = None
    fixed_step: bool = True
    #: True for a stepper that integrates models with the ``"constraints"`` capability
    handles_constraints: bool = False

    def __init__(self, model: Model, h: float | None = None) -> None:
        self.n_dof = check_model(model)
        self.h = h
        self._built_for = model            # what run() integrates
        self.model = CountingModel(model)  # rebound to the run's model by initialize()
        self.want_quadrature = False
        self.n_steps = 0

    # -- the protocol ---------------------------------------------------------------------------
    def initialize(self, model: Model, t0: float, q0: np.ndarray, v0: np.ndarray, a0: np.ndarray,
                   t_bound: float, *, want_quadrature: bool = False, lam0: np.ndarray | None = None) -> None:
        """Take the model of the run, the initial state and the end of the run; no step is taken.

        Parameters
        ----------
        model : Model
            The model to evaluate (the driver passes the one bound to the run's initial event state).
        t0 : float
            Initial time.
        q0, v0, a0 : array_like, shape (n_dof,)
            Initial state; ``a0`` consistent (``r(t0, q0, v0, a0) = 0``).
        t_bound : float
            End of the run.
        want_quadrature : bool
            True when monitors will use each step's quadrature.
        lam0 : array_like, shape (n_constraints,), optional
            The consistent initial multipliers of a model with the ``"constraints"`` capability
            (with ``a0`` from the same KKT system); None: a stepper that handles constraints
            computes both itself.
        """
        self.model.rebind(model)
        self.want_quadrature = bool(want_quadrature)
        self.t = float(t0)
        self.q, self.v, self.a = (np.array(x, dtype=float) for x in (q0, v0, a0))
        self.lam = None if lam0 is None else np.array(lam0, dtype=float)
        self.t0, self.t_bound = self.t, float(t_bound)
        self.previous = None
        self.n_steps = 0
        self._setup()
        self.model.reset()     # the counters count the steps' work, not the set-up's

    def _setup(self) -> None:
        """Method-specific set-up once the state is known (its model evaluations are not counted)."""

    @abstractmethod
    def step(self) -> StepOutcome:
        """Advance one step from the current state; must not change the state.

        Returns
        -------
        StepOutcome
            The new state, or ``StepOutcome.failure(reason)``.
        """

    def accept(self, outcome: StepOutcome) -> None:
        """Make ``outcome`` the current state and count the step (the driver calls this).

        Parameters
        ----------
        outcome : StepOutcome
            A successful step.
        """
        self.previous = (self.t, self.q, self.v, self.a)
        self.t, self.q, self.v, self.a = outcome.t, outcome.q, outcome.v, outcome.a
        if outcome.lam is not None:
            self.lam = outcome.lam
        self.n_steps += 1

    def interpolate(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """State at ``t`` inside the last step (quintic Hermite through both ends).

        Parameters
        ----------
        t : float
            A time inside the last accepted step.

        Returns
        -------
        q, v, a : ndarray
            Interpolated state.
        """
        t0, q0, v0, a0 = self.previous
        return hermite5(t0, (q0, v0, a0), self.t, (self.q, self.v, self.a), t)

    def restart(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, model: Model) -> None:
        """Continue from a state changed by a model event (history is dropped).

        Parameters
        ----------
        t : float
            Time of the event.
        q, v, a : ndarray
            The changed state; ``a`` is consistent with it and with ``model`` (the driver solves for it).
        model : Model
            The model bound to the event's new state; evaluated from now on (counters carry on).
        """
        self.model.rebind(model)
        self.t, self.q, self.v, self.a = float(t), q, v, a
        self.previous = None

    # -- records --------------------------------------------------------------------------------
    @property
    def stats(self) -> dict:
        """Work counters since :meth:`initialize`: ``steps``, ``residual_evals``, ``jacobian_evals``."""
        return {"steps": self.n_steps, **self.model.counts()}

    def options(self) -> dict:
        """The integrator's options as a JSON-able dict (stored in the Result).

        Returns
        -------
        dict
            ``{"h": h}`` for a fixed-step method, else empty.
        """
        return {"h": self.h} if self.fixed_step else {}

    def run(self, t_span: tuple[float, float], **kwargs: Any) -> Result:
        """Integrate the model this stepper was built on over ``t_span`` through the driver.

        Parameters
        ----------
        t_span : (t0, tf)
            Time interval.
        **kwargs
            Those of :func:`ancfdae.simulate` without ``method``, ``h`` and the integrator's
            options: ``t_eval, monitors, hooks, q0, v0, state0, max_steps, progress``.

        Returns
        -------
        Result
            The same as :func:`ancfdae.simulate` with this stepper.
        """
        return integrate(self, self._built_for, t_span, **kwargs)
