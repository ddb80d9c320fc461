"""Compiled BE2D internal forces at several configurations, projected, in one call.

The projection entry point of :meth:`ancfdae.models.beam.stages.StageEvaluator.projection` for BE2D: for ``k``
configurations ``Q_l = Z @ A[:, l]`` of the free coordinates, ``out[:, s] = sum_l B[l, s] dU/dq(Q_l)``
(the energy-preserving collocation's projected conservative force; the element force of
:func:`.be2d_numba._element`, chapter Eqs. 70, 78, 82-88). Per element the configurations' eight
coordinates are formed from ``Z`` in the element's gather and the ``k`` forces, held in scalars, are
weighted into ``r`` rows before one scatter: no ``(n_dof, k)`` array is written. Each column equals the
sum of ``k`` single-configuration calls to round-off (test).

numba's cache holds a compiled copy of the inlined :func:`.be2d_numba._element`: after editing it, delete
this folder's ``__pycache__/*.nbi *.nbc``.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..beam.assembly_numba import gather_configurations, scatter_projection
from .be2d_numba import _element

__all__ = ["be2d_projection"]


@njit(cache=True, fastmath={"contract"})
def be2d_projection(Z, q_fixed, gather, vec_slot, A, B, out, dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4):
    """``out[:, s] = sum_l B[l, s] dU/dq(Z @ A[:, l])`` (zeroed first; shape (n_dof + 1, r), last row the fixed
    coordinates' share). Element arrays as :func:`.be2d_numba.be2d_forces`."""
    k, r = B.shape
    out[:, :] = 0.0
    Qe, fe = np.empty((k, 8)), np.empty((r, 8))
    Ku, dg, dc = np.empty((8, 8)), np.empty(8), np.empty(8)
    for e in range(w.shape[0]):
        gather_configurations(Z, q_fixed, gather, e, A, Qe)
        fe[:, :] = 0.0
        for l in range(k):
            f0, f1, f2, f3, f4, f5, f6, f7 = _element(e, Qe[l, 0], Qe[l, 1], Qe[l, 2], Qe[l, 3], Qe[l, 4], Qe[l, 5],
                                                      Qe[l, 6], Qe[l, 7], dN, ddN, w, eps_ref, K_ref, n_a, form,
                                                      EA, E, I, I4, False, Ku, dg, dc)
            for s in range(r):
                c = B[l, s]
                fe[s, 0] += c * f0
                fe[s, 1] += c * f1
                fe[s, 2] += c * f2
                fe[s, 3] += c * f3
                fe[s, 4] += c * f4
                fe[s, 5] += c * f5
                fe[s, 6] += c * f6
                fe[s, 7] += c * f7
        scatter_projection(fe, e, vec_slot, out)
