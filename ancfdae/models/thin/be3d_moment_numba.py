"""Compiled generalised force of a dead moment on BE3D, and its exact q-derivative.

The same expressions as the NumPy reference :func:`.be3d_moment.moment_load`:
the virtual rotation of the frame at ``s`` is
``delta phi = e1 x delta e1 + (delta theta + g . delta r') e1`` (Eqs. 96-100
under a variation), so with ``a = r'``, ``p = |a|^2``, ``e1 = a / |a|``:

    f_r'    = (M x a) / p + g (M . e1),      f_theta = M . e1,
    d f_r' / da = [M]_x / p - 2 (M x a) a^T / p^2 + (M . e1) G + g (d(M . e1)/da)^T,
    d(M . e1)/da = (M - (M . e1) e1) / |a|,

with ``g``, ``G = dg/da`` of the spin (:mod:`.be3d_inertia_numba`). The
Hermite functions at ``s`` are evaluated here (chapter Eq. 60, derivative
per xi), so a call does no NumPy work.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .be3d_inertia_numba import spin_scratch, spin_vector

__all__ = ["be3d_moment"]


@njit(cache=True)
def be3d_moment(q, dof, theta, s, L, dA, dB, M, tangent):
    """Force (14,) and, if ``tangent``, its derivative (14, 14) (else shape (0, 14)) of moment ``M`` at ``s``."""
    n = q.size
    c = 2.0 / L
    dN = np.empty(4)
    dN[0] = (-0.75 + 0.75 * s * s) * c
    dN[1] = L / 8.0 * (-1.0 - 2.0 * s + 3.0 * s * s) * c
    dN[2] = (0.75 - 0.75 * s * s) * c
    dN[3] = L / 8.0 * (-1.0 + 2.0 * s + 3.0 * s * s) * c
    l0, l1 = 0.5 - 0.5 * s, 0.5 + 0.5 * s
    a = np.zeros(3)
    d = np.empty(3)
    for i in range(3):
        for k in range(4):
            a[i] += dN[k] * q[dof[k, i]]
        d[i] = l0 * dA[i] + l1 * dB[i]
    g = np.empty(3)
    Gm = np.empty((3, 3))
    Hg = np.empty((1, 3, 3))
    V, G, H, m, dm = spin_scratch(1)
    spin_vector(a, d, g, Gm, Hg, 1, V, G, H, m, dm)
    p = a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
    sp = np.sqrt(p)
    Me1 = (M[0] * a[0] + M[1] * a[1] + M[2] * a[2]) / sp
    Mxa = np.empty(3)
    Mxa[0] = M[1] * a[2] - M[2] * a[1]
    Mxa[1] = M[2] * a[0] - M[0] * a[2]
    Mxa[2] = M[0] * a[1] - M[1] * a[0]
    fa = np.empty(3)
    for i in range(3):
        fa[i] = Mxa[i] / p + g[i] * Me1
    f = np.zeros(n)
    for k in range(4):
        for i in range(3):
            f[dof[k, i]] += dN[k] * fa[i]
    f[theta[0]] += l0 * Me1
    f[theta[1]] += l1 * Me1
    if not tangent:
        return f, np.zeros((0, n))
    dMe1 = np.empty(3)
    for i in range(3):
        dMe1[i] = (M[i] - Me1 * a[i] / sp) / sp
    Mx = np.zeros((3, 3))          # d(M x a)/da = [M]_x
    Mx[0, 1], Mx[0, 2] = -M[2], M[1]
    Mx[1, 0], Mx[1, 2] = M[2], -M[0]
    Mx[2, 0], Mx[2, 1] = -M[1], M[0]
    dfa = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            dfa[i, j] = Mx[i, j] / p - 2.0 * Mxa[i] * a[j] / (p * p) + Me1 * Gm[i, j] + g[i] * dMe1[j]
    K = np.zeros((n, n))
    for k in range(4):
        for l in range(4):
            ckl = dN[k] * dN[l]
            for i in range(3):
                for j in range(3):
                    K[dof[k, i], dof[l, j]] += ckl * dfa[i, j]
    for l in range(4):
        for j in range(3):
            col = dof[l, j]
            K[theta[0], col] += l0 * dMe1[j] * dN[l]
            K[theta[1], col] += l1 * dMe1[j] * dN[l]
    return f, K
