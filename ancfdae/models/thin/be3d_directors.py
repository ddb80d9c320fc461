"""The director event of :class:`~ancfdae.models.be3d.BE3D`: the nodal directors as event state and
their update after an accepted step (chapter Sect. 3.6)."""
from __future__ import annotations

import numpy as np

from .be3d_inertia import director_sines, update_directors

__all__ = ["BE3DEvents"]


class BE3DEvents:
    """Event methods of :class:`~ancfdae.models.be3d.BE3D` (a mixin: it uses the element's
    ``director_update`` and ``update_below``)."""

    def event_state(self, geom: dict) -> dict:
        """``{"directors": (n_nodes, 3)}``: the nodal directors, carried by the driver between steps."""
        return {"directors": geom["directors"]}

    def bind(self, geom: dict, state: dict) -> dict:
        """``geom`` with the nodal directors of ``state`` (read-only; ``geom`` itself is unchanged)."""
        D = np.array(state["directors"], dtype=float)
        if D.shape != geom["directors"].shape:
            raise ValueError(f"`state['directors']` must have shape {geom['directors'].shape}, got {D.shape}.")
        D.setflags(write=False)
        return dict(geom, directors=D)

    def step_event(self, geom: dict, Q: np.ndarray, V: np.ndarray) -> tuple | None:
        """Director update of Sect. 3.6 (``director_update``, ``update_below``); None when not done.

        See :func:`._be3d_dynamics.update_directors`.
        """
        if self.director_update == "none":
            return None
        D = geom["directors"]
        Q = np.asarray(Q, dtype=float)
        if self.update_below is not None and np.min(director_sines(D, Q)) >= self.update_below:
            return None
        Q2, V2, D2 = update_directors(D, Q, np.asarray(V, dtype=float), self.director_update)
        return Q2, V2, {"directors": D2}
