"""A rigid body in natural coordinates (Betsch & Steinmann 2001): a Model with a constant mass matrix.

The coordinates are the position ``x`` of a reference point and the body's directors, the columns of its
rotation matrix: ``q = (x, d_1, .., d_dim)``, ``dim (dim + 1)`` numbers (6 in the plane, 12 in space), in
the same vector space as ANCF's nodal positions and slopes (chapter Sects. 3-4): no rotation parameters.
Every body-fixed point is linear in ``q`` (``r(X) = x + sum_k X_k d_k``), so the kinetic energy has the
constant mass matrix ``E (x) I`` of :mod:`.inertia`, the equations of motion are ``M a - f_ext(t, q) +
G^T lambda = 0`` with the orthonormality constraints ``g = 0`` of :mod:`.orthonormality` (declared as
the ``"constraints"`` capability, ``G^T lambda`` not in :meth:`RigidBody.residual`), and every joint to
a body-fixed point or director is at most quadratic in ``q``.
"""
from __future__ import annotations

import numbers
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

from .._validate import check_shape, finite_vector
from ..attachment import Attachment
from ..loads import DistributedLoad, Gravity, PointForce, PointMoment
from ..problem import Energy, JacobianBlocks
from .body_loads import BodyLoads, point_map
from .inertia import euler_matrix, inertia_tensor
from .orthonormality import Orthonormality

__all__ = ["RigidBody", "MODEL_FORMAT"]

#: Version tag of the dict that :meth:`RigidBody.describe` returns.
MODEL_FORMAT = "ancfdae.RigidBody/1"

_LOADS = (Gravity, PointForce, PointMoment, DistributedLoad)


def _rotation(name: str, value, dim: int) -> np.ndarray:
    """A proper rotation matrix (columns: the directors); a planar one may be given as an angle."""
    if dim == 2 and np.ndim(value) == 0:
        try:
            a = float(value)
        except (TypeError, ValueError):
            raise ValueError(f"`{name}` must be an angle or a 2x2 rotation matrix, got {value!r}.") from None
        return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    R = np.asarray(value, dtype=float)
    if R.shape != (dim, dim) or not np.all(np.isfinite(R)):
        raise ValueError(f"`{name}` must be a finite {dim}x{dim} rotation matrix (columns: the body axes in "
                         f"global coordinates), got shape {R.shape}.")
    err = float(np.max(np.abs(R.T @ R - np.eye(dim))))
    if err > 1e-10 or np.linalg.det(R) <= 0:
        raise ValueError(f"`{name}` must be a proper rotation matrix (R^T R = I to 1e-10, det R = +1), got "
                         f"max|R^T R - I| = {err:.3g}, det R = {np.linalg.det(R):.6g}.")
    return R


class RigidBody:
    """A rigid body in natural coordinates: position of a reference point and its directors.

    Parameters
    ----------
    mass : float
        Positive.
    inertia : float or array_like
        About the centre of mass, in body axes: the polar moment ``I_zz`` (2D); 3 principal moments or a
        3x3 tensor (3D), which must be that of a real body (see :func:`.inertia.inertia_tensor`).
    position : array_like, shape (dim,)
        Initial position of the reference point; its length sets the dimension (2 or 3).
    orientation : float or array_like, optional
        Initial rotation matrix whose columns are the body axes in global coordinates (a planar body may
        give its angle); default the identity.
    com : array_like, shape (dim,), optional
        Centre of mass in body coordinates, relative to the reference point; default the reference point.
    velocity : array_like, shape (dim,), optional
        Initial velocity of the reference point; default zero.
    angular_velocity : float or array_like, optional
        Initial angular velocity in global coordinates: a scalar about e_z (2D) or a 3-vector; default zero.
    loads : load or sequence, optional
        :class:`~ancfdae.loads.Gravity`; :class:`~ancfdae.loads.PointForce` and
        :class:`~ancfdae.loads.PointMoment` with ``node=0`` (the force at the centre of mass); a pair
        ``(PointForce, point)`` for a force at a body-fixed point. Time functions as on beams.
    name : str, optional
        For messages and results.

    Notes
    -----
    A Model with the capabilities ``"residual_jacobian"``, ``"potential"`` (``P`` the potential of gravity,
    for energy-momentum schemes) and ``"constraints"`` (its orthonormality, :mod:`.orthonormality`); the
    constraint forces ``G^T lambda`` are not part of :meth:`residual`.
    """

    mass_is_constant = True
    potential_degree = 1
    #: The orthonormality rows do not depend on time and are quadratic in ``q`` (read by a System).
    rheonomic = False
    constraint_degree = 2

    def __init__(self, mass: float, inertia: float | ArrayLike, position: ArrayLike,
                 orientation: float | ArrayLike | None = None, *, com: ArrayLike | None = None,
                 velocity: ArrayLike | None = None, angular_velocity: float | ArrayLike | None = None,
                 loads: Any = (), name: str = "rigid body") -> None:
        x0 = finite_vector("position", position)
        dim = x0.shape[0]
        if dim not in (2, 3):
            raise ValueError(f"`position` must have 2 or 3 components (planar or spatial body), got {dim}.")
        self.dim, self.name = dim, str(name)
        self.n_dof = dim * (dim + 1)
        self.inertia = inertia_tensor(inertia, dim)
        self.com = np.zeros(dim) if com is None else finite_vector("com", com, dim)
        self.body_mass = float(mass)
        self.euler = euler_matrix(mass, self.com, self.inertia, dim)
        self.body_mass = float(self.euler[0, 0])
        R0 = np.eye(dim) if orientation is None else _rotation("orientation", orientation, dim)
        self.q_ref = np.concatenate((x0, R0.T.reshape(-1)))
        v_ref = np.zeros(dim) if velocity is None else finite_vector("velocity", velocity, dim)
        self.omega0 = self._omega_argument(angular_velocity)
        dR = self._spin(self.omega0) @ R0
        self._v0 = np.concatenate((v_ref, dR.T.reshape(-1)))
        self.loads = (loads,) if isinstance(loads, _LOADS) else tuple(loads or ())
        self._loads = BodyLoads(self.loads, dim, self.body_mass, self.com)
        self._ortho = Orthonormality(dim)
        self.n_constraints = self._ortho.n_constraints
        self.constraint_labels = tuple(f"{self.name}: {s}" for s in self._ortho.labels)
        n = self.n_dof
        self._M = np.kron(self.euler, np.eye(dim))
        # One full (dense) pattern for K, D and M: a 6x6 or 12x12 block, combined by its data arrays.
        self._indptr = np.arange(0, n * n + 1, n)
        self._indices = np.tile(np.arange(n), n)
        self._zero = np.zeros(n * n)

    def _omega_argument(self, value) -> np.ndarray:
        if value is None:
            return np.zeros(1 if self.dim == 2 else 3)
        if self.dim == 2:
            if isinstance(value, bool) or not isinstance(value, numbers.Real) or not np.isfinite(value):
                raise ValueError(f"`angular_velocity` of a planar body must be a finite number (about e_z), "
                                 f"got {value!r}.")
            return np.array([float(value)])
        return finite_vector("angular_velocity", value, 3)

    def _spin(self, omega: np.ndarray) -> np.ndarray:
        """``W`` with ``W v = omega x v``."""
        if self.dim == 2:
            return omega[0] * np.array([[0.0, -1.0], [1.0, 0.0]])
        w1, w2, w3 = omega
        return np.array([[0.0, -w3, w2], [w3, 0.0, -w1], [-w2, w1, 0.0]])

    def _csr(self, dense: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((dense.reshape(-1).copy(), self._indices, self._indptr), shape=(self.n_dof,) * 2)

    def _check(self, q, v=None, a=None):
        n = (self.n_dof,)
        for arg, x in (("q", q), ("v", v), ("a", a)):
            if x is not None and getattr(x, "shape", None) != n:
                check_shape(arg, x, n, f"n_dof = {self.n_dof} of {self.name}")

    # -- capabilities --------------------------------------------------------
    @property
    def capabilities(self) -> frozenset:
        """``residual_jacobian``, ``potential`` and ``constraints`` (see :data:`ancfdae.problem.CAPABILITIES`)."""
        return frozenset({"residual_jacobian", "potential", "constraints"})

    # -- the Model contract ----------------------------------------------------
    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Initial ``(q0, v0)``: the given pose and the velocities ``d_k_dot = omega x d_k``."""
        return self.q_ref.copy(), self._v0.copy()

    def mass(self, q: np.ndarray | None = None) -> sp.csr_matrix:
        """The constant mass matrix ``E (x) I_dim`` (:mod:`.inertia`)."""
        if q is not None:
            self._check(q)
        return self._csr(self._M)

    def residual(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """``r = M a - f_ext(t, q)`` (gravity, forces, moments; without ``G^T lambda``)."""
        self._check(q, v, a)
        f, _ = self._loads.nonconservative(t, q)
        return self._M @ a - f - self._loads.gravity

    def residual_parts(self) -> tuple[np.ndarray, np.ndarray, list, list]:
        """``(M, f_g, forces, moments)`` of :meth:`residual`: the dense mass matrix, gravity's generalised force,
        ``[(time, f)]`` and ``[(time, C)]`` with ``f_ext(t, q) = sum time(t) f + (sum time(t) C) q`` (copies;
        what a compiled step of a System evaluates, :mod:`ancfdae.integrators._index3_steps`)."""
        lo = self._loads
        return (self._M.copy(), lo.gravity.copy(), [(tm, f.copy()) for tm, f in lo.forces],
                [(tm, C.copy()) for tm, C in lo.moments])

    def jacobian(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> JacobianBlocks:
        """Exact ``dr/dq = -df_ext/dq`` (moments only), ``dr/dv = 0``, ``dr/da = M``, on one full pattern."""
        return self.residual_jacobian(t, q, v, a)[1]

    def residual_jacobian(self, t: float, q: np.ndarray, v: np.ndarray,
                          a: np.ndarray) -> tuple[np.ndarray, JacobianBlocks]:
        """``(residual, jacobian)`` from one evaluation of the loads."""
        self._check(q, v, a)
        f, C = self._loads.nonconservative(t, q)
        r = self._M @ a - f - self._loads.gravity
        return r, JacobianBlocks(self._csr(-C), self._csr(self._zero), self._csr(self._M), same_pattern=True)

    def energy(self, t: float, q: np.ndarray, v: np.ndarray) -> Energy:
        """Kinetic ``1/2 v^T M v``, no strain, gravity's potential (zero in the initial pose)."""
        self._check(q, v)
        return Energy(kinetic=float(0.5 * v @ (self._M @ v)), strain=0.0, potential=self.potential(t, q))

    def external_power(self, t: float, q: np.ndarray, v: np.ndarray) -> float:
        """Power of the forces and moments (gravity's work is the potential)."""
        self._check(q, v)
        return float(self._loads.nonconservative(t, q)[0] @ v)

    # -- the potential capability ------------------------------------------------
    def potential(self, t: float, q: np.ndarray) -> float:
        """Gravity's potential ``-f_g . (q - q_ref)``."""
        return -float(self._loads.gravity @ (q - self.q_ref))

    def potential_gradient(self, t: float, q: np.ndarray,
                           tangent: bool = True) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """``(-f_g, 0)``."""
        return -self._loads.gravity.copy(), (self._csr(self._zero) if tangent else None)

    def nonconservative_force(self, t: float, q: np.ndarray,
                              tangent: bool = True) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """Forces and moments ``(f_nc(t, q), df_nc/dq)``."""
        f, C = self._loads.nonconservative(t, q)
        return f, (self._csr(C) if tangent else None)

    def symmetry_generators(self) -> tuple[np.ndarray, list[sp.csr_matrix]]:
        """Translations of the reference point; rotations of the point and every director."""
        dim = self.dim
        T = np.zeros((self.n_dof, dim))
        T[:dim] = np.eye(dim)
        axes = np.eye(3) if dim == 3 else np.eye(1)
        A = [sp.csr_matrix(np.kron(np.eye(dim + 1), self._spin(w))) for w in axes]
        return T, A

    # -- the constraints capability (orthonormal directors) --------------------------
    def constraints(self, t: float, q: np.ndarray) -> np.ndarray:
        """Orthonormality ``g(q)`` of the directors (:mod:`.orthonormality`)."""
        self._check(q)
        return self._ortho.constraints(t, q)

    def constraint_jacobian(self, t: float, q: np.ndarray) -> sp.csr_matrix:
        """``G = dg/dq`` on a fixed pattern."""
        self._check(q)
        return self._ortho.constraint_jacobian(t, q)

    def constraint_force(self, t: float, q: np.ndarray, lam: np.ndarray) -> np.ndarray:
        """``G^T lambda`` without forming ``G`` (the optional fast path of the constraints capability)."""
        self._check(q)
        check_shape("lam", lam, (self.n_constraints,), f"n_constraints = {self.n_constraints}")
        return self._ortho.constraint_force(t, q, lam)

    def constraint_force_jacobian(self, t: float, q: np.ndarray, lam: np.ndarray) -> sp.csr_matrix:
        """``d(G^T lambda)/dq`` (constant in q)."""
        check_shape("lam", lam, (self.n_constraints,), f"n_constraints = {self.n_constraints}")
        return self._ortho.constraint_force_jacobian(t, q, lam)

    def constraint_quadratic_form(self) -> tuple[list, sp.csr_matrix, np.ndarray]:
        """The orthonormality rows as ``1/2 q^T A_r q + b_r . q + c_r`` with constant ``A_r, b, c`` and no time
        (:meth:`.orthonormality.Orthonormality.quadratic_form`): what a System folds into its compiled rows."""
        return self._ortho.quadratic_form()

    def constraint_rates(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(g_t, gamma)`` of ``G v + g_t = 0``, ``G a = gamma``."""
        self._check(q, v)
        return self._ortho.constraint_rates(t, q, v)

    def constraint_velocity_jacobian(self, t: float, q: np.ndarray, v: np.ndarray) -> sp.csr_matrix:
        """``Z(v) = d(G v)/dq`` on G's pattern (index-2 formulations): ``G`` is linear in ``q``, so ``Z(v) = G(v)``."""
        self._check(q, v)
        return self._ortho.constraint_jacobian(t, v)

    # -- where joints take hold -----------------------------------------------------
    def attachment(self, where: ArrayLike | None = None) -> Attachment:
        """The body-fixed point ``where`` (body coordinates; default the reference point) and the directors.

        Returns
        -------
        Attachment
            ``position = S(X)``, ``axes = (D_1, .., D_dim)`` with ``d_k = D_k q`` (:mod:`ancfdae.attachment`).
        """
        X = np.zeros(self.dim) if where is None else finite_vector("where", where, self.dim)
        n, dim = self.n_dof, self.dim
        axes = tuple(sp.csr_matrix(np.kron(np.eye(dim + 1)[k + 1], np.eye(dim))) for k in range(dim))
        label = f"{self.name} point ({', '.join(f'{c:g}' for c in X)})"
        return Attachment(position=sp.csr_matrix(point_map(X)), axes=axes, label=label)

    # -- results: pose, angular velocity and points of states ---------------------------
    def _states(self, q) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        if q.shape[-1:] != (self.n_dof,):
            raise ValueError(f"`q` must have shape (..., {self.n_dof}) (states of {self.name}), got {q.shape}.")
        return q

    def orientation(self, q: ArrayLike) -> np.ndarray:
        """Rotation matrices (columns: the directors) of one state (dim, dim) or many (n, dim, dim)."""
        q = self._states(q)
        return np.swapaxes(q[..., self.dim:].reshape(q.shape[:-1] + (self.dim, self.dim)), -1, -2)

    def angular_velocity(self, q: ArrayLike, v: ArrayLike) -> np.ndarray:
        """Angular velocity in global coordinates, ``omega = 1/2 sum_k d_k x d_k_dot`` (exact for orthonormal
        directors); a scalar per state in 2D, a 3-vector in 3D."""
        R, Rd = self.orientation(q), self.orientation(v)
        if self.dim == 2:
            return 0.5 * np.sum(R[..., 0, :] * Rd[..., 1, :] - R[..., 1, :] * Rd[..., 0, :], axis=-1)
        return 0.5 * np.sum(np.cross(R, Rd, axis=-2), axis=-1)

    def points(self, q: ArrayLike, X: ArrayLike) -> np.ndarray:
        """Positions of the body-fixed points ``X`` (n_points, dim) in the states ``q``: (..., n_points, dim).

        Also the velocities of the points when ``q`` holds velocities (the map is linear).
        """
        q = self._states(q)
        X = np.atleast_2d(np.asarray(X, dtype=float))
        if X.shape[-1] != self.dim:
            raise ValueError(f"`X` must hold body-fixed points of {self.dim} coordinates, got shape {X.shape}.")
        x = q[..., None, :self.dim]
        return x + np.einsum("pk,...kd->...pd", X, np.swapaxes(self.orientation(q), -1, -2))

    def centre_of_mass(self, q: ArrayLike) -> np.ndarray:
        """Position of the centre of mass in the states ``q``: (dim,) or (n, dim)."""
        return self.points(q, self.com[None, :])[..., 0, :]

    # -- description (result files) ---------------------------------------------------------
    def describe(self) -> dict:
        """JSON-able description: mass, inertia, centre of mass, initial pose and velocities, loads (by repr)."""
        return {"format": MODEL_FORMAT, "body": "RigidBody", "name": self.name, "dim": self.dim,
                "mass": self.body_mass, "inertia": (float(self.inertia[0, 0]) if self.dim == 2
                                                    else self.inertia.tolist()),
                "com": self.com.tolist(), "position": self.q_ref[:self.dim].tolist(),
                "orientation": self.orientation(self.q_ref).tolist(),
                "velocity": self._v0[:self.dim].tolist(),
                "angular_velocity": float(self.omega0[0]) if self.dim == 2 else self.omega0.tolist(),
                "loads": [repr(load) for load in self.loads]}

    @classmethod
    def from_description(cls, model: dict) -> RigidBody:
        """The body of a :meth:`describe` dict (e.g. ``Result.model``), without its loads.

        Raises
        ------
        ValueError
            When ``model`` is not a rigid body's description of this format.
        """
        if not isinstance(model, dict) or model.get("format") != MODEL_FORMAT:
            got = model.get("format") if isinstance(model, dict) else type(model).__name__
            raise ValueError(f"`model` must be a rigid body's description of format {MODEL_FORMAT!r}, got {got!r}.")
        return cls(model["mass"], model["inertia"], model["position"], model["orientation"], com=model["com"],
                   velocity=model["velocity"], angular_velocity=model["angular_velocity"], name=model["name"])

    def dof_labels(self) -> tuple[np.ndarray, np.ndarray]:
        """Node (0: a body has one) and coordinate name (``x``, ``y``(, ``z``), ``d1x``, ..) of each coordinate."""
        axes = "xyz"[:self.dim]
        names = list(axes) + [f"d{k + 1}{c}" for k in range(self.dim) for c in axes]
        return np.zeros(self.n_dof, dtype=int), np.array(names)
