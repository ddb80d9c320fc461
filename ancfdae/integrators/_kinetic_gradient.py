"""The energy-momentum step's kinetic part for a configuration-dependent mass matrix (BE3D, BE3DSR).

With ``T = 1/2 v^T M(q) v`` the midpoint velocity update of :mod:`.energy_momentum` no longer gives the
energy identity. The step from ``(q0, v0)`` to ``(q1, v1)`` is instead::

    q1 - q0 = h (v0 + v1) / 2
    (M(q1) v1 - M(q0) v0) / h = -G(q0, q1) + K(q0, q1; v0, v1) + f_nc(t + h/2, (q0 + q1)/2)

``G`` the discrete gradient of the potential and ``K`` Gonzalez's discrete gradient of the bilinear form
``B(q) = 1/2 v0^T M(q) v1`` with ``v0, v1`` frozen (metric ``W``, ``d = q1 - q0``)::

    K = dB(m) + (B(q1) - B(q0) - dB(m) . d) / (d^T W d) W d,   m = (q0 + q1) / 2,

so that ``K . d = B(q1) - B(q0)``. Multiplying the second line by ``(v0 + v1)/2 = d/h``, the symmetric
``M`` gives ``T1 - T0 + B(q1) - B(q0)`` on the left, and the step keeps ``T + P - W_ext`` exactly (the
work by the midpoint rule): the discrete gradient of the Hamiltonian ``p^T M(q)^-1 p / 2 + P(q)`` written
in the velocities. For a constant ``M`` it is the scheme of :mod:`.energy_momentum` (``K = 0``). No
momentum is claimed. The model supplies ``mass_action`` and ``mass_bilinear`` (capability ``"mass_forms"``).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["KineticPart"]


class KineticPart:
    """The terms of one step that involve ``M(q)``: residual part and its exact Jacobian in ``y``.

    The unknown is ``y = q1 - q0 - h v0`` (as in :mod:`.energy_momentum`): ``q1 = q0 + h v0 + y``,
    ``v1 = v0 + 2 y / h``, ``m = q0 + (h v0 + y) / 2``, ``d = h v0 + y``.

    Parameters
    ----------
    model : Model with the ``"mass_forms"`` capability
    W : sparse matrix
        The metric of the Gonzalez correction (symmetric positive definite: the mass at the start).
    """

    def __init__(self, model, W) -> None:
        self.model, self.W = model, sp.csr_matrix(W)

    def start(self, q0: np.ndarray, v0: np.ndarray, h: float) -> None:
        """Fix the step's start."""
        self.q0, self.v0, self.h = q0, v0, h
        self.M0v0 = self.model.mass_action(q0, v0, False)[0]

    def _parts(self, y, order):
        q0, v0, h = self.q0, self.v0, self.h
        d = h * v0 + y
        q1, v1, m = q0 + d, v0 + (2.0 / h) * y, q0 + 0.5 * d
        M1v1, dM1v1 = self.model.mass_action(q1, v1, order >= 2)
        bil = self.model.mass_bilinear(m, v0, v1, order)
        gm = bil[1]
        n = self.W @ d
        D = float(n @ d)
        N = 0.5 * float(v0 @ M1v1) - 0.5 * float(v1 @ self.M0v0) - float(gm @ d)
        c = N / D if D > 0.0 else 0.0
        return d, q1, v1, m, M1v1, dM1v1, bil, n, D, c

    def residual(self, y: np.ndarray) -> np.ndarray:
        """``(M(q1) v1 - M(q0) v0) / h - K``."""
        d, q1, v1, m, M1v1, _, bil, n, D, c = self._parts(y, 1)
        return (M1v1 - self.M0v0) / self.h - (bil[1] + c * n)

    def jacobian(self, y: np.ndarray) -> np.ndarray:
        """The exact derivative of :meth:`residual` in ``y`` (dense: the correction has rank-one terms)."""
        h, v0, model = self.h, self.v0, self.model
        d, q1, v1, m, M1v1, dM1v1, bil, n, D, c = self._parts(y, 2)
        gm, Hm = bil[1], bil[2]
        M1 = model.mass(q1)
        g1 = model.mass_bilinear(q1, v0, v1, 1)[1]
        Xm = 0.5 * model.mass_action(m, v0, True)[1].T.toarray()        # d gm / d v1
        M1v0 = model.mass_action(q1, v0, False)[0]
        J = ((dM1v1 + (2.0 / h) * M1) / h).toarray() - 0.5 * Hm.toarray() - c * self.W.toarray() - (2.0 / h) * Xm
        if D > 0.0:
            dN_q = g1 - 0.5 * (Hm @ d) - gm                                  # dN/dy at fixed v1
            dN_v = 0.5 * M1v0 - 0.5 * self.M0v0 - Xm.T @ d                   # dN/dv1
            J -= np.outer(n, (dN_q - 2.0 * c * n) / D + (2.0 / h) * dN_v / D)
        return J
