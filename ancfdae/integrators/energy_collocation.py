"""A fourth-order energy-preserving integrator: HBVM(k, 2), the energy-preserving Gauss collocation.

The scheme
----------
For ``M a + grad P(q) = f_nc(t, q)`` with a constant ``M`` (:class:`ancfdae.problem.PotentialModel`,
as for :class:`~ancfdae.integrators.EnergyMomentum`), one step seeks the acceleration over
``[t0, t0 + h]`` as a polynomial of degree 1 and the position ``sigma`` as one of degree 2, as the
2-stage Gauss collocation does, but projects the forces onto the polynomial basis with a ``k``-point
Gauss rule, ``k >= 2`` (the *silent stages*), instead of collocating at 2 points:

    M Y_i / h^2 = sum_l b_l P_i(c_l) F(t0 + c_l h, sigma(c_l h)),   i = 0, 1,   F = f_nc - grad P

(Hamiltonian boundary value method HBVM(k, 2): Brugnano, Iavernaro and Trigiante, JNAIAM 5:17, 2010;
the energy-preserving variant of collocation: Hairer, JNAIAM 5:73, 2010; the notation in
:mod:`ancfdae.integrators._hbvm_coefficients`). The unknowns are the two Legendre coefficients of the
acceleration, ``2 n_dof`` numbers as for Lobatto IIIA-3; only the number of force evaluations per
residual grows with ``k``.

What holds
----------
* Order 4 in ``q`` and ``v`` (``2 s``), symmetric, for every ``k >= 2``.
* Energy: ``T1 - T0 + P1 - P0 = h sum_l b_l f_nc(t_l, sigma_l) . sigma'_l`` whenever the ``k``-point
  rule integrates ``grad P(sigma(c)) . sigma'(c)`` exactly: for a polynomial ``P`` of degree
  ``nu <= k`` (``2 k / s``). The default ``k`` is therefore the declared ``potential_degree`` (4 for
  the St. Venant-Kirchhoff continuum formulations); for the other potentials (BE2D, Cable3D, the
  structural SQ formulations) :data:`SMOOTH_SILENT_STAGES`, where the energy error per step,
  ``O(h^(2k+1))``, lies below round-off at the steps that resolve the motion. The step hands that
  ``k``-point rule to the monitors (:class:`~ancfdae.integrators.Quadrature`: nodes ``t_l``,
  ``sigma_l``, ``sigma'_l``, weights ``h b_l``), so ``T + U + V - W_ext`` is constant under loads.
* Linear momentum ``T^T M v``: exact (the rule sums internal forces orthogonal to the translations).
  Angular momentum: not exact (the forces are evaluated off the configuration a rotation invariant
  needs); it drifts at the truncation error's size (``docs/energy_momentum.md``).

Newton
------
Modified Newton on the shared solver, driven to round-off as the energy identity needs (the
defaults of :data:`~ancfdae.integrators.energy_momentum.DEFAULT_NEWTON`). The exact Jacobian of the
stage equations is ``dR_i/dY_m = delta_im M / h^2 + sum_l C[i, m, l] K_l`` with the stiffness ``K_l``
at every node (real, ``2 n_dof`` square, interleaved, banded). The default iteration matrix freezes
one stiffness, at the step's midpoint: then ``sum_l C[:, :, l] = X^2`` and the matrix splits in the
eigenbasis of ``X`` (eigenvalues ``1/4 +- i / sqrt(48)``, those of Lobatto IIIA-3's implicit block)
into one complex ``n_dof`` square banded LU, as Lobatto IIIA-3 (:class:`~ancfdae.integrators._linsolve.StageMatrix`).
A step that fails with it is retried with the exact Jacobian; full Newton uses the exact Jacobian.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ancfdae import _validate as validate
from ancfdae._scale import ENERGY_ROUNDOFF
from ancfdae.integrators._hbvm_coefficients import hbvm_coefficients
from ancfdae.integrators._linsolve import StageMatrix
from ancfdae.integrators._newton_records import NewtonOptions
from ancfdae.integrators._potential_split import require_potential_model, require_potential_split
from ancfdae.integrators.energy_momentum import DEFAULT_NEWTON
from ancfdae.integrators.newton_stepper import NewtonStepper
from ancfdae.integrators.protocol import Quadrature, StepOutcome
from ancfdae.problem import JacobianBlocks, Model, capabilities

__all__ = ["EnergyCollocation", "SMOOTH_SILENT_STAGES", "ITERATION_MATRICES"]

#: Silent stages for a potential that is not a polynomial (chosen by measurement, see docs/energy_momentum.md).
SMOOTH_SILENT_STAGES = 6
ITERATION_MATRICES = ("split", "exact")
_S = 2          # fundamental stages: order 4


class _SplitMatrix(StageMatrix):
    """The frozen iteration matrix ``M / h^2 + K X^2`` for the unknowns ``Y = h^2 gamma``.

    :class:`StageMatrix` with ``a = X`` solves for ``gamma`` (acceleration units); the solution is
    scaled by ``h^2``.
    """

    def factorize(self):
        return _Scaled(super().factorize(), self.h * self.h)


class _Scaled:
    def __init__(self, inner, factor):
        self.inner, self.factor = inner, factor
        self.singular = getattr(inner, "singular", False)

    def solve(self, rhs):
        return self.factor * self.inner.solve(rhs)


def interleaved_pattern(indptr: np.ndarray, indices: np.ndarray, n: int, m: int) -> tuple:
    """Index map from per-entry block values ``(nnz, m, m)`` to an interleaved CSR of size ``n m``.

    Row ``p m + i``, column ``q m + j`` holds block ``(i, j)`` at ``(p, q)`` of the shared pattern.

    Returns
    -------
    order, big_indices, big_indptr : ndarray
        ``csr_matrix((vals.ravel()[order], big_indices, big_indptr))``.
    """
    nnz = indices.size
    row = np.repeat(np.arange(n), np.diff(indptr))
    e, i, j = (g.ravel() for g in np.meshgrid(np.arange(nnz), np.arange(m), np.arange(m), indexing="ij"))
    order = np.lexsort((j, e, i, row[e]))
    big_indices = (indices[e] * m + j)[order]
    big_indptr = np.r_[0, np.cumsum(np.repeat(np.diff(indptr) * m, m))]
    return order, big_indices, big_indptr


class EnergyCollocation(NewtonStepper):
    """HBVM(k, 2): order 4 and the energy kept exactly; see the module docstring.

    Parameters
    ----------
    model : Model with the ``"potential"`` capability
        Constant mass matrix (``mass_is_constant``), residual ``M a + dP/dq - f_nc(t, q)``.
    h : float
        Step size (> 0); the last step is shortened to end at the bound.
    silent_stages : int or "auto"
        ``k >= 2``, the Gauss nodes of the force projection. ``"auto"``: the declared
        ``potential_degree`` (at least 2; the energy is then exact), else :data:`SMOOTH_SILENT_STAGES`.
    iteration_matrix : {"split", "exact"}
        Modified Newton's matrix: ``"split"`` (one stiffness at the midpoint, one complex ``n_dof``
        LU; the default, chosen by measurement) or ``"exact"`` (the exact Jacobian, ``2 n_dof``
        real LU). Full Newton always uses the exact Jacobian.
    newton : NewtonOptions or dict, optional
        Default :data:`~ancfdae.integrators.energy_momentum.DEFAULT_NEWTON` (relative tolerance
        1e-15 so that the residual's round-off floor decides, refresh at rate 0.1, 40 iterations).
    """

    name = "energy-collocation"
    order = 4
    fixed_step = True
    FLOOR_ROUNDOFF = ENERGY_ROUNDOFF
    FLOOR_UPDATE = "replace"     # as energy-momentum: the energy identity needs the latest floor

    def __init__(self, model: Model, h: float, *, silent_stages: int | str = "auto",
                 iteration_matrix: str = "split", newton: NewtonOptions | dict | None = None) -> None:
        require_potential_model(model, self.name)
        super().__init__(model, h, newton=DEFAULT_NEWTON if newton is None else newton)
        degree = getattr(model, "potential_degree", None)
        if isinstance(silent_stages, str) and silent_stages == "auto":
            k = max(_S, int(degree)) if degree is not None else SMOOTH_SILENT_STAGES
        elif isinstance(silent_stages, (int, np.integer)) and not isinstance(silent_stages, bool) \
                and silent_stages >= _S:
            k = int(silent_stages)
        else:
            raise ValueError(f"`silent_stages` must be 'auto' or an integer >= {_S}, got {silent_stages!r}.")
        self.silent_stages = k
        self.iteration_matrix = validate.choice("iteration_matrix", iteration_matrix, ITERATION_MATRICES)
        self._co = hbvm_coefficients(k, _S)
        self._pattern = None

    def options(self) -> dict:
        """The options as a JSON-able dict: ``h``, the Newton options, ``silent_stages``, ``iteration_matrix``."""
        o = super().options()
        o.update(silent_stages=self.silent_stages, iteration_matrix=self.iteration_matrix)
        return o

    def _setup(self):
        """Mass matrix of the run's model, its factorisation, the split check; no predictor yet."""
        super()._setup()
        self._bind()
        require_potential_split(self.model, self.t, self.q, self.v, self.name)

    def _bind(self):
        m = self.model
        self._M = sp.csr_matrix(m.mass(self.q))
        self._Mlu = spla.splu(sp.csc_matrix(self._M))
        self._stages = "residual_stages" in capabilities(m)
        self._zeros = np.zeros((self.n_dof, self._co.k))
        self._prev = None          # (h, Y) of the last step: the predictor

    def restart(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, model: Model) -> None:
        """Carry on from a state a model event changed (the predictor is dropped, the model rebound)."""
        super().restart(t, q, v, a, model)
        self._bind()

    # -- the stage equations --------------------------------------------------------------------
    def _forces(self, ts, Q):
        """``-F = grad P - f_nc`` at the nodes (columns): the model's residual at zero velocity and acceleration."""
        if self._stages:
            return self.model.residual_stages(ts, Q, self._zeros, self._zeros)
        z = self._zeros[:, 0]
        return np.column_stack([self.model.residual(t, Q[:, l], z, z) for l, t in enumerate(ts)])

    def _exact(self, blocks, h):
        """The exact Jacobian ``delta_im M / h^2 + sum_l C[i, m, l] K_l``, interleaved CSR."""
        co, n = self._co, self.n_dof
        K0 = blocks[0].K
        same = all(b.same_pattern and b.K.indptr is K0.indptr and b.K.indices is K0.indices for b in blocks) \
            or all(b.same_pattern and np.array_equal(b.K.indptr, K0.indptr)
                   and np.array_equal(b.K.indices, K0.indices) for b in blocks)
        if same:
            if self._pattern is None or self._pattern[0] is not K0.indptr or self._pattern[1] is not K0.indices:
                self._pattern = (K0.indptr, K0.indices, *interleaved_pattern(K0.indptr, K0.indices, n, _S))
            _, _, order, big_indices, big_indptr = self._pattern
            Kd = np.stack([b.K.data for b in blocks])                  # (k, nnz)
            vals = np.einsum("iml,le->eim", co.C, Kd)                   # (nnz, s, s)
            Md = blocks[0].M.data / (h * h)
            for i in range(_S):
                vals[:, i, i] += Md
            return sp.csr_matrix((vals.ravel()[order], big_indices, big_indptr), shape=(_S * n, _S * n))
        out = None
        for i in range(_S):
            for m in range(_S):
                B = sum(co.C[i, m, l] * b.K for l, b in enumerate(blocks))
                if i == m:
                    B = B + self._M / (h * h)
                E = sp.csr_matrix(([1.0], ([i], [m])), shape=(_S, _S))
                term = sp.kron(B, E, format="csr")
                out = term if out is None else out + term
        return out.tocsr()

    def stage_equations(self, t0: float, h: float, split: list):
        """The step's equations from the current state: ``(residual(x), jacobian(x))`` of the unknowns
        ``x = Y.ravel()`` (interleaved); ``jacobian`` returns ``(matrix, floor)``, the split matrix while
        ``split[0]`` is true, else the exact Jacobian."""
        co, n, model = self._co, self.n_dof, self.model
        q0, v0 = self.q, self.v
        ts = t0 + co.c * h
        base = q0[:, None] + np.outer(h * v0, co.c)                     # sigma at the nodes without Y
        WqT, BPT, M, ih2 = co.Wq.T, co.BP.T, self._M, 1.0 / (h * h)
        zn = self._zeros[:, 0]

        def residual(x):
            Y = x.reshape(n, _S)
            return (ih2 * (M @ Y) + self._forces(ts, base + Y @ WqT) @ BPT).ravel()

        def jacobian(x):
            Y = x.reshape(n, _S)
            if split[0]:
                qm = q0 + 0.5 * h * v0 + Y @ co.mid
                blk = model.jacobian(t0 + 0.5 * h, qm, zn, zn)
                if blk.same_pattern:
                    K = blk.K
                    blk = JacobianBlocks(K, sp.csr_matrix((np.zeros_like(K.data), K.indices, K.indptr),
                                                          shape=K.shape), blk.M, True)
                    return _SplitMatrix(blk, h, co.X), self.floor_of(K, qm)
            Q = base + Y @ WqT
            blocks = [model.jacobian(t, Q[:, l], zn, zn) for l, t in enumerate(ts)]
            floor = max(self.floor_of(b.K, Q[:, l]) for l, b in enumerate(blocks))
            return self._exact(blocks, h), floor

        return residual, jacobian

    def _step_impl(self, t0, h):
        """One HBVM(k, 2) step from the current state; the state is left unchanged."""
        co, n, model = self._co, self.n_dof, self.model
        q0, v0 = self.q, self.v
        split = [self.iteration_matrix == "split" and self.newton.options.jacobian == "modified"]
        residual, jacobian = self.stage_equations(t0, h, split)
        guess = self._predict(h)
        out = self._solve(residual, jacobian, guess.ravel())
        if not out.converged and split[0]:
            # the one-stiffness matrix can be too crude where the nodes differ much: retry with the exact one
            split[0] = False
            self.newton.invalidate()
            out = self._solve(residual, jacobian, guess.ravel())
            self.newton.invalidate()       # the next step starts again from the split matrix
        if not out.converged:
            return StepOutcome.failure(f"Newton: {out.message}")
        Y = out.x.reshape(n, _S)
        t1 = t0 + h
        q1 = q0 + (h * v0 + Y @ co.q_end)
        v1 = v0 + Y[:, 0] / h
        # The acceleration at t1 (interpolation, the next step's first guess): M a1 = -r(t1, q1, v1, 0).
        a1 = self._Mlu.solve(-np.asarray(model.residual(t1, q1, v1, np.zeros_like(q1)), dtype=float))
        if not np.all(np.isfinite(a1)):
            return StepOutcome.failure(f"the acceleration at t = {t1:.9g} is not finite (the model's residual there)")
        self._prev = (h, Y)
        quad = None
        if self.want_quadrature:     # the scheme's own rule: the energy balance is exact with it
            quad = Quadrature(t=t0 + co.c * h, q=(q0[:, None] + np.outer(h * v0, co.c) + Y @ co.Wq.T).T,
                              v=(v0[:, None] + (Y @ co.Wd.T) / h).T, w=h * co.b)
        return StepOutcome(ok=True, t=t1, q=q1, v=v1, a=a1, quadrature=quad)

    def _predict(self, h):
        """The previous step's acceleration polynomial continued (same ``h``), else ``Y = (h^2 a, 0)``."""
        if self._prev is not None and self._prev[0] == h:
            return self._prev[1] @ self._co.predictor.T
        Y = np.zeros((self.n_dof, _S))
        Y[:, 0] = (h * h) * self.a
        return Y
