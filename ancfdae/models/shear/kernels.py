"""The NumPy reference kernel object of SQ2D and SQ3D: energy, forces and tangent over the point groups.

The element's points come in groups, one per distinct quadrature rule
(:meth:`.base.SQElement.prepare`); at each group the local variables
``v = B q_e`` (:mod:`.points`) enter the structural (:mod:`.structural`) or
continuum (:mod:`.continuum`) energy density, and ``B^T g``, ``B^T H B``
assemble the element force and tangent. The compiled twin is
:class:`~.sq_kernel.SQCompiled`.
"""
from __future__ import annotations

import numpy as np

from ..element import OnePassKernel
from .continuum import continuum_kernel
from .moment import moment_load
from .points import assemble, local_map
from .structural import structural_kernel

__all__ = ["SQReference"]


class SQReference(OnePassKernel):
    """The NumPy reference of the SQ kernels: vectorised over all elements x points of a group."""

    name = "numpy"

    def energy_forces(self, geom: dict, q: np.ndarray, order: int) -> tuple:
        """Energy (n_el,), and for ``order`` >= 1 the forces, for ``order`` 2 the tangent (else None).

        ``order`` is that of the jets: 0 energy, 1 plus gradient, 2 plus Hessian.
        """
        el = self.element
        q = np.asarray(q, dtype=float)
        W, f, K = 0.0, 0.0, None
        for grp in geom["groups"]:
            B = local_map(grp["N"], grp["dN"], el.dim)    # (n_el, n_pts, n_v, n_edof): not kept in geom
            E, P, nv = B.shape[:3]
            v = np.einsum("epvi,ei->epv", B, q).reshape(E * P, nv)
            if el.formulation == "structural":
                w, g, H, _ = structural_kernel(el._strains, grp["which"], v, el.dim, grp["ref"], grp["Dw"], order)
            else:
                w, g, H = continuum_kernel(v, el.dim, grp["Pc"], grp["ws"], grp["Ds"], grp["ref"], grp["wax"],
                                           order)
            W = W + w.reshape(E, P).sum(axis=1)
            if order >= 1:
                fg, Kg = assemble(B, g.reshape(E, P, nv), None if H is None else H.reshape(E, P, nv, nv))
                f = f + fg
                K = Kg if K is None else K + Kg
        return W, f, K

    def moment_load(self, geom: dict, q: np.ndarray, s: float, moment: np.ndarray, element: int,
                    tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """The dead moment of :func:`.moment.moment_load`."""
        return moment_load(self.element, geom, q, s, moment, element, tangent)
