"""The potential capability of a :class:`~ancfdae.models.Beam` (``ancfdae.problem.PotentialModel``).

Energy-momentum integrators need the conservative part of the beam's forces on its own:
the potential ``P = U + V`` (strain energy plus gravity), its gradient and Hessian at
arbitrary states, the non-conservative loads (dead forces and moments) separately, and
the rigid motions that leave ``U`` unchanged. :class:`PotentialMixin` provides them from
the beam's element kernels; ``Beam`` inherits it.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["PotentialMixin"]


class PotentialMixin:
    """``potential``, ``potential_gradient``, ``nonconservative_force``, ``symmetry_generators``."""

    @property
    def potential_degree(self) -> int | None:
        """Polynomial degree of ``P`` in the coordinates, or None (from the element's ``energy_degree``)."""
        return getattr(self.element, "energy_degree", None)

    def potential(self, t: float, q: np.ndarray) -> float:
        """``U(q) + V(q)``, with the gravity potential zero in the reference configuration."""
        U = float(np.sum(self.element.strain_energy(self.geom, self._element_q(q))))
        return U - self.load_factor * float(self._f_gravity @ (q - self.q_ref[self.free]))

    def potential_gradient(self, t: float, q: np.ndarray,
                           tangent: bool = True) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """``(dU/dq - lambda f_gravity, d2U/dq2 as CSR or None)``."""
        g, kdata = self.internal_forces(q, tangent)
        return g - self.load_factor * self._f_gravity, (self._asm.csr(kdata) if tangent else None)

    def nonconservative_force(self, t: float, q: np.ndarray,
                             tangent: bool = True) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """Dead forces and moments ``(f_nc, df_nc/dq as CSR or None)`` (every load except gravity)."""
        f, kdata = self._f_nonconservative(t, self.expand(q), tangent)
        if not tangent:
            return self.load_factor * f, None
        kdata = self._zero_data if kdata is None else kdata
        return self.load_factor * f, self._asm.csr(self.load_factor * kdata)

    def symmetry_generators(self) -> tuple[np.ndarray, list[sp.csr_matrix]]:
        """Translations of the nodal positions and rotations of every nodal vector (free beams only).

        Every node of a constant-mass ANCF element carries ``n_node_dof / dim``
        vectors (position first, then slopes) that a rigid rotation turns alike,
        and the strain energy depends on them only through rotation-invariant
        strains. A support fixes coordinates and breaks both symmetries: then
        ``(T, A)`` are empty.
        """
        dim, nnd = self.element.dim, self.element.n_node_dof
        if self.fixed.any() or nnd % dim:
            return np.zeros((self.n_dof, 0)), []
        n_vec = self.n_nodes * nnd // dim
        T = np.zeros((self.n_nodes, nnd, dim))
        T[:, :dim, :] = np.eye(dim)
        T = T.reshape(-1, dim)
        axes = [np.array([[0.0, -1.0], [1.0, 0.0]])] if dim == 2 else [
            np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),
            np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]]),
            np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])]
        A = [sp.csr_matrix(sp.kron(sp.identity(n_vec), W)) for W in axes]
        return T, A
