"""The residual's mass and load terms, ``f + M a - lam f_ext``, as compiled loops (needs numba).

Shared by the beam's residual (:mod:`ancfdae.models.beam`), its compiled Newton iterations and the
compiled whole steps of the integrators (:mod:`ancfdae.integrators._index3_steps_numba`): one rounding
everywhere, the one scipy's CSR product gives, so that a compiled path and the NumPy path give the same
bits for the same forces. It lives below both the models and the integrators, which import it.
"""
from __future__ import annotations

from numba import njit

__all__ = ["finish_residual", "finish_stages"]


@njit(cache=True)
def finish_residual(r, m_data, indptr, indices, a, lam, f_ext):
    """``r[i] = (r[i] + (M a)[i]) - lam * f_ext[i]`` for ``i < n``, with M in CSR form.

    Rounds as ``f + M @ a - lam * f_ext`` does with scipy (row sums from zero in
    pattern order; no fused multiply-add).
    """
    n = indptr.size - 1
    for i in range(n):
        s = 0.0
        for jj in range(indptr[i], indptr[i + 1]):
            s += m_data[jj] * a[indices[jj]]
        r[i] = (r[i] + s) - lam * f_ext[i]


@njit(cache=True)
def finish_stages(F, m_data, indptr, indices, A, lam, f_ext, R):
    """``R[i, k] = (F[k, i] + (M A)[i, k]) - lam * f_ext[i, k]`` for the stages ``k``.

    ``F`` (m, n + 1): the stages' assembled forces (last column: fixed bin);
    ``A``, ``f_ext``, ``R`` (n, m). Rounds as ``F.T + M @ A - lam * f_ext`` with
    scipy (its CSR times dense matrix accumulates row by row in pattern order).
    """
    n = indptr.size - 1
    m = A.shape[1]
    for i in range(n):
        for k in range(m):
            s = 0.0
            for jj in range(indptr[i], indptr[i + 1]):
                s += m_data[jj] * A[indices[jj], k]
            R[i, k] = (F[k, i] + s) - lam * f_ext[i, k]
