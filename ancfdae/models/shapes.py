"""Shape functions along the beam axis, vectorised over elements and points.

All functions take the normalised coordinate ``s`` in [-1, 1] (shape
``(n_pts,)``) and the element reference lengths ``L`` (shape ``(n_el,)``) and
return arrays of shape ``(n_el, n_pts, n_shape)``; derivatives are with respect
to the chapter's dimensional axial coordinate ``xi = s L / 2``.
"""
from __future__ import annotations

import numpy as np

__all__ = ["hermite", "linear", "quadratic"]


def _grid(s, L):
    s = np.asarray(s, dtype=float)[None, :, None]
    L = np.asarray(L, dtype=float)[:, None, None]
    return s, L


def hermite(s, L):
    """Cubic Hermite functions of chapter Eq. 60 and their first two xi-derivatives.

    Order ``(S1, S2, S3, S4)`` multiplies ``(r_A, r'_A, r_B, r'_B)``.

    Returns
    -------
    N, dN, ddN : ndarray, shape (n_el, n_pts, 4)

    Notes
    -----
    Evaluated once per distinct length and gathered (the same bits): a mesh of 10^6 equal
    elements otherwise spends ~40 % of its construction in this function's temporaries.
    """
    L = np.asarray(L, dtype=float)
    if L.ndim == 1 and L.size > 64:
        u, inv = np.unique(L, return_inverse=True)
        if u.size * 4 <= L.size:
            return tuple(a[inv] for a in hermite(s, u))
    s, L = _grid(s, L)
    one = np.ones_like(s) * np.ones_like(L)
    N = np.concatenate([
        (0.5 - 0.75 * s + 0.25 * s**3) * one,
        L / 8 * (1 - s - s**2 + s**3),
        (0.5 + 0.75 * s - 0.25 * s**3) * one,
        L / 8 * (-1 - s + s**2 + s**3),
    ], axis=-1)
    d = 2.0 / L  # ds/dxi
    dN = np.concatenate([
        (-0.75 + 0.75 * s**2) * d,
        L / 8 * (-1 - 2 * s + 3 * s**2) * d,
        (0.75 - 0.75 * s**2) * d,
        L / 8 * (-1 + 2 * s + 3 * s**2) * d,
    ], axis=-1)
    ddN = np.concatenate([
        1.5 * s * d**2,
        L / 8 * (-2 + 6 * s) * d**2,
        -1.5 * s * d**2,
        L / 8 * (2 + 6 * s) * d**2,
    ], axis=-1)
    return N, dN, ddN


def linear(s, L):
    """Linear Lagrange functions (chapter Eqs. 102, 104, 106), order ``(A, B)``.

    Returns
    -------
    N, dN : ndarray, shape (n_el, n_pts, 2)
    """
    s, L = _grid(s, L)
    one = np.ones_like(L)
    N = np.concatenate([(0.5 - 0.5 * s) * one, (0.5 + 0.5 * s) * one], axis=-1)
    dN = np.concatenate([-1.0 / L * np.ones_like(s), 1.0 / L * np.ones_like(s)], axis=-1)
    return N, dN


def quadratic(s, L):
    """Quadratic Lagrange functions (chapter Eqs. 105, 107), order ``(A, B, C)``.

    ``A`` at s = -1, ``B`` at s = +1, ``C`` (the middle node) at s = 0.

    Returns
    -------
    N, dN : ndarray, shape (n_el, n_pts, 3)
    """
    s, L = _grid(s, L)
    one = np.ones_like(L)
    N = np.concatenate([0.5 * s * (s - 1) * one, 0.5 * s * (s + 1) * one, (1 - s**2) * one], axis=-1)
    d = 2.0 / L
    dN = np.concatenate([(s - 0.5) * d, (s + 0.5) * d, -2 * s * d], axis=-1)
    return N, dN
