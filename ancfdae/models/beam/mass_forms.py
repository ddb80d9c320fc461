"""The mass forms of a beam whose mass matrix depends on the configuration (BE3D, BE3DSR).

An energy-momentum integrator for ``T = 1/2 v^T M(q) v`` needs more of ``M`` than the Model contract's
``mass(q)``: the action ``M(q) x`` with its derivative in ``q``, and the bilinear form
``B(q) = 1/2 u^T M(q) w`` with its gradient and Hessian for fixed ``u, w`` (the capability
``"mass_forms"`` of :mod:`ancfdae.problem`). :class:`MassForms` gives a :class:`~.beam.Beam` these from its
element's ``inertia`` (with ``v = 0`` the inertia force is ``M_rot(q) a``) and ``mass_bilinear`` and the
constant mass of the axis (chapter Eq. 27).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["MassForms"]


class MassForms:
    """Mixin of :class:`~.beam.Beam`: ``mass_action`` and ``mass_bilinear`` over the free coordinates."""

    def mass_action(self, q: np.ndarray, x: np.ndarray, tangent: bool = True) -> tuple:
        """``M(q) x`` and, if ``tangent``, its derivative ``d(M(q) x)/dq`` (CSR), else None.

        Parameters
        ----------
        q, x : ndarray (n_dof,)
            Free coordinates and the vector ``M`` acts on.
        tangent : bool
        """
        Mx = self._M_csr @ x
        if self.mass_is_constant:
            return Mx, (sp.csr_matrix((self.n_dof, self.n_dof)) if tangent else None)
        f, blocks = self._inertia(q, np.zeros(self.n_dof), x, tangent)
        return Mx + f, (self._asm.csr(blocks[0]) if tangent else None)

    def mass_bilinear(self, q: np.ndarray, u: np.ndarray, w: np.ndarray, order: int = 2) -> tuple:
        """``B = 1/2 u^T M(q) w`` and, by ``order``, ``dB/dq`` (n_dof,) and ``d2B/dq2`` (CSR), ``u, w`` fixed.

        Parameters
        ----------
        q, u, w : ndarray (n_dof,)
        order : int
            0, 1 or 2: the highest derivative returned.
        """
        value = 0.5 * float(u @ (self._M_csr @ w))
        if self.mass_is_constant:
            zeros = (np.zeros(self.n_dof), sp.csr_matrix((self.n_dof, self.n_dof)))
            return (value, *zeros[:order])
        e = self.edofs
        out = self.element.mass_bilinear(self.geom, self.expand(q)[e], self._expand_v(u)[e], self._expand_v(w)[e],
                                         order)
        res = [value + float(np.sum(out[0]))]
        if order >= 1:
            res.append(self._asm.vector(out[1]))
        if order >= 2:
            res.append(self._asm.csr(self._asm.data(out[2])))
        return tuple(res)
