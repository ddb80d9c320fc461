"""The counting proxy of a model: every stepper's work counters, kept in one place.

:meth:`ancfdae.integrators.Integrator.initialize` wraps the model of the run in a
:class:`CountingModel` once; the stepper evaluates ``self.model`` and never counts by hand. The
proxy declares the wrapped model's capabilities deliberately (an instance attribute, which
:func:`ancfdae.problem.capabilities` reads without ``__getattr__``), so every fast path stays
available, and it forwards everything it does not count.

Cost: a counted call is one Python call more than the model's own, as the steppers' former
hand-counting methods were. Measured with ``python -m benchmarks.counting_overhead`` (process-CPU
medians, 3 runs on a shared 2-core machine): +0.13 to +0.29 us per call over a direct call of a model
that does no work, against +0.08 to +0.15 us for the former hand-counting method; the residual of an
8-element BE2D beam takes 8 to 14 us.
"""
from __future__ import annotations

from ancfdae.problem import capabilities

__all__ = ["CountingModel"]


class CountingModel:
    """A model whose residual, Jacobian and potential evaluations are counted.

    Parameters
    ----------
    model : Model
        The model to evaluate (the run's, bound to its event state).

    Attributes
    ----------
    wrapped : Model
        The model evaluated.
    capabilities : frozenset
        The wrapped model's declared capabilities, checked (forwarded deliberately).
    n_residual : int
        Residuals evaluated: one per ``residual`` or ``residual_jacobian`` call, one per stage of a
        ``residual_stages`` call (the same work as that many ``residual`` calls).
    n_jacobian : int
        Jacobians evaluated (``jacobian`` and ``residual_jacobian`` calls).
    n_potential, n_potential_gradient : int
        ``potential`` and ``potential_gradient`` calls (the energy-momentum stepper's discrete
        gradients).
    """

    __slots__ = ("wrapped", "capabilities", "n_residual", "n_jacobian", "n_potential", "n_potential_gradient")

    def __init__(self, model) -> None:
        self.rebind(model)
        self.reset()

    def rebind(self, model) -> None:
        """Evaluate ``model`` from now on (after a model event); the counters carry on."""
        self.wrapped = model
        self.capabilities = capabilities(model)

    def reset(self) -> None:
        """Set the counters to zero."""
        self.n_residual = self.n_jacobian = self.n_potential = self.n_potential_gradient = 0

    def counts(self) -> dict:
        """The residual and Jacobian counters under the names of ``Result.stats``."""
        return {"residual_evals": self.n_residual, "jacobian_evals": self.n_jacobian}

    # -- counted ------------------------------------------------------------------------------
    def residual(self, t, q, v, a):
        """The wrapped model's ``residual``, counted."""
        self.n_residual += 1
        return self.wrapped.residual(t, q, v, a)

    def jacobian(self, t, q, v, a):
        """The wrapped model's ``jacobian``, counted."""
        self.n_jacobian += 1
        return self.wrapped.jacobian(t, q, v, a)

    def residual_jacobian(self, t, q, v, a):
        """The wrapped model's ``residual_jacobian``, counted as one residual and one Jacobian."""
        self.n_residual += 1
        self.n_jacobian += 1
        return self.wrapped.residual_jacobian(t, q, v, a)

    def residual_stages(self, ts, Q, V, A):
        """The wrapped model's ``residual_stages``, counted as one residual per stage."""
        self.n_residual += len(ts)
        return self.wrapped.residual_stages(ts, Q, V, A)

    def potential(self, t, q):
        """The wrapped model's ``potential``, counted."""
        self.n_potential += 1
        return self.wrapped.potential(t, q)

    def potential_gradient(self, t, q, tangent=True):
        """The wrapped model's ``potential_gradient``, counted."""
        self.n_potential_gradient += 1
        return self.wrapped.potential_gradient(t, q, tangent)

    def potential_gradient_stages(self, ts, Q):
        """The wrapped model's ``potential_gradient_stages``, counted as one gradient per configuration."""
        self.n_potential_gradient += len(ts)
        return self.wrapped.potential_gradient_stages(ts, Q)

    def potential_gradient_projection(self, ts, Z, A, B):
        """The wrapped model's ``potential_gradient_projection``, counted as one gradient per configuration."""
        self.n_potential_gradient += len(ts)
        return self.wrapped.potential_gradient_projection(ts, Z, A, B)

    # -- forwarded ----------------------------------------------------------------------------
    def __getattr__(self, name):
        # Only for names not defined above (mass, n_dof, event_state, nonconservative_force, ...).
        # Dunders and the proxy's own slots are not forwarded: an unset slot would recurse here.
        if name.startswith("__") or name in CountingModel.__slots__:
            raise AttributeError(name)
        return getattr(self.wrapped, name)
