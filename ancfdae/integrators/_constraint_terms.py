"""What the constrained steppers evaluate beyond the ``"constraints"`` capability's own methods.

The capability (:data:`ancfdae.problem.CAPABILITIES`) gives ``g``, ``G = dg/dq``,
``H(lam) = d(G^T lam)/dq`` and ``(g_t, gamma)``. The stabilised index-2 (GGL) formulations of
Lobatto IIIA and IDA also need ``W(v) = d(G v + g_t)/dq = Z(v) + G_t`` (``Z(v) = d(G v)/dq``) in their
Newton matrices: :func:`velocity_constraint_jacobian` takes it from the model's optional
``constraint_velocity_jacobian`` or, without it, forms ``Z(v)`` exactly from ``m`` products
``H(e_i)`` (row ``i`` of ``Z(v)`` is ``v^T H(e_i)``) and leaves ``G_t`` out -- exact for scleronomic
constraints; for rheonomic ones the Newton matrix then lacks ``G_t`` (Newton still converges on the
exact residual, possibly in more iterations).

:func:`consistent_multipliers` solves the acceleration-level KKT system
``[[M, G^T], [G, 0]] [a; lam] = [-f; gamma]`` with ``f = r(t, q, v, 0)``.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ancfdae.problem import capabilities

__all__ = ["constraint_rows", "velocity_constraint_jacobian", "consistent_multipliers"]


def constraint_rows(model) -> int:
    """``model.n_constraints`` when the model declares ``"constraints"``, else 0 (checked).

    Raises
    ------
    TypeError
        When ``n_constraints`` is not a non-negative integer.
    """
    if "constraints" not in capabilities(model):
        return 0
    m = getattr(model, "n_constraints", None)
    if isinstance(m, bool) or not isinstance(m, (int, np.integer)) or m < 0:
        raise TypeError(f"{type(model).__name__} declares 'constraints' but its `n_constraints` is {m!r}; "
                        "it must be a non-negative integer.")
    return int(m)


def velocity_constraint_jacobian(model, t: float, q: np.ndarray, v: np.ndarray) -> sp.csr_matrix:
    """``d(G v + g_t)/dq`` at ``(t, q, v)`` as CSR (m, n); see the module docstring for the fallback.

    Parameters
    ----------
    model : Model with the ``"constraints"`` capability
    t : float
    q, v : ndarray, shape (n_dof,)

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n_constraints, n_dof)
    """
    fun = getattr(model, "constraint_velocity_jacobian", None)
    if callable(fun):
        return sp.csr_matrix(fun(t, q, v))
    m, n = model.n_constraints, q.size
    rows = []
    for i in range(m):
        e = np.zeros(m)
        e[i] = 1.0
        rows.append(sp.csr_matrix(model.constraint_force_jacobian(t, q, e)).T @ v)
    return sp.csr_matrix(np.array(rows).reshape(m, n))


def consistent_multipliers(model, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Accelerations and multipliers consistent with ``(t, q, v)``: ``M a + f + G^T lam = 0``, ``G a = gamma``.

    Parameters
    ----------
    model : Model with the ``"constraints"`` capability
    t : float
    q, v : ndarray, shape (n_dof,)

    Returns
    -------
    a : ndarray, shape (n_dof,)
    lam : ndarray, shape (n_constraints,)

    Raises
    ------
    ValueError
        When the KKT matrix is singular (redundant constraints: ``G`` without full row rank) or the
        solution is not finite.
    """
    n, m = q.size, model.n_constraints
    G = sp.csr_matrix(model.constraint_jacobian(t, q))
    _, gamma = model.constraint_rates(t, q, v)
    f = np.asarray(model.residual(t, q, v, np.zeros(n)), dtype=float)
    J = sp.bmat([[sp.csr_matrix(model.mass(q)), G.T], [G, None]], format="csc")
    try:
        x = spla.splu(J).solve(np.r_[-f, np.asarray(gamma, dtype=float)])
    except RuntimeError as exc:
        raise ValueError(f"the KKT matrix [[M, G^T], [G, 0]] at t = {t:g} is singular ({exc}); are some "
                         f"of the {m} constraint rows redundant (G without full row rank)?") from None
    if not np.all(np.isfinite(x)):
        raise ValueError(f"the consistent acceleration and multipliers at t = {t:g} are not finite.")
    return x[:n], x[n:]
