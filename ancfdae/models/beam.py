"""Beam: mesh + element + supports + loads, assembled into a :class:`ancfdae.problem.Model`.

The beam eliminates the fixed coordinates of its supports (every remaining coordinate is free),
numbers the nodes along the axis (banded matrices) and assembles the element
kernels of :mod:`ancfdae.models._element` into CSR matrices whose pattern is
fixed at construction: K, D and M share one pattern, so an integrator forms
its iteration matrix by combining data arrays.
"""
from __future__ import annotations

import copy
import functools
import numbers
from collections.abc import Iterable, Mapping

import numpy as np
import scipy.sparse as sp

from .._validate import check_shape
from ..loads import DistributedLoad, Gravity, PointForce, PointMoment
from ..problem import Energy, JacobianBlocks
from . import _describe
from ._assembly import Assembler
from ._element import Element
from ._mesh import mesh_from_points, straight_mesh
from ._potential import PotentialMixin
from ._quadrature import gauss

__all__ = ["Beam"]


@functools.cache
def _finish_residual():
    """The compiled ``f + M a - lambda f_ext`` (imports numba: only reached on the fused path)."""
    from ._assembly_numba import finish_residual
    return finish_residual


@functools.cache
def _finish_stages():
    """The compiled stage version of :func:`_finish_residual`."""
    from ._assembly_numba import finish_stages
    return finish_stages


class Beam(PotentialMixin):
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

    Notes
    -----
    Also a :class:`ancfdae.problem.PotentialModel` (methods of
    :class:`~ancfdae.models._potential.PotentialMixin`).
    load_factor : float
        Multiplies every external load (the static solver steps it).
    """

    def __init__(self, element: Element, n_elements=None, length=None, start=None, direction=None, *,
                 nodes=None, normal=None, supports=None, loads=(), initial_velocity=None):
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
        fixed = np.zeros(self.q_ref.size, dtype=bool)
        if supports is not None and not isinstance(supports, Mapping):
            raise TypeError(f"`supports` must be a dict {{node: kind}} with kind 'clamp', 'pin' or a tuple of "
                            f"coordinate names, e.g. {{0: 'clamp'}}; got {supports!r}.")
        for node, kind in (supports or {}).items():
            i = self._node_index(node, "supports")
            if not isinstance(kind, (str, tuple, list)):
                raise ValueError(f"`supports` kind must be 'clamp', 'pin' or a tuple of coordinate names "
                                 f"{element.node_coordinates}, got {kind!r} at node {node}.")
            if isinstance(kind, str):
                if kind not in ("clamp", "pin"):
                    raise ValueError(f"`supports` kind must be 'clamp', 'pin' or a tuple of coordinate names "
                                     f"{element.node_coordinates}, got {kind!r} at node {node}.")
                names = element.support_coordinates(kind, frames[i])
            else:
                names = tuple(kind)
            for name in names:
                if name not in element.node_coordinates:
                    raise ValueError(f"`supports` coordinate must be one of {element.node_coordinates}, "
                                     f"got {name!r} at node {node}.")
                fixed[i * nnd + element.node_coordinates.index(name)] = True
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
    def assembly(self, value):
        if value not in ("fused", "numpy"):
            raise ValueError(f"`assembly` must be 'fused' or 'numpy', got {value!r}.")
        self._assembly = value

    # -- geometry helpers -------------------------------------------------
    def _node_index(self, node, arg):
        if isinstance(node, bool) or not isinstance(node, numbers.Integral):
            raise ValueError(f"`{arg}` node must be an integer index, got {node!r}.")
        if not -self.n_nodes <= node < self.n_nodes:
            raise ValueError(f"`{arg}` node must be in [-{self.n_nodes}, {self.n_nodes - 1}] "
                             f"(the beam has {self.n_nodes} nodes), got {node}.")
        return int(node) % self.n_nodes

    def _locate(self, s, arg="s"):
        """Element index and normalised coordinate of axis point(s) at arc length s."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        total = self.s_nodes[-1]
        if np.any(~np.isfinite(s)) or np.any(s < -1e-12 * total) or np.any(s > total * (1 + 1e-12)):
            raise ValueError(f"`{arg}` must lie on the beam, in [0, {total}], got {s.tolist()}.")
        ends = np.concatenate([[0.0], np.cumsum(self.lengths)])
        e = np.clip(np.searchsorted(ends, s, side="right") - 1, 0, self.n_elements - 1)
        loc = 2.0 * (s - ends[e]) / self.lengths[e] - 1.0
        return e, np.clip(loc, -1.0, 1.0)

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

    def point_matrix(self, s) -> sp.csr_matrix:
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

    def position(self, q: np.ndarray, s) -> np.ndarray:
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

    # -- loads ------------------------------------------------------------
    def _setup_loads(self, loads):
        el, dim = self.element, self.element.dim
        self._dead = []          # (time function, free-vector) of dead forces
        self._moments = []       # (time, element, s_loc, moment3, scatter)
        self._f_gravity = np.zeros(self.n_dof)
        sq, wq = gauss(6)
        S_all = el.shape_matrix(sq, self.lengths)                       # (n_el, n_pts, dim, nd)
        w_el = wq[None, :] * self.lengths[:, None] / 2
        for load in loads:
            if isinstance(load, (PointForce, PointMoment)):
                if load.node is not None:
                    s = self.s_nodes[self._node_index(load.node, "load")]
                else:
                    s = load.s
                (e,), (loc,) = self._locate(s, "load s")
            if isinstance(load, PointForce):
                F = load.force
                if F.shape[0] != dim:
                    raise ValueError(f"`force` must have {dim} components for {el.name}, got {F.shape[0]}.")
                S = el.shape_matrix(np.array([loc]), self.lengths[[e]])[0, 0]
                fe = np.zeros((self.n_elements, el.n_edof))
                fe[e] = S.T @ F
                self._dead.append((load.time, self._asm.vector(fe)))
            elif isinstance(load, PointMoment):
                if dim == 2 and load.moment.shape[0] != 1:
                    raise ValueError(f"`moment` of a planar element must be a scalar, got {load.moment.tolist()}.")
                self._moments.append((load.time, int(e), float(loc), load.vector3(), self._asm.element_scatter(int(e))))
            elif isinstance(load, (Gravity, DistributedLoad)):
                w = load.g if isinstance(load, Gravity) else load.w
                if w.shape[0] != dim:
                    raise ValueError(f"gravity/line load must have {dim} components for {el.name}, got {w.shape[0]}.")
                rhoA = el.material.rho * el.section.A if isinstance(load, Gravity) else 1.0
                fe = rhoA * np.einsum("ep,epdk,d->ek", w_el, S_all, w)
                if isinstance(load, Gravity):
                    self._f_gravity += self._asm.vector(fe)
                else:
                    self._dead.append((load.time, self._asm.vector(fe)))
            else:
                raise TypeError(f"`loads` entries must be PointForce, PointMoment, Gravity or DistributedLoad, "
                                f"got {load!r}.")

    def _f_nonconservative(self, t, q_full, tangent):
        """Non-conservative external forces (free vector) and their q-derivative data."""
        f = np.zeros(self.n_dof)
        for time, vec in self._dead:
            f += time(t) * vec
        kdata = None
        if self._moments:
            kdata = np.zeros(self._asm.nnz) if tangent else None
            for time, e, loc, m, (vmask, vidx, mmask, mslot) in self._moments:
                scale = time(t)
                if scale == 0.0:
                    continue
                fm, km = self.element.moment_load(self.geom, q_full[self.edofs[e]], loc, scale * m, e, tangent)
                np.add.at(f, vidx, fm[vmask])
                if tangent:
                    np.add.at(kdata, mslot, km.ravel()[mmask])
        return f, kdata

    # -- the Model contract -------------------------------------------------
    def _check(self, q, v=None, a=None):
        """Shape checks of the contract's arguments: a wrong length would otherwise assemble silently
        into a wrong-sized residual or fail deep inside numpy."""
        n = (self.n_dof,)
        # Attribute access for arrays (tens of ns); anything else goes through np.shape in check_shape.
        if getattr(q, "shape", None) != n:
            check_shape("q", q, n, f"n_dof = {self.n_dof}")
        if v is not None and getattr(v, "shape", None) != n:
            check_shape("v", v, n, f"n_dof = {self.n_dof}")
        if a is not None and getattr(a, "shape", None) != n:
            check_shape("a", a, n, f"n_dof = {self.n_dof}")

    def initial_state(self):
        """Reference configuration and the initial velocity."""
        return self.q_ref[self.free].copy(), self._v0.copy()

    def _initial_velocity(self, iv):
        nnd = self.element.n_node_dof
        if iv is None:
            return np.zeros(self.n_dof)
        if callable(iv):
            dim = self.element.dim
            V = np.zeros((self.n_nodes, nnd))
            v = np.asarray(iv(self.points), dtype=float)
            if v.shape != self.points.shape or not np.all(np.isfinite(v)):
                raise ValueError(f"`initial_velocity` must return finite velocities of shape {self.points.shape}, "
                                 f"got {v.shape}.")
            V[:, :dim] = v
            names = self.element.node_coordinates
            if len(names) >= 2 * dim and names[dim].endswith("'"):
                h = 1e-5 * float(self.lengths.min())
                t = self.frames[:, :, 0]
                V[:, dim:2 * dim] = (np.asarray(iv(self.points + h * t)) - np.asarray(iv(self.points - h * t))) / (2 * h)
            return V.reshape(-1)[self.free]
        V = np.asarray(iv, dtype=float)
        if V.shape != (self.n_nodes, nnd) or not np.all(np.isfinite(V)):
            raise ValueError(f"`initial_velocity` array must be finite with shape {(self.n_nodes, nnd)}, got {V.shape}.")
        return V.reshape(-1)[self.free]

    def mass(self, q=None) -> sp.csr_matrix:
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

    def _f_external(self, t, q, tangent):
        """``fnc + f_gravity`` (free vector) and the load tangent data (or None); skips the
        non-conservative pass when the beam has no such loads (bit-for-bit: 0 + f_g = f_g)."""
        if not self._moments:
            if not self._dead:
                return self._f_gravity, None
            time, vec = self._dead[0]
            f = time(t) * vec
            for time, vec in self._dead[1:]:
                f += time(t) * vec
            return f + self._f_gravity, None
        fnc, kload = self._f_nonconservative(t, self.expand(q), tangent)
        return fnc + self._f_gravity, kload

    def _fused(self, geom):
        """The element's fused entry point ``(fn, args)`` for ``geom``, or None (NumPy assembly)."""
        return self.element.fused_kernel(geom) if self._assembly == "fused" else None

    def internal_forces(self, q, tangent=True):
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

    def residual(self, t, q, v, a):
        """``r = M(q) a + f_int(q) [+ inertia(q, v, a)] - lambda f_ext(t, q)``."""
        self._check(q, v, a)
        f, _, fused = self._assemble(q, False)
        r = self._static_residual(a, f, self._f_external(t, q, False)[0], fused)
        if not self.mass_is_constant:
            r += self._inertia(q, v, a, False)[0]
        return r

    def residual_stages(self, ts, Q, V, A):
        """Residuals of several stages in one element pass: column ``i`` of the (n_dof, m) result is
        ``residual(ts[i], Q[:, i], V[:, i], A[:, i])`` (optional Model method; Lobatto IIIA uses it).

        The element kernel runs once on the stages' elements stacked (a geometry for ``m`` copies of
        the mesh, prepared on first use), which halves the per-call overhead of small meshes.
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
        geom, gather, idx = self._stage_geometry(m)
        n = self.n_dof
        fused = self._fused(geom)
        if fused is None:
            ext = np.empty((n + self._q_fixed.size, m))   # (free q; fixed values) per stage, stage fastest
            ext[:n] = Q
            ext[n:] = self._q_fixed[:, None]
            fe, _ = self.element.internal_forces(geom, ext.ravel().take(gather), False)
            F = np.bincount(idx, weights=fe.ravel(), minlength=m * (n + 1))
            F = F.reshape(m, n + 1)[:, :n].T
            R = F + self._M_csr @ A
            if not self._dead and not self._moments:
                R -= self.load_factor * self._f_gravity[:, None]
            else:
                for i in range(m):
                    R[:, i] -= self.load_factor * self._f_external(ts[i], Q[:, i], False)[0]
            return R
        fn, args = fused
        F = np.empty((m, n + 1))
        q_fixed_m, gravity_m = self._stage_constants(m)
        fn(np.ascontiguousarray(Q, dtype=float).reshape(-1), q_fixed_m, gather, idx,
           self._asm._slot_all, False, F.reshape(-1), self._no_k, *args)
        if not self._dead and not self._moments:
            fext = gravity_m
        else:
            fext = np.column_stack([self._f_external(ts[i], Q[:, i], False)[0] for i in range(m)])
        R = np.empty((n, m))
        _finish_stages()(F, self._M_data, self._asm.indptr, self._asm.indices, np.ascontiguousarray(A, dtype=float),
                         float(self.load_factor), fext, R)
        return R

    def _stage_constants(self, m):
        """The fixed coordinates repeated per stage and the gravity force per stage, (n, m) (cached)."""
        cache = self.__dict__.setdefault("_stage_const", {})
        if m not in cache:
            cache[m] = (np.repeat(self._q_fixed, m), np.repeat(self._f_gravity[:, None], m, axis=1))
        return cache[m]

    def _stage_geometry(self, m):
        """Element geometry of ``m`` stacked copies of the mesh and the matching scatter index."""
        cache = self.__dict__.setdefault("_stage_cache", {})
        if m not in cache:
            q_ref_e = self.q_ref[self.edofs]
            geom = self.element.prepare(np.tile(q_ref_e, (m, 1)), np.tile(self.lengths, m))
            vec_all = self._asm._vec_all
            idx = (np.arange(m)[:, None] * (self.n_dof + 1) + vec_all[None, :]).ravel()
            gather = (self._gather[None] * m + np.arange(m)[:, None, None]).reshape(-1, self._gather.shape[1])
            cache[m] = (geom, gather, idx)
        return cache[m]

    def residual_jacobian(self, t, q, v, a):
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

    def jacobian(self, t, q, v, a) -> JacobianBlocks:
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

    def energy(self, t, q, v) -> Energy:
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

    def external_power(self, t, q, v) -> float:
        """Power of all loads except gravity (whose work is the potential)."""
        self._check(q, v)
        f, _ = self._f_nonconservative(t, self.expand(q), False)
        return float(self.load_factor * f @ v)

    # -- capabilities and event state (ancfdae.problem.CAPABILITIES) --------------------------
    @property
    def capabilities(self) -> frozenset:
        """The optional capabilities this beam offers (see :func:`ancfdae.problem.capabilities`)."""
        caps = {"residual_jacobian", "residual_stages"}
        if not self.mass_is_constant:
            caps.add("variable_mass")
        else:
            caps.add("potential")       # M a + dP/dq - f_nc with a constant M (PotentialMixin)
        if self.element.event_state(self.geom):
            caps.add("step_events")
        return frozenset(caps)

    def event_state(self) -> dict:
        """The element's event state (BE3D: ``{"directors": (n_nodes, 3)}``), read-only arrays."""
        return dict(self.element.event_state(self.geom))

    def bind(self, state: dict) -> "Beam":
        """A beam evaluating with the event ``state``, sharing everything else (this one is unchanged)."""
        other = copy.copy(self)
        other.geom = self.element.bind(self.geom, state)
        return other

    def step_event(self, t, q, v):
        """The element's event after an accepted step (BE3D director update); None when nothing changed."""
        ev = self.element.step_event(self.geom, self.nodal(q), self._expand_v(v).reshape(self.n_nodes, -1))
        if ev is None:
            return None
        Q, V, state = ev
        return Q.reshape(-1)[self.free], V.reshape(-1)[self.free], state
