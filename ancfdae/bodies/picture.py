"""A rigid body drawn as the homogeneous box of its mass and inertia (:func:`.inertia.equivalent_box`).

Geometry only (no plotting or file library): the body-fixed corners of the box, centred at the centre of
mass along the principal axes, in the vertex order of VTK's hexahedron (a quad in the plane), the edges
between them, and the corners in given states (linear in the coordinates, so velocities map alike).
"""
from __future__ import annotations

import numpy as np

from .inertia import equivalent_box

__all__ = ["box_corners", "box_edges", "box_points", "BOX_CELL"]

_SIGNS = {2: np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=float),
          3: np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                       [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)}

#: VTK cell type of the box per dimension (meshio's names).
BOX_CELL = {2: "quad", 3: "hexahedron"}


def box_corners(body) -> np.ndarray:
    """Body-fixed corners of the body's equivalent box, shape (4, 2) or (8, 3), in VTK vertex order."""
    half, axes = equivalent_box(body.body_mass, body.inertia)
    return body.com + (_SIGNS[body.dim] * half) @ axes.T


def box_edges(dim: int) -> list[tuple[int, int]]:
    """Pairs of corner indices joined by an edge of the box (4 in the plane, 12 in space)."""
    ring = [(0, 1), (1, 2), (2, 3), (3, 0)]
    if dim == 2:
        return ring
    return ring + [(a + 4, b + 4) for a, b in ring] + [(k, k + 4) for k in range(4)]


def box_points(body, q) -> np.ndarray:
    """The box's corners in the states ``q`` (one (n_dof,) or many (..., n_dof)), shape (..., n_corners, dim)."""
    return body.points(q, box_corners(body))
