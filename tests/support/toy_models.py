"""Small nonlinear Models satisfying ancfdae.problem.Model, with exact Jacobians (test fixtures).

SpringChain  -- planar chain of point masses joined by geometrically nonlinear springs, hinged at
                the origin, gravity, optional pulse force on the last mass and Rayleigh-type damping;
                constant mass, banded sparse matrices sharing one CSR pattern, ``position(q, s)``,
                and the PotentialModel capability (potential, its gradient, the pulse force apart).
DoublePendulum -- angles as coordinates: configuration-dependent mass, velocity-dependent terms,
                optional pulse torque on the first joint.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae.problem import Energy, JacobianBlocks


def pulse(t, T):
    """(1 - cos(2 pi t / T)) / 2 on [0, T], 0 after (benchmarks.md B2)."""
    return np.where((t >= 0) & (t <= T), 0.5 * (1.0 - np.cos(2 * np.pi * t / T)), 0.0)


def pulse_rate(t, T):
    return np.where((t >= 0) & (t <= T), np.pi / T * np.sin(2 * np.pi * t / T), 0.0)


class _Assembler:
    """Fixed CSR pattern for a list of (row, col) contributions; assemble(values) by bincount."""

    def __init__(self, rows, cols, n):
        A = sp.csr_matrix((np.arange(1, rows.size + 1, dtype=float), (rows, cols)), shape=(n, n))
        A.sum_duplicates()
        A.sort_indices()
        lin = rows.astype(np.int64) * n + cols
        csr_lin = np.repeat(np.arange(n), np.diff(A.indptr)).astype(np.int64) * n + A.indices
        self.slot = np.searchsorted(csr_lin, lin)
        self.indptr, self.indices, self.n, self.nnz = A.indptr, A.indices, n, A.indices.size

    def __call__(self, values):
        data = np.bincount(self.slot, weights=values, minlength=self.nnz)
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))


class _RecordsAcceptedSteps:
    """The step-event hooks of the contract, doing nothing but record each accepted step's time in
    ``self.accepted`` (the driver must call ``step_event`` once per accepted step, never for a rejected one)."""

    def event_state(self):
        return {}

    def bind(self, state):
        return self

    def step_event(self, t, q, v):
        self.accepted.append(t)
        return None


class SpringChain(_RecordsAcceptedSteps):
    """N point masses in the plane; spring i joins mass i-1 (or the hinge at the origin) and mass i."""

    mass_is_constant = True
    capabilities = frozenset({"step_events", "potential"})   # step_events: records the accepted steps

    def __init__(self, n_masses=3, mass=1.0, k=200.0, l0=1.0, g=9.81, force=(0.0, 0.0), T=1.0,
                 damping=0.0, v0=None, hinge=True):
        self.N, self.m, self.k, self.l0, self.g = n_masses, mass, k, l0, g
        self.F0, self.T, self.c = np.asarray(force, float), T, damping
        self.hinge = hinge
        self.n_dof = 2 * n_masses
        self._v0 = np.zeros(self.n_dof) if v0 is None else np.asarray(v0, float)
        N = n_masses
        # blocks: diag (i,i) for each mass, off-diagonal (i-1,i) and (i,i-1)
        rows, cols = [], []
        for bi, bj in [(i, i) for i in range(N)] + [(i - 1, i) for i in range(1, N)] + \
                      [(i, i - 1) for i in range(1, N)]:
            for a in range(2):
                for b in range(2):
                    rows.append(2 * bi + a)
                    cols.append(2 * bj + b)
        self._asm = _Assembler(np.array(rows), np.array(cols), self.n_dof)
        self._nd, self._no = N, N - 1
        self._M = self._asm(np.r_[np.tile([mass, 0, 0, mass], N), np.zeros(8 * (N - 1))])
        self.accepted = []

    def initial_state(self):
        x = self.l0 * np.arange(1, self.N + 1)
        q = np.column_stack([x, np.zeros(self.N)]).ravel()
        return q, self._v0.copy()

    def mass(self, q):
        return self._M

    def _points(self, q):
        P = q.reshape(self.N, 2)
        prev = np.vstack([np.zeros((1, 2)), P[:-1]]) if self.hinge else P[:-1]
        d = P - prev if self.hinge else P[1:] - P[:-1]
        return d

    def _spring(self, q):
        d = self._points(q)
        L = np.linalg.norm(d, axis=1)
        f = self.k * (1.0 - self.l0 / L)[:, None] * d                       # dU/dd
        H = self.k * ((1.0 - self.l0 / L)[:, None, None] * np.eye(2)
                      + (self.l0 / L**3)[:, None, None] * d[:, :, None] * d[:, None, :])
        return d, L, f, H

    def _fint(self, q):
        d, L, f, H = self._spring(q)
        F = np.zeros((self.N, 2))
        if self.hinge:
            F += f
            F[:-1] -= f[1:]
        else:
            F[1:] += f
            F[:-1] -= f
        return F.ravel(), H

    def _fext(self, t):
        F = np.zeros((self.N, 2))
        F[:, 1] -= self.m * self.g
        F[-1] += float(pulse(t, self.T)) * self.F0
        return F.ravel()

    def residual(self, t, q, v, a):
        fint, _ = self._fint(q)
        return self._M @ a + fint + self.c * (self._M @ v) - self._fext(t)

    def jacobian(self, t, q, v, a):
        _, H = self._fint(q)
        N = self.N
        diag = np.zeros((N, 2, 2))
        if self.hinge:
            diag += H
            diag[:-1] += H[1:]
            off = -H[1:]
        else:
            diag[1:] += H
            diag[:-1] += H
            off = -H
        K = self._asm(np.r_[diag.ravel(), off.ravel(), np.transpose(off, (0, 2, 1)).ravel()])
        D = sp.csr_matrix((self.c * self._M.data, self._M.indices, self._M.indptr), shape=self._M.shape)
        return JacobianBlocks(K=K, D=D, M=self._M, same_pattern=True)

    def energy(self, t, q, v):
        d, L, _, _ = self._spring(q)
        U = 0.5 * self.k * np.sum((L - self.l0) ** 2)
        T = 0.5 * v @ (self._M @ v)
        Vg = self.m * self.g * np.sum(q[1::2])
        return Energy(kinetic=float(T), strain=float(U), potential=float(Vg))

    def external_power(self, t, q, v):
        return float(pulse(t, self.T)) * float(self.F0 @ v[-2:])

    # -- PotentialModel (ancfdae.problem): for the energy-momentum integrator --------------------
    potential_degree = None

    def potential(self, t, q):
        e = self.energy(t, q, np.zeros_like(q))
        return e.strain + e.potential

    def potential_gradient(self, t, q, tangent=True):
        fint, _ = self._fint(q)
        g = fint - self._fext(-1.0)          # gravity only (the pulse is zero before t = 0)
        return g, (self.jacobian(t, q, q, q).K if tangent else None)

    def nonconservative_force(self, t, q, tangent=True):
        f = self._fext(t) - self._fext(-1.0)
        return f, (sp.csr_matrix(self._M.shape) if tangent else None)

    def position(self, q, s):
        """Piecewise-linear 'axis' through hinge and masses; s in [0, N] (affine in q)."""
        P = np.vstack([np.zeros((1, 2)), q.reshape(self.N, 2)])
        i = int(min(np.floor(s), self.N - 1))
        th = s - i
        return (1 - th) * P[i] + th * P[i + 1]


class DoublePendulum(_RecordsAcceptedSteps):
    """Double pendulum in absolute angles (from the downward vertical); M depends on q."""

    mass_is_constant = False
    capabilities = frozenset({"step_events", "variable_mass"})
    n_dof = 2

    def __init__(self, m1=1.0, m2=1.0, l1=1.0, l2=1.0, g=9.81, theta0=(np.pi / 2, np.pi / 2),
                 torque=0.0, T=1.0):
        self.m1, self.m2, self.l1, self.l2, self.g = m1, m2, l1, l2, g
        self.theta0, self.tau0, self.T = np.asarray(theta0, float), torque, T
        self.accepted = []

    def initial_state(self):
        return self.theta0.copy(), np.zeros(2)

    def mass(self, q):
        P = self.m2 * self.l1 * self.l2 * np.cos(q[0] - q[1])
        return sp.csr_matrix(np.array([[(self.m1 + self.m2) * self.l1**2, P], [P, self.m2 * self.l2**2]]))

    def residual(self, t, q, v, a):
        m1, m2, l1, l2, g = self.m1, self.m2, self.l1, self.l2, self.g
        c, s = np.cos(q[0] - q[1]), np.sin(q[0] - q[1])
        P = m2 * l1 * l2
        r1 = (m1 + m2) * l1**2 * a[0] + P * c * a[1] + P * s * v[1] ** 2 + (m1 + m2) * g * l1 * np.sin(q[0])
        r2 = m2 * l2**2 * a[1] + P * c * a[0] - P * s * v[0] ** 2 + m2 * g * l2 * np.sin(q[1])
        return np.array([r1 - self.tau0 * float(pulse(t, self.T)), r2])

    def jacobian(self, t, q, v, a):
        m1, m2, l1, l2, g = self.m1, self.m2, self.l1, self.l2, self.g
        c, s = np.cos(q[0] - q[1]), np.sin(q[0] - q[1])
        P = m2 * l1 * l2
        K = np.array([
            [-P * s * a[1] + P * c * v[1] ** 2 + (m1 + m2) * g * l1 * np.cos(q[0]), P * s * a[1] - P * c * v[1] ** 2],
            [-P * s * a[0] - P * c * v[0] ** 2, P * s * a[0] + P * c * v[0] ** 2 + m2 * g * l2 * np.cos(q[1])]])
        D = np.array([[0.0, 2 * P * s * v[1]], [-2 * P * s * v[0], 0.0]])
        M = self.mass(q).toarray()
        ones = sp.csr_matrix(np.ones((2, 2)))
        mk = [sp.csr_matrix((X[ones.nonzero()], ones.indices, ones.indptr), shape=(2, 2)) for X in (K, D, M)]
        return JacobianBlocks(K=mk[0], D=mk[1], M=mk[2], same_pattern=True)

    def energy(self, t, q, v):
        T = 0.5 * v @ (self.mass(q) @ v)
        Vg = -(self.m1 + self.m2) * self.g * self.l1 * np.cos(q[0]) - self.m2 * self.g * self.l2 * np.cos(q[1])
        return Energy(kinetic=float(T), strain=0.0, potential=float(Vg))

    def external_power(self, t, q, v):
        return self.tau0 * float(pulse(t, self.T)) * float(v[0])

    def tip(self, q):
        return np.array([self.l1 * np.sin(q[0]) + self.l2 * np.sin(q[1]),
                         -self.l1 * np.cos(q[0]) - self.l2 * np.cos(q[1])])


class NaNAfter:
    """Wraps a model (forwarding everything, declaring nothing); its residual turns NaN after t_bad (a step
    that cannot converge)."""

    def __init__(self, model, t_bad):
        self.m, self.t_bad = model, t_bad
        self.n_dof, self.mass_is_constant = model.n_dof, model.mass_is_constant

    def __getattr__(self, name):
        return getattr(self.m, name)

    def residual(self, t, q, v, a):
        r = self.m.residual(t, q, v, a)
        return r * np.nan if t > self.t_bad else r
