"""SQ3D: the spatial shear- and cross-section-deformable ANCF beam element (chapter Sect. 4).

Per node the position and the two cross-section slopes,
``(x, y, z, x_eta, y_eta, z_eta, x_zeta, y_zeta, z_zeta)`` (Eq. 57); quadratic
three-node interpolation (Eq. 107, 27 DOF) by default, linear two-node
(Eq. 106, 18 DOF) as an option.
"""
from __future__ import annotations

import numpy as np

from ..jets import vector as jet
from ..jets.vector import Jet
from .base import SQElement, shear_factors

__all__ = ["SQ3D"]


def frame(a2: Jet, a3: Jet) -> tuple[Jet, Jet, Jet, Jet, Jet, Jet]:
    """The local frame of chapter Eq. 7 from the slope jets ``a2 = x_eta``, ``a3 = x_zeta``.

    Returns the jets ``e1, e2, e3`` and the scalars ``m = |a3|``,
    ``n = |a2 x a3|``, ``t = a2 . e3`` used by the curvature.
    """
    m = jet.sqrt(jet.dot(a3, a3))
    e3 = jet.mul(jet.recip(m), a3)
    c = jet.cross(a2, a3)
    n = jet.sqrt(jet.dot(c, c))
    e1 = jet.mul(jet.recip(n), c)
    e2 = jet.cross(e3, e1)
    return e1, e2, e3, m, n, jet.dot(a2, e3)


class SQ3D(SQElement):
    """Spatial shear- and cross-section-deformable ANCF beam element (chapter Sect. 4).

    Parameters
    ----------
    material : Material
    section : RectangularSection or CircularSection
        Structural: ``A``, ``I2``, ``I3``, ``J``, ``k_t`` and the shear factors
        ``(k2, k3) = section.shear_factors_of(material)`` (or ``k_s(material)``
        for both), set with ``RectangularSection(h, b, shear_factors=(k2, k3),
        torsion_factor=k_t)``.
    formulation : {"structural", "continuum", "continuum-locking"}
        ``"structural"`` (Sects. 2.1.2, 2.2.2, 4.2.2, after Simo 1985): the
        frame of Eq. 7, generalised strains ``Gamma_i = e_i.r' - delta_i1``
        (Eq. 16 in the local frame) and ``kappa_i`` the local components of
        ``k = 1/2 e_i x e_i'`` (Eqs. 19, 25), which for the frame of Eq. 7 are
        ``kappa_1 = -e_2.a3'/m``, ``kappa_2 = e_1.a3'/m``,
        ``kappa_3 = e_1.(t a3' - m a2')/n`` (``m = |a3|``, ``n = |a2 x a3|``,
        ``t = a2.e_3``); ``U = 1/2 int D_SM`` (Eqs. 42, 111, shear
        stiffnesses ``k2 G A`` for ``Gamma_2`` (along eta) and ``k3 G A`` for
        ``Gamma_3`` (along zeta), torsion ``G J k_t``) plus the cross-section
        energy of Eq. 48, ``1/2 int EA (E_22^2 + E_33^2) + GA gamma_23^2`` with
        ``gamma_23 = 2 E_23 = a2.a3`` (Eq. 50). The chapter's Eq. 47 writes
        ``2G E_23 dE_23``; ``T:dE`` of the isotropic law gives ``4G E_23 dE_23``,
        used here (it only matters for cross-section shear).
        ``"continuum"``: Green strain, St. Venant-Kirchhoff (Eqs. 28-36, Eq. 34
        read as the standard isotropic law, whose factors the chapter's text lost), transverse shears ``gamma_12`` with ``k2 G`` and
        ``gamma_13`` with ``k3 G``, with the Poisson-locking remedy of Eq. 108;
        ``"continuum-locking"`` without it. The continuum cross-section stays
        plane (no warping), so its torsional rigidity is that of the shear
        strains ``gamma_12 = -zeta phi'``, ``gamma_13 = eta phi'`` of a plane
        twisted section, ``G (k2 I2 + k3 I3)`` -- ``k_s G J`` with the polar
        moment ``J = I2 + I3`` -- not Saint-Venant's ``G J k_t``: 28 % stiffer
        on a 0.1 x 0.06 rectangle with Cowper's ``k_s``, more on flatter
        sections; ``torsion_factor`` does not enter (tests).
    nodes : {3, 2}
        Quadratic (default, Eq. 107) or linear (Eq. 106) interpolation.
    quadrature : dict, optional
        As for :class:`~ancfdae.models.SQ2D`.
    kernel : {"auto", "numba", "numpy"}
        As for :class:`~ancfdae.models.SQ2D`: the compiled kernel (default)
        or the NumPy reference.
    """

    name = "SQ3D"
    dim = 3
    node_coordinates = ("x", "y", "z", "x_eta", "y_eta", "z_eta", "x_zeta", "y_zeta", "z_zeta")
    _terms = ("axial", "shear", "shear", "bending", "bending", "bending",
              "cross_section", "cross_section", "cross_section")

    def _stiffness(self):
        m, s = self.material, self.section
        E, G, A = m.E, m.G, s.A
        k2, k3 = shear_factors(s, m)
        return np.array([E * A, k2 * G * A, k3 * G * A, G * s.J * s.k_t, E * s.I2, E * s.I3, E * A, E * A, G * A])

    @staticmethod
    def _strains(p, which):
        """``(terms, s)`` of Gamma_1..3, kappa_1..3, E_22, E_33, gamma_23 (those in ``which``).

        Derivative blocks: 0 = r', 1 = a2', 2 = a3'.
        """
        a2, a3 = p
        half = np.full(a2.v.shape[0], 0.5)
        out = {6: ([], jet.combine([half], [jet.dot(a2, a2)])), 7: ([], jet.combine([half], [jet.dot(a3, a3)])),
               8: ([], jet.dot(a2, a3))}
        if any(k < 6 for k in which):
            e1, e2, e3, m, n, t = frame(a2, a3)
            im, inn = jet.recip(m), jet.recip(n)
            out.update({0: ([(0, e1)], None), 1: ([(0, e2)], None), 2: ([(0, e3)], None),
                        3: ([(2, jet.mul(im, e2, -1.0))], None), 4: ([(2, jet.mul(im, e1))], None),
                        5: ([(1, jet.mul(jet.mul(m, inn), e1, -1.0)), (2, jet.mul(jet.mul(t, inn), e1))], None)})
        return [out[k] for k in which]

    def _rotation_force(self, p, moment):
        """``G^T M`` and its derivative for ``delta phi = 1/2 e_i x delta e_i`` (Sect. 2.2), frame of Eq. 7."""
        x = p[None, :]
        a2, a3 = jet.variable(x, 0, 3, 0, 6), jet.variable(x, 3, 3, 3, 6)
        M = moment
        f = np.zeros(6)
        K = np.zeros((6, 6))
        Mx = np.array([[0, -M[2], M[1]], [M[2], 0, -M[0]], [-M[1], M[0], 0]])
        for e in frame(a2, a3)[:3]:
            w = np.cross(M, e.v[0])                     # M . (e x de) = de . (M x e)
            f += 0.5 * e.g[0].T @ w
            K += 0.5 * (np.einsum("c,ckl->kl", w, e.h[0]) + e.g[0].T @ Mx @ e.g[0])
        return f, K
