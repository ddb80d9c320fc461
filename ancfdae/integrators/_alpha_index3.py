"""One step of the Newmark family on a constrained model: index 3, Arnold-Bruls form, scaled.

For ``r(t, q, v, a) + G^T lam = 0``, ``g(t, q) = 0`` (:class:`ancfdae.problem.ConstrainedModel`) the step
of Arnold and Bruls (Multibody Syst. Dyn. 18:185, 2007) puts the equilibrium and the constraints at
``t_{n+1}`` with the *true* acceleration ``a_{n+1}`` and keeps the alpha weights in the recurrence of the
algorithmic acceleration ``ah`` only::

    r(t1, q1, v1, a1) + G(t1, q1)^T lam1 = 0,      g(t1, q1) = 0
    (1 - am) ah1 + am ah0 = (1 - af) a1 + af a0
    q1 = q0 + h v0 + h^2 (1/2 - beta) ah0 + h^2 beta ah1,      v1 = v0 + h (1 - gamma) ah0 + h gamma ah1

Why this form: in the state-averaged form of the unconstrained family the multiplier satisfies the
equilibrium at ``t_{n+1-af}`` and converges at order 1 at ``t_{n+1}``; here ``q``, ``v`` and ``lam`` are all
second order (measured on damped test problems: 2.00 each, with ``rho_inf < 1``).

Unknowns and scaling: ``x = [y, mu]`` with ``q1 = q_pred + y`` (an increment: iterating on ``q1`` itself
puts its representation error ``eps |q|`` into ``a1`` as ``eps |q| / (beta h^2)``) and ``lam = s m mu``,
``s = (1 - am) / ((1 - af) beta h^2)`` (``d a1 / d y``), ``m`` the mean diagonal of ``M``. The rows are
``[r + G^T lam; s m g]``, both in force units (a position error ``d`` costs ``s M d`` in the dynamic rows and
``s m d`` in the constraint rows), so the Newton test in the residual's units and the modified-Newton
contraction rate read both alike; the matrix is ``s`` times the scaled matrix of Bottasso, Bauchau and
Cardona (Multibody Syst. Dyn. 18:1, 2007)::

    s [[M + c_D D + c_K (K + H(lam)),  m G^T],      c_K = 1/s,  c_D = gamma / (beta h s)
       [m G,                           0     ]]

whose condition number does not grow like ``h^-4``. ``H(lam) = d(G^T lam)/dq``; the matrix is exact.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae.integrators.protocol import StepOutcome

__all__ = ["index3_step", "index3_equations", "mass_scale", "constraint_force", "constraint_terms"]


def mass_scale(M) -> float:
    """Mean of the mass matrix's diagonal (the scale of the constraint rows)."""
    d = np.asarray(sp.csr_matrix(M).diagonal(), dtype=float)
    return float(np.mean(np.abs(d))) if d.size else 1.0


def constraint_force(model):
    """``(t, q, lam) -> G^T lam``: the model's fast path when it has one (:class:`ancfdae.System`)."""
    fast = getattr(model, "constraint_force", None)
    if callable(fast):
        return fast
    return lambda t, q, lam: model.constraint_jacobian(t, q).T @ lam


def constraint_terms(model, t: float):
    """``(q, lam) -> (g(t, q), G(t, q)^T lam)``: the model's one-pass fast path at ``t`` when it has one (a
    compiled :class:`ancfdae.System`), else ``constraints`` and :func:`constraint_force`."""
    fast = getattr(model, "constraint_terms_at", None)
    if callable(fast):
        return fast(t)
    force = constraint_force(model)
    return lambda q, lam: (model.constraints(t, q), force(t, q, lam))


def index3_equations(st, t: float, h: float):
    """The step's Newton system: ``(residual, jacobian, x0, state)`` for the stepper ``st`` (a
    ``_AlphaFamily`` with ``_ah``, ``lam``, ``_mscale``); ``state(x) -> (q1, v1, a1, lam1)``."""
    am, af, b, g = st.alpha_m, st.alpha_f, st.beta, st.gamma
    model, n = st.model, st.q.size
    t1 = t + h
    q0, v0, a0, ah0 = st.q, st.v, st.a, st._ah
    q_pred = q0 + h * v0 + (h * h * (0.5 - b)) * ah0
    v_pred = v0 + (h * (1.0 - g)) * ah0
    s = (1.0 - am) / ((1.0 - af) * b * h * h)
    sm = s * st._mscale
    c_v = g / (b * h)
    const_a = (am * ah0 - af * a0) / (1.0 - af)

    def state(x):
        y = x[:n]
        q1 = q_pred + y
        v1 = v_pred + c_v * y
        a1 = s * y + const_a          # ((1 - am) ah1 + am ah0 - af a0) / (1 - af), ah1 = y / (beta h^2)
        return q1, v1, a1, sm * x[n:]

    terms = constraint_terms(model, t1)

    def residual(x):
        q1, v1, a1, lam = state(x)
        g, f = terms(q1, lam)
        return np.concatenate([np.asarray(model.residual(t1, q1, v1, a1), dtype=float) + f, sm * g])

    def jacobian(x):
        q1, v1, a1, lam = state(x)
        J = model.jacobian(t1, q1, v1, a1)
        G = sp.csr_matrix(model.constraint_jacobian(t1, q1))
        mat = st._kkt.assemble([J.combine(1.0, c_v, s), model.constraint_force_jacobian(t1, q1, lam)],
                               G, sm, G, sm)
        # the round-off of the dynamic rows and of the scaled constraint rows
        return mat, max(st.floor_of(J.K, q1), st.floor_of(sm * G, q1))

    x0 = np.concatenate([(b * h * h) * ah0, st.lam / sm])
    return residual, jacobian, x0, state


def index3_step(st, t: float, h: float) -> StepOutcome:
    """One Arnold-Bruls step of the stepper ``st``: the outcome with the true acceleration ``a1`` and
    ``lam1``; ``st._ah_next`` holds ``ah1`` for its ``accept``."""
    residual, jacobian, x0, state = index3_equations(st, t, h)
    out = st._solve(residual, jacobian, x0)
    if not out.converged:
        return StepOutcome.failure(f"Newton (index 3): {out.message}")
    q1, v1, a1, lam1 = state(out.x)
    st._ah_next = out.x[:q1.size] / (st.beta * h * h)
    return StepOutcome(ok=True, t=t + h, q=q1, v=v1, a=a1, lam=lam1)
