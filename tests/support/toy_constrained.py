"""Constrained toy Models (the ``"constraints"`` capability) and an independent reference solution.

:class:`PointChains` -- planar point masses joined by bars: a consistent (banded, non-diagonal) bar
mass matrix, a quartic Green-strain axial energy, a quadratic bending energy invariant under rigid
motions, optional axial strain-rate and bending damping (zero on rigid motions), gravity; plus joints,
each row of the form ``g_i = 1/2 q^T A_i q + b_i(t) . q + c_i(t)`` with a constant ``A_i`` (every
joint between nodal coordinates is at most quadratic in q, time only in the linear part):

* ``pin_ground(p, X)``: point p at X (2 linear rows);
* ``pin(p, r)``: points p and r coincide (2 linear rows);
* ``distance(p, r, L)``: ``(|x_r - x_p|^2 - L^2) / 2 = 0`` (1 quadratic row);
* ``prescribed_position(p, path)``: ``x_p = path(t)`` (2 rheonomic rows, ``c(t)``);
* ``prescribed_direction(p, r, theta)``: ``n(theta(t)) . (x_r - x_p) = 0``, ``n = (-sin, cos)``
  (1 rheonomic row, ``b(t)``).

Problems (after the constraints prototype's (a), (b), (c)): :func:`double_pendulum` (linear g),
:func:`hanging_link` (a chain pinned to the ground, a second chain hanging on a distance link:
quadratic g), :func:`hub` (a chain driven by a hub spinning up: rheonomic g).

:func:`consistent_start` solves ``[[M, G^T], [G, 0]] [a; lam] = [-f; gamma]``;
:func:`reference` integrates the index-1 ODE (y = [q, v], a from that system) with DOP853 -- an
explicit method sharing no error with the implicit steppers under test.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.integrate import solve_ivp

from ancfdae.problem import Energy, JacobianBlocks

GRAV = 9.81


class PointChains:
    """Planar point masses, bars, bending triples and joints (see the module docstring)."""

    mass_is_constant = True
    capabilities = frozenset({"constraints"})

    def __init__(self, points, gravity=True):
        self.X0 = np.asarray(points, float)
        self.n_dof = 2 * len(self.X0)
        self.bars, self.bends, self.rows = [], [], []   # rows: (A (n, n) or None, bfun, cfun, label)
        self.gravity = gravity
        self.velocity_jacobian_provided = True

    # -- building ------------------------------------------------------------------------------
    def chain(self, start, end, nseg, mass, EA, EI, damping=(0.0, 0.0)):
        """Points from ``start`` to ``end`` (new points), bars and bending triples; returns their indices."""
        first = len(self.X0)
        pts = np.linspace(start, end, nseg + 1)
        idx = list(range(first, first + nseg + 1))
        self.X0 = np.vstack([self.X0, pts]) if self.X0.size else pts
        self.n_dof = 2 * len(self.X0)
        L = np.linalg.norm(np.subtract(end, start)) / nseg
        for a, b in zip(idx[:-1], idx[1:]):
            self.bars.append((a, b, mass / nseg, EA, damping[0], L))
        for i, j, k in zip(idx[:-2], idx[1:-1], idx[2:]):
            self.bends.append((i, j, k, EI / L ** 3, damping[1] * EI / L ** 3))
        return idx

    def _row(self, A=None, b=None, c=None, label=""):
        self.rows.append((A, b, c, label))

    def _unit(self, p, k):
        e = np.zeros(self.n_dof)
        e[2 * p + k] = 1.0
        return e

    def pin_ground(self, p, X):
        for k in range(2):
            e = self._unit(p, k)
            self._row(b=lambda t, e=e: (e, 0 * e, 0 * e), c=lambda t, x=X[k]: (-x, 0.0, 0.0), label=f"ground[{k}]")

    def pin(self, p, r):
        for k in range(2):
            e = self._unit(p, k) - self._unit(r, k)
            self._row(b=lambda t, e=e: (e, 0 * e, 0 * e), label=f"pin {p}-{r}[{k}]")

    def distance(self, p, r, L):
        A = np.zeros((self.n_dof, self.n_dof))
        for k in range(2):
            d = self._unit(r, k) - self._unit(p, k)
            A += np.outer(d, d)
        self._row(A=A, c=lambda t: (-0.5 * L * L, 0.0, 0.0), label=f"distance {p}-{r}")

    def prescribed_position(self, p, path):
        for k in range(2):
            e = self._unit(p, k)
            self._row(b=lambda t, e=e: (e, 0 * e, 0 * e),
                      c=lambda t, k=k: tuple(-x[k] for x in path(t)), label=f"hub position[{k}]")

    def prescribed_direction(self, p, r, theta):
        def b(t):
            th, dth, ddth = theta(t)
            n = np.array([-np.sin(th), np.cos(th)])
            dn = np.array([-np.cos(th), -np.sin(th)])
            out = [np.zeros(self.n_dof) for _ in range(3)]
            for vec, o in zip((n, dn * dth, -n * dth ** 2 + dn * ddth), out):
                o[2 * r:2 * r + 2] += vec
                o[2 * p:2 * p + 2] -= vec
            return tuple(out)
        self._row(b=b, label="hub direction")

    def finalize(self):
        n, m = self.n_dof, len(self.rows)
        self.n_constraints = m
        self.A = np.zeros((m, n, n))
        for i, (A, _, _, _) in enumerate(self.rows):
            if A is not None:
                self.A[i] = A
        self.M = np.zeros((n, n))
        self.fg = np.zeros(n)
        self.Kb, self.Cb = np.zeros((n, n)), np.zeros((n, n))
        for a, b, mass, _, _, _ in self.bars:
            for (i, j), w in (((a, a), 2), ((b, b), 2), ((a, b), 1), ((b, a), 1)):
                self.M[2 * i:2 * i + 2, 2 * j:2 * j + 2] += mass / 6 * w * np.eye(2)
            if self.gravity:
                self.fg[2 * a + 1] -= GRAV * mass / 2
                self.fg[2 * b + 1] -= GRAV * mass / 2
        for i, j, k, kb, cb in self.bends:
            C = np.zeros((2, n))
            for p, w in ((i, 1.0), (j, -2.0), (k, 1.0)):
                C[:, 2 * p:2 * p + 2] = w * np.eye(2)
            self.Kb += kb * C.T @ C
            self.Cb += cb * C.T @ C
        # one structural pattern for K, D, M; the constraint rows' union over t and q
        S = (np.abs(self.M) + np.abs(self.Kb) + np.abs(self.Cb)) > 0
        for a, b, *_ in self.bars:
            for i in (a, b):
                for j in (a, b):
                    S[2 * i:2 * i + 2, 2 * j:2 * j + 2] = True
        S |= np.eye(n, dtype=bool)
        self._pat = sp.csr_matrix(S.astype(float))
        self._pr, self._pc = np.nonzero(S)
        Gs = np.any(self.A != 0, axis=2)
        for i, (_, bf, _, _) in enumerate(self.rows):
            if bf is not None:
                for tt in (0.0, 0.37, 1.1):
                    Gs[i] |= bf(tt)[0] != 0
        self._gpat = sp.csr_matrix(Gs.astype(float))
        self._gr, self._gc = np.nonzero(Gs)
        return self

    # -- the Model contract ----------------------------------------------------------------------
    def initial_state(self):
        return self.X0.ravel().copy(), np.zeros(self.n_dof)

    def _csr(self, dense):
        return sp.csr_matrix((dense[self._pr, self._pc], self._pat.indices, self._pat.indptr), shape=dense.shape)

    def mass(self, q):
        return self._csr(self.M)

    def _forces(self, q, v, tangent):
        n = self.n_dof
        f = self.Kb @ q + self.Cb @ v - self.fg
        K, D = (self.Kb.copy(), self.Cb.copy()) if tangent else (None, None)
        for a, b, _, EA, c, L in self.bars:
            ia, ib = slice(2 * a, 2 * a + 2), slice(2 * b, 2 * b + 2)
            d, w = q[ib] - q[ia], v[ib] - v[ia]
            eps, deps = (d @ d - L * L) / (2 * L * L), (d @ w) / (L * L)
            fb = (EA * eps + c * deps) / L * d
            f[ib] += fb
            f[ia] -= fb
            if tangent:
                kq = (EA * (np.outer(d, d) / L ** 3 + eps / L * np.eye(2))
                      + c * (np.outer(d, w) / L ** 3 + deps / L * np.eye(2)))
                kv = c * np.outer(d, d) / L ** 3
                for X, blk in ((K, kq), (D, kv)):
                    X[ib, ib] += blk
                    X[ia, ia] += blk
                    X[ia, ib] -= blk
                    X[ib, ia] -= blk
        return f, K, D

    def residual(self, t, q, v, a):
        return self.M @ a + self._forces(q, v, False)[0]

    def jacobian(self, t, q, v, a):
        _, K, D = self._forces(q, v, True)
        return JacobianBlocks(self._csr(K), self._csr(D), self._csr(self.M), same_pattern=True)

    def energy(self, t, q, v):
        U = 0.5 * q @ self.Kb @ q
        for a, b, _, EA, _, L in self.bars:
            d = q[2 * b:2 * b + 2] - q[2 * a:2 * a + 2]
            U += EA * L / 2 * ((d @ d - L * L) / (2 * L * L)) ** 2
        return Energy(0.5 * v @ self.M @ v, U, -self.fg @ q)

    def external_power(self, t, q, v):
        return 0.0

    # -- the "constraints" capability --------------------------------------------------------------
    def _parts(self, t):
        m, n = self.n_constraints, self.n_dof
        B, c = np.zeros((3, m, n)), np.zeros((3, m))
        for i, (_, bf, cf, _) in enumerate(self.rows):
            if bf is not None:
                B[:, i] = bf(t)
            if cf is not None:
                c[:, i] = cf(t)
        return B, c

    def _gcsr(self, dense):
        return sp.csr_matrix((dense[self._gr, self._gc], self._gpat.indices, self._gpat.indptr), shape=dense.shape)

    def constraints(self, t, q):
        B, c = self._parts(t)
        return 0.5 * np.einsum("j,ijk,k->i", q, self.A, q) + B[0] @ q + c[0]

    def constraint_jacobian(self, t, q):
        return self._gcsr(self.dense_constraint_jacobian(t, q))

    def dense_constraint_jacobian(self, t, q):
        B, _ = self._parts(t)
        return self.A @ q + B[0]

    def constraint_force_jacobian(self, t, q, lam):
        return sp.csr_matrix(np.einsum("i,ijk->jk", lam, self.A))

    def constraint_rates(self, t, q, v):
        B, c = self._parts(t)
        g_t = B[1] @ q + c[1]
        gamma = -(np.einsum("j,ijk,k->i", v, self.A, v) + 2 * B[1] @ v + B[2] @ q + c[2])
        return g_t, gamma

    def constraint_velocity_jacobian(self, t, q, v):
        B, _ = self._parts(t)
        return self._gcsr(self.A @ v + B[1])


class WithoutVelocityJacobian:
    """The same model without the optional ``constraint_velocity_jacobian`` (the fallback path)."""

    mass_is_constant = True
    capabilities = frozenset({"constraints"})

    def __init__(self, model):
        self._m = model
        self.n_dof, self.n_constraints = model.n_dof, model.n_constraints

    def __getattr__(self, name):
        if name == "constraint_velocity_jacobian" or name.startswith("__"):
            raise AttributeError(name)
        return getattr(self._m, name)


# -- problems -----------------------------------------------------------------------------------
SOFT = dict(EA=2e3, EI=100.0, damping=(2.0, 0.002))


def double_pendulum(nseg=3, EA=SOFT["EA"], EI=SOFT["EI"], damping=SOFT["damping"]):
    """Two chains of 1 m, 1 kg, pinned to the ground and to each other, released horizontally (linear g)."""
    s = PointChains(np.zeros((0, 2)))
    c1 = s.chain((0.0, 0.0), (1.0, 0.0), nseg, 1.0, EA, EI, damping)
    c2 = s.chain((1.0, 0.0), (2.0, 0.0), nseg, 1.0, EA, EI, damping)
    s.pin_ground(c1[0], (0.0, 0.0))
    s.pin(c1[-1], c2[0])
    return s.finalize()


def hanging_link(nseg=3, link=0.3, EA=SOFT["EA"], EI=SOFT["EI"], damping=SOFT["damping"]):
    """A chain pinned to the ground; a second chain (0.5 m, 0.5 kg) hangs on a massless link of length
    ``link`` from its tip (quadratic g: the distance row)."""
    s = PointChains(np.zeros((0, 2)))
    c1 = s.chain((0.0, 0.0), (1.0, 0.0), nseg, 1.0, EA, EI, damping)
    c2 = s.chain((1.0 + link, 0.0), (1.5 + link, 0.0), 2, 0.5, EA, EI, damping)
    s.pin_ground(c1[0], (0.0, 0.0))
    s.distance(c1[-1], c2[0], link)
    return s.finalize()


RHUB, OMEGA_S, T_S = 0.2, 6.0, 2.0


def spinup(t):
    """Kane's spin-up profile: theta, theta', theta'' (theta' = theta'' = 0 at t = 0)."""
    w = 2 * np.pi / T_S
    return (OMEGA_S / T_S * (t * t / 2 + (np.cos(w * t) - 1) / w ** 2),
            OMEGA_S / T_S * (t - np.sin(w * t) / w), OMEGA_S / T_S * (1 - np.cos(w * t)))


def _hub_path(t):
    th, dth, ddth = spinup(t)
    e, ep = np.array([np.cos(th), np.sin(th)]), np.array([-np.sin(th), np.cos(th)])
    return RHUB * e, RHUB * dth * ep, RHUB * (ddth * ep - dth ** 2 * e)


def hub(nseg=3, EA=SOFT["EA"], EI=SOFT["EI"], damping=SOFT["damping"]):
    """A 1 m chain whose root follows a hub of radius 0.2 m spinning up (rheonomic g), no gravity."""
    s = PointChains(np.zeros((0, 2)), gravity=False)
    c = s.chain((RHUB, 0.0), (RHUB + 1.0, 0.0), nseg, 1.0, EA, EI, damping)
    s.prescribed_position(c[0], _hub_path)
    s.prescribed_direction(c[0], c[1], spinup)
    return s.finalize()


# -- consistent start and reference ----------------------------------------------------------------
def kkt(model, t, q, v):
    """(a, lam) from [[M, G^T], [G, 0]] [a; lam] = [-f; gamma] (dense)."""
    n, m = model.n_dof, model.n_constraints
    G = model.dense_constraint_jacobian(t, q)
    _, gam = model.constraint_rates(t, q, v)
    J = np.zeros((n + m, n + m))
    J[:n, :n], J[:n, n:], J[n:, :n] = model.M, G.T, G
    x = np.linalg.solve(J, np.r_[-model._forces(q, v, False)[0], gam])
    return x[:n], x[n:]


def consistent_start(model, t0=0.0):
    """(q0, v0, a0, lam0) with the model's initial (q0, v0), which satisfy both constraint levels."""
    q0, v0 = model.initial_state()
    g = model.constraints(t0, q0)
    gv = model.constraint_jacobian(t0, q0) @ v0 + model.constraint_rates(t0, q0, v0)[0]
    assert np.max(np.abs(g)) < 1e-14 and np.max(np.abs(gv)) < 1e-14, "the toy's initial state must be consistent"
    a0, lam0 = kkt(model, t0, q0, v0)
    return q0, v0, a0, lam0


def reference(model, times, rtol=1e-12):
    """(q, v, lam) at ``times`` (rows) from DOP853 on the index-1 ODE, starting at times[0]."""
    n = model.n_dof
    q0, v0, _, _ = consistent_start(model, times[0])

    def rhs(t, y):
        return np.r_[y[n:], kkt(model, t, y[:n], y[n:])[0]]

    sol = solve_ivp(rhs, (times[0], times[-1]), np.r_[q0, v0], method="DOP853", rtol=rtol, atol=rtol,
                    t_eval=times)
    Y = sol.y.T
    lam = np.array([kkt(model, t, y[:n], y[n:])[1] for t, y in zip(times, Y)])
    return Y[:, :n], Y[:, n:], lam


def step_to(st, model, t_end):
    """Step an initialized constrained stepper ``st`` to ``t_end`` (every step must succeed); returns the largest
    position residual ``|g|`` and velocity residual ``|G v + g_t|`` seen after a step."""
    g = gv = 0.0
    while st.t < t_end - 1e-12:
        out = st.step()
        assert out.ok, out.message
        st.accept(out)
        g = max(g, np.abs(model.constraints(st.t, st.q)).max())
        gv = max(gv, np.abs(model.constraint_jacobian(st.t, st.q) @ st.v
                            + model.constraint_rates(st.t, st.q, st.v)[0]).max())
    return g, gv
