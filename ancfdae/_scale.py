"""The yardsticks of Newton's absolute tests: the problem's force scale and the round-off floors.

A fixed absolute tolerance in newtons is wrong for some problem whatever its value: 1e-10 N is the
whole load of a micro-fibre and far below round-off for a 100 m steel beam. The residual's own
round-off level is ``eps`` times the size of the terms that cancel in it. Two measures of that size
are used, each with its own factor, measured where it was chosen:

* :func:`force_scale` of the whole problem, once per solve or run, times :data:`ATOL_ROUNDOFF`:
  the default absolute tolerance of the static solver and of the time steppers;
* the largest stiffness entry times the coordinates, at every Jacobian evaluation
  (:func:`roundoff_floor`), times :data:`STIFFNESS_ROUNDOFF` for the fixed-step steppers and
  :data:`ENERGY_ROUNDOFF` for the energy-momentum stepper: the floor that follows the configuration.

:func:`max_abs`, the max-norm these tests take (one compiled pass), is shared by the Newton solvers, the
integrators' compiled steps and the driver's checks.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit

__all__ = ["ATOL_ROUNDOFF", "STIFFNESS_ROUNDOFF", "ENERGY_ROUNDOFF", "force_scale", "absolute_tolerance",
           "roundoff_floor", "max_abs"]

#: Absolute tolerance = ATOL_ROUNDOFF * eps * force_scale: a residual below it is round-off of the terms
#: that cancel in the assembled forces. Set below the attainable level (measured on B1, 256 BE2D
#: elements: max|r| stalls at 0.46 eps * force_scale) so that the stagnation test of the Newton solver,
#: not the tolerance, ends a solve whose residual cannot fall further; at 1.0 that solve stopped one
#: iteration early per load step and the tip moved 3.5e-9 m from the converged 4e-11 m error.
ATOL_ROUNDOFF = 0.1
#: Residual floor of the fixed-step steppers = STIFFNESS_ROUNDOFF * eps * max|K| * max(1, max|q|): the
#: round-off level of the elastic forces (measured 4e-7 N = 1.0 eps max|K| on the 25-element BE2D
#: pendulum, with spikes to 10x), above the relative test ``1e-8 max|r_0|`` of a 1e-4 s step (2.5e-7 N).
STIFFNESS_ROUNDOFF = 10.0
#: Residual floor of the energy-momentum stepper = ENERGY_ROUNDOFF * eps * max|dG/dq| * max(1, max|q|),
#: a tenth of the round-off of the elastic forces: the energy identity inherits the residual r as
#: (q1 - q0) . r, and a Newton stop above round-off leaves r biased along the step (measured on B2, BE2D,
#: 1 element, h = 5 ms: mean energy error per step 9.5e-18 J with the factor 1, 2.5e-19 J with 0.1 for
#: 0.3 more iterations per step).
ENERGY_ROUNDOFF = 0.1


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
        The equations of motion.
    t : float
        Time.
    q : ndarray, shape (n_dof,)
        Coordinates.
    v, a : ndarray, shape (n_dof,), optional
        Velocities and accelerations (zero by default: statics).

    Returns
    -------
    float
        Non-negative; ``ATOL_ROUNDOFF * eps * force_scale`` is the absolute
        tolerance below which a residual is round-off (:func:`absolute_tolerance`).
    """
    z = np.zeros_like(q)
    v = z if v is None else v
    a = z if a is None else a
    J = model.jacobian(t, q, v, a)

    def amax(x):
        if sp.issparse(x):   # the stored entries (implicit zeros cannot raise a max of |.|): no new matrix
            return float(np.abs(x.data).max()) if x.nnz else 0.0
        x = abs(x)
        return float(x.max()) if x.shape[0] else 0.0
    r = model.residual(t, q, z, z)
    return amax(J.K) * amax(q) + amax(J.D) * amax(v) + amax(J.M) * amax(a) + amax(r)


def absolute_tolerance(model, t: float, q: np.ndarray, v: np.ndarray | None = None,
                       a: np.ndarray | None = None) -> float:
    """Newton's default absolute tolerance on the residual: ``ATOL_ROUNDOFF * eps * force_scale``.

    Parameters
    ----------
    model, t, q, v, a
        As for :func:`force_scale`.

    Returns
    -------
    float
        In the residual's units.
    """
    return ATOL_ROUNDOFF * np.finfo(float).eps * force_scale(model, t, q, v, a)


def roundoff_floor(factor: float, K: sp.spmatrix | np.ndarray, q: np.ndarray) -> float:
    """``factor * eps * max|K| * max(1, max|q|)``: the round-off floor of a residual with stiffness ``K`` at ``q``.

    Parameters
    ----------
    factor : float
        :data:`STIFFNESS_ROUNDOFF` or :data:`ENERGY_ROUNDOFF`.
    K : sparse matrix or ndarray
        The stiffness just evaluated (its largest entry is the size of the terms that cancel).
    q : ndarray
        The coordinates it was evaluated at (``max(1, .)``: slopes are of order one).

    Returns
    -------
    float
        In the residual's units.
    """
    kmax = float(np.max(np.abs(K.data if sp.issparse(K) else K), initial=0.0))
    return factor * np.finfo(float).eps * kmax * max(1.0, float(np.max(np.abs(q))))


@njit(cache=True)
def max_abs(x):
    """``max|x|`` of a 1-D array, 0 when empty, NaN if any entry is NaN (inf propagates).

    One compiled pass: ``float(np.abs(x).max())`` costs 1.4 us on a Newton-sized
    vector, mostly call overhead, and runs three times per iteration.
    """
    m = 0.0
    for v in x:
        a = abs(v)
        if a != a:
            return a
        if a > m:
            m = a
    return m
