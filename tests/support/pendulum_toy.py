"""A constrained toy: the planar double pendulum of two point masses on massless rods (quadratic g).

``q = (x1, y1, x2, y2)``, ``g = [(|r1 - p(t)|^2 - L1^2) / 2, (|r2 - r1|^2 - L2^2) / 2]`` with the pivot
``p(t) = (A sin(w t), 0)`` (``A = 0``: a fixed pivot, scleronomic); gravity ``-g e_y``. Cheap (n = 4,
m = 2), smooth and without fast modes, so convergence orders read cleanly; the rows are quadratic, so
an index-3 or a state-averaged scheme shows its true multiplier order.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae.problem import Energy, JacobianBlocks


class PointPendulum:
    """The double pendulum of point masses (see the module docstring)."""

    mass_is_constant = True
    capabilities = frozenset({"constraints", "potential"})
    n_dof, n_constraints = 4, 2
    potential_degree = 1
    constraint_degree = 2

    def __init__(self, m=(1.0, 0.5), L=(1.0, 0.7), grav=9.81, amplitude=0.0, omega=3.0):
        self.m, self.L, self.grav, self.A, self.w = m, L, grav, amplitude, omega
        self.M = sp.csr_matrix(np.diag([m[0], m[0], m[1], m[1]]))
        self.fg = np.array([0.0, -m[0] * grav, 0.0, -m[1] * grav])

    def pivot(self, t):
        """``(p, p', p'')`` of the pivot's x coordinate."""
        s, c = np.sin(self.w * t), np.cos(self.w * t)
        return self.A * s, self.A * self.w * c, -self.A * self.w ** 2 * s

    def initial_state(self):
        p = self.pivot(0.0)[0]
        return np.array([p + self.L[0], 0.0, p + self.L[0] + self.L[1], 0.0]), np.zeros(4)

    def mass(self, q=None):
        return self.M.copy()

    def residual(self, t, q, v, a):
        return self.M @ a - self.fg

    def jacobian(self, t, q, v, a):
        Z = sp.csr_matrix((4, 4))
        return JacobianBlocks(Z, Z, self.M.copy())

    def energy(self, t, q, v):
        return Energy(kinetic=0.5 * v @ (self.M @ v), strain=0.0, potential=-self.fg @ q)

    def external_power(self, t, q, v):
        return 0.0

    def potential(self, t, q):
        return float(-self.fg @ q)

    def potential_gradient(self, t, q, tangent=True):
        return -self.fg.copy(), (sp.csr_matrix((4, 4)) if tangent else None)

    def nonconservative_force(self, t, q, tangent=True):
        return np.zeros(4), (sp.csr_matrix((4, 4)) if tangent else None)

    def symmetry_generators(self):
        return np.zeros((4, 0)), []

    # -- the constraints --------------------------------------------------------------------------
    def _d(self, t, q):
        p = self.pivot(t)[0]
        return np.array([q[0] - p, q[1]]), q[2:] - q[:2]

    def constraints(self, t, q):
        d1, d2 = self._d(t, q)
        return 0.5 * np.array([d1 @ d1 - self.L[0] ** 2, d2 @ d2 - self.L[1] ** 2])

    def constraint_jacobian(self, t, q):
        d1, d2 = self._d(t, q)
        return sp.csr_matrix(np.array([[d1[0], d1[1], 0.0, 0.0], [-d2[0], -d2[1], d2[0], d2[1]]]))

    def constraint_force_jacobian(self, t, q, lam):
        A1 = np.diag([1.0, 1.0, 0.0, 0.0])
        A2 = np.kron(np.array([[1.0, -1.0], [-1.0, 1.0]]), np.eye(2))
        return sp.csr_matrix(lam[0] * A1 + lam[1] * A2)

    def constraint_rates(self, t, q, v):
        p, dp, ddp = self.pivot(t)
        d1, d2 = self._d(t, q)
        g_t = np.array([-d1[0] * dp, 0.0])
        # gamma = -(Z(v) v + 2 G_t v + g_tt); G_t = [[-dp, 0, 0, 0], [0...]], g_tt = -(x1 - p) p'' + p'^2
        zv = np.array([v[0] ** 2 + v[1] ** 2, (v[2] - v[0]) ** 2 + (v[3] - v[1]) ** 2])
        gtv = np.array([-dp * v[0], 0.0])
        g_tt = np.array([-d1[0] * ddp + dp * dp, 0.0])
        return g_t, -(zv + 2.0 * gtv + g_tt)
