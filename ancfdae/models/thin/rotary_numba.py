"""Compiled rotary inertia from the spin coefficients at one point (the twin of :mod:`.rotary`).

Each function adds one quadrature point's share (weight ``W = rho J w_p``) to an element's outputs, from
``c`` (n,), ``C = dc/dq`` (n, n) and ``Hc = d2c/dq2`` (n, n, n); the formulas are those of :mod:`.rotary`.
"""
from __future__ import annotations

from numba import njit

__all__ = ["rotary_energy", "rotary_force", "rotary_bilinear"]

_OPTS = dict(cache=True, inline="always", fastmath={"contract"})


@njit(**_OPTS)
def rotary_energy(W, c, v):
    """``1/2 W (c . v)^2``."""
    om = 0.0
    for r in range(c.size):
        om += c[r] * v[r]
    return 0.5 * W * om * om


@njit(**_OPTS)
def rotary_force(W, c, C, Hc, v, acc, f, Kq, Dv, Ma, tangent, work):
    """Adds ``W [c Omega + omega1 (C v - C^T v)]`` to ``f`` and, if ``tangent``, its derivatives to
    ``Kq, Dv, Ma`` (:func:`.rotary.rotary_inertia`); ``work`` (>= 6, n) scratch."""
    n = c.size
    Cv, CTv, skew, dOm = work[0], work[1], work[2], work[3]
    om = 0.0
    Om = 0.0
    for i in range(n):
        om += c[i] * v[i]
        Om += c[i] * acc[i]
        s = 0.0
        s2 = 0.0
        for k in range(n):
            s += C[i, k] * v[k]
            s2 += C[k, i] * v[k]
        Cv[i] = s
        CTv[i] = s2
    for i in range(n):
        Om += v[i] * Cv[i]
    for i in range(n):
        skew[i] = Cv[i] - CTv[i]
        f[i] += W * (c[i] * Om + om * skew[i])
    if not tangent:
        return
    for l in range(n):
        s = 0.0
        for i in range(n):
            s += C[i, l] * acc[i]
            for k in range(n):
                s += v[i] * Hc[i, k, l] * v[k]
        dOm[l] = s
    for i in range(n):
        for k in range(n):
            Ma[i, k] += W * c[i] * c[k]
            Dv[i, k] += W * (c[i] * (Cv[k] + CTv[k]) + skew[i] * c[k] + om * (C[i, k] - C[k, i]))
            h = 0.0
            for j in range(n):
                h += (Hc[i, j, k] - Hc[j, i, k]) * v[j]
            Kq[i, k] += W * (C[i, k] * Om + c[i] * dOm[k] + skew[i] * CTv[k] + om * h)


@njit(**_OPTS)
def rotary_bilinear(W, c, C, Hc, u, w, g, Hq, order, work):
    """``1/2 W (c.u)(c.w)``; adds its q-gradient to ``g`` (order >= 1) and Hessian to ``Hq`` (order 2)
    (:func:`.rotary.mass_bilinear`); ``work`` (>= 2, n) scratch."""
    n = c.size
    cu = 0.0
    cw = 0.0
    for i in range(n):
        cu += c[i] * u[i]
        cw += c[i] * w[i]
    if order >= 1:
        Ctu, Ctw = work[0], work[1]
        for k in range(n):
            s = 0.0
            s2 = 0.0
            for i in range(n):
                s += C[i, k] * u[i]
                s2 += C[i, k] * w[i]
            Ctu[k] = s
            Ctw[k] = s2
            g[k] += 0.5 * W * (cw * s + cu * s2)
        if order >= 2:
            for k in range(n):
                for l in range(n):
                    h = Ctu[k] * Ctw[l] + Ctw[k] * Ctu[l]
                    for i in range(n):
                        h += Hc[i, k, l] * (cw * u[i] + cu * w[i])
                    Hq[k, l] += 0.5 * W * h
    return 0.5 * W * cu * cw
