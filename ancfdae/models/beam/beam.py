"""Beam: mesh + element + supports + loads, assembled into a :class:`ancfdae.problem.Model`.

The beam eliminates the fixed coordinates of its supports (every remaining coordinate is free),
numbers the nodes along the axis (banded matrices) and assembles the element
kernels of :mod:`ancfdae.models._element` into CSR matrices whose pattern is
fixed at construction: K, D and M share one pattern, so an integrator forms
its iteration matrix by combining data arrays.
"""
from __future__ import annotations

import functools
from collections.abc import Iterable
from typing import Callable

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

from ...loads import DistributedLoad, Gravity, PointForce, PointMoment
from ...problem import Energy, JacobianBlocks
from . import describe as _describe
from .assembly import Assembler
from .checks import BeamChecks
from .events import BeamEvents
from .loads import BeamLoads
from .stages import BeamStages
from ..element import Element
from .mesh import mesh_from_points, straight_mesh
from .potential import PotentialMixin

__all__ = ["Beam"]


@functools.cache
def _finish_residual():
    """The compiled ``f + M a - lambda f_ext`` (imports numba: only reached on the fused path)."""
    from .assembly_numba import finish_residual
    return finish_residual


class Beam(PotentialMixin, BeamChecks, BeamLoads, BeamStages, BeamEvents):
    """A beam of ANCF elements with supports and loads: a Model.

    Parameters
    ----------
    element : Element
        Element type with its material, section and formulation, e.g.
        ``BE2D(material, section)``.
    n_elements : int
        Number of elements of a straight beam.
    length : float
        Length of a straight beam.
    start, direction : array_like, optional
        Start point and axis direction of a straight beam; default the origin
        and ``e_x`` in the element's dimension.
    nodes : array_like, shape (n_nodes, dim), optional
        Node positions of a curved or irregular beam instead of
        ``n_elements``/``length``/``start``/``direction`` (3-node elements
        need ``2 n_el + 1`` nodes, mid-nodes included).
    normal : array_like, optional
        3D only: direction of the cross-section axis e2 (eta); see
        :func:`ancfdae.models._mesh.frame_from_tangent`.
    supports : dict, optional
        ``{node: kind}`` with kind ``"clamp"``, ``"pin"`` or a tuple of
        coordinate names of ``element.node_coordinates`` to fix. Negative
        node indices count from the end. Without supports the beam flies
        freely (dynamics); a static solve then fails (singular stiffness).
    loads : load or sequence of loads, optional
        :class:`~ancfdae.loads.PointForce`, :class:`~ancfdae.loads.PointMoment`,
        :class:`~ancfdae.loads.Gravity`, :class:`~ancfdae.loads.DistributedLoad`.
    initial_velocity : callable or array_like, optional
        Either ``v(points) -> velocities`` of the axis, shape (n, dim) (nodal
        position velocities take it directly; axial slope velocities ``r'``
        are its derivative along the axis by central differences; other slope
        velocities are zero), or the full nodal velocity array
        ``(n_nodes, n_node_dof)``.

    Attributes
    ----------
    n_dof : int
        Free coordinates.
    load_factor : float
        Multiplies every external load (the static solver steps it).

    Notes
    -----
    Also a :class:`ancfdae.problem.PotentialModel` (methods of
    :class:`~ancfdae.models._potential.PotentialMixin`).
    """

    def __init__(self, element: Element, n_elements: int | None = None, length: float | None = None,
                 start: ArrayLike | None = None, direction: ArrayLike | None = None, *,
                 nodes: ArrayLike | None = None, normal: ArrayLike | None = None, supports: dict | None = None,
                 loads: (DistributedLoad | Gravity | PointForce | PointMoment
                        | Iterable[DistributedLoad | Gravity | PointForce | PointMoment]) = (),
                 initial_velocity: Callable | ArrayLike | None = None) -> None:
        if not isinstance(element, Element):
            raise TypeError(f"`element` must be an ancfdae element (e.g. BE2D(...)), got {element!r}.")
        self.element = element
        self.normal = normal   # kept for describe()
        dim = element.dim
        npe = element.n_nodes
        if nodes is not None:
            if n_elements is not None or length is not None:
                raise ValueError("give either `nodes` or `n_elements` and `length`, not both.")
            points, frames, lengths = mesh_from_points(nodes, npe, normal)
            if points.shape[1] != dim:
                raise ValueError(f"`nodes` must have {dim} columns for {element.name}, got {points.shape[1]}.")
        else:
            if n_elements is None or length is None:
                raise ValueError("give `n_elements` and `length` (or `nodes`).")
            start = np.zeros(dim) if start is None else start
            direction = np.eye(dim)[0] if direction is None else direction
            if np.size(start) != dim:
                raise ValueError(f"`start` must have {dim} components for {element.name}, got {np.size(start)}.")
            points, frames, lengths = straight_mesh(n_elements, length, start, direction, npe, normal)
        self.points, self.frames, self.lengths = points, frames, lengths
        n_el = lengths.size
        self.n_elements = n_el
        self.n_nodes = points.shape[0]
        nnd = element.n_node_dof
        # Element-to-node map; 3-node elements are ordered (A, B, C) = (start, end, middle).
        k = npe - 1
        base = np.arange(n_el)[:, None] * k
        order = [0, k] + list(range(1, k))
        self.element_nodes = base + np.array(order)[None, :]
        self.edofs = (self.element_nodes[:, :, None] * nnd + np.arange(nnd)).reshape(n_el, -1)
        self.s_nodes = np.concatenate([[0.0], np.cumsum(np.repeat(lengths / k, k))])

        self.q_ref = element.reference_coordinates(points, frames).reshape(-1).copy()
        self.geom = element.prepare(self.q_ref[self.edofs], lengths)

        # Supports: eliminate fixed coordinates.
        fixed = self._fixed_coordinates(supports)
        self.fixed = fixed
        self.free = np.flatnonzero(~fixed)
        self.n_dof = int(self.free.size)
        if self.n_dof == 0:
            raise ValueError("`supports` fix every coordinate; nothing is left to solve for.")
        free_of_full = np.full(self.q_ref.size, -1)
        free_of_full[self.free] = np.arange(self.n_dof)
        self._asm = Assembler(self.edofs, free_of_full, self.n_dof)
        self.mass_is_constant = bool(element.mass_is_constant)
        self._M_data = self._asm.data(element.mass_matrix(self.geom))
        self._M_csr = self._asm.csr(self._M_data)   # constant-mass product M a, built once
        self._zero_data = np.zeros(self._asm.nnz)
        self.load_factor = 1.0
        if isinstance(loads, (PointForce, PointMoment, Gravity, DistributedLoad)):
            loads = (loads,)   # a single load is a sequence of one
        elif loads is None:
            loads = ()
        elif not isinstance(loads, Iterable):
            raise TypeError(f"`loads` must be a load or a sequence of loads (PointForce, PointMoment, Gravity, "
                            f"DistributedLoad), got {loads!r}.")
        self.loads = tuple(loads)   # kept for describe()
        self._setup_loads(self.loads)
        # Gather of the element coordinates from (free q, fixed reference values) in one take.
        ext_of_full = free_of_full.copy()
        ext_of_full[fixed] = self.n_dof + np.arange(int(fixed.sum()))
        self._q_fixed = self.q_ref[fixed].copy()
        self._gather = ext_of_full[self.edofs]
        self._v0 = self._initial_velocity(initial_velocity)
        self._no_k = np.empty(1)
        self.assembly = "fused"

    @property
    def assembly(self) -> str:
        """Assembly path: "fused" (default) or "numpy".

        ``"fused"``: with an element that offers a compiled kernel
        (:meth:`ancfdae.models._element.Element.fused_kernel`), gather, kernel
        and scatter into the fixed CSR data run as one compiled call per
        evaluation; otherwise (and with ``"numpy"``, the readable reference) the
        element kernel returns element arrays that ``np.bincount`` sums. Both
        give the same bits for the same kernel.
        """
        return self._assembly

    @assembly.setter
    def assembly(self, value: str) -> None:
        if value not in ("fused", "numpy"):
            raise ValueError(f"`assembly` must be 'fused' or 'numpy', got {value!r}.")
        self._assembly = value

    # -- geometry helpers -------------------------------------------------
    def expand(self, q: np.ndarray) -> np.ndarray:
        """Full coordinate vector: free coordinates ``q``, fixed ones from the reference."""
        full = self.q_ref.copy()
        full[self.free] = q
        return full

    def _expand_v(self, v):
        full = np.zeros_like(self.q_ref)
        full[self.free] = v
        return full

    def nodal(self, q: np.ndarray) -> np.ndarray:
        """Coordinates per node, shape (n_nodes, n_node_dof)."""
        return self.expand(q).reshape(self.n_nodes, -1)

    def point_matrix(self, s: ArrayLike) -> sp.csr_matrix:
        """Sparse operator P with ``r(s) = P @ expand(q)``, shape (n_pts*dim, n_full)."""
        e, loc = self._locate(s)
        dim, nd = self.element.dim, self.element.n_edof
        rows, cols, vals = [], [], []
        for k, (ek, sk) in enumerate(zip(e, loc)):   # a few sensor points, at construction only
            S = self.element.shape_matrix(np.array([sk]), self.lengths[[ek]])[0, 0]
            rows.append(np.repeat(np.arange(dim) + k * dim, nd))
            cols.append(np.tile(self.edofs[ek], dim))
            vals.append(S.ravel())
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(len(e) * dim, self.q_ref.size))

    def position(self, q: np.ndarray, s: ArrayLike) -> np.ndarray:
        """Axis position at reference arc length ``s`` (scalar -> (dim,), array -> (n, dim))."""
        self._check(q)
        r = (self.point_matrix(s) @ self.expand(q)).reshape(-1, self.element.dim)
        return r[0] if np.ndim(s) == 0 else r

    def describe(self) -> dict:
        """JSON-able description (element, material, section, mesh, supports, loads); see
        :func:`ancfdae.models._describe.describe`."""
        return _describe.describe(self)

    def dof_labels(self) -> tuple[np.ndarray, np.ndarray]:
        """Node index and coordinate name of each free coordinate; see
        :func:`ancfdae.models._describe.dof_labels`."""
        return _describe.dof_labels(self)

    # -- the Model contract -------------------------------------------------
    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Reference configuration and the initial velocity."""
        return self.q_ref[self.free].copy(), self._v0.copy()

    def mass(self, q: np.ndarray | None = None) -> sp.csr_matrix:
        """Mass matrix M(q) (constant unless the element says otherwise; ``q=None``: the reference state)."""
        if q is not None:
            self._check(q)
        if self.mass_is_constant:
            return self._asm.csr(self._M_data.copy())
        if q is None:
            q = self.q_ref[self.free]
        _, blocks = self._inertia(q, np.zeros(self.n_dof), np.zeros(self.n_dof), True)
        return self._asm.csr(self._M_data + blocks[2])

    def _inertia(self, q, v, a, jac):
        qf, vf, af = self.expand(q), self._expand_v(v), self._expand_v(a)
        e = self.edofs
        out = self.element.inertia(self.geom, qf[e], vf[e], af[e], jac)
        f = self._asm.vector(out[0])
        blocks = tuple(self._asm.data(b) for b in out[1:]) if jac else None
        return f, blocks

    def _element_q(self, q):
        """Element coordinates (n_el, n_edof) of free coordinates ``q`` (= ``expand(q)[edofs]``)."""
        return np.concatenate((q, self._q_fixed))[self._gather]

    def _fused(self, geom):
        """The element's fused entry point ``(fn, args)`` for ``geom``, or None (NumPy assembly)."""
        return self.element.fused_kernel(geom) if self._assembly == "fused" else None

    def internal_forces(self, q: np.ndarray, tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Assembled ``dU/dq`` (free vector) and tangent CSR data (or None)."""
        return self._assemble(q, tangent)[:2]

    def _assemble(self, q, tangent):
        """``(f, kdata, fused)``: assembled ``dU/dq``, tangent data or None, and which path ran."""
        fused = self._fused(self.geom)
        if fused is None:
            fe, ke = self.element.internal_forces(self.geom, self._element_q(q), tangent)
            return self._asm.vector(fe), (self._asm.data(ke) if tangent else None), False
        fn, args = fused
        n, nnz = self.n_dof, self._asm.nnz
        r = np.empty(n + 1)
        kd = np.empty(nnz + 1) if tangent else self._no_k
        fn(np.ascontiguousarray(q, dtype=float), self._q_fixed, self._gather, self._asm._vec_all,
           self._asm._slot_all, bool(tangent), r, kd, *args)
        return r[:n], (kd[:nnz] if tangent else None), True

    def _static_residual(self, a, f, fext, fused):
        """``f + M a - lambda f_ext`` (in place in ``f`` on the fused path: the same rounding)."""
        if fused:
            _finish_residual()(f, self._M_data, self._asm.indptr, self._asm.indices,
                            np.ascontiguousarray(a, dtype=float), float(self.load_factor),
                            np.ascontiguousarray(fext, dtype=float))
            return f
        return f + self._M_csr @ a - self.load_factor * fext

    def residual(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """``r = M(q) a + f_int(q) [+ inertia(q, v, a)] - lambda f_ext(t, q)``."""
        self._check(q, v, a)
        f, _, fused = self._assemble(q, False)
        r = self._static_residual(a, f, self._f_external(t, q, False)[0], fused)
        if not self.mass_is_constant:
            r += self._inertia(q, v, a, False)[0]
        return r

    def residual_jacobian(self, t: float, q: np.ndarray, v: np.ndarray,
                          a: np.ndarray) -> tuple[np.ndarray, JacobianBlocks]:
        """``(residual, jacobian)`` from one kernel pass (the fused path of full Newton)."""
        self._check(q, v, a)
        f, K, fused = self._assemble(q, True)
        fext, kload = self._f_external(t, q, True)
        r = self._static_residual(a, f, fext, fused)
        if kload is not None:
            K -= self.load_factor * kload
        D, M = self._zero_data, self._M_data
        if not self.mass_is_constant:
            f_in, (iq, iv, ia) = self._inertia(q, v, a, True)
            r += f_in
            K, D, M = K + iq, iv, M + ia
        return r, JacobianBlocks(self._asm.csr(K), self._asm.csr(D.copy()), self._asm.csr(M.copy()),
                                 same_pattern=True)

    def jacobian(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> JacobianBlocks:
        """Exact ``dr/dq``, ``dr/dv``, ``dr/da`` with one shared CSR pattern."""
        self._check(q, v, a)
        _, K = self.internal_forces(q, True)
        kload = self._f_external(t, q, True)[1] if self._moments else None
        if kload is not None:
            K -= self.load_factor * kload
        D = self._zero_data
        M = self._M_data
        if not self.mass_is_constant:
            _, (iq, iv, ia) = self._inertia(q, v, a, True)
            K, D, M = K + iq, iv, M + ia
        return JacobianBlocks(self._asm.csr(K), self._asm.csr(D.copy()), self._asm.csr(M.copy()), same_pattern=True)

    def energy(self, t: float, q: np.ndarray, v: np.ndarray) -> Energy:
        """Kinetic ``1/2 v^T M v`` (+ element extra), strain, gravity potential."""
        self._check(q, v)
        T = 0.5 * v @ (self._M_csr @ v)
        if not self.mass_is_constant:
            qf, vf = self.expand(q), self._expand_v(v)
            T += float(np.sum(self.element.kinetic_energy_extra(self.geom, qf[self.edofs], vf[self.edofs])))
        U = float(np.sum(self.element.strain_energy(self.geom, self.expand(q)[self.edofs])))
        # Gravity's potential, zero in the reference configuration.
        V = -self.load_factor * float(self._f_gravity @ (q - self.q_ref[self.free]))
        return Energy(kinetic=float(T), strain=U, potential=V)
