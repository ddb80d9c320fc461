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
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike
from numba import njit

from ._linsolve import factorize
from ._newton_records import NewtonOptions, NewtonOutcome, NewtonStats

__all__ = ["NewtonOptions", "NewtonStats", "NewtonOutcome", "NewtonSolver"]

#: A rate above this with a matrix evaluated during the current attempt counts
#: as divergence; two such iterations in a row end the attempt early.
DIVERGENCE_RATE = 1.0


@njit(cache=True)
def max_abs(x):
    """``max|x|`` of a 1-D array, 0 when empty, NaN if any entry is NaN (inf propagates).

    One compiled pass: ``float(np.abs(x).max())`` costs 1.4 us on a Newton-sized
    vector, mostly call overhead, and runs three times per iteration.
    """
    m = 0.0
    for v in x:
        a = abs(v)
        if a != a:
            return a
        if a > m:
            m = a
    return m


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

    scaled_atol : float
        The absolute tolerance used when ``options.atol`` is ``None``, set by
        the caller from the problem's force scale (``0`` until it does).
    residual_floor : float
        Absolute round-off floor of the residual that the caller may set (and
        update, e.g. at every Jacobian evaluation): the convergence test is
        ``max|r_k| <= max(tol * max|r_0|, atol, residual_floor)`` (``atol`` the
        property below). The
        integrators set it to ``ROUNDOFF * eps * max|K| * max(1, max|q|)``:
        a residual of elastic forces cannot be computed more accurately than
        that (measured: 4e-7 N on Exudyn's 25-element BE2D pendulum, where
        ``tol * max|r_0|`` of a 1e-4 s step can be 2.5e-7 N).

    Notes
    -----
    The solver keeps at most one factorisation. The caller must call
    :meth:`invalidate` whenever the meaning of the Jacobian changes in a way
    the contraction test cannot be trusted to detect (new step size, new
    iteration-matrix coefficients, different equations).
    """

    def __init__(self, options: NewtonOptions | None = None) -> None:
        if options is None:
            options = NewtonOptions()
        if not isinstance(options, NewtonOptions):
            raise TypeError(f"`options` must be a NewtonOptions, got {type(options).__name__}.")
        self.options = options
        self.stats = NewtonStats()
        self.scaled_atol = 0.0
        self.residual_floor = 0.0
        self._lu: _Factor | None = None

    @property
    def atol(self) -> float:
        """The absolute tolerance in force: ``options.atol``, or :attr:`scaled_atol` when that is ``None``."""
        a = self.options.atol
        return self.scaled_atol if a is None else a

    def invalidate(self) -> None:
        """Drop the cached factorisation; the next iteration refactorises."""
        self._lu = None

    @property
    def has_factorization(self) -> bool:
        """True while a factorisation is cached."""
        return self._lu is not None

    def _refresh(self, jacobian, x, J=None):
        if J is None:
            J = jacobian(x)
        self.stats.jacobian_evals += 1
        try:
            self._lu = _Factor(J)
        except RuntimeError as exc:  # SuperLU: "Factor is exactly singular"
            self._lu = None
            return f"factorisation failed: {exc}"
        self.stats.factorizations += 1
        return None

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
        residual_jacobian: Callable[[np.ndarray], tuple] | None = None,
    ) -> NewtonOutcome:
        """Iterate from ``x0`` until the residual test passes.

        Parameters
        ----------
        residual : callable
            ``residual(x) -> ndarray`` of the shape of ``x``.
        jacobian : callable
            ``jacobian(x) -> d residual / dx`` as a scipy sparse matrix or a
            dense 2-D array.
        x0 : array_like
            Initial guess (not modified).
        residual_jacobian : callable, optional
            ``residual_jacobian(x) -> (residual, jacobian)`` in one pass. With
            full Newton every residual is followed by a Jacobian at the same
            point, so a model that computes both from one kernel evaluation
            saves the second pass (B1 with BE2D: about a fifth of the solve).
            Ignored by modified Newton, which seldom needs the Jacobian.

        Returns
        -------
        NewtonOutcome
            Never raises on non-convergence; exceptions raised by the
            callbacks propagate.
        """
        fused = residual_jacobian if self.options.jacobian == "full" else None
        x0 = np.array(x0, dtype=float, copy=True).ravel()
        self.stats.solves += 1
        if fused is not None:
            r, J = self._eval_fused(fused, x0)
        else:
            r, J = self._eval(residual, x0), None
        if not math.isfinite(max_abs(r)):
            self.stats.failed_solves += 1
            return NewtonOutcome(x0, False, 0, float("nan"), "residual at the initial guess is not finite")
        outcome = self._attempt(residual, jacobian, x0, r, fused, J)
        if (not outcome[0].converged and outcome[1] and self.options.jacobian == "modified"
                and self.options.retry):
            # The failed attempt started from a matrix of an earlier solve:
            # retry once from the initial guess with a fresh one.
            self.stats.retries += 1
            self.invalidate()
            first = outcome[0]
            retry, _ = self._attempt(residual, jacobian, x0, r)
            outcome = (NewtonOutcome(retry.x, retry.converged, first.iterations + retry.iterations,
                                     retry.residual_norm,
                                     retry.message if retry.converged else
                                     f"{retry.message} (after a retry with a fresh Jacobian; "
                                     f"first attempt: {first.message})"), False)
        if not outcome[0].converged:
            self.stats.failed_solves += 1
        return outcome[0]

    def _attempt(self, residual, jacobian, x0, r, fused=None, J=None):
        """One Newton attempt; returns (outcome, started_with_stale_matrix).

        With ``fused`` (full Newton and a ``residual_jacobian``), ``J`` is the
        Jacobian evaluated with ``r``, and every new residual brings its own.
        """
        opts = self.options
        full = opts.jacobian == "full"
        stale = self._lu is not None and not full
        x = x0.copy()
        err0 = err = max_abs(r)
        rel = max(opts.tol * err0, self.atol)
        threshold = max(rel, self.residual_floor)
        if err <= threshold:
            return NewtonOutcome(x, True, 0, err, "converged at the initial guess"), stale
        fresh = False  # the cached matrix was evaluated during this attempt
        diverging = 0
        for k in range(1, opts.max_iter + 1):
            if full or self._lu is None:
                msg = self._refresh(jacobian, x, J)
                if msg is not None:
                    return NewtonOutcome(x, False, k - 1, err, msg), stale
                fresh = True
                threshold = max(rel, self.residual_floor)  # the caller may update it with the Jacobian
            dx = self._lu.solve(r)   # the correction is -dx (negation commutes exactly with the solve)
            self.stats.iterations += 1
            dx_max = max_abs(dx)  # NaN/inf propagate into the max
            if not math.isfinite(dx_max):   # math: 20x cheaper than np on a float
                return NewtonOutcome(x, False, k, err, "Newton correction is not finite "
                                     "(singular iteration matrix?)"), stale
            x = x - dx
            if fused is not None:
                r, J = self._eval_fused(fused, x)
            else:
                r = self._eval(residual, x)
            err_new = max_abs(r)
            if not math.isfinite(err_new):
                return NewtonOutcome(x, False, k, float("nan"),
                                     f"residual became non-finite at iteration {k}"), stale
            if err_new <= threshold:
                return NewtonOutcome(x, True, k, err_new, f"converged in {k} iterations"), stale
            # Round-off stagnation: a fresh matrix, a correction at round-off
            # level and a residual that no longer falls -- the attainable accuracy.
            if (fresh and err_new > 0.5 * err
                    and dx_max <= opts.xtol * max(1.0, max_abs(x))):
                return NewtonOutcome(x, True, k, err_new, f"converged in {k} iterations "
                                     f"(correction at round-off level, max|r| = {err_new:.3e})"), stale
            rate = err_new / err if err > 0 else np.inf
            err = err_new
            if rate > opts.contraction:
                if fresh and rate >= DIVERGENCE_RATE:
                    diverging += 1
                    if diverging >= 2:
                        return NewtonOutcome(x, False, k, err, f"diverging (rate {rate:.3g} at "
                                             f"iteration {k} with a fresh Jacobian)"), stale
                else:
                    diverging = 0
                if not full:
                    self._lu = None  # refresh at the current iterate
            else:
                diverging = 0
        return NewtonOutcome(x, False, opts.max_iter, err,
                             f"not converged in {opts.max_iter} iterations "
                             f"(max|r| = {err:.3e}, target {threshold:.3e})"), stale
