"""Compiled banded LU with partial pivoting (the algorithm of LAPACK's dgbtf2/dgbtrs).

Beam matrices with nodes numbered along the axis are banded with a half
bandwidth of two nodes' coordinates, whatever the mesh (BE2D: 7, SQ3D: 26,
twice that for two coupled Runge-Kutta stages). At these widths LAPACK's own
work is a few microseconds and the cost of calling it from Python (argument
checks, copies, the f2py wrappers) is of the same size; these loops run the
same elimination from one compiled call, reading the matrix straight from the
CSR data through a precomputed map into band storage.

Storage: ``ab`` of shape ``(n, 2 kl + ku + 1)`` in C order, i.e. LAPACK's
Fortran ``AB(ldab, n)`` with ``A[i, j]`` at ``ab[j, kl + ku + i - j]``; the
first ``kl`` rows of AB (the fill-in of U) start as zero. The pivots ``piv``
are 0-based row indices. The transpose ``ab.T`` is LAPACK's factor itself, so the solve is the
package's :func:`ancfdae.integrators._linsolve_numba.band_solve` applied to ``ab.T``.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["band_fill", "band_factor"]


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
    """
    n = ab.shape[0]
    kv = kl + ku
    info = 0
    col = np.empty(kl + 1)
    ju = 0   # last column touched by the row interchanges so far
    for j in range(n):
        km = min(kl, n - 1 - j)
        # pivot: largest |A[j + i, j]|, i = 0..km (first one on ties, as idamax)
        jp = 0
        big = abs(ab[j, kv])
        for i in range(1, km + 1):
            v = abs(ab[j, kv + i])
            if v > big:
                big, jp = v, i
        piv[j] = j + jp
        if ab[j, kv + jp] == 0.0:
            if info == 0:
                info = j + 1
            continue
        ju = max(ju, min(j + ku + jp, n - 1))
        if jp != 0:   # swap rows j and j + jp in columns j..ju
            for c in range(j, ju + 1):
                a = kv + j - c
                tmp = ab[c, a + jp]
                ab[c, a + jp] = ab[c, a]
                ab[c, a] = tmp
        if km > 0:
            rp = 1.0 / ab[j, kv]
            for i in range(1, km + 1):
                ab[j, kv + i] *= rp
                col[i] = ab[j, kv + i]   # the multipliers, apart: the update loop then vectorises
            for c in range(j + 1, ju + 1):
                a = kv + j - c
                u = ab[c, a]
                if u != 0.0:
                    row = ab[c]
                    for i in range(1, km + 1):
                        row[a + i] -= col[i] * u
    return info

