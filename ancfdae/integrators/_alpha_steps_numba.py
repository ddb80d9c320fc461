"""Whole steps of the Newmark family as one compiled call, for a model that offers compiled iterations.

:mod:`ancfdae.models.beam.iteration_numba` runs the Newton iterations of one step in one call; the step around them --
the grid time, the predictor, the solver's decisions, the update of ``q, v, a``, the counters -- is
Python work of some 100 us per step on a 25-element beam, as much as the whole step of Exudyn. An
element that offers iterations also offers *steps* (``Kernel.alpha_steps``; BE2D:
:func:`ancfdae.models.thin.be2d_numba.be2d_alpha_steps`), a one-line call of :func:`alpha_steps`
with its own iterations entry point (contract in :mod:`ancfdae.models.beam.iteration_numba`), which takes as many steps as it can in one call::

    steps(S, P, fpar, ipar, out, lub, piv, gravity, dead, scales, arrays, element_args)

* ``S`` (3, n): ``q, v, a`` at ``fpar[T]`` on entry, the state reached on return; ``P`` (3, n): the
  state before the last step taken (written only when a step is taken).
* ``fpar`` (float64, indices below): the grid ``t0, h, t_bound``, the stop time ``t_stop``, the step
  size the cached matrix was built for ``h_matrix``, the scheme ``beta, gamma, alpha_m, alpha_f``, the
  load factor ``lam``, the solver's ``tol``, ``atol``, ``floor``, ``contraction`` and the driver's
  ``grid_tol``; on return ``fpar[T]`` is the time reached and ``fpar[T_PREV]`` the time before the last
  step.
* ``ipar`` (int64): ``n_steps`` (steps accepted before the call), ``max_count``, the solver's
  ``max_iter``, the band factors' ``kl, ku``.
* ``out`` (int64, written): ``[steps taken, status, Newton iterations, residual evaluations]``;
  status ``STOPPED`` (the last step reached ``t_stop`` as the driver tests an output time, or the end
  of the run, or ``max_count`` steps were taken) or ``NEEDS_PYTHON`` (the next step needs a decision
  taken in Python: ``S`` is the state before it, and the Python step redoes it from there).
* ``gravity`` (n,), ``dead`` (m, n), ``scales`` (k, m): the external force of the ``i``-th step of the
  call is ``scales[i, 0] dead[0] + ... + gravity`` (the loads' order of
  :meth:`ancfdae.models.beam.loads.LoadSet.external`, so the same bits), ``scales`` evaluated by the
  caller at the steps' weighted times; at most ``k`` steps are taken when ``m > 0``.
* ``arrays``, ``element_args``: the iterations entry point's model arrays and element arguments.

The loop is the integrator's (this module); the element's file holds only the call, because numba
caches a function on disk only when the entry point it calls is a compile-time constant (see
:mod:`ancfdae.models.beam.iteration_numba`): :func:`alpha_steps` is inlined into that call (numba's
``inline="always"``), where the entry point is a global name; passed as a value to a separate
function it becomes a pointer to the dispatcher object, which numba refuses to cache. numba keys that cache
on the element's file alone: after editing this module, delete the element's ``*.nbi``/``*.nbc`` files (e.g.
``ancfdae/models/thin/__pycache__/be2d_numba.be2d_alpha_steps-*``), or the old loop runs on. Each step is exactly the Python path's -- :meth:`ancfdae.integrators.FixedStepIntegrator.next_time`,
:meth:`ancfdae.integrators.newmark._AlphaFamily._step_impl`,
:meth:`ancfdae.integrators._newton.NewtonSolver.solve` with a cached (stale) matrix -- as long as no
decision needs Python: a step-size change (the matrix is rebuilt), a residual or correction that is
not finite, an iteration that does not contract (the matrix is refreshed), ``max_iter`` iterations
(the retry). Then the loop returns ``NEEDS_PYTHON`` before that step and counts none of its work: the
Python step takes the same iterations to the same decision and counts them, so every counter equals
the Python path's. A compiled step never has a fresh matrix, so the solver's round-off stagnation
test (fresh matrices only) cannot fire in it.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ._affine import affine2, newmark_predict

__all__ = ["alpha_steps", "T0", "H", "T", "T_BOUND", "T_STOP", "H_MATRIX", "BETA", "GAMMA", "ALPHA_M",
           "ALPHA_F", "LAM", "TOL", "ATOL", "FLOOR", "CONTRACTION", "GRID_TOL", "T_PREV", "N_FPAR",
           "N_STEPS", "MAX_COUNT", "MAX_ITER", "KL", "KU", "N_IPAR", "STOPPED", "NEEDS_PYTHON"]

# fpar
T0, H, T, T_BOUND, T_STOP, H_MATRIX, BETA, GAMMA, ALPHA_M, ALPHA_F, LAM, TOL, ATOL, FLOOR, CONTRACTION, \
    GRID_TOL, T_PREV = range(17)
N_FPAR = 17
# ipar
N_STEPS, MAX_COUNT, MAX_ITER, KL, KU = range(5)
N_IPAR = 5
# out[1]
STOPPED, NEEDS_PYTHON = 0, 1


@njit(cache=True)
def _external(f, gravity, dead, scales, i):
    """``f <- scales[i, 0] dead[0] + ... + gravity`` in the order of ``LoadSet.external`` (same rounding)."""
    m = dead.shape[0]
    if m == 0:
        f[:] = gravity
        return
    for j in range(f.size):
        s = scales[i, 0] * dead[0, j]
        for k in range(1, m):
            s += scales[i, k] * dead[k, j]
        f[j] = s + gravity[j]


@njit(cache=True)
def _finite(x):
    for v in x:
        if not np.isfinite(v):
            return False
    return True


@njit(cache=True, inline="always")   # inlined: the entry point stays a constant, not a value (on-disk cache)
def alpha_steps(iterations, S, P, fpar, ipar, out, lub, piv, gravity, dead, scales, arrays, element_args):
    """Newmark-family steps until ``t_stop``, the end, ``max_count`` steps or a decision for Python
    (module docstring); ``iterations`` is the element's entry point of
    :mod:`ancfdae.models.beam.iteration_numba`."""
    n = S.shape[1]
    t0, h, t_bound, t_stop, h_matrix = fpar[T0], fpar[H], fpar[T_BOUND], fpar[T_STOP], fpar[H_MATRIX]
    beta, gamma, am, af, lam = fpar[BETA], fpar[GAMMA], fpar[ALPHA_M], fpar[ALPHA_F], fpar[LAM]
    tol, atol, floor, contraction, grid_tol = fpar[TOL], fpar[ATOL], fpar[FLOOR], fpar[CONTRACTION], fpar[GRID_TOL]
    n_steps, max_count, max_iter, kl, ku = ipar[N_STEPS], ipar[MAX_COUNT], ipar[MAX_ITER], ipar[KL], ipar[KU]
    if dead.shape[0] > 0 and scales.shape[0] < max_count:
        max_count = scales.shape[0]
    x, r, f_ext = np.empty(n), np.empty(n), np.empty(n)
    rbuf, kdata = np.empty(n + 1), np.empty(1)
    t = fpar[T]
    done, iters, evals, status = 0, 0, 0, NEEDS_PYTHON
    while done < max_count:
        # FixedStepIntegrator.next_time and NewtonStepper.step's test of the matrix's step size
        t_new = t0 + (n_steps + done + 1) * h
        if t_new >= t_bound - grid_tol * h:
            t_new = t_bound
        hs = t_new - t
        if abs(hs - h_matrix) > 1e-8 * h:
            break
        # _AlphaFamily._step_impl
        _external(f_ext, gravity, dead, scales, done)
        q_pred, v_pred, qa0, va0, aa0 = newmark_predict(S[0], S[1], S[2], hs, beta, gamma, am, af)
        cq, cv = hs * hs * beta, hs * gamma
        cqa, cva, caa = (1 - af) * cq, (1 - af) * cv, 1.0 - am
        # NewtonSolver.solve with a stale matrix
        x[:] = S[2]
        err = iterations(x, r, 0.0, 0, 0.0, 0.0, lub, kl, ku, piv, qa0, va0, aa0, cqa, cva, caa, lam, f_ext,
                         *arrays, rbuf, kdata, *element_args)[1]
        if not np.isfinite(err):
            break
        threshold = max(max(tol * err, atol), floor)
        converged = err <= threshold
        k, its = 0, 0
        while not converged and k < max_iter:
            k += 1
            dx_max, err_new, err_prev, m = iterations(x, r, err, max_iter - k + 1, contraction, threshold, lub, kl,
                                                      ku, piv, qa0, va0, aa0, cqa, cva, caa, lam, f_ext, *arrays,
                                                      rbuf, kdata, *element_args)
            its += m
            k += m - 1
            if not (np.isfinite(dx_max) and np.isfinite(err_new)):
                break
            if err_new <= threshold:
                converged = True
                break
            rate = err_new / err_prev if err_prev > 0 else np.inf
            if rate > contraction:
                break
            err = err_new
        if not converged:
            break
        q, v = affine2(q_pred, v_pred, cq, cv, x)
        if not (_finite(q) and _finite(v)):
            break
        P[:, :] = S
        S[0], S[1], S[2] = q, v, x
        iters += its
        evals += 1 + its
        done += 1
        t_prev, t = t, t_new
        fpar[T_PREV], fpar[T] = t_prev, t
        # the driver's test of an output time at the step's end (GRID_TOL of the step), or the end
        if t >= t_bound or t_stop <= t + grid_tol * (t - t_prev):
            status = STOPPED
            break
    if done == max_count:
        status = STOPPED
    out[0], out[1], out[2], out[3] = done, status, iters, evals
