"""Coefficients of the Hamiltonian boundary value method HBVM(k, s) for ``M q'' = F(t, q)``.

HBVM(k, s) (Brugnano, Iavernaro and Trigiante, JNAIAM 5:17, 2010; BIT 51:91, 2011), equivalently the
energy-preserving variant of the s-stage Gauss collocation (Hairer, JNAIAM 5:73, 2010), seeks the
acceleration over one step ``[t0, t0 + h]`` as a polynomial of degree ``s - 1`` in the shifted,
orthonormal Legendre basis ``P_j(c)`` on ``[0, 1]`` (``int_0^1 P_i P_j dc = delta_ij``; ``P_0 = 1``,
``P_1 = sqrt(3) (2c - 1)``), and projects the force onto that basis with a ``k``-point Gauss rule
``(c_l, b_l)`` (the *silent stages*, ``k >= s``). With ``Y_j = h^2 gamma_j`` (the Legendre
coefficients of the acceleration, scaled to displacements) the step reads::

    sigma(c_l h) = q0 + c_l h v0 + sum_j Wq[l, j] Y_j                      (position at node l)
    h sigma'(c_l h) = h v0 + sum_j Wd[l, j] Y_j                            (velocity at node l)
    M Y_i / h^2 = sum_l BP[i, l] F(t0 + c_l h, sigma(c_l h)),   i = 0..s-1
    q1 = q0 + h v0 + sum_j q_end[j] Y_j,   h v1 = h v0 + Y_0

with ``I_j(c) = int_0^c P_j``, ``X_ij = int_0^1 P_i I_j`` (the matrix ``X_s`` of Brugnano et al.:
``X_00 = 1/2``, ``X_{j+1,j} = -X_{j,j+1} = 1 / (2 sqrt(4 (j+1)^2 - 1))``), ``Wq = I X``, ``Wd = P X``,
``BP[i, l] = b_l P_i(c_l)``, ``q_end = X[0]``. The position ``sigma`` is a polynomial of degree ``s``
and its derivative ``sigma'`` is the projection of the velocity polynomial onto degree ``s - 1``.
Order ``2s``; for ``F = -grad P`` the energy ``v^T M v / 2 + P`` is kept exactly whenever the
``k``-point rule integrates ``grad P(sigma) . sigma'`` exactly, i.e. for a polynomial ``P`` of
degree ``nu <= 2k / s``, and up to ``O(h^(2k+1))`` per step otherwise. ``k = s`` is the Gauss
method itself.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.polynomial import Polynomial
from numpy.polynomial import legendre as leg

from ancfdae._validate import positive_int

__all__ = ["HBVMCoefficients", "hbvm_coefficients", "legendre01"]


def legendre01(j: int) -> Polynomial:
    """The orthonormal shifted Legendre polynomial ``P_j`` on ``[0, 1]`` in the power basis."""
    return leg.Legendre.basis(j, domain=[0.0, 1.0]).convert(kind=Polynomial) * np.sqrt(2 * j + 1)


@dataclass(frozen=True)
class HBVMCoefficients:
    """The matrices of HBVM(k, s) (module docstring); all arrays read-only.

    Attributes
    ----------
    k, s : int
        Silent stages (Gauss nodes) and fundamental stages (polynomial degree of the position).
    c, b : ndarray, shape (k,)
        Gauss nodes and weights on ``[0, 1]``.
    X : ndarray, shape (s, s)
        ``X_ij = int_0^1 P_i I_j``.
    Wq, Wd : ndarray, shape (k, s)
        Position and (``h`` times) velocity of the polynomial at the nodes, per unknown ``Y_j``.
    BP : ndarray, shape (s, k)
        ``b_l P_i(c_l)``: the discrete projection of the node forces.
    C : ndarray, shape (s, s, k)
        ``C[i, m, l] = BP[i, l] Wq[l, m]``: the weight of the node-``l`` stiffness in the exact
        Jacobian block ``(i, m)``; ``C.sum(axis=2) = X @ X``.
    q_end : ndarray, shape (s,)
        ``q1 = q0 + h v0 + q_end . Y``.
    predictor : ndarray, shape (s, s)
        ``Y_next = Y_prev @ predictor.T``: the previous step's acceleration polynomial continued
        over the next step of the same size and projected (exact for a polynomial of degree ``s - 1``).
    mid : ndarray, shape (s,)
        ``sigma(h/2) = q0 + h v0 / 2 + mid . Y``.
    """

    k: int
    s: int
    c: np.ndarray
    b: np.ndarray
    X: np.ndarray
    Wq: np.ndarray
    Wd: np.ndarray
    BP: np.ndarray
    C: np.ndarray
    q_end: np.ndarray
    predictor: np.ndarray
    mid: np.ndarray


@lru_cache(maxsize=None)
def hbvm_coefficients(k: int, s: int = 2) -> HBVMCoefficients:
    """The coefficients of HBVM(k, s), ``k >= s >= 1``, from exact polynomial integrals.

    Parameters
    ----------
    k : int
        Silent stages (Gauss nodes).
    s : int
        Fundamental stages (order ``2 s``).

    Returns
    -------
    HBVMCoefficients
    """
    s = positive_int("s", s)
    k = positive_int("k", k)
    if k < s:
        raise ValueError(f"`k` (silent stages) must be >= s = {s}, got {k}.")
    x, w = leg.leggauss(k)
    c, b = (x + 1.0) / 2.0, w / 2.0
    polys = [legendre01(j) for j in range(s)]
    ints = [p.integ() for p in polys]                       # I_j(c) = int_0^c P_j, zero at 0
    P = np.array([[p(cl) for p in polys] for cl in c])
    I = np.array([[q(cl) for q in ints] for cl in c])
    X = np.array([[(polys[i] * ints[j]).integ()(1.0) for j in range(s)] for i in range(s)])
    X[np.abs(X) < 1e-15] = 0.0                              # exact zeros of the tridiagonal X_s
    Wq, Wd = I @ X, P @ X
    BP = (b[:, None] * P).T
    C = np.einsum("il,lm->iml", BP, Wq)
    # the previous step's polynomial at 1 + c, projected onto P_i with an exact (s-point) Gauss rule
    xg, wg = leg.leggauss(s)
    cg, bg = (xg + 1.0) / 2.0, wg / 2.0
    Pg = np.array([[p(x) for p in polys] for x in cg])
    Pg1 = np.array([[p(1.0 + x) for p in polys] for x in cg])
    predictor = (bg[:, None] * Pg).T @ Pg1
    mid = np.array([q(0.5) for q in ints]) @ X
    out = HBVMCoefficients(k, s, c, b, X, Wq, Wd, BP, C, X[0].copy(), predictor, mid)
    for name in ("c", "b", "X", "Wq", "Wd", "BP", "C", "q_end", "predictor", "mid"):
        getattr(out, name).setflags(write=False)
    return out
