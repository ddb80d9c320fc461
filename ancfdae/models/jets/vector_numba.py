"""Compiled second-order forward differentiation ("jets") for one point at a time.

The compiled counterpart of :mod:`ancfdae.models._jet` (vector jets), used by the compiled
SQ kernels (:mod:`ancfdae.models._sq_numba`). A jet of a ``d``-vector over
``K`` variables is three arrays: value ``v`` (d,), gradient ``g`` (d, K) and
Hessian ``h`` (d, K, K); a scalar is a jet with ``d = 1``. Jets are rows of
three work arrays owned by the caller, ``V`` (n, 3), ``G`` (n, 3, K) and
``Hs`` (n, 3, K, K), and the functions take row numbers: no function
allocates or creates an array view (each view costs reference counting),
which at a few hundred flops per call would cost more than the arithmetic.
``order`` selects how much is propagated (0: value,
1: plus gradient, 2: plus Hessian); entries above ``order`` are left as they
are. Every rule is the plain product or chain rule, exact to rounding.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["jvar", "jdot", "jcross", "jmul", "jsqrt", "jrecip", "jturn"]

_OPTS = dict(cache=True, fastmath={"contract"})


@njit(**_OPTS)
def jvar(x, x0, d, first, V, G, Hs, o, order):
    """Independent variables ``x[x0:x0 + d]`` numbered ``first .. first + d - 1`` into row ``o``."""
    K = G.shape[2]
    for c in range(d):
        V[o, c] = x[x0 + c]
    if order >= 1:
        for c in range(d):
            for k in range(K):
                G[o, c, k] = 0.0
            G[o, c, first + c] = 1.0
    if order >= 2:
        for c in range(d):
            for k in range(K):
                for l in range(K):
                    Hs[o, c, k, l] = 0.0


@njit(**_OPTS)
def jdot(d, V, G, Hs, a, b, o, order):
    """Scalar product ``a . b`` of two d-vector jets into the scalar jet ``o``."""
    K = G.shape[2]
    s = 0.0
    for c in range(d):
        s += V[a, c] * V[b, c]
    V[o, 0] = s
    if order >= 1:
        for k in range(K):
            s = 0.0
            for c in range(d):
                s += G[a, c, k] * V[b, c] + V[a, c] * G[b, c, k]
            G[o, 0, k] = s
    if order >= 2:
        for k in range(K):
            for l in range(k, K):
                s = 0.0
                for c in range(d):
                    s += (Hs[a, c, k, l] * V[b, c] + V[a, c] * Hs[b, c, k, l]
                          + G[a, c, k] * G[b, c, l] + G[a, c, l] * G[b, c, k])
                Hs[o, 0, k, l] = s
                Hs[o, 0, l, k] = s


@njit(**_OPTS)
def jcross(V, G, Hs, a, b, o, order):
    """Cross product ``a x b`` of two 3-vector jets."""
    K = G.shape[2]
    for c in range(3):
        i, j = (c + 1) % 3, (c + 2) % 3
        V[o, c] = V[a, i] * V[b, j] - V[a, j] * V[b, i]
        if order >= 1:
            for k in range(K):
                G[o, c, k] = G[a, i, k] * V[b, j] + V[a, i] * G[b, j, k] - G[a, j, k] * V[b, i] - V[a, j] * G[b, i, k]
        if order >= 2:
            for k in range(K):
                for l in range(k, K):
                    s = (Hs[a, i, k, l] * V[b, j] + V[a, i] * Hs[b, j, k, l]
                         - Hs[a, j, k, l] * V[b, i] - V[a, j] * Hs[b, i, k, l]
                         + G[a, i, k] * G[b, j, l] + G[a, i, l] * G[b, j, k]
                         - G[a, j, k] * G[b, i, l] - G[a, j, l] * G[b, i, k])
                    Hs[o, c, k, l] = s
                    Hs[o, c, l, k] = s


@njit(**_OPTS)
def jmul(sign, d, V, G, Hs, a, b, o, order):
    """``sign * a * b``: scalar jet ``a`` times d-vector jet ``b``."""
    K = G.shape[2]
    sa = sign * V[a, 0]
    for c in range(d):
        V[o, c] = sa * V[b, c]
    if order >= 1:
        for c in range(d):
            for k in range(K):
                G[o, c, k] = sa * G[b, c, k] + sign * G[a, 0, k] * V[b, c]
    if order >= 2:
        for c in range(d):
            for k in range(K):
                for l in range(k, K):
                    s = (sa * Hs[b, c, k, l] + sign * (Hs[a, 0, k, l] * V[b, c] + G[a, 0, k] * G[b, c, l]
                                                   + G[a, 0, l] * G[b, c, k]))
                    Hs[o, c, k, l] = s
                    Hs[o, c, l, k] = s


@njit(**_OPTS)
def _junary(f, f1, f2, V, G, Hs, a, o, order):
    """Chain rule for a scalar function with value f and derivatives f1, f2 at ``a``."""
    K = G.shape[2]
    V[o, 0] = f
    if order >= 1:
        for k in range(K):
            G[o, 0, k] = f1 * G[a, 0, k]
    if order >= 2:
        for k in range(K):
            for l in range(k, K):
                s = f1 * Hs[a, 0, k, l] + f2 * G[a, 0, k] * G[a, 0, l]
                Hs[o, 0, k, l] = s
                Hs[o, 0, l, k] = s


@njit(**_OPTS)
def jsqrt(V, G, Hs, a, o, order):
    """``sqrt(a)`` of a scalar jet."""
    r = np.sqrt(V[a, 0])
    _junary(r, 0.5 / r, -0.25 / (r * V[a, 0]), V, G, Hs, a, o, order)


@njit(**_OPTS)
def jrecip(V, G, Hs, a, o, order):
    """``1 / a`` of a scalar jet."""
    inv = 1.0 / V[a, 0]
    _junary(inv, -inv * inv, 2.0 * inv * inv * inv, V, G, Hs, a, o, order)


@njit(**_OPTS)
def jturn(sign, V, G, Hs, a, o, order):
    """``sign * (a_y, -a_x)`` of a 2-vector jet: ``a`` turned by -90 degrees (times sign)."""
    K = G.shape[2]
    V[o, 0] = sign * V[a, 1]
    V[o, 1] = -sign * V[a, 0]
    if order >= 1:
        for k in range(K):
            G[o, 0, k] = sign * G[a, 1, k]
            G[o, 1, k] = -sign * G[a, 0, k]
    if order >= 2:
        for k in range(K):
            for l in range(K):
                Hs[o, 0, k, l] = sign * Hs[a, 1, k, l]
                Hs[o, 1, k, l] = -sign * Hs[a, 0, k, l]
