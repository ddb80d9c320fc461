"""One energy-momentum step on a constrained model: the constraint forces through a discrete derivative.

For ``M a + grad P - f_nc + G^T lam = 0``, ``g(t, q) = 0`` the step (Gonzalez, J. Nonlinear Sci. 9:293,
1999, for holonomic constraints) is::

    q1 - q0 = h (v0 + v1) / 2
    M (v1 - v0) = -h DP(q0, q1) + h f_nc(t_m, q_m) - h G_d^T lam,      g(t1, q1) = 0
    G_d = (G(t0, q_m) + G(t1, q_m)) / 2,      q_m = (q0 + q1) / 2

For constraints at most quadratic in ``q`` with time only in the linear part (every joint of
:mod:`ancfdae.joints`, ``constraint_degree <= 2``), ``G(t, q_m) (q1 - q0) = g(t, q1) - g(t, q0)`` *exactly*:
``G(q_m)`` is a discrete derivative with no correction. Multiplying by ``v_m = (q1 - q0)/h`` gives::

    E1 - E0 = h f_nc . v_m - lam . (G_d (q1 - q0)),
    G_d (q1 - q0) = [g(t0, q1) - g(t0, q0) + g(t1, q1) - g(t1, q0)] / 2

so with ``g(t0, q0) = g(t1, q1) = 0`` a scleronomic joint does no work (energy kept to round-off) and
``g(t1, q1) = 0`` holds to the Newton tolerance at every step; a prescribed motion does exactly
``lam . Delta_t g`` (``Delta_t g = [g(t1, q1) - g(t0, q1) + g(t1, q0) - g(t0, q0)] / 2``). The velocity
constraint ``G v + g_t = 0`` is not imposed (it would break the energy identity): exact for linear rows
(pins), ``O(h^2)`` for quadratic ones.

Unknowns ``x = [y, mu]``, ``y = q1 - q0 - h v0``, ``lam = s m mu`` with ``s = 2 / h^2`` and ``m`` the mean mass
diagonal; rows ``[dyn; s m g(t1, q1)]`` in force units (as in :mod:`._alpha_index3`). Exact matrix::

    [[s M + dDP/dq1 - K_nc / 2 + H_d(lam) / 2,  s m G_d^T],      H_d = (H(t0, q_m, lam) + H(t1, q_m, lam)) / 2
     [s m G(t1, q1),                            0        ]]
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae.constrained import multipliers
from ancfdae.integrators._alpha_index3 import constraint_force
from ancfdae.integrators.protocol import Quadrature, StepOutcome

__all__ = ["constrained_em_step", "constrained_em_equations"]


def constrained_em_equations(st, t0: float, h: float):
    """The step's Newton system ``(residual, jacobian, x0)`` for ``st`` (an
    :class:`~ancfdae.integrators.EnergyMomentum` on a constrained model); ``x = [y, mu]``."""
    q0, v0 = st.q, st.v
    tm, t1 = t0 + 0.5 * h, t0 + h
    model, dg, M, c = st.model, st._dg, st._M, 2.0 / (h * h)
    n = q0.size
    sm = c * st._mscale
    dg.start(tm, q0)
    hv0 = h * v0

    def G_d(qm):
        A, B = sp.csr_matrix(model.constraint_jacobian(t0, qm)), sp.csr_matrix(model.constraint_jacobian(t1, qm))
        if np.array_equal(A.indptr, B.indptr) and np.array_equal(A.indices, B.indices):   # the fixed pattern
            return sp.csr_matrix((0.5 * (A.data + B.data), A.indices, A.indptr), shape=A.shape)
        return 0.5 * (A + B)

    force = constraint_force(model)

    def residual(x):
        y, lam = x[:n], sm * x[n:]
        u = hv0 + y
        qm = q0 + 0.5 * u
        f, _ = model.nonconservative_force(tm, qm, False)
        dyn = c * (M @ y) + dg.gradient(q0 + u) - f + 0.5 * (force(t0, qm, lam) + force(t1, qm, lam))
        return np.concatenate([dyn, sm * model.constraints(t1, q0 + u)])

    def jacobian(x):
        y, lam = x[:n], sm * x[n:]
        u = hv0 + y
        qm = q0 + 0.5 * u
        _, Kf = model.nonconservative_force(tm, qm, True)
        J = dg.jacobian(q0 + u)
        Gd, G1 = sm * sp.csr_matrix(G_d(qm)), sm * sp.csr_matrix(model.constraint_jacobian(t1, q0 + u))
        # the round-off of the gradient rows and of the scaled constraint rows (a model without stiffness,
        # such as point masses on rods, has only the latter)
        floor = max(st.floor_of(J, q0 + u), st.floor_of(G1, q0 + u))
        H = 0.25 * (model.constraint_force_jacobian(t0, qm, lam) + model.constraint_force_jacobian(t1, qm, lam))
        if sp.issparse(J):
            return st._kkt.assemble([c * M, J, -0.5 * Kf, H], Gd, 1.0, G1, 1.0), floor
        A = J + (c * M - 0.5 * Kf + H).toarray()
        m = G1.shape[0]
        return np.block([[A, Gd.T.toarray()], [G1.toarray(), np.zeros((m, m))]]), floor

    return residual, jacobian, np.concatenate([_predict(st, h), st.lam / sm])


def _predict(st, h: float) -> np.ndarray:
    """Initial guess of ``y``: the last step's discrete acceleration ``(v1 - v0) / h_p = 2 y_p / h_p^2``.

    Not the acceleration at ``t0`` (the unconstrained step's predictor): the scheme keeps every mode's
    energy, stiff axial ones included, and with ``omega h`` in the hundreds their part of ``a(t0)`` is
    far from their part of the step's mean acceleration. Measured on B5 (BE2D, 8 elements, h = 0.05): with
    ``a(t0)`` Newton's first residual grew to 1.8e6 and it diverged at t = 1.9 s; with the discrete
    acceleration the run goes on (4 s, 5.8 iterations per step). On B7 (Cable3D, 4 elements, E = 5e7,
    h = 0.02, 2 s) iterations fell from 1354 to 881. The first step uses ``a(t0)``.
    """
    prev = st.previous
    if prev is not None and st.t > prev[0]:
        hp = st.t - prev[0]
        return (st.q - prev[1] - hp * prev[2]) * (h / hp) ** 2
    return (0.5 * h * h) * st.a


def constrained_em_step(st, t0: float, h: float) -> StepOutcome:
    """One step of ``st`` (an :class:`~ancfdae.integrators.EnergyMomentum` on a constrained model)."""
    residual, jacobian, x0 = constrained_em_equations(st, t0, h)
    out = st._solve(residual, jacobian, x0)
    if not out.converged:
        return StepOutcome.failure(f"Newton: {out.message}")
    q0, v0, n, model = st.q, st.v, st.q.size, st.model
    tm, t1 = t0 + 0.5 * h, t0 + h
    hv0 = h * v0
    y, lam = out.x[:n], 2.0 / (h * h) * st._mscale * out.x[n:]
    q1 = q0 + (hv0 + y)
    v1 = v0 + (2.0 / h) * y
    # The acceleration at t1 (the next step's predictor, the interpolation): from the KKT system at
    # (t1, q1, v1). With M a1 = -r - G^T lam and the step's own, midpoint multipliers instead, the predictor
    # is O(h) off and Newton diverged on the spatial double pendulum of Cable3D beams at h = 2 ms.
    try:
        a1, _ = multipliers(model, t1, q1, v1, assembler=st._kkt_out)
    except np.linalg.LinAlgError as exc:
        return StepOutcome.failure(str(exc))
    if not np.all(np.isfinite(a1)):
        return StepOutcome.failure(f"the acceleration at t = {t1:.9g} is not finite (the model's residual there)")
    quad = None
    if st.want_quadrature:
        quad = Quadrature(t=np.array([tm]), q=(q0 + 0.5 * (hv0 + y))[None, :], v=(v0 + y / h)[None, :],
                          w=np.array([h]))
    return StepOutcome(ok=True, t=t1, q=q1, v=v1, a=a1, quadrature=quad, lam=lam)
