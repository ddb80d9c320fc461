"""Reference geometry of a beam: node positions, cross-section frames, element lengths, and the numbering
of nodes and coordinates along the axis (banded matrices)."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..._validate import finite_vector, positive, positive_int

__all__ = ["build", "numbering", "point_matrix", "straight_mesh", "mesh_from_points", "frame_from_tangent"]


def frame_from_tangent(e1: np.ndarray, normal=None) -> np.ndarray:
    """Orthonormal frame (columns e1, e2[, e3]) with e1 along the tangent (chapter Eq. 6).

    2D: ``e2`` is ``e1`` turned by +90 degrees. 3D: ``e2`` is ``normal`` made
    orthogonal to ``e1`` if given, else ``e_z x e1`` (so a beam along e_x gets
    the reference frame e_x, e_y, e_z of chapter Sect. 2.1), or ``e1 x e_y``
    for a beam along e_z.
    """
    e1 = e1 / np.linalg.norm(e1)
    if e1.shape[0] == 2:
        return np.column_stack([e1, [-e1[1], e1[0]]])
    if normal is not None:
        e2 = normal - (normal @ e1) * e1
        if np.linalg.norm(e2) < 1e-10 * np.linalg.norm(normal):
            raise ValueError(f"`normal` must not be parallel to the beam axis, got {list(normal)}.")
    else:
        e2 = np.cross([0.0, 0.0, 1.0], e1)
        if np.linalg.norm(e2) < 1e-10:
            e2 = np.cross(e1, [0.0, 1.0, 0.0])
    e2 = e2 / np.linalg.norm(e2)
    return np.column_stack([e1, e2, np.cross(e1, e2)])


def straight_mesh(n_elements, length, start, direction, nodes_per_element, normal=None):
    """Nodes and frames of a straight beam.

    Returns
    -------
    points : (n_nodes, dim), frames : (n_nodes, dim, dim), lengths : (n_el,)
    """
    n = positive_int("n_elements", n_elements)
    L = positive("length", length)
    start = finite_vector("start", start)
    dim = start.shape[0]
    if dim not in (2, 3):
        raise ValueError(f"`start` must have 2 or 3 components, got {dim}.")
    d = finite_vector("direction", direction, dim)
    if np.linalg.norm(d) == 0:
        raise ValueError("`direction` must be a non-zero vector, got all zeros.")
    if normal is not None:
        normal = finite_vector("normal", normal, 3)
    frame = frame_from_tangent(d, normal)
    n_nodes = n * (nodes_per_element - 1) + 1
    s = np.linspace(0.0, L, n_nodes)
    points = start[None, :] + s[:, None] * frame[:, 0][None, :]
    frames = np.repeat(frame[None], n_nodes, axis=0)
    return points, frames, np.full(n, L / n)


def mesh_from_points(points, nodes_per_element, normal=None):
    """Nodes and frames of a (possibly curved) beam through given node positions.

    Tangents are the central differences of the node positions (one-sided at
    the ends); element lengths are the chords between element end nodes.
    """
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] not in (2, 3) or p.shape[0] < nodes_per_element or not np.all(np.isfinite(p)):
        raise ValueError(f"`nodes` must be a finite (n_nodes, 2|3) array with at least {nodes_per_element} rows, "
                         f"got shape {p.shape}.")
    if (p.shape[0] - 1) % (nodes_per_element - 1):
        raise ValueError(f"`nodes` of {nodes_per_element}-node elements must number k*{nodes_per_element - 1}+1, "
                         f"got {p.shape[0]}.")
    t = np.gradient(p, axis=0)
    if np.any(np.linalg.norm(t, axis=1) == 0):
        raise ValueError("`nodes` must not repeat a point.")
    frames = np.stack([frame_from_tangent(ti, normal) for ti in t])
    ends = p[:: nodes_per_element - 1]
    lengths = np.linalg.norm(np.diff(ends, axis=0), axis=1)
    return p, frames, lengths


def build(element, n_elements=None, length=None, start=None, direction=None, nodes=None, normal=None):
    """Points, frames and element lengths of the mesh that :class:`~ancfdae.models.Beam`'s arguments describe:
    ``nodes`` (a curved or irregular beam) or ``n_elements`` and ``length`` (a straight one)."""
    dim, npe = element.dim, element.n_nodes
    if nodes is not None:
        if n_elements is not None or length is not None:
            raise ValueError("give either `nodes` or `n_elements` and `length`, not both.")
        points, frames, lengths = mesh_from_points(nodes, npe, normal)
        if points.shape[1] != dim:
            raise ValueError(f"`nodes` must have {dim} columns for {element.name}, got {points.shape[1]}.")
        return points, frames, lengths
    if n_elements is None or length is None:
        raise ValueError("give `n_elements` and `length` (or `nodes`).")
    start = np.zeros(dim) if start is None else start
    direction = np.eye(dim)[0] if direction is None else direction
    if np.size(start) != dim:
        raise ValueError(f"`start` must have {dim} components for {element.name}, got {np.size(start)}.")
    return straight_mesh(n_elements, length, start, direction, npe, normal)


def numbering(lengths: np.ndarray, nodes_per_element: int, node_dof: int) -> tuple:
    """``(element_nodes, edofs, s_nodes)``: the nodes of each element, its full coordinate indices and the
    reference arc length of each node.

    Nodes are numbered along the axis, so the matrices are banded; a 3-node
    element orders its nodes (A, B, C) = (start, end, middle) (chapter Eq. 105).
    """
    n_el = lengths.size
    k = nodes_per_element - 1
    base = np.arange(n_el)[:, None] * k
    order = [0, k] + list(range(1, k))
    element_nodes = base + np.array(order)[None, :]
    edofs = (element_nodes[:, :, None] * node_dof + np.arange(node_dof)).reshape(n_el, -1)
    s_nodes = np.concatenate([[0.0], np.cumsum(np.repeat(lengths / k, k))])
    return element_nodes, edofs, s_nodes


def point_matrix(element, edofs: np.ndarray, lengths: np.ndarray, e: np.ndarray, loc: np.ndarray,
                 n_full: int) -> sp.csr_matrix:
    """Sparse operator P with ``r = P @ q_full`` at the axis points ``loc`` (normalised) of elements ``e``."""
    dim, nd = element.dim, element.n_edof
    rows, cols, vals = [], [], []
    for k, (ek, sk) in enumerate(zip(e, loc)):   # a few sensor points, at construction only
        S = element.shape_matrix(np.array([sk]), lengths[[ek]])[0, 0]
        rows.append(np.repeat(np.arange(dim) + k * dim, nd))
        cols.append(np.tile(edofs[ek], dim))
        vals.append(S.ravel())
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(len(e) * dim, n_full))
