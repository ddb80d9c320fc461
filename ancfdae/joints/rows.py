"""Constraint rows of the form every joint of this package has, and the affine maps they are built from.

A joint between the bodies' coordinates (ANCF nodal vectors, rigid bodies in natural coordinates) places its
points and frame vectors *affinely* in ``q`` (:class:`ancfdae.attachment.Attachment`), so each of its
equations is at most quadratic in ``q``, with time only in the part that is linear in ``q``::

    g_i(t, q) = 1/2 q^T A_i q + b_i . q + c_i + sum_j phi_j(t) (B_j q + c_j)_i                     (R)

``A_i`` constant and symmetric, ``phi_j`` scalar functions of time with their first two derivatives (a
prescribed motion). Then ``G = dg/dq`` is affine in ``q``, ``d(G^T lam)/dq = sum_i lam_i A_i`` does not depend
on ``q``, and the energy-momentum step's midpoint Jacobian is an exact discrete derivative. :class:`Rows`
holds (R) for a group of rows in the coordinates of a :class:`~ancfdae.System`; :class:`Affine` is a point or
a frame vector ``X q + x0`` in those coordinates, and :func:`dot` the quadratic row ``(X q + x0).(Y q + y0)``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp

__all__ = ["Affine", "Rows", "TimedTerm", "dot", "linear"]


@dataclass(frozen=True)
class Affine:
    """A vector ``X q + x0`` (a point or a frame vector) in the system's coordinates.

    Attributes
    ----------
    X : scipy.sparse.csr_matrix, shape (dim, n)
    x0 : ndarray, shape (dim,)
    """

    X: sp.csr_matrix
    x0: np.ndarray

    def __sub__(self, other: Affine) -> Affine:
        return Affine(sp.csr_matrix(self.X - other.X), self.x0 - other.x0)

    def value(self, q: np.ndarray) -> np.ndarray:
        """The vector at ``q``."""
        return self.X @ q + self.x0

    def rotated(self) -> Affine:
        """The vector turned by +90 degrees (planar only): ``(-y, x)``, affine as well."""
        J = sp.csr_matrix(np.array([[0.0, -1.0], [1.0, 0.0]]))
        return Affine(sp.csr_matrix(J @ self.X), J @ self.x0)

    @staticmethod
    def combination(coef: np.ndarray, vectors: list[Affine]) -> Affine:
        """``sum_k coef[k] vectors[k]`` (constant coefficients)."""
        X = sum(c * o.X for c, o in zip(coef, vectors))
        return Affine(sp.csr_matrix(X), sum(c * o.x0 for c, o in zip(coef, vectors)))


@dataclass(frozen=True)
class TimedTerm:
    """``phi(t) (B q + c)``: the rheonomic part of rows (R).

    Attributes
    ----------
    phi : callable
        ``phi(t) -> (phi, dphi/dt, d2phi/dt2)`` (floats).
    B : scipy.sparse.csr_matrix, shape (m, n)
    c : ndarray, shape (m,)
    """

    phi: Callable[[float], tuple[float, float, float]]
    B: sp.csr_matrix
    c: np.ndarray


@dataclass
class Rows:
    """A group of constraint rows (R) in the system's ``n`` coordinates.

    Attributes
    ----------
    n : int
        Number of coordinates.
    labels : list of str
        One per row, ``"joint[k]"``.
    b : list of sparse row vectors (1, n); c : list of float; A : list of sparse (n, n) or None
        The scleronomic part of each row.
    timed : list of (row indices, TimedTerm)
        Rheonomic terms acting on some of the rows.
    """

    n: int
    labels: list = field(default_factory=list)
    b: list = field(default_factory=list)
    c: list = field(default_factory=list)
    A: list = field(default_factory=list)
    timed: list = field(default_factory=list)

    @property
    def m(self) -> int:
        """Number of rows."""
        return len(self.labels)

    def add(self, label: str, b, c: float, A=None) -> int:
        """Append the row ``1/2 q^T A q + b.q + c``; return its index."""
        self.labels.append(label)
        self.b.append(sp.csr_matrix(b, shape=(1, self.n)))
        self.c.append(float(c))
        self.A.append(None if A is None else sp.csr_matrix(A))
        return len(self.labels) - 1

    def add_timed(self, rows: list[int], term: TimedTerm) -> None:
        """Add ``phi(t) (B q + c)`` to the rows ``rows`` (``B`` with one row per entry of ``rows``)."""
        self.timed.append((list(rows), term))

    def extend(self, other: Rows) -> None:
        """Append the rows of ``other`` (the same coordinates)."""
        base = self.m
        self.labels += other.labels
        self.b += other.b
        self.c += other.c
        self.A += other.A
        self.timed += [([base + i for i in rows], term) for rows, term in other.timed]


def linear(rows: Rows, label: str, u: Affine) -> list[int]:
    """Append the rows ``u(q) = X q + x0 = 0`` (one per component); return their indices."""
    X = sp.csr_matrix(u.X)
    return [rows.add(f"{label}[{k}]" if X.shape[0] > 1 else label, X[k], u.x0[k]) for k in range(X.shape[0])]


def dot(rows: Rows, label: str, u: Affine, w: Affine, c: float = 0.0) -> int:
    """Append the row ``u(q).w(q) + c``: ``A = X^T Y + Y^T X``, ``b = X^T y0 + Y^T x0``."""
    X, Y = sp.csr_matrix(u.X), sp.csr_matrix(w.X)
    A = sp.csr_matrix(X.T @ Y + Y.T @ X)
    A.eliminate_zeros()
    b = (X.T @ w.x0 + Y.T @ u.x0).reshape(1, -1)
    return rows.add(label, b, float(u.x0 @ w.x0) + c, A if A.nnz else None)
