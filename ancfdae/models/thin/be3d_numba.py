"""Compiled BE3D kernels: strain energy, internal forces and exact tangent (chapter Sects. 3.5-3.6), and the
kernel object :class:`BE3DCompiled` that adds the compiled rotary inertia and dead moment.

The same energy as the NumPy reference :class:`.be3d.BE3DReference`: the
axial term of Eq. 16 at the axial points, and at the bending points
``1/2 sum_i C_i (k_i - k_i,ref)^2`` (``C``: the curvature stiffnesses) with the twist and curvatures of the
frame of Eqs. 96-100 (formulas in :mod:`.be3d_kinematics`),

    k1 = theta' - tau0,  k2 = s X - c Y,  k3 = c X + s Y,

written in the invariants ``p = a.a``, ``a.d``, ``|d x a|^2``, ``a.b``,
``b.d``, ``b.(d x a)``, ``d'.(d x a)`` of the slope ``a = r'``, ``b = r''``
and the interpolated director ``d``. Exact gradients and Hessians with
respect to the eight local variables ``(a, b, theta, theta')`` come from the
slot jets of :mod:`ancfdae.models.jets.scalar_numba`. The nodal directors are
an input array, so the kernel reads no state besides its arguments. BE3D offers
no fused assembly entry point: the beam scatters its element arrays with
``np.bincount``.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..element import OnePassKernel
from ..jets import scalar_numba as jet
from .be3d_inertia_numba import be3d_inertia, be3d_kinetic_energy, be3d_mass_bilinear
from .be3d_moment_numba import be3d_moment
from .spatial_numba import axial_point, hermite_map, scatter, slope

__all__ = ["BE3DCompiled", "be3d_forces", "be3d_element", "be3d_scratch", "curvature_point", "N_SLOTS", "K1", "K2",
           "K3"]

# Jet slots: inputs, then intermediates, then the results k1, k2, k3.
(P, AD, M2, AB, BD, T, TP, SP, SM, R1, X, N1, N2, NY, R2, Y, N3, N4, NT, R3, TAU, W1, W2, K1, K2, K3) = range(26)
N_SLOTS = 26
N_LOC = 8


@njit(cache=True)
def curvature_point(V, G, H, a, b, th, thp, d, dp, order):
    """Jets of ``(k1, k2, k3)`` over ``(a, b, theta, theta')`` in slots K1, K2, K3 (8 variables).

    ``X``, ``Y`` and ``tau0`` depend on ``(a, b)`` only: their jets run over
    those six variables (36 Hessian entries, not 64); the angle enters
    through ``cos``/``sin`` and ``theta'`` linearly, so the jets of the
    ``k_i`` over all eight variables are written out from them at the end.
    """
    n = 6
    for o in (P, AD, M2, AB, BD, T, TP):
        jet.zero(V, G, H, o, n, order)
    m0 = d[1] * a[2] - d[2] * a[1]          # m = d x a
    m1 = d[2] * a[0] - d[0] * a[2]
    m2 = d[0] * a[1] - d[1] * a[0]
    dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    ad = a[0] * d[0] + a[1] * d[1] + a[2] * d[2]
    V[P] = a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
    V[AD] = ad
    V[M2] = m0 * m0 + m1 * m1 + m2 * m2
    V[AB] = a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    V[BD] = b[0] * d[0] + b[1] * d[1] + b[2] * d[2]
    V[T] = b[0] * m0 + b[1] * m1 + b[2] * m2
    V[TP] = dp[0] * m0 + dp[1] * m1 + dp[2] * m2
    # b x d and d' x d: gradients of b.(d x a) = a.(b x d) and d'.(d x a) in a
    G[T, 0] = b[1] * d[2] - b[2] * d[1]
    G[T, 1] = b[2] * d[0] - b[0] * d[2]
    G[T, 2] = b[0] * d[1] - b[1] * d[0]
    G[TP, 0] = dp[1] * d[2] - dp[2] * d[1]
    G[TP, 1] = dp[2] * d[0] - dp[0] * d[2]
    G[TP, 2] = dp[0] * d[1] - dp[1] * d[0]
    G[T, 3], G[T, 4], G[T, 5] = m0, m1, m2
    for i in range(3):
        G[P, i] = 2.0 * a[i]
        G[AD, i] = d[i]
        G[M2, i] = 2.0 * (dd * a[i] - ad * d[i])
        G[AB, i] = b[i]
        G[AB, 3 + i] = a[i]
        G[BD, 3 + i] = d[i]
    if order >= 2:
        for i in range(3):
            H[P, i, i] = 2.0
            H[AB, i, 3 + i] = 1.0
            H[AB, 3 + i, i] = 1.0
            for j in range(3):
                H[M2, i, j] = 2.0 * ((dd if i == j else 0.0) - d[i] * d[j])
        # d2 (b.(d x a)) / (da_i db_j) = eps_ijk d_k
        H[T, 0, 4] = H[T, 4, 0] = d[2]
        H[T, 1, 3] = H[T, 3, 1] = -d[2]
        H[T, 2, 3] = H[T, 3, 2] = d[1]
        H[T, 0, 5] = H[T, 5, 0] = -d[1]
        H[T, 1, 5] = H[T, 5, 1] = d[0]
        H[T, 2, 4] = H[T, 4, 2] = -d[0]
    jet.sqrt(V, G, H, SP, P, n, order)
    jet.sqrt(V, G, H, SM, M2, n, order)
    # X = t / (|m| |a|)
    jet.mul(V, G, H, W1, SM, SP, n, order)
    jet.recip(V, G, H, R1, W1, n, order)
    jet.mul(V, G, H, X, T, R1, n, order)
    # Y = (b.d p - (a.b)(a.d)) / (p |m|)
    jet.mul(V, G, H, N1, BD, P, n, order)
    jet.mul(V, G, H, N2, AB, AD, n, order)
    jet.lin(V, G, H, NY, 1.0, N1, -1.0, N2, n, order)
    jet.mul(V, G, H, W2, P, SM, n, order)
    jet.recip(V, G, H, R2, W2, n, order)
    jet.mul(V, G, H, Y, NY, R2, n, order)
    # tau0 = (p d'.m - (a.d) t) / (|a| |m|^2)
    jet.mul(V, G, H, N3, P, TP, n, order)
    jet.mul(V, G, H, N4, AD, T, n, order)
    jet.lin(V, G, H, NT, 1.0, N3, -1.0, N4, n, order)
    jet.mul(V, G, H, W1, SP, M2, n, order)
    jet.recip(V, G, H, R3, W1, n, order)
    jet.mul(V, G, H, TAU, NT, R3, n, order)
    # k1 = theta' - tau0, k2 = s X - c Y, k3 = c X + s Y over (a, b, theta, theta')
    c, s = np.cos(th), np.sin(th)
    for o in (K1, K2, K3):
        jet.zero(V, G, H, o, N_LOC, order)
    vx, vy = V[X], V[Y]
    V[K1] = thp - V[TAU]
    V[K2] = s * vx - c * vy
    V[K3] = c * vx + s * vy
    G[K1, 7] = 1.0
    G[K2, 6] = V[K3]
    G[K3, 6] = -V[K2]
    for i in range(n):
        G[K1, i] = -G[TAU, i]
        G[K2, i] = s * G[X, i] - c * G[Y, i]
        G[K3, i] = c * G[X, i] + s * G[Y, i]
    if order >= 2:
        for i in range(n):
            h2 = c * G[X, i] + s * G[Y, i]          # d2 k2 / (d x_i d theta)
            h3 = -s * G[X, i] + c * G[Y, i]         # d2 k3 / (d x_i d theta)
            H[K2, i, 6] = H[K2, 6, i] = h2
            H[K3, i, 6] = H[K3, 6, i] = h3
            for j in range(n):
                H[K1, i, j] = -H[TAU, i, j]
                H[K2, i, j] = s * H[X, i, j] - c * H[Y, i, j]
                H[K3, i, j] = c * H[X, i, j] + s * H[Y, i, j]
        H[K2, 6, 6] = -V[K2]
        H[K3, 6, 6] = -V[K3]


@njit(cache=True, inline="always")
def be3d_scratch(tangent):
    """Work arrays of :func:`be3d_element` (allocated once per kernel call, not per element)."""
    return (np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.zeros((N_LOC, 4), dtype=np.int64),
            np.zeros((N_LOC, 4)), np.zeros(N_LOC), np.zeros((N_LOC, N_LOC)), np.zeros(N_SLOTS),
            np.zeros((N_SLOTS, N_LOC)), np.zeros((N_SLOTS if tangent else 1, N_LOC, N_LOC)))


@njit(cache=True, inline="always")
def be3d_element(f, K, q, dof, theta, dNa, wa, slope_ref, dNb, ddNb, wb, lin, L, dA, dB, k_ref, stiffness, EA,
                 tangent, scratch):
    """One element: adds ``dU/dq`` to ``f`` (14,) and, if ``tangent``, the stiffness to ``K``; returns U.

    ``theta`` (2,): element coordinates of the nodal angles; ``lin`` (n_b, 2):
    the linear functions at the bending points; ``dA, dB``: the element's
    nodal directors; ``k_ref`` (n_b, 3); ``stiffness = (G J k_t, E I2, E I3)``;
    ``scratch`` from :func:`be3d_scratch`.
    """
    a, b, d, dp, idx, coef, grad, Hl, V, G, H = scratch
    U = 0.0
    for p in range(wa.size):
        U += axial_point(f, K, q, dof, dNa[p], wa[p], slope_ref[p], EA, a, idx, coef, grad, Hl, tangent)
    for i in range(3):
        dp[i] = (dB[i] - dA[i]) / L
    for p in range(wb.size):
        slope(q, dof, dNb[p], a)
        slope(q, dof, ddNb[p], b)
        l0, l1 = lin[p, 0], lin[p, 1]
        for i in range(3):
            d[i] = l0 * dA[i] + l1 * dB[i]
        th = l0 * q[theta[0]] + l1 * q[theta[1]]
        thp = (q[theta[1]] - q[theta[0]]) / L
        curvature_point(V, G, H, a, b, th, thp, d, dp, 2 if tangent else 1)
        for v in range(N_LOC):
            grad[v] = 0.0
            for u in range(N_LOC):
                Hl[v, u] = 0.0
        for i in range(3):
            k = K1 + i
            wi = stiffness[i] * wb[p]
            dk = V[k] - k_ref[p, i]
            ri = dk * wi
            U += 0.5 * ri * dk
            for v in range(N_LOC):
                grad[v] += ri * G[k, v]
            if tangent:
                for v in range(N_LOC):
                    gv = wi * G[k, v]
                    for u in range(N_LOC):
                        Hl[v, u] += ri * H[k, v, u] + gv * G[k, u]
        hermite_map(idx, coef, dof, dNb[p], ddNb[p])
        for r in range(4):
            idx[6, r] = idx[7, r] = 0
            coef[6, r] = coef[7, r] = 0.0
        idx[6, 0], idx[6, 1], coef[6, 0], coef[6, 1] = theta[0], theta[1], l0, l1
        idx[7, 0], idx[7, 1], coef[7, 0], coef[7, 1] = theta[0], theta[1], -1.0 / L, 1.0 / L
        scatter(f, K, idx, coef, N_LOC, grad, Hl, tangent)
    return U


@njit(cache=True)
def be3d_forces(q, dof, theta, dNa, wa, slope_ref, dNb, ddNb, wb, lin, L, directors, k_ref, stiffness, EA,
                tangent):
    """Energy (n_el,), forces (n_el, 14) and, if ``tangent``, stiffness (n_el, 14, 14) of all elements.

    ``directors`` (n_el + 1, 3): the nodal directors along the beam. Without
    ``tangent`` the stiffness output has shape (0, 14, 14).
    """
    n_el, n = q.shape
    U = np.zeros(n_el)
    f = np.zeros((n_el, n))
    K = np.zeros((n_el, n, n) if tangent else (1, n, n))
    scratch = be3d_scratch(tangent)
    for e in range(n_el):
        U[e] = be3d_element(f[e], K[e if tangent else 0], q[e], dof, theta, dNa[e], wa[e], slope_ref[e],
                            dNb[e], ddNb[e], wb[e], lin, L[e], directors[e], directors[e + 1], k_ref[e], stiffness,
                            EA, tangent, scratch)
    if not tangent:
        K = K[:0]
    return U, f, K


class BE3DCompiled(OnePassKernel):
    """The compiled kernel object of BE3D: :func:`be3d_forces`, and the compiled rotary inertia
    (:mod:`.be3d_inertia_numba`) and dead moment (:mod:`.be3d_moment_numba`)."""

    name = "numba"

    def energy_forces(self, geom: dict, q: np.ndarray, order: int) -> tuple:
        """``(U, f, K)`` of :func:`be3d_forces` (the tangent for ``order`` 2)."""
        el = self.element
        ax, bd = geom["axial"], geom["bend"]
        return be3d_forces(np.ascontiguousarray(q, dtype=float), bd.dof_map, bd.theta, ax.dN, ax.wdx,
                           geom["slope_ref"], bd.dN, bd.ddN, bd.wdx, bd.lin, geom["L"], _directors(geom),
                           geom["k_ref"], el.curvature_stiffness, el.EA, order >= 2)

    def moment_load(self, geom: dict, q: np.ndarray, s: float, moment: np.ndarray, element: int,
                    tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """As :meth:`.be3d.BE3DReference.moment_load`, compiled."""
        rule = geom["bend"]
        directors = _directors(geom)
        f, K = be3d_moment(np.ascontiguousarray(q, dtype=float), rule.dof_map, rule.theta, float(s),
                           float(geom["L"][element]), directors[element], directors[element + 1], moment,
                           bool(tangent))
        return f, (K if tangent else None)

    def inertia(self, geom: dict, q: np.ndarray, v: np.ndarray, a: np.ndarray, tangent: bool = True) -> tuple:
        """As :meth:`.be3d.BE3DReference.inertia`, compiled."""
        rule = geom["inertia"]
        f, Kq, Dv, Ma = be3d_inertia(*(np.ascontiguousarray(x, dtype=float) for x in (q, v, a)), rule.dof_map,
                                     rule.theta, rule.dN, rule.wdx, rule.lin, _directors(geom),
                                     self.element.rhoJ, bool(tangent))
        return (f, Kq, Dv, Ma) if tangent else (f, None, None, None)

    def kinetic_energy(self, geom: dict, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """As :meth:`.be3d.BE3DReference.kinetic_energy`, compiled."""
        rule = geom["inertia"]
        return be3d_kinetic_energy(np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(v, dtype=float),
                                   rule.dof_map, rule.theta, rule.dN, rule.wdx, rule.lin, _directors(geom),
                                   self.element.rhoJ)

    def mass_bilinear(self, geom: dict, q: np.ndarray, u: np.ndarray, w: np.ndarray, order: int = 2) -> tuple:
        """As :meth:`.be3d.BE3DReference.mass_bilinear`, compiled (:func:`.be3d_inertia_numba.be3d_mass_bilinear`)."""
        rule = geom["inertia"]
        out = be3d_mass_bilinear(*(np.ascontiguousarray(x, dtype=float) for x in (q, u, w)), rule.dof_map,
                                 rule.theta, rule.dN, rule.wdx, rule.lin, _directors(geom), self.element.rhoJ,
                                 int(order))
        return out[:order + 1]


def _directors(geom):
    """The nodal directors (n_nodes, 3) as the compiled kernels take them (C-contiguous floats)."""
    return np.ascontiguousarray(geom["directors"], dtype=float)
