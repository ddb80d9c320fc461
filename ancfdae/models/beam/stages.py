"""Stacked-stage residuals of a :class:`~ancfdae.models.beam.Beam`: the residuals of several stages from
one element pass over the stages' elements stacked (the optional ``residual_stages`` Model method)."""
from __future__ import annotations

import functools

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import check_shape

__all__ = ["BeamStages"]


@functools.cache
def _finish_stages():
    """The compiled stage version of :func:`ancfdae.models.beam._finish_residual`."""
    from .assembly_numba import finish_stages
    return finish_stages


class BeamStages:
    """Stage methods of :class:`~ancfdae.models.beam.Beam` (a mixin: it uses the beam's element, assembler
    and the fused entry point)."""

    def residual_stages(self, ts: ArrayLike, Q: np.ndarray, V: np.ndarray, A: np.ndarray) -> np.ndarray:
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
