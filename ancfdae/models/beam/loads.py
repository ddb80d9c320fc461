"""The loads of a :class:`~ancfdae.models.beam.Beam`: their set-up into free force vectors and the
non-conservative external forces (dead loads with a time function, follower point moments)."""
from __future__ import annotations

import numpy as np

from ...loads import DistributedLoad, Gravity, PointForce, PointMoment
from ..._quadrature import gauss

__all__ = ["BeamLoads"]


class BeamLoads:
    """Load methods of :class:`~ancfdae.models.beam.Beam` (a mixin: it uses the beam's element, mesh and
    assembler)."""

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

    def external_power(self, t: float, q: np.ndarray, v: np.ndarray) -> float:
        """Power of all loads except gravity (whose work is the potential)."""
        self._check(q, v)
        f, _ = self._f_nonconservative(t, self.expand(q), False)
        return float(self.load_factor * f @ v)
