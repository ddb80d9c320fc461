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

__all__ = ["index3_step", "index3_equations", "predictor", "constant_start", "mass_scale", "constraint_force", "constraint_terms"]

#: steps whose sizes differ by at most this (relative) count as equal for the extrapolating predictor (the step's
#: matrix is kept under the same rule: :class:`ancfdae.integrators.newton_stepper.NewtonStepper`)
EXTRAPOLATE_TOL = 1e-8


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

    ah_guess, lam_guess = predictor(st, h)
    x0 = np.concatenate([(b * h * h) * ah_guess, lam_guess / sm])
    return residual, jacobian, x0, state


def constant_start(st, h: float) -> np.ndarray:
    """Newton's constant start ``[beta h^2 ah_n, lam_n / sm]`` for the step of size ``h`` (the unknowns of
    :func:`index3_equations`)."""
    sm = (1.0 - st.alpha_m) / ((1.0 - st.alpha_f) * st.beta * h * h) * st._mscale
    return np.concatenate([(st.beta * h * h) * st._ah, st.lam / sm])


def predictor(st, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Newton's start for the step of size ``h``: ``(ah1, lam1)`` extrapolated linearly from the current step and
    the last one, ``2 ah_n - ah_{n-1}`` and ``2 lam_n - lam_{n-1}``, when the last step had the same size (to
    :data:`EXTRAPOLATE_TOL`) and ``st.predictor`` is not "constant"; else the current ``(ah_n, lam_n)`` (the first
    step, after an event or a change of size).

    Why: a driven system's first residual is its drive's row at the new time, ``s m g(q_pred)``, with the
    position error of the constant start, O(h^3); extrapolated it is O(h^4). Measured (generalized-alpha,
    rho_inf 0.9, tol 1e-8, ``python -m benchmarks.index3_predictor``): B6's Newton iterations a step at
    h = 2e-4 / 1e-4 / 5e-5 3.64 / 4.27 / 3.85 -> 2.99 / 3.10 / 2.73, B5's at h = 0.02 / 0.005 3.00 / 2.64 ->
    2.49 / 2.09; the solutions move within Newton's tolerance.
    """
    last = st._last
    if st.predictor == "constant" or last is None or abs(last[0] - h) > EXTRAPOLATE_TOL * h:
        return st._ah, st.lam
    return 2.0 * st._ah - last[1], 2.0 * st.lam - last[2]


def index3_step(st, t: float, h: float) -> StepOutcome:
    """One Arnold-Bruls step of the stepper ``st``: the outcome with the true acceleration ``a1`` and
    ``lam1``; ``st._ah_next`` holds ``ah1`` for its ``accept``."""
    residual, jacobian, x0, state = index3_equations(st, t, h)
    out = st._solve(residual, jacobian, x0)
    x_const = None if out.converged else constant_start(st, h)   # only a failed step needs it
    if x_const is not None and not np.array_equal(x0, x_const):
        # an extrapolated start can fall outside Newton's basin where the constant one does not (B5, h = 0.05,
        # rho_inf 0.8: a step at 9.3 s diverges from the extrapolated start and converges from the constant one)
        first = out.message
        out = st._solve(residual, jacobian, x_const)
        if not out.converged:
            return StepOutcome.failure(f"Newton (index 3): {out.message} (also from the extrapolated start: {first})")
    if not out.converged:
        return StepOutcome.failure(f"Newton (index 3): {out.message}")
    q1, v1, a1, lam1 = state(out.x)
    st._ah_next = out.x[:q1.size] / (st.beta * h * h)
    return StepOutcome(ok=True, t=t + h, q=q1, v=v1, a=a1, lam=lam1)
