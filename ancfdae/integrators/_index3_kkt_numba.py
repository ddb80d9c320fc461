"""The KKT matrices of a System's compiled index-3 steps in band storage: fill, solve, reactions (needs numba).

The step's matrix ``[[K + s M + H(lam), sm G^T], [sm G, 0]]`` and the reactions' ``[[M, G^T], [G, 0]]``
(:func:`ancfdae.constrained.multipliers`) share one pattern and the band order of
:attr:`ancfdae.system_compiled.SystemArrays.kkt`, ``kkt = (pos, kl, ku, at_k, at_m, at_c, at_h, at_g, at_gt)``:
unknown ``i`` at row and column ``pos[i]`` of the band-ordered matrix, ``kl``/``ku`` its sub- and super-diagonals,
and the flat index in the band storage ``AB`` (``(n + m, 2 kl + ku + 1)``, C order, the layout of
:func:`~ancfdae.integrators._linsolve_numba.band_factor`) of every entry of each part: the beam's CSR entries
(``at_k``; tangent and mass share the pattern), the rigid bodies' mass and timed-moment entries (``at_m``,
``at_c``), ``H``'s quadratic entries (``at_h``) and ``G``'s CSR entries and their transposes (``at_g``, ``at_gt``).

A fill is one pass over each part's data, the parts in a fixed order, so every entry of ``AB`` receives its
additions in the order the earlier fill through ``pos`` gave them (the same bits). Why: through ``pos`` B6's fill
(62 unknowns) took 7.8 us of which the beam's tangent ~4.7 us (c56277c, ``python -m benchmarks.index3_cost``), and
the reactions allocated and filled a new matrix at every output time (B5 records every step).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ancfdae.integrators._linsolve_numba import band_factor, band_solve_ab
from ancfdae.joints.assembled_numba import _jacobian_data, _rates
from ancfdae._residual_numba import finish_residual

__all__ = ["kkt_solve", "rigid_residual", "kkt_fill", "system_multipliers", "multiplier_work"]


@njit(cache=True, error_model="numpy")   # a zero pivot gives inf/nan, as LAPACK does
def kkt_solve(AB, piv, kkt, r, d, b):
    """``d = A^-1 r`` with the band factors ``AB, piv`` of the KKT matrix in band order (``piv`` with the trims,
    ``3 (n + m)``: :func:`~ancfdae.integrators._linsolve_numba.band_factor`; ``d`` returned, ``b`` a work array, both
    of ``r``'s size); ``r`` is in the System's order, and so is the result."""
    pos, kl, ku = kkt[0], kkt[1], kkt[2]
    for i in range(r.size):
        b[pos[i]] = r[i]
    band_solve_ab(AB, kl, ku, piv, b)
    for i in range(r.size):
        d[i] = b[pos[i]]
    return d


@njit(cache=True)
def rigid_residual(r, q, a, w, rigid, f, ma):
    """``r_i = (M a)_i - f_i(t, q) - f_g,i`` on the rigid bodies' coordinates (``RigidBody.residual``); ``f``,
    ``ma``: work arrays of ``r``'s size."""
    ridx, mi, mj, mv, grav, fvec, fcol, ci, cj, cv, ccol = rigid
    for i in ridx:   # every entry below is on a rigid body's coordinates
        f[i] = 0.0
        ma[i] = 0.0
    for k in range(fcol.size):
        s = w[fcol[k]]
        for i in ridx:
            f[i] += s * fvec[k, i]
    for e in range(ci.size):
        f[ci[e]] += w[ccol[e]] * cv[e] * q[cj[e]]
    for e in range(mi.size):
        ma[mi[e]] += mv[e] * a[mj[e]]
    for i in ridx:
        r[i] = (ma[i] - f[i]) - grav[i]


@njit(inline="always")
def kkt_fill(fused, AB, x, q, n, m, s, sm, w, cons, rigid, beam, eargs, rbuf, kbuf, kkt, lam, gdata):
    """The step's KKT matrix at ``x`` (state ``q``) into ``AB`` (band order and storage, ``kkt``); returns
    ``(max|K|, max|sm G|)``. ``lam`` (m), ``gdata`` (``G``'s nnz): work arrays."""
    ob, nb, q_fixed, gather, vec_slot, mat_slot, m_data = beam[:7]
    lt, lv, qi, qk, qa, ls, qslot = cons[0], cons[3], cons[7], cons[9], cons[10], cons[11], cons[12]
    mv, cvv, ccol = rigid[3], rigid[9], rigid[10]
    at_k, at_m, at_c, at_h, at_g, at_gt = kkt[3:]
    f = AB.reshape(-1)
    f[:] = 0.0
    fused(q[ob:ob + nb], q_fixed, gather, vec_slot, mat_slot, True, rbuf, kbuf, *eargs)
    kmax = 0.0
    for jj in range(at_k.size):
        k = kbuf[jj]
        f[at_k[jj]] += k + s * m_data[jj]
        kmax = max(kmax, abs(k))
    for e in range(at_m.size):
        f[at_m[e]] += s * mv[e]
    for e in range(at_c.size):
        k = -(w[ccol[e]] * cvv[e])
        f[at_c[e]] += k
        kmax = max(kmax, abs(k))
    for i in range(m):
        lam[i] = sm * x[n + i]
    for e in range(at_h.size):   # H(lam) = sum_i lam_i A_i
        f[at_h[e]] += qa[e] * lam[qi[e]]
    _jacobian_data(w, lt, ls, lv, qslot, qk, qa, q, gdata)
    gmax = 0.0
    for jj in range(at_g.size):
        val = sm * gdata[jj]
        f[at_g[jj]] += val
        f[at_gt[jj]] += val
        gmax = max(gmax, abs(val))
    return kmax, gmax


@njit(cache=True)
def multiplier_work(n, m, nb, width, ng):
    """The work arrays of :func:`system_multipliers` (allocated once per compiled call, not per output time)."""
    N = n + m
    return (np.empty((N, width)), np.empty(3 * N, dtype=np.int64), np.empty(n), np.empty(N), np.empty(N), np.empty(N),
            np.empty(nb + 1), np.empty(1), np.zeros(n), np.empty(n), np.empty(n), np.empty(m), np.empty(m),
            np.empty(ng))


@njit(inline="always")
def system_multipliers(fused, W, ext, q, v, a_out, lam_out, cons, rigid, beam, eargs, lf, kkt, work, force):
    """``(a, lam)`` from ``[[M, G^T], [G, 0]] [a; lam] = [-r(t, q, v, 0); gamma]``
    (:func:`ancfdae.constrained.multipliers`) into ``a_out``, ``lam_out``: ``W`` (3, nw) the time weights at ``t``
    and their derivatives, ``ext`` the beam's external force at ``t``, ``lf`` its load factor, ``work`` from
    :func:`multiplier_work`, ``force`` the beam's fused force at ``q`` when the caller has it (the steps' last
    residual was at ``q``), else empty; the matrix in the band order ``kkt`` (its pattern is in the steps' KKT
    pattern); a singular matrix gives non-finite values."""
    n, m = q.size, lam_out.size
    ob, nb, q_fixed, gather, vec_slot, mat_slot, m_data = beam[:7]
    mr_data, mr_indptr, mr_indices = beam[9:12]
    lt, lr, lc, lv, ct, cr, cv, qi, qj, qk, qa, ls, qslot = cons[:13]
    mv = rigid[3]
    at_k, at_m, at_g, at_gt = kkt[3], kkt[4], kkt[7], kkt[8]
    AB, piv, r, rhs, xs, bs, rbuf, kbuf, zero, f2, ma, gt, gamma, gdata = work
    if force.size == 0:
        fused(q[ob:ob + nb], q_fixed, gather, vec_slot, mat_slot, False, rbuf, kbuf, *eargs)
        force = rbuf
    r[:] = 0.0
    for i in range(nb):
        r[ob + i] = force[i]
    finish_residual(r[ob:ob + nb], mr_data, mr_indptr, mr_indices, zero[ob:ob + nb], lf, ext)
    rigid_residual(r, q, zero, W[0], rigid, f2, ma)
    _rates(W[1], W[2], lt, lr, lc, lv, ct, cr, cv, qi, qj, qk, qa, q, v, gt, gamma)
    f = AB.reshape(-1)
    f[:] = 0.0
    for jj in range(at_k.size):
        f[at_k[jj]] += m_data[jj]
    for e in range(at_m.size):
        f[at_m[e]] += mv[e]
    _jacobian_data(W[0], lt, ls, lv, qslot, qk, qa, q, gdata)
    for jj in range(at_g.size):
        f[at_g[jj]] += gdata[jj]
        f[at_gt[jj]] += gdata[jj]
    for i in range(n):
        rhs[i] = -r[i]
    for i in range(m):
        rhs[n + i] = gamma[i]
    band_factor(AB, kkt[1], kkt[2], piv)
    kkt_solve(AB, piv, kkt, rhs, xs, bs)
    for i in range(n):
        a_out[i] = xs[i]
    for i in range(m):
        lam_out[i] = xs[n + i]
