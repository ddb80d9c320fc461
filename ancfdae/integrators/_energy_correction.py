"""The velocity correction of the energy-preserving collocation: exact energy and linear momentum after a
Newton solve stopped at a tolerance.

The step's stage equations ``R(Y) = 0`` (:mod:`ancfdae.integrators.energy_collocation`) give, for *any*
``Y`` and its residual ``R``, the two identities (``V = [h v0, 0] + Y X^T`` the Legendre coefficients of
``h sigma'``, ``T`` the translations of :meth:`~ancfdae.problem.PotentialModel.symmetry_generators`)::

    T1 - T0 + P1 - P0 - W = sum_i V_i . R_i                      (energy, exact rule)
    T^T M (v1 - v0) = - h T^T F_0 + h T^T R_0                    (linear momentum; F_0 the mean force)

so a solve stopped at a relative residual ``tol`` leaves an energy defect ``D = sum_i V_i . R_i`` and a
momentum defect ``h T^T R_0`` that are *known* from the last residual. Rather than iterating on to
round-off (1 to 2 more iterations per step, each evaluating the potential at every silent stage), the
step removes both from the new velocity ``v1`` alone: first the rigid translation ``T c`` with
``T^T M T c = -h T^T R_0``, then it scales the velocity relative to the translations,
``w = v1 - T (T^T M T)^{-1} T^T M v1``, by ``1 + alpha`` so that ``T(v1) = T(v1_Newton) - D``.
``w`` is ``M``-orthogonal to the translations: the scaling keeps the momentum just restored. The
correction is of the size of the Newton tolerance (``alpha ~ D / T_w``): it keeps the order.
Angular momentum is not exact under the scheme anyway; the scaling changes it by ``alpha`` times its
relative part. Without translations (a support) only the scaling applies, to the whole velocity.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae.integrators._csr_numba import csr_matvec
from ancfdae.integrators._hbvm_numba import kinetic_work, velocity_correction

__all__ = ["VelocityCorrection", "PotentialDefect", "MAX_SCALING", "ENERGY_DEFECT", "energy_defect", "round_off_test",
           "keep_residual"]

_EPS = float(np.finfo(float).eps)
#: Newton's round-off test accepts a step when the energy defect is below this times eps times its terms' size.
ENERGY_DEFECT = 1.0

#: The scaling is refused (the step then iterates to round-off instead) when the defect exceeds this share
#: of the kinetic energy relative to the translations: a body near rest, whose ``w`` cannot carry it.
MAX_SCALING = 0.5


class VelocityCorrection:
    """Remove a step's energy and linear-momentum defects from its new velocity (module docstring).

    Parameters
    ----------
    model : PotentialModel
        Its ``symmetry_generators()`` give the translations (none: no momentum correction).
    M : sparse matrix
        The constant mass matrix.
    """

    def __init__(self, model, M) -> None:
        T = np.zeros((M.shape[0], 0))
        generators = getattr(model, "symmetry_generators", None)
        if generators is not None:
            T = np.asarray(generators()[0], dtype=float).reshape(M.shape[0], -1)
        M = _nonzeros(M)
        self._M = (M.indptr, M.indices, M.data)     # M v compiled: scipy's product costs 20-30 us to call
        self._T = np.ascontiguousarray(T, dtype=float)
        self._MT = np.ascontiguousarray(M @ T, dtype=float) if T.shape[1] else self._T
        # (T^T M T)^-1, the translations' mass (d x d): every product below is with it or the dense M T
        self._TMT_inv = np.linalg.inv(T.T @ self._MT) if T.shape[1] else np.zeros((0, 0))

    def __call__(self, h: float, v1: np.ndarray, R0: np.ndarray, defect: float) -> np.ndarray | None:
        """The corrected ``v1``, or None when the scaling cannot carry ``defect`` (:data:`MAX_SCALING`).

        One compiled call (:func:`~ancfdae.integrators._hbvm_numba.velocity_correction`; the dozen NumPy products
        of :meth:`reference` cost ~30 us a step, a tenth of energy-collocation's overhead per step on B2); equal
        to :meth:`reference` to a few ulp (test)."""
        out = np.empty(v1.size)
        indptr, indices, data = self._M
        status = velocity_correction(data, indptr, indices, self._T, self._MT, self._TMT_inv,
                                     np.ascontiguousarray(v1, dtype=float), np.ascontiguousarray(R0, dtype=float),
                                     float(h), float(defect), MAX_SCALING, out)
        return None if status == 1 else out

    def reference(self, h: float, v1: np.ndarray, R0: np.ndarray, defect: float) -> np.ndarray | None:
        """:meth:`__call__` in NumPy, the readable reference.

        Parameters
        ----------
        h : float
            The step.
        v1 : ndarray
            The velocity at the step's end from Newton's last iterate.
        R0 : ndarray
            The stage residual's first Legendre row at that iterate.
        defect : float
            ``D = sum_i V_i . R_i`` at that iterate.

        Notes
        -----
        One sparse product ``M v1`` (compiled); the rest are products with the ``d`` translations (``M T`` dense).
        """
        T, MT, inv = self._T, self._MT, self._TMT_inv
        Mv = csr_matvec(*self._M, v1)
        target = 0.5 * float(v1 @ Mv) - defect
        if T.shape[1]:
            dc = inv @ (-h * (T.T @ R0))            # the momentum's translation velocity
            v1 = v1 + T @ dc
            Mv = Mv + MT @ dc
            p = T.T @ Mv                            # the momentum T^T M v1
            c = inv @ p
            vt = T @ c
            kin_t = 0.5 * float(c @ p)
        else:
            vt, kin_t = 0.0, 0.0
        kin_w = 0.5 * float(v1 @ Mv) - kin_t       # w = v1 - vt is M-orthogonal to vt
        w = v1 - vt
        if not kin_w > 0.0:
            return None if defect != 0.0 else v1
        delta = (target - kin_t - kin_w) / kin_w        # (1 + alpha)^2 = 1 + delta
        if not abs(delta) <= MAX_SCALING:
            return None
        alpha = delta / (np.sqrt(1.0 + delta) + 1.0)
        return vt + (1.0 + alpha) * w


class PotentialDefect:
    """The step's energy defect from the model's own energy: ``D = T(v1) + P(q1) - T(v0) - P(q0) - W``.

    ``sum_i V_i . R_i`` (:func:`energy_defect`) is the step's energy defect only where the ``k``-point rule
    integrates ``grad P(sigma) . sigma'`` exactly (a polynomial ``P`` of degree ``<= k``); otherwise it misses
    the rule's error, ``O(h^(2k+1))`` per step. This defect is the balance itself, exact for every potential,
    at the price of one :meth:`~ancfdae.problem.PotentialModel.potential` call per step (``P(q0)`` is the
    previous step's ``P(q1)`` while the state is that step's). ``W`` is the loads' work by the step's own rule
    (the one handed to the monitors), so ``T + U + V - W_ext`` is what the correction keeps; ``T`` and ``W`` in
    one compiled pass (:func:`~ancfdae.integrators._hbvm_numba.kinetic_work`).

    Parameters
    ----------
    model : PotentialModel
    M : sparse matrix
        The constant mass matrix.
    loads : HBVMCoefficients
        The loads' rule (nodes, ``Wd``, weights ``b``).
    """

    def __init__(self, model, M, loads) -> None:
        M = _nonzeros(M)
        self._model, self._M = model, (M.data, M.indptr, M.indices)
        self._WdT, self._b = np.ascontiguousarray(loads.Wd.T), np.ascontiguousarray(loads.b)
        self._last = (None, 0.0)          # (q1, P(q1)) of the last call: P(q0) of the next step

    def __call__(self, t0: float, h: float, q0: np.ndarray, v0: np.ndarray, q1: np.ndarray, v1: np.ndarray,
                 Y: np.ndarray, F: np.ndarray) -> float:
        """``D`` of the step ``(t0, q0, v0) -> (t0 + h, q1, v1)`` with unknowns ``Y`` and loads ``F`` at the loads'
        nodes (n_dof, 2)."""
        model = self._model
        last_q, P0 = self._last
        if last_q is not q0:
            P0 = float(model.potential(t0, q0))
        P1 = float(model.potential(t0 + h, q1))
        self._last = (q1, P1)
        dT, W = kinetic_work(*self._M, v0, v1, np.ascontiguousarray(F, dtype=float), Y, self._WdT, self._b, h)
        return dT + (P1 - P0) - W


def _nonzeros(M) -> sp.csr_matrix:
    """``M`` as a CSR copy without its stored zeros: a beam's mass keeps the stiffness' pattern (B3, 16 SQ3D: 1161
    nonzeros of 10449 stored entries), and the products here run once a step over what is stored."""
    M = sp.csr_matrix(M, dtype=float, copy=True)
    M.eliminate_zeros()
    return M


def energy_defect(Y: np.ndarray, R: np.ndarray, X: np.ndarray, hv: np.ndarray) -> float:
    """``D = sum_i V_i . R_i``, ``V = [h v0, 0] + Y X^T`` (``Y``, ``R``: (n_dof, 2); ``hv = h v0``)."""
    V = Y @ X.T
    V[:, 0] += hv
    return float(np.sum(V * R))


def round_off_test(M, X: np.ndarray, h: float, v0: np.ndarray):
    """Newton's ``accept`` of ``energy_correction="newton"``: the step's energy identity holds to round-off.

    A residual at its round-off floor is not enough: it leaves ``R`` biased along the step, and the defect
    piles up (one SQ3D element, 2000 steps of 10 ms: 9.1e-13 of the energy with the floor alone, 3.1e-14
    with this test). Accepted when ``|sum V . R|`` is below ``ENERGY_DEFECT * eps`` times the sum of the
    terms' magnitudes ``|V| (|A| + |R - A|)``, ``A = M Y / h^2``; Newton also stops when its correction no
    longer halves (round-off reached).
    """
    n, hv, ih2 = v0.size, h * v0, 1.0 / (h * h)

    def accept(x, r):
        Y, R = x.reshape(n, 2), r.reshape(n, 2)
        V = Y @ X.T
        V[:, 0] += hv
        A = ih2 * (M @ Y)
        scale = float(np.sum(np.abs(V) * (np.abs(A) + np.abs(R - A))))
        return abs(float(np.sum(V * R))) / (ENERGY_DEFECT * _EPS * scale + 1e-300)

    return accept


def keep_residual(last: dict):
    """Newton's ``accept`` of ``energy_correction="velocity"``: accepts, and keeps the converged iterate and
    its residual in ``last`` (the correction needs that residual; the solver has evaluated it already)."""

    def accept(x, r):
        last["x"], last["r"] = x, r
        return 0.0

    return accept
