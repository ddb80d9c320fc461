"""``simulate``: the one front door to the integrators (design.md Sect. 2, 5).

Imitates scipy's ``solve_ivp``: a ``METHODS`` registry, options forwarded to
the integrator, and a :class:`~ancfdae.result.Result` that reports failure in
its ``status`` instead of raising. Bad arguments still raise (ValueError /
TypeError naming the argument).
"""
from __future__ import annotations

import inspect

from ancfdae.integrators._base import FixedStepIntegrator
from ancfdae.integrators.ida import IDA
from ancfdae.integrators.lobatto import LobattoIIIA
from ancfdae.integrators.newmark import GeneralizedAlpha, HHTAlpha, Newmark
from ancfdae._resultfile import describe_model
from ancfdae.result import Result

__all__ = ["simulate", "METHODS"]


class Lobatto3(LobattoIIIA):
    """Lobatto IIIA with 3 stages (order 4; the chapter's integrator)."""

    def __init__(self, model, h, *, newton=None, predictor="constant"):
        super().__init__(model, h, 3, newton=newton, predictor=predictor)


class Lobatto2(LobattoIIIA):
    """Lobatto IIIA with 2 stages (trapezoidal rule, order 2)."""

    def __init__(self, model, h, *, newton=None, predictor="constant"):
        super().__init__(model, h, 2, newton=newton, predictor=predictor)


#: name -> integrator class; fixed-step classes take ``h``, IDA does not.
METHODS = {
    "lobatto3": Lobatto3,
    "lobatto2": Lobatto2,
    "newmark": Newmark,
    "hht": HHTAlpha,
    "generalized-alpha": GeneralizedAlpha,
    "ida": IDA,
}


def _resolve(method):
    if isinstance(method, str):
        if method not in METHODS:
            raise ValueError(f"`method` must be one of {sorted(METHODS)} or an integrator class, got {method!r}.")
        return METHODS[method]
    if inspect.isclass(method) and (issubclass(method, FixedStepIntegrator) or issubclass(method, IDA)):
        return method
    raise ValueError(f"`method` must be one of {sorted(METHODS)} or an integrator class, got {method!r}.")


def simulate(model, t_span, method="lobatto3", h=None, t_eval=None, monitors=(), hooks=(), q0=None, v0=None,
             **options) -> Result:
    """Integrate ``model`` over ``t_span`` with the named integrator.

    Parameters
    ----------
    model : Model
        Anything implementing :class:`ancfdae.problem.Model`.
    t_span : (t0, tf)
    method : str or class
        A key of :data:`METHODS` -- ``"lobatto3"`` (default, the chapter's
        Lobatto IIIA, order 4), ``"lobatto2"``, ``"newmark"``, ``"hht"``,
        ``"generalized-alpha"``, ``"ida"`` -- or an integrator class.
    h : float
        Step size; required by the fixed-step methods, not accepted by IDA
        (use ``max_step``).
    t_eval : array_like, optional
        Output times within ``t_span`` (default: every step). Off-grid times
        are interpolated (quintic Hermite through ``q, v, a``).
    monitors : sequence of Monitor
        E.g. ``[EnergyMonitor(), PointSensor(s=1.0)]``; logged at the output
        times into ``Result.monitors``.
    hooks : sequence of callables
        ``hook(t, q, v, a)`` after every accepted step; returning True ends
        the run early (status "success").
    q0, v0 : array_like, optional
        Initial state (default ``model.initial_state()``).
    **options
        Passed to the integrator: ``newton=NewtonOptions(...)`` (fixed-step),
        ``beta, gamma`` (newmark), ``alpha`` (hht), ``rho_inf``
        (generalized-alpha), ``predictor`` (lobatto), ``rtol, atol,
        max_order, ...`` (ida).

    Returns
    -------
    Result
        ``status`` "success" or "failed" (with ``message`` and ``t_fail``);
        a failed run keeps every output up to the failure.
    """
    cls = _resolve(method)
    params = inspect.signature(cls.__init__).parameters
    allowed = [p for p in params if p not in ("self", "model", "h")]
    unknown = sorted(set(options) - set(allowed))
    if unknown:
        raise ValueError(f"unknown option(s) {unknown} for method {getattr(cls, 'name', cls.__name__)!r}; "
                         f"allowed: {allowed}.")
    if "h" in params:
        if h is None:
            raise ValueError(f"`h` (the step size) is required by the fixed-step method {method!r}.")
        integrator = cls(model, h, **options)
    else:
        if h is not None:
            raise ValueError(f"`h` is not used by the variable-step method {method!r}; pass `max_step` instead.")
        integrator = cls(model, **options)
    result = integrator.run(t_span, t_eval=t_eval, monitors=monitors, hooks=hooks, q0=q0, v0=v0)
    if not result.model:   # the model's self-description, for self-describing result files
        result.model = describe_model(model)
    return result
