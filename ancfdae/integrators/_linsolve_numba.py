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

__all__ = ["band_solve", "pair_solve", "band_fill", "band_factor", "band_solve_ab"]


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


# The factorisation as one compiled loop, for a Newton iteration that runs entirely compiled (the static
# full Newton of :mod:`ancfdae.models.beam.static_numba`): from Python, LAPACK's ``dgbtrf`` stays the choice
# (module :mod:`._linsolve`). Storage: ``ab`` of shape ``(n, 2 kl + ku + 1)`` in C order, i.e. LAPACK's
# Fortran ``AB(ldab, n)`` with ``A[i, j]`` at ``ab[j, kl + ku + i - j]``, so ``ab.T`` is the factor that
# :func:`band_solve` reads; the elimination is ``dgbtf2``'s (LAPACK's own choice below its block size 32),
# which gives LAPACK's bits on beam matrices (``tests/integrators/test_linsolve.py``).
@njit(cache=True)
def band_fill(data, flat, ab):
    """Zero ``ab`` and place the CSR ``data`` at the precomputed flat band positions ``flat``.

    Positions may repeat (a non-canonical CSR pattern); repeated entries add.
    """
    ab[:] = 0.0
    for k in range(data.size):
        ab[flat[k]] += data[k]


@njit(cache=True)
def band_factor(ab, kl, ku, piv):
    """In-place LU with partial pivoting of a band matrix in ``ab`` (layout: module docstring).

    Returns the LAPACK ``info``: 0, or ``j + 1`` for the first exactly zero
    pivot ``U[j, j]`` (the factorisation is completed; a solve then divides by zero).
    ``dgbtf2``'s pivots and bits, without the updates by exact zeros (a zero entry of the pivot row, the
    multipliers after the last nonzero one): KKT matrices in band order are mostly zeros inside the band (B6's
    262 nonzeros in 982 band entries, 326 in its factors). With ``piv`` of size ``3 n``, ``piv[n + j]`` receives
    the number of multipliers of column ``j`` up to its last nonzero one and ``piv[2 n + j]`` the distance from
    ``U``'s diagonal to the first nonzero of column ``j`` (0: none above it): the trims :func:`band_solve_ab` reads.
    """
    n, width = ab.shape
    kv = kl + ku
    f = ab.reshape(-1)   # flat indices: numba then addresses without 2-d strides (B6: 5.2 -> 3.6 us)
    trims = piv.size >= 3 * n
    if trims:
        piv[n:3 * n] = 0
    info = 0
    col = np.empty(kl + 1)
    ju = 0   # last column touched by the row interchanges so far
    for j in range(n):
        km = min(kl, n - 1 - j)
        d = j * width + kv   # A[j, j]; A[j + i, j] at d + i; A[j, c] at c * (width - 1) + kv + j
        # pivot: largest |A[j + i, j]|, i = 0..km (first one on ties, as idamax)
        jp = 0
        big = abs(f[d])
        for i in range(1, km + 1):
            v = abs(f[d + i])
            if v > big:
                big, jp = v, i
        piv[j] = j + jp
        last, hi = 0, max(ju, min(j + ku, n - 1))   # a zero pivot: no elimination (dgbtf2), U's trims of row j
        if f[d + jp] == 0.0:
            if info == 0:
                info = j + 1
        else:
            ju = max(ju, min(j + ku + jp, n - 1))
            hi = ju
            if jp != 0:   # swap rows j and j + jp in columns j..ju
                for c in range(j, ju + 1):
                    a = c * (width - 1) + kv + j
                    tmp = f[a + jp]
                    f[a + jp] = f[a]
                    f[a] = tmp
            if km > 0:
                rp = 1.0 / f[d]
                for i in range(1, km + 1):
                    x = f[d + i] * rp
                    f[d + i] = x
                    col[i] = x   # the multipliers, apart: the update loop then vectorises
                    if x != 0.0:
                        last = i
        for c in range(j + 1, hi + 1):
            a = c * (width - 1) + kv + j
            u = f[a]
            if u != 0.0:
                if trims and piv[2 * n + c] == 0:
                    piv[2 * n + c] = c - j
                for i in range(1, last + 1):
                    f[a + i] -= col[i] * u
        if trims:
            piv[n + j] = last
    return info


@njit(cache=True, error_model="numpy")   # a zero pivot gives inf/nan, as LAPACK does
def band_solve_ab(ab, kl, ku, piv, b):
    """Solve ``A x = b`` in place in ``b`` with the factors of :func:`band_factor` in its own layout, ``piv`` of
    size ``3 n`` (with the trims).

    The arithmetic of ``band_solve(ab.T, kl, ku, piv, b)`` without the products with the exact zeros outside the
    trims (the same bits for finite values): on B6's factors 573 of 1488 products.
    """
    n, width = ab.shape
    kv = kl + ku
    f = ab.reshape(-1)
    for j in range(n - 1):
        p = piv[j]
        if p != j:
            tmp = b[p]
            b[p] = b[j]
            b[j] = tmp
        bj = b[j]
        d = j * width + kv
        for i in range(1, piv[n + j] + 1):
            b[j + i] -= f[d + i] * bj
    for j in range(n - 1, -1, -1):
        d = j * width + kv - j   # A[i, j] at d + i
        b[j] /= f[d + j]
        bj = b[j]
        for i in range(j - piv[2 * n + j], j):
            b[i] -= f[d + i] * bj
