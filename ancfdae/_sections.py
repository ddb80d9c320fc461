"""The beam as a solid: cross-sections at the nodes drawn from each element's own kinematics.

A material point of the cross-section at a node is ``r + eta a_eta + zeta a_zeta``
with ``(eta, zeta)`` its section coordinates (``h`` along eta, ``b`` along
zeta) and the two section vectors taken from the element:

* SQ2D/SQ3D: the nodal cross-section slopes ``r_eta`` (and ``r_zeta``), so a
  deformed cross-section shows as it is (chapter Eqs. 104-107); SQ2D's
  out-of-plane axis is ``e_z``.
* BE3D: ``e2``, ``e3`` of the node's frame from slope, director and angle
  theta (chapter Sect. 3.6), so torsion shows.
* BE2D: ``e2`` the unit normal of ``r'`` in the plane, ``e3 = e_z``
  (chapter Eq. 6).
* Cable3D: ``e2`` the reference ``e2`` projected normal to ``r'``, ``e3 = e1 x e2``
  (the cable has no torsion coordinate).
"""
from __future__ import annotations

import numpy as np

__all__ = ["section_outline", "section_vectors", "output_directors", "solid_points", "reference_points",
           "wedge_cells"]


def section_outline(section, n_circle: int = 16) -> np.ndarray:
    """Section coordinates ``(eta, zeta)`` of the outline, counter-clockwise, shape (n, 2).

    A rectangle gives its 4 corners, a circle ``n_circle`` points.
    """
    if hasattr(section, "h") and hasattr(section, "b"):
        h, b = section.h / 2, section.b / 2
        return np.array([[-h, -b], [h, -b], [h, b], [-h, b]])
    if hasattr(section, "d"):
        phi = 2 * np.pi * np.arange(n_circle) / n_circle
        return 0.5 * section.d * np.column_stack([np.cos(phi), np.sin(phi)])
    r = np.sqrt(section.A / np.pi)   # any other section: a circle of the same area
    phi = 2 * np.pi * np.arange(n_circle) / n_circle
    return r * np.column_stack([np.cos(phi), np.sin(phi)])


def _embed(x: np.ndarray) -> np.ndarray:
    """Planar vectors (..., 2) as 3D vectors with z = 0."""
    if x.shape[-1] == 3:
        return x
    return np.concatenate([x, np.zeros(x.shape[:-1] + (1,))], axis=-1)


def _unit(x: np.ndarray) -> np.ndarray:
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def section_vectors(beam, q: np.ndarray, directors: np.ndarray | None = None):
    """Axis points and section vectors at the nodes.

    Parameters
    ----------
    beam : Beam
    q : ndarray, shape (n_dof,)
        Free coordinates.
    directors : ndarray, shape (n_nodes, 3), optional
        BE3D only: the nodal directors belonging to ``q`` (default the
        beam's current ones).

    Returns
    -------
    r : ndarray, shape (n_nodes, 3)
    a_eta, a_zeta : ndarray, shape (n_nodes, 3)
    """
    el = beam.element
    Q = beam.nodal(q)
    dim = el.dim
    r = _embed(Q[:, :dim])
    ez = np.broadcast_to([0.0, 0.0, 1.0], r.shape)
    name = el.name
    if name in ("SQ2D", "SQ3D"):
        a_eta = _embed(Q[:, dim:2 * dim])
        a_zeta = Q[:, 2 * dim:3 * dim] if dim == 3 else ez
        return r, a_eta, np.array(a_zeta)
    if name == "BE3D":
        geom = beam.geom if directors is None else el.bind(beam.geom, {"directors": directors})
        qe = beam.expand(q)[beam.edofs]
        F = el.frames(geom, qe, np.array([-1.0, 1.0]))            # (n_el, 2, 3, 3)
        e2, e3 = np.empty_like(r), np.empty_like(r)
        for k in (0, 1):    # element start and end nodes; shared nodes get equal frames
            e2[beam.element_nodes[:, k]] = F[:, k, :, 1]
            e3[beam.element_nodes[:, k]] = F[:, k, :, 2]
        return r, e2, e3
    t = _unit(_embed(Q[:, dim:2 * dim]))                           # unit r' (BE2D, Cable3D)
    if dim == 2:
        return r, np.column_stack([-t[:, 1], t[:, 0], np.zeros(len(t))]), np.array(ez)
    e2_ref = beam.frames[:, :, 1]
    e2 = _unit(e2_ref - np.einsum("ni,ni->n", e2_ref, t)[:, None] * t)
    return r, e2, np.cross(t, e2)


def output_directors(result, beam) -> np.ndarray | None:
    """BE3D's nodal directors at each output of ``result``, shape (n_out, n_nodes, 3); None for other elements.

    Taken from ``result.model_state["directors"]``; a BE3D beam without director updates keeps
    its reference directors.

    Raises
    ------
    ValueError
        If a BE3D result with director updates does not carry them.
    """
    if beam.element.name != "BE3D":
        return None
    if "directors" in result.model_state:
        return np.asarray(result.model_state["directors"], dtype=float)
    if beam.element.director_update == "none":
        return np.repeat(beam.geom["directors"][None], result.t.size, axis=0)
    raise ValueError("`result` of a BE3D beam with director updates needs result.model_state['directors'] "
                     "(the nodal directors at each output) to draw the cross-section frames.")


def solid_points(beam, q: np.ndarray, outline: np.ndarray, directors=None) -> np.ndarray:
    """Points of the solid: per node its axis point, then the outline, shape (n_nodes * (1 + n), 3)."""
    r, a_eta, a_zeta = section_vectors(beam, q, directors)
    ring = r[:, None, :] + outline[None, :, 0, None] * a_eta[:, None, :] + outline[None, :, 1, None] * a_zeta[:, None, :]
    return np.concatenate([r[:, None, :], ring], axis=1).reshape(-1, 3)


def reference_points(beam, outline: np.ndarray) -> np.ndarray:
    """:func:`solid_points` of the reference configuration: every element's reference section vectors
    are the mesh frame's ``e2``, ``e3`` (``e_z`` in the plane), shape (n_nodes * (1 + n), 3)."""
    r = _embed(beam.points)
    if beam.element.dim == 2:
        a_eta, a_zeta = _embed(beam.frames[:, :, 1]), np.broadcast_to([0.0, 0.0, 1.0], r.shape)
    else:
        a_eta, a_zeta = beam.frames[:, :, 1], beam.frames[:, :, 2]
    ring = r[:, None, :] + outline[None, :, 0, None] * a_eta[:, None, :] + outline[None, :, 1, None] * a_zeta[:, None, :]
    return np.concatenate([r[:, None, :], ring], axis=1).reshape(-1, 3)


def wedge_cells(n_nodes: int, n_outline: int) -> np.ndarray:
    """Wedge cells (VTK order) between consecutive nodes: center, two outline points, and the same ahead."""
    stride = 1 + n_outline
    k = np.arange(n_outline)
    ring = np.column_stack([np.zeros(n_outline, int), 1 + k, 1 + (k + 1) % n_outline])   # (n, 3) in one station
    cells = [np.concatenate([i * stride + ring, (i + 1) * stride + ring], axis=1) for i in range(n_nodes - 1)]
    return np.concatenate(cells)
