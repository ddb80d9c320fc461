"""What the energy-conserving integrators ask of a model: a constant mass and the residual split.

Both :class:`~ancfdae.integrators.EnergyMomentum` and
:class:`~ancfdae.integrators.EnergyCollocation` integrate ``M a + grad P(q) - f_nc(t, q) = 0`` with a
constant ``M`` (:class:`ancfdae.problem.PotentialModel`); a model outside that form would be integrated
wrongly without a word (a damping force dropped), so they refuse it, the first at construction, the
second once the run's state is known.
"""
from __future__ import annotations

import numpy as np

from ancfdae.problem import Model, capabilities

__all__ = ["require_potential_model", "require_potential_split"]


def require_potential_model(model: Model, method: str, variable_mass: bool = False) -> None:
    """Raise ValueError unless ``model`` has the ``"potential"`` capability and a constant mass matrix.

    Parameters
    ----------
    model : Model
    method : str
        The method's name, for the message.
    variable_mass : bool
        True for a method that also takes a configuration-dependent mass through the ``"mass_forms"``
        capability (energy-momentum's kinetic discrete gradient).
    """
    if variable_mass and not getattr(model, "mass_is_constant", False):
        if "mass_forms" not in capabilities(model):
            raise ValueError("`model` must have a constant mass matrix (mass_is_constant=True) or declare the "
                             f"'mass_forms' capability (mass_action, mass_bilinear) for method {method!r}; "
                             f"{type(model).__name__} has mass_is_constant=False and declares "
                             f"{sorted(capabilities(model))}.")
    elif not getattr(model, "mass_is_constant", False):
        raise ValueError(f"`model` must have a constant mass matrix for method {method!r} "
                         f"(mass_is_constant=True), got {type(model).__name__} with mass_is_constant=False "
                         "(BE3D: the cross-section's rotary inertia depends on the slopes, so the kinetic "
                         "energy is not quadratic in v with a constant matrix and the scheme's energy "
                         "identity does not hold).")
    if "potential" not in capabilities(model):
        raise ValueError("`model` must declare the 'potential' capability (ancfdae.problem.PotentialModel: "
                         f"potential, potential_gradient, nonconservative_force) for method {method!r}; "
                         f"{type(model).__name__} declares {sorted(capabilities(model))}.")


def require_potential_split(model: Model, t: float, q: np.ndarray, v: np.ndarray, method: str,
                            variable_mass: bool = False) -> None:
    """Raise ValueError unless ``r(t, q, v', 0) = grad P(q) - f_nc(t, q)`` at ``(t, q)`` for ``v' = v + 1``.

    A velocity-dependent force (damping) or a residual that differs from the declared split shows
    as a difference above ``1e-8`` of the larger of the two.

    Parameters
    ----------
    model : Model with the ``"potential"`` capability
    t : float
    q, v : ndarray
        The state where the split is checked (the run's initial state).
    method : str
        The method's name, for the message.
    variable_mass : bool
        True for a model whose mass depends on q: its velocity-dependent inertia (not part of the split)
        is then left out by probing at zero velocity, which a damping force linear in v escapes; the
        constant-mass probe ``v + 1`` shows it.
    """
    probe = 0 * v if variable_mass else v + 1.0         # a velocity-dependent force must show (constant M)
    r = np.asarray(model.residual(t, q, probe, np.zeros_like(q)), dtype=float)
    split = model.potential_gradient(t, q, False)[0] - model.nonconservative_force(t, q, False)[0]
    scale = max(float(np.max(np.abs(r), initial=0.0)), float(np.max(np.abs(split), initial=0.0)), 1e-300)
    err = float(np.max(np.abs(r - split), initial=0.0))
    if err > 1e-8 * scale:
        raise ValueError(f"`model` residual must be M a + dP/dq - f_nc(t, q) for method {method!r}; "
                         f"at t = {t:g} it differs from the PotentialModel split by {err:.3g} "
                         f"(scale {scale:.3g}): damping or velocity-dependent forces are not supported.")
