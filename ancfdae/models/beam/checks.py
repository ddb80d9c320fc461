"""The argument checks of a :class:`~ancfdae.models.beam.Beam`: supports, node indices, arc lengths on
the axis, initial velocities and the shapes of the Model contract's arguments."""
from __future__ import annotations

import numbers
from collections.abc import Mapping

import numpy as np

from ..._validate import check_shape

__all__ = ["BeamChecks"]


class BeamChecks:
    """Checking methods of :class:`~ancfdae.models.beam.Beam` (a mixin: it uses the beam's element and
    mesh)."""

    def _fixed_coordinates(self, supports):
        """Mask of the full coordinates that ``supports`` fix (checked against the element's names)."""
        element, frames, nnd = self.element, self.frames, self.element.n_node_dof
        fixed = np.zeros(self.q_ref.size, dtype=bool)
        if supports is not None and not isinstance(supports, Mapping):
            raise TypeError(f"`supports` must be a dict {{node: kind}} with kind 'clamp', 'pin' or a tuple of "
                            f"coordinate names, e.g. {{0: 'clamp'}}; got {supports!r}.")
        for node, kind in (supports or {}).items():
            i = self._node_index(node, "supports")
            if not isinstance(kind, (str, tuple, list)):
                raise ValueError(f"`supports` kind must be 'clamp', 'pin' or a tuple of coordinate names "
                                 f"{element.node_coordinates}, got {kind!r} at node {node}.")
            if isinstance(kind, str):
                if kind not in ("clamp", "pin"):
                    raise ValueError(f"`supports` kind must be 'clamp', 'pin' or a tuple of coordinate names "
                                     f"{element.node_coordinates}, got {kind!r} at node {node}.")
                names = element.support_coordinates(kind, frames[i])
            else:
                names = tuple(kind)
            for name in names:
                if name not in element.node_coordinates:
                    raise ValueError(f"`supports` coordinate must be one of {element.node_coordinates}, "
                                     f"got {name!r} at node {node}.")
                fixed[i * nnd + element.node_coordinates.index(name)] = True
        return fixed

    def _node_index(self, node, arg):
        if isinstance(node, bool) or not isinstance(node, numbers.Integral):
            raise ValueError(f"`{arg}` node must be an integer index, got {node!r}.")
        if not -self.n_nodes <= node < self.n_nodes:
            raise ValueError(f"`{arg}` node must be in [-{self.n_nodes}, {self.n_nodes - 1}] "
                             f"(the beam has {self.n_nodes} nodes), got {node}.")
        return int(node) % self.n_nodes

    def _locate(self, s, arg="s"):
        """Element index and normalised coordinate of axis point(s) at arc length s."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        total = self.s_nodes[-1]
        if np.any(~np.isfinite(s)) or np.any(s < -1e-12 * total) or np.any(s > total * (1 + 1e-12)):
            raise ValueError(f"`{arg}` must lie on the beam, in [0, {total}], got {s.tolist()}.")
        ends = np.concatenate([[0.0], np.cumsum(self.lengths)])
        e = np.clip(np.searchsorted(ends, s, side="right") - 1, 0, self.n_elements - 1)
        loc = 2.0 * (s - ends[e]) / self.lengths[e] - 1.0
        return e, np.clip(loc, -1.0, 1.0)

    def _check(self, q, v=None, a=None):
        """Shape checks of the contract's arguments: a wrong length would otherwise assemble silently
        into a wrong-sized residual or fail deep inside numpy."""
        n = (self.n_dof,)
        # Attribute access for arrays (tens of ns); anything else goes through np.shape in check_shape.
        if getattr(q, "shape", None) != n:
            check_shape("q", q, n, f"n_dof = {self.n_dof}")
        if v is not None and getattr(v, "shape", None) != n:
            check_shape("v", v, n, f"n_dof = {self.n_dof}")
        if a is not None and getattr(a, "shape", None) != n:
            check_shape("a", a, n, f"n_dof = {self.n_dof}")

    def _initial_velocity(self, iv):
        nnd = self.element.n_node_dof
        if iv is None:
            return np.zeros(self.n_dof)
        if callable(iv):
            dim = self.element.dim
            V = np.zeros((self.n_nodes, nnd))
            v = np.asarray(iv(self.points), dtype=float)
            if v.shape != self.points.shape or not np.all(np.isfinite(v)):
                raise ValueError(f"`initial_velocity` must return finite velocities of shape {self.points.shape}, "
                                 f"got {v.shape}.")
            V[:, :dim] = v
            names = self.element.node_coordinates
            if len(names) >= 2 * dim and names[dim].endswith("'"):
                h = 1e-5 * float(self.lengths.min())
                t = self.frames[:, :, 0]
                V[:, dim:2 * dim] = (np.asarray(iv(self.points + h * t)) - np.asarray(iv(self.points - h * t))) / (2 * h)
            return V.reshape(-1)[self.free]
        V = np.asarray(iv, dtype=float)
        if V.shape != (self.n_nodes, nnd) or not np.all(np.isfinite(V)):
            raise ValueError(f"`initial_velocity` array must be finite with shape {(self.n_nodes, nnd)}, got {V.shape}.")
        return V.reshape(-1)[self.free]
