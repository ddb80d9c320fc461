"""An energy-momentum integrator for ANCF beams with a constant mass matrix.

The scheme
----------
With the residual split as ``M a + grad P(q) = f_nc(t, q)`` (constant ``M``, conservative
potential ``P = U + V`` of the strain energy and gravity, non-conservative loads ``f_nc``:
dead forces and moments), one step from ``(q0, v0)`` to ``(q1, v1)`` is::

    q1 - q0 = h (v0 + v1) / 2
    M (v1 - v0) = -h G(q0, q1) + h f_nc(t + h/2, (q0 + q1)/2)

with ``G`` a *discrete gradient* of ``P`` (``G . (q1 - q0) = P(q1) - P(q0)`` exactly, see
:mod:`ancfdae.integrators._discrete_gradient`). Multiplying the second line by
``v_mid = (v0 + v1)/2 = (q1 - q0)/h`` gives the discrete energy balance
``T1 - T0 + P1 - P0 = h f_nc,mid . v_mid``: the total energy changes by exactly the work
of the non-conservative loads evaluated with the midpoint rule, and stays constant, to
round-off and the Newton tolerance, once they vanish. The step reports that midpoint rule as
its :class:`~ancfdae.integrators.protocol.Quadrature` (one node at ``t + h/2`` with weight
``h``), so that an energy monitor's ``T + U + V - W_ext`` is constant under loads as well.
Symmetric, second order, one implicit system of ``n_dof`` unknowns per step (Lobatto IIIA-3
solves ``2 n_dof``).

Why this scheme
---------------
The energy-momentum idea (Simo and Tarnow, ZAMP 43:757, 1992; Gonzalez, J. Nonlinear Sci.
6:449, 1996 and Comput. Methods Appl. Mech. Eng. 190:1763, 2000; Betsch and Steinmann,
Comput. Methods Appl. Mech. Eng. 191:467, 2001) replaces the gradient in the midpoint rule by
a discrete gradient. ANCF makes it natural: the mass matrix is constant and
``M = m (x) I`` acts alike on every nodal vector, so the midpoint velocity update is already
momentum-neutral, and only ``G`` decides what is conserved. Strain-based discrete gradients
(Simo-Tarnow's algorithmic stress, Betsch-Steinmann) would need the strains at every
quadrature point of every element formulation; the two chosen here need nothing but the
potential, its gradient and its Hessian at arbitrary states, so they work on every element
of the package, and the user's own models, through one small capability
(:class:`ancfdae.problem.PotentialModel`):

* ``"avf"`` (default where ``P`` is a polynomial: SQ2D and SQ3D, continuum formulations,
  degree 4) -- the average vector field integral with a 2-point Gauss rule along the step,
  exact; smooth in the unknowns (no 0/0), Jacobian ``sum_j w_j s_j K(q_sj)``, as sparse as
  ``K``. Hairer's energy-preserving collocation (BIT 50:91, 2010) is its higher-order
  relative.
* ``"gonzalez"`` (default otherwise: BE2D, Cable3D, SQ2D/SQ3D structural, and available for
  every model) -- Gonzalez's midpoint discrete gradient, corrected along the mass-metric
  projection of the step off the rigid motions, which adds exact conservation of linear and
  angular momentum to that of energy. Its exact Jacobian is the sparse ``K(m)/2`` plus a
  dense term of rank ``k + 1`` (``k`` rigid motions), so its linear solves are dense.

What holds exactly (to round-off and the Newton tolerance)
-----------------------------------------------------------
* energy ``T + U + V`` after the loads end, and the balance ``T + U + V - W_ext`` with
  loads (``W_ext`` by the step's midpoint rule): every constant-mass element (BE2D,
  Cable3D, SQ2D, SQ3D), both formulations, either discrete gradient -- the discrete-gradient
  identity and the midpoint velocity (above). With ``"avf"`` only if ``P`` is a polynomial
  of the declared degree; the constructor refuses ``"avf"`` otherwise.
* linear momentum ``T^T M v`` (free beam, no gravity, under a pure moment or no load):
  both, because ``G . T = 0`` for a translation-invariant strain energy (the AVF integrand
  is orthogonal to ``T`` at every ``s``; the Gonzalez correction by construction), and a
  dead moment's generalised force has no resultant.
* angular momentum ``(M v) . (A_k q)`` (free beam, no loads): ``"gonzalez"`` with
  ``angular_momentum=True`` (the default) only.
  ``G . A_k m = 0`` because ``grad P(m) . A_k m = 0`` for a rotation-invariant ``P`` and the
  correction is orthogonal to ``A_k m``; with ``M A_k`` skew this gives the exact balance.
  ``"avf"`` evaluates the gradient off the midpoint and does not keep it (measured: 1.1e-3
  relative over 1.5 s, SQ3D continuum, 2 elements, h = 10 ms), nor does ``"gonzalez"`` with
  ``angular_momentum=False`` (6.2e-3 on the same run). The Gonzalez correction keeps the
  rotations out at a price: for a step that is nearly a rigid rotation its coefficient is a
  ratio of two small numbers, and Newton needs more iterations.
* supports break the symmetries: then no momentum is conserved and the Gonzalez correction
  is the plain mass-metric one; energy still holds exactly.
* constrained models (capability ``"constraints"``, joints of :mod:`ancfdae.joints`): the constraint
  forces enter through the midpoint Jacobian ``G(q_m)``, an exact discrete derivative for rows at most
  quadratic in ``q`` (``constraint_degree <= 2``, refused otherwise); energy is kept and ``g(t1, q1) = 0``
  holds to round-off (:mod:`ancfdae.integrators._em_constrained`).
* BE3D, BE3DSR (mass matrix depending on the slopes: the rotary inertia of the cross-section):
  the kinetic part of :mod:`._kinetic_gradient` (a discrete gradient of ``B = v0^T M(q) v1 / 2``)
  keeps the energy identity; between director updates the energy is kept to round-off, so the
  updates' jumps are the only change of the balance. No momentum is claimed; the Gonzalez
  gradient of the potential is corrected off the translations only. A model with a variable
  mass needs the ``"mass_forms"`` capability (:mod:`ancfdae.problem`), else a ValueError.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ancfdae import _validate as validate
from ancfdae._scale import ENERGY_ROUNDOFF
from ancfdae.integrators._alpha_index3 import mass_scale
from ancfdae.integrators._body_gradient import BodyWiseGradient, has_bodies
from ancfdae.integrators._discrete_gradient import AVFGradient, GonzalezGradient
from ancfdae.integrators._em_constrained import constrained_em_step
from ancfdae.kkt import KKTAssembler
from ancfdae.integrators._kinetic_gradient import KineticPart
from ancfdae.integrators._newton_records import NewtonOptions
from ancfdae.integrators._potential_split import require_potential_model, require_potential_split
from ancfdae.integrators.newton_stepper import NewtonStepper
from ancfdae.integrators.protocol import Quadrature, StepOutcome
from ancfdae.problem import Model, capabilities

__all__ = ["EnergyMomentum", "DISCRETE_GRADIENTS", "DEFAULT_NEWTON"]

DISCRETE_GRADIENTS = ("auto", "avf", "gonzalez")
#: Newton driven to round-off (the energy identity holds only for the converged step); the
#: iteration matrix is refreshed when the rate exceeds 0.1 rather than 0.3, with up to 40
#: iterations: on B3 with 8 SQ3D elements at h = 10 ms the 0.3 default converged at rate 0.3 and
#: ran out of 25 iterations at t = 2.35 s; with 0.1/40 the run reaches 4 s at 11.6 iterations per
#: step (full Newton: 7.3 iterations, 35 % more time).
DEFAULT_NEWTON = NewtonOptions(tol=1e-15, residual_atol=0.0, contraction=0.1, max_iter=40)


class EnergyMomentum(NewtonStepper):
    """Energy-momentum (discrete-gradient midpoint) integrator; see the module docstring.

    Parameters
    ----------
    model : Model with the ``"potential"`` capability
        Constant mass matrix (``mass_is_constant``), residual ``M a + dP/dq - f_nc(t, q)``
        (:class:`ancfdae.problem.PotentialModel`).
    h : float
        Step size (> 0); the last step is shortened to end at the bound.
    discrete_gradient : {"auto", "avf", "gonzalez"}
        ``"auto"``: ``"avf"`` when the model declares a polynomial potential
        (``potential_degree``), else ``"gonzalez"``.
    angular_momentum : bool
        ``"gonzalez"`` only: project the correction off the rotations as well (angular momentum
        exact; Newton slower when the motion is dominated by rigid rotation, see
        :class:`~ancfdae.integrators._discrete_gradient.GonzalezGradient`). False: off the
        translations only (linear momentum and energy exact).
    newton : NewtonOptions or dict, optional
        Default :data:`DEFAULT_NEWTON` (modified Newton, relative tolerance 1e-15, so that the
        residual floor decides; refresh at rate 0.1; 40 iterations). The floor is
        ``ENERGY_ROUNDOFF * eps * max|dG/dq| * max(1, max|q|)`` (:mod:`ancfdae._scale`); a
        stagnating iteration still ends by the solver's test on the correction.
    """

    name = "energy-momentum"
    order = 2
    fixed_step = True
    FLOOR_ROUNDOFF = ENERGY_ROUNDOFF
    FLOOR_UPDATE = "replace"     # the floor of the latest Jacobian (a running maximum moved energy and flying3d)
    handles_constraints = True

    def __init__(self, model: Model, h: float, *, discrete_gradient: str = "auto", angular_momentum: bool = True,
                 newton: NewtonOptions | dict | None = None) -> None:
        self.variable_mass = not getattr(model, "mass_is_constant", False)
        require_potential_model(model, "energy-momentum", variable_mass=True)
        if "constraints" in capabilities(model) and self.variable_mass:
            raise ValueError("`model` with constraints must have a constant mass matrix for method "
                             "'energy-momentum' (its constrained step uses M; mass_is_constant=False given).")
        if "constraints" in capabilities(model) and getattr(model, "constraint_degree", None) not in (1, 2):
            raise ValueError("`model` constraints must be at most quadratic in q (constraint_degree 1 or 2) for "
                             "method 'energy-momentum', whose midpoint constraint Jacobian is then an exact "
                             f"discrete derivative; got constraint_degree="
                             f"{getattr(model, 'constraint_degree', None)!r}.")
        super().__init__(model, h, newton=DEFAULT_NEWTON if newton is None else newton)
        validate.choice("discrete_gradient", discrete_gradient, DISCRETE_GRADIENTS)
        degree = getattr(model, "potential_degree", None)
        if discrete_gradient == "auto":
            # a System: body by body (momentum about the gravity axis kept; AVF is not rotation-equivariant)
            discrete_gradient = "avf" if degree is not None and not has_bodies(model) else "gonzalez"
        if discrete_gradient == "avf" and degree is None:
            raise ValueError("`discrete_gradient` 'avf' needs a polynomial potential (model.potential_degree), "
                             f"got potential_degree=None for {type(model).__name__}; use 'gonzalez'.")
        self.discrete_gradient = discrete_gradient
        if not isinstance(angular_momentum, bool):
            raise ValueError(f"`angular_momentum` must be True or False, got {angular_momentum!r}.")
        self.angular_momentum = angular_momentum
        self._bind(model)

    def _bind(self, model):
        """Mass matrix, its factorisation and the discrete gradient of ``model`` (a plain model).

        The discrete gradient evaluates ``self.model``, the counting proxy (its ``potential*`` calls
        show in the stats), which then wraps ``model``.
        """
        self._model_bound = model
        self._M = sp.csr_matrix(model.mass(model.initial_state()[0]))
        # M alone is factorised for the unconstrained step's acceleration only: a constrained model's M may be
        # singular (a lamina's director), its accelerations come from the saddle-point (KKT) system.
        constrained = "constraints" in capabilities(model)
        self._Mlu = None if constrained or self.variable_mass else spla.splu(sp.csc_matrix(self._M))
        degree = getattr(model, "potential_degree", None)
        if self.discrete_gradient == "avf":
            self._dg = AVFGradient(self.model, degree)
        elif has_bodies(model) and self.angular_momentum and not self.variable_mass:
            self._dg = BodyWiseGradient(model, counter=self.model)
        else:
            self._dg = GonzalezGradient(self.model, self._M, rotations=self.angular_momentum and not self.variable_mass)
        self._kin = KineticPart(self.model, self._M) if self.variable_mass else None

    def _setup(self):
        """The driver may hand another model instance: bind it; check the residual split."""
        super()._setup()
        if self.model.wrapped is not self._model_bound:
            self._bind(self.model.wrapped)
        require_potential_split(self.model, self.t, self.q, self.v, "energy-momentum",
                                variable_mass=self.variable_mass)
        self._constrained = "constraints" in capabilities(self.model)
        if self._constrained:
            self._mscale = mass_scale(self._M)
            self._kkt, self._kkt_out = KKTAssembler(), KKTAssembler()
            if self.lam is None:
                self.lam = np.zeros(self.model.n_constraints)

    def restart(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, model: Model) -> None:
        """Carry on from a state a model event changed (grid and Newton matrix kept; a new model rebound).

        Parameters
        ----------
        t, q, v, a, model
            As for :meth:`~ancfdae.integrators.Integrator.restart`.
        """
        super().restart(t, q, v, a, model)
        if self.model.wrapped is not self._model_bound:
            self._bind(self.model.wrapped)

    # -- one step ------------------------------------------------------------------------
    def _step_impl(self, t0, h):
        """One discrete-gradient midpoint step from the current state; the state is left unchanged."""
        if self._constrained:
            return constrained_em_step(self, t0, h)
        q0, v0 = self.q, self.v
        tm, t1 = t0 + 0.5 * h, t0 + h
        model, dg, M, c, kin = self.model, self._dg, self._M, 2.0 / (h * h), self._kin
        dg.start(tm, q0)
        hv0 = h * v0
        if kin is not None:
            kin.start(q0, v0, h)

        # Unknown: y = q1 - q0 - h v0 (the step's deviation from the free flight, O(h^2)). Then
        # v1 - v0 = 2 y / h is formed from y, not from q1 - q0: the energy identity's error is
        # (q1 - q0) . r + G . delta, with delta the rounding of q1 (eps |q| |G|) and r Newton's
        # residual, which y resolves to the round-off of the forces instead of eps |q| 2 |M| / h^2.
        def residual(y):
            u = hv0 + y
            f, _ = model.nonconservative_force(tm, q0 + 0.5 * u, False)
            inertia = kin.residual(y) if kin is not None else c * (M @ y)
            return inertia + dg.gradient(q0 + u) - f

        def jacobian(y):
            u = hv0 + y
            _, Kf = model.nonconservative_force(tm, q0 + 0.5 * u, True)
            J = dg.jacobian(q0 + u)
            floor = self.floor_of(J, q0 + u)      # dG/dq plays the stiffness' part
            if kin is not None:
                return (J.toarray() if sp.issparse(J) else J) + kin.jacobian(y) - 0.5 * Kf.toarray(), floor
            if sp.issparse(J):
                return sp.csr_matrix(c * M + J - 0.5 * Kf), floor
            return J + (c * M - 0.5 * Kf).toarray(), floor

        out = self._solve(residual, jacobian, self._predict(h))
        if not out.converged:
            return StepOutcome.failure(f"Newton: {out.message}")
        y = out.x
        q1 = q0 + (hv0 + y)
        v1 = v0 + (2.0 / h) * y
        # The acceleration at t1 (for interpolation and the next predictor): M a1 = -r(t1, q1, v1, 0).
        r1 = -np.asarray(model.residual(t1, q1, v1, np.zeros_like(q1)), dtype=float)
        a1 = spla.splu(sp.csc_matrix(model.mass(q1))).solve(r1) if kin is not None else self._Mlu.solve(r1)
        if not np.all(np.isfinite(a1)):
            return StepOutcome.failure(f"the acceleration at t = {t1:.9g} is not finite (the model's residual there)")
        quad = None
        if self.want_quadrature:
            # The scheme's own rule: midpoint state, velocity (q1 - q0)/h, weight h.
            quad = Quadrature(t=np.array([tm]), q=(q0 + 0.5 * (hv0 + y))[None, :], v=(v0 + y / h)[None, :],
                              w=np.array([h]))
        return StepOutcome(ok=True, t=t1, q=q1, v=v1, a=a1, quadrature=quad)

    def _predict(self, h):
        """Initial guess of ``y = q1 - q0 - h v0 = h^2 a / 2 + h^3 a' / 6 + O(h^4)``, with ``a'`` from
        the last two accelerations."""
        y = (0.5 * h * h) * self.a
        if self.previous is not None and self.t > self.previous[0]:
            y += (h ** 3 / (6.0 * (self.t - self.previous[0]))) * (self.a - self.previous[3])
        return y

    # -- records -------------------------------------------------------------------------
    @property
    def stats(self) -> dict:
        """Work counters since :meth:`initialize`.

        Newton's residual here is the discrete-gradient equation, not the model's residual: its
        evaluations count among ``residual_evals`` beside the model's (one per step, for the
        acceleration), and ``jacobian_evals`` are the evaluations of its matrix (a discrete
        gradient's Jacobian). ``potential_evals`` and ``potential_gradient_evals`` count the
        model's calls (every discrete-gradient pass, Jacobians included; on a System with the body-wise
        gradient, the bodies' calls).
        """
        st = super().stats
        st["residual_evals"] = self.newton.stats.residual_evals + self.model.n_residual
        st["jacobian_evals"] = self.newton.stats.jacobian_evals
        st["potential_gradient_evals"] = self.model.n_potential_gradient
        st["potential_evals"] = self.model.n_potential
        return st

    def options(self) -> dict:
        """The options as a JSON-able dict.

        Returns
        -------
        dict
            ``h``, the Newton options, ``discrete_gradient`` and ``angular_momentum``.
        """
        o = super().options()
        o["discrete_gradient"] = self.discrete_gradient
        o["angular_momentum"] = self.angular_momentum
        return o
