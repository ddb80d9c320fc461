"""The rigid motions of a free :class:`~ancfdae.models.Beam`, for the potential capability
(``ancfdae.problem.PotentialModel``).

Energy-momentum integrators need the conservative part of the beam's forces on its own (the beam's
``potential``, ``potential_gradient`` and ``nonconservative_force``) and the rigid motions that leave the
strain energy unchanged, which :func:`symmetry_generators` gives; :func:`beam_potential` is the beam's
``potential``.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..element import Element

__all__ = ["symmetry_generators", "beam_potential"]


def beam_potential(beam: "ancfdae.models.Beam", t: float, q: np.ndarray) -> float:
    """``U(q) + V(q)``, with the gravity potential zero in the reference configuration (the beam's ``potential``).

    ``U`` in one compiled call where the element's kernel object offers the optional method
    ``fused_energy(geom) -> (fn, args)``: ``U = fn(q, q_fixed, gather, *args)``, the elements' energies summed
    with their coordinates read through the beam's gather (:mod:`ancfdae.models.thin.be2d_energy_numba`;
    energy-collocation's energy balance calls this once per step; cost of both paths:
    ``python -m benchmarks.be2d_potential``). Else, as for an element subclass with its own ``strain_energy``,
    the sum of ``element.strain_energy``; both equal to round-off (``tests/models/thin/test_be2d_energy.py``).
    """
    el = beam.element
    fused = getattr(getattr(el, "kernels", None), "fused_energy", None)
    if fused is None or type(el).strain_energy is not Element.strain_energy:
        U = float(np.sum(el.strain_energy(beam.geom, beam._element_q(q))))
    else:
        fn, args = fused(beam.geom)
        U = fn(np.ascontiguousarray(q, dtype=float), beam._q_fixed, beam._gather, *args)
    return U - beam.load_factor * float(beam._load_set.gravity @ (q - beam.q_ref[beam.free]))


def symmetry_generators(dim: int, node_dof: int, n_nodes: int, fixed: np.ndarray) -> tuple[np.ndarray, list]:
    """Translations of the nodal positions and rotations of every nodal vector (free beams only).

    Every node of a constant-mass ANCF element carries ``node_dof / dim``
    vectors (position first, then slopes) that a rigid rotation turns alike,
    and the strain energy depends on them only through rotation-invariant
    strains. A support fixes coordinates and breaks both symmetries: then
    ``(T, A)`` are empty.

    Returns
    -------
    T : ndarray (n_dof, dim)
        The translations, one column per axis.
    A : list of csr_matrix (n_dof, n_dof)
        The generators of the rotations about the axes (one in 2D, three in 3D).
    """
    n_dof = int((~fixed).sum())
    if fixed.any() or node_dof % dim:
        return np.zeros((n_dof, 0)), []
    n_vec = n_nodes * node_dof // dim
    T = np.zeros((n_nodes, node_dof, dim))
    T[:, :dim, :] = np.eye(dim)
    T = T.reshape(-1, dim)
    axes = [np.array([[0.0, -1.0], [1.0, 0.0]])] if dim == 2 else [
        np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),
        np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]]),
        np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])]
    A = [sp.csr_matrix(sp.kron(sp.identity(n_vec), W)) for W in axes]
    return T, A
