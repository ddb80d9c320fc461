"""Compiled rotary inertia of BE3D: force, its exact derivatives K, D, M, and the kinetic energy.

The same expressions as the NumPy reference :func:`.be3d_inertia.rotary_inertia`
(derivation in that module's docstring): with the spin
``omega1 = w(q) . v``, ``w = N_theta + Ba^T g(a)``,
``g(a) = (a.d)(d x a) / (|a| |d x a|^2)``, ``G = dg/da``, ``Hg = d2g/da2``,

    f    = int rho J [ w Omega + omega1 Ba^T (G - G^T) a_dot ] dxi,
    Omega = w . acc + a_dot^T G a_dot,

and its derivatives with respect to the accelerations (``M``), velocities
(``D``) and coordinates (``K``). Per point, ``g, G, Hg`` come from the jet of
the scalar ``c = (a.d) / (|a| |d x a|^2)`` over ``a`` (three variables,
:mod:`ancfdae.models.jets.scalar_numba`): ``g = c m``, ``m = d x a = [d]_x a``. Products with the
Hermite operator ``Ba`` use its sparsity: ``(Ba^T x)[dof[k, i]] += dN_k x_i``. The energy-momentum method's
``1/2 u^T M_rot(q) w`` with its q-derivatives (:func:`be3d_mass_bilinear`) goes through :mod:`.rotary_numba`.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..jets import scalar_numba as jet
from .rotary_numba import rotary_bilinear
from .spatial_numba import slope

__all__ = ["be3d_inertia", "be3d_inertia_element", "inertia_scratch", "be3d_kinetic_energy", "be3d_mass_bilinear"]

_P, _AD, _M2, _SP, _W, _R, _C = range(7)


@njit(cache=True, inline="always")
def spin_scratch(order):
    """Work arrays of :func:`spin_vector`: jet slots (V, G, H), a 3-vector and a 3x3 matrix."""
    return np.zeros(7), np.zeros((7, 3)), np.zeros((7 if order >= 2 else 1, 3, 3)), np.zeros(3), np.zeros((3, 3))


# Explicit signatures: one compilation each (constant flags would otherwise each get their own).
_V3, _M33, _T333 = "float64[::1]", "float64[:, ::1]", "float64[:, :, ::1]"


@njit(f"void({_V3}, {_V3}, {_V3}, {_M33}, {_T333}, int64, {_V3}, {_M33}, {_T333}, {_V3}, {_M33})", cache=True)
def spin_vector(a, d, g, Gm, Hg, order, V, G, H, m, dm):
    """``g(a)``, ``G = dg/da`` and, for ``order`` 2, ``Hg[i, j, k] = d2 g_i / da_j da_k`` at one point.

    ``V, G, H, m, dm``: work arrays from :func:`spin_scratch`.
    """
    m[0] = d[1] * a[2] - d[2] * a[1]
    m[1] = d[2] * a[0] - d[0] * a[2]
    m[2] = d[0] * a[1] - d[1] * a[0]
    dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    ad = a[0] * d[0] + a[1] * d[1] + a[2] * d[2]
    for o in (_P, _AD, _M2):
        jet.zero(V, G, H, o, 3, order)
    V[_P] = a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
    V[_AD] = ad
    V[_M2] = m[0] * m[0] + m[1] * m[1] + m[2] * m[2]
    for i in range(3):
        G[_P, i] = 2.0 * a[i]
        G[_AD, i] = d[i]
        G[_M2, i] = 2.0 * (dd * a[i] - ad * d[i])
        if order >= 2:
            H[_P, i, i] = 2.0
            for j in range(3):
                H[_M2, i, j] = 2.0 * ((dd if i == j else 0.0) - d[i] * d[j])
    jet.sqrt(V, G, H, _SP, _P, 3, order)
    jet.mul(V, G, H, _W, _SP, _M2, 3, order)
    jet.recip(V, G, H, _R, _W, 3, order)
    jet.mul(V, G, H, _C, _AD, _R, 3, order)
    # dm/da = [d]_x
    dm[0, 1], dm[0, 2] = -d[2], d[1]
    dm[1, 0], dm[1, 2] = d[2], -d[0]
    dm[2, 0], dm[2, 1] = -d[1], d[0]
    c = V[_C]
    for i in range(3):
        g[i] = c * m[i]
        for j in range(3):
            Gm[i, j] = G[_C, j] * m[i] + c * dm[i, j]
            if order >= 2:
                for k in range(3):
                    Hg[i, j, k] = H[_C, j, k] * m[i] + G[_C, j] * dm[i, k] + G[_C, k] * dm[i, j]


@njit(f"void({_V3}, int64[:, ::1], {_V3}, {_V3}, float64)", cache=True)
def _bat(out, dof, dN, x, scale):
    """``out += scale Ba^T x`` for a 3-vector ``x``."""
    for k in range(4):
        for i in range(3):
            out[dof[k, i]] += scale * dN[k] * x[i]


@njit(f"void({_M33}, int64[:, ::1], {_V3}, {_M33}, float64)", cache=True)
def _bat_m_ba(out, dof, dN, M, scale):
    """``out += scale Ba^T M Ba`` for a 3x3 ``M``."""
    for k in range(4):
        for l in range(4):
            c = scale * dN[k] * dN[l]
            for i in range(3):
                for j in range(3):
                    out[dof[k, i], dof[l, j]] += c * M[i, j]


@njit(cache=True, inline="always")
def _point_state(q, dof, theta, dN, l0, l1, dA, dB, a, d, w, g, Gm, Hg, order, scratch):
    """Slope ``a``, director ``d``, ``g, G, Hg`` and the spin row ``w = N_theta + Ba^T g`` at a point."""
    slope(q, dof, dN, a)
    for i in range(3):
        d[i] = l0 * dA[i] + l1 * dB[i]
    V, G, H, m, dm = scratch
    spin_vector(a, d, g, Gm, Hg, order, V, G, H, m, dm)
    w[:] = 0.0
    w[theta[0]] = l0
    w[theta[1]] = l1
    _bat(w, dof, dN, g, 1.0)


@njit(cache=True, inline="always")
def inertia_scratch(n, tangent):
    """Work arrays of :func:`be3d_inertia_element` for ``n`` element coordinates."""
    return ((np.empty(3), np.empty(3), np.empty(3), np.empty((3, 3)), np.empty((3, 3, 3)), np.empty(3),
             np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty((3, 3))),
            (np.empty(n), np.empty(n), np.empty(n), np.empty(n)), spin_scratch(2 if tangent else 1))


@njit(cache=True, inline="always")
def be3d_inertia_element(f, Kq, Dv, Ma, q, v, acc, dof, theta, dN, wdx, lin, dA, dB, rhoJ, tangent, work):
    """One element: adds the rotary inertia force to ``f`` (14,) and, if ``tangent``, df/dq, df/dv, df/da.

    ``work`` from :func:`inertia_scratch`.
    """
    n = q.size
    (a, d, g, Gm, Hg, ad, add, Gad, x, y, M3), (w, c, t, u), scratch = work
    for p in range(wdx.size):
        W = rhoJ * wdx[p]
        _point_state(q, dof, theta, dN[p], lin[p, 0], lin[p, 1], dA, dB, a, d, w, g, Gm, Hg, 2 if tangent else 1, scratch)
        slope(v, dof, dN[p], ad)                       # a_dot
        om = 0.0
        wacc = 0.0
        for r in range(n):
            om += w[r] * v[r]
            wacc += w[r] * acc[r]
        Om = wacc
        for i in range(3):
            s = 0.0
            s2 = 0.0
            for k in range(3):
                s += Gm[i, k] * ad[k]
                s2 += Gm[k, i] * ad[k]
            Gad[i] = s
            x[i] = s - s2                               # (G - G^T) a_dot
            Om += ad[i] * s
        c[:] = 0.0
        _bat(c, dof, dN[p], x, 1.0)
        for r in range(n):
            f[r] += W * (w[r] * Om + om * c[r])
        if not tangent:
            continue
        for r in range(n):
            for s_ in range(n):
                Ma[r, s_] += W * w[r] * w[s_]
        # D: w sym^T + c w^T + om Ba^T (G - G^T) Ba, sym = Ba^T (G + G^T) a_dot
        for i in range(3):
            y[i] = 2.0 * Gad[i] - x[i]                  # (G + G^T) a_dot
            for j in range(3):
                M3[i, j] = Gm[i, j] - Gm[j, i]
        t[:] = 0.0
        _bat(t, dof, dN[p], y, 1.0)
        for r in range(n):
            for s_ in range(n):
                Dv[r, s_] += W * (w[r] * t[s_] + c[r] * w[s_])
        _bat_m_ba(Dv, dof, dN[p], M3, W * om)
        # K: Ba^T G Ba Om + w dOm^T + c dom^T + om Ba^T A2 Ba,
        # dOm = Ba^T (G^T a_ddot + a_dot^T Hg a_dot), dom = Ba^T G^T a_dot, A2 = Hg.a_dot - (Hg.a_dot)^T-like
        slope(acc, dof, dN[p], add)                    # a_ddot
        for k in range(3):
            s = 0.0
            s2 = 0.0
            for i in range(3):
                s += Gm[i, k] * add[i]
                s2 += Gm[i, k] * ad[i]
                for j in range(3):
                    s += ad[i] * Hg[i, j, k] * ad[j]
            x[k] = s
            y[k] = s2
        t[:] = 0.0
        u[:] = 0.0
        _bat(t, dof, dN[p], x, 1.0)
        _bat(u, dof, dN[p], y, 1.0)
        for r in range(n):
            for s_ in range(n):
                Kq[r, s_] += W * (w[r] * t[s_] + c[r] * u[s_])
        _bat_m_ba(Kq, dof, dN[p], Gm, W * Om)
        for i in range(3):
            for k in range(3):
                s = 0.0
                for j in range(3):
                    s += (Hg[i, j, k] - Hg[j, i, k]) * ad[j]
                M3[i, k] = s
        _bat_m_ba(Kq, dof, dN[p], M3, W * om)


@njit(cache=True)
def be3d_inertia(q, v, acc, dof, theta, dN, wdx, lin, directors, rhoJ, tangent):
    """Rotary inertia force (n_el, 14) and, if ``tangent``, df/dq, df/dv, df/da (n_el, 14, 14) each.

    ``dN`` (n_el, n_pts, 4), ``wdx`` (n_el, n_pts), ``lin`` (n_pts, 2): the
    inertia rule; ``directors`` (n_el + 1, 3). Without ``tangent`` the three
    blocks have shape (0, 14, 14).
    """
    n_el, n = q.shape
    f = np.zeros((n_el, n))
    m = n_el if tangent else 1
    Kq = np.zeros((m, n, n))
    Dv = np.zeros((m, n, n))
    Ma = np.zeros((m, n, n))
    work = inertia_scratch(n, tangent)
    for e in range(n_el):
        j = e if tangent else 0
        be3d_inertia_element(f[e], Kq[j], Dv[j], Ma[j], q[e], v[e], acc[e], dof, theta, dN[e], wdx[e], lin,
                             directors[e], directors[e + 1], rhoJ, tangent, work)
    if not tangent:
        return f, Kq[:0], Dv[:0], Ma[:0]
    return f, Kq, Dv, Ma


@njit(cache=True)
def be3d_kinetic_energy(q, v, dof, theta, dN, wdx, lin, directors, rhoJ):
    """``1/2 int rho J omega1^2 dxi`` per element, shape (n_el,)."""
    n_el, n = q.shape
    T = np.zeros(n_el)
    a = np.empty(3)
    d = np.empty(3)
    g = np.empty(3)
    Gm = np.empty((3, 3))
    Hg = np.empty((1, 3, 3))
    w = np.empty(n)
    scratch = spin_scratch(1)
    for e in range(n_el):
        for p in range(wdx.shape[1]):
            _point_state(q[e], dof, theta, dN[e, p], lin[p, 0], lin[p, 1], directors[e], directors[e + 1],
                         a, d, w, g, Gm, Hg, 1, scratch)
            om = 0.0
            for r in range(n):
                om += w[r] * v[e, r]
            T[e] += 0.5 * rhoJ * wdx[e, p] * om * om
    return T


@njit(cache=True)
def be3d_mass_bilinear(q, u, w, dof, theta, dN, wdx, lin, directors, rhoJ, order):
    """``B = 1/2 u^T M_rot(q) w`` per element (n_el,), its q-gradient (n_el, 14) and, for ``order`` 2, Hessian
    (n_el, 14, 14; else shape (0, 14, 14)): :func:`.be3d_inertia.rotary_bilinear`, compiled.

    Per point the spin coefficients of :func:`.rotary_numba.rotary_bilinear`: ``c = N_theta + Ba^T g``,
    ``C = Ba^T G Ba`` and ``Hc[i, k, l] = (Ba^T)_ij Hg[j, m, r] Ba_mk Ba_rl``, through the sparsity of ``Ba``.
    """
    n_el, n = q.shape
    B = np.zeros(n_el)
    g_out = np.zeros((n_el, n))
    Hq = np.zeros((n_el if order >= 2 else 1, n, n))
    a, d, g = np.empty(3), np.empty(3), np.empty(3)
    Gm, Hg = np.empty((3, 3)), np.zeros((3, 3, 3))
    c, C = np.empty(n), np.zeros((n, n))
    Hc = np.zeros((n if order >= 2 else 1, n, n))
    work = np.empty((2, n))
    scratch = spin_scratch(2 if order >= 2 else 1)
    for e in range(n_el):
        j = e if order >= 2 else 0
        for p in range(wdx.shape[1]):
            dNp = dN[e, p]
            _point_state(q[e], dof, theta, dNp, lin[p, 0], lin[p, 1], directors[e], directors[e + 1],
                         a, d, c, g, Gm, Hg, 2 if order >= 2 else 1, scratch)
            if order >= 1:
                C[:] = 0.0
                _bat_m_ba(C, dof, dNp, Gm, 1.0)
            if order >= 2:
                Hc[:] = 0.0
                for k1 in range(4):
                    for k2 in range(4):
                        for k3 in range(4):
                            s = dNp[k1] * dNp[k2] * dNp[k3]
                            for i1 in range(3):
                                for i2 in range(3):
                                    for i3 in range(3):
                                        Hc[dof[k1, i1], dof[k2, i2], dof[k3, i3]] += s * Hg[i1, i2, i3]
            B[e] += rotary_bilinear(rhoJ * wdx[e, p], c, C, Hc, u[e], w[e], g_out[e], Hq[j], order, work)
    if order < 2:
        return B, g_out, Hq[:0]
    return B, g_out, Hq
