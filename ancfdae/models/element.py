"""The element interface that :class:`ancfdae.models.Beam` assembles.

An element type is a class with a few class attributes describing its node
layout and methods that work on *all elements at once*: element coordinate
arrays have shape ``(n_el, n_edof)`` and element matrices
``(n_el, n_edof, n_edof)``; kernels loop over neither elements nor quadrature
points in Python.

Conventions
-----------
* Normalised element coordinate ``s`` in [-1, 1]; the chapter's axial
  coordinate is ``xi = s L / 2`` with ``L`` the element's reference length.
* Element coordinates are the nodal coordinate blocks in element node order,
  ``q_e = [q^(A), q^(B)(, q^(C))]`` (chapter Eq. 54); 3-node elements order
  their nodes A (s = -1), B (s = +1), C (s = 0) as in chapter Eq. 105.
  Along the beam, nodes are numbered in axial order, so the global matrices
  are banded.
* Residual sign: ``internal_forces`` returns ``+dU/dq_e`` (the force the
  element needs, not the force it applies).
* A *geometry* object, returned by :meth:`Element.prepare`, holds whatever the
  element precomputes for a mesh (reference lengths, shape functions at the
  quadrature points, reference strains, constant mass matrices, directors);
  the beam passes it back to every kernel call.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, Callable, ClassVar

import numpy as np

__all__ = ["Element"]


class Element(ABC):
    """Base class of the ANCF element types.

    Attributes
    ----------
    name : str
        Short name used in tables ("BE2D", "SQ3D", ...).
    dim : int
        Space dimension, 2 or 3.
    node_params : tuple of float
        Normalised coordinate ``s`` of each element node, in element node
        order: ``(-1, 1)`` or ``(-1, 1, 0)``.
    node_coordinates : tuple of str
        Names of the coordinates of one node, e.g. ``("x", "y", "x'", "y'")``.
    mass_is_constant : bool
        False only for elements whose mass matrix depends on q (BE3D).
    formulations : tuple of str
        The formulation variants the element offers.
    energy_degree : int or None
        Degree of the strain energy as a polynomial in the element
        coordinates, or None when it is not a polynomial (an energy-momentum
        integrator integrates the gradient of a polynomial energy exactly
        along the step with a Gauss rule).
    material : Material
        Instance attribute, required: the beam reads ``rho`` from it.
    section : RectangularSection or CircularSection
        Instance attribute, required: the beam reads ``A`` from it.

    Notes
    -----
    The attributes up to ``energy_degree`` are class attributes. Subclasses
    keep every constructor option under its argument name, so that
    :meth:`Beam.describe` records it and a result file can rebuild the element.
    """

    name: ClassVar[str]
    dim: ClassVar[int]
    node_params: ClassVar[tuple[float, ...]]
    node_coordinates: ClassVar[tuple[str, ...]]
    mass_is_constant: ClassVar[bool] = True
    formulations: ClassVar[tuple[str, ...]] = ("structural",)
    energy_degree: ClassVar[int | None] = None

    @property
    def n_nodes(self) -> int:
        """Nodes per element."""
        return len(self.node_params)

    @property
    def n_node_dof(self) -> int:
        """Coordinates per node."""
        return len(self.node_coordinates)

    @property
    def n_edof(self) -> int:
        """Coordinates per element."""
        return self.n_nodes * self.n_node_dof

    # -- mesh ---------------------------------------------------------------
    @abstractmethod
    def reference_coordinates(self, points: np.ndarray, frames: np.ndarray) -> np.ndarray:
        """Nodal coordinates of the undeformed configuration.

        Parameters
        ----------
        points : ndarray, shape (n_nodes_global, dim)
            Node positions on the axis.
        frames : ndarray, shape (n_nodes_global, dim, dim)
            Orthonormal cross-section frames, columns ``(e1, e2[, e3])``, with
            ``e1`` the unit axis tangent (chapter Eq. 6).

        Returns
        -------
        ndarray, shape (n_nodes_global, n_node_dof)
        """

    @abstractmethod
    def support_coordinates(self, kind: str, frame: np.ndarray) -> tuple[str, ...]:
        """Names of the node coordinates that a support of ``kind`` fixes.

        ``kind`` is ``"clamp"`` (position and orientation) or ``"pin"``
        (position only). ``frame`` is the node's reference frame; elements
        use it to leave the axial stretch free at a clamp where that can be
        done by fixing coordinates (the cantilever of chapter Sect. 5.1).
        """

    @abstractmethod
    def prepare(self, q_ref: np.ndarray, lengths: np.ndarray) -> Any:
        """Precompute everything that depends on the mesh only.

        Parameters
        ----------
        q_ref : ndarray, shape (n_el, n_edof)
            Element coordinates of the undeformed configuration.
        lengths : ndarray, shape (n_el,)
            Reference lengths of the elements.
        """

    # -- kernels ------------------------------------------------------------
    @abstractmethod
    def mass_matrix(self, geom: Any) -> np.ndarray:
        """Constant element mass matrices, shape (n_el, n_edof, n_edof).

        For an element with ``mass_is_constant = False`` this is the constant
        part only (the axis translation); the rest comes from :meth:`inertia`.
        """

    @abstractmethod
    def strain_energy(self, geom: Any, q: np.ndarray) -> np.ndarray:
        """Strain energy of each element, shape (n_el,)."""

    @abstractmethod
    def internal_forces(self, geom: Any, q: np.ndarray, tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """``f = dU/dq_e`` and, if ``tangent``, ``K = d f / d q_e``.

        Returns
        -------
        f : ndarray, shape (n_el, n_edof)
        K : ndarray, shape (n_el, n_edof, n_edof), or None
        """

    @abstractmethod
    def shape_matrix(self, s: np.ndarray, lengths: np.ndarray) -> np.ndarray:
        """Axis position interpolation ``r(s) = S(s) q_e``.

        Returns
        -------
        ndarray, shape (n_el, n_pts, dim, n_edof)
        """

    @abstractmethod
    def moment_load(self, geom: Any, q: np.ndarray, s: float, moment: np.ndarray, element: int,
                    tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Generalised force of a dead moment acting at axis point ``s`` of one element.

        The virtual work of a moment is ``M . delta phi`` with the virtual
        rotation ``delta phi`` of the cross-section frame at ``s``
        (chapter Sect. 2.2), ``delta phi = G(q) delta q``; the generalised
        force is ``G^T M``.

        Parameters
        ----------
        q : ndarray, shape (n_edof,)
            Coordinates of element ``element``.
        moment : ndarray, shape (3,) (the z component alone acts in 2D)

        Returns
        -------
        f : ndarray, shape (n_edof,)
            Load vector (enters the residual with a minus sign).
        dfdq : ndarray, shape (n_edof, n_edof), or None
        """

    # -- optional: fused compiled assembly ----------------------------------
    def fused_kernel(self, geom: Any) -> tuple[Callable, tuple] | None:
        """The element's fused gather-kernel-scatter entry point, or None (the default).

        An element with a compiled kernel returns ``(fn, args)``; the beam then
        assembles the internal forces and tangent by the single call
        ``fn(q, q_fixed, gather, vec_slot, mat_slot, tangent, r, kdata, *args)``
        (the contract is in :mod:`ancfdae.models._assembly_numba`), which must
        give the same arrays as :meth:`internal_forces` followed by the beam's
        scatter. ``geom`` may be the geometry of stacked copies of the mesh.
        """
        return None

    # -- optional: configuration-dependent inertia (BE3D) ------------------
    def inertia(self, geom: Any, q: np.ndarray, v: np.ndarray, a: np.ndarray, jacobian: bool = True) -> tuple:
        """Inertia forces beyond the constant mass matrix.

        Only for ``mass_is_constant = False``: returns ``f`` of shape
        (n_el, n_edof) such that the element's inertia force is
        ``M_const a + f``, and if ``jacobian`` the blocks ``df/dq``, ``df/dv``,
        ``df/da`` of shape (n_el, n_edof, n_edof).
        """
        raise NotImplementedError

    def kinetic_energy_extra(self, geom: Any, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Kinetic energy beyond ``1/2 v^T M_const v``, shape (n_el,)."""
        return np.zeros(len(q))

    def event_state(self, geom: Any) -> dict:
        """The element's event state in ``geom`` (arrays that may change between steps); none by default."""
        return {}

    def bind(self, geom: Any, state: dict) -> Any:
        """A geometry equal to ``geom`` but with the event ``state`` (``geom`` is not changed)."""
        return geom

    def step_event(self, geom: Any, Q: np.ndarray, V: np.ndarray) -> tuple | None:
        """Event after an accepted time or load step (BE3D's director update); None = nothing changed.

        ``Q``, ``V``: full nodal coordinate and velocity arrays, shape
        (n_nodes_global, n_node_dof). Returns None or the (re-parametrised) ``(Q, V, state)``
        with the new event state; the physical configuration must not change.
        """
        return None
