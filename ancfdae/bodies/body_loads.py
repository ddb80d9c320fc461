"""The loads of a rigid body as generalised forces on its natural coordinates ``q = (x, d_1, .., d_dim)``.

A force ``F`` at the body-fixed point ``X`` does the virtual work ``F . delta r(X) = F . S(X) delta q`` with
``S(X) = [1, X_1, .., X_dim] (x) I_dim``: its generalised force ``S(X)^T F`` is constant, exactly as a
force at a point of a beam (:mod:`ancfdae.loads`). Gravity is the force ``m g`` at the centre of mass.

A moment ``M`` works through the virtual rotation of the frame, which for orthonormal directors is
``delta phi = 1/2 sum_k d_k x delta d_k`` (the same formula as the cross-section frame of a beam,
chapter Sect. 2.2): ``delta W = sum_k (1/2 M x d_k) . delta d_k``. The generalised force is *linear* in
the directors, ``f = C(M) q`` with the constant ``C(M) = 1/2 diag(0, W, .., W)``, ``W v = M x v``
(``W = M [[0, -1], [1, 0]]`` in 2D), so its tangent is the constant ``C(M)`` itself.
"""
from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from .._validate import finite_vector
from ..loads import DistributedLoad, Gravity, PointForce, PointMoment

__all__ = ["BodyLoads", "point_map"]


def point_map(point: np.ndarray) -> np.ndarray:
    """Dense ``S(X)`` (dim, dim (dim + 1)) with ``r(X) = S(X) q``."""
    dim = point.shape[0]
    return np.kron(np.concatenate(([1.0], point)), np.eye(dim))


def _skew(moment: np.ndarray, dim: int) -> np.ndarray:
    """``W`` with ``W v = M x v`` in the plane (scalar M about e_z) or in space."""
    if dim == 2:
        return moment[0] * np.array([[0.0, -1.0], [1.0, 0.0]])
    m1, m2, m3 = moment
    return np.array([[0.0, -m3, m2], [m3, 0.0, -m1], [-m2, m1, 0.0]])


class BodyLoads:
    """A rigid body's loads, built once.

    Parameters
    ----------
    loads : sequence
        :class:`~ancfdae.loads.Gravity`; :class:`~ancfdae.loads.PointForce` and
        :class:`~ancfdae.loads.PointMoment` with ``node=0`` (a rigid body's one node: a force acts at the
        centre of mass); or a pair ``(PointForce, point)`` for a force at the body-fixed ``point``.
    dim : int
    mass : float
    com : ndarray (dim,)

    Attributes
    ----------
    gravity : ndarray (n_dof,)
        The generalised force of gravity (its work is the potential).
    forces : list of (time function, ndarray (n_dof,))
    moments : list of (time function, ndarray (n_dof, n_dof))
        ``C(M)`` of every moment.
    """

    def __init__(self, loads: Iterable, dim: int, mass: float, com: np.ndarray) -> None:
        n = dim * (dim + 1)
        self.gravity = np.zeros(n)
        self.forces, self.moments = [], []
        for entry in loads:
            load, point = entry if isinstance(entry, tuple) and len(entry) == 2 else (entry, None)
            if isinstance(load, Gravity):
                if point is not None:
                    raise ValueError(f"gravity acts at the centre of mass; give it without a point, got {entry!r}.")
                if load.g.shape[0] != dim:
                    raise ValueError(f"`g` of gravity must have {dim} components for a {dim}D body, "
                                     f"got {load.g.tolist()}.")
                self.gravity += point_map(com).T @ (mass * load.g)
            elif isinstance(load, (PointForce, PointMoment)):
                if load.node not in (0, -1) or load.s is not None:
                    raise ValueError(f"a load on a rigid body names node=0 (its centre of mass) or comes as a pair "
                                     f"(PointForce, body-fixed point); got node={load.node!r}, s={load.s!r}.")
                if isinstance(load, PointMoment):
                    if point is not None:
                        raise ValueError(f"a moment on a rigid body acts on the whole body; give it without a "
                                         f"point, got {entry!r}.")
                    m = load.moment
                    if m.shape[0] != (1 if dim == 2 else 3):
                        raise ValueError(f"`moment` on a {dim}D body must be "
                                         f"{'a scalar' if dim == 2 else 'a 3-vector'}, got {m.tolist()}.")
                    C = np.zeros((n, n))
                    C[dim:, dim:] = 0.5 * np.kron(np.eye(dim), _skew(m, dim))
                    self.moments.append((load.time, C))
                else:
                    if load.force.shape[0] != dim:
                        raise ValueError(f"`force` on a {dim}D body must have {dim} components, "
                                         f"got {load.force.tolist()}.")
                    X = com if point is None else finite_vector("point", point, dim)
                    self.forces.append((load.time, point_map(X).T @ load.force))
            elif isinstance(load, DistributedLoad):
                raise ValueError("a DistributedLoad acts along a beam's axis, not on a rigid body; give its "
                                 "resultant as a PointForce.")
            else:
                raise TypeError(f"`loads` of a rigid body must be Gravity, PointForce or PointMoment (or a pair "
                                f"(PointForce, point)), got {entry!r}.")

    def nonconservative(self, t: float, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every load but gravity: ``(f_nc(t, q), df_nc/dq)`` (dense; the tangent is constant in q)."""
        n = q.shape[0]
        f = np.zeros(n)
        C = np.zeros((n, n))
        for time, vec in self.forces:
            f += time(t) * vec
        for time, Cm in self.moments:
            C += time(t) * Cm
        if self.moments:
            f += C @ q
        return f, C
