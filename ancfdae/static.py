"""Static equilibrium by Newton's method with uniform load steps (chapter Sect. 5.1)."""
from __future__ import annotations

import time as _time
import warnings
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike
from scipy.linalg import LinAlgWarning

from . import _validate as validate
from ._scale import absolute_tolerance
from .integrators._newton import NewtonSolver
from .integrators._newton_records import RENAMED_ATOL, NewtonOptions
from .problem import Model, capabilities

__all__ = ["solve_static", "StaticResult"]


@dataclass
class StaticResult:
    """Outcome of :func:`solve_static`.

    Attributes
    ----------
    q : ndarray
        Coordinates of the last converged load step (the solution when
        ``status == "success"``; never an unconverged iterate).
    status : {"success", "failed"}
        As :attr:`ancfdae.Result.status`: "success" when every load step converged.
    message : str
        Says which load step failed and with which residual, if one did.
    iterations : int
        Newton iterations over all load steps.
    steps : list of dict
        Per load step: ``load_factor``, ``iterations``, ``residual``, ``converged``, ``q``.
    stats : dict
        Work counters under the names of :attr:`ancfdae.Result.stats`: ``newton_iterations``,
        ``newton_solves``, ``failed_solves``, ``retries``, ``residual_evals``, ``jacobian_evals``,
        ``factorizations``, and ``cpu_time`` (process time of the solve in seconds).
    state : dict
        The model's event state after the last converged load step (models with the
        ``"step_events"`` capability, e.g. BE3D's ``{"directors": ...}``); empty otherwise.
    """

    q: np.ndarray
    status: str
    message: str
    iterations: int
    steps: list = field(default_factory=list)
    stats: dict = field(default_factory=dict)
    state: dict = field(default_factory=dict)

    @property
    def success(self) -> bool:
        """True when every load step converged."""
        return self.status == "success"


@validate.renamed("atol", "residual_atol", RENAMED_ATOL)
def solve_static(model: Model, load_steps: int = 10, *, t: float = 0.0, q0: ArrayLike | None = None, tol: float = 1e-8,
                 residual_atol: float | None = None, max_iter: int = 25, jacobian: str = "full") -> StaticResult:
    """Solve ``r(t, q, 0, 0) = 0`` with the loads applied in uniform steps.

    Load step ``i`` solves for the load factor ``lambda_i = i / load_steps``,
    starting from the solution of step ``i - 1`` (chapter Sect. 5.1: ten
    uniform steps ``F_i = i/10 F``, full Newton, converged when
    ``max|r| / max|r_first| < 1e-8``).

    Parameters
    ----------
    model : Model
        Must have a ``load_factor`` attribute (as :class:`ancfdae.models.Beam`
        does) when ``load_steps > 1``; the attribute is restored afterwards.
    load_steps : int
        Number of uniform load steps (>= 1).
    t : float
        Time at which the time functions of the loads are evaluated.
    q0 : array_like, optional
        Initial guess; the model's initial state by default.
    tol : float
        Relative tolerance: a load step converges when ``max|r| <= tol *
        max|r_0|``, ``r_0`` the residual at its start (the chapter's test).
    residual_atol : float, optional
        Absolute tolerance on the residual, in its units (formerly ``atol``). By
        default it is derived from round-off, ``ATOL_ROUNDOFF * eps *
        force_scale(model, t, q0)`` at full load (see
        :func:`ancfdae._scale.absolute_tolerance`), never a fixed number of newtons:
        a 1e-10 N tip load on a micro-fibre is then solved, not declared converged
        before the first iteration.
    max_iter : int
        Newton iterations allowed per load step.
    jacobian : {"full", "modified"}
        Newton's refresh policy (:class:`ancfdae.integrators.NewtonOptions`);
        ``"full"`` is the chapter's classical Newton.

    Returns
    -------
    StaticResult
        A step that does not converge ends the solve with ``status="failed"``
        and a message naming the load step and its residual; ``q`` is then the
        last converged step's solution.
    """
    load_steps = validate.positive_int("load_steps", load_steps)
    if load_steps > 1 and not hasattr(model, "load_factor"):
        raise ValueError("`model` must have a `load_factor` attribute for load stepping; "
                         f"use load_steps=1 with {type(model).__name__}.")
    caps = capabilities(model)
    state = model.event_state() if "step_events" in caps else {}
    m = model.bind(state) if state else model   # the model is never changed; the state is carried here
    q = model.initial_state()[0].copy() if q0 is None else np.array(q0, dtype=float)
    if q.shape != (model.n_dof,):
        raise ValueError(f"`q0` must have shape ({model.n_dof},), got {q.shape}.")
    if residual_atol is None:
        residual_atol = absolute_tolerance(model, t, q)
    solver = NewtonSolver(NewtonOptions(tol=tol, residual_atol=residual_atol, max_iter=max_iter, jacobian=jacobian))
    z = np.zeros(model.n_dof)
    saved = getattr(model, "load_factor", None)
    steps, status, message = [], "success", f"converged in {load_steps} load steps"
    start = _time.process_time()
    try:
        for i in range(1, load_steps + 1):
            lam = i / load_steps
            if saved is not None:
                m.load_factor = saved * lam
            fused = None
            if "residual_jacobian" in caps:
                def fused(x, m=m):
                    r, J = m.residual_jacobian(t, x, z, z)
                    return r, J.K
            # A singular stiffness (no supports: rigid-body motions) makes LAPACK warn and Newton's
            # correction non-finite; the failed status below says why instead of the warning.
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", LinAlgWarning)
                out = solver.solve(lambda x, m=m: m.residual(t, x, z, z), lambda x, m=m: m.jacobian(t, x, z, z).K,
                                   q, residual_atol=residual_atol, residual_jacobian=fused)
            singular = [w for w in caught if issubclass(w.category, LinAlgWarning)]
            for w in caught:
                if w not in singular or out.converged:
                    warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
            steps.append({"load_factor": lam, "iterations": out.iterations, "residual": out.residual_norm,
                          "converged": out.converged, "q": out.x if out.converged else q.copy()})
            if not out.converged:
                status = "failed"
                message = (f"load step {i} of {load_steps} (load factor {lam:g}) did not converge: "
                           f"{out.message}; max|r| = {out.residual_norm:.3e}")
                if singular or "singular" in out.message or "factorisation failed" in out.message:
                    why = f" ({singular[0].message})" if singular else ""
                    message += (f". The stiffness matrix is singular{why}: a static "
                                "problem needs supports that remove every rigid-body motion.")
                break
            q = out.x
            ev = m.step_event(t, q, z) if state else None
            if ev is not None:   # BE3D: the directors follow the converged configuration
                q, _, state = ev
                m = model.bind(state)
    finally:
        if saved is not None:
            model.load_factor = saved
    stats = solver.stats.as_stats()
    stats["cpu_time"] = _time.process_time() - start
    return StaticResult(q=q, status=status, message=message,
                        iterations=sum(s["iterations"] for s in steps), steps=steps, stats=stats, state=state)
