"""Compiled triangular solves on LAPACK's banded LU factors (``dgbtrf``/``zgbtrf`` output).

LAPACK factorises faster than a compiled loop at every band width we have, but
for the narrow bands of beam models (half bandwidth up to about 8) the
forward and back substitution cost less in one compiled loop than through
scipy's ``dgbtrs`` wrapper (measured 1.9 against 2.7 us at n = 68 and 6.1
against 8.5 us at n = 257, half bandwidth 7; ``benchmarks/banded_lu.py``).
Modified Newton solves many times per factorisation, so the solve is what
counts. ``lub`` is LAPACK's Fortran-ordered ``(2 kl + ku + 1, n)`` factor and
``piv`` its pivots (0-based, as scipy's wrapper returns them); the algorithm is ``dgbtrs`` without transpose.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["band_solve", "pair_solve"]


@njit(cache=True, error_model="numpy")   # a zero pivot gives inf/nan, as LAPACK does
def band_solve(lub, kl, ku, piv, b):
    """Solve ``A x = b`` in place in ``b`` with LAPACK's banded LU factors of ``A``."""
    n = lub.shape[1]
    kv = kl + ku
    if kl > 0:
        for j in range(n - 1):
            lm = min(kl, n - 1 - j)
            p = piv[j]
            if p != j:
                tmp = b[p]
                b[p] = b[j]
                b[j] = tmp
            bj = b[j]
            for i in range(1, lm + 1):
                b[j + i] -= lub[kv + i, j] * bj
    for j in range(n - 1, -1, -1):
        b[j] /= lub[kv, j]
        bj = b[j]
        for i in range(max(0, j - kv), j):
            b[i] -= lub[kv + i - j, j] * bj


@njit(cache=True, error_model="numpy")   # a zero pivot gives inf/nan, as LAPACK does
def pair_solve(lub, kl, ku, piv, R, s0, s1, w0, w1, out):
    """The two-stage eigenbasis solve of a complex-conjugate pair (``StageMatrix``), in one call.

    ``c = R[:, 0] s0 + R[:, 1] s1`` (the first column of ``R S``), ``y = A^-1 c``
    with the complex factors, then ``out[:, k] = 2 Re(y w_k)`` (``w`` the first
    row of ``S^-1``; the conjugate solution supplies the other half).
    """
    n = R.shape[0]
    y = np.empty(n, dtype=np.complex128)
    for i in range(n):
        y[i] = R[i, 0] * s0 + R[i, 1] * s1
    band_solve(lub, kl, ku, piv, y)
    for i in range(n):
        out[i, 0] = 2.0 * (y[i] * w0).real
        out[i, 1] = 2.0 * (y[i] * w1).real
