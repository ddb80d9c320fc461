"""Compiled SQ2D/SQ3D kernels: energy, internal forces and exact tangent of all elements in one call.

The compiled twin of :class:`.kernels.SQReference`, as the kernel object
:class:`SQCompiled`. Each entry point loops over the elements
and calls an inlined per-element function that loops over the element's
quadrature points: it gathers the local variables ``v = B q_e`` (chapter
Eqs. 104-107: ``a_k`` with the shape functions, ``r', a_k'`` with their
derivatives), evaluates the energy density's gradient ``g`` and Hessian
``H`` (:mod:`.structural_numba`, :mod:`.continuum_numba`) and scatters ``B^T g`` and
``B^T H B`` into the element's output rows without forming ``B``. Work arrays
are allocated once per call, never per point.

The fused entry points :func:`sq_structural_fused` and :func:`sq_continuum_fused`
add the gather of the element coordinates and the scatter into the beam's CSR
data (:mod:`ancfdae.models.beam.assembly_numba`) around the same loops.

Importing this module compiles (or loads) numba code; the kernel object that offers
these calls to the beam is :class:`.sq_kernel.SQCompiled`.

numba's on-disk cache is keyed on the source file of the cached function
only, and a cached function holds a compiled copy of the functions it calls:
after editing a function in another file (:mod:`ancfdae.models.jets.vector_numba`,
:mod:`.structural_numba`, :mod:`.continuum_numba`), delete the
``*.nbi``/``*.nbc`` files in the ``__pycache__`` folders, or the old code keeps
running (measured: a stale cache kept running the previous SQ tangent, which
``tests/models/beam/test_fused_assembly.py`` caught as a fused/NumPy-assembly mismatch;
the same holds for :mod:`.moment_numba`).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..beam.assembly_numba import gather_elements, scatter
from .continuum import voigt
from .continuum_numba import continuum_point
from .structural3d_numba import sq3d_structural_elements
from .structural_numba import N_JETS, needs_frame, structural_point

__all__ = ["compiled_geometry", "sq_structural", "sq_continuum", "sq_structural_fused",
           "sq_continuum_fused"]

_INLINE = dict(cache=True, inline="always", fastmath={"contract"})


@njit(**_INLINE)
def _shape_table(N, dN, dim, Sb, col):
    """Per block ``b`` of ``v`` and node ``i``: the scalar factor ``Sb[b, i]`` and the first column ``col[b, i]``.

    Blocks: ``a_2 (, a_3)`` with ``N``, then ``r'``, ``a_2' (, a_3')`` with ``dN``; node vectors ``[r, a_2(, a_3)]``.
    """
    nn = N.shape[0]
    for b in range(2 * dim - 1):
        vec = b + 1 if b < dim - 1 else b - (dim - 1)
        for i in range(nn):
            Sb[b, i] = N[i] if b < dim - 1 else dN[i]
            col[b, i] = (i * dim + vec) * dim


@njit(**_INLINE)
def _gather(qe, Sb, col, dim, v):
    nb, nn = Sb.shape
    for b in range(nb):
        for c in range(dim):
            x = 0.0
            for i in range(nn):
                x += Sb[b, i] * qe[col[b, i] + c]
            v[b * dim + c] = x


@njit(**_INLINE)
def _scatter(g, H, Sb, col, dim, nba, f_row, K_row, order):
    """``f_row += B^T g`` and, for order 2, ``K_row += B^T H B``, over the first ``nba`` blocks of ``v``.

    ``g`` and ``H`` must vanish outside those blocks (a point with cross-section terms only touches
    the slopes ``a_k``). ``B^T H B`` is symmetric: each pair of (block, node) entries of ``B`` is
    visited once and its 3 x 3 product added at both places; zero shape-function values are skipped
    (the end-point rule has ``N = delta``).
    """
    nn = Sb.shape[1]
    for b in range(nba):
        for i in range(nn):
            for c in range(dim):
                f_row[col[b, i] + c] += Sb[b, i] * g[b * dim + c]
    if order < 2:
        return
    for u in range(nba * nn):
        b, i = u // nn, u % nn
        si = Sb[b, i]
        if si == 0.0:
            continue
        r0 = col[b, i]
        for u2 in range(u, nba * nn):
            b2, j = u2 // nn, u2 % nn
            s = si * Sb[b2, j]
            if s == 0.0:
                continue
            c0 = col[b2, j]
            if u2 == u:
                for c in range(dim):
                    for c2 in range(dim):
                        K_row[r0 + c, c0 + c2] += s * H[b * dim + c, b2 * dim + c2]
            else:
                for c in range(dim):
                    for c2 in range(dim):
                        x = s * H[b * dim + c, b2 * dim + c2]
                        K_row[r0 + c, c0 + c2] += x
                        K_row[c0 + c2, r0 + c] += x


@njit(**_INLINE)
def _structural_element(dim, qe, N, dN, Dw, ref, f_row, K_row, order, Sb, col, v, g, H, JV, JG, JH, eps, sig, Jm):
    """Energy of one element; its force and tangent added into ``f_row`` and ``K_row``."""
    W = 0.0
    nb = 2 * dim - 1
    for p in range(N.shape[0]):
        _shape_table(N[p], dN[p], dim, Sb, col)
        _gather(qe, Sb, col, dim, v)
        W += structural_point(dim, v, Dw[p], ref[p], JV, JG, JH, eps, sig, Jm, g, H, order)
        if order >= 1:
            # without the frame terms only the slopes a_k (the first dim - 1 blocks) carry energy
            _scatter(g, H, Sb, col, dim, nb if needs_frame(dim, Dw[p]) else dim - 1, f_row, K_row, order)
    return W


@njit(cache=True, fastmath={"contract"})
def sq_structural(q, N, dN, Dw, ref, dim, order):
    """Structural formulation of all elements: energy (n_el,), forces (n_el, n_edof), tangents.

    Parameters
    ----------
    q : (n_el, n_edof) element coordinates. N, dN : (n_el, n_pts, n_nodes) shape functions and
    xi-derivatives at all points (every rule's points concatenated). Dw, ref : (n_el, n_pts, n_strain)
    stiffness x weight (zero where a term does not act) and reference strains. dim : 2 or 3.
    order : 0 energy, 1 plus forces, 2 plus tangents.

    Returns
    -------
    W : (n_el,); f : (n_el, n_edof) (zeros for order 0); K : (n_el, n_edof, n_edof), or (0, ...) below order 2.
    """
    n_el, n_pts, nn = N.shape
    nedof, nb, nk, npv = nn * dim * dim, 2 * dim - 1, Dw.shape[2], dim * (dim - 1)
    nv = nb * dim
    W = np.zeros(n_el)
    f = np.zeros((n_el, nedof))
    K = np.zeros((n_el if order >= 2 else 1, nedof, nedof))
    Sb, col = np.empty((nb, nn)), np.empty((nb, nn), dtype=np.int64)
    v, g, H = np.empty(nv), np.zeros(nv), np.zeros((nv, nv))
    JV, JG, JH = np.zeros((N_JETS, 3)), np.zeros((N_JETS, 3, npv)), np.zeros((N_JETS, 3, npv, npv))
    eps, sig, Jm = np.empty(nk), np.empty(nk), np.zeros((nk, nv))
    if dim == 3:      # SQ3D: sparse point blocks and the two-pass scatter
        sq3d_structural_elements(q, N, dN, Dw, ref, order, Sb, col, W, f, K)
    else:
        for e in range(n_el):
            W[e] = _structural_element(2, q[e], N[e], dN[e], Dw[e], ref[e], f[e], K[e if order >= 2 else 0],
                                       order, Sb, col, v, g, H, JV, JG, JH, eps, sig, Jm)
    return W, f, K[:n_el if order >= 2 else 0]


@njit(**_INLINE)
def _continuum_element(dim, qe, N, dN, wax, blk, coef, cnt, ws, Ds, ref, vi, vj, f_row, K_row, order,
                       Sb, col, v, g, H, X, eps, sig, S, Bm, DB, HX):
    """Energy of one element; its force and tangent added into ``f_row`` and ``K_row``."""
    W = 0.0
    for p in range(N.shape[0]):
        _shape_table(N[p], dN[p], dim, Sb, col)
        _gather(qe, Sb, col, dim, v)
        W += continuum_point(dim, v, blk, coef, cnt, ws, Ds, ref[p], wax[p], vi, vj, X, eps, sig, S, Bm, DB, HX,
                             g, H, order)
        if order >= 1:
            _scatter(g, H, Sb, col, dim, 2 * dim - 1, f_row, K_row, order)
    return W


@njit(cache=True, fastmath={"contract"})
def sq_continuum(q, N, dN, wax, blk, coef, cnt, ws, Ds, ref, vi, vj, dim, order):
    """Continuum formulation of all elements: energy (n_el,), forces (n_el, n_edof), tangents.

    Parameters
    ----------
    q : (n_el, n_edof). N, dN : (n_el, n_pts, n_nodes). wax : (n_el, n_pts) axial weights.
    blk, coef, cnt : sparse section map (see :func:`continuum_point`). ws : (S,) section weights.
    Ds : (S, n_voigt, n_voigt). ref : (n_el, n_pts, S, n_voigt) reference strains. vi, vj : Voigt pairs.

    Returns
    -------
    As :func:`sq_structural`.
    """
    n_el, n_pts, nn = N.shape
    nedof, nb, nvo = nn * dim * dim, 2 * dim - 1, vi.shape[0]
    nv, ndd = nb * dim, dim * dim
    W = np.zeros(n_el)
    f = np.zeros((n_el, nedof))
    K = np.zeros((n_el if order >= 2 else 1, nedof, nedof))
    Sb, col = np.empty((nb, nn)), np.empty((nb, nn), dtype=np.int64)
    v, g, H = np.empty(nv), np.zeros(nv), np.zeros((nv, nv))
    X, S = np.zeros((dim, dim)), np.zeros((dim, dim))
    eps, sig = np.empty(nvo), np.empty(nvo)
    Bm, DB, HX = np.zeros((nvo, ndd)), np.zeros((nvo, ndd)), np.zeros((ndd, ndd))
    if dim == 3:
        for e in range(n_el):
            W[e] = _continuum_element(3, q[e], N[e], dN[e], wax[e], blk, coef, cnt, ws, Ds, ref[e], vi, vj,
                                      f[e], K[e if order >= 2 else 0], order, Sb, col, v, g, H, X, eps, sig, S,
                                      Bm, DB, HX)
    else:
        for e in range(n_el):
            W[e] = _continuum_element(2, q[e], N[e], dN[e], wax[e], blk, coef, cnt, ws, Ds, ref[e], vi, vj,
                                      f[e], K[e if order >= 2 else 0], order, Sb, col, v, g, H, X, eps, sig, S,
                                      Bm, DB, HX)
    return W, f, K[:n_el if order >= 2 else 0]


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


def compiled_geometry(formulation: str, dim: int, n_strain: int, geom: dict) -> tuple:
    """Contiguous arrays for the compiled kernels, from the NumPy kernel's point groups.

    Structural: every group's points concatenated per element, with the stiffness and the
    reference strains widened to all strain components (zero where a group's terms do not act).
    Continuum: the section map ``Pc`` as the sparse table the compiled kernel walks.
    """
    groups = geom["groups"]
    n_el = groups[0]["N"].shape[0]
    N = np.ascontiguousarray(np.concatenate([g["N"] for g in groups], axis=1))
    dN = np.ascontiguousarray(np.concatenate([g["dN"] for g in groups], axis=1))
    if formulation == "structural":
        Dw, ref = [], []
        for g in groups:
            P = g["N"].shape[1]
            full_D, full_r = np.zeros((n_el, P, n_strain)), np.zeros((n_el, P, n_strain))
            full_D[:, :, g["which"]] = g["Dw"].reshape(n_el, P, -1)
            full_r[:, :, g["which"]] = g["ref"].reshape(n_el, P, -1)
            Dw.append(full_D)
            ref.append(full_r)
        return (N, dN, np.ascontiguousarray(np.concatenate(Dw, axis=1)),
                np.ascontiguousarray(np.concatenate(ref, axis=1)))
    (g,) = groups
    Pc = g["Pc"]
    S, _, nb = Pc.shape
    used = [[b for b in range(nb) if np.any(Pc[:, c, b] != 0.0)] for c in range(dim)]
    width = max(len(u) for u in used)
    blk = np.zeros((S, dim, width), dtype=np.int64)
    coef = np.zeros((S, dim, width))
    cnt = np.zeros((S, dim), dtype=np.int64)
    for c, u in enumerate(used):
        blk[:, c, :len(u)] = u
        coef[:, c, :len(u)] = Pc[:, c, u]
        cnt[:, c] = len(u)
    pairs, _ = voigt(dim)
    vi = np.array([p[0] for p in pairs], dtype=np.int64)
    vj = np.array([p[1] for p in pairs], dtype=np.int64)
    P = g["N"].shape[1]
    return (N, dN, np.ascontiguousarray(g["wax"].reshape(n_el, P)), blk, coef, cnt,
            np.ascontiguousarray(g["ws"], dtype=float), np.ascontiguousarray(g["Ds"], dtype=float),
            np.ascontiguousarray(g["ref"].reshape(n_el, P, S, -1)), vi, vj)
