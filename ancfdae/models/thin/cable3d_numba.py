"""Compiled Cable3D kernel: strain energy, internal forces and exact tangent in one call.

The same energy as the NumPy reference :class:`.cable3d.Cable3DReference`
(chapter Eqs. 94-95): ``EA/2 (|r'| - |r'_ref|)^2`` at the axial points and
``EI/2 K^2`` with ``K^2 = g / p^2``, ``g = |a x b|^2 = p |b|^2 - (a.b)^2``,
``p = |a|^2`` (``a = r'``, ``b = r''``) at the bending points. One loop over
elements calls :func:`cable3d_element`, which writes the element's row of the
outputs; the tests hold it equal to the reference on random states.
:class:`Cable3DCompiled` is the kernel object. Cable3D offers no fused assembly
entry point: the beam scatters its element arrays with ``np.bincount``.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..element import OnePassKernel
from .spatial_numba import axial_point, hermite_map, scatter, slope

__all__ = ["Cable3DCompiled", "cable3d_forces", "cable3d_element", "cable3d_scratch"]


@njit(cache=True, inline="always")
def _bending_point(f, K, q, dof, dN, ddN, wdx, EI, a, b, ga, gb, idx, coef, grad, H, tangent):
    """``EI/2 K^2 w`` at a point: adds force and tangent, returns the energy."""
    slope(q, dof, dN, a)
    slope(q, dof, ddN, b)
    p = a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
    ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    bb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2]
    g = p * bb - ab * ab
    c = 0.5 * EI * wdx
    p2, p3 = p * p, p * p * p
    for i in range(3):
        ga[i] = 2.0 * (a[i] * bb - ab * b[i])
        gb[i] = 2.0 * (b[i] * p - ab * a[i])
        grad[i] = c * (ga[i] / p2 - 4.0 * g * a[i] / p3)
        grad[3 + i] = c * gb[i] / p2
    if tangent:
        p4 = p2 * p2
        for i in range(3):
            for j in range(3):
                dij = 1.0 if i == j else 0.0
                gaa = 2.0 * (bb * dij - b[i] * b[j])
                gab = 4.0 * a[i] * b[j] - 2.0 * b[i] * a[j] - 2.0 * ab * dij
                gbb = 2.0 * (p * dij - a[i] * a[j])
                H[i, j] = c * (gaa / p2 - 4.0 * (ga[i] * a[j] + a[i] * ga[j]) / p3
                               + 24.0 * g * a[i] * a[j] / p4 - 4.0 * g * dij / p3)
                fab = c * (gab / p2 - 4.0 * a[i] * gb[j] / p3)
                H[i, 3 + j] = fab
                H[3 + j, i] = fab
                H[3 + i, 3 + j] = c * gbb / p2
    hermite_map(idx, coef, dof, dN, ddN)
    scatter(f, K, idx, coef, 6, grad, H, tangent)
    return c * g / p2


@njit(cache=True, inline="always")
def cable3d_scratch():
    """Work arrays of :func:`cable3d_element` (allocated once per kernel call, not per element)."""
    return (np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.zeros((6, 4), dtype=np.int64),
            np.zeros((6, 4)), np.zeros(6), np.zeros((6, 6)))


@njit(cache=True, inline="always")
def cable3d_element(f, K, q, dof, dNa, wa, slope_ref, dNb, ddNb, wb, EA, EI, tangent, scratch):
    """One element: adds ``dU/dq`` to ``f`` (12,) and, if ``tangent``, the stiffness to ``K`` (12, 12).

    ``dNa`` (n_a, 4), ``wa``, ``slope_ref`` (n_a,): the axial rule; ``dNb``,
    ``ddNb`` (n_b, 4), ``wb`` (n_b,): the bending rule; ``scratch`` from
    :func:`cable3d_scratch`. Returns the element's strain energy.
    """
    a, b, ga, gb, idx, coef, grad, H = scratch
    U = 0.0
    for p in range(wa.size):
        U += axial_point(f, K, q, dof, dNa[p], wa[p], slope_ref[p], EA, a, idx, coef, grad, H, tangent)
    for p in range(wb.size):
        U += _bending_point(f, K, q, dof, dNb[p], ddNb[p], wb[p], EI, a, b, ga, gb, idx, coef, grad, H, tangent)
    return U


@njit(cache=True)
def cable3d_forces(q, dof, dNa, wa, slope_ref, dNb, ddNb, wb, EA, EI, tangent):
    """Energy (n_el,), forces (n_el, 12) and, if ``tangent``, stiffness (n_el, 12, 12) of all elements.

    Without ``tangent`` the stiffness output has shape (0, 12, 12).
    """
    n_el, n = q.shape
    U = np.zeros(n_el)
    f = np.zeros((n_el, n))
    K = np.zeros((n_el, n, n) if tangent else (1, n, n))
    scratch = cable3d_scratch()
    for e in range(n_el):
        U[e] = cable3d_element(f[e], K[e if tangent else 0], q[e], dof, dNa[e], wa[e], slope_ref[e],
                               dNb[e], ddNb[e], wb[e], EA, EI, tangent, scratch)
    if not tangent:
        K = K[:0]
    return U, f, K


class Cable3DCompiled(OnePassKernel):
    """The compiled kernel object of Cable3D: :func:`cable3d_forces` with the arrays of the geometry."""

    name = "numba"

    def energy_forces(self, geom: dict, q: np.ndarray, order: int) -> tuple:
        """``(U, f, K)`` of :func:`cable3d_forces` (the tangent for ``order`` 2)."""
        el = self.element
        ax, bd = geom["axial"], geom["bend"]
        return cable3d_forces(np.ascontiguousarray(q, dtype=float), ax.dof_map, ax.dN, ax.wdx, geom["slope_ref"],
                              bd.dN, bd.ddN, bd.wdx, el.material.E * el.section.A, el.material.E * el.section.I3,
                              order >= 2)
