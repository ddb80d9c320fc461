"""Shared machinery of the integrators (design.md Sect. 5).

* :func:`check_model`, :func:`consistent_acceleration` -- validation and the
  consistent initial acceleration ``M(q0) a0 = f_ext - f_int`` obtained from
  the contract as ``M(q0) a0 = -r(t0, q0, v0, 0)``.
* :class:`Recorder` -- output arrays, monitors and the :class:`Result`.
* :class:`FixedStepIntegrator` -- the fixed-step loop. As in scipy's
  ``_ivp/base.py`` the public :meth:`~FixedStepIntegrator.step` does the
  bookkeeping (time grid, status, counters, the model's ``accept_step`` hook)
  and calls one private ``_step_impl`` that a method implements.

Output times (``t_eval``) that lie on the step grid (within ``1e-9 h``) are
reported exactly; others are interpolated with the quintic Hermite polynomial
through ``(q, v, a)`` at the two ends of the step (interpolation error
O(h^6) in ``q``, O(h^5) in ``v``, O(h^4) in ``a``, below the integrators'
own error for the step sizes they are used with).
"""
from __future__ import annotations

import time
from abc import ABC, abstractmethod

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ancfdae import _validate as V
from ancfdae.integrators._hermite import hermite5
from ancfdae.integrators._newton import NewtonOptions, NewtonSolver, NewtonStats
from ancfdae.problem import accept_step
from ancfdae.result import Result

__all__ = ["check_model", "consistent_acceleration", "output_times", "Recorder", "FixedStepIntegrator",
           "hermite5"]

_CONTRACT = ("initial_state", "mass", "residual", "jacobian")
#: output times within this fraction of a step from a grid point are on the grid
GRID_TOL = 1e-9
#: Newton's residual floor is ROUNDOFF * eps * max|K| * max(1, max|q|): the round-off level of
#: elastic forces (measured 4e-7 N = 1.0 eps max|K| on the 25-element BE2D pendulum, spikes to 10x).
ROUNDOFF = 10.0


def check_model(model) -> int:
    """Check that ``model`` offers the Model contract; return ``n_dof``."""
    missing = [m for m in _CONTRACT if not callable(getattr(model, m, None))]
    if missing:
        raise TypeError(f"`model` must implement the Model contract (ancfdae.problem.Model); "
                        f"{type(model).__name__} lacks {missing}.")
    n = getattr(model, "n_dof", None)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise TypeError(f"`model.n_dof` must be a positive integer, got {n!r}.")
    return int(n)


def consistent_acceleration(model, t, q, v):
    """Solve ``M(q) a = -r(t, q, v, 0)``; return ``(a, None)`` or ``(None, reason)``."""
    rhs = -np.asarray(model.residual(t, q, v, np.zeros_like(q)), dtype=float)
    M = model.mass(q)
    try:
        if sp.issparse(M):
            a = spla.splu(sp.csc_matrix(M)).solve(rhs)
        else:
            a = np.linalg.solve(np.asarray(M, dtype=float), rhs)
    except (RuntimeError, np.linalg.LinAlgError) as exc:
        return None, f"mass matrix at t0 is singular ({exc})"
    if not np.all(np.isfinite(a)):
        return None, "initial acceleration is not finite"
    return a, None


def output_times(t_span, t_eval):
    """Validate ``t_span = (t0, tf)`` and ``t_eval``; return ``(t0, tf, t_out or None)``."""
    try:
        t0, tf = (float(x) for x in t_span)
    except (TypeError, ValueError):
        raise ValueError(f"`t_span` must be a pair (t0, tf) of numbers, got {t_span!r}.") from None
    if not (np.isfinite(t0) and np.isfinite(tf)) or tf <= t0:
        raise ValueError(f"`t_span` must satisfy t0 < tf (finite), got {t_span!r}.")
    if t_eval is None:
        return t0, tf, None
    te = V.finite_vector("t_eval", t_eval)
    if te.size == 0:
        raise ValueError("`t_eval` must hold at least one time, got an empty array.")
    if np.any(np.diff(te) <= 0):
        raise ValueError("`t_eval` must be strictly increasing.")
    if te[0] < t0 or te[-1] > tf:
        raise ValueError(f"`t_eval` must lie within t_span [{t0}, {tf}], got [{te[0]}, {te[-1]}].")
    return t0, tf, te


class Recorder:
    """Collect output samples and drive the monitors; build the :class:`Result`."""

    def __init__(self, model, monitors=()):
        monitors = list(monitors or ())
        names = set()
        for m in monitors:
            if not all(callable(getattr(m, k, None)) for k in ("start", "advance", "sample", "log")):
                raise TypeError(f"`monitors` entries must be Monitor objects (start/advance/sample/log), got {m!r}.")
            if m.name in names:
                raise ValueError(f"monitor names must be unique, got {m.name!r} twice.")
            names.add(m.name)
        self.model, self.monitors = model, monitors
        self.t, self.q, self.v, self.a = [], [], [], []

    def start(self, t, q, v, a):
        for m in self.monitors:
            m.start(self.model, t, q, v, a)

    def advance(self, t, q, v, a, nodes=None):
        for m in self.monitors:
            m.advance(t, q, v, a, nodes)

    def sample(self, t, q, v, a):
        self.t.append(float(t))
        self.q.append(np.array(q, dtype=float))
        self.v.append(np.array(v, dtype=float))
        self.a.append(np.array(a, dtype=float))
        for m in self.monitors:
            m.sample(t, q, v, a)

    def stop_reason(self):
        for m in self.monitors:
            reason = m.stop_reason() if callable(getattr(m, "stop_reason", None)) else None
            if reason:
                return reason
        return None

    def result(self, n_dof, **kw) -> Result:
        def stack(rows):
            return np.array(rows) if rows else np.zeros((0, n_dof))
        return Result(t=np.array(self.t), q=stack(self.q), v=stack(self.v), a=stack(self.a),
                      monitors={m.name: m.log() for m in self.monitors}, **kw)


class FixedStepIntegrator(ABC):
    """Base of the fixed-step integrators.

    Parameters
    ----------
    model : Model
        Anything implementing :class:`ancfdae.problem.Model`.
    h : float
        Step size (> 0). The last step is shortened to end exactly at ``tf``.
    newton : NewtonOptions or dict, optional
        Options of the Newton solver (dict: keyword arguments of
        :class:`NewtonOptions`).

    Attributes
    ----------
    t, q, v, a : current state (after :meth:`initialize`)
    status : {"idle", "running", "finished", "failed"}
    message : str
    """

    name = "fixed-step"
    order = 0

    def __init__(self, model, h, *, newton=None):
        self.n_dof = check_model(model)
        self.model = model
        self.h = V.positive("h", h)
        if newton is None:
            newton = NewtonOptions()
        elif isinstance(newton, dict):
            newton = NewtonOptions(**newton)
        elif not isinstance(newton, NewtonOptions):
            raise TypeError(f"`newton` must be a NewtonOptions or a dict, got {type(newton).__name__}.")
        self.newton = NewtonSolver(newton)
        self.status, self.message = "idle", ""
        self._h_matrix = None
        #: build the step's quadrature nodes for the monitors (set by run() when there are monitors)
        self.want_nodes = False

    # -- options record ----------------------------------------------------------------------
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

    # -- state -------------------------------------------------------------------------------
    def initialize(self, t0=0.0, q0=None, v0=None, a0=None, t_bound=None) -> bool:
        """Set the initial state; compute a consistent ``a0`` unless given.

        Returns False (with ``status == "failed"``) when ``a0`` cannot be
        computed.
        """
        t0 = float(t0)
        q_i, v_i = self.model.initial_state() if (q0 is None or v0 is None) else (None, None)
        q0 = V.finite_vector("q0", q_i if q0 is None else q0, self.n_dof).copy()
        v0 = V.finite_vector("v0", v_i if v0 is None else v0, self.n_dof).copy()
        self._n_res = self._n_jac = self.n_steps = 0
        self.newton.invalidate()
        self.newton.residual_floor = 0.0
        self.t0, self.t, self.t_bound = t0, t0, (None if t_bound is None else float(t_bound))
        self.q, self.v = q0, v0
        self.status, self.message, self.t_fail = "running", "", None
        self._last_nodes = None
        if a0 is None:
            self._n_res += 1
            a0, reason = consistent_acceleration(self.model, t0, q0, v0)
            if a0 is None:
                self.status, self.t_fail = "failed", t0
                self.message = f"initial acceleration at t = {t0:g} failed: {reason}"
                return False
        self.a = V.finite_vector("a0", a0, self.n_dof).copy()
        self._init_impl()
        return True

    def _init_impl(self) -> None:
        """Method-specific set-up after the initial state is known."""

    def step(self) -> bool:
        """Advance one step; on failure keep the state and set ``status = "failed"``."""
        if self.status != "running":
            raise RuntimeError(f"step() needs a running integrator (call initialize()), status is {self.status!r}.")
        t_new = self.t0 + (self.n_steps + 1) * self.h
        if self.t_bound is not None and t_new >= self.t_bound - GRID_TOL * self.h:
            t_new = self.t_bound
        h = t_new - self.t
        if self._h_matrix is None or abs(h - self._h_matrix) > 1e-8 * self.h:
            self.newton.invalidate()  # iteration-matrix coefficients depend on h
            self._h_matrix = h
        ok, info = self._step_impl(self.t, h)
        if not ok:
            self.status, self.t_fail = "failed", self.t
            self.message = f"step from t = {self.t:.9g} to {t_new:.9g} failed: {info}"
            return False
        q, v, a, nodes = info
        q, v = accept_step(self.model, t_new, q, v)
        self.t, self.q, self.v, self.a, self._last_nodes = t_new, q, v, a, nodes
        self.n_steps += 1
        if self.t_bound is not None and t_new >= self.t_bound:
            self.status = "finished"
        return True

    @abstractmethod
    def _step_impl(self, t, h):
        """Return ``(True, (q, v, a, nodes))`` or ``(False, reason)``; must not change the state."""

    # -- statistics --------------------------------------------------------------------------
    @property
    def stats(self) -> dict:
        """Work counters since :meth:`initialize`."""
        ns = self.newton.stats
        return {"steps": self.n_steps, "newton_iterations": ns.iterations, "newton_solves": ns.solves,
                "failed_solves": ns.failed_solves, "retries": ns.retries,
                "residual_evals": self._n_res, "jacobian_evals": self._n_jac,
                "factorizations": ns.factorizations}

    # -- the loop ----------------------------------------------------------------------------
    def run(self, t_span, t_eval=None, monitors=(), hooks=(), q0=None, v0=None) -> Result:
        """Integrate over ``t_span``; never raises on integration failure.

        Parameters
        ----------
        t_span : (t0, tf)
        t_eval : array_like, optional
            Output times (default: every step).
        monitors : sequence of Monitor
        hooks : sequence of callables
            ``hook(t, q, v, a)`` after every accepted step; returning True ends
            the run early with status "success".
        q0, v0 : array_like, optional
            Initial state (default ``model.initial_state()``).
        """
        t0, tf, t_out = output_times(t_span, t_eval)
        hooks = list(hooks or ())
        for k in hooks:
            if not callable(k):
                raise TypeError(f"`hooks` entries must be callables hook(t, q, v, a), got {k!r}.")
        rec = Recorder(self.model, monitors)
        self.want_nodes = bool(rec.monitors)
        self.newton.stats = NewtonStats()
        wall = time.perf_counter()
        j = 0
        if self.initialize(t0, q0, v0, t_bound=tf):
            rec.start(self.t, self.q, self.v, self.a)
            if t_out is None or abs(t_out[0] - t0) <= GRID_TOL * self.h:
                rec.sample(self.t, self.q, self.v, self.a)
                j = 1
            stopped = None
            while self.status == "running":
                old = (self.t, (self.q, self.v, self.a))
                if not self.step():
                    break
                rec.advance(self.t, self.q, self.v, self.a, self._last_nodes)
                if t_out is None:
                    rec.sample(self.t, self.q, self.v, self.a)
                else:
                    while j < t_out.size and t_out[j] <= self.t + GRID_TOL * self.h:
                        if abs(t_out[j] - self.t) <= GRID_TOL * self.h:
                            rec.sample(self.t, self.q, self.v, self.a)
                        else:
                            rec.sample(t_out[j], *hermite5(old[0], old[1], self.t, (self.q, self.v, self.a),
                                                           t_out[j]))
                        j += 1
                reason = rec.stop_reason()
                if reason:
                    self.status, self.message, self.t_fail = "failed", reason, self.t
                    break
                if any(k(self.t, self.q, self.v, self.a) is True for k in hooks):
                    stopped = self.t
                    break
            if self.status == "finished":
                self.message = f"reached tf = {tf:g} in {self.n_steps} steps"
            elif stopped is not None:
                self.status, self.message = "finished", f"stopped by a hook at t = {stopped:.9g}"
        stats = self.stats
        stats["wall_time"] = time.perf_counter() - wall
        status = "success" if self.status == "finished" else "failed"
        return rec.result(self.n_dof, status=status, message=self.message, stats=stats, t_fail=self.t_fail,
                          method=self.name, options=self.options())
