"""The stage evaluator of a :class:`~ancfdae.models.Beam`: the residuals of several stages from one element
pass over the stages' elements stacked (the optional ``residual_stages`` Model method, which Lobatto IIIA
uses); it halves the per-call overhead of small meshes."""
from __future__ import annotations

import functools

import numpy as np

from ..._validate import check_shape
from .assembly import Assembler

__all__ = ["StageEvaluator", "potential_gradient_stages"]


@functools.cache
def _finish_stages():
    """The compiled ``F + M A - lambda F_ext`` of the stages (imports numba: only reached on the fused path)."""
    from ..._residual_numba import finish_stages
    return finish_stages


class StageEvaluator:
    """Residuals ``F(Q) + M A - lambda F_ext`` of ``m`` stages of a constant-mass beam in one element pass.

    The element kernel runs once on the stages' elements stacked: a geometry
    for ``m`` copies of the mesh, prepared on first use of each ``m``. With a
    fused entry point of the element (:meth:`ancfdae.models.Element.fused_kernel`)
    gather, kernel, scatter and the residual run compiled; else NumPy gathers
    and ``np.bincount`` scatters (the same sums in the same order).

    Parameters
    ----------
    element : Element
    q_ref_elements : ndarray (n_el, n_edof)
        Element coordinates of the reference configuration.
    lengths : ndarray (n_el,)
    gather : ndarray (n_el, n_edof)
        Index of each element coordinate in ``(free q, fixed values)``.
    q_fixed : ndarray
        Reference values of the fixed coordinates.
    assembler : Assembler
    mass_data : ndarray
        CSR data of the constant mass matrix (pattern of ``assembler``).
    """

    def __init__(self, element, q_ref_elements: np.ndarray, lengths: np.ndarray, gather: np.ndarray,
                 q_fixed: np.ndarray, assembler: Assembler, mass_data: np.ndarray) -> None:
        self.element = element
        self._q_ref_elements, self._lengths = q_ref_elements, lengths
        self._gather, self._q_fixed = gather, q_fixed
        self._asm = assembler
        self._mass_data = mass_data
        self._mass_csr = assembler.csr(mass_data)
        self._no_k = np.empty(1)
        self._cache = {}

    def _stacked(self, m):
        """Element geometry of ``m`` stacked copies of the mesh, its gather, scatter index and fixed values."""
        if m not in self._cache:
            n = self._asm.n_free
            geom = self.element.prepare(np.tile(self._q_ref_elements, (m, 1)), np.tile(self._lengths, m))
            idx = (np.arange(m)[:, None] * (n + 1) + self._asm._vec_all[None, :]).ravel()
            gather = (self._gather[None] * m + np.arange(m)[:, None, None]).reshape(-1, self._gather.shape[1])
            self._cache[m] = (geom, gather, idx, np.repeat(self._q_fixed, m))
        return self._cache[m]

    def gradients(self, Q: np.ndarray) -> np.ndarray:
        """``G[:, i] = dU/dq(Q[:, i])`` of ``m`` configurations, shape (n_dof, m), from one element pass.

        The same sums in the same order as :meth:`Beam.internal_forces` per column (the stacked copies
        are scattered copy by copy, elements in mesh order): equal bits.
        """
        n, m = Q.shape
        geom, gather, idx, q_fixed_m = self._stacked(m)
        fused = self.element.fused_kernel(geom)
        if fused is None:
            ext = np.empty((n + self._q_fixed.size, m))
            ext[:n] = Q
            ext[n:] = self._q_fixed[:, None]
            fe, _ = self.element.internal_forces(geom, ext.ravel().take(gather), False)
            return np.bincount(idx, weights=fe.ravel(), minlength=m * (n + 1)).reshape(m, n + 1)[:, :n].T
        fn, args = fused
        F = np.empty((m, n + 1))
        fn(np.ascontiguousarray(Q, dtype=float).reshape(-1), q_fixed_m, gather, idx, self._asm._slot_all, False,
           F.reshape(-1), self._no_k, *args)
        return F[:, :n].T

    def residuals(self, Q: np.ndarray, A: np.ndarray, F_ext: np.ndarray, load_factor: float) -> np.ndarray:
        """``R[:, i] = f(Q[:, i]) + M A[:, i] - load_factor F_ext[:, i]``, shape (n_dof, m)."""
        n, m = Q.shape
        geom, gather, idx, q_fixed_m = self._stacked(m)
        fused = self.element.fused_kernel(geom)
        if fused is None:
            ext = np.empty((n + self._q_fixed.size, m))   # (free q; fixed values) per stage, stage fastest
            ext[:n] = Q
            ext[n:] = self._q_fixed[:, None]
            fe, _ = self.element.internal_forces(geom, ext.ravel().take(gather), False)
            F = np.bincount(idx, weights=fe.ravel(), minlength=m * (n + 1))
            F = F.reshape(m, n + 1)[:, :n].T
            R = F + self._mass_csr @ A
            R -= load_factor * F_ext
            return R
        fn, args = fused
        F = np.empty((m, n + 1))
        fn(np.ascontiguousarray(Q, dtype=float).reshape(-1), q_fixed_m, gather, idx, self._asm._slot_all, False,
           F.reshape(-1), self._no_k, *args)
        R = np.empty((n, m))
        _finish_stages()(F, self._mass_data, self._asm.indptr, self._asm.indices, np.ascontiguousarray(A, dtype=float),
                         float(load_factor), F_ext, R)
        return R


def potential_gradient_stages(beam: "ancfdae.models.Beam", ts: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """``G[:, i] = beam.potential_gradient(ts[i], Q[:, i], False)[0]`` for ``m`` configurations in one element
    pass (the ``"potential_stages"`` capability of :mod:`ancfdae.problem`; the energy-preserving collocation
    evaluates the conservative force at its ``k`` silent stages with it), shape (n_dof, m)."""
    m = np.size(ts)
    if np.ndim(ts) != 1 or np.shape(Q) != (beam.n_dof, m):
        check_shape("ts", ts, (m,), "one time per configuration")
        check_shape("Q", Q, (beam.n_dof, m), f"(n_dof, number of configurations) = ({beam.n_dof}, {m})")
    G = beam._stages.gradients(Q)
    return G - beam.load_factor * beam._load_set.gravity[:, None]
