"""Compiled second-order forward differentiation ("jets") for one point at a time.

The compiled counterpart of :mod:`ancfdae.models._jet`, used by the compiled
SQ kernels (:mod:`ancfdae.models._sq_numba`). A jet of a ``d``-vector over
``K`` variables is three arrays: value ``v`` (d,), gradient ``g`` (d, K) and
Hessian ``h`` (d, K, K); a scalar is a jet with ``d = 1``. The caller owns the
storage (rows of preallocated work arrays), so no function allocates: the
kernels call these once per quadrature point and an allocation would cost
more than the arithmetic. ``order`` selects how much is propagated (0: value,
1: plus gradient, 2: plus Hessian); entries above ``order`` are left as they
are. Every rule is the plain product or chain rule, exact to rounding.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["jvar", "jdot", "jcross", "jmul", "jsqrt", "jrecip", "jturn"]

_OPTS = dict(cache=True, fastmath={"contract"})


@njit(**_OPTS)
def jvar(x, first, ov, og, oh, order):
    """Independent variables ``x`` (d,) numbered ``first .. first + d - 1``."""
    d = x.shape[0]
    for c in range(d):
        ov[c] = x[c]
    if order >= 1:
        og[:d, :] = 0.0
        for c in range(d):
            og[c, first + c] = 1.0
    if order >= 2:
        oh[:d, :, :] = 0.0


@njit(**_OPTS)
def jdot(d, av, ag, ah, bv, bg, bh, ov, og, oh, order):
    """Scalar product ``a . b`` of two d-vector jets into the scalar jet ``o``."""
    K = og.shape[1]
    s = 0.0
    for c in range(d):
        s += av[c] * bv[c]
    ov[0] = s
    if order >= 1:
        for k in range(K):
            s = 0.0
            for c in range(d):
                s += ag[c, k] * bv[c] + av[c] * bg[c, k]
            og[0, k] = s
    if order >= 2:
        for k in range(K):
            for l in range(k, K):
                s = 0.0
                for c in range(d):
                    s += ah[c, k, l] * bv[c] + av[c] * bh[c, k, l] + ag[c, k] * bg[c, l] + ag[c, l] * bg[c, k]
                oh[0, k, l] = s
                oh[0, l, k] = s


@njit(**_OPTS)
def jcross(av, ag, ah, bv, bg, bh, ov, og, oh, order):
    """Cross product ``a x b`` of two 3-vector jets."""
    K = og.shape[1]
    for c in range(3):
        i, j = (c + 1) % 3, (c + 2) % 3
        ov[c] = av[i] * bv[j] - av[j] * bv[i]
        if order >= 1:
            for k in range(K):
                og[c, k] = ag[i, k] * bv[j] + av[i] * bg[j, k] - ag[j, k] * bv[i] - av[j] * bg[i, k]
        if order >= 2:
            for k in range(K):
                for l in range(k, K):
                    s = (ah[i, k, l] * bv[j] + av[i] * bh[j, k, l] - ah[j, k, l] * bv[i] - av[j] * bh[i, k, l]
                         + ag[i, k] * bg[j, l] + ag[i, l] * bg[j, k] - ag[j, k] * bg[i, l] - ag[j, l] * bg[i, k])
                    oh[c, k, l] = s
                    oh[c, l, k] = s


@njit(**_OPTS)
def jmul(sign, d, av, ag, ah, bv, bg, bh, ov, og, oh, order):
    """``sign * a * b``: scalar jet ``a`` times d-vector jet ``b``."""
    K = og.shape[1]
    a = sign * av[0]
    for c in range(d):
        ov[c] = a * bv[c]
    if order >= 1:
        for c in range(d):
            for k in range(K):
                og[c, k] = a * bg[c, k] + sign * ag[0, k] * bv[c]
    if order >= 2:
        for c in range(d):
            for k in range(K):
                for l in range(k, K):
                    s = (a * bh[c, k, l] + sign * (ah[0, k, l] * bv[c] + ag[0, k] * bg[c, l]
                                                   + ag[0, l] * bg[c, k]))
                    oh[c, k, l] = s
                    oh[c, l, k] = s


@njit(**_OPTS)
def _junary(f, f1, f2, ag, ah, ov, og, oh, order):
    """Chain rule for a scalar function with value f and derivatives f1, f2 at ``a``."""
    K = og.shape[1]
    ov[0] = f
    if order >= 1:
        for k in range(K):
            og[0, k] = f1 * ag[0, k]
    if order >= 2:
        for k in range(K):
            for l in range(k, K):
                s = f1 * ah[0, k, l] + f2 * ag[0, k] * ag[0, l]
                oh[0, k, l] = s
                oh[0, l, k] = s


@njit(**_OPTS)
def jsqrt(av, ag, ah, ov, og, oh, order):
    """``sqrt(a)`` of a scalar jet."""
    r = np.sqrt(av[0])
    _junary(r, 0.5 / r, -0.25 / (r * av[0]), ag, ah, ov, og, oh, order)


@njit(**_OPTS)
def jrecip(av, ag, ah, ov, og, oh, order):
    """``1 / a`` of a scalar jet."""
    inv = 1.0 / av[0]
    _junary(inv, -inv * inv, 2.0 * inv * inv * inv, ag, ah, ov, og, oh, order)


@njit(**_OPTS)
def jturn(sign, av, ag, ah, ov, og, oh, order):
    """``sign * (a_y, -a_x)`` of a 2-vector jet: ``a`` turned by -90 degrees (times sign)."""
    K = og.shape[1]
    ov[0] = sign * av[1]
    ov[1] = -sign * av[0]
    if order >= 1:
        for k in range(K):
            og[0, k] = sign * ag[1, k]
            og[1, k] = -sign * ag[0, k]
    if order >= 2:
        for k in range(K):
            for l in range(K):
                oh[0, k, l] = sign * ah[1, k, l]
                oh[1, k, l] = -sign * ah[0, k, l]
