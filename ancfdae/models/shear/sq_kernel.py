"""The compiled kernel object of SQ2D and SQ3D: one face over the compiled entry points.

:class:`SQCompiled` hands the beam the element family's compiled calls: the forces and energy
(:mod:`.kernels_numba`), the dead moment (:mod:`.moment_numba`), the fused assembly entry points and the
forces at several configurations projected (:mod:`.projection_numba`). It lives apart from the kernels so that
the projection kernels, which reuse the element kernels, and this face that offers both import in one
direction. Importing it compiles (or loads) numba code; :mod:`.base` imports it only when the compiled kernel is
selected.
"""
from __future__ import annotations

import numpy as np

from ..element import OnePassKernel
from . import projection_numba as pn
from .kernels_numba import compiled_geometry, sq_continuum, sq_continuum_fused, sq_structural, sq_structural_fused
from .moment_numba import sq_moment_load

__all__ = ["SQCompiled"]


class SQCompiled(OnePassKernel):
    """The compiled kernel object of SQ2D and SQ3D: :func:`sq_structural` or :func:`sq_continuum`, the
    compiled dead moment and the fused entry points."""

    name = "numba"

    def _arrays(self, geom):
        """The compiled kernels' arrays of ``geom`` (:func:`compiled_geometry`), built once per geometry."""
        arrays = geom.get("_numba")
        if arrays is None:
            el = self.element
            arrays = geom["_numba"] = compiled_geometry(el.formulation, el.dim, len(el._terms), geom)
        return arrays

    def energy_forces(self, geom: dict, q: np.ndarray, order: int) -> tuple:
        """As :meth:`.kernels.SQReference.energy_forces`, compiled (the forces are zeros for ``order`` 0)."""
        q = np.ascontiguousarray(q, dtype=float)
        if self.element.formulation == "structural":
            return sq_structural(q, *self._arrays(geom), self.element.dim, order)
        return sq_continuum(q, *self._arrays(geom), self.element.dim, order)

    def moment_load(self, geom: dict, q: np.ndarray, s: float, moment: np.ndarray, element: int,
                    tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """As :meth:`.kernels.SQReference.moment_load`, compiled."""
        el = self.element
        f, K = sq_moment_load(np.ascontiguousarray(q, dtype=float), float(s), el.nodes, el.dim,
                              np.ascontiguousarray(moment, dtype=float), bool(tangent))
        return f, (K if tangent else None)

    def fused(self, geom: dict) -> tuple:
        """``(sq_structural_fused or sq_continuum_fused, args)`` (see :meth:`ancfdae.models.Element.fused_kernel`)."""
        hit = geom.get("_numba_fused")
        if hit is None:
            fn = sq_structural_fused if self.element.formulation == "structural" else sq_continuum_fused
            hit = geom["_numba_fused"] = (fn, tuple(self._arrays(geom)) + (self.element.dim,))
        return hit

    def fused_projection(self, geom: dict) -> tuple:
        """``(fn, args)``: the forces at several configurations, projected (``sq3d_structural_projection``,
        ``sq2d_structural_projection`` or ``sq_continuum_projection`` of :mod:`.projection_numba`; see
        :meth:`ancfdae.models.beam.stages.StageEvaluator.projection`)."""
        if self.element.formulation == "structural":     # one entry point per dimension (compiled on first use)
            return (pn.sq3d_structural_projection if self.element.dim == 3 else pn.sq2d_structural_projection,
                    tuple(self._arrays(geom)))
        return pn.sq_continuum_projection, tuple(self._arrays(geom)) + (self.element.dim,)
