"""A constrained midpoint (energy-momentum) stepper for tests of constrained models, on the Model contract.

The scheme of Gonzalez (1999) and Betsch & Steinmann (2001) for ``M a + f(t, q) + G^T lambda = 0``,
``g(q) = 0`` with a constant ``M`` and constraints at most quadratic in ``q``::

    M (v1 - v0) / h + f(t_m, q_m) + G(q_m)^T lambda = 0,    g(q1) = 0,    (q1 - q0) / h = (v0 + v1) / 2

``f`` is read off the model's residual at the midpoint (exact discrete gradient for potentials at most
quadratic: here gravity and none). For a quadratic ``g``, ``g(q1) - g(q0) = G(q_m) (q1 - q0)`` exactly, so
the constraints hold to the Newton tolerance and the work of ``G^T lambda`` over the step is zero: the
energy of a conservative system is kept to round-off. Kept independent of the package's integrators, so
that the rigid-body tests do not depend on them.
"""
import numpy as np


class Constraints:
    """The model's own constraints (the ``"constraints"`` capability) stacked with extra ones.

    ``extra``: a list of ``(g(q), G(q) dense, H(lam) dense)`` callables of quadratic constraints built in a
    test (a pin, a distance).
    """

    def __init__(self, model, extra=()):
        self.model, self.extra = model, list(extra)
        self.m_own = model.n_constraints

    def g(self, q):
        return np.concatenate([self.model.constraints(0.0, q)] + [e[0](q) for e in self.extra])

    def G(self, q):
        return np.vstack([self.model.constraint_jacobian(0.0, q).toarray()] + [e[1](q) for e in self.extra])

    def H(self, q, lam):
        H = self.model.constraint_force_jacobian(0.0, q, lam[:self.m_own]).toarray()
        k = self.m_own
        for e in self.extra:
            m = e[0](q).size
            H = H + e[2](lam[k:k + m])
            k += m
        return H


def step(model, cons, t, h, q0, v0, lam0, tol=1e-14, max_iter=30):
    """One constrained midpoint step: ``(q1, v1, lam)`` (full Newton on ``(q1, lam)``, exact Jacobian)."""
    n = q0.size
    M = model.mass(q0).toarray()
    q1, lam = q0 + h * v0, lam0.copy()
    tm = t + 0.5 * h
    for _ in range(max_iter):
        qm = 0.5 * (q0 + q1)
        v1 = 2.0 * (q1 - q0) / h - v0
        a = (v1 - v0) / h
        r, jac = model.residual_jacobian(tm, qm, 0.5 * (v0 + v1), a)
        Gm = cons.G(qm)
        R = np.concatenate((r + Gm.T @ lam, cons.g(q1)))
        J = np.zeros((n + lam.size, n + lam.size))
        J[:n, :n] = 2.0 / h ** 2 * jac.M.toarray() + 0.5 * (jac.K.toarray() + cons.H(qm, lam)) \
            + 1.0 / h * jac.D.toarray()
        J[:n, n:] = Gm.T
        J[n:, :n] = cons.G(q1)
        dx = np.linalg.solve(J, -R)
        q1 = q1 + dx[:n]
        lam = lam + dx[n:]
        if np.max(np.abs(dx[:n])) <= tol * max(1.0, np.max(np.abs(q1))):
            return q1, 2.0 * (q1 - q0) / h - v0, lam
    raise RuntimeError(f"constrained midpoint: Newton did not converge at t = {t}")


def run(model, cons, t_end, h, q0=None, v0=None):
    """States at every step: ``(t, Q, V, Lam)``."""
    if q0 is None:
        q0, v0 = model.initial_state()
    n_steps = int(round(t_end / h))
    m = cons.g(q0).size
    Q, V, L = [q0], [v0], [np.zeros(m)]
    q, v, lam = q0, v0, np.zeros(m)
    for i in range(n_steps):
        q, v, lam = step(model, cons, i * h, h, q, v, lam)
        Q.append(q), V.append(v), L.append(lam)
    return h * np.arange(n_steps + 1), np.array(Q), np.array(V), np.array(L)

