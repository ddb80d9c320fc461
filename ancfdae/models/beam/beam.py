"""Beam: mesh + element + supports + loads, assembled into a :class:`ancfdae.problem.Model`.

The beam eliminates the fixed coordinates of its supports (every remaining coordinate is free),
numbers the nodes along the axis (banded matrices) and assembles the element kernels of
:class:`ancfdae.models.Element` into CSR matrices whose pattern is fixed at construction: K, D and M
share one pattern, so an integrator forms its iteration matrix by combining data arrays.

The beam is one class that owns its collaborators, each built once from explicit inputs: the
:class:`~.assembly.Assembler` (the fixed pattern), the :class:`~.loads.LoadSet` (the loads as free force
vectors) and the :class:`~.stages.StageEvaluator` (several stages in one element pass); argument checks,
mesh, description, rigid motions: the functions of :mod:`.checks`, :mod:`.mesh`, :mod:`.describe`, :mod:`.potential`.
"""
from __future__ import annotations

import copy
import functools
from collections.abc import Iterable
from typing import Callable

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

from ..._validate import check_shape
from ...attachment import Attachment
from ...loads import DistributedLoad, Gravity, PointForce, PointMoment
from ...problem import Energy, JacobianBlocks
from ..element import Element
from . import checks, describe as description, mesh
from .assembly import Assembler
from .attach import beam_attachment
from .compiled import compiled_residual
from .loads import LoadSet, load_sequence
from .mass_forms import MassForms
from .potential import symmetry_generators
from .stages import StageEvaluator, potential_gradient_stages

__all__ = ["Beam"]


@functools.cache
def _finish_residual():
    """The compiled ``f + M a - lambda f_ext`` (imports numba: only reached on the fused path)."""
    from ..._residual_numba import finish_residual
    return finish_residual


class Beam(MassForms):
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
        :func:`ancfdae.models.beam.mesh.frame_from_tangent`.
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
    Also a :class:`ancfdae.problem.PotentialModel` (``potential``, ``potential_gradient``,
    ``nonconservative_force``, ``symmetry_generators``) when its mass is constant.
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
        points, frames, lengths = mesh.build(element, n_elements, length, start, direction, nodes, normal)
        self.points, self.frames, self.lengths = points, frames, lengths
        self.n_elements = lengths.size
        self.n_nodes = points.shape[0]
        self.element_nodes, self.edofs, self.s_nodes = mesh.numbering(lengths, element.n_nodes, element.n_node_dof)
        self.q_ref = element.reference_coordinates(points, frames).reshape(-1).copy()
        # The element's event state of the reference configuration (BE3D: its nodal directors) is an argument.
        self.geom = element.prepare(self.q_ref[self.edofs], lengths, **element.reference_state(points, frames))

        # Supports: eliminate fixed coordinates.
        fixed = checks.fixed_coordinates(supports, element, frames)
        self.fixed = fixed
        self.free = np.flatnonzero(~fixed)
        self.n_dof = int(self.free.size)
        if self.n_dof == 0:
            raise ValueError("`supports` fix every coordinate; nothing is left to solve for.")
        free_of_full = np.full(self.q_ref.size, -1)
        free_of_full[self.free] = np.arange(self.n_dof)
        self._asm = Assembler(self.edofs, free_of_full, self.n_dof, element.n_node_dof)
        self.mass_is_constant = bool(element.mass_is_constant)
        self._M_data = self._asm.data(element.mass_matrix(self.geom))
        self._M_csr = self._asm.product_csr(self._M_data)   # constant-mass product M a, built once
        self._zero_data = np.zeros(self._asm.nnz)
        self.load_factor = 1.0
        self.loads = load_sequence(loads)   # kept for describe()
        self._load_set = LoadSet(self.loads, element, lengths, self.s_nodes, self.edofs, self._asm)
        # Gather of the element coordinates from (free q, fixed reference values) in one take.
        ext_of_full = free_of_full.copy()
        ext_of_full[fixed] = self.n_dof + np.arange(int(fixed.sum()))
        self._q_fixed = self.q_ref[fixed].copy()
        self._gather = ext_of_full[self.edofs]
        self._stages = StageEvaluator(element, self.q_ref[self.edofs], lengths, self._gather, self._q_fixed,
                                      self._asm, self._M_data)
        self._v0 = checks.initial_velocity(initial_velocity, element, points, frames, lengths, self.free)
        self._no_k = np.empty(1)

    @classmethod
    def from_description(cls, model: dict) -> Beam:
        """The beam of a :meth:`describe` dict (e.g. ``Result.model`` of a result file), without its loads: the same
        coordinates and reference configuration; see :func:`~ancfdae.models.beam.describe.beam_arguments`."""
        element, kwargs = description.beam_arguments(model)
        return cls(element, **kwargs)

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
        e, loc = checks.locate(s, self.s_nodes, self.lengths)
        return mesh.point_matrix(self.element, self.edofs, self.lengths, e, loc, self.q_ref.size)

    def position(self, q: np.ndarray, s: ArrayLike) -> np.ndarray:
        """Axis position at reference arc length ``s`` (scalar -> (dim,), array -> (n, dim))."""
        checks.check_state(self.n_dof, q)
        r = (self.point_matrix(s) @ self.expand(q)).reshape(-1, self.element.dim)
        return r[0] if np.ndim(s) == 0 else r

    def attachment(self, where: int | float | dict) -> Attachment:
        """Where a joint holds the beam: node ``where`` (int, negative from the end) or the axis point at arc
        length ``where`` (float, or ``{"s": float}``), as an :class:`ancfdae.attachment.Attachment` on the free
        coordinates (supports enter its offsets); see :mod:`.attach`."""
        return beam_attachment(self, where)

    def describe(self) -> dict:
        """JSON-able description (element, material, section, mesh, supports, loads); see :mod:`.describe`."""
        return description.describe(self)

    def dof_labels(self) -> tuple[np.ndarray, np.ndarray]:
        """Node index and coordinate name of each free coordinate; see :func:`.describe.dof_labels`."""
        return description.dof_labels(self)

    # -- capabilities and event state (ancfdae.problem.CAPABILITIES) -------
    @property
    def capabilities(self) -> frozenset:
        """The optional capabilities this beam offers (see :func:`ancfdae.problem.capabilities`)."""
        caps = {"residual_jacobian", "residual_stages"}
        if self.mass_is_constant or callable(getattr(self.element, "mass_bilinear", None)):
            caps |= {"potential", "potential_stages"}   # d/dt(M v) - dT/dq + dP/dq - f_nc; constant M or its forms
        if not self.mass_is_constant:
            caps |= {"variable_mass"} | ({"mass_forms"} if "potential" in caps else set())
        if self.element.event_state(self.geom):
            caps.add("step_events")
        return frozenset(caps)

    def event_state(self) -> dict:
        """The element's event state (BE3D: ``{"directors": (n_nodes, 3)}``), read-only arrays."""
        return dict(self.element.event_state(self.geom))

    def bind(self, state: dict) -> Beam:
        """A beam evaluating with the event ``state``, sharing everything else (this one is unchanged)."""
        other = copy.copy(self)
        other.geom = self.element.bind(self.geom, state)
        return other

    def step_event(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple | None:
        """The element's event after an accepted step (BE3D director update); None when nothing changed."""
        ev = self.element.step_event(self.geom, self.nodal(q), self._expand_v(v).reshape(self.n_nodes, -1))
        if ev is None:
            return None
        Q, V, state = ev
        return Q.reshape(-1)[self.free], V.reshape(-1)[self.free], state

    # -- the Model contract -------------------------------------------------
    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Reference configuration and the initial velocity."""
        return self.q_ref[self.free].copy(), self._v0.copy()

    def mass(self, q: np.ndarray | None = None) -> sp.csr_matrix:
        """Mass matrix M(q) (constant unless the element says otherwise; ``q=None``: the reference state)."""
        if q is not None:
            checks.check_state(self.n_dof, q)
        if self.mass_is_constant:
            return self._asm.csr(self._M_data.copy())
        if q is None:
            q = self.q_ref[self.free]
        _, blocks = self._inertia(q, np.zeros(self.n_dof), np.zeros(self.n_dof), True)
        return self._asm.csr(self._M_data + blocks[2])

    def _inertia(self, q, v, a, tangent):
        """The element's inertia beyond the constant mass: force and, if ``tangent``, the K, D, M data."""
        qf, vf, af = self.expand(q), self._expand_v(v), self._expand_v(a)
        e = self.edofs
        out = self.element.inertia(self.geom, qf[e], vf[e], af[e], tangent)
        f = self._asm.vector(out[0])
        blocks = tuple(self._asm.data(b) for b in out[1:]) if tangent else None
        return f, blocks

    def _element_q(self, q):
        """Element coordinates (n_el, n_edof) of free coordinates ``q`` (= ``expand(q)[edofs]``)."""
        return np.concatenate((q, self._q_fixed))[self._gather]

    def internal_forces(self, q: np.ndarray, tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Assembled ``dU/dq`` (free vector) and tangent CSR data (or None)."""
        return self._assemble(q, tangent)[:2]

    def _assemble(self, q, tangent):
        """``(f, kdata, fused)``: assembled ``dU/dq``, tangent data or None, and which path ran.

        With the element's fused entry point (a compiled kernel) gather, kernel and scatter run as one
        compiled call; otherwise the element kernel returns element arrays that ``np.bincount`` sums,
        the readable reference. Both give the same bits for the same kernel.
        """
        fused = self.element.fused_kernel(self.geom)
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
            _finish_residual()(f, self._M_csr.data, self._M_csr.indptr, self._M_csr.indices,
                            np.ascontiguousarray(a, dtype=float), float(self.load_factor),
                            np.ascontiguousarray(fext, dtype=float))
            return f
        return f + self._M_csr @ a - self.load_factor * fext

    def residual(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """``r = M(q) a + f_int(q) [+ inertia(q, v, a)] - lambda f_ext(t, q)``."""
        checks.check_state(self.n_dof, q, v, a)
        f, _, fused = self._assemble(q, False)
        r = self._static_residual(a, f, self._f_external(t, q, False)[0], fused)
        if not self.mass_is_constant:
            r += self._inertia(q, v, a, False)[0]
        return r

    def residual_jacobian(self, t: float, q: np.ndarray, v: np.ndarray,
                          a: np.ndarray) -> tuple[np.ndarray, JacobianBlocks]:
        """``(residual, jacobian)`` from one kernel pass (the fused path of full Newton)."""
        checks.check_state(self.n_dof, q, v, a)
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
        checks.check_state(self.n_dof, q, v, a)
        _, K = self.internal_forces(q, True)
        kload = self._f_external(t, q, True)[1] if self._load_set.moments else None
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
        checks.check_state(self.n_dof, q, v)
        T = 0.5 * v @ (self._M_csr @ v)
        if not self.mass_is_constant:
            qf, vf = self.expand(q), self._expand_v(v)
            T += float(np.sum(self.element.kinetic_energy_extra(self.geom, qf[self.edofs], vf[self.edofs])))
        U = float(np.sum(self.element.strain_energy(self.geom, self.expand(q)[self.edofs])))
        # Gravity's potential, zero in the reference configuration.
        V = -self.load_factor * float(self._load_set.gravity @ (q - self.q_ref[self.free]))
        return Energy(kinetic=float(T), strain=U, potential=V)

    def _f_external(self, t, q, tangent):
        """``f_nc + f_gravity`` (free vector) and the load tangent data (or None); see :class:`.loads.LoadSet`."""
        loads = self._load_set
        return loads.external(t, self.expand(q) if loads.moments else None, self.geom, tangent)

    def external_power(self, t: float, q: np.ndarray, v: np.ndarray) -> float:
        """Power of all loads except gravity (whose work is the potential)."""
        checks.check_state(self.n_dof, q, v)
        f, _ = self._load_set.nonconservative(t, self.expand(q), self.geom, False)
        return float(self.load_factor * f @ v)

    def residual_stages(self, ts: ArrayLike, Q: np.ndarray, V: np.ndarray, A: np.ndarray) -> np.ndarray:
        """Residuals of several stages in one element pass: column ``i`` of the (n_dof, m) result is
        ``residual(ts[i], Q[:, i], V[:, i], A[:, i])`` (optional Model method; Lobatto IIIA uses it).

        A constant-mass beam runs the kernel once on the stages' elements stacked (:class:`.stages.StageEvaluator`).
        """
        m = np.size(ts)
        if np.ndim(ts) != 1 or np.shape(Q) != (self.n_dof, m) or np.shape(V) != (self.n_dof, m) \
                or np.shape(A) != (self.n_dof, m):
            check_shape("ts", ts, (m,), "one time per stage")
            for name, X in (("Q", Q), ("V", V), ("A", A)):
                check_shape(name, X, (self.n_dof, m), f"(n_dof, number of stages) = ({self.n_dof}, {m})")
        ts = np.asarray(ts, dtype=float)
        m = ts.size
        if not self.mass_is_constant:
            return np.column_stack([self.residual(ts[i], Q[:, i], V[:, i], A[:, i]) for i in range(m)])
        if self._load_set.gravity_only:
            F_ext = self._load_set.gravity_columns(m)
        else:
            F_ext = np.column_stack([self._f_external(ts[i], Q[:, i], False)[0] for i in range(m)])
        return self._stages.residuals(Q, A, F_ext, float(self.load_factor))

    compiled_residual = compiled_residual   # the residual as compiled pieces, or None (:mod:`.compiled`)
    potential_gradient_stages = potential_gradient_stages   # k configurations in one pass (:mod:`.stages`)

    # -- the potential capability (ancfdae.problem.PotentialModel) ---------
    @property
    def potential_degree(self) -> int | None:
        """Polynomial degree of ``P`` in the coordinates, or None (from the element's ``energy_degree``)."""
        return getattr(self.element, "energy_degree", None)

    def potential(self, t: float, q: np.ndarray) -> float:
        """``U(q) + V(q)``, with the gravity potential zero in the reference configuration."""
        U = float(np.sum(self.element.strain_energy(self.geom, self._element_q(q))))
        return U - self.load_factor * float(self._load_set.gravity @ (q - self.q_ref[self.free]))

    def potential_gradient(self, t: float, q: np.ndarray,
                           tangent: bool = True) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """``(dU/dq - lambda f_gravity, d2U/dq2 as CSR or None)``."""
        g, kdata = self.internal_forces(q, tangent)
        return g - self.load_factor * self._load_set.gravity, (self._asm.csr(kdata) if tangent else None)

    def nonconservative_force(self, t: float, q: np.ndarray,
                              tangent: bool = True) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """Dead forces and moments ``(f_nc, df_nc/dq as CSR or None)`` (every load except gravity)."""
        f, kdata = self._load_set.nonconservative(t, self.expand(q), self.geom, tangent)
        if not tangent:
            return self.load_factor * f, None
        return self.load_factor * f, self._asm.csr(self.load_factor * (self._zero_data if kdata is None else kdata))

    def symmetry_generators(self) -> tuple[np.ndarray, list[sp.csr_matrix]]:
        """Translations and rotations that keep the strain energy (free beams only; :mod:`.potential`)."""
        return symmetry_generators(self.element.dim, self.element.n_node_dof, self.n_nodes, self.fixed)
