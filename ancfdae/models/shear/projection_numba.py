"""Compiled SQ2D/SQ3D internal forces at several configurations, projected, in one call.

The projection entry points of :meth:`ancfdae.models.beam.stages.StageEvaluator.projection`: for ``k`` configurations
``Q_l = Z @ A[:, l]`` of the free coordinates they return ``P[:, s] = sum_l B[l, s] dU/dq(Q_l)`` (the
energy-preserving collocation's ``sum_l b_l P_i(c_l) grad U(sigma(c_l))``, chapter Eqs. 104-107 for the
local variables, the densities of :mod:`.structural_numba`, :mod:`.structural3d_numba` and
:mod:`.continuum_numba`). Per element the configurations' coordinates are formed from ``Z`` in the
element's own gather (:func:`~ancfdae.models.beam.assembly_numba.gather_configurations`), the shape
tables, stiffness and reference strains are read once, and the ``k`` forces are weighted into ``r``
element rows before one scatter: no ``(n_dof, k)`` array of configurations or forces is written. SQ3D's
structural kernel weights at each point (the local gradient ``g``, 15 numbers) and scatters ``B^T``
once per point and output; the others weight the element rows. Force only (no tangent): the order-1
pass of the kernels. Each column equals the sum of ``k`` single-configuration calls to round-off (the
configurations are summed in another order than NumPy's ``Z @ A``; test).

numba's cache holds compiled copies of the inlined kernels: after editing them, delete this folder's
and ``beam/``'s ``__pycache__/*.nbi *.nbc`` (see :mod:`.kernels_numba`).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..beam.assembly_numba import gather_configurations, scatter_projection, weigh_into
from .kernels_numba import _continuum_element, _shape_table, _structural_element
from .structural3d_force_numba import N_ROWS, point_force
from .structural3d_numba import NK, NP, NV, _scatter
from .structural_numba import N_JETS, needs_frame

__all__ = ["sq3d_structural_projection", "sq2d_structural_projection", "sq_continuum_projection"]

_OPTS = dict(cache=True, fastmath={"contract"})


@njit(**_OPTS)
def _sq3d_structural(Z, q_fixed, gather, vec_slot, A, B, out, N, dN, Dw, ref):
    """SQ3D structural: the point gradients weighted at each point, ``B^T`` scattered once per output."""
    n_el, n_pts, nn = N.shape
    k, r = B.shape
    ne = nn * 9
    Qe, fe = np.empty((k, ne)), np.empty((r, ne))
    Sb, col = np.empty((5, nn)), np.empty((5, nn), dtype=np.int64)
    v, g, H = np.empty(NV), np.zeros(NV), np.zeros((NV, NV))
    gp, Y, K_row = np.empty((r, NV)), np.zeros((NV, ne)), np.zeros((1, ne))    # Y, H, K_row: unused at order 1
    eps, sig, SV, SG = np.empty(NK), np.empty(NK), np.zeros(N_ROWS), np.zeros((N_ROWS, NP))
    for e in range(n_el):
        gather_configurations(Z, q_fixed, gather, e, A, Qe)
        fe[:, :] = 0.0
        for p in range(n_pts):
            _shape_table(N[e, p], dN[e, p], 3, Sb, col)
            need_frame = needs_frame(3, Dw[e, p])
            gp[:, :] = 0.0
            for l in range(k):
                for b in range(5):
                    for c in range(3):
                        x = 0.0
                        for i in range(nn):
                            x += Sb[b, i] * Qe[l, col[b, i] + c]
                        v[3 * b + c] = x
                point_force(v, Dw[e, p], ref[e, p], SV, SG, eps, sig, g, need_frame)
                weigh_into(gp, B, l, g, NV)
            for s in range(r):
                _scatter(gp[s], H, Sb, col, 5 if need_frame else 2, Y, fe[s], K_row, 1)
        scatter_projection(fe, e, vec_slot, out)


@njit(**_OPTS)
def _sq2d_structural(Z, q_fixed, gather, vec_slot, A, B, out, N, dN, Dw, ref):
    """SQ2D structural: each configuration's element forces weighted into the element's output rows."""
    n_el, n_pts, nn = N.shape
    k, r = B.shape
    ne, nb, nk, npv = nn * 4, 3, Dw.shape[2], 2
    nv = nb * 2
    Qe, fe, fl = np.empty((k, ne)), np.empty((r, ne)), np.empty(ne)
    Sb, col = np.empty((nb, nn)), np.empty((nb, nn), dtype=np.int64)
    v, g, H, K_row = np.empty(nv), np.zeros(nv), np.zeros((nv, nv)), np.zeros((1, ne))   # K_row: unused at order 1
    JV, JG, JH = np.zeros((N_JETS, 3)), np.zeros((N_JETS, 3, npv)), np.zeros((N_JETS, 3, npv, npv))
    eps, sig, Jm = np.empty(nk), np.empty(nk), np.zeros((nk, nv))
    for e in range(n_el):
        gather_configurations(Z, q_fixed, gather, e, A, Qe)
        fe[:, :] = 0.0
        for l in range(k):
            fl[:] = 0.0
            _structural_element(2, Qe[l], N[e], dN[e], Dw[e], ref[e], fl, K_row, 1, Sb, col, v, g, H,
                                JV, JG, JH, eps, sig, Jm)
            weigh_into(fe, B, l, fl, ne)
        scatter_projection(fe, e, vec_slot, out)


@njit(cache=True)
def sq3d_structural_projection(Z, q_fixed, gather, vec_slot, A, B, out, N, dN, Dw, ref):
    """SQ3D structural formulation: ``out[:, s] = sum_l B[l, s] dU/dq(Z @ A[:, l])`` (zeroed first; shape
    (n_dof + 1, r), last row the fixed coordinates' share). Element arrays as :func:`.kernels_numba.sq_structural`.
    One entry point per dimension: a beam compiles only its own (the 2D one alone took most of the first
    call's compiling)."""
    out[:, :] = 0.0
    _sq3d_structural(Z, q_fixed, gather, vec_slot, A, B, out, N, dN, Dw, ref)


@njit(cache=True)
def sq2d_structural_projection(Z, q_fixed, gather, vec_slot, A, B, out, N, dN, Dw, ref):
    """SQ2D structural formulation: as :func:`sq3d_structural_projection`."""
    out[:, :] = 0.0
    _sq2d_structural(Z, q_fixed, gather, vec_slot, A, B, out, N, dN, Dw, ref)


@njit(**_OPTS)
def _continuum(dim, Z, q_fixed, gather, vec_slot, A, B, out, N, dN, wax, blk, coef, cnt, ws, Ds, ref, vi, vj):
    """Continuum formulation: each configuration's element forces weighted into the element's output rows."""
    n_el, n_pts, nn = N.shape
    k, r = B.shape
    ne, nb, nvo, ndd = nn * dim * dim, 2 * dim - 1, vi.shape[0], dim * dim
    nv = nb * dim
    Qe, fe, fl = np.empty((k, ne)), np.empty((r, ne)), np.empty(ne)
    Sb, col = np.empty((nb, nn)), np.empty((nb, nn), dtype=np.int64)
    v, g, H, K_row = np.empty(nv), np.zeros(nv), np.zeros((nv, nv)), np.zeros((1, ne))
    X, S = np.zeros((dim, dim)), np.zeros((dim, dim))
    eps, sig = np.empty(nvo), np.empty(nvo)
    Bm, DB, HX = np.zeros((nvo, ndd)), np.zeros((nvo, ndd)), np.zeros((ndd, ndd))
    for e in range(n_el):
        gather_configurations(Z, q_fixed, gather, e, A, Qe)
        fe[:, :] = 0.0
        for l in range(k):
            fl[:] = 0.0
            if dim == 3:     # the literal dimension, as in sq_continuum
                _continuum_element(3, Qe[l], N[e], dN[e], wax[e], blk, coef, cnt, ws, Ds, ref[e], vi, vj, fl,
                                   K_row, 1, Sb, col, v, g, H, X, eps, sig, S, Bm, DB, HX)
            else:
                _continuum_element(2, Qe[l], N[e], dN[e], wax[e], blk, coef, cnt, ws, Ds, ref[e], vi, vj, fl,
                                   K_row, 1, Sb, col, v, g, H, X, eps, sig, S, Bm, DB, HX)
            weigh_into(fe, B, l, fl, ne)
        scatter_projection(fe, e, vec_slot, out)


@njit(cache=True)
def sq_continuum_projection(Z, q_fixed, gather, vec_slot, A, B, out, N, dN, wax, blk, coef, cnt, ws, Ds, ref,
                            vi, vj, dim):
    """Continuum formulation: as :func:`sq3d_structural_projection`; element arrays as
    :func:`.kernels_numba.sq_continuum`."""
    out[:, :] = 0.0
    _continuum(dim, Z, q_fixed, gather, vec_slot, A, B, out, N, dN, wax, blk, coef, cnt, ws, Ds, ref, vi, vj)
