"""Second-order forward-mode differentiation for compiled kernels: scalar jets in slot arrays.

The compiled counterpart of :mod:`._scalar_jet`, for one point at a time and
without allocation: a jet is a *slot* ``k`` of three work arrays, its value
``V[k]``, gradient ``G[k, :n]`` and Hessian ``H[k, :n, :n]`` with respect to
``n`` local variables. Each operation writes slot ``o`` from its operands;
the Hessian is written first, then the gradient, then the value, so an
operand may be the output slot. ``second=False`` skips the Hessians
(residual path).

The functions are compiled for one explicit signature each: called with
constant slot numbers, numba would otherwise compile a specialisation per
distinct constant (it did: ten copies of :func:`jmul`, a third of the first-
call compile time of the BE3D kernel).
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["jmul", "jlin", "jchain", "jrecip", "jsqrt", "jcos", "jsin", "jconst", "jzero"]

_ARR = "float64[::1], float64[:, ::1], float64[:, :, ::1]"


def _sig(*scalars: str) -> str:
    """Signature ``void(V, G, H, *scalars)``."""
    return f"void({_ARR}, {', '.join(scalars)})"


@njit(_sig("int64", "int64", "boolean"), cache=True)
def jzero(V, G, H, o, n, second):
    """Slot ``o`` := 0 (value, gradient and Hessian)."""
    V[o] = 0.0
    for i in range(n):
        G[o, i] = 0.0
    if second:
        for i in range(n):
            for j in range(n):
                H[o, i, j] = 0.0


@njit(_sig("int64", "float64", "int64", "boolean"), cache=True)
def jconst(V, G, H, o, value, n, second):
    """Slot ``o`` := a constant."""
    jzero(V, G, H, o, n, second)
    V[o] = value


@njit(_sig("int64", "int64", "int64", "int64", "boolean"), cache=True)
def jmul(V, G, H, o, a, b, n, second):
    """``o = a * b``."""
    va, vb = V[a], V[b]
    if second:
        for i in range(n):
            gai, gbi = G[a, i], G[b, i]
            for j in range(n):
                H[o, i, j] = H[a, i, j] * vb + H[b, i, j] * va + gai * G[b, j] + gbi * G[a, j]
    for i in range(n):
        G[o, i] = G[a, i] * vb + G[b, i] * va
    V[o] = va * vb


@njit(_sig("int64", "float64", "int64", "float64", "int64", "int64", "boolean"), cache=True)
def jlin(V, G, H, o, ca, a, cb, b, n, second):
    """``o = ca * a + cb * b`` for constants ``ca, cb``."""
    if second:
        for i in range(n):
            for j in range(n):
                H[o, i, j] = ca * H[a, i, j] + cb * H[b, i, j]
    for i in range(n):
        G[o, i] = ca * G[a, i] + cb * G[b, i]
    V[o] = ca * V[a] + cb * V[b]


@njit(_sig("int64", "int64", "float64", "float64", "float64", "int64", "boolean"), cache=True)
def jchain(V, G, H, o, a, f0, f1, f2, n, second):
    """``o = phi(a)`` for a scalar function with ``phi(a) = f0``, ``phi' = f1``, ``phi'' = f2``."""
    if second:
        for i in range(n):
            gi = G[a, i]
            for j in range(n):
                H[o, i, j] = H[a, i, j] * f1 + gi * G[a, j] * f2
    for i in range(n):
        G[o, i] = G[a, i] * f1
    V[o] = f0


@njit(_sig("int64", "int64", "int64", "boolean"), cache=True)
def jrecip(V, G, H, o, a, n, second):
    """``o = 1 / a``."""
    r = 1.0 / V[a]
    jchain(V, G, H, o, a, r, -r * r, 2.0 * r * r * r, n, second)


@njit(_sig("int64", "int64", "int64", "boolean"), cache=True)
def jsqrt(V, G, H, o, a, n, second):
    """``o = sqrt(a)``."""
    s = np.sqrt(V[a])
    jchain(V, G, H, o, a, s, 0.5 / s, -0.25 / (s * V[a]), n, second)


@njit(_sig("int64", "int64", "int64", "boolean"), cache=True)
def jcos(V, G, H, o, a, n, second):
    """``o = cos(a)``."""
    c, s = np.cos(V[a]), np.sin(V[a])
    jchain(V, G, H, o, a, c, -s, -c, n, second)


@njit(_sig("int64", "int64", "int64", "boolean"), cache=True)
def jsin(V, G, H, o, a, n, second):
    """``o = sin(a)``."""
    c, s = np.cos(V[a]), np.sin(V[a])
    jchain(V, G, H, o, a, s, c, -s, n, second)
