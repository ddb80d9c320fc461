"""The contract between models and integrators.

A *Model* is the semi-discrete equation of motion in residual form, with the
boundary conditions already applied (fixed coordinates eliminated)::

    r(t, q, v, a) = M(q) a + f_int(q, v) - f_ext(t, q, v) = 0

Integrators -- ours and a user's own -- need nothing but this protocol.
"""
from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
import scipy.sparse as sp

__all__ = ["Model", "JacobianBlocks", "Energy", "CAPABILITIES", "capabilities", "PotentialModel",
           "ConstrainedModel"]


@dataclass(frozen=True)
class JacobianBlocks:
    """Partial derivatives of the residual ``r(t, q, v, a)``.

    Attributes
    ----------
    K : scipy.sparse matrix
        ``dr/dq`` (tangent stiffness, including load and inertia terms that
        depend on ``q``).
    D : scipy.sparse matrix
        ``dr/dv`` (damping and velocity-dependent inertia).
    M : scipy.sparse matrix
        ``dr/da`` (the mass matrix).
    same_pattern : bool
        True when ``K``, ``D`` and ``M`` are CSR matrices sharing one
        sparsity structure (identical ``indptr`` and ``indices``); then an
        iteration matrix ``alpha*K + beta*D + gamma*M`` can be formed by
        combining the ``data`` arrays alone (see :meth:`combine`).
    """

    K: sp.spmatrix
    D: sp.spmatrix
    M: sp.spmatrix
    same_pattern: bool = False

    def combine(self, alpha: float, beta: float, gamma: float) -> sp.csr_matrix:
        """Return ``alpha*K + beta*D + gamma*M`` as a CSR matrix.

        Uses the shared pattern when available (no sparse addition, no
        pattern reallocation), otherwise falls back to sparse arithmetic.
        """
        if self.same_pattern:
            data = alpha * self.K.data + beta * self.D.data + gamma * self.M.data
            return sp.csr_matrix((data, self.K.indices, self.K.indptr), shape=self.K.shape)
        return sp.csr_matrix(alpha * self.K + beta * self.D + gamma * self.M)


@dataclass(frozen=True)
class Energy:
    """Mechanical energies of a state.

    Attributes
    ----------
    kinetic : float
        ``T = 1/2 v^T M(q) v``.
    strain : float
        Strain energy ``U(q)`` of the elastic forces.
    potential : float
        Potential ``V(t, q)`` of the conservative loads (e.g. gravity).
    """

    kinetic: float
    strain: float
    potential: float = 0.0

    @property
    def total(self) -> float:
        """``T + U + V``."""
        return self.kinetic + self.strain + self.potential


@runtime_checkable
class Model(Protocol):
    """Semi-discrete equations of motion ``M(q) a + f_int(q, v) - f_ext(t, q, v) = 0``.

    Attributes
    ----------
    n_dof : int
        Number of (free) coordinates.
    mass_is_constant : bool
        True when ``M`` does not depend on ``q`` (every ANCF element except
        BE3D, whose cross-section rotary inertia depends on the slopes).

    Notes
    -----
    ``jacobian`` must be exact (analytic or automatic differentiation),
    never finite differences at run time. What a model offers beyond this
    contract it declares in ``capabilities`` (see :data:`CAPABILITIES` and
    :func:`capabilities`); solvers use nothing undeclared.
    """

    n_dof: int
    mass_is_constant: bool

    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Initial coordinates and velocities ``(q0, v0)``."""
        ...

    def mass(self, q: np.ndarray) -> sp.spmatrix:
        """Mass matrix ``M(q)``."""
        ...

    def residual(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """Residual ``r(t, q, v, a)``, shape ``(n_dof,)``."""
        ...

    def jacobian(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> JacobianBlocks:
        """Exact ``dr/dq``, ``dr/dv``, ``dr/da``."""
        ...

    def energy(self, t: float, q: np.ndarray, v: np.ndarray) -> Energy:
        """Kinetic, strain and conservative-load potential energy."""
        ...

    def external_power(self, t: float, q: np.ndarray, v: np.ndarray) -> float:
        """Power of the non-conservative loads, ``f_nc(t, q, v) . v``."""
        ...


#: Optional capabilities a model may declare in its ``capabilities`` attribute (a set of these names),
#: each with the methods it promises. Solvers use a capability only when it is declared.
#:
#: ``"residual_jacobian"``
#:     ``residual_jacobian(t, q, v, a) -> (r, JacobianBlocks)``: both from one kernel pass (full Newton,
#:     the static solver).
#: ``"residual_stages"``
#:     ``residual_stages(ts, Q, V, A) -> R`` with columns = stages, shape ``(n_dof, m)``: all implicit
#:     stages of a Runge-Kutta step in one call (Lobatto IIIA).
#: ``"variable_mass"``
#:     ``M`` depends on ``q`` (then ``mass_is_constant`` must be False); no extra method.
#: ``"mass_forms"``
#:     with ``"variable_mass"``: ``mass_action(q, x, tangent) -> (M(q) x, d(M x)/dq or None)`` and
#:     ``mass_bilinear(q, u, w, order) -> (B, dB/dq, d2B/dq2)`` of ``B = u^T M(q) w / 2`` (the
#:     energy-momentum integrator's discrete gradient of a configuration-dependent kinetic energy).
#: ``"step_events"``
#:     the model has an *event state* (a dict of arrays, e.g. BE3D's nodal directors) that may change
#:     between steps: ``event_state() -> dict`` (the initial state), ``bind(state) -> Model`` (a model
#:     evaluating with that state and sharing everything else; cheap; the original is never changed) and
#:     ``step_event(t, q, v) -> None or (q, v, state)`` called after every accepted step, None meaning
#:     nothing changed. The driver carries the state, restarts the integrator when it changes and
#:     stores it in ``Result.model_state``.
#: ``"potential"``
#:     the residual splits as ``M a + dP/dq - f_nc(t, q)`` with a constant ``M`` (with
#:     ``"mass_forms"``: ``d/dt(M(q) v) - dT/dq + dP/dq - f_nc``):
#:     ``potential``, ``potential_gradient``, ``nonconservative_force`` (and optionally
#:     ``symmetry_generators``, ``potential_degree``), see :class:`PotentialModel`
#:     (energy-momentum integrators).
#: ``"potential_stages"``
#:     with ``"potential"``: ``potential_gradient_stages(ts, Q) -> G`` of shape ``(n_dof, m)``, column ``i``
#:     ``potential_gradient(ts[i], Q[:, i], False)[0]``: ``m`` configurations in one call (the
#:     energy-preserving collocation's silent stages).
#: ``"potential_projection"``
#:     with ``"potential"``: ``potential_gradient_projection(ts, Z, A, B) -> P`` of shape ``(n_dof, r)``,
#:     ``P[:, s] = sum_l B[l, s] potential_gradient(ts[l], Z @ A[:, l], False)[0]`` for ``Z`` (n_dof, p), ``A``
#:     (p, k), ``B`` (k, r): ``k`` configurations that are combinations of a few vectors, their forces
#:     weighted, in one call (the energy-preserving collocation's projection onto its Legendre basis).
#: ``"constraints"``
#:     holonomic constraints ``g(t, q) = 0`` (``n_constraints`` rows); the equations of motion become
#:     ``r(t, q, v, a) + G^T lam = 0``, ``g = 0`` (``residual`` stays without ``G^T lam``):
#:     ``n_constraints`` (int), ``constraints(t, q) -> g`` (m,), ``constraint_jacobian(t, q) -> G``
#:     (csr (m, n), fixed pattern), ``constraint_force_jacobian(t, q, lam) -> d(G^T lam)/dq`` (csr
#:     (n, n)), ``constraint_rates(t, q, v) -> (g_t, gamma)``: the velocity constraint is
#:     ``G v + g_t = 0``, the acceleration constraint ``G a = gamma``. Optional within it:
#:     ``constraint_velocity_jacobian(t, q, v) -> d(G v + g_t)/dq`` (csr (m, n)), which the index-2
#:     (stabilised) formulations put in their Newton matrices; without it they form ``d(G v)/dq``
#:     from ``m`` calls of ``constraint_force_jacobian`` and leave out ``dg_t/dq`` (exact for
#:     constraints that do not depend on time). Only a stepper that declares
#:     ``handles_constraints = True`` is run on such a model (see :class:`ConstrainedModel`).
CAPABILITIES: dict[str, tuple[str, ...]] = {
    "residual_jacobian": ("residual_jacobian",),
    "residual_stages": ("residual_stages",),
    "variable_mass": (),
    "mass_forms": ("mass_action", "mass_bilinear"),
    "step_events": ("event_state", "bind", "step_event"),
    "potential": ("potential", "potential_gradient", "nonconservative_force"),
    "potential_stages": ("potential_gradient_stages",),
    "potential_projection": ("potential_gradient_projection",),
    "constraints": ("constraints", "constraint_jacobian", "constraint_force_jacobian", "constraint_rates"),
}


def capabilities(model: object) -> frozenset:
    """The optional capabilities ``model`` declares, checked; empty when it declares none.

    The declaration is looked up without ``__getattr__`` (:func:`inspect.getattr_static`), so a
    wrapper that forwards attributes to the model it wraps does not inherit the wrapped model's
    fast paths by accident -- it falls back to the plain contract unless it declares (and thereby
    forwards) them deliberately.

    Raises
    ------
    TypeError
        When the declaration is not a collection of strings, names an unknown capability, or a
        declared capability's methods are not callable.
    """
    try:
        inspect.getattr_static(model, "capabilities")
    except AttributeError:
        return frozenset()
    declared = model.capabilities
    if isinstance(declared, str) or not all(isinstance(c, str) for c in declared):
        raise TypeError(f"`{type(model).__name__}.capabilities` must be a set of capability names "
                        f"{sorted(CAPABILITIES)}, got {declared!r}.")
    declared = frozenset(declared)
    unknown = sorted(declared - set(CAPABILITIES))
    if unknown:
        raise TypeError(f"`{type(model).__name__}.capabilities` names unknown capabilities {unknown}; "
                        f"known: {sorted(CAPABILITIES)}.")
    for cap in declared:
        missing = [m for m in CAPABILITIES[cap] if not callable(getattr(model, m, None))]
        if missing:
            raise TypeError(f"{type(model).__name__} declares the capability {cap!r} but lacks the "
                            f"callable(s) {missing}.")
    if "constraints" in declared:
        m = getattr(model, "n_constraints", None)
        if isinstance(m, bool) or not isinstance(m, (int, np.integer)) or m < 0:
            raise TypeError(f"{type(model).__name__} declares 'constraints' but `n_constraints` is {m!r}, "
                            "not a non-negative integer.")
    if "variable_mass" in declared and getattr(model, "mass_is_constant", False):
        raise TypeError(f"{type(model).__name__} declares 'variable_mass' but mass_is_constant is True.")
    return declared


# -- optional capability: the potential, for energy-momentum integrators ---------------------
@runtime_checkable
class PotentialModel(Protocol):
    """What a structure-preserving (discrete-gradient) integrator needs beyond :class:`Model`.

    The residual splits as ``r = M a + dP/dq - f_nc(t, q)`` with a *constant* mass
    matrix, the conservative potential ``P = U + V`` (strain energy plus the
    potential of the conservative loads, i.e. gravity) and the non-conservative
    loads ``f_nc`` (dead forces, moments). Optional: a model offers it by declaring
    the ``"potential"`` capability (:data:`CAPABILITIES`); ``symmetry_generators``
    and ``potential_degree`` are optional within it.

    Attributes
    ----------
    potential_degree : int or None
        Polynomial degree of ``P`` in ``q`` when ``P`` is a polynomial (4 for
        the St. Venant-Kirchhoff continuum formulations, whose Green strain is
        quadratic in ``q``), else None.
    """

    potential_degree: int | None

    def potential(self, t: float, q: np.ndarray) -> float:
        """``P(q) = U(q) + V(q)`` (equal to ``energy(t, q, v).strain + .potential``)."""
        ...

    def potential_gradient(self, t: float, q: np.ndarray,
                           tangent: bool = True) -> tuple[np.ndarray, sp.spmatrix | None]:
        """``(dP/dq, d2P/dq2 as a sparse matrix or None)``."""
        ...

    def nonconservative_force(self, t: float, q: np.ndarray,
                             tangent: bool = True) -> tuple[np.ndarray, sp.spmatrix | None]:
        """``(f_nc(t, q), df_nc/dq as a sparse matrix or None)``; ``external_power = f_nc . v``."""
        ...

    def symmetry_generators(self) -> tuple[np.ndarray, list[sp.spmatrix]]:
        """Rigid motions that leave the strain energy unchanged: ``(T, A)``.

        ``T`` (n_dof, k_t): constant translation directions; ``A``: list of
        sparse skew matrices, the infinitesimal rotations ``q -> A q`` (rotating
        every nodal vector). Both empty when supports break the symmetry.
        """
        ...



# -- optional capability: holonomic constraints ---------------------------------------------
@runtime_checkable
class ConstrainedModel(Protocol):
    """Holonomic constraints ``g(t, q) = 0`` with multipliers ``lam``: the ``"constraints"`` capability.

    The equations of motion are the index-3 DAE::

        r(t, q, v, a) + G(t, q)^T lam = 0,      g(t, q) = 0,      G = dg/dq

    (``residual`` stays ``r``, without the ``G^T lam`` term; ``-G^T lam`` are the reaction forces). Hidden
    in them: the velocity constraint ``G v + g_t = 0`` and the acceleration constraint ``G a = gamma`` with
    ``gamma = -(Z(v) v + 2 G_t v + g_tt)``, ``Z(v) = d(G v)/dq``. Every derivative is exact and, like the
    residual's, checked against finite differences. The joints of :mod:`ancfdae.joints` are at most
    quadratic in ``q``, so ``G`` is affine in ``q`` and ``d(G^T lam)/dq`` does not depend on ``q``.

    Attributes
    ----------
    n_constraints : int
        ``m``, the number of rows of ``g``.

    Notes
    -----
    Optional, used when present: ``constraint_force(t, q, lam) -> G^T lam`` (without forming ``G``; the
    steppers' residuals need it at every Newton iteration), ``constraint_velocity_jacobian(t, q, v) ->
    d(G v + g_t)/dq`` (index-2 formulations), ``constraint_degree`` (1 or 2 when every row is at most
    quadratic in ``q`` with time only in its linear part; the energy-momentum method requires it) and
    ``constraint_labels`` (one name per row, for messages and results).
    """

    n_constraints: int

    def constraints(self, t: float, q: np.ndarray) -> np.ndarray:
        """``g(t, q)``, shape ``(m,)``."""
        ...

    def constraint_jacobian(self, t: float, q: np.ndarray) -> sp.spmatrix:
        """``G = dg/dq``, CSR of shape ``(m, n_dof)`` on a fixed sparsity pattern (the same at every t, q)."""
        ...

    def constraint_force_jacobian(self, t: float, q: np.ndarray, lam: np.ndarray) -> sp.spmatrix:
        """``d(G^T lam)/dq``, shape ``(n_dof, n_dof)`` (Newton matrices add it to ``K``)."""
        ...

    def constraint_rates(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(g_t, gamma)``, each shape ``(m,)``: ``G v + g_t = 0`` and ``G a = gamma`` on the motion."""
        ...
