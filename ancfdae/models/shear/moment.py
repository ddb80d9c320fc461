"""The dead-moment load of SQ2D and SQ3D in NumPy (chapter Sect. 2.2).

The virtual rotation of the cross-section frame at ``s`` depends on the
cross-section slopes ``p`` there alone, ``delta phi = G(p) delta p``; each
element gives ``G^T M`` and its derivative in ``p`` (its ``_rotation_force``:
the frame of Eq. 7 in 3D, the slope's turn in 2D), and ``p = Bp q_e`` with the
Lagrange functions of Eqs. 104-107 carries it to the element coordinates. The
compiled twin is :func:`.moment_numba.sq_moment_load`.
"""
from __future__ import annotations

import numpy as np

from .points import local_map, shapes

__all__ = ["moment_load"]


def slope_map(element, geom: dict, s: float, index: int) -> np.ndarray:
    """``p = Bp q_e``: the cross-section slopes at ``s`` of element ``index``, shape (n_p, n_edof)."""
    N, dN = shapes(element.nodes, np.array([float(s)]), geom["L"][[index]])
    return local_map(N, dN, element.dim)[0, 0, :element.dim * (element.dim - 1)]


def moment_load(element, geom: dict, q: np.ndarray, s: float, moment: np.ndarray, index: int,
                tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """Force (n_edof,) and, if ``tangent``, its derivative of the dead ``moment`` (3,) at ``s`` of element
    ``index`` (``q``: that element's coordinates)."""
    Bp = slope_map(element, geom, s, index)
    fp, dfp = element._rotation_force(Bp @ np.asarray(q, dtype=float), np.asarray(moment, dtype=float))
    return Bp.T @ fp, (Bp.T @ dfp @ Bp if tangent else None)
