"""Compiled building blocks of the thin spatial elements Cable3D and BE3D.

Per quadrature point an element kernel works with a few *local* variables
(the slope ``a = r'``, its derivative ``b = r''``, for BE3D also ``theta``
and ``theta'``); each local variable is a combination of at most four
element coordinates, ``x_v = sum_r coef[v, r] q[idx[v, r]]``. :func:`scatter`
maps a local gradient and Hessian to the element force and stiffness with
that sparse map (the dense Hermite operators of the NumPy reference would
multiply mostly zeros). :func:`axial_point` is the axial strain energy of
chapter Eqs. 78/94 with Eq. 82, shared by both elements.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["scatter", "hermite_map", "axial_point", "slope"]


@njit(cache=True, inline="always")
def hermite_map(idx, coef, dof, dN, ddN):
    """Fill rows 0-5 of the local map: ``a_i`` from ``dN``, ``b_i`` from ``ddN`` (Hermite vector k at ``dof[k]``)."""
    for i in range(3):
        for k in range(4):
            idx[i, k] = dof[k, i]
            coef[i, k] = dN[k]
            idx[3 + i, k] = dof[k, i]
            coef[3 + i, k] = ddN[k]


@njit(cache=True, inline="always")
def slope(q, dof, dN, out):
    """``out = sum_k dN_k q[dof[k]]`` (r' or r'' at a point)."""
    for i in range(3):
        s = 0.0
        for k in range(4):
            s += dN[k] * q[dof[k, i]]
        out[i] = s


@njit(cache=True, inline="always")
def scatter(f, K, idx, coef, n_loc, grad, H, tangent):
    """``f += B^T grad`` and, if ``tangent``, ``K += B^T H B`` for the local map ``B`` of ``(idx, coef)``."""
    for v in range(n_loc):
        gv = grad[v]
        for r in range(4):
            f[idx[v, r]] += coef[v, r] * gv
    if not tangent:
        return
    for v in range(n_loc):
        for u in range(n_loc):
            h = H[v, u]
            if h == 0.0:
                continue
            for r in range(4):
                cr = coef[v, r] * h
                if cr == 0.0:
                    continue
                row = idx[v, r]
                for s in range(4):
                    K[row, idx[u, s]] += cr * coef[u, s]


@njit(cache=True, inline="always")
def axial_point(f, K, q, dof, dN, wdx, slope_ref, EA, a, idx, coef, grad, H, tangent):
    """Axial energy ``EA/2 (|a| - |a_ref|)^2 w`` at a point; adds its force and tangent, returns the energy.

    ``grad, H`` (>= 3, >= 3x3) and ``idx, coef`` (>= 3 x 4) are scratch arrays.
    The Hessian in ``a`` is ``EA w [(j/|a|) e e^T + (1 - j/|a|) I]``, ``e = a/|a|``, ``j = |a_ref|``.
    """
    slope(q, dof, dN, a)
    na = np.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    stretch = na - slope_ref
    c = EA * wdx
    for i in range(3):
        grad[i] = c * stretch * a[i] / na
        for k in range(4):
            idx[i, k] = dof[k, i]
            coef[i, k] = dN[k]
    if tangent:
        ratio = slope_ref / na
        for i in range(3):
            for j in range(3):
                H[i, j] = c * ratio * a[i] * a[j] / (na * na)
            H[i, i] += c * (1.0 - ratio)
    scatter(f, K, idx, coef, 3, grad, H, tangent)
    return 0.5 * c * stretch * stretch
