"""Fused assembly entry points of the compiled SQ2D/SQ3D kernels (see ``_assembly_numba``).

Gather, the element loop of :mod:`ancfdae.models._sq_numba` and the scatter into the beam's CSR
data in one compiled call, for both formulations.

numba's on-disk cache is keyed on this file only: the cached entry points hold a compiled copy of the
SQ kernels they call, so after editing any SQ kernel module delete the ``*.nbi``/``*.nbc`` files in
``ancfdae/models/__pycache__`` (measured: a stale cache kept running the previous SQ tangent, which
``tests/test_fused_assembly.py`` caught as a fused/NumPy-assembly mismatch).
"""
from __future__ import annotations

from numba import njit

from ..beam.assembly_numba import gather_elements, scatter
from .kernels_numba import sq_continuum, sq_structural

__all__ = ["sq_structural_fused", "sq_continuum_fused"]


@njit(cache=True)
def sq_structural_fused(q, q_fixed, gather, vec_slot, mat_slot, tangent, r, kdata, N, dN, Dw, ref, dim):
    """Structural formulation: ``dU/dq`` into ``r`` and, if ``tangent``, its tangent into ``kdata``."""
    qe = gather_elements(q, q_fixed, gather)
    _, f, K = sq_structural(qe, N, dN, Dw, ref, dim, 2 if tangent else 1)
    scatter(f, vec_slot, r)
    if tangent:
        scatter(K, mat_slot, kdata)


@njit(cache=True)
def sq_continuum_fused(q, q_fixed, gather, vec_slot, mat_slot, tangent, r, kdata,
                       N, dN, wax, blk, coef, cnt, ws, Ds, ref, vi, vj, dim):
    """Continuum formulation: as :func:`sq_structural_fused`."""
    qe = gather_elements(q, q_fixed, gather)
    _, f, K = sq_continuum(qe, N, dN, wax, blk, coef, cnt, ws, Ds, ref, vi, vj, dim, 2 if tangent else 1)
    scatter(f, vec_slot, r)
    if tangent:
        scatter(K, mat_slot, kdata)
