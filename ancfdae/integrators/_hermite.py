"""Quintic Hermite interpolation of ``(q, v, a)`` inside a step (the default dense output).

Interpolation error O(h^6) in ``q``, O(h^5) in ``v``, O(h^4) in ``a``: below the integrators'
own error for the step sizes they are used with.
"""
from __future__ import annotations

import numpy as np

__all__ = ["hermite5"]


def _hermite_basis():
    # p(th) = sum_k c_k th^k; rows: p(0), p'(0), p''(0), p(1), p'(1), p''(1)
    A = np.zeros((6, 6))
    for k in range(6):
        A[0, k] = 1.0 if k == 0 else 0.0
        A[1, k] = 1.0 if k == 1 else 0.0
        A[2, k] = 2.0 if k == 2 else 0.0
        A[3, k] = 1.0
        A[4, k] = k
        A[5, k] = k * (k - 1)
    return np.linalg.inv(A)  # column j: coefficients of the basis for datum j


_H5 = _hermite_basis()


def hermite5(t0, y0, t1, y1, t):
    """Quintic Hermite interpolation of ``(q, v, a)`` at ``t`` in ``[t0, t1]``.

    ``y0``, ``y1`` are ``(q, v, a)`` triples at the ends. Returns ``(q, v, a)``.
    """
    h = t1 - t0
    th = (t - t0) / h
    pw = th ** np.arange(6)
    d1 = np.r_[0.0, np.arange(1, 6) * th ** np.arange(5)]
    d2 = np.r_[0.0, 0.0, np.arange(2, 6) * np.arange(1, 5) * th ** np.arange(4)]
    data = (y0[0], h * y0[1], h * h * y0[2], y1[0], h * y1[1], h * h * y1[2])
    out = []
    for d, scale in ((pw, 1.0), (d1, 1.0 / h), (d2, 1.0 / (h * h))):
        w = d @ _H5  # weight of each datum
        out.append(scale * sum(wj * yj for wj, yj in zip(w, data)))
    return tuple(out)
