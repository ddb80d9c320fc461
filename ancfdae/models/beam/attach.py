"""Where a joint takes hold of a beam: :meth:`Beam.attachment` as constant affine maps of its free coordinates.

A beam's material point and its frame vectors are linear in the *full* nodal coordinates (chapter Eqs. 54,
60: ``r(x) = S(x) e``); the beam solves for the free ones only, so each map splits into the columns of the
free coordinates and a constant from the coordinates its supports fixed (:class:`ancfdae.attachment.Attachment`
with ``offset``).

The frame vectors of a node are its slope vectors: ``r'`` for the thin elements (BE2D, Cable3D, BE3D, whose
torsion angle is not a vector), the cross-section directors ``r_eta (, r_zeta)`` for SQ2D/SQ3D. At an arc
length ``s`` inside an element the thin elements give the axial slope ``r' = dS/dx e`` (the derivative of
the cubic Hermite interpolation, exact: a five-point difference of a cubic in the normalised coordinate),
the SQ elements their directors interpolated like the position.
"""
from __future__ import annotations

import numbers

import numpy as np
import scipy.sparse as sp

from ...attachment import Attachment
from . import checks

__all__ = ["beam_attachment"]


def _where(beam, where):
    """``("node", index)`` or ``("s", arc length)`` from the user's ``where``, checked."""
    if isinstance(where, dict):
        if set(where) != {"s"}:
            raise ValueError(f"`where` as a dict must be {{'s': arc length}}, got {where!r}.")
        where = where["s"]
        if isinstance(where, (bool, np.bool_)) or not isinstance(where, numbers.Real):
            raise ValueError(f"`where['s']` must be an arc length (a number), got {where!r}.")
        return "s", float(where)
    if isinstance(where, (bool, np.bool_)):
        raise ValueError(f"`where` must be a node index (int), an arc length (float) or {{'s': float}}, "
                         f"got {where!r}.")
    if isinstance(where, numbers.Integral):
        i = int(where)
        if not -beam.n_nodes <= i < beam.n_nodes:
            raise ValueError(f"`where` node index must lie in [-{beam.n_nodes}, {beam.n_nodes - 1}] "
                             f"({beam.n_nodes} nodes), got {i}.")
        return "node", i % beam.n_nodes
    if isinstance(where, numbers.Real):
        return "s", float(where)
    raise ValueError(f"`where` must be a node index (int), an arc length (float) or {{'s': float}}, got {where!r}.")


def _thin(element):
    """True for the elements whose node holds ``r`` and ``r'`` (Hermite interpolation along the axis)."""
    names = element.node_coordinates
    return len(names) > element.dim and names[element.dim].endswith("'")


def _n_axes(element):
    if _thin(element):
        return 1
    return element.n_node_dof // element.dim - 1


def _full_maps(beam, kind, value):
    """Position and axes maps on the *full* coordinates: list of (dim, n_full) arrays, position first."""
    el, dim, nd = beam.element, beam.element.dim, beam.element.n_node_dof
    n_full = beam.q_ref.size
    if kind == "node":
        maps = []
        for k in range(1 + _n_axes(el)):
            P = np.zeros((dim, n_full))
            P[np.arange(dim), value * nd + k * dim + np.arange(dim)] = 1.0
            maps.append(P)
        return maps
    e, loc = checks.locate(value, beam.s_nodes, beam.lengths, arg="where")
    e, loc = int(e[0]), float(loc[0])
    cols = beam.edofs[e]
    L = beam.lengths[[e]]

    def S_at(x):
        return el.shape_matrix(np.array([x]), L)[0, 0]        # (dim, n_edof)

    S = S_at(loc)
    maps = [S]
    if _thin(el):
        # d/dx = (2/L) d/ds; the five-point central difference is exact for polynomials of degree <= 4
        hs = 0.5
        dS = (S_at(loc - 2 * hs) - 8 * S_at(loc - hs) + 8 * S_at(loc + hs) - S_at(loc + 2 * hs)) / (12 * hs)
        maps.append(dS * (2.0 / L[0]))
    else:
        # the SQ elements interpolate every nodal vector with the same functions: shift S to the k-th vector
        nn = el.n_nodes
        S4 = S.reshape(dim, nn, el.n_node_dof // dim, dim)
        for k in range(1, _n_axes(el) + 1):
            D4 = np.zeros_like(S4)
            D4[:, :, k, :] = S4[:, :, 0, :]
            maps.append(D4.reshape(dim, -1))
    full = []
    for X in maps:
        F = np.zeros((dim, n_full))
        np.add.at(F, (slice(None), cols), X)
        full.append(F)
    return full


def beam_attachment(beam, where) -> Attachment:
    """The :class:`~ancfdae.attachment.Attachment` of ``beam`` at ``where``; see :meth:`Beam.attachment`."""
    kind, value = _where(beam, where)
    maps = _full_maps(beam, kind, value)
    free, fixed = beam.free, beam.fixed
    q_fixed = beam.q_ref[fixed]
    parts = [(sp.csr_matrix(F[:, free]), F[:, fixed] @ q_fixed) for F in maps]
    label = f"node {value}" if kind == "node" else f"s = {value:g}"
    return Attachment(position=parts[0][0], axes=tuple(p[0] for p in parts[1:]), label=label,
                      offset=parts[0][1], axes_offset=tuple(p[1] for p in parts[1:]))
