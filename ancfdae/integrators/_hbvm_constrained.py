"""One HBVM(k, 2) step on a constrained model: a multiplier polynomial and two conditions per row.

For ``M a + grad P - f_nc + G^T lam = 0``, ``g(t, q) = 0`` with rows at most quadratic in ``q``
(``constraint_degree <= 2``), the multiplier is a polynomial of degree 1 over the step,
``Lam(c) = Lam_0 + Lam_1 P_1(c)``, its force projected with the same ``k`` silent nodes as the
conservative force, and each row gets two conditions (Amodio, Brugnano, Frasca-Caccia and Iavernaro's
line-integral construction for quadratic holonomic constraints)::

    g(t1, q1) = 0,     C_1 = h sum_l b_l P_1(c_l) (G(t_l, sigma_l) sigma'_l + g_t(t_l, sigma_l)) = 0

The work of the constraint forces over the step is ``-h sum_l b_l Lam(c_l) . G sigma'``; its ``Lam_0`` part
is ``-Lam_0 . (g(q1) - g(q0)) = 0`` when the rule integrates ``d g(sigma)/dc`` exactly (degree 3 for
quadratic ``g``: any ``k >= 2``), its ``Lam_1`` part is ``-Lam_1 . C_1 = 0``. So a scleronomic joint does
no work (energy kept as without constraints) and ``g(t1, q1) = 0`` holds to the Newton tolerance at
every step; a prescribed motion does the work of its ``g_t`` terms. The velocity constraint is not
imposed (it would break the energy identity).

Unknowns ``x = [Y (interleaved, 2 n), mu_0 (m), mu_1 (m)]``, ``Lam_j = s mu_j`` with ``s = m / h^2`` (``m``
the mean mass diagonal), the constraint rows scaled by ``s``: force units, as for the other constrained
steppers. The Newton matrix is the exact Jacobian (the constraint force Hessians join the potential's
at the nodes; ``d(G v)/dq = G(t, v) - G(t, 0)`` for quadratic rows) except for the ``q``-derivative of
``g_t`` (zero for scleronomic joints), which modified Newton does without.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae.constrained import multipliers
from ancfdae.integrators.protocol import Quadrature, StepOutcome

__all__ = ["constrained_hbvm_equations", "constrained_hbvm_step"]

_S = 2


def _P1(c):
    return np.sqrt(3.0) * (2.0 * c - 1.0)


def constrained_hbvm_equations(st, t0: float, h: float):
    """The step's Newton system ``(residual, jacobian, x0)`` for ``st`` (an
    :class:`~ancfdae.integrators.EnergyCollocation` on a constrained model)."""
    model, co, n, M = st.model, st._co, st.n_dof, st._M
    m = model.n_constraints
    q0, v0, t1 = st.q, st.v, t0 + h
    sm = st._mscale / (h * h)
    P = np.column_stack([np.ones(co.k), _P1(co.c)])                   # (k, 2): P_j(c_l)
    ts = t0 + co.c * h
    zero_v = np.zeros(n)

    def unpack(x):
        return x[:_S * n].reshape(n, _S), sm * x[_S * n:].reshape(_S, m)

    def nodes(Y):
        _, Q = st._nodes(t0, h, Y, co)
        D = v0[:, None] + (Y @ co.Wd.T) / h                            # sigma' at the nodes
        return Q, D

    def residual(x):
        Y, Lam = unpack(x)
        Q, D = nodes(Y)
        Lc = P @ Lam                                                    # (k, m): Lam(c_l)
        GtL = np.column_stack([model.constraint_jacobian(t, Q[:, l]).T @ Lc[l] for l, t in enumerate(ts)])
        dyn = (M @ Y) / (h * h) + st._forces(t0, h, Y) + GtL @ co.BP.T
        q1 = q0 + h * v0 + Y @ co.q_end
        rate = np.column_stack([model.constraint_jacobian(t, Q[:, l]) @ D[:, l]
                                + model.constraint_rates(t, Q[:, l], D[:, l])[0] for l, t in enumerate(ts)])
        c1 = h * (rate @ (co.b * P[:, 1]))
        return np.concatenate([dyn.ravel(), sm * model.constraints(t1, q1), sm * c1])

    def jacobian(x):
        Y, Lam = unpack(x)
        Q, D = nodes(Y)
        Lc = P @ Lam
        Hs = [model.potential_gradient(t, Q[:, l], True)[1] + model.constraint_force_jacobian(t, Q[:, l], Lc[l])
              for l, t in enumerate(ts)]
        floor = max(st.floor_of(H, Q[:, l]) for l, H in enumerate(Hs))
        _, Qn = st._nodes(t0, h, Y, st._loads)
        Kf = [model.nonconservative_force(t, Qn[:, j], True)[1] for j, t in enumerate(t0 + st._loads.c * h)]
        A = st._assemble(Hs, Kf, h)
        Gs = [sp.csr_matrix(model.constraint_jacobian(t, Q[:, l])) for l, t in enumerate(ts)]
        e = np.eye(_S)
        # d dyn_i / d mu_j = s sum_l BP[i, l] P_j(c_l) G_l^T, rows p*2 + i
        B = sp.hstack([sum(sp.kron(sm * sum(co.BP[i, l] * P[l, j] * Gs[l].T for l in range(co.k)), e[:, [i]])
                           for i in range(_S)) for j in range(_S)], format="csr")
        G1 = sp.csr_matrix(model.constraint_jacobian(t1, q0 + h * v0 + Y @ co.q_end))
        C0 = sum(sp.kron(sm * co.q_end[j] * G1, e[[j], :]) for j in range(_S))
        # d C_1 / d Y_j = h sum_l b_l P_1(c_l) [Z_l Wq[l, j] + G_l Wd[l, j] / h],  Z_l = G(t_l, sigma'_l) - G(t_l, 0)
        Z = [sp.csr_matrix(model.constraint_jacobian(t, D[:, l]) - model.constraint_jacobian(t, zero_v))
             for l, t in enumerate(ts)]
        C1 = sum(sp.kron(sm * sum(co.b[l] * P[l, 1] * (h * co.Wq[l, j] * Z[l] + co.Wd[l, j] * Gs[l])
                                  for l in range(co.k)), e[[j], :]) for j in range(_S))
        J = sp.bmat([[A, B], [sp.vstack([C0, C1]), sp.csr_matrix((_S * m, _S * m))]], format="csr")
        return J, max(floor, st.floor_of(G1 * sm, q0))

    Y0 = st._predict(h)
    mu0 = np.concatenate([st.lam / sm, np.zeros(m)])
    return residual, jacobian, np.concatenate([Y0.ravel(), mu0])


def constrained_hbvm_step(st, t0: float, h: float) -> StepOutcome:
    """One step of ``st`` (an :class:`~ancfdae.integrators.EnergyCollocation` on a constrained model)."""
    residual, jacobian, x0 = constrained_hbvm_equations(st, t0, h)
    out = st._solve(residual, jacobian, x0)
    if not out.converged:
        return StepOutcome.failure(f"Newton: {out.message}")
    co, n, model = st._co, st.n_dof, st.model
    m = model.n_constraints
    Y = out.x[:_S * n].reshape(n, _S)
    Lam = st._mscale / (h * h) * out.x[_S * n:].reshape(_S, m)
    t1 = t0 + h
    q1 = st.q + (h * st.v + Y @ co.q_end)
    v1 = st.v + Y[:, 0] / h
    lam1 = Lam[0] + _P1(1.0) * Lam[1]                                  # the multiplier polynomial at t1
    # The acceleration at t1 (the next step's first guess, the interpolation) from the saddle-point (KKT)
    # system at (t1, q1, v1): M alone may be singular (a lamina payload's axis director carries no mass).
    try:
        a1, _ = multipliers(model, t1, q1, v1, assembler=st._kkt_out)
    except np.linalg.LinAlgError as exc:
        return StepOutcome.failure(str(exc))
    if not np.all(np.isfinite(a1)):
        return StepOutcome.failure(f"the acceleration at t = {t1:.9g} is not finite (the model's residual there)")
    st._prev = (h, Y)
    quad = None
    if st.want_quadrature:
        ld = st._loads
        ts, Q = st._nodes(t0, h, Y, ld)
        quad = Quadrature(t=ts, q=Q.T, v=(st.v[:, None] + (Y @ ld.Wd.T) / h).T, w=h * ld.b)
    return StepOutcome(ok=True, t=t1, q=q1, v=v1, a=a1, quadrature=quad, lam=lam1)
