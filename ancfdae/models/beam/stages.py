"""The stage evaluator of a :class:`~ancfdae.models.Beam`: the residuals of several stages from one element
pass over the stages' elements stacked (the optional ``residual_stages`` Model method, which Lobatto IIIA
uses; it halves the per-call overhead of small meshes), and the conservative force at several
configurations, alone or projected (``potential_gradient_stages``, ``potential_gradient_projection``: the
energy-preserving collocation's silent stages)."""
from __future__ import annotations

import functools

import numpy as np

from ..._validate import check_shape
from .assembly import Assembler

__all__ = ["StageEvaluator", "potential_gradient_stages", "potential_gradient_projection"]


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
        self._mass_csr = assembler.csr(mass_data)
        # The compiled finish multiplies by the mass' nonzeros only: the assembler's pattern is the stiffness',
        # mostly zeros for the mass (B3, 16 SQ3D: 1161 of 10449 entries). The same sums (a zero adds nothing).
        nz = self._mass_csr.copy()
        nz.eliminate_zeros()
        self._mass_nz = (nz.data, nz.indptr, nz.indices)
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

    def projection(self, Z: np.ndarray, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """``P[:, s] = sum_l B[l, s] dU/dq(Z @ A[:, l])``, shape (n_dof, r), for ``Z`` (n_dof, p), ``A`` (p, k),
        ``B`` (k, r).

        With the element's compiled projection entry point one call forms the configurations per element,
        evaluates the ``k`` forces and weights them: equal to the reference below to round-off. The entry point
        is the optional method ``fused_projection(geom) -> (fn, args)`` of a compiled kernel object that also
        offers a fused kernel (:mod:`ancfdae.models.shear.projection_numba`,
        :mod:`ancfdae.models.thin.be2d_projection_numba`), called as
        ``fn(Z, q_fixed, gather, vec_slot, A, B, out, *args)`` with ``out`` (n_dof + 1, r) zeroed by ``fn``,
        its last row the fixed coordinates' share (``gather`` and ``vec_slot`` as for the fused assembly,
        :mod:`ancfdae.models.beam.assembly_numba`). Else (the NumPy kernel, an element without it) the
        reference: the configurations ``Z @ A``, their forces in one stacked pass (:meth:`gradients`) and ``G @ B``.
        """
        call = self._cache.get("projection")
        if call is None:
            call = self._cache["projection"] = self._projection_call()
        if not call:
            return self.gradients(Z @ A) @ B
        fn, head, args = call
        out = np.empty((Z.shape[0] + 1, B.shape[1]))
        fn(np.ascontiguousarray(Z, dtype=float), *head, np.ascontiguousarray(A, dtype=float),
           np.ascontiguousarray(B, dtype=float), out, *args)
        return out[:-1]

    def _projection_call(self):
        """``(fn, (q_fixed, gather, vec_slot), args)`` of the element's projection entry point, or ``()``: only
        beside a fused kernel (an element subclass that declines the fused path declines this one too)."""
        geom, gather, _, q_fixed = self._stacked(1)
        entry = getattr(getattr(self.element, "kernels", None), "fused_projection", None) \
            if self.element.fused_kernel(geom) is not None else None
        if entry is None:
            return ()
        fn, args = entry(geom)
        return fn, (q_fixed, gather, self._asm._vec_all), tuple(args)

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
        _finish_stages()(F, *self._mass_nz, np.ascontiguousarray(A, dtype=float),
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


def potential_gradient_projection(beam: "ancfdae.models.Beam", ts: np.ndarray, Z: np.ndarray, A: np.ndarray,
                                  B: np.ndarray) -> np.ndarray:
    """``P[:, s] = sum_l B[l, s] beam.potential_gradient(ts[l], Z @ A[:, l], False)[0]``, shape (n_dof, r): the
    conservative force at ``k`` configurations ``Z @ A[:, l]`` (``Z`` (n_dof, p), ``A`` (p, k)) weighted by
    ``B`` (k, r) in one compiled call where the element offers it (the ``"potential_projection"`` capability
    of :mod:`ancfdae.problem`; :meth:`StageEvaluator.projection`)."""
    k, zs, bs = np.size(ts), np.shape(Z), np.shape(B)
    if np.ndim(ts) != 1 or len(zs) != 2 or zs[0] != beam.n_dof or np.shape(A) != (zs[1], k) or len(bs) != 2 \
            or bs[0] != k:
        check_shape("ts", ts, (k,), "one time per configuration")
        check_shape("Z", Z, (beam.n_dof, np.shape(A)[0] if np.ndim(A) == 2 else 1), "(n_dof, p) with A (p, k)")
        check_shape("A", A, (zs[1] if len(zs) == 2 else 1, k), "(columns of Z, number of configurations)")
        check_shape("B", B, (k, bs[-1] if bs else 1), "(number of configurations, r)")
    P = beam._stages.projection(Z, A, B)
    gravity = beam._load_set.gravity
    if beam.load_factor != 0.0 and gravity.any():     # sum_l B[l, s] (-lambda f_gravity)
        P -= (beam.load_factor * gravity)[:, None] * np.sum(B, axis=0)[None, :]
    return P
