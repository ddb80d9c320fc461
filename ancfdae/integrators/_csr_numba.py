"""Compiled products with the constraint Jacobian ``G`` (CSR, few rows) for the constrained steppers.

Each Newton iteration of a constrained step needs ``G v``, ``G^T lam`` and ``G^T mu`` per stage; through
scipy each costs more to call (format checks, index-dtype checks: 10-30 us) than to compute for the
few rows of a joint set, so the products run as compiled loops on the CSR arrays.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["csr_matvec", "csr_rmatvec", "ggl_reduce", "ggl_expand", "ggl_stage_rows"]


@njit(cache=True)
def csr_matvec(indptr, indices, data, x):
    """``G x`` for ``G = (data, indices, indptr)``."""
    m = indptr.size - 1
    out = np.zeros(m)
    for i in range(m):
        s = 0.0
        for k in range(indptr[i], indptr[i + 1]):
            s += data[k] * x[indices[k]]
        out[i] = s
    return out


@njit(cache=True)
def csr_rmatvec(indptr, indices, data, u, n):
    """``G^T u`` for ``G = (data, indices, indptr)`` with ``n`` columns."""
    out = np.zeros(n)
    for i in range(indptr.size - 1):
        ui = u[i]
        for k in range(indptr[i], indptr[i + 1]):
            out[indices[k]] += data[k] * ui
    return out


@njit(cache=True)
def ggl_reduce(r, n, m, ns, h, ms, a, Kp, Ki, Kd, Gp, Gi, Gd, Wp, Wi, Wd, perm):
    """Right-hand side of the reduced GGL stage system (frozen blocks), permuted; and ``rho``.

    ``r`` = [RK, RD, Rg, Rv] (stage copies interleaved); ``rho = RK h / ms``, ``P = h rho a^T``;
    returns ``b[perm]`` with ``b = [RD - Kt P, Rg - ms/h^2 G P, Rv - ms/h W P]``, and ``rho`` (n, ns).
    """
    rho = np.empty((n, ns))
    for p in range(n):
        for i in range(ns):
            rho[p, i] = r[p * ns + i] * (h / ms)
    P = np.zeros((n, ns))
    for p in range(n):
        for i in range(ns):
            s = 0.0
            for k in range(ns):
                s += a[i, k] * rho[p, k]
            P[p, i] = h * s
    nb = (n + 2 * m) * ns
    b = np.empty(nb)
    o = n * ns
    for p in range(n):
        for i in range(ns):
            s = 0.0
            for kk in range(Kp[p], Kp[p + 1]):
                s += Kd[kk] * P[Ki[kk], i]
            b[p * ns + i] = r[o + p * ns + i] - s
    for j in range(m):
        for i in range(ns):
            sg = 0.0
            for kk in range(Gp[j], Gp[j + 1]):
                sg += Gd[kk] * P[Gi[kk], i]
            sw = 0.0
            for kk in range(Wp[j], Wp[j + 1]):
                sw += Wd[kk] * P[Wi[kk], i]
            b[o + j * ns + i] = r[2 * o + j * ns + i] - ms / (h * h) * sg
            b[o + m * ns + j * ns + i] = r[2 * o + m * ns + j * ns + i] - ms / h * sw
    out = np.empty(nb)
    for t in range(nb):
        out[t] = b[perm[t]]
    return out, rho


@njit(cache=True)
def ggl_expand(zp, rho, n, m, ns, h, a, Gp, Gi, Gd, perm):
    """The full Newton correction ``[dK, dA, dLam, dU]`` from the reduced solution ``zp`` (permuted):
    ``dK = rho + h dA a^T + h G^T dU`` (frozen ``G``)."""
    nb = zp.size
    z = np.empty(nb)
    for t in range(nb):
        z[perm[t]] = zp[t]
    o = n * ns
    out = np.empty(2 * o + 2 * m * ns)
    for p in range(n):
        for i in range(ns):
            s = 0.0
            for k in range(ns):
                s += a[i, k] * z[p * ns + k]
            out[p * ns + i] = rho[p, i] + h * s
    for j in range(m):
        for kk in range(Gp[j], Gp[j + 1]):
            c = Gi[kk]
            for i in range(ns):
                out[c * ns + i] += h * Gd[kk] * z[o + m * ns + j * ns + i]
    for t in range(nb):
        out[o + t] = z[t]
    return out


@njit(cache=True)
def ggl_stage_rows(out, i, n, m, ns, ms, h, Gp, Gi, Gd, K, V, U, L, g, g_t):
    """Stage ``i``'s rows of the GGL residual ``out = [RK, RD, Rg, Rv]`` (``RD`` holds the model's
    residual on entry): ``RK = ms/h (K - V - h G^T U)``, ``RD += G^T Lam``, ``Rg = ms/h^2 g``,
    ``Rv = ms/h (G V + g_t)`` (the module docstring of ``lobatto_constrained``)."""
    o = n * ns
    c = ms / h
    for p in range(n):
        out[p * ns + i] = c * (K[p, i] - V[p, i])
    for j in range(m):
        gv = 0.0
        for kk in range(Gp[j], Gp[j + 1]):
            col = Gi[kk]
            out[col * ns + i] -= ms * Gd[kk] * U[j, i]
            out[o + col * ns + i] += Gd[kk] * L[j, i]
            gv += Gd[kk] * V[col, i]
        out[2 * o + j * ns + i] = c / h * g[j]
        out[2 * o + m * ns + j * ns + i] = c * (gv + g_t[j])
