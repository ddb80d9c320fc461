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
residual grows with ``k``. Only the conservative force ``grad P`` needs the ``k`` nodes: the loads
``f_nc`` are projected with the 2-point Gauss rule (``k = 2``, the Gauss method's own rule, order 4).

What holds
----------
* Order 4 in ``q`` and ``v`` (``2 s``), symmetric, for every ``k >= 2``.
* Energy: ``T1 - T0 + P1 - P0 = h sum_j b_j f_nc(t_j, sigma_j) . sigma'_j`` (2 Gauss nodes ``j``) whenever the
  ``k``-point rule integrates ``grad P(sigma(c)) . sigma'(c)`` exactly: for a polynomial ``P`` of degree
  ``nu <= k`` (``2 k / s``), so the default ``k`` is the declared ``potential_degree`` (4 for the St.
  Venant-Kirchhoff continuum formulations). For the other potentials (BE2D, Cable3D, the structural SQ
  formulations) the rule misses ``O(h^(2k+1))`` per step: the velocity correction removes the balance
  computed from the model's potential (``energy_defect="potential"``), and ``k`` =
  :data:`CORRECTED_SILENT_STAGES` is chosen for the accuracy alone (:data:`SMOOTH_SILENT_STAGES` where the rule
  must keep the energy itself: ``energy_correction="newton"``). The step hands the loads' rule to the
  monitors (:class:`~ancfdae.integrators.Quadrature`), so ``T + U + V - W_ext`` is constant under loads.
* Linear momentum ``T^T M v``: exact (the rule sums internal forces orthogonal to the translations).
  Angular momentum: not exact (the forces are evaluated off the configuration a rotation invariant
  needs); it drifts at the truncation error's size (``docs/energy_momentum.md``).
* Constrained models (capability ``"constraints"``, rows at most quadratic in ``q``): a multiplier
  polynomial of degree 1 and two conditions per row keep ``g(t1, q1) = 0`` and the energy
  (:mod:`ancfdae.integrators._hbvm_constrained`).

Newton
------
Modified Newton on the shared solver. For any iterate ``Y`` with residual ``R`` the step's energy changes
by exactly ``sum_i V_i . R_i`` (``V = [h v0, 0] + Y X^T``, the Legendre coefficients of ``h sigma'``), so the
energy needs no Newton at round-off: by default (``energy_correction="velocity"``, unconstrained models)
Newton stops at Lobatto IIIA-3's relative tolerance 1e-8 and that known defect, with the momentum defect
``h T^T R_0``, is removed from ``v1`` (:mod:`ancfdae.integrators._energy_correction`). ``"newton"`` (constrained models) iterates on until
the defect is at round-off (the defaults of :data:`~ancfdae.integrators.energy_momentum.DEFAULT_NEWTON`,
the solver's ``accept``). The exact Jacobian of the
stage equations is ``dR_i/dY_m = delta_im M / h^2 + sum_l C[i, m, l] H_l - sum_j C'[i, m, j] Kf_j`` with
the Hessian ``H_l`` of ``P`` at every node and the load tangent ``Kf_j`` at the loads' nodes (real,
``2 n_dof`` square, interleaved, banded). The default iteration matrix freezes
one stiffness ``K`` of the residual, at the step's midpoint: then ``sum_l C[:, :, l] = X^2`` and the matrix splits in the
eigenbasis of ``X`` (eigenvalues ``1/4 +- i / sqrt(48)``, those of Lobatto IIIA-3's implicit block)
into one complex ``n_dof`` square banded LU, as Lobatto IIIA-3 (:class:`~ancfdae.integrators._linsolve.StageMatrix`).
A step that fails with it is retried with the exact Jacobian; full Newton uses the exact Jacobian.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae import _validate as validate
from ancfdae.kkt import KKTAssembler
from ancfdae._scale import ENERGY_ROUNDOFF
from ancfdae.integrators._alpha_index3 import mass_scale
from ancfdae.integrators._energy_correction import (PotentialDefect, VelocityCorrection, energy_defect, keep_residual,
                                                    round_off_test)
from ancfdae.integrators._hbvm_coefficients import hbvm_coefficients
from ancfdae.integrators._hbvm_constrained import constrained_hbvm_step
from ancfdae.integrators._hbvm_matrix import ExactMatrix, _SplitMatrix
from ancfdae.integrators._hbvm_options import (CORRECTED_SILENT_STAGES, ENERGY_CORRECTIONS, ENERGY_DEFECTS,
                                               SMOOTH_SILENT_STAGES, hbvm_options)
from ancfdae.integrators._hbvm_numba import stage_residual
from ancfdae.integrators._linsolve import factorize
from ancfdae.integrators._newton_records import NewtonOptions
from ancfdae.integrators._potential_split import require_potential_model, require_potential_split
from ancfdae.integrators.energy_momentum import DEFAULT_NEWTON
from ancfdae.integrators.newton_stepper import NewtonStepper
from ancfdae.integrators.protocol import Quadrature, StepOutcome
from ancfdae.problem import JacobianBlocks, Model, capabilities

__all__ = ["EnergyCollocation", "SMOOTH_SILENT_STAGES", "CORRECTED_SILENT_STAGES", "ITERATION_MATRICES",
           "ENERGY_CORRECTIONS", "ENERGY_DEFECTS", "CORRECTED_NEWTON"]

ITERATION_MATRICES = ("split", "exact")
#: Newton of ``energy_correction="velocity"``: the chapter's relative tolerance, as Lobatto IIIA-3; refresh at rate 0.2
#: (B3 8 SQ3D, h = 5 ms: 7.14 against 8.08 it/step at 0.3, 0.70 against 0.39 refreshes; docs/energy_momentum.md).
CORRECTED_NEWTON = NewtonOptions(tol=1e-8, contraction=0.2)
_S = 2          # fundamental stages: order 4


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
        ``potential_degree`` (at least 2; the energy is then exact), else :data:`CORRECTED_SILENT_STAGES`
        with the potential's own defect, :data:`SMOOTH_SILENT_STAGES` without it.
    iteration_matrix : {"split", "exact"}
        Modified Newton's matrix: ``"split"`` (one stiffness at the midpoint, one complex ``n_dof``
        LU; the default, chosen by measurement) or ``"exact"`` (the exact Jacobian, ``2 n_dof``
        real LU). Full Newton always uses the exact Jacobian.
    energy_correction : {"auto", "velocity", "newton"}
        ``"velocity"``: Newton to ``newton``'s tolerance, then the step's energy and momentum defects
        removed from ``v1`` (module docstring); ``"newton"``: Newton on to the energy's round-off (the
        only choice with constraints, which a change of ``v1`` alone would break). ``"auto"``: ``"newton"``
        for a constrained model, else ``"velocity"``.
    energy_defect : {"auto", "rule", "potential"}
        The defect the velocity correction removes: ``"rule"``, ``sum_i V_i . R_i`` (exact where the ``k``-point rule
        integrates the potential's power; free) or ``"potential"``, the balance from the model's ``potential`` (exact
        always; one call per step). "auto": "rule" if ``potential_degree <= k`` or with "newton", else "potential".
    newton : NewtonOptions or dict, optional
        Default :data:`CORRECTED_NEWTON` (the chapter's relative tolerance 1e-8, refresh at rate 0.2) with the velocity
        correction, else :data:`~ancfdae.integrators.energy_momentum.DEFAULT_NEWTON` (relative tolerance
        1e-15 so that the residual's round-off floor decides, refresh at rate 0.1, 40 iterations).
    """

    name = "energy-collocation"
    order = 4
    fixed_step = True
    handles_constraints = True
    FLOOR_ROUNDOFF = ENERGY_ROUNDOFF
    FLOOR_UPDATE = "replace"     # as energy-momentum: the energy identity needs the latest floor

    def __init__(self, model: Model, h: float, *, silent_stages: int | str = "auto",
                 iteration_matrix: str = "split", energy_correction: str = "auto", energy_defect: str = "auto",
                 newton: NewtonOptions | dict | None = None) -> None:
        require_potential_model(model, self.name)
        if "constraints" in capabilities(model) and getattr(model, "constraint_degree", None) not in (1, 2):
            raise ValueError("`model` constraints must be at most quadratic in q (constraint_degree 1 or 2) for "
                             f"method {self.name!r}, whose 3-point exactness of d g(sigma)/dc keeps the joints "
                             f"workless; got constraint_degree={getattr(model, 'constraint_degree', None)!r}.")
        correction, defect, k = hbvm_options(model, silent_stages, energy_correction, energy_defect)
        if newton is None:
            newton = CORRECTED_NEWTON if correction == "velocity" else DEFAULT_NEWTON
        super().__init__(model, h, newton=newton)
        self.energy_correction, self.energy_defect, self.silent_stages = correction, defect, k
        if correction == "velocity":      # Newton stops at a tolerance, as Lobatto IIIA-3: its floor and update
            self.FLOOR_ROUNDOFF, self.FLOOR_UPDATE = NewtonStepper.FLOOR_ROUNDOFF, NewtonStepper.FLOOR_UPDATE
        self.iteration_matrix = validate.choice("iteration_matrix", iteration_matrix, ITERATION_MATRICES)
        self._co = hbvm_coefficients(k, _S)
        self._loads = hbvm_coefficients(_S, _S)      # the 2-point Gauss rule of the loads
        self._exact_matrix = ExactMatrix(self._co, self._loads)
        co = self._co                                # the rules' matrices as the step uses them, formed once
        self._WqT, self._WlT, self._BPT = co.Wq.T.copy(), self._loads.Wq.T.copy(), co.BP.T.copy()
        self._BlT, self._eye = self._loads.BP.T.copy(), np.eye(_S)
        self._A = np.vstack([np.ones(k), co.c, self._WqT])     # sigma_l = [q0, h v0, Y] @ A[:, l]

    def options(self) -> dict:
        """The options as a JSON-able dict: ``h``, the Newton options, ``silent_stages``, ``iteration_matrix``."""
        o = super().options()
        o.update(silent_stages=self.silent_stages, iteration_matrix=self.iteration_matrix,
                 energy_correction=self.energy_correction, energy_defect=self.energy_defect)
        return o

    def _setup(self):
        """Mass matrix of the run's model, its factorisation, the split check; no predictor yet."""
        super()._setup()
        self._bind()
        require_potential_split(self.model, self.t, self.q, self.v, self.name)
        self._constrained = "constraints" in capabilities(self.model)
        self._stages = "potential_stages" in capabilities(self.model)
        self._projection = "potential_projection" in capabilities(self.model)
        if self._constrained:
            self._mscale = mass_scale(self._M)
            if self.lam is None:
                self.lam = np.zeros(self.model.n_constraints)

    def _bind(self):
        m = self.model
        self._M = sp.csr_matrix(m.mass(self.q))
        self._M_nz = self._M.copy()       # the residual's mass product over the nonzeros only (same sums)
        self._M_nz.eliminate_zeros()
        # M alone is factorised for the unconstrained step's acceleration only: a constrained model's M may be
        # singular (a lamina's axis director carries no mass), its accelerations come from the saddle-point
        # (KKT) system, regular on the constraint manifold.
        constrained = "constraints" in capabilities(m)
        # The shared factorisation (banded LAPACK for a beam's banded M): a SuperLU solve costs 30-140 us a call on
        # B3 against a few us, once per step.
        self._Mlu = None if constrained else factorize(self._M)
        self._kkt_out = KKTAssembler() if constrained else None
        z = np.zeros(self.n_dof)
        self._Mcsr = sp.csr_matrix(m.jacobian(self.t, self.q, z, z).M)   # the mass on the stiffness' pattern
        self._prev = None          # (h, Y) of the last step: the predictor
        self._correct = VelocityCorrection(m, self._M)
        self._balance = PotentialDefect(m, self._M, self._loads) if self.energy_defect == "potential" else None
        self._last_loads = (None, None)       # (x, loads at its nodes) of the last residual: the step's work

    def restart(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, model: Model) -> None:
        """Carry on from a state a model event changed (the predictor is dropped, the model rebound)."""
        super().restart(t, q, v, a, model)
        self._bind()

    # -- the stage equations --------------------------------------------------------------------
    def _nodes(self, t0, h, Y, co):
        """Times and positions ``sigma`` of the nodes of the rule ``co`` for the unknowns ``Y``."""
        return t0 + co.c * h, self.q[:, None] + np.outer(h * self.v, co.c) + Y @ co.Wq.T

    def _forces(self, t0, h, Y):
        """``sum_l BP[i, l] (grad P - f_nc)(sigma_l)``: the conservative force at the ``k`` nodes, the
        loads at the 2 Gauss nodes (the Gauss method's own rule: order 4, and the work of the loads is
        that rule's, handed to the monitors)."""
        return self._force_terms(t0, h)(Y)

    def _force_terms(self, t0, h):
        """:meth:`_forces` of the step from ``(t0, q, v)`` as a function of ``Y`` alone (see :meth:`_stage_values`)."""
        values, BlT = self._stage_values(t0, h), self._BlT

        def forces(Y):
            G, F = values(Y)
            return G - F @ BlT

        return forces

    def _stage_values(self, t0, h):
        """``values(Y) -> (G, F)``: ``sum_l BP[i, l] grad P(sigma_l)`` over the ``k`` nodes (n_dof, 2) and ``f_nc``
        at the 2 Gauss nodes (n_dof, 2) of the step from ``(t0, q, v)``; the nodes' parts that do not depend on
        ``Y`` formed once per step. Where the model offers it (capability ``"potential_projection"``) the nodes
        ``sigma_l = [q0, h v0, Y] @ [1; c_l; Wq[l]]``, their gradients and the projection are one compiled call;
        else the ``k`` gradients in one model call (``"potential_stages"``) or one call per node, projected here."""
        m, co, ld = self.model, self._co, self._loads
        ts, tl = t0 + co.c * h, t0 + ld.c * h
        base_l = self.q[:, None] + np.outer(h * self.v, ld.c)
        WqT, WlT, BPT = self._WqT, self._WlT, self._BPT
        gradient, load = m.potential_gradient, m.nonconservative_force
        projection, stages, n = self._projection, self._stages, self.n_dof
        if projection:
            Z = np.empty((self.n_dof, 2 + _S))
            Z[:, 0], Z[:, 1] = self.q, h * self.v
            A = self._A
        else:
            base = self.q[:, None] + np.outer(h * self.v, co.c)

        def values(Y):
            if projection:
                Z[:, 2:] = Y
                G = m.potential_gradient_projection(ts, Z, A, BPT)
            else:
                Q = base + Y @ WqT
                if stages:
                    G = m.potential_gradient_stages(ts, Q)
                else:
                    G = np.column_stack([gradient(t, Q[:, l], False)[0] for l, t in enumerate(ts)])
                G = G @ BPT
            Q = base_l + Y @ WlT
            F = np.empty((n, _S))       # filled column by column: np.column_stack costs ~4 us a call
            for j in range(_S):
                F[:, j] = load(tl[j], Q[:, j], False)[0]
            return G, F

        return values

    def _exact(self, t0, h, Y):
        """The exact Jacobian ``delta_im M / h^2 + sum_l C[i, m, l] H_l - sum_j Cnc[i, m, j] Kf_j`` (Hessians
        ``H_l`` of ``P`` at the ``k`` nodes, load tangents ``Kf_j`` at the 2 Gauss nodes), interleaved CSR,
        and the round-off floor of the largest Hessian."""
        m, co, ld = self.model, self._co, self._loads
        ts, Q = self._nodes(t0, h, Y, co)
        H = [m.potential_gradient(t, Q[:, l], True)[1] for l, t in enumerate(ts)]
        floor = max(self.floor_of(K, Q[:, l]) for l, K in enumerate(H))
        ts, Q = self._nodes(t0, h, Y, ld)
        Kf = [m.nonconservative_force(t, Q[:, l], True)[1] for l, t in enumerate(ts)]
        return self._assemble(H, Kf, h), floor

    def _assemble(self, H, Kf, h):
        """``delta_im M / h^2 + sum_l C[i, m, l] H[l] - sum_j Cnc[i, m, j] Kf[j]`` as an interleaved CSR."""
        return self._exact_matrix(H, Kf, self._Mcsr, h)

    def stage_equations(self, t0: float, h: float, split: list) -> tuple:
        """The step's equations from the current state: ``(residual(x), jacobian(x))`` of the unknowns
        ``x = Y.ravel()`` (interleaved); ``jacobian`` returns ``(matrix, floor)``, the split matrix while
        ``split[0]`` is true, else the exact Jacobian."""
        co, n, model = self._co, self.n_dof, self.model
        q0, v0 = self.q, self.v
        ih2 = 1.0 / (h * h)
        zn = np.zeros(n)

        values, eye, BlT = self._stage_values(t0, h), self._eye, self._BlT
        mass = (self._M_nz.data, self._M_nz.indptr, self._M_nz.indices)

        def residual(x):      # M Y / h^2 + G - F BL^T in one compiled call (G projected already)
            Y = x.reshape(n, _S)
            G, F = values(Y)
            self._last_loads = (x, F)
            R = np.empty((n, _S))
            stage_residual(Y, np.asarray(G, dtype=float), eye, np.asarray(F, dtype=float), BlT, *mass, ih2, R)
            return R.ravel()

        def jacobian(x):
            Y = x.reshape(n, _S)
            if split[0]:
                qm = q0 + 0.5 * h * v0 + Y @ co.mid
                blk = model.jacobian(t0 + 0.5 * h, qm, zn, zn)
                if blk.same_pattern:
                    K = blk.K
                    if blk.D.data.any():      # the scheme has no velocity term; an undamped model's D is zero already
                        blk = JacobianBlocks(K, sp.csr_matrix((np.zeros_like(K.data), K.indices, K.indptr),
                                                              shape=K.shape), blk.M, True)
                    return _SplitMatrix(blk, h, co.X), self.floor_of(K, qm)
            return self._exact(t0, h, Y)

        return residual, jacobian

    def _step_impl(self, t0, h):
        """One HBVM(k, 2) step from the current state; the state is left unchanged."""
        if self._constrained:
            return constrained_hbvm_step(self, t0, h)
        co, n, model = self._co, self.n_dof, self.model
        q0, v0 = self.q, self.v
        split = [self.iteration_matrix == "split" and self.newton.options.jacobian == "modified"]
        guess = self._predict(h).ravel()
        out, r = self._solve_full(t0, h, split, guess)
        if not out.converged:
            return StepOutcome.failure(f"Newton: {out.message}")
        Y = out.x.reshape(n, _S)
        t1 = t0 + h
        q1 = q0 + (h * v0 + Y @ co.q_end)
        v1 = v0 + Y[:, 0] / h
        if r is not None:
            R = r.reshape(n, _S)
            v1c = self._correct(h, v1, R[:, 0], self._defect(t0, h, out.x, R, q1, v1))
            if v1c is None:     # a body near rest cannot carry the defect in its velocity: iterate to round-off
                residual, jacobian = self.stage_equations(t0, h, split)
                out = self._solve(residual, jacobian, out.x, accept=round_off_test(self._M, co.X, h, v0))
                if not out.converged:
                    return StepOutcome.failure(f"Newton: {out.message}")
                Y = out.x.reshape(n, _S)
                q1 = q0 + (h * v0 + Y @ co.q_end)
                v1c = v0 + Y[:, 0] / h
                if self._balance is not None:     # the rule's own error is left: removed where the velocity can
                    v1r = self._correct(h, v1c, np.zeros(n), self._defect(t0, h, out.x, None, q1, v1c))
                    v1c = v1c if v1r is None else v1r
            v1 = v1c
        # The acceleration at t1 (interpolation, the next step's first guess): M a1 = -r(t1, q1, v1, 0).
        a1 = self._Mlu.solve(-np.asarray(model.residual(t1, q1, v1, np.zeros_like(q1)), dtype=float))
        if not np.all(np.isfinite(a1)):
            return StepOutcome.failure(f"the acceleration at t = {t1:.9g} is not finite (the model's residual there)")
        self._prev = (h, Y)
        quad = None
        if self.want_quadrature:     # the loads' rule: the energy balance is exact with it
            ld = self._loads
            ts, Q = self._nodes(t0, h, Y, ld)
            quad = Quadrature(t=ts, q=Q.T, v=(v0[:, None] + (Y @ ld.Wd.T) / h).T, w=h * ld.b)
        return StepOutcome(ok=True, t=t1, q=q1, v=v1, a=a1, quadrature=quad)

    def _solve_full(self, t0, h, split, guess):
        """Newton on the full stage residual: ``(outcome, residual at outcome.x)`` for the velocity correction,
        ``(outcome, None)`` with ``energy_correction="newton"`` (Newton on to the energy's round-off)."""
        residual, jacobian = self.stage_equations(t0, h, split)
        last = {}
        velocity = self.energy_correction == "velocity"
        accept = keep_residual(last) if velocity else round_off_test(self._M, self._co.X, h, self.v)
        out = self._solve(residual, jacobian, guess, accept=accept)
        if not out.converged and split[0]:
            # the one-stiffness matrix can be too crude where the nodes differ much: retry with the exact one
            split[0] = False
            self.newton.invalidate()
            out = self._solve(residual, jacobian, guess, accept=accept)
            self.newton.invalidate()       # the next step starts again from the split matrix
        if not (out.converged and velocity):
            return out, None
        return out, (last["r"] if last.get("x") is out.x else residual(out.x))

    def _defect(self, t0, h, x, R, q1, v1):
        """The energy defect the velocity correction removes (``energy_defect``; ``R``: the residual at ``x``)."""
        Y, v0, ld = x.reshape(self.n_dof, _S), self.v, self._loads
        if self._balance is None:
            return energy_defect(Y, R, self._co.X, h * v0)
        x_F, F = self._last_loads            # the loads at x's nodes when x's residual was the last one evaluated
        if x_F is not x:
            ts, Q = self._nodes(t0, h, Y, ld)
            F = np.column_stack([self.model.nonconservative_force(t, Q[:, j], False)[0] for j, t in enumerate(ts)])
        return self._balance(t0, h, self.q, v0, q1, v1, Y, F)

    def _predict(self, h):
        """The previous step's acceleration polynomial continued (same ``h``), else ``Y = (h^2 a, 0)``."""
        if self._prev is not None and self._prev[0] == h:
            return self._prev[1] @ self._co.predictor.T
        Y = np.zeros((self.n_dof, _S))
        Y[:, 0] = (h * h) * self.a
        return Y

