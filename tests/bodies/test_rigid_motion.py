"""Motions of rigid bodies in natural coordinates: the torque-free symmetric top and a physical pendulum.

Integrated with the constrained midpoint scheme of ``support.constrained_midpoint`` (Gonzalez 1999,
Betsch & Steinmann 2001): the body's own orthonormality constraints through its ``"constraints"``
capability, a pin built in the test, nothing of the package's integrators.
"""
import numpy as np
import pytest
from scipy.linalg import expm

from ancfdae import Gravity
from ancfdae.bodies import RigidBody
from support import constrained_midpoint as cm

A_TOP, C_TOP = 0.5, 0.8                 # symmetric top: diametral and axial moments about the centre of mass
OMEGA_BODY = np.array([1.2, 0.0, 5.0])  # initial angular velocity in body axes


def _skew(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def _top(R0):
    return RigidBody(2.0, [A_TOP, A_TOP, C_TOP], [0.3, -0.2, 0.1], R0, velocity=[0.1, 0.2, -0.3],
                     angular_velocity=R0 @ OMEGA_BODY)


def _top_closed_form(R0, t):
    """``R(t) = exp(t |L|/A [l]) R0 exp(t psi_dot [e3])``: precession about the constant angular momentum
    ``L`` at ``|L| / A`` and the spin relative to it ``psi_dot = omega_3 (A - C) / A``."""
    L = R0 @ (np.array([A_TOP, A_TOP, C_TOP]) * OMEGA_BODY)
    psi_dot = OMEGA_BODY[2] * (A_TOP - C_TOP) / A_TOP
    return expm(t / A_TOP * _skew(L)) @ R0 @ expm(t * psi_dot * _skew([0.0, 0.0, 1.0]))


def _angular_momentum(body, q, v):
    """``L = int r x r_dot dm = sum_ab E_ab q_a x v_b`` about the origin (blocks of the natural coordinates)."""
    Qb, Vb = q.reshape(4, 3), v.reshape(4, 3)
    return sum(body.euler[a, b] * np.cross(Qb[a], Vb[b]) for a in range(4) for b in range(4))


def test_free_symmetric_top_follows_the_closed_form_and_keeps_its_frame():
    # Catches: a wrong Euler tensor (the precession and spin rates are those of A and C), initial director
    # velocities not omega x d, orthonormality drifting (constraint forces or G wrong).
    R0 = expm(_skew([0.3, -0.5, 0.2]))
    body = _top(R0)
    cons = cm.Constraints(body)
    t_end, errors = 1.0, []
    for h in (0.01, 0.005):
        t, Q, V, _ = cm.run(body, cons, t_end, h)
        R = body.orientation(Q)
        errors.append(max(np.abs(R[i] - _top_closed_form(R0, t[i])).max() for i in range(0, t.size, 10)))
        drift = np.abs(np.array([body.constraints(0.0, q) for q in Q])).max()
        assert drift < 1e-14                                       # orthonormal to round-off
        E = np.array([body.energy(0.0, q, v).total for q, v in zip(Q, V)])
        assert np.abs(E - E[0]).max() < 1e-13 * E[0]
        L = np.array([_angular_momentum(body, q, v) for q, v in zip(Q, V)])
        assert np.abs(L - L[0]).max() < 1e-12 * np.linalg.norm(L[0])
        assert np.allclose(Q[-1, :3], [0.3, -0.2, 0.1] + t_end * np.array([0.1, 0.2, -0.3]), rtol=0, atol=1e-12)
    order = np.log2(errors[0] / errors[1])
    assert errors[1] < 2e-3 and 1.9 < order < 2.1, (errors, order)   # the midpoint rule's second order
    omega = body.angular_velocity(Q[-1], V[-1])
    assert np.linalg.norm(omega - _top_closed_form(R0, t_end) @ body.orientation(Q[-1]).T @ omega) < 1e-2


def _pendulum(theta0, d=0.4, m=1.5, Izz=0.05, g=9.81):
    """A planar body hanging from a pin at the origin; body point ``(0, d)`` above the centre of mass."""
    Xp = np.array([0.0, d])
    R = np.array([[np.cos(theta0), -np.sin(theta0)], [np.sin(theta0), np.cos(theta0)]])
    body = RigidBody(m, Izz, -R @ Xp, theta0, loads=[Gravity([0.0, -g])])
    P = body.attachment(tuple(Xp)).position.toarray()
    pin = (lambda q: P @ q, lambda q: P, lambda lam: np.zeros((6, 6)))   # linear: r(X_p) = 0
    return body, cm.Constraints(body, [pin]), 2 * np.pi * np.sqrt((Izz + m * d * d) / (m * g * d))


def test_rigid_pendulum_has_the_small_amplitude_period():
    # Catches: gravity at the reference point instead of the centre of mass, a missing m X_c coupling in M
    # (either changes the period by percents), and a pin force that does work (energy drift).
    theta0 = 0.05
    body, cons, T0 = _pendulum(theta0)
    h = 4e-3
    t, Q, V, Lam = cm.run(body, cons, 2.3 * T0, h)
    R = body.orientation(Q)
    theta = np.arctan2(R[:, 1, 0], R[:, 0, 0])
    up = np.flatnonzero((theta[:-1] < 0) & (theta[1:] >= 0))          # upward zero crossings
    tc = t[up] - theta[up] * h / (theta[up + 1] - theta[up])
    period = np.diff(tc).mean()
    # The finite amplitude lengthens the period by theta0^2 / 16 (O(theta0^4) = 2e-8 left); the midpoint rule
    # turns a linear oscillation of frequency w by 2 atan(w h / 2) per step (1e-5 longer period at this h).
    wh = 2 * np.pi / T0 * h
    assert period == pytest.approx(T0 * (1 + theta0 ** 2 / 16) * (wh / 2) / np.arctan(wh / 2), rel=1e-6)
    assert abs(theta).max() == pytest.approx(theta0, rel=1e-4)
    E = np.array([body.energy(0.0, q, v).total for q, v in zip(Q, V)])
    assert np.abs(E - E[0]).max() < 1e-12 * 1.5 * 9.81 * 0.4
    assert np.abs(np.array([cons.g(q) for q in Q])).max() < 1e-14
    # The pin carries the weight (the constraint force on the body is -G^T lambda = -lambda: lambda_y = -m g,
    # up to the small centripetal and tangential parts, which average to 2e-3 of it).
    assert -Lam[1:, 4].mean() == pytest.approx(1.5 * 9.81, rel=2e-3)
