"""Gauss-Legendre rules on the normalised element coordinate s in [-1, 1].

An element of reference length L maps s to the chapter's axial coordinate
xi = s L / 2 in [-L/2, L/2], so ``int f dxi = L/2 * sum_k w_k f(s_k)``.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ._validate import positive_int

__all__ = ["gauss", "gauss_for_order"]


@lru_cache(maxsize=None)
def _gauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    s, w = np.polynomial.legendre.leggauss(n)
    s.setflags(write=False)
    w.setflags(write=False)
    return s, w


def gauss(n_points: int) -> tuple[np.ndarray, np.ndarray]:
    """Points and weights of the ``n_points`` Gauss-Legendre rule on [-1, 1] (read-only arrays)."""
    return _gauss(positive_int("n_points", n_points))


def gauss_for_order(order: int) -> tuple[np.ndarray, np.ndarray]:
    """The smallest Gauss rule that integrates polynomials of degree ``order`` exactly.

    The chapter (end of Sect. 3.5) speaks of integration *orders*: order 5 is
    the 3-point rule, order 9 the 5-point rule.
    """
    order = positive_int("order", order)
    return gauss((order + 2) // 2)
