"""Static equilibrium by Newton's method with uniform load steps (chapter Sect. 5.1)."""
from __future__ import annotations

import logging
import numbers
import time as _time
import warnings
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike
from scipy.linalg import LinAlgWarning

from . import _static_checks
from . import _validate as validate
from ._scale import absolute_tolerance
from ._static_compiled import CompiledStatic
from .integrators._newton import NewtonSolver
from .integrators._newton_records import RENAMED_ATOL, NewtonOptions
from .problem import Model, capabilities

__all__ = ["solve_static", "StaticResult"]

_log = logging.getLogger("ancfdae")


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
    negative_eigenvalues : int or None
        Negative eigenvalues of the (symmetric part of the) tangent stiffness at ``q``, counted by
        the inertia of its ``L D L^T`` factorisation (:func:`ancfdae._static_checks.inertia`);
        None when not determined (``check_stability=False``, or no load step converged).
    zero_eigenvalues : int or None
        Eigenvalues within round-off of zero (a neutral direction), likewise.
    warnings : list of str
        What is implausible about ``q`` (axial strain beyond the elements' range, a folded
        element; :func:`ancfdae._static_checks.plausibility`) or unstable about it; each is also
        logged as a warning on the ``"ancfdae"`` logger.
    """

    q: np.ndarray
    status: str
    message: str
    iterations: int
    steps: list = field(default_factory=list)
    stats: dict = field(default_factory=dict)
    state: dict = field(default_factory=dict)
    negative_eigenvalues: int | None = None
    zero_eigenvalues: int | None = None
    warnings: list = field(default_factory=list)

    @property
    def success(self) -> bool:
        """True when every load step converged."""
        return self.status == "success"

    @property
    def stable(self) -> bool | None:
        """True when the tangent at ``q`` is positive definite (a stable equilibrium, for conservative
        loads); False when it has a negative or zero eigenvalue; None when not determined."""
        if self.negative_eigenvalues is None:
            return None
        return self.negative_eigenvalues == 0 and self.zero_eigenvalues == 0


@validate.renamed("atol", "residual_atol", RENAMED_ATOL)
def solve_static(model: Model, load_steps: int = 10, *, t: float = 0.0, q0: ArrayLike | None = None, tol: float = 1e-8,
                 residual_atol: float | None = None, max_iter: int = 25, jacobian: str = "full",
                 check_stability: bool = True, max_strain: float | None = _static_checks.MAX_STRAIN) -> StaticResult:
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
        ``"full"`` is the chapter's classical Newton. With ``"full"``, a BE2D beam without point
        moments solves each load step in one compiled call (:mod:`ancfdae._static_compiled`): the same
        iterates, counters and messages as the Python iteration, without its per-iteration overhead.
    check_stability : bool
        Count the negative eigenvalues of the tangent at the solution (one sparse ``L D L^T``
        factorisation). Newton converges to any equilibrium near its start, e.g. a cantilever
        held by a pin only pointing against its tip force; such an unstable equilibrium is
        reported in ``negative_eigenvalues``, ``stable`` and ``warnings`` and logged.
    max_strain : float or None
        Axial strain above which the solution is flagged as beyond the elements' range
        (default 0.1: the Green strain with St. Venant-Kirchhoff's law is meant for small
        strains); folded elements are flagged too. None skips the check.

    Returns
    -------
    StaticResult
        A step that does not converge ends the solve with ``status="failed"``
        and a message naming the load step and its residual; ``q`` is then the
        last converged step's solution. A converged solution that is unstable or
        implausible keeps ``status="success"`` and says so in ``warnings``.

    Raises
    ------
    ValueError
        For bad arguments, naming the argument: a non-finite or wrong-length ``q0``
        (also the model's initial state), a non-finite ``t``, or loads whose residual at
        ``q0`` is not finite.
    """
    load_steps = validate.positive_int("load_steps", load_steps)
    if load_steps > 1 and not hasattr(model, "load_factor"):
        raise ValueError("`model` must have a `load_factor` attribute for load stepping; "
                         f"use load_steps=1 with {type(model).__name__}.")
    caps = capabilities(model)
    state = model.event_state() if "step_events" in caps else {}
    m = model.bind(state) if state else model   # the model is never changed; the state is carried here
    if isinstance(t, bool) or not isinstance(t, numbers.Real) or not np.isfinite(t):
        raise ValueError(f"`t` must be a finite real number (the time at which the loads are evaluated), got {t!r}.")
    t = float(t)
    if q0 is None:
        q = validate.finite_vector("q0 (the model's initial state, used as q0 was not given)",
                                   model.initial_state()[0], model.n_dof).copy()
    else:
        q = validate.finite_vector("q0", q0, model.n_dof).copy()
    check_stability = validate.flag("check_stability", check_stability)
    if max_strain is not None:
        max_strain = validate.positive("max_strain", max_strain)
    z0 = np.zeros(model.n_dof)
    r0 = np.asarray(m.residual(t, q, z0, z0), dtype=float)
    if not np.all(np.isfinite(r0)):
        raise ValueError(f"the residual at `q0` (t = {t:g}) is not finite: a load (or its time function) or the "
                         "model returns NaN or inf there; check the loads' values and time functions.")
    if residual_atol is None:
        residual_atol = absolute_tolerance(model, t, q)
    solver = NewtonSolver(NewtonOptions(tol=tol, residual_atol=residual_atol, max_iter=max_iter, jacobian=jacobian))
    z = np.zeros(model.n_dof)
    saved = getattr(model, "load_factor", None)
    steps, status, message = [], "success", f"converged in {load_steps} load steps"
    start = _time.process_time()
    compiled = CompiledStatic.offer(m, t, jacobian, bool(state))   # a load step in one compiled call, or None
    try:
        for i in range(1, load_steps + 1):
            lam = i / load_steps
            if saved is not None:
                m.load_factor = saved * lam
            if compiled is not None:
                out = compiled.solve(solver, q, residual_atol)
                steps.append({"load_factor": lam, "iterations": out.iterations, "residual": out.residual_norm,
                              "converged": out.converged, "q": out.x if out.converged else q.copy()})
                if not out.converged:
                    status, message = "failed", _failure(i, load_steps, lam, out, [])
                    break
                q = out.x
                continue
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
                status, message = "failed", _failure(i, load_steps, lam, out, singular)
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
    result = StaticResult(q=q, status=status, message=message,
                          iterations=sum(s["iterations"] for s in steps), steps=steps, stats=stats, state=state)
    if any(s["converged"] for s in steps):
        _judge(result, m, t, check_stability, max_strain, len([s for s in steps if s["converged"]]), load_steps)
    return result


def _failure(i, load_steps, lam, out, singular):
    """The message of a load step that did not converge (``singular``: LAPACK's warnings during it)."""
    message = (f"load step {i} of {load_steps} (load factor {lam:g}) did not converge: "
               f"{out.message}; max|r| = {out.residual_norm:.3e}")
    if singular or "singular" in out.message or "factorisation failed" in out.message:
        why = f" ({singular[0].message})" if singular else ""
        message += (f". The stiffness matrix is singular{why}: a static "
                    "problem needs supports that remove every rigid-body motion.")
    return message


def _judge(result, m, t, check_stability, max_strain, done, load_steps):
    """Fill ``result``'s stability and plausibility of the last converged load step; log what is wrong."""
    where = "the solution" if done == load_steps else f"the last converged load step ({done} of {load_steps})"
    if check_stability and done == load_steps:      # the tangent at the full load, where q is the solution
        z = np.zeros_like(result.q)
        n_neg, n_zero, how = _static_checks.inertia(m.jacobian(t, result.q, z, z).K)
        result.negative_eigenvalues, result.zero_eigenvalues = n_neg, n_zero
        if n_neg:
            result.warnings.append(f"{where} is an unstable equilibrium: the tangent stiffness has {n_neg} "
                                   f"negative eigenvalue(s) ({how}); a small disturbance leaves it (e.g. a "
                                   "beam held by a pin pointing against its load); start from another q0")
        elif n_zero:
            result.warnings.append(f"{where} is not a stable equilibrium: the tangent stiffness has {n_zero} "
                                   f"zero eigenvalue(s) ({how}), a neutral direction")
        elif n_neg is None:
            result.warnings.append(f"the stability of {where} was {how}")
    if max_strain is not None:
        result.warnings += [f"{where}: {w}" for w in _static_checks.plausibility(m, result.q, max_strain)]
    for w in result.warnings:
        _log.warning("solve_static: %s", w)
