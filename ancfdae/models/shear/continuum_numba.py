"""Compiled continuum-mechanics energy density of SQ2D and SQ3D at one axial point.

The same energy as :func:`.continuum.continuum_kernel`:
St. Venant-Kirchhoff on the Green strain (chapter Eqs. 13, 28-33) integrated
over the cross-section by points. At section point ``s`` the convected
gradient has the columns ``X_c = sum_b P[s, c, b] v_b`` (``x_xi = r' + eta
a_2' (+ zeta a_3')``, ``x_eta = a_2`` (, ``x_zeta = a_3``)); each column
uses only a few blocks ``b`` of the local variables, given as the sparse
table ``blk[s, c, m]``, ``coef[s, c, m]`` with ``cnt[s, c]`` entries. The
Voigt order is that of :func:`.continuum.voigt` (pairs
``vi[a], vj[a]``): normal strains ``C_ii / 2``, engineering shears ``C_ij``.
"""
from __future__ import annotations

from numba import njit

__all__ = ["continuum_point"]

_OPTS = dict(cache=True, fastmath={"contract"})


@njit(cache=True, inline="always", fastmath={"contract"})
def continuum_point(dim, v, blk, coef, cnt, ws, Ds, ref, wax, vi, vj, X, eps, sig, S, Bm, DB, HX, g, H, order):
    """Energy at one axial point; gradient into ``g`` and Hessian into ``H`` (overwritten).

    Parameters
    ----------
    v : (n_v,) local variables. blk, coef : (S, dim, 3); cnt : (S, dim). ws : (S,) section weights.
    Ds : (S, n_voigt, n_voigt) elasticity per section point. ref : (S, n_voigt) reference strains.
    wax : axial weight. vi, vj : (n_voigt,) Voigt index pairs.
    X (dim, dim), eps, sig (n_voigt,), S (dim, dim), DB (n_voigt, dim * dim), HX (dim * dim,) * 2: work;
    Bm (n_voigt, dim * dim): unused (DB is formed from X directly), kept for the callers.
    """
    nvo = vi.shape[0]
    ndd = dim * dim
    W = 0.0
    if order >= 1:
        g[:] = 0.0
    if order >= 2:
        H[:, :] = 0.0
    for s in range(ws.shape[0]):
        w = wax * ws[s]
        for i in range(dim):
            for c in range(dim):
                x = 0.0
                for m in range(cnt[s, c]):
                    x += coef[s, c, m] * v[blk[s, c, m] * dim + i]
                X[i, c] = x
        for a in range(nvo):
            p, r = vi[a], vj[a]
            x = 0.0
            for i in range(dim):
                x += X[i, p] * X[i, r]
            eps[a] = (0.5 * x if p == r else x) - ref[s, a]
        Wp = 0.0
        for a in range(nvo):
            x = 0.0
            for b in range(nvo):
                x += Ds[s, a, b] * eps[b]
            sig[a] = x
            Wp += x * eps[a]
        W += 0.5 * w * Wp
        if order == 0:
            continue
        # Second Piola-Kirchhoff stress S_cd and the force dW/dX_ic = sum_d S_cd X_id.
        for a in range(nvo):
            p, r = vi[a], vj[a]
            S[p, r] = sig[a]
            S[r, p] = sig[a]
        for i in range(dim):
            for c in range(dim):
                x = 0.0
                for d in range(dim):
                    x += S[c, d] * X[i, d]
                x *= w
                for m in range(cnt[s, c]):
                    g[blk[s, c, m] * dim + i] += coef[s, c, m] * x
        if order == 1:
            continue
        # d eps_a / d X_ic (Bm: row a is X[:, r] in column p and X[:, p] in column r, one column for a
        # normal strain), DB = D Bm over the nonzeros of D and Bm (the split D0 is diagonal), then
        # HX = delta_ij S_cd + Bm^T D Bm (in X) row by row over Bm's nonzeros, then mapped onto v.
        for a in range(nvo):
            for k in range(ndd):
                DB[a, k] = 0.0
        for b in range(nvo):
            p, r = vi[b], vj[b]
            for a in range(nvo):
                dab = Ds[s, a, b]
                if dab == 0.0:
                    continue
                for i in range(dim):
                    DB[a, i * dim + p] += dab * X[i, r]
                    if p != r:
                        DB[a, i * dim + r] += dab * X[i, p]
        for k in range(ndd):                 # upper triangle, then scaled and mirrored
            for l in range(k, ndd):
                HX[k, l] = S[k % dim, l % dim] if k // dim == l // dim else 0.0
        for a in range(nvo):
            p, r = vi[a], vj[a]
            for i in range(dim):
                x = X[i, r]
                k = i * dim + p
                for l in range(k, ndd):
                    HX[k, l] += x * DB[a, l]
                if p != r:
                    x = X[i, p]
                    k = i * dim + r
                    for l in range(k, ndd):
                        HX[k, l] += x * DB[a, l]
        for k in range(ndd):
            for l in range(k, ndd):
                x = HX[k, l] * w
                HX[k, l] = x
                HX[l, k] = x
        for i in range(dim):
            for c in range(dim):
                for j in range(dim):
                    for d in range(dim):
                        x = HX[i * dim + c, j * dim + d]
                        for m in range(cnt[s, c]):
                            row = blk[s, c, m] * dim + i
                            xm = coef[s, c, m] * x
                            for n in range(cnt[s, d]):
                                H[row, blk[s, d, n] * dim + j] += xm * coef[s, d, n]
    return W
