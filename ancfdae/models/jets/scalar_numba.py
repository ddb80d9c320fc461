"""Scalar jets compiled: one point at a time, without allocation, in slots of three work arrays.

The compiled twin of :mod:`.scalar`: ``mul``, ``chain``, ``recip`` and ``sqrt``
carry the NumPy names with the operands in the same order; ``zero`` clears a
slot and ``lin`` forms ``ca a + cb b`` (what the NumPy twin's operators
``+`` and ``-`` do). A jet is a *slot* ``k`` of three work arrays: its value
``V[k]``, gradient ``G[k, :n]`` and Hessian ``H[k, :n, :n]`` with respect to
``n`` local variables. Each operation writes slot ``o`` from its operands; the
Hessian is written first, then the gradient, then the value, so an operand may
be the output slot. ``order`` 1 skips the Hessians (residual path), ``order``
2 propagates them. Every call reads
``op(V, G, H, o, <the operands of the NumPy twin>, n, order)``.

The functions are compiled for one explicit signature each: called with
constant slot numbers, numba would otherwise compile a specialisation per
distinct constant (it did: ten copies of ``mul``, a third of the first-call
compile time of the BE3D kernel).
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["zero", "mul", "lin", "chain", "recip", "sqrt"]

_ARR = "float64[::1], float64[:, ::1], float64[:, :, ::1]"


def _sig(*scalars: str) -> str:
    """Signature ``void(V, G, H, *scalars)``."""
    return f"void({_ARR}, {', '.join(scalars)})"


@njit(_sig("int64", "int64", "int64"), cache=True)
def zero(V, G, H, o, n, order):
    """Slot ``o`` := 0 (value, gradient and Hessian)."""
    V[o] = 0.0
    for i in range(n):
        G[o, i] = 0.0
    if order >= 2:
        for i in range(n):
            for j in range(n):
                H[o, i, j] = 0.0


@njit(_sig("int64", "int64", "int64", "int64", "int64"), cache=True)
def mul(V, G, H, o, a, b, n, order):
    """``o = a * b``."""
    va, vb = V[a], V[b]
    if order >= 2:
        for i in range(n):
            gai, gbi = G[a, i], G[b, i]
            for j in range(n):
                H[o, i, j] = H[a, i, j] * vb + H[b, i, j] * va + gai * G[b, j] + gbi * G[a, j]
    for i in range(n):
        G[o, i] = G[a, i] * vb + G[b, i] * va
    V[o] = va * vb


@njit(_sig("int64", "float64", "int64", "float64", "int64", "int64", "int64"), cache=True)
def lin(V, G, H, o, ca, a, cb, b, n, order):
    """``o = ca * a + cb * b`` for constants ``ca, cb``."""
    if order >= 2:
        for i in range(n):
            for j in range(n):
                H[o, i, j] = ca * H[a, i, j] + cb * H[b, i, j]
    for i in range(n):
        G[o, i] = ca * G[a, i] + cb * G[b, i]
    V[o] = ca * V[a] + cb * V[b]


@njit(_sig("int64", "int64", "float64", "float64", "float64", "int64", "int64"), cache=True)
def chain(V, G, H, o, a, f0, f1, f2, n, order):
    """``o = phi(a)`` for a scalar function with ``phi(a) = f0``, ``phi' = f1``, ``phi'' = f2``."""
    if order >= 2:
        for i in range(n):
            gi = G[a, i]
            for j in range(n):
                H[o, i, j] = H[a, i, j] * f1 + gi * G[a, j] * f2
    for i in range(n):
        G[o, i] = G[a, i] * f1
    V[o] = f0


@njit(_sig("int64", "int64", "int64", "int64"), cache=True)
def recip(V, G, H, o, a, n, order):
    """``o = 1 / a``."""
    r = 1.0 / V[a]
    chain(V, G, H, o, a, r, -r * r, 2.0 * r * r * r, n, order)


@njit(_sig("int64", "int64", "int64", "int64"), cache=True)
def sqrt(V, G, H, o, a, n, order):
    """``o = sqrt(a)``."""
    s = np.sqrt(V[a])
    chain(V, G, H, o, a, s, 0.5 / s, -0.25 / (s * V[a]), n, order)
