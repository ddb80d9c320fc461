"""The shared parts of compiled Newmark-family Newton iterations (needs numba).

An element's compiled kernel may offer an *iterations* entry point besides its fused one
(:func:`ancfdae.models.beam.compiled.compiled_residual`)::

    iterations(x, r, err, max_k, contraction, threshold, lub, kl, ku, piv, qa0, va0, aa0, cqa, cva, caa,
               lam, f_ext, q_fixed, gather, vec_slot, mat_slot, m_data, indptr, indices, rbuf, kdata,
               *element_args) -> (max|dx|, err_new, err_prev, k)

Each iteration is ``dx = J^-1 r`` from LAPACK's banded factors ``(lub, kl, ku, piv)``, ``x <- x - dx``
and the residual ``f(q) + M a - lam f_ext`` at the weighted state ``(qa0 + cqa x, va0 + cva x,
aa0 + caa x)`` of the Newmark family (:mod:`ancfdae.integrators.newmark`): :func:`alpha_update`,
the element's fused call, :func:`alpha_finish`; ``x`` and ``r`` are updated in place (no array is
returned: boxing one costs a few microseconds). The loop goes on while an iteration is one in which
:class:`ancfdae.integrators._newton.NewtonSolver` would simply carry on -- finite, not converged
(``err_new > threshold``), contracting (``err_new / err <= contraction`` and ``err_new <= err / 2``,
so no round-off stagnation test can fire) -- for at most ``max_k`` iterations; it returns the error
after the last iteration and before it and the number of iterations ``k`` (after a non-finite
correction, ``x`` and ``r`` are those before it), and the solver takes that iteration's decision in
Python. With ``max_k = 0`` it writes the residual at ``x`` into ``r`` (``lub``, ``piv`` unused; ``k = 0``).
The element calls its fused kernel by name, a compile-time constant, so numba caches the loop on disk
(a numba function passed as an argument, or a closure over one, costs some 50 us of dispatch per call
or a fresh compilation in every process); see
:func:`ancfdae.models.thin.be2d_numba.be2d_alpha_iterations`.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ...integrators._affine import affine3
from ...integrators._linsolve_numba import band_solve
from ..._scale import max_abs
from ..._residual_numba import finish_residual

__all__ = ["alpha_update", "alpha_finish", "carry_on"]


@njit(cache=True)
def alpha_update(x, r, lub, kl, ku, piv, qa0, va0, aa0, cqa, cva, caa):
    """``(q, v, a, max|dx|)``: the correction ``dx = J^-1 r``, ``x <- x - dx`` in place (only when ``dx`` is
    finite) and the weighted state of the new ``x``."""
    dx = r.copy()
    band_solve(lub, kl, ku, piv, dx)
    dx_max = max_abs(dx)
    if dx_max == dx_max and dx_max != np.inf:
        for i in range(x.size):
            x[i] = x[i] - dx[i]
    q, v, a = affine3(qa0, va0, aa0, cqa, cva, caa, x)
    return q, v, a, dx_max


@njit(cache=True)
def alpha_finish(r, rbuf, m_data, indptr, indices, a, lam, f_ext):
    """``max|r|`` after ``r <- rbuf + M a - lam f_ext`` in place (``rbuf``: the fused kernel's forces)."""
    finish_residual(rbuf, m_data, indptr, indices, a, lam, f_ext)
    for i in range(r.size):
        r[i] = rbuf[i]
    return max_abs(r)


@njit(cache=True)
def carry_on(err_new, err, threshold, contraction):
    """True when the solver would carry on after this iteration without a decision (module docstring)."""
    if not (err_new > threshold) or err_new != err_new:
        return False
    return err_new / err <= contraction and not (err_new > 0.5 * err)
