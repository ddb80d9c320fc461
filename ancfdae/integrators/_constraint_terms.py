"""What the constrained steppers evaluate beyond the ``"constraints"`` capability's own methods.

The capability (:data:`ancfdae.problem.CAPABILITIES`) gives ``g``, ``G = dg/dq``,
``H(lam) = d(G^T lam)/dq`` and ``(g_t, gamma)``. The stabilised index-2 (GGL) formulations of
Lobatto IIIA and IDA also need ``W(v) = d(G v + g_t)/dq = Z(v) + G_t`` (``Z(v) = d(G v)/dq``) in their
Newton matrices: :func:`velocity_constraint_jacobian` takes it from the model's optional
``constraint_velocity_jacobian`` or, without it, forms ``Z(v)`` exactly from ``m`` products
``H(e_i)`` (row ``i`` of ``Z(v)`` is ``v^T H(e_i)``) and leaves ``G_t`` out -- exact for scleronomic
constraints; for rheonomic ones the Newton matrix then lacks ``G_t`` (Newton still converges on the
exact residual, possibly in more iterations).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["velocity_constraint_jacobian"]


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
