"""SQ2D: the planar shear- and cross-section-deformable ANCF beam element (chapter Sect. 4).

Per node the position and the cross-section slope, ``(x, y, x_eta, y_eta)``
(gradient-deficient, Eq. 57 without ``x_zeta``); quadratic three-node
interpolation (Eq. 105, 12 DOF) by default, linear two-node (Eq. 104, 8 DOF)
as an option.
"""
from __future__ import annotations

import numpy as np

from ..jets import vector as jet
from .base import SQElement, shear_factors

__all__ = ["SQ2D"]



class SQ2D(SQElement):
    """Planar shear- and cross-section-deformable ANCF beam element (chapter Sect. 4).

    Parameters
    ----------
    material : Material
    section : RectangularSection or CircularSection
        Structural: ``A``, ``I3`` (in-plane bending) and the shear factor
        ``k2`` of the shear along eta (``section.shear_factors_of(material)[0]``,
        i.e. ``k_s`` unless ``shear_factors=(k2, k3)`` is given).
    formulation : {"structural", "continuum", "continuum-locking"}
        ``"structural"`` (Sect. 4.2.2): the frame of the cross-section slope,
        ``e_2 = a/|a|``, ``e_1 = e_2 x e_z`` with ``a = x_eta`` (the planar
        analogue of Eq. 7); generalised strains ``Gamma_1 = e_1.r' - 1``,
        ``Gamma_2 = e_2.r'`` (Eq. 16), curvature ``kappa = (a x a').e_z/|a|^2``
        (Eqs. 19, 25) and thickness strain ``E_22 = (a.a - 1)/2`` (Eq. 50), with
        ``U = 1/2 int EA Gamma_1^2 + k2 GA Gamma_2^2 + EI kappa^2 + EA E_22^2
        dxi`` (Eqs. 109, 110).
        ``"continuum"`` (Sect. 4.2.1): Green strain and St. Venant-Kirchhoff,
        plane stress, shear with ``k2``, with the Poisson-locking remedy of
        Eq. 108 (Poisson part on the axis only). ``"continuum-locking"``: the
        same without the remedy (Poisson locking in bending).
    nodes : {3, 2}
        Quadratic (default, Eq. 105) or linear (Eq. 104) interpolation.
    quadrature : dict, optional
        Override of :meth:`default_quadrature`: structural terms ``"axial"``,
        ``"shear"``, ``"bending"``, ``"cross_section"``; continuum ``"axial"``,
        ``"section"``; each a number of Gauss points or
        ``("gauss"|"lobatto", n)``.
    kernel : {"auto", "numba", "numpy"}
        Implementation of the energy, forces, tangent and moment load.
        ``"numba"`` and ``"auto"`` (the default): one compiled loop over
        elements x points (:class:`~ancfdae.models.shear.sq_kernel.SQCompiled`,
        same results to rounding; the first use compiles, 1-3 minutes on a
        loaded 2-core machine, then loads from the on-disk cache in about a
        second). ``"numpy"``: the vectorised NumPy kernels
        (:class:`~ancfdae.models.shear.kernels.SQReference`), the readable
        reference. Settable later through the ``kernel`` attribute;
        ``kernel_in_use`` says which one runs.
    """

    name = "SQ2D"
    dim = 2
    node_coordinates = ("x", "y", "x_eta", "y_eta")
    _terms = ("axial", "shear", "bending", "cross_section")

    def _stiffness(self):
        m, s = self.material, self.section
        k2 = shear_factors(s, m)[0]                 # shear along eta, the in-plane transverse direction
        return np.array([m.E * s.A, k2 * m.G * s.A, m.E * s.I3, m.E * s.A])

    @staticmethod
    def _strains(p, which):
        """``(terms, s)`` of Gamma_1, Gamma_2, kappa, E_22 (those in ``which``); blocks 0 = r', 1 = a'."""
        a = p[0]
        aa = jet.dot(a, a)
        out = {3: ([], jet.combine([np.full(aa.v.shape, 0.5)], [aa]))}
        if any(k < 3 for k in which):
            e2 = jet.mul(jet.recip(jet.sqrt(aa)), a)
            # e_1 = (e_2y, -e_2x): e_2 turned by -90 degrees, so that (e_1, e_2, e_z) is right-handed;
            # (a x a').e_z / |a|^2 = a' . (-a_y, a_x) / |a|^2
            out.update({0: ([(0, jet.turn(e2, 1.0))], None), 1: ([(0, e2)], None),
                        2: ([(1, jet.mul(jet.recip(aa), jet.turn(a, -1.0)))], None)})
        return [out[k] for k in which]

    def _rotation_force(self, p, moment):
        """Planar dead moment: ``delta phi = (a x delta a).e_z / |a|^2`` of the slope ``a = x_eta``."""
        a = jet.variable(p[None, :], 0, 2, 0, 2)
        g = jet.mul(jet.recip(jet.dot(a, a)), jet.turn(a, -1.0))
        Mz = float(moment[2])
        return Mz * g.v[0], Mz * g.g[0]
