"""Vector jets compiled: one point at a time, without allocation, in rows of three work arrays.

The compiled twin of :mod:`.vector`, used by the compiled SQ kernels: the same
functions (``variable``, ``dot``, ``cross``, ``mul``, ``chain``, ``sqrt``,
``recip``, ``turn``) with the operands in the same order. A jet of a
``d``-vector over ``K`` variables is three arrays: value ``v`` (d,), gradient
``g`` (d, K) and Hessian ``h`` (d, K, K); a scalar is a jet with ``d = 1``.
Jets are rows of three work arrays owned by the caller, ``V`` (n, 3), ``G``
(n, 3, K) and ``H`` (n, 3, K, K), and every call reads
``op(V, G, H, o, <the operands of the NumPy twin>, d, order)`` with ``o`` the
output row: no function allocates or creates an array view (each view costs
reference counting), which at a few hundred flops per call would cost more
than the arithmetic. ``order`` selects how much is propagated (0: value,
1: plus gradient, 2: plus Hessian); entries above ``order`` are left as they
are. Every rule is the plain product or chain rule, exact to rounding.

Each function is compiled for one explicit signature: called with constant row
numbers, numba specialises a function per distinct combination of constants
(``mul`` had ten copies). Measured (cold numba cache, first ``residual_jacobian``
of a 16-element SQ2D then SQ3D beam, shared 2-core machine): 207 s and 225 s
with the specialisations, 100 s and 133 s with one signature each; the time per
call afterwards is the same within the noise. The outputs differ from the
specialised build at rounding level (3e-16 of the largest entry): LLVM
contracts some products into fused multiply-adds differently when the rows are
constants.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["variable", "dot", "cross", "mul", "chain", "sqrt", "recip", "turn", "lin", "constant", "atan2"]

_ARR = "float64[:, ::1], float64[:, :, ::1], float64[:, :, :, ::1]"


def _sig(*scalars: str) -> str:
    """Signature ``void(V, G, H, *scalars)``."""
    return f"void({_ARR}, {', '.join(scalars)})"


_OPTS = dict(cache=True, fastmath={"contract"})


@njit(_sig("int64", "float64[::1]", "int64", "int64", "int64", "int64"), **_OPTS)
def variable(V, G, H, o, x, x0, d, first, order):
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
                    H[o, c, k, l] = 0.0


@njit(_sig("int64", "int64", "int64", "int64", "int64"), **_OPTS)
def dot(V, G, H, o, a, b, d, order):
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
                    s += (H[a, c, k, l] * V[b, c] + V[a, c] * H[b, c, k, l]
                          + G[a, c, k] * G[b, c, l] + G[a, c, l] * G[b, c, k])
                H[o, 0, k, l] = s
                H[o, 0, l, k] = s


@njit(_sig("int64", "int64", "int64", "int64"), **_OPTS)
def cross(V, G, H, o, a, b, order):
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
                    s = (H[a, i, k, l] * V[b, j] + V[a, i] * H[b, j, k, l]
                         - H[a, j, k, l] * V[b, i] - V[a, j] * H[b, i, k, l]
                         + G[a, i, k] * G[b, j, l] + G[a, i, l] * G[b, j, k]
                         - G[a, j, k] * G[b, i, l] - G[a, j, l] * G[b, i, k])
                    H[o, c, k, l] = s
                    H[o, c, l, k] = s


@njit(_sig("int64", "int64", "int64", "float64", "int64", "int64"), **_OPTS)
def mul(V, G, H, o, a, b, sign, d, order):
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
                    s = (sa * H[b, c, k, l] + sign * (H[a, 0, k, l] * V[b, c] + G[a, 0, k] * G[b, c, l]
                                                      + G[a, 0, l] * G[b, c, k]))
                    H[o, c, k, l] = s
                    H[o, c, l, k] = s


@njit(_sig("int64", "int64", "float64", "float64", "float64", "int64"), **_OPTS)
def chain(V, G, H, o, a, f0, f1, f2, order):
    """``phi(a)`` of a scalar jet for a function with value ``f0`` and derivatives ``f1``, ``f2`` at ``a``."""
    K = G.shape[2]
    V[o, 0] = f0
    if order >= 1:
        for k in range(K):
            G[o, 0, k] = f1 * G[a, 0, k]
    if order >= 2:
        for k in range(K):
            for l in range(k, K):
                s = f1 * H[a, 0, k, l] + f2 * G[a, 0, k] * G[a, 0, l]
                H[o, 0, k, l] = s
                H[o, 0, l, k] = s


@njit(_sig("int64", "int64", "int64"), **_OPTS)
def sqrt(V, G, H, o, a, order):
    """``sqrt(a)`` of a scalar jet."""
    r = np.sqrt(V[a, 0])
    chain(V, G, H, o, a, r, 0.5 / r, -0.25 / (r * V[a, 0]), order)


@njit(_sig("int64", "int64", "int64"), **_OPTS)
def recip(V, G, H, o, a, order):
    """``1 / a`` of a scalar jet."""
    inv = 1.0 / V[a, 0]
    chain(V, G, H, o, a, inv, -inv * inv, 2.0 * inv * inv * inv, order)


@njit(_sig("int64", "int64", "float64", "int64"), **_OPTS)
def turn(V, G, H, o, a, sign, order):
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
                H[o, 0, k, l] = sign * H[a, 1, k, l]
                H[o, 1, k, l] = -sign * H[a, 0, k, l]


@njit(_sig("int64", "float64", "int64", "float64", "int64", "int64", "int64"), **_OPTS)
def lin(V, G, H, o, ca, a, cb, b, d, order):
    """``ca a + cb b`` of two d-vector jets (constants ``ca, cb``) into row ``o``."""
    K = G.shape[2]
    for c in range(d):
        V[o, c] = ca * V[a, c] + cb * V[b, c]
    if order >= 1:
        for c in range(d):
            for k in range(K):
                G[o, c, k] = ca * G[a, c, k] + cb * G[b, c, k]
    if order >= 2:
        for c in range(d):
            for k in range(K):
                for l in range(K):
                    H[o, c, k, l] = ca * H[a, c, k, l] + cb * H[b, c, k, l]


@njit(_sig("int64", "float64[::1]", "int64", "int64"), **_OPTS)
def constant(V, G, H, o, x, d, order):
    """The constant d-vector ``x`` into row ``o`` (zero derivatives)."""
    K = G.shape[2]
    for c in range(d):
        V[o, c] = x[c]
    if order >= 1:
        for c in range(d):
            for k in range(K):
                G[o, c, k] = 0.0
    if order >= 2:
        for c in range(d):
            for k in range(K):
                for l in range(K):
                    H[o, c, k, l] = 0.0


@njit(_sig("int64", "int64", "int64", "int64"), **_OPTS)
def atan2(V, G, H, o, s, c, order):
    """The angle ``atan2(s, c)`` of two scalar jets into the scalar row ``o``."""
    K = G.shape[2]
    vs, vc = V[s, 0], V[c, 0]
    r2 = vc * vc + vs * vs
    if order >= 2:
        for k in range(K):
            gk = (vc * G[s, 0, k] - vs * G[c, 0, k]) / r2
            dk = 2.0 * (vc * G[c, 0, k] + vs * G[s, 0, k])
            for l in range(k, K):
                gl = (vc * G[s, 0, l] - vs * G[c, 0, l]) / r2
                dl = 2.0 * (vc * G[c, 0, l] + vs * G[s, 0, l])
                x = (vc * H[s, 0, k, l] - vs * H[c, 0, k, l] - 0.5 * (gk * dl + gl * dk)) / r2
                H[o, 0, k, l] = x
                H[o, 0, l, k] = x
    if order >= 1:
        for k in range(K):
            G[o, 0, k] = (vc * G[s, 0, k] - vs * G[c, 0, k]) / r2
    V[o, 0] = np.arctan2(vs, vc)
