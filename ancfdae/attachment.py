"""Where a joint takes hold of a body: a material point and the vectors of its frame.

Every body of this package -- an ANCF beam (chapter Sects. 3-4: nodal positions and slopes are the
coordinates, Eqs. (1)-(3)) and a rigid body in natural coordinates (a point and its directors) -- places a
material point and its frame vectors *linearly* in its coordinates: ``r = P q``, ``d_k = D_k q`` with
constant matrices. A joint therefore needs nothing of a body but these maps, and every joint built from
them (points coincide, a point on a line, axes aligned, a fixed distance) is at most quadratic in ``q``:
its Jacobian is affine in ``q`` and the derivative of ``G^T lambda`` does not depend on ``q``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

__all__ = ["Attachment"]


@dataclass(frozen=True)
class Attachment:
    """A material point of one body and its frame vectors, as constant affine maps of the body's coordinates.

    Attributes
    ----------
    position : scipy.sparse.csr_matrix, shape (dim, n_dof)
        ``P`` with ``r = P q + offset``: the point's position from the body's coordinates ``q``.
    axes : tuple of scipy.sparse.csr_matrix, each shape (dim, n_dof)
        ``D_k`` with ``d_k = D_k q + axes_offset[k]``: the frame vectors at the point, in the body's own convention (a beam
        node: its slope vectors, e.g. ``r_x`` for BE2D and Cable3D, ``r_x, r_y (, r_z)`` for SQ2D/SQ3D;
        a rigid body: its directors). Not normalised: a beam's slope stretches.
    label : str
        How the point was named (``"node 3"``, ``"s = 0.5"``, ``"point (0.1, 0, 0)"``) for messages.
    offset : ndarray, shape (dim,), optional
        The constant part of the position: coordinates a body eliminated (a beam's supports) are not
        among ``q`` and enter here with their fixed values. Default zeros.
    axes_offset : tuple of ndarray, each shape (dim,), optional
        The constant parts of the frame vectors, likewise. Default zeros.
    """

    position: sp.csr_matrix
    axes: tuple[sp.csr_matrix, ...]
    label: str
    offset: np.ndarray | None = field(default=None)
    axes_offset: tuple[np.ndarray, ...] | None = field(default=None)

    def __post_init__(self) -> None:
        dim = self.position.shape[0]
        if self.offset is None:
            object.__setattr__(self, "offset", np.zeros(dim))
        if self.axes_offset is None:
            object.__setattr__(self, "axes_offset", tuple(np.zeros(dim) for _ in self.axes))
        if len(self.axes_offset) != len(self.axes):
            raise ValueError(f"`axes_offset` must hold one vector per axis ({len(self.axes)}), "
                             f"got {len(self.axes_offset)}.")

    @property
    def dim(self) -> int:
        """Spatial dimension (2 or 3)."""
        return self.position.shape[0]

    @property
    def n_dof(self) -> int:
        """Number of coordinates of the body the maps act on."""
        return self.position.shape[1]
