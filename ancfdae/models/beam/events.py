"""Capabilities and event state of a :class:`~ancfdae.models.beam.Beam` (the BE3D director update)."""
from __future__ import annotations

import copy

import numpy as np

__all__ = ["BeamEvents"]


class BeamEvents:
    """Capability and event methods of :class:`~ancfdae.models.beam.Beam` (a mixin: it uses the beam's
    element and geometry)."""

    # -- capabilities and event state (ancfdae.problem.CAPABILITIES) --------------------------
    @property
    def capabilities(self) -> frozenset:
        """The optional capabilities this beam offers (see :func:`ancfdae.problem.capabilities`)."""
        caps = {"residual_jacobian", "residual_stages"}
        if not self.mass_is_constant:
            caps.add("variable_mass")
        else:
            caps.add("potential")       # M a + dP/dq - f_nc with a constant M (PotentialMixin)
        if self.element.event_state(self.geom):
            caps.add("step_events")
        return frozenset(caps)

    def event_state(self) -> dict:
        """The element's event state (BE3D: ``{"directors": (n_nodes, 3)}``), read-only arrays."""
        return dict(self.element.event_state(self.geom))

    def bind(self, state: dict) -> "Beam":
        """A beam evaluating with the event ``state``, sharing everything else (this one is unchanged)."""
        other = copy.copy(self)
        other.geom = self.element.bind(self.geom, state)
        return other

    def step_event(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple | None:
        """The element's event after an accepted step (BE3D director update); None when nothing changed."""
        ev = self.element.step_event(self.geom, self.nodal(q), self._expand_v(v).reshape(self.n_nodes, -1))
        if ev is None:
            return None
        Q, V, state = ev
        return Q.reshape(-1)[self.free], V.reshape(-1)[self.free], state
