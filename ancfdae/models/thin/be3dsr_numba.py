"""Compiled BE3DSR kernels: strain energy, forces and tangent, rotary inertia, and the kernel object.

The compiled twin of :class:`.be3dsr.BE3DSRReference`: per quadrature point the same vector-jet operations
as :mod:`.be3dsr_kinematics`, in the same order, on rows of work arrays
(:mod:`ancfdae.models.jets.vector_numba`), over the 14 element coordinates. The rotary inertia goes through
:mod:`.rotary_numba` from the spin coefficients ``(c, C, Hc)``. Work arrays are allocated once per call;
the nodal frames, which do not depend on the point, are computed once per element (:func:`_nodes`).

numba's cache is keyed on this file only: after editing :mod:`ancfdae.models.jets.vector_numba` or
:mod:`.rotary_numba`, delete the ``*.nbi``/``*.nbc`` files in ``__pycache__`` (see
:mod:`ancfdae.models.shear.kernels_numba`).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..element import OnePassKernel
from ..jets import vector_numba as vj
from .be3d_numba import BE3DCompiled
from .rotary_numba import rotary_bilinear, rotary_energy, rotary_force
from .spatial_numba import axial_point

__all__ = ["BE3DSRCompiled", "sr_forces", "sr_spin", "N_ROWS"]

K = 14
# rows of the work arrays: inputs, the two nodal frames (X = A: +0, X = B: +NODE), the point, the results
(A, B, ONE, PA, NA, INA, T) = range(7)
# per node: slope, angle, director, unit tangent, 1/|a_X|, m = d x a_X, |m|^2, e20, e30, cos, sin, e2, e3,
# transport 1/(1 + u.t), u + t, scalars, the transported e2, e3, and two temporaries
(XA, XTH, XD, XU, XINV, XM, XM2, XE20, XE30, XC, XS, XE2, XE3, XIC, XW, XT1, XT2, XEB2, XEB3, XS1, XS2, XS3,
 XS4) = range(23)
NODE = 23
N0 = 7
(PHI, AL, CA, SA, E2, E3, K1, K2, K3, AXB, IPA, TAUA, TAUB, R1, R2, R3, SC, SN) = range(N0 + 2 * NODE,
                                                                                N0 + 2 * NODE + 18)
N_ROWS = N0 + 2 * NODE + 18
# spin rows (reusing the temporaries): per node g_X and the coefficient vectors
(SAD, SW, SW2, SCOEF, SG, SH, SCX, SCH) = (XS3, XS1, XS2, XS4, XEB2, XEB3, XE20, XE30)


@njit(cache=True, inline="always")
def _hermite(V, G, H, o, q, dof, N, order):
    """Row ``o`` := ``sum_k N_k q[dof[k]]`` (``r'`` or ``r''``) with its derivatives over the coordinates."""
    for i in range(3):
        s = 0.0
        for k in range(4):
            s += N[k] * q[dof[k, i]]
        V[o, i] = s
        if order >= 1:
            for j in range(K):
                G[o, i, j] = 0.0
            for k in range(4):
                G[o, i, dof[k, i]] = N[k]
        if order >= 2:
            for j in range(K):
                for l in range(K):
                    H[o, i, j, l] = 0.0


@njit(cache=True, inline="always")
def _unit(V, G, H, o, inv, x, tmp, tmp2, order):
    """Row ``o`` := ``x / |x|``, row ``inv`` := ``1/|x|`` (``tmp, tmp2`` scratch rows; no operation of
    :mod:`ancfdae.models.jets.vector_numba` but ``lin`` may write one of its operands)."""
    vj.dot(V, G, H, tmp, x, x, 3, order)
    vj.sqrt(V, G, H, tmp2, tmp, order)
    vj.recip(V, G, H, inv, tmp2, order)
    vj.mul(V, G, H, o, inv, x, 1.0, 3, order)


@njit(cache=True, inline="always")
def _node(V, G, H, X, q, first, d, order):
    """The nodal frame (Eqs. 96-100) of the node whose slope starts at coordinate ``first`` into rows X + ..."""
    vj.variable(V, G, H, X + XA, q, first, 3, first, order)
    vj.variable(V, G, H, X + XTH, q, first + 3, 1, first + 3, order)
    vj.constant(V, G, H, X + XD, d, 3, order)
    _unit(V, G, H, X + XU, X + XINV, X + XA, X + XS3, X + XS4, order)
    vj.cross(V, G, H, X + XM, X + XD, X + XA, order)
    vj.dot(V, G, H, X + XM2, X + XM, X + XM, 3, order)
    vj.sqrt(V, G, H, X + XS1, X + XM2, order)
    vj.recip(V, G, H, X + XS2, X + XS1, order)
    vj.mul(V, G, H, X + XE20, X + XS2, X + XM, 1.0, 3, order)
    vj.cross(V, G, H, X + XE30, X + XU, X + XE20, order)
    th = V[X + XTH, 0]
    c, s = np.cos(th), np.sin(th)
    vj.chain(V, G, H, X + XC, X + XTH, c, -s, -c, order)
    vj.chain(V, G, H, X + XS, X + XTH, s, c, -s, order)
    vj.mul(V, G, H, X + XT1, X + XC, X + XE20, 1.0, 3, order)
    vj.mul(V, G, H, X + XT2, X + XS, X + XE30, 1.0, 3, order)
    vj.lin(V, G, H, X + XE2, 1.0, X + XT1, 1.0, X + XT2, 3, order)
    vj.mul(V, G, H, X + XT1, X + XC, X + XE30, 1.0, 3, order)
    vj.mul(V, G, H, X + XT2, X + XS, X + XE20, 1.0, 3, order)
    vj.lin(V, G, H, X + XE3, 1.0, X + XT1, -1.0, X + XT2, 3, order)


@njit(cache=True, inline="always")
def _transport(V, G, H, X, order):
    """``ebar2, ebar3`` of node X on the tangent row T, and ``1/(1 + u.t)`` (:func:`.be3dsr_kinematics.transported`)."""
    vj.dot(V, G, H, X + XS1, X + XU, T, 3, order)
    vj.lin(V, G, H, X + XS1, 1.0, X + XS1, 1.0, ONE, 1, order)
    vj.recip(V, G, H, X + XIC, X + XS1, order)
    vj.lin(V, G, H, X + XW, 1.0, X + XU, 1.0, T, 3, order)
    for e, out in ((X + XE2, X + XEB2), (X + XE3, X + XEB3)):
        vj.dot(V, G, H, X + XS1, T, e, 3, order)
        vj.mul(V, G, H, X + XS2, X + XIC, X + XS1, 1.0, 1, order)
        vj.mul(V, G, H, X + XT1, X + XS2, X + XW, 1.0, 3, order)
        vj.lin(V, G, H, out, 1.0, e, -1.0, X + XT1, 3, order)


@njit(cache=True, inline="always")
def _nodes(V, G, H, q, dA, dB, one, order):
    """The two nodal frames and the constant row ONE: once per element, since they do not depend on the
    point (the point operations below write none of the node rows they read: XA, XD, XU, XINV, XM, XM2,
    XE2, XE3)."""
    vj.constant(V, G, H, ONE, one, 1, order)
    _node(V, G, H, N0, q, 3, dA, order)
    _node(V, G, H, N0 + NODE, q, 10, dB, order)


@njit(cache=True, inline="always")
def _common(V, G, H, q, dof, dN, order):
    """Slope, tangent and the transports of the nodal frames at a point, after :func:`_nodes`
    (:func:`.be3dsr_kinematics._common`)."""
    _hermite(V, G, H, A, q, dof, dN, order)
    vj.dot(V, G, H, PA, A, A, 3, order)
    vj.sqrt(V, G, H, NA, PA, order)
    vj.recip(V, G, H, INA, NA, order)
    vj.mul(V, G, H, T, INA, A, 1.0, 3, order)
    _transport(V, G, H, N0, order)
    _transport(V, G, H, N0 + NODE, order)


@njit(cache=True, inline="always")
def _curvatures(V, G, H, q, dof, dN, ddN, S5, S6, L, order):
    """Rows K1, K2, K3 := twist and curvatures at a point, after :func:`_nodes`
    (:func:`.be3dsr_kinematics.curvatures`)."""
    _common(V, G, H, q, dof, dN, order)
    XA_, XB_ = N0, N0 + NODE
    _hermite(V, G, H, B, q, dof, ddN, order)
    vj.dot(V, G, H, SN, XA_ + XEB3, XB_ + XEB2, 3, order)
    vj.dot(V, G, H, SC, XA_ + XEB2, XB_ + XEB2, 3, order)
    vj.atan2(V, G, H, PHI, SN, SC, order)
    vj.lin(V, G, H, AL, S6, PHI, 0.0, PHI, 1, order)
    al = V[AL, 0]
    c, s = np.cos(al), np.sin(al)
    vj.chain(V, G, H, CA, AL, c, -s, -c, order)
    vj.chain(V, G, H, SA, AL, s, c, -s, order)
    vj.mul(V, G, H, R1, CA, XA_ + XEB2, 1.0, 3, order)
    vj.mul(V, G, H, R2, SA, XA_ + XEB3, 1.0, 3, order)
    vj.lin(V, G, H, E2, 1.0, R1, 1.0, R2, 3, order)
    vj.mul(V, G, H, R1, CA, XA_ + XEB3, 1.0, 3, order)
    vj.mul(V, G, H, R2, SA, XA_ + XEB2, 1.0, 3, order)
    vj.lin(V, G, H, E3, 1.0, R1, -1.0, R2, 3, order)
    vj.dot(V, G, H, R3, B, E2, 3, order)
    vj.mul(V, G, H, K3, INA, R3, 1.0, 1, order)
    vj.dot(V, G, H, R3, B, E3, 3, order)
    vj.mul(V, G, H, K2, INA, R3, -1.0, 1, order)
    vj.cross(V, G, H, AXB, A, B, order)
    vj.recip(V, G, H, IPA, PA, order)
    for X, tau in ((XA_, TAUA), (XB_, TAUB)):
        vj.mul(V, G, H, R1, IPA, X + XIC, 1.0, 1, order)
        vj.dot(V, G, H, R3, X + XU, AXB, 3, order)
        vj.mul(V, G, H, tau, R1, R3, -1.0, 1, order)
    vj.lin(V, G, H, R1, S5, TAUA, S6, TAUB, 1, order)
    vj.lin(V, G, H, K1, 1.0 / L, PHI, 1.0, R1, 1, order)


@njit(cache=True)
def sr_forces(q, dof, dNa, wa, slope_ref, dNb, ddNb, wb, lin, L, directors, k_ref, stiffness, EA, order):
    """Energy (n_el,), forces (n_el, 14) and, for ``order`` 2, the tangent (n_el, 14, 14) of all elements.

    ``order`` 0 gives the energy only (forces zero); without the tangent its output has shape (0, 14, 14).
    """
    n_el = q.shape[0]
    U = np.zeros(n_el)
    f = np.zeros((n_el, K))
    Kt = np.zeros((n_el if order >= 2 else 0, K, K))
    V = np.zeros((N_ROWS, 3))
    G = np.zeros((N_ROWS, 3, K))
    H = np.zeros((N_ROWS if order >= 2 else 1, 3, K, K))
    a = np.empty(3)
    idx = np.zeros((3, 4), dtype=np.int64)
    coef = np.zeros((3, 4))
    grad = np.zeros(3)
    Hl = np.zeros((3, 3))
    Kax = np.zeros((K, K))
    one = np.ones(1)
    for e in range(n_el):
        Ke = Kt[e] if order >= 2 else Kax
        for p in range(wa.shape[1]):
            U[e] += axial_point(f[e], Ke, q[e], dof, dNa[e, p], wa[e, p], slope_ref[e, p], EA, a, idx, coef, grad,
                                Hl, order >= 2)
        _nodes(V, G, H, q[e], directors[e], directors[e + 1], one, order)
        for p in range(wb.shape[1]):
            _curvatures(V, G, H, q[e], dof, dNb[e, p], ddNb[e, p], lin[p, 0], lin[p, 1], L[e], order)
            for i in range(3):
                wc = stiffness[i] * wb[e, p]
                r = V[K1 + i, 0] - k_ref[e, p, i]
                U[e] += 0.5 * wc * r * r
                if order >= 1:
                    for k in range(K):
                        f[e, k] += wc * r * G[K1 + i, 0, k]
                if order >= 2:
                    for k in range(K):
                        gk = wc * G[K1 + i, 0, k]
                        for l in range(K):
                            Ke[k, l] += wc * r * H[K1 + i, 0, k, l] + gk * G[K1 + i, 0, l]
    return U, f, Kt


@njit(cache=True, inline="always")
def sr_spin(V, G, H, q, dof, dN, S5, S6, c, C, Hc, order):
    """The spin coefficients ``c`` (14,), ``C`` (14, 14), ``Hc`` (14, 14, 14) at a point (by ``order``), after
    :func:`_nodes` for the element.

    :func:`.be3dsr_kinematics.spin_coefficients`: per node ``c_X = g_X + h_X/|a_X|`` and ``ch_X = h_X/|a|``.
    """
    _common(V, G, H, q, dof, dN, order)
    for X in (N0, N0 + NODE):
        vj.dot(V, G, H, X + SAD, X + XA, X + XD, 3, order)
        vj.recip(V, G, H, X + SW, X + XINV, order)
        vj.mul(V, G, H, X + SW2, X + SW, X + XM2, 1.0, 1, order)
        vj.recip(V, G, H, X + SW, X + SW2, order)
        vj.mul(V, G, H, X + SCOEF, X + SAD, X + SW, 1.0, 1, order)
        vj.mul(V, G, H, X + SG, X + SCOEF, X + XM, 1.0, 3, order)
        vj.cross(V, G, H, X + XT2, T, X + XU, order)
        vj.mul(V, G, H, X + SH, X + XIC, X + XT2, 1.0, 3, order)
        vj.mul(V, G, H, X + XT2, X + XINV, X + SH, 1.0, 3, order)
        vj.lin(V, G, H, X + SCX, 1.0, X + SG, 1.0, X + XT2, 3, order)
        vj.mul(V, G, H, X + SCH, INA, X + SH, 1.0, 3, order)
    # ch = S5 ch_A + S6 ch_B into row R1
    vj.lin(V, G, H, R1, S5, N0 + SCH, S6, N0 + NODE + SCH, 3, order)
    c[:] = 0.0
    if order >= 1:
        C[:] = 0.0
    if order >= 2:
        Hc[:] = 0.0
    for S, X, first, theta in ((S5, N0, 3, 6), (S6, N0 + NODE, 10, 13)):
        c[theta] += S
        for i in range(3):
            c[first + i] += S * V[X + SCX, i]
            if order >= 1:
                for k in range(K):
                    C[first + i, k] += S * G[X + SCX, i, k]
            if order >= 2:
                for k in range(K):
                    for l in range(K):
                        Hc[first + i, k, l] += S * H[X + SCX, i, k, l]
    for kk in range(4):
        for i in range(3):
            n = dof[kk, i]
            w = dN[kk]
            c[n] += w * V[R1, i]
            if order >= 1:
                for k in range(K):
                    C[n, k] += w * G[R1, i, k]
            if order >= 2:
                for k in range(K):
                    for l in range(K):
                        Hc[n, k, l] += w * H[R1, i, k, l]


@njit(cache=True)
def sr_rotary(q, v, acc, dof, dN, wdx, lin, directors, rhoJ, mode, order):
    """Rotary quantities of all elements from the spin at the inertia points (:mod:`.rotary_numba`).

    ``mode`` 0: kinetic energy (n_el,); 1: inertia force and, for ``order`` 2, df/dq, df/dv, df/da;
    2: ``1/2 v^T M_rot acc`` with its q-gradient and, for ``order`` 2, Hessian (``v, acc`` as ``u, w``).
    Returns ``(s, f, K1, K2, K3)`` (unused outputs empty).
    """
    n_el = q.shape[0]
    m = n_el if order >= 2 else 1
    s_out = np.zeros(n_el)
    f = np.zeros((n_el, K))
    K1_ = np.zeros((m, K, K))
    K2_ = np.zeros((m, K, K))
    K3_ = np.zeros((m, K, K))
    V = np.zeros((N_ROWS, 3))
    G = np.zeros((N_ROWS, 3, K))
    H = np.zeros((N_ROWS if order >= 2 else 1, 3, K, K))
    c = np.zeros(K)
    C = np.zeros((K, K))
    Hc = np.zeros((K if order >= 2 else 1, K, K))
    one = np.ones(1)
    work = np.zeros((6, K))
    spin_order = order if mode != 0 else 0
    for e in range(n_el):
        j = e if order >= 2 else 0
        _nodes(V, G, H, q[e], directors[e], directors[e + 1], one, spin_order)
        for p in range(wdx.shape[1]):
            sr_spin(V, G, H, q[e], dof, dN[e, p], lin[p, 0], lin[p, 1], c, C, Hc, spin_order)
            W = rhoJ * wdx[e, p]
            if mode == 0:
                s_out[e] += rotary_energy(W, c, v[e])
            elif mode == 1:
                rotary_force(W, c, C, Hc, v[e], acc[e], f[e], K1_[j], K2_[j], K3_[j], order >= 2, work)
            else:
                s_out[e] += rotary_bilinear(W, c, C, Hc, v[e], acc[e], f[e], K1_[j], order, work)
    if order < 2:
        return s_out, f, K1_[:0], K2_[:0], K3_[:0]
    return s_out, f, K1_, K2_, K3_


class BE3DSRCompiled(OnePassKernel):
    """The compiled kernel object of BE3DSR: :func:`sr_forces`, :func:`sr_rotary` and BE3D's compiled moment."""

    name = "numba"

    def energy_forces(self, geom: dict, q: np.ndarray, order: int) -> tuple:
        """``(U, f, K)`` of :func:`sr_forces`."""
        el = self.element
        ax, bd = geom["axial"], geom["bend"]
        U, f, Kt = sr_forces(np.ascontiguousarray(q, dtype=float), bd.dof_map, ax.dN, ax.wdx, geom["slope_ref"],
                             bd.dN, bd.ddN, bd.wdx, bd.lin, geom["L"], _directors(geom),
                             np.ascontiguousarray(geom["k_ref"]), el.curvature_stiffness, el.EA, order)
        return U, f, (Kt if order >= 2 else None)

    # The dead moment acts through the nodal frames, which BE3DSR shares with BE3D: BE3D's compiled load.
    moment_load = BE3DCompiled.moment_load

    def _rotary(self, geom, q, v, acc, mode, order):
        rule = geom["inertia"]
        return sr_rotary(*(np.ascontiguousarray(x, dtype=float) for x in (q, v, acc)), rule.dof_map, rule.dN,
                         rule.wdx, rule.lin, _directors(geom), self.element.rhoJ, mode, order)

    def inertia(self, geom: dict, q: np.ndarray, v: np.ndarray, a: np.ndarray, tangent: bool = True) -> tuple:
        """As :meth:`.be3dsr.BE3DSRReference.inertia`, compiled."""
        _, f, Kq, Dv, Ma = self._rotary(geom, q, v, a, 1, 2 if tangent else 1)
        return (f, Kq, Dv, Ma) if tangent else (f, None, None, None)

    def kinetic_energy(self, geom: dict, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """As :meth:`.be3dsr.BE3DSRReference.kinetic_energy`, compiled."""
        return self._rotary(geom, q, v, v, 0, 0)[0]

    def mass_bilinear(self, geom: dict, q: np.ndarray, u: np.ndarray, w: np.ndarray, order: int = 2) -> tuple:
        """As :meth:`.be3dsr.BE3DSRReference.mass_bilinear`, compiled."""
        B, g, Hq, _, _ = self._rotary(geom, q, u, w, 2, order)
        return (B, g, Hq)[:order + 1]


def _directors(geom):
    """The nodal directors (n_nodes, 3) as the compiled kernels take them (C-contiguous floats)."""
    return np.array(geom["directors"], dtype=float, order="C")   # a writable copy: the jet rows take float64[::1]
