"""The element contract that :class:`ancfdae.models.Beam` assembles, the registry of element types and the kernel option.

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
* Registry: every subclass that sets its own ``name`` is registered under it
  (:meth:`Element.by_name`), so that a result file, which records the name,
  can rebuild a user's element as well as the built-in ones.
* Kernel option: an element with a NumPy reference and a compiled twin of its kernels lists both
  in ``kernel_twins``; setting ``kernel`` builds one :class:`Kernel` object, which the element's
  kernel methods call. The choice is made once, never per call.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from typing import Any, Callable, ClassVar

import numpy as np

from .._validate import choice

__all__ = ["Element", "Kernel", "OnePassKernel", "KERNELS", "resolve_kernel"]

#: Values of the ``kernel`` option.
KERNELS = ("auto", "numba", "numpy")

# Element types by name (filled by Element.__init_subclass__).
_REGISTRY: dict[str, type] = {}


def resolve_kernel(kernel: str) -> str:
    """The implementation a ``kernel`` option selects: "numba" (compiled) or "numpy" (the reference).

    ``"auto"``, the default, is the compiled kernel: numba is a dependency of
    ancfdae (``import ancfdae`` imports it), so there is nothing to fall back
    from; the value stays accepted because result files record it.
    """
    return "numpy" if choice("kernel", kernel, KERNELS) == "numpy" else "numba"


class Kernel:
    """One implementation of an element's kernels: the NumPy reference or its compiled twin.

    A subclass implements the element methods that have two implementations,
    with the element's signatures (e.g. ``internal_forces(geom, q, tangent)``);
    the element's own methods call the kernel object its ``kernel`` option built.
    The NumPy reference sits in the element's module ``x.py``, the compiled
    twin in ``x_numba.py``.

    Parameters
    ----------
    element : Element
        The element whose material, section and options the kernels read.

    Attributes
    ----------
    name : str
        ``"numpy"`` or ``"numba"``: what :attr:`Element.kernel_in_use` reports.
    """

    name: ClassVar[str] = "numpy"

    def __init__(self, element: Element) -> None:
        self.element = element

    def fused(self, geom: Any) -> tuple[Callable, tuple] | None:
        """The fused assembly entry point ``(fn, args)`` (see :meth:`Element.fused_kernel`); None here.

        Only a compiled kernel offers one; the NumPy reference assembles with
        ``np.bincount``, which is also the path that the tests hold the fused
        one equal to.
        """
        return None


class OnePassKernel(Kernel):
    """A kernel whose one pass gives energy, forces and tangent: :meth:`energy_forces`.

    ``strain_energy`` and ``internal_forces`` are that pass at ``order`` 0 and
    1 or 2 (the order of the jets: 0 energy, 1 plus forces, 2 plus tangent).
    """

    def energy_forces(self, geom: Any, q: np.ndarray, order: int) -> tuple:
        """``(U, f, K)``: energy (n_el,), forces (n_el, n_edof) and, for ``order`` 2, the tangent."""
        raise NotImplementedError

    def strain_energy(self, geom: Any, q: np.ndarray) -> np.ndarray:
        """Strain energy of each element, shape (n_el,)."""
        return self.energy_forces(geom, q, 0)[0]

    def internal_forces(self, geom: Any, q: np.ndarray, tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """``f = dU/dq_e`` and, if ``tangent``, ``K = df/dq_e`` (else None)."""
        _, f, K = self.energy_forces(geom, q, 2 if tangent else 1)
        return f, (K if tangent else None)


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

    kernel_twins : dict
        ``{"numpy": factory, "numba": factory}``, each factory taking the
        element and returning its :class:`Kernel`; empty (the default) for an
        element with one implementation, which then has no ``kernel`` option.
    kernels : Kernel
        Instance attribute of an element with ``kernel_twins``: the kernel
        object that the ``kernel`` option selected.

    Notes
    -----
    The attributes up to ``kernel_twins`` are class attributes. Subclasses
    keep every constructor option under its argument name, so that
    :meth:`Beam.describe` records it and a result file can rebuild the element;
    a subclass that sets its own ``name`` is registered under it
    (:meth:`by_name`).
    """

    name: ClassVar[str]
    dim: ClassVar[int]
    node_params: ClassVar[tuple[float, ...]]
    node_coordinates: ClassVar[tuple[str, ...]]
    mass_is_constant: ClassVar[bool] = True
    formulations: ClassVar[tuple[str, ...]] = ("structural",)
    energy_degree: ClassVar[int | None] = None
    kernel_twins: ClassVar[Mapping[str, Callable[[Element], Kernel]]] = {}

    def __init_subclass__(cls, **kwargs) -> None:
        super().__init_subclass__(**kwargs)
        name = cls.__dict__.get("name")
        if name is None:   # an abstract base, or a variant that keeps its parent's name
            return
        known = _REGISTRY.get(name)
        if known is not None and (known.__module__, known.__qualname__) != (cls.__module__, cls.__qualname__):
            raise TypeError(f"element `name` {name!r} is taken by {known.__module__}.{known.__qualname__}; "
                            f"give {cls.__qualname__} a name of its own.")
        _REGISTRY[name] = cls   # a class defined again (a re-run script) replaces its earlier self

    @staticmethod
    def by_name(name: str) -> type[Element]:
        """The element type registered under ``name`` (the ``name`` a result file records).

        Raises
        ------
        ValueError
            If no element type of that name has been defined (imported) yet.
        """
        if name not in _REGISTRY:
            raise ValueError(f"element type must be one of {sorted(_REGISTRY)}, got {name!r} (an element type "
                             "is known once its class has been defined: import it first).")
        return _REGISTRY[name]

    # -- the kernel option ----------------------------------------------------
    @property
    def kernel(self) -> str:
        """The ``kernel`` option as given: "auto" (compiled, the default), "numba" or "numpy".

        Setting it (also later, on a built beam's element) builds the kernel
        object :attr:`kernels` once (:func:`resolve_kernel`).
        """
        return self._kernel

    @kernel.setter
    def kernel(self, value: str) -> None:
        if not self.kernel_twins:
            raise AttributeError(f"{type(self).__name__} has one implementation of its kernels: it takes no `kernel`.")
        self.kernels = self.kernel_twins[resolve_kernel(value)](self)
        self._kernel = value

    @property
    def kernel_in_use(self) -> str:
        """The implementation that runs: "numba" or "numpy"."""
        return self.kernels.name

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

    def reference_state(self, points: np.ndarray, frames: np.ndarray) -> dict:
        """The event state of the undeformed configuration (BE3D: its nodal directors); none by default.

        The beam passes it to :meth:`prepare` as keyword arguments.
        """
        return {}

    @abstractmethod
    def prepare(self, q_ref: np.ndarray, lengths: np.ndarray, **state: Any) -> Any:
        """Precompute everything that depends on the mesh only.

        The beam passes the event state of :meth:`reference_state` as keyword
        arguments (BE3D: ``directors``); most elements take none.

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

    def _twin(self, method: str) -> Callable:
        """The kernel object's ``method``: the default of the kernel methods below."""
        if not self.kernel_twins:
            raise NotImplementedError(f"{type(self).__name__} must implement `{method}` (or list its kernel "
                                      "implementations in `kernel_twins`).")
        return getattr(self.kernels, method)

    def strain_energy(self, geom: Any, q: np.ndarray) -> np.ndarray:
        """Strain energy of each element, shape (n_el,).

        This and :meth:`internal_forces` and :meth:`moment_load` call the
        kernel object (:attr:`kernels`) of an element with ``kernel_twins``;
        an element with one implementation overrides them.
        """
        return self._twin("strain_energy")(geom, q)

    def internal_forces(self, geom: Any, q: np.ndarray, tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """``f = dU/dq_e`` and, if ``tangent``, ``K = d f / d q_e``.

        Returns
        -------
        f : ndarray, shape (n_el, n_edof)
        K : ndarray, shape (n_el, n_edof, n_edof), or None
        """
        return self._twin("internal_forces")(geom, q, tangent)

    @abstractmethod
    def shape_matrix(self, s: np.ndarray, lengths: np.ndarray) -> np.ndarray:
        """Axis position interpolation ``r(s) = S(s) q_e``.

        Returns
        -------
        ndarray, shape (n_el, n_pts, dim, n_edof)
        """

    def moment_load(self, geom: Any, q: np.ndarray, s: float, moment: np.ndarray, element: int,
                    tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Generalised force of a dead moment acting at axis point ``s`` of one element.

        The virtual work of a moment is ``M . delta phi`` with the virtual rotation ``delta phi`` of the
        cross-section frame at ``s`` (chapter Sect. 2.2), ``delta phi = G(q) delta q``; the force is ``G^T M``.

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
        return self._twin("moment_load")(geom, q, s, moment, element, tangent)

    def moment_slope_operator(self, s: float, length: float) -> np.ndarray | None:
        """``S'`` (dim, n_edof), ``r'(s) = S' q_e``, when :meth:`moment_load` is the turn of the axis tangent
        that the beam applies compiled (:mod:`ancfdae.models.beam.moments_numba`); None (default) if not."""
        return None

    # -- optional: fused compiled assembly ----------------------------------
    def fused_kernel(self, geom: Any) -> tuple[Callable, tuple] | None:
        """The element's fused gather-kernel-scatter entry point, or None.

        A compiled kernel object may return ``(fn, args)`` (:meth:`Kernel.fused`);
        the beam then assembles the internal forces and tangent by the single
        call ``fn(q, q_fixed, gather, vec_slot, mat_slot, tangent, r, kdata,
        *args)`` (the contract is in :mod:`ancfdae.models.beam.assembly_numba`),
        which must give the same arrays as :meth:`internal_forces` followed by
        the beam's ``np.bincount`` scatter. With None (the NumPy kernel, an
        element with one implementation, or a subclass that returns None) the
        beam takes that NumPy path. ``geom`` may be the geometry of stacked
        copies of the mesh.
        """
        return self.kernels.fused(geom) if self.kernel_twins else None

    # -- optional: configuration-dependent inertia (BE3D) ------------------
    def inertia(self, geom: Any, q: np.ndarray, v: np.ndarray, a: np.ndarray, tangent: bool = True) -> tuple:
        """Inertia forces beyond the constant mass matrix.

        Only for ``mass_is_constant = False``: returns ``f`` of shape
        (n_el, n_edof) such that the element's inertia force is
        ``M_const a + f``, and if ``tangent`` the blocks ``df/dq``, ``df/dv``,
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
