"""The force scale of a problem: the yardstick of Newton's absolute tolerance.

A fixed absolute tolerance in newtons is wrong for some problem whatever its value: 1e-10 N is the
whole load of a micro-fibre and far below round-off for a 100 m steel beam. The residual's own
round-off level is ``eps`` times the size of the terms that cancel in it; :func:`force_scale` measures
that size from the model, so that a floor ``ROUNDOFF * eps * force_scale`` is unit-free.
"""
from __future__ import annotations

import numpy as np

__all__ = ["ROUNDOFF", "force_scale"]

#: Absolute floor = ROUNDOFF * eps * force_scale: a residual below it is round-off of the terms that
#: cancel in the assembled forces. Set below the attainable level (measured on B1, 256 BE2D elements:
#: max|r| stalls at 0.46 eps * force_scale) so that the stagnation test of the Newton solver, not the
#: floor, ends a solve whose residual cannot fall further; at 1.0 that solve stopped one iteration
#: early per load step and the tip moved 3.5e-9 m from the converged 4e-11 m error.
ROUNDOFF = 0.1


def force_scale(model, t: float, q: np.ndarray, v: np.ndarray | None = None, a: np.ndarray | None = None) -> float:
    """The problem's own force scale at ``(t, q, v, a)``, in the residual's units.

    ``max|K| max|q| + max|D| max|v| + max|M| max|a| + max|r(t, q, 0, 0)|``:
    stiffness times coordinates (the size of the terms that cancel in the
    elastic forces), the damping and inertia forces, and the static residual
    (the applied load, in the reference configuration where the elastic
    forces vanish). It is independent of the unit system: a 1 um fibre and a
    100 m beam get their own scale. One Jacobian and one residual evaluation.

    Parameters
    ----------
    model : Model
    t : float
    q : ndarray, shape (n_dof,)
    v, a : ndarray, shape (n_dof,), optional
        Velocities and accelerations (zero by default: statics).

    Returns
    -------
    float
        Non-negative; ``ROUNDOFF * eps * force_scale`` is the absolute floor
        below which a residual is round-off.
    """
    z = np.zeros_like(q)
    v = z if v is None else v
    a = z if a is None else a
    J = model.jacobian(t, q, v, a)

    def amax(x):
        x = abs(x)
        return float(x.max()) if x.shape[0] else 0.0
    r = model.residual(t, q, z, z)
    return amax(J.K) * amax(q) + amax(J.D) * amax(v) + amax(J.M) * amax(a) + amax(r)
