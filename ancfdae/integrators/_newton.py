"""Newton and modified Newton iteration with LU reuse.

The chapter (Sect. 5.1) solves each load step with a classical Newton method
and (Sect. 5.2) each time step with a *modified* Newton method that updates
the Jacobian "only if required, i.e., if the Newton residual is not converging
fast enough"; both stop when the max-norm of the residual over the max-norm of
the initial residual drops below ``1e-8``. :class:`NewtonSolver` implements
both policies on a caller-supplied residual and Jacobian:

* ``jacobian="full"``: evaluate and factorise the Jacobian at every iteration.
* ``jacobian="modified"``: keep the factorised matrix across iterations *and*
  across calls to :meth:`NewtonSolver.solve`; refresh it when the observed
  contraction rate ``max|r_{k+1}| / max|r_k|`` exceeds ``contraction``, and,
  when a solve that started from a stale matrix fails, retry it once from the
  initial guess with a fresh matrix before giving up.

Imitates the simplified Newton of scipy's ``radau.solve_collocation_system``
(LU reuse, rate estimate, early exit) with the chapter's residual test.
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike

from .._scale import max_abs
from ._linsolve import factorize
from . import _newton_messages as says
from ._newton_records import CONTRACTION, NewtonOptions, NewtonOutcome, NewtonStats

__all__ = ["NewtonSolver"]

#: A rate above this with a matrix evaluated during the current attempt counts
#: as divergence; two such iterations in a row end the attempt early.
DIVERGENCE_RATE = 1.0
#: An ``accept`` test failed by at most this factor converges after one more correction from the residual at
#: hand, without evaluating a new one: modified Newton shrinks what ``accept`` measures by its rate (0.03 to
#: 0.1 on the energy-preserving collocation's steps). Measured there (one SQ3D element, 1000 steps of 10 ms,
#: residuals per step): energy drift 3.8e-14 with 10.6; 6.0e-15 with 11.2 at factor 10; 4.3e-15 with 12.1
#: iterating on every time; 4.9e-13 with 10.4 for the residual test alone.
ACCEPT_AFTER_CORRECTION = 100.0




class _Factor:
    """LU factorisation (banded LAPACK, dense LAPACK or SuperLU; see ``_linsolve``)."""

    def __init__(self, matrix):
        self._lu = factorize(matrix)

    def solve(self, rhs):
        return self._lu.solve(rhs)


class NewtonSolver:
    """Solve ``residual(x) = 0`` by (modified) Newton iteration.

    Parameters
    ----------
    options : NewtonOptions, optional
        Defaults to ``NewtonOptions()``.

    Attributes
    ----------
    stats : NewtonStats
        Cumulative counters over every call.

    Notes
    -----
    A solve converges when ``max|r_k| <= max(tol * max|r_0|, residual_atol, floor)``. The two
    absolute levels are arguments of :meth:`solve`, never state of the solver: ``residual_atol`` is
    the caller's tolerance (the steppers derive it once per run from the problem's force scale), and
    ``floor`` the round-off level of the residual, which the caller knows from its stiffness (see
    :mod:`ancfdae._scale`). The solver keeps at most one factorisation. The caller must call
    :meth:`invalidate` whenever the meaning of the Jacobian changes in a way the contraction test
    cannot be trusted to detect (new step size, new iteration-matrix coefficients, different
    equations).
    """

    def __init__(self, options: NewtonOptions | None = None) -> None:
        if options is None:
            options = NewtonOptions()
        if not isinstance(options, NewtonOptions):
            raise TypeError(f"`options` must be a NewtonOptions, got {type(options).__name__}.")
        #: as given (``contraction`` None: the method's choice, :meth:`choose_contraction`)
        self.given = options
        self.options = options if options.contraction is not None else replace(options, contraction=CONTRACTION)
        self.stats = NewtonStats()
        self._lu: _Factor | None = None

    def choose_contraction(self, value: float) -> None:
        """The method's refresh threshold ``value``, unless the user gave one (``NewtonOptions.contraction``)."""
        if self.given.contraction is None:
            self.options = replace(self.given, contraction=value)

    def invalidate(self) -> None:
        """Drop the cached factorisation; the next iteration refactorises."""
        self._lu = None

    @property
    def has_factorization(self) -> bool:
        """True while a factorisation is cached."""
        return self._lu is not None

    def _refresh(self, jacobian, x, J, floor, keep_max):
        """Evaluate (unless given) and factorise the matrix; returns ``(error message or None, floor)``."""
        if J is None:
            J = jacobian(x)
            if type(J) is tuple:      # (matrix, the residual's round-off floor at x)
                J, new = J
                floor = max(floor, new) if keep_max else new
        self.stats.jacobian_evals += 1
        try:
            self._lu = _Factor(J)
        except RuntimeError as exc:  # SuperLU: "Factor is exactly singular"
            self._lu = None
            return f"factorisation failed: {exc}", floor
        self.stats.factorizations += 1
        return None, floor

    def _eval(self, residual, x):
        self.stats.residual_evals += 1
        r = residual(x)
        if type(r) is not np.ndarray or r.dtype != np.float64:
            r = np.asarray(r, dtype=float)
        if r.shape != x.shape:
            raise ValueError(f"`residual` must return shape {x.shape}, got {r.shape}.")
        return r

    def _eval_fused(self, residual_jacobian, x):
        self.stats.residual_evals += 1
        r, J = residual_jacobian(x)
        if type(r) is not np.ndarray or r.dtype != np.float64:
            r = np.asarray(r, dtype=float)
        if r.shape != x.shape:
            raise ValueError(f"`residual_jacobian` must return a residual of shape {x.shape}, got {r.shape}.")
        return r, J

    def solve(
        self,
        residual: Callable[[np.ndarray], np.ndarray],
        jacobian: Callable[[np.ndarray], object],
        x0: ArrayLike,
        *,
        residual_atol: float | None = None,
        floor: float = 0.0,
        floor_update: str = "max",
        residual_jacobian: Callable[[np.ndarray], tuple] | None = None,
        iterate: Callable | None = None,
        accept: Callable[[np.ndarray, np.ndarray], bool] | None = None,
    ) -> NewtonOutcome:
        """Iterate from ``x0`` until the residual test passes.

        Parameters
        ----------
        residual : callable
            ``residual(x) -> ndarray`` of the shape of ``x``.
        jacobian : callable
            ``jacobian(x) -> d residual / dx`` as a scipy sparse matrix or a
            dense 2-D array; or ``jacobian(x) -> (matrix, floor)`` with the
            round-off floor of the residual at ``x`` (see :mod:`ancfdae._scale`),
            which updates ``floor`` from that iteration on (``floor_update``).
        x0 : array_like
            Initial guess (not modified).
        residual_atol : float, optional
            Absolute tolerance of this solve, in the residual's units.
            Default: ``options.residual_atol``, 0 when that is None.
        floor : float
            The residual's round-off floor at the start of this solve (the
            caller's, carried from its earlier solves: a modified Newton solve
            may start with an earlier matrix).
        floor_update : {"max", "replace"}
            How a floor that comes with a new matrix updates the one in effect:
            ``"max"`` keeps the larger (a running maximum, when the caller
            carries it over a run), ``"replace"`` takes the new one (the floor
            of the matrix in use).
        residual_jacobian : callable, optional
            ``residual_jacobian(x) -> (residual, jacobian)`` in one pass. With
            full Newton every residual is followed by a Jacobian at the same
            point, so a model that computes both from one kernel evaluation
            saves the second pass (B1 with BE2D: about a fifth of the solve).
            Ignored by modified Newton, which seldom needs the Jacobian.
        iterate : callable, optional
            ``iterate(x, r, factor, err, max_k, contraction, threshold) -> (max|dx|, err_new, err_prev, k)``
            or None when it cannot use ``factor``: ``k >= 1`` iterations as one compiled call that updates
            ``x`` and ``r`` in place, on while this loop would carry on without a decision (contract in
            :mod:`ancfdae.models.beam.iteration_numba`; :mod:`ancfdae.integrators._alpha_iteration`);
            modified Newton only.

        accept : callable, optional
            ``accept(x, r) -> float``, asked once the residual test passes or the residual stagnates
            (``r`` the residual at ``x``): how many times a quantity exceeds its allowance. At most 1:
            converged; at most :data:`ACCEPT_AFTER_CORRECTION`: converged after one more correction
            (no new residual); else the iteration carries on with the same matrix while the correction
            still halves, converging when it no longer does (the attainable accuracy) or ``accept``
            agrees. The energy-preserving collocation asks for its energy identity to round-off with
            it. Python iterations only (not with ``iterate``).

        Returns
        -------
        NewtonOutcome
            Never raises on non-convergence; exceptions raised by the
            callbacks propagate. ``floor`` is the floor in effect at the end,
            to start the next solve with.
        """
        if residual_atol is None:
            residual_atol = self.options.residual_atol or 0.0
        keep_max = floor_update == "max"
        if not keep_max and floor_update != "replace":
            raise ValueError(f"`floor_update` must be one of ['max', 'replace'], got {floor_update!r}.")
        fused = residual_jacobian if self.options.jacobian == "full" else None
        x0 = np.array(x0, dtype=float, copy=True).ravel()
        self.stats.solves += 1
        if fused is not None:
            r, J = self._eval_fused(fused, x0)
        else:
            r, J = self._eval(residual, x0), None
        if not math.isfinite(max_abs(r)):
            self.stats.failed_solves += 1
            return NewtonOutcome(x0, False, 0, float("nan"), says.initial_not_finite(), floor)
        if fused is not None:
            iterate = None
        outcome, stale = self._attempt(residual, jacobian, x0, r, residual_atol, floor, keep_max, fused, J, iterate,
                                       accept)
        if (not outcome.converged and stale and self.options.jacobian == "modified"
                and self.options.retry):
            # The failed attempt started from a matrix of an earlier solve:
            # retry once from the initial guess with a fresh one.
            self.stats.retries += 1
            self.invalidate()
            first = outcome
            retry, _ = self._attempt(residual, jacobian, x0, r, residual_atol, first.floor, keep_max,
                                     iterate=iterate, accept=accept)
            outcome = NewtonOutcome(retry.x, retry.converged, first.iterations + retry.iterations,
                                    retry.residual_norm,
                                    retry.message if retry.converged else
                                    f"{retry.message} (after a retry with a fresh Jacobian; "
                                    f"first attempt: {first.message})", retry.floor)
        if not outcome.converged:
            self.stats.failed_solves += 1
        return outcome

    def _attempt(self, residual, jacobian, x0, r, atol, floor, keep_max, fused=None, J=None, iterate=None,
                 accept=None):
        """One Newton attempt; returns (outcome, started_with_stale_matrix).

        With ``fused`` (full Newton and a ``residual_jacobian``), ``J`` is the
        Jacobian evaluated with ``r``, and every new residual brings its own.
        With ``iterate``, an iteration is one compiled call where the factor allows it.
        """
        opts = self.options
        full = opts.jacobian == "full"
        stale = self._lu is not None and not full
        x = x0.copy()
        if iterate is not None:
            r = r.copy()   # compiled iterations update r in place; the caller's r starts a retry
        err0 = err = max_abs(r)
        rel = max(opts.tol * err0, atol)
        threshold = max(rel, floor)
        if err <= threshold and (accept is None or accept(x, r) <= 1.0):
            return NewtonOutcome(x, True, 0, err, says.converged_initial(), floor), stale
        polish = err <= threshold   # below the residual test, not accepted: iterate on while the correction halves
        dx_last = np.inf
        fresh = False  # the cached matrix was evaluated during this attempt
        diverging = 0
        k = 0
        while k < opts.max_iter:
            k += 1
            if full or self._lu is None:
                msg, floor = self._refresh(jacobian, x, J, floor, keep_max)
                if msg is not None:
                    return NewtonOutcome(x, False, k - 1, err, msg, floor), stale
                fresh = True
                threshold = max(rel, floor)  # a new matrix may bring a new floor
            step = (iterate(x, r, self._lu._lu, err, opts.max_iter - k + 1, opts.contraction, threshold)
                    if iterate is not None else None)   # x, r: this attempt's own arrays
            if step is not None:
                # compiled iterations, x and r in place, up to the one that needs a decision (iterate's docstring)
                dx_max, err_new, err, n = step
                self.stats.iterations += n
                k += n - 1
                if n > 1:
                    diverging = 0   # the iterations before the last one contracted
                finite = math.isfinite(dx_max)
                self.stats.residual_evals += n if finite else n - 1
                if not finite:
                    return NewtonOutcome(x, False, k, err, says.dx_not_finite(), floor), stale
            else:
                dx = self._lu.solve(r)   # the correction is -dx (negation commutes exactly with the solve)
                self.stats.iterations += 1
                dx_max = max_abs(dx)  # NaN/inf propagate into the max
                if not math.isfinite(dx_max):   # math: 20x cheaper than np on a float
                    return NewtonOutcome(x, False, k, err, says.dx_not_finite(), floor), stale
                x = x - dx
                if fused is not None:
                    r, J = self._eval_fused(fused, x)
                else:
                    r = self._eval(residual, x)
                err_new = max_abs(r)
            if not math.isfinite(err_new):
                return NewtonOutcome(x, False, k, float("nan"),
                                     says.r_not_finite(k), floor), stale
            # Round-off stagnation: a fresh matrix, a correction at round-off
            # level and a residual that no longer falls -- the attainable accuracy.
            stagnant = (err_new > threshold and fresh and err_new > 0.5 * err
                        and dx_max <= opts.xtol * max(1.0, max_abs(x)))
            if accept is None and err_new <= threshold:
                return NewtonOutcome(x, True, k, err_new, says.converged(k), floor), stale
            if accept is None and stagnant:
                return NewtonOutcome(x, True, k, err_new, says.stagnant(k, err_new), floor), stale
            if accept is not None and (polish or stagnant or err_new <= threshold):
                ratio = accept(x, r)
                if ratio <= 1.0:
                    return NewtonOutcome(x, True, k, err_new, says.converged(k), floor), stale
                if ratio <= ACCEPT_AFTER_CORRECTION:
                    self.stats.iterations += 1
                    return NewtonOutcome(x - self._lu.solve(r), True, k + 1, err_new, says.last_without_residual(k + 1), floor), stale
                if polish and not dx_max <= 0.5 * dx_last:
                    return NewtonOutcome(x, True, k, err_new, says.stalled(k, dx_max), floor), stale
                polish, dx_last, err = True, dx_max, err_new
                continue           # the matrix kept: a residual at its floor says nothing about the rate
            rate = err_new / err if err > 0 else np.inf
            err = err_new
            if rate > opts.contraction:
                if fresh and rate >= DIVERGENCE_RATE:
                    diverging += 1
                    if diverging >= 2:
                        return NewtonOutcome(x, False, k, err, says.diverging(rate, k), floor), stale
                else:
                    diverging = 0
                if not full:
                    self._lu = None  # refresh at the current iterate
            else:
                diverging = 0
        if polish:
            return NewtonOutcome(x, True, opts.max_iter, err, says.at_floor(opts.max_iter), floor), stale
        return NewtonOutcome(x, False, opts.max_iter, err,
                             says.not_converged(opts.max_iter, err, threshold), floor), stale
