"""The mass distribution of a rigid body as its Euler tensor, and the box of equal inertia.

A rigid body in natural coordinates (Betsch & Steinmann 2001) places its material point with body-fixed
coordinates ``X`` (relative to the body's reference point, along its directors) at
``r(X) = x + sum_k X_k d_k``: linear in the coordinates ``q = (x, d_1, ..., d_dim)``. Its kinetic energy
``T = 1/2 int rho |r_dot|^2 dV`` is then ``1/2 q_dot^T M q_dot`` with the *constant* mass matrix
``M = E (x) I_dim``, where ``E`` is the (dim+1) x (dim+1) matrix of the mass moments about the reference
point::

    E = [[m,      m X_c^T],
         [m X_c,  J      ]],     J = int rho X X^T dV = m X_c X_c^T + J_c,

``X_c`` the centre of mass and ``J_c`` the Euler tensor about it. The usual way to give the mass
distribution is the inertia tensor ``Theta_c`` about the centre of mass (body axes); in 3D the two are
related by ``J_c = 1/2 tr(Theta_c) I - Theta_c``. In 2D only the polar moment ``I_zz = tr(J_c)`` is given;
the kinetic energy of an orthonormal pair of directors depends on nothing else
(``T_rot = 1/2 (J_11 + J_22) omega^2``), so ``J_c = I_zz / 2 I`` is used.
"""
from __future__ import annotations

import numpy as np

from .._validate import finite_vector, positive

__all__ = ["euler_matrix", "inertia_tensor", "equivalent_box"]


def inertia_tensor(inertia, dim: int) -> np.ndarray:
    """The inertia argument of a rigid body checked: a float (2D, ``I_zz``), or 3 principal moments or a
    symmetric positive definite 3x3 tensor (3D) that satisfies the triangle inequalities of a real body
    (equality: a lamina such as a thin disk).

    Returns
    -------
    ndarray
        ``(1, 1)`` in 2D, ``(3, 3)`` in 3D: the inertia tensor about the centre of mass in body axes.
    """
    if dim == 2:
        try:
            value = float(np.asarray(inertia, dtype=float).reshape(()))
        except (TypeError, ValueError):
            raise ValueError(f"`inertia` of a planar body must be the polar moment I_zz about the centre of "
                             f"mass (a positive number), got {inertia!r}.") from None
        return np.array([[positive("inertia", value)]])
    try:
        arr = np.asarray(inertia, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"`inertia` must be 3 principal moments or a 3x3 tensor, got {inertia!r}.") from None
    if arr.shape == (3,):
        arr = np.diag(arr)
    if arr.shape != (3, 3) or not np.all(np.isfinite(arr)):
        raise ValueError(f"`inertia` of a spatial body must be 3 principal moments or a finite 3x3 tensor about "
                         f"the centre of mass, got shape {arr.shape}.")
    if not np.allclose(arr, arr.T, rtol=1e-12, atol=0.0):
        raise ValueError(f"`inertia` must be symmetric, got {arr.tolist()}.")
    principal = np.linalg.eigvalsh(arr)
    # J_c = tr/2 I - Theta must be positive semi-definite: no principal moment above the sum of the others.
    # Equality is a lamina (a thin disk: m r^2/2 = 2 m r^2/4): M is then singular along the director normal
    # to it, but positive on the rigid motions, so the constrained equations stay regular.
    if principal[0] <= 0 or principal[2] > (principal[0] + principal[1]) * (1 + 1e-12):
        raise ValueError(f"`inertia` must be the tensor of a real body: positive principal moments, none "
                         f"larger than the sum of the other two; got principal moments {principal.tolist()}.")
    return arr


def euler_matrix(mass: float, com, inertia: np.ndarray, dim: int) -> np.ndarray:
    """The (dim+1) x (dim+1) matrix ``E`` of the module docstring (mass matrix ``E (x) I_dim``).

    Parameters
    ----------
    mass : float
        Positive.
    com : array_like, shape (dim,)
        Centre of mass in body coordinates (relative to the reference point).
    inertia : ndarray
        The checked tensor of :func:`inertia_tensor`.
    dim : int
    """
    mass = positive("mass", mass)
    Xc = finite_vector("com", com, dim)
    Jc = 0.5 * inertia[0, 0] * np.eye(2) if dim == 2 else 0.5 * np.trace(inertia) * np.eye(3) - inertia
    E = np.empty((dim + 1, dim + 1))
    E[0, 0] = mass
    E[0, 1:] = E[1:, 0] = mass * Xc
    E[1:, 1:] = mass * np.outer(Xc, Xc) + Jc
    return E


def equivalent_box(mass: float, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Half side lengths and axes (columns, body coordinates) of the homogeneous box of equal mass and inertia.

    A box of sides ``a_k`` has ``J_c = m diag(a_k^2) / 12``, so ``a_k = sqrt(12 lambda_k(J_c) / m)`` along the
    eigenvectors of ``J_c``; a planar body (only ``I_zz`` known) is drawn as the square of its polar moment.
    """
    if inertia.shape == (1, 1):
        half = 0.5 * np.sqrt(6.0 * inertia[0, 0] / mass)
        return np.array([half, half]), np.eye(2)
    Jc = 0.5 * np.trace(inertia) * np.eye(3) - inertia
    lam, axes = np.linalg.eigh(Jc)
    return 0.5 * np.sqrt(12.0 * np.maximum(lam, 0.0) / mass), axes
