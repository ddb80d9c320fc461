"""A load step of the static full Newton as one compiled call, for a beam whose element offers it (needs numba).

:func:`ancfdae.solve_static` with full Newton solves ``r(q) = f(q) - lambda f_ext = 0`` per load step.
Run from Python, an iteration of a 16-element BE2D cantilever (B1) costs some 100 us -- the fused kernel,
the copy into band storage, LAPACK's factorisation, three CSR wrappers -- where the arithmetic is a few
microseconds. An element that offers a static entry point (``Kernel.static_newton``; BE2D:
:func:`ancfdae.models.thin.be2d_numba.be2d_static_newton`, a one-line call of :func:`static_newton` with its
fused kernel, for the on-disk cache as in :mod:`.iteration_numba`; numba keys that cache on the element's
file, so after editing this module delete the element's ``*.nbi``/``*.nbc`` files) runs the whole solve of a
load step in one call::

    static_newton(x, r, f_ext, fpar, ipar, flat, ab, piv, kdata, rbuf, arrays, element_args)
        -> (status, iterations, residual_evals, err, rate, threshold)

* ``x`` (n): the initial guess, the last iterate on return; ``r`` (n): its residual on return.
* ``f_ext`` (n): the external force at the solve's time (gravity and dead loads, no moments).
* ``fpar``: ``[tol, residual_atol, xtol, contraction, divergence_rate, lam]``; ``ipar``: ``[max_iter, kl, ku]``.
* ``flat`` (nnz): the band positions of the tangent's CSR entries (``_linsolve._band_map``), ``ab``
  (n, 2 kl + ku + 1) and ``piv`` (n) the factorisation's storage, ``kdata`` (nnz + 1), ``rbuf`` (n + 1)
  the fused kernel's outputs.
* ``arrays``: ``(q_fixed, gather, vec_slot, mat_slot)``, the fused kernel's arrays after ``q``.

Each iteration is :meth:`ancfdae.integrators._newton.NewtonSolver._attempt`'s with full Newton, a fused
``residual_jacobian`` and no ``accept`` (floor 0): factorise the tangent at ``x`` (:func:`band_factor`,
LAPACK's elimination), ``dx = K^-1 r``, ``x <- x - dx``, the fused residual and tangent at the new ``x``,
then the solver's tests in its order -- converged, round-off stagnation (the matrix is always fresh),
the rate against ``contraction`` and twice in a row at least ``divergence_rate`` -- and the same
status for every way it ends (``CONVERGED_INITIAL`` ... ``MAX_ITER``), which the caller turns into the
solver's outcome and counters (:mod:`ancfdae._static_compiled`). The residual is ``(f + 0) - lam f_ext``,
the rounding of ``f + M 0 - lam f_ext`` (:func:`ancfdae._residual_numba.finish_residual` with ``a = 0``).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ...integrators._linsolve_numba import band_factor, band_fill, band_solve
from ..._scale import max_abs

__all__ = ["static_newton", "CONVERGED_INITIAL", "CONVERGED", "STAGNANT", "INITIAL_NOT_FINITE",
           "DX_NOT_FINITE", "R_NOT_FINITE", "DIVERGING", "MAX_ITER"]

CONVERGED_INITIAL, CONVERGED, STAGNANT, INITIAL_NOT_FINITE, DX_NOT_FINITE, R_NOT_FINITE, DIVERGING, MAX_ITER = range(8)


@njit(cache=True)
def _residual(r, rbuf, lam, f_ext):
    """``r <- (f + 0) - lam f_ext`` from the fused kernel's forces ``rbuf``; returns ``max|r|``."""
    for i in range(r.size):
        r[i] = (rbuf[i] + 0.0) - lam * f_ext[i]
    return max_abs(r)


@njit(cache=True, inline="always")   # inlined: the kernel stays a constant, not a value (on-disk cache)
def static_newton(kernel, x, r, f_ext, fpar, ipar, flat, ab, piv, kdata, rbuf, arrays, element_args):
    """One load step's full Newton solve (module docstring); ``kernel`` is the element's fused entry point."""
    tol, atol, xtol, contraction, divergence, lam = fpar[0], fpar[1], fpar[2], fpar[3], fpar[4], fpar[5]
    max_iter, kl, ku = ipar[0], ipar[1], ipar[2]
    q_fixed, gather, vec_slot, mat_slot = arrays
    nnz = kdata.size - 1
    kernel(x, q_fixed, gather, vec_slot, mat_slot, True, rbuf, kdata, *element_args)
    err = _residual(r, rbuf, lam, f_ext)
    evals = 1
    if not np.isfinite(err):
        return INITIAL_NOT_FINITE, 0, evals, np.nan, np.nan, np.nan
    threshold = max(tol * err, atol)
    if err <= threshold:
        return CONVERGED_INITIAL, 0, evals, err, np.nan, threshold
    lub = ab.T
    dx = np.empty(x.size)
    diverging = 0
    k = 0
    while k < max_iter:
        k += 1
        band_fill(kdata[:nnz], flat, ab.reshape(-1))
        band_factor(ab, kl, ku, piv)
        dx[:] = r
        band_solve(lub, kl, ku, piv, dx)
        dx_max = max_abs(dx)
        if not np.isfinite(dx_max):
            return DX_NOT_FINITE, k, evals, err, np.nan, threshold
        for i in range(x.size):
            x[i] = x[i] - dx[i]
        kernel(x, q_fixed, gather, vec_slot, mat_slot, True, rbuf, kdata, *element_args)
        err_new = _residual(r, rbuf, lam, f_ext)
        evals += 1
        if not np.isfinite(err_new):
            return R_NOT_FINITE, k, evals, np.nan, np.nan, threshold
        if err_new <= threshold:
            return CONVERGED, k, evals, err_new, np.nan, threshold
        if err_new > 0.5 * err and dx_max <= xtol * max(1.0, max_abs(x)):
            return STAGNANT, k, evals, err_new, np.nan, threshold
        rate = err_new / err if err > 0 else np.inf
        err = err_new
        if rate > contraction and rate >= divergence:
            diverging += 1
            if diverging >= 2:
                return DIVERGING, k, evals, err, rate, threshold
        else:
            diverging = 0
    return MAX_ITER, max_iter, evals, err, np.nan, threshold
