"""The argument checks of a :class:`~ancfdae.models.Beam`: supports, node indices, arc lengths on the axis,
initial velocities and the shapes of the Model contract's arguments.

Plain functions of what they check and the mesh data they need: the beam calls
them with its own attributes, and nothing here keeps state.
"""
from __future__ import annotations

import numbers
from collections.abc import Mapping

import numpy as np

from ..._validate import check_shape

__all__ = ["fixed_coordinates", "node_index", "locate", "check_state", "initial_velocity"]


def node_index(node, n_nodes: int, arg: str) -> int:
    """``node`` as an index in ``[0, n_nodes)`` (negative indices count from the end); ``arg`` names it in errors."""
    if isinstance(node, bool) or not isinstance(node, numbers.Integral):
        raise ValueError(f"`{arg}` node must be an integer index, got {node!r}.")
    if not -n_nodes <= node < n_nodes:
        raise ValueError(f"`{arg}` node must be in [-{n_nodes}, {n_nodes - 1}] "
                         f"(the beam has {n_nodes} nodes), got {node}.")
    return int(node) % n_nodes


def fixed_coordinates(supports, element, frames: np.ndarray) -> np.ndarray:
    """Mask of the full coordinates that ``supports`` fix (checked against the element's names)."""
    n_nodes, nnd = len(frames), element.n_node_dof
    fixed = np.zeros(n_nodes * nnd, dtype=bool)
    if supports is not None and not isinstance(supports, Mapping):
        raise TypeError(f"`supports` must be a dict {{node: kind}} with kind 'clamp', 'pin' or a tuple of "
                        f"coordinate names, e.g. {{0: 'clamp'}}; got {supports!r}.")
    for node, kind in (supports or {}).items():
        i = node_index(node, n_nodes, "supports")
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


def locate(s, s_nodes: np.ndarray, lengths: np.ndarray, arg: str = "s") -> tuple[np.ndarray, np.ndarray]:
    """Element index and normalised coordinate of the axis point(s) at arc length ``s``."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    total = s_nodes[-1]
    if np.any(~np.isfinite(s)) or np.any(s < -1e-12 * total) or np.any(s > total * (1 + 1e-12)):
        raise ValueError(f"`{arg}` must lie on the beam, in [0, {total}], got {s.tolist()}.")
    ends = np.concatenate([[0.0], np.cumsum(lengths)])
    e = np.clip(np.searchsorted(ends, s, side="right") - 1, 0, lengths.size - 1)
    loc = 2.0 * (s - ends[e]) / lengths[e] - 1.0
    return e, np.clip(loc, -1.0, 1.0)


def check_state(n_dof: int, q, v=None, a=None) -> None:
    """Shape checks of the contract's arguments: a wrong length would otherwise assemble silently into a
    wrong-sized residual or fail deep inside numpy."""
    n = (n_dof,)
    # Attribute access for arrays (tens of ns); anything else goes through np.shape in check_shape.
    if getattr(q, "shape", None) != n:
        check_shape("q", q, n, f"n_dof = {n_dof}")
    if v is not None and getattr(v, "shape", None) != n:
        check_shape("v", v, n, f"n_dof = {n_dof}")
    if a is not None and getattr(a, "shape", None) != n:
        check_shape("a", a, n, f"n_dof = {n_dof}")


def initial_velocity(iv, element, points: np.ndarray, frames: np.ndarray, lengths: np.ndarray,
                     free: np.ndarray) -> np.ndarray:
    """The free initial velocities of the ``initial_velocity`` argument of :class:`~ancfdae.models.Beam`."""
    n_nodes, nnd = len(points), element.n_node_dof
    if iv is None:
        return np.zeros(free.size)
    if callable(iv):
        dim = element.dim
        V = np.zeros((n_nodes, nnd))
        v = np.asarray(iv(points), dtype=float)
        if v.shape != points.shape or not np.all(np.isfinite(v)):
            raise ValueError(f"`initial_velocity` must return finite velocities of shape {points.shape}, "
                             f"got {v.shape}.")
        V[:, :dim] = v
        names = element.node_coordinates
        if len(names) >= 2 * dim and names[dim].endswith("'"):
            # axial slope velocities: the derivative of v along the axis, by central differences
            h = 1e-5 * float(lengths.min())
            t = frames[:, :, 0]
            V[:, dim:2 * dim] = (np.asarray(iv(points + h * t)) - np.asarray(iv(points - h * t))) / (2 * h)
        return V.reshape(-1)[free]
    V = np.asarray(iv, dtype=float)
    if V.shape != (n_nodes, nnd) or not np.all(np.isfinite(V)):
        raise ValueError(f"`initial_velocity` array must be finite with shape {(n_nodes, nnd)}, got {V.shape}.")
    return V.reshape(-1)[free]
