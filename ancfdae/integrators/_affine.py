"""Compiled updates of the states that are affine in Newton's unknown.

The fixed-step methods write the states of a step as constant parts plus multiples of the unknown
(Newmark family: ``q = q0 + cq x``, ``v = v0 + cv x``, ``a = a0 + ca x``; Lobatto IIIA:
``Q = Q0 + X CQ``, ``V = V0 + X CV``). With NumPy each update is two calls of about 0.7 us at the
sizes of small meshes, six per Newton iteration; one compiled call forms them all. Each call
returns fresh arrays (a model may keep what it is given), and the arithmetic is the NumPy
expression's, term by term, without fused multiply-adds: results are bit-for-bit NumPy's.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["affine2", "affine3", "newmark_predict", "stage_constants", "stage_states"]


@njit(cache=True)
def affine3(q0, v0, a0, cq, cv, ca, x):
    """``(q0 + cq x, v0 + cv x, a0 + ca x)`` as three new 1-D arrays."""
    n = x.shape[0]
    q, v, a = np.empty(n), np.empty(n), np.empty(n)
    for i in range(n):
        xi = x[i]
        q[i] = q0[i] + cq * xi
        v[i] = v0[i] + cv * xi
        a[i] = a0[i] + ca * xi
    return q, v, a


@njit(cache=True)
def stage_states(Q0, V0, CQ, CV, x):
    """``X = x`` as (n, m), ``Q = Q0 + X @ CQ`` and ``V = V0 + X @ CV`` (new C-ordered arrays).

    The product's sum runs over ``k = 0 .. m-1`` in order; NumPy's matmul may order or fuse it
    differently, so Q and V agree with the NumPy expression to round-off, not bit for bit.
    """
    n, m = Q0.shape
    X = x.reshape(n, m)
    Q, V = np.empty((n, m)), np.empty((n, m))
    for i in range(n):
        for j in range(m):
            sq = 0.0
            sv = 0.0
            for k in range(m):
                sq += X[i, k] * CQ[k, j]
                sv += X[i, k] * CV[k, j]
            Q[i, j] = Q0[i, j] + sq
            V[i, j] = V0[i, j] + sv
    return Q, V, X


@njit(cache=True)
def newmark_predict(q, v, a, h, beta, gamma, alpha_m, alpha_f):
    """The constant parts of a generalized-alpha step, in one pass (bit-for-bit the NumPy forms).

    Returns ``q_pred = q + h v + h^2 (1/2 - beta) a``, ``v_pred = v + h (1 - gamma) a`` and the
    weighted ``qa0 = q + (1 - af)(q_pred - q)``, ``va0 = v + (1 - af)(v_pred - v)``, ``aa0 = am a``.
    """
    n = q.shape[0]
    cqa, cva, w = h * h * (0.5 - beta), h * (1.0 - gamma), 1 - alpha_f
    q_pred, v_pred = np.empty(n), np.empty(n)
    qa0, va0, aa0 = np.empty(n), np.empty(n), np.empty(n)
    for i in range(n):
        qp = q[i] + h * v[i] + cqa * a[i]
        vp = v[i] + cva * a[i]
        q_pred[i], v_pred[i] = qp, vp
        qa0[i] = q[i] + w * (qp - q[i])
        va0[i] = v[i] + w * (vp - v[i])
        aa0[i] = alpha_m * a[i]
    return q_pred, v_pred, qa0, va0, aa0


@njit(cache=True)
def affine2(q0, v0, cq, cv, x):
    """``(q0 + cq x, v0 + cv x)`` as two new 1-D arrays."""
    n = x.shape[0]
    q, v = np.empty(n), np.empty(n)
    for i in range(n):
        q[i] = q0[i] + cq * x[i]
        v[i] = v0[i] + cv * x[i]
    return q, v


@njit(cache=True)
def stage_constants(q, v, a, ca, cc, ca2):
    """The constant parts of Lobatto's stage states, ``V0 = v + a ca^T`` and
    ``Q0 = q + v cc^T + a ca2^T`` as (n, m) arrays (bit-for-bit the NumPy broadcasts)."""
    n, m = q.shape[0], ca.shape[0]
    Q0, V0 = np.empty((n, m)), np.empty((n, m))
    for i in range(n):
        for j in range(m):
            V0[i, j] = v[i] + ca[j] * a[i]
            Q0[i, j] = q[i] + cc[j] * v[i] + ca2[j] * a[i]
    return Q0, V0
