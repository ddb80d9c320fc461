"""The compiled kernel object of BE2D: one face over the compiled entry points.

:class:`BE2DCompiled` hands the beam BE2D's compiled calls: the forces and tangent and the fused assembly,
Newton iterations and whole steps (:mod:`.be2d_numba`), the strain energy (:mod:`.be2d_energy_numba`) and the
forces at several configurations projected (:mod:`.be2d_projection_numba`). It lives apart from the kernels so
that the projection kernel, which reuses the element kernel, and this face that offers both import in one
direction. Importing it compiles (or loads) numba code; :mod:`.be2d` imports it only when the compiled kernel is
selected.
"""
from __future__ import annotations

import numpy as np

from ..element import Kernel
from .be2d_energy_numba import CONTINUUM, STRUCTURAL, be2d_energies, be2d_energy_fused
from .be2d_numba import (be2d_alpha_iterations, be2d_alpha_steps, be2d_forces, be2d_fused, be2d_index3_steps,
                         be2d_multipliers, be2d_static_newton)
from .be2d_projection_numba import be2d_projection

__all__ = ["BE2DCompiled"]


class BE2DCompiled(Kernel):
    """The compiled kernel object of BE2D: :func:`be2d_forces` and the fused entry point :func:`be2d_fused`."""

    name = "numba"

    def _args(self, geom):
        """The kernel's arguments after ``q``: C-contiguous float copies, made once per geometry."""
        args = geom.get("_numba")
        if args is None:
            el = self.element
            E, sec = el.material.E, el.section
            form = STRUCTURAL if el.formulation == "structural" else CONTINUUM
            args = geom["_numba"] = tuple(np.ascontiguousarray(geom[k], dtype=float)
                                          for k in ("dN_e", "ddN_e", "w", "eps_ref", "K_ref")) + (
                geom["n_a"], form, E * sec.A, E, sec.I3, sec.I4)
        return args

    def internal_forces(self, geom: dict, q: np.ndarray,
                        tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """As :meth:`.be2d.BE2DReference.internal_forces`, compiled."""
        f, K = be2d_forces(np.ascontiguousarray(q, dtype=float), *self._args(geom), bool(tangent))
        return f, (K if tangent else None)

    def fused(self, geom: dict) -> tuple:
        """``(be2d_fused, args)``: the fused assembly entry point (see :meth:`ancfdae.models.Element.fused_kernel`)."""
        return be2d_fused, self._args(geom)

    def fused_projection(self, geom: dict) -> tuple:
        """``(be2d_projection, args)``: the forces at several configurations, projected (see
        :meth:`ancfdae.models.beam.stages.StageEvaluator.projection`; :mod:`.be2d_projection_numba`)."""
        return be2d_projection, self._args(geom)

    def alpha_iterations(self, geom: dict) -> tuple:
        """``(be2d_alpha_iterations, args)``: compiled Newton iterations (:mod:`ancfdae.models.beam.iteration_numba`)."""
        return be2d_alpha_iterations, self._args(geom)

    def alpha_steps(self, geom: dict) -> tuple:
        """``(be2d_alpha_steps, args)``: compiled whole steps (:mod:`ancfdae.integrators._alpha_steps_numba`)."""
        return be2d_alpha_steps, self._args(geom)

    def static_newton(self, geom: dict) -> tuple:
        """``(be2d_static_newton, args)``: a load step's static full Newton (:mod:`ancfdae.models.beam.static_numba`)."""
        return be2d_static_newton, self._args(geom)

    def index3_steps(self, geom: dict) -> tuple:
        """``(be2d_index3_steps, args)``: whole index-3 steps of a System (:mod:`ancfdae.integrators._index3_steps_numba`)."""
        return be2d_index3_steps, self._args(geom)

    def multipliers(self, geom: dict) -> tuple:
        """``(be2d_multipliers, args)``: a System's reactions at an output time (:mod:`ancfdae.system_compiled`)."""
        return be2d_multipliers, self._args(geom)

    def strain_energy(self, geom: dict, q: np.ndarray) -> np.ndarray:
        """As :meth:`.be2d.BE2DReference.strain_energy`, compiled (:mod:`.be2d_energy_numba`)."""
        return be2d_energies(np.ascontiguousarray(q, dtype=float), *self._args(geom))

    def fused_energy(self, geom: dict) -> tuple:
        """``(be2d_energy_fused, args)``: the beam's strain energy read through its gather (the optional kernel
        method of :func:`ancfdae.models.beam.potential.beam_potential`)."""
        return be2d_energy_fused, self._args(geom)
