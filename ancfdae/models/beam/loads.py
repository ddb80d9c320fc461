"""The load set of a :class:`~ancfdae.models.Beam`: its loads as free force vectors, built once, and the
non-conservative external forces (dead loads with a time function, point moments whose generalised force
follows the configuration, chapter Sect. 2.2).

Point moments of an element that offers :meth:`~ancfdae.models.Element.moment_slope_operator` (BE2D,
Cable3D: the moment turns the axis tangent) are stacked at construction -- the slope operator at each
load point, the element's coordinates, its scatter slots -- and applied by one compiled call
(:func:`.moments_numba.tangent_moments`) while the element runs its compiled kernel; the element's
``moment_load`` is the path of its NumPy kernel and of every other element, one call per moment.
"""
from __future__ import annotations

import functools
from collections.abc import Iterable

import numpy as np

from ..._quadrature import gauss
from ...loads import DistributedLoad, Gravity, PointForce, PointMoment
from .assembly import Assembler
from .checks import locate, node_index

__all__ = ["LoadSet", "load_sequence"]

_LOADS = (PointForce, PointMoment, Gravity, DistributedLoad)


@functools.cache
def _tangent_moments():
    """The compiled moment pass (imports numba: only reached when the element runs its compiled kernel)."""
    from .moments_numba import tangent_moments
    return tangent_moments


def load_sequence(loads) -> tuple:
    """The ``loads`` argument of :class:`~ancfdae.models.Beam` as a tuple (a single load is a sequence of one)."""
    if isinstance(loads, _LOADS):
        return (loads,)
    if loads is None:
        return ()
    if not isinstance(loads, Iterable):
        raise TypeError(f"`loads` must be a load or a sequence of loads (PointForce, PointMoment, Gravity, "
                        f"DistributedLoad), got {loads!r}.")
    return tuple(loads)


class LoadSet:
    """A beam's loads as free force vectors.

    Parameters
    ----------
    loads : sequence of loads
    element : Element
    lengths, s_nodes : ndarray
        Element lengths and the reference arc length of each node.
    edofs : ndarray (n_el, n_edof)
        Full coordinate indices of each element.
    assembler : Assembler
        The beam's fixed pattern (free force vectors and tangent data).

    Attributes
    ----------
    gravity : ndarray (n_dof,)
        Force of gravity (its work is the potential: not in :meth:`nonconservative`).
    dead : list of (time function, ndarray (n_dof,))
        Dead point and line forces.
    moments : list
        Point moments ``(time, element, s, moment (3,), element coordinates, scatter)``; their
        generalised force depends on the configuration.
    stacked : tuple of ndarray or None
        The moments stacked for the compiled pass (module docstring): element coordinates,
        slope operators, moment vectors, vector and CSR slots; None when the element offers no slope operator.
    """

    def __init__(self, loads: Iterable, element, lengths: np.ndarray, s_nodes: np.ndarray, edofs: np.ndarray,
                 assembler: Assembler) -> None:
        el, dim = element, element.dim
        self.element = element
        self.n_dof, self.nnz = assembler.n_free, assembler.nnz
        self.dead = []
        self.moments = []
        self.gravity = np.zeros(self.n_dof)
        self._gravity_columns = {}
        S_all = w_el = None        # the distributed loads' shape matrices, built for the first of them
        for load in loads:
            if isinstance(load, (PointForce, PointMoment)):
                s = s_nodes[node_index(load.node, s_nodes.size, "load")] if load.node is not None else load.s
                (e,), (loc,) = locate(s, s_nodes, lengths, "load s")
            if isinstance(load, PointForce):
                F = load.force
                if F.shape[0] != dim:
                    raise ValueError(f"`force` must have {dim} components for {el.name}, got {F.shape[0]}.")
                S = el.shape_matrix(np.array([loc]), lengths[[e]])[0, 0]
                fe = np.zeros((lengths.size, el.n_edof))
                fe[e] = S.T @ F
                self.dead.append((load.time, assembler.vector(fe)))
            elif isinstance(load, PointMoment):
                if dim == 2 and load.moment.shape[0] != 1:
                    raise ValueError(f"`moment` of a planar element must be a scalar, got {load.moment.tolist()}.")
                self.moments.append((load.time, int(e), float(loc), load.vector3(), edofs[int(e)],
                                     assembler.element_scatter(int(e))))
            elif isinstance(load, (Gravity, DistributedLoad)):
                w = load.g if isinstance(load, Gravity) else load.w
                if w.shape[0] != dim:
                    raise ValueError(f"gravity/line load must have {dim} components for {el.name}, got {w.shape[0]}.")
                if S_all is None:
                    sq, wq = gauss(6)
                    S_all = el.shape_matrix(sq, lengths)           # (n_el, n_pts, dim, nd)
                    w_el = wq[None, :] * lengths[:, None] / 2
                rhoA = el.material.rho * el.section.A if isinstance(load, Gravity) else 1.0
                fe = rhoA * np.einsum("ep,epdk,d->ek", w_el, S_all, w)
                if isinstance(load, Gravity):
                    self.gravity += assembler.vector(fe)
                else:
                    self.dead.append((load.time, assembler.vector(fe)))
            else:
                raise TypeError(f"`loads` entries must be PointForce, PointMoment, Gravity or DistributedLoad, "
                                f"got {load!r}.")
        self.stacked = self._stack(assembler, lengths, edofs) if self.moments else None

    def _stack(self, assembler, lengths, edofs):
        """The moments' arrays for :func:`.moments_numba.tangent_moments`, or None (no slope operator)."""
        ops = [self.element.moment_slope_operator(loc, float(lengths[e])) for _, e, loc, *_ in self.moments]
        if any(op is None for op in ops):
            return None
        n_el, nd = edofs.shape
        es = np.array([e for _, e, *_ in self.moments])
        vslot = assembler._vec_all.reshape(n_el, nd)[es]
        mslot = assembler._slot_all.reshape(n_el, nd * nd)[es]
        return (np.ascontiguousarray(edofs[es]), np.ascontiguousarray(np.stack(ops), dtype=float),
                np.stack([m for _, _, _, m, *_ in self.moments]).astype(float),
                np.ascontiguousarray(vslot), np.ascontiguousarray(mslot))

    @property
    def gravity_only(self) -> bool:
        """True when no load but gravity acts: the external force is constant."""
        return not self.dead and not self.moments

    def gravity_columns(self, m: int) -> np.ndarray:
        """Gravity's force repeated for ``m`` stages, shape (n_dof, m) (built once per ``m``)."""
        if m not in self._gravity_columns:
            self._gravity_columns[m] = np.repeat(self.gravity[:, None], m, axis=1)
        return self._gravity_columns[m]

    def nonconservative(self, t: float, q_full: np.ndarray | None, geom,
                        tangent: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """Every load but gravity as a free vector, and its q-derivative as tangent data (None without moments).

        ``q_full``: the full coordinate vector (read only by the moments); ``geom``: the element geometry.
        """
        f = np.zeros(self.n_dof)
        for time, vec in self.dead:
            f += time(t) * vec
        kdata = None
        if self.moments:
            kdata = np.zeros(self.nnz) if tangent else None
            if self.stacked is not None and self.element.kernel_in_use == "numba":
                dofs, ops, moments, vslot, mslot = self.stacked
                scales = np.array([time(t) for time, *_ in self.moments], dtype=float)
                _tangent_moments()(np.ascontiguousarray(q_full, dtype=float), dofs, ops, moments, scales, vslot,
                                   mslot, bool(tangent), f, kdata if tangent else f[:0])
                return f, kdata
            for time, e, loc, m, dofs, (vmask, vidx, mmask, mslot) in self.moments:
                scale = time(t)
                if scale == 0.0:
                    continue
                fm, km = self.element.moment_load(geom, q_full[dofs], loc, scale * m, e, tangent)
                np.add.at(f, vidx, fm[vmask])
                if tangent:
                    np.add.at(kdata, mslot, km.ravel()[mmask])
        return f, kdata

    def external(self, t: float, q_full: np.ndarray | None, geom,
                 tangent: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """``f_nc + f_gravity`` and the load tangent data (or None).

        Without moments the non-conservative pass is skipped (bit for bit the
        same: ``0 + f_g = f_g``), and ``q_full`` may be None.
        """
        if not self.moments:
            if not self.dead:
                return self.gravity, None
            time, vec = self.dead[0]
            f = time(t) * vec
            for time, vec in self.dead[1:]:
                f += time(t) * vec
            return f + self.gravity, None
        fnc, kload = self.nonconservative(t, q_full, geom, tangent)
        return fnc + self.gravity, kload
