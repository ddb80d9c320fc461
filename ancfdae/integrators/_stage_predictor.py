"""The linearized predictor of Lobatto IIIA's stage accelerations (``predictor="linearized"``).

The constant predictor ``A_i = a_n`` puts the stage positions at ``Q_i = q_n + c_i h v_n + (c_i h)^2 / 2
a_n``. For a mode of frequency ``w`` that the step does not resolve (``h w >> 1``: the shear and
cross-section modes of SQ3D) ``a_n = -w^2 q_n`` makes that mode's predicted amplitude ``(h w)^2 / 2``
times its actual one, about 1e4 times at ``h w = 160`` (SQ3D 16 el, h = 1e-3); the residual there is
dominated by the strain energy's cubic terms, and Newton diverges even with an exact Jacobian
(issue 22: ``lobatto3`` failed at h >= 1e-3 on a free-flying 16-element SQ3D beam). The linearized
predictor solves the stage equations linearized at the step's start instead,

    r(t_i, q_n, v_n, a_n) + K (Q_i - q_n) + D (V_i - v_n) + M (A_i - a_n) = 0,

one solve with the Newton matrix (exact for a linear model), so that a stiff mode starts near its
stage value and Newton iterates on the nonlinear rest.
"""
from __future__ import annotations

import numpy as np

from ancfdae.integrators._affine import stage_states
from ancfdae.integrators._linsolve import StageMatrix

__all__ = ["linearized_guess"]


def linearized_guess(stepper, t, h, ts, Q0, V0, CQ, CV, x0):
    """Stage accelerations (interleaved, like ``x0``) from one linear solve about ``(q_n, v_n, a_n)``.

    Uses the Newton solver's cached stage matrix and its blocks (``stepper._stage_blocks``) when they
    are current, else evaluates the blocks at the step's start and primes the solver with their matrix.
    Returns ``x0`` unchanged when the model's blocks do not share one pattern (no stage matrix).
    """
    model, newton = stepper.model, stepper.newton
    blk = stepper._stage_blocks if newton.has_factorization else None
    if blk is None:
        blk = model.jacobian(t, stepper.q, stepper.v, stepper.a)
        if not blk.same_pattern or not newton.prime(StageMatrix(blk, h, stepper._a_rest)):
            return x0
        stepper._stage_blocks = blk
    Q, V, X = stage_states(Q0, V0, CQ, CV, x0)
    q, v, a = stepper.q[:, None], stepper.v[:, None], stepper.a
    m = ts.size
    rep = np.repeat
    R = model.residual_stages(ts, rep(q, m, axis=1), rep(v, m, axis=1), rep(a[:, None], m, axis=1)) \
        if stepper._stages else np.column_stack([model.residual(ts[i], stepper.q, stepper.v, a) for i in range(m)])
    R = R + blk.K @ (Q - q) + blk.D @ (V - v) + blk.M @ (X - a[:, None])
    dx = newton.solve_cached(R.ravel())
    if not np.all(np.isfinite(dx)):
        return x0
    return x0 - dx
