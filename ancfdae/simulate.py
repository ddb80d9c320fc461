"""``simulate``: the one front door to the integrators.

Imitates scipy's ``solve_ivp``: a ``METHODS`` registry, options forwarded to
the integrator, and a :class:`~ancfdae.result.Result` that reports failure in
its ``status`` instead of raising. Bad arguments still raise (ValueError /
TypeError naming the argument). The run itself is the one driver loop of
:mod:`ancfdae.integrators.driver`; integrators are steppers
(:mod:`ancfdae.integrators.protocol`), ours and a user's own alike, and
``simulate(model, t_span, method=stepper)`` returns the same Result as
``stepper.run(t_span)``.
"""
from __future__ import annotations

import inspect
from collections.abc import Callable, Sequence
from typing import Any

from numpy.typing import ArrayLike

from ancfdae.integrators.driver import integrate
from ancfdae.integrators.energy_collocation import EnergyCollocation
from ancfdae.integrators.energy_momentum import EnergyMomentum
from ancfdae.integrators.ida import IDA
from ancfdae.integrators.integrator import Integrator
from ancfdae.integrators.lobatto import Lobatto2, Lobatto3
from ancfdae.integrators.newmark import GeneralizedAlpha, HHTAlpha, Newmark
from ancfdae.monitors import Monitor
from ancfdae.problem import Model
from ancfdae.result import Result

__all__ = ["simulate", "METHODS"]


#: name -> integrator class; fixed-step classes take ``h``, IDA does not.
METHODS = {
    "lobatto3": Lobatto3,
    "lobatto2": Lobatto2,
    "newmark": Newmark,
    "hht": HHTAlpha,
    "generalized-alpha": GeneralizedAlpha,
    "ida": IDA,
    "energy-momentum": EnergyMomentum,
    "energy-collocation": EnergyCollocation,
}


def _label(method):
    return method if isinstance(method, str) else getattr(method, "name", type(method).__name__)


def _build(model, method, h, options):
    """The stepper for ``method`` (a name, an Integrator subclass or an instance)."""
    if isinstance(method, Integrator):
        if options or h is not None:
            raise ValueError(f"`method` is an integrator instance ({_label(method)!r}): give its step and "
                             f"options to its constructor, not to simulate (got h={h!r}, options {sorted(options)}).")
        return method
    if isinstance(method, str):
        if method not in METHODS:
            raise ValueError(f"`method` must be one of {sorted(METHODS)}, an Integrator subclass or instance, "
                             f"got {method!r}.")
        cls = METHODS[method]
    elif inspect.isclass(method) and issubclass(method, Integrator):
        cls = method
    else:
        raise ValueError(f"`method` must be one of {sorted(METHODS)}, an Integrator subclass or instance, "
                         f"got {method!r}.")
    label = _label(method)
    params = inspect.signature(cls.__init__).parameters
    allowed = [p for p in params if p not in ("self", "model", "h")]
    if not any(p.kind is p.VAR_KEYWORD for p in params.values()):
        unknown = sorted(set(options) - set(allowed))
        if unknown:
            raise ValueError(f"unknown option(s) {unknown} for method {label!r}; allowed: {allowed}.")
    fixed = bool(getattr(cls, "fixed_step", False))
    if fixed and h is None:
        raise ValueError(f"`h` (the step size) is required by the fixed-step method {label!r}.")
    if not fixed and h is not None:
        raise ValueError(f"`h` is not used by the variable-step method {label!r}; pass `max_step` instead.")
    try:
        return cls(model, h, **options) if fixed else cls(model, **options)
    except (ValueError, TypeError) as exc:
        raise type(exc)(f"method {label!r}: {exc}") from exc


def simulate(model: Model, t_span: tuple[float, float], method: str | type[Integrator] | Integrator = "lobatto3",
             h: float | None = None, t_eval: ArrayLike | None = None, monitors: Sequence[Monitor] = (),
             hooks: Sequence[Callable] = (), q0: ArrayLike | None = None, v0: ArrayLike | None = None,
             state0: dict | None = None, max_steps: int | None = None, progress: bool = False,
             **options: Any) -> Result:
    """Integrate ``model`` over ``t_span`` with the named integrator.

    Parameters
    ----------
    model : Model
        Anything implementing :class:`ancfdae.problem.Model`.
    t_span : (t0, tf)
    method : str, Integrator subclass or Integrator instance
        A key of :data:`METHODS` -- ``"lobatto3"`` (default, the chapter's
        Lobatto IIIA, order 4), ``"lobatto2"``, ``"newmark"``, ``"hht"``,
        ``"generalized-alpha"``, ``"ida"``, ``"energy-momentum"`` (constant
        mass matrix and the ``"potential"`` capability: energy and momenta
        kept exactly, order 2), ``"energy-collocation"`` (the same models:
        energy kept exactly, order 4) -- or a class written against
        :class:`ancfdae.integrators.Integrator` (built with
        ``cls(model, h, **options)`` or ``cls(model, **options)``), or a
        constructed instance (then no ``h`` or options here).
    h : float
        Step size; required by the fixed-step methods, not accepted by IDA
        (use ``max_step``).
    t_eval : array_like, optional
        Output times within ``t_span`` (default: every step). Off-grid times
        are interpolated by the integrator (quintic Hermite through ``q, v, a``
        for the one-step methods, IDA's own interpolant for IDA).
    monitors : sequence of Monitor
        E.g. ``[EnergyMonitor(), PointSensor(s=1.0)]``; logged at the output
        times into ``Result.monitors``.
    hooks : sequence of callables
        ``hook(t, q, v, a)`` after every accepted step; returning True ends
        the run early (status "success").
    q0, v0 : array_like, optional
        Initial state (default ``model.initial_state()``).
    state0 : dict, optional
        The model's event state to start from (models with the
        ``"step_events"`` capability, e.g. BE3D's ``{"directors": ...}``; a
        row of a previous ``Result.model_state`` resumes that run).
    max_steps : int, optional
        Limit of accepted steps (default 10,000,000). A fixed-step run that
        needs more is refused before it starts (ValueError); a variable-step
        run that reaches it ends as failed.
    progress : bool
        Show a tqdm progress bar of the simulated time (steps/s, ETA).
    **options
        Passed to the integrator: ``newton=NewtonOptions(...)`` (the Newton steppers),
        ``beta, gamma`` (newmark), ``alpha`` (hht), ``rho_inf``
        (generalized-alpha), ``predictor`` (lobatto), ``rtol, atol,
        max_order, linsolver, ...`` (ida).

    Returns
    -------
    Result
        ``status`` "success" or "failed" (with ``message`` and ``t_fail``);
        a failed run -- also one ended by an exception in a user's callback,
        whose type and text are in ``message`` -- keeps every output up to
        the failure.
    """
    stepper = _build(model, method, h, options)
    return integrate(stepper, model, t_span, t_eval=t_eval, monitors=monitors, hooks=hooks, q0=q0, v0=v0,
                     state0=state0, max_steps=max_steps, progress=bool(progress))
