"""LU factorisations for the Newton iterations: banded LAPACK whenever the pattern is banded.

Beam matrices with nodes numbered along the axis are banded with a half
bandwidth of about two nodes' coordinates, independent of the mesh. LAPACK's
banded LU (``dgbtrf``/``dgbtrs``, ``zgbtrf``/``zgbtrs`` for complex systems)
then costs O(n b^2). Measured on this kind of machine (one thread, factor and
solve with the copy into band storage): 10.7 us against dense LAPACK's 62 us
and SuperLU's 81-91 us for a 68-coordinate BE2D system (half bandwidth 7),
and it stays ahead of dense LU even where the band fills the whole matrix
(n = 27, half bandwidth 26: 7.3 us against 20.8 us), because scipy's dense
``lu_factor`` costs more to call than LAPACK needs to work. A compiled banded
LU (numba, the same elimination as ``dgbtf2``) was measured as well: equal at
half bandwidth 7, 1.7-2.2 times slower at 26 and 53 (``benchmarks/banded_lu.py``),
so LAPACK stays. The mapping from a CSR pattern to band storage is computed
once per pattern and cached.
"""
from __future__ import annotations

import functools

import numpy as np
import scipy.linalg as sla
import scipy.linalg.lapack as lapack
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = ["factorize", "StageMatrix"]

#: Substitute with the compiled loop (``_linsolve_numba``) up to this ``kl + ku``; LAPACK's
#: ``dgbtrs`` above (equal at 30, faster at 52 and more: ``benchmarks/banded_lu.py``).
COMPILED_SOLVE_MAX = 20

#: Up to this size every sparse matrix is factorised as banded, whatever its bandwidth (banded
#: LAPACK was faster than dense LAPACK at every width measured there, and than SuperLU up to n = 200
#: even with a full band: ``benchmarks/solver_selection.py``).
SMALL = 200
#: Above ``SMALL``: banded while the pattern fills at least this fraction of the band
#: (``nnz >= BAND_DENSITY n (kl + ku + 1)``), otherwise SuperLU. Measured (``benchmarks/solver_selection.py``,
#: fill + factor + one solve): on beam patterns (fill 0.3-1) banded takes 0.07-0.25 of SuperLU's time at
#: every size from 50 to 10^4 and every half bandwidth from 7 to 120, static and dynamic, real and complex;
#: on a band with dense last rows and columns (a body coupled to every node; fill 0.01-0.04) SuperLU wins
#: from n = 400 on (banded 2x at 400, 13x at 1000). The earlier rule, banded while ``2 kl + ku + 1 <= n/4``,
#: sent SQ3D beams of 201-315 coordinates (B1 with 12-16 elements) to SuperLU at 8-11 times the cost.
BAND_DENSITY = 0.1

_band_cache: dict = {}


def _band_map(indptr, indices, n):
    """(kl, ku, ldab, flat, unique) of a CSR pattern, cached by the identity of its ``indptr``.

    ``indices`` is compared by content when it is not the cached array itself: scipy's CSR constructor
    copies it (scipy 1.17), so a Newton matrix formed by ``JacobianBlocks.combine`` arrives with a
    fresh copy at every refresh; recomputing the map (``np.unique`` over the pattern) cost 28 ms per
    refresh of a 400-element BE2D beam (n = 1602), comparing costs microseconds.
    """
    key = (id(indptr), n)
    hit = _band_cache.get(key)
    if hit is not None and hit[0] is indptr and (hit[1] is indices or np.array_equal(hit[1], indices)):
        return hit[2]
    rows = np.repeat(np.arange(n), np.diff(indptr))
    off = rows - indices
    kl, ku = (int(max(off.max(), 0)), int(max(-off.min(), 0))) if off.size else (0, 0)
    ldab = 2 * kl + ku + 1
    # Fortran-ordered band storage of dgbtrf: ab[kl + ku + i - j, j].
    flat = (kl + ku + rows - indices) + indices.astype(np.int64) * ldab
    unique = np.unique(flat).size == flat.size
    info = (kl, ku, ldab, flat, unique)
    if len(_band_cache) > 32:
        _band_cache.clear()
    _band_cache[key] = (indptr, indices, info)
    return info


@functools.cache
def _band_solve():
    from ._linsolve_numba import band_solve
    return band_solve


@functools.cache
def _pair_solve():
    from ._linsolve_numba import pair_solve
    return pair_solve


class _Dense:
    def __init__(self, a):
        self.lu = sla.lu_factor(a, check_finite=False)

    def solve(self, rhs):
        return sla.lu_solve(self.lu, rhs, check_finite=False)


class _Banded:
    def __init__(self, data, band, n):
        kl, ku, ldab, flat, unique = band
        cplx = np.iscomplexobj(data)
        ab = np.zeros(ldab * n, dtype=complex if cplx else float)
        if unique:
            ab[flat] = data
        else:
            np.add.at(ab, flat, data)
        trf, self._trs = (lapack.zgbtrf, lapack.zgbtrs) if cplx else (lapack.dgbtrf, lapack.dgbtrs)
        self.kl, self.ku, self.dtype = kl, ku, ab.dtype
        self.lub, self.piv, info = trf(ab.reshape((ldab, n), order="F"), kl, ku, overwrite_ab=1)
        self.singular = info > 0
        self._compiled = kl + ku <= COMPILED_SOLVE_MAX
        if self._compiled:
            self._trim()

    def _trim(self):
        """Drop the factor's leading rows that are zero in every column (``ku`` shrinks with them).

        ``dgbtrf`` keeps ``kl`` rows for the fill of row interchanges; where the interchanges never
        reach that far (a beam's Newton matrix: 3 of 22 rows at half bandwidth 7), the compiled
        substitution would subtract ``0 * b[j]`` there, which changes no bit of a finite ``b``.
        """
        z = 0
        while z < self.ku and not self.lub[z].any():
            z += 1
        if z:
            self.lub, self.ku = np.asfortranarray(self.lub[z:]), self.ku - z

    def solve(self, rhs):
        if self._compiled:
            x = np.array(rhs, dtype=self.dtype)   # a copy: solved in place
            _band_solve()(self.lub, self.kl, self.ku, self.piv, x)
            return x
        x, _ = self._trs(self.lub, self.kl, self.ku, rhs, self.piv)
        return x


class _SuperLU:
    def __init__(self, m):
        self.lu = spla.splu(sp.csc_matrix(m))

    def solve(self, rhs):
        return self.lu.solve(rhs)


class StageMatrix:
    """The Newton matrix of an implicit Runge-Kutta step with one set of Jacobian blocks.

    For stage accelerations ``X`` (n, m) stored interleaved (``x = X.ravel()``)
    and blocks ``K, D, M`` evaluated at one state, the matrix of the stage
    residuals ``r_i = r(t_i, Q_i, V_i, X_i)`` with ``V = V0 + h X A^T``,
    ``Q = Q0 + h^2 X (A^2)^T`` acts as::

        J(dX) = M dX + h D dX A^T + h^2 K dX (A^T)^2.

    With the eigendecomposition ``A^T = S diag(lam) S^-1`` and ``dX = Y S^-1``
    it splits into ``m`` independent n x n systems
    ``(M + h lam_j D + h^2 lam_j^2 K) y_j = (R S)_j`` (as Radau codes do for
    first-order systems). A complex-conjugate pair of eigenvalues (Lobatto
    IIIA-3: ``lam = 1/4 +- i/sqrt(48)``) needs one complex factorisation, the
    other solution being its conjugate: one complex n x n banded LU instead of
    a real 2n x 2n one with twice the bandwidth, about half the work, and one
    set of blocks to evaluate instead of one per stage.

    Parameters
    ----------
    blocks : JacobianBlocks
        ``K, D, M`` as CSR matrices sharing one pattern (``same_pattern``).
    h : float
        Step size.
    a : ndarray, shape (m, m)
        The implicit part of the tableau (the rows and columns of the implicit stages).
    """

    def __init__(self, blocks, h, a):
        if not getattr(blocks, "same_pattern", False):
            raise ValueError("`blocks` must share one CSR pattern (same_pattern=True) for StageMatrix.")
        self.blocks, self.h = blocks, float(h)
        a = np.asarray(a, dtype=float)
        lam, S = np.linalg.eig(a.T)
        self.m = a.shape[0]
        self.lam, self.S, self.Sinv = lam, S, np.linalg.inv(S)

    def factorize(self):
        """Factorise the m (or fewer, for conjugate pairs) systems; returns an object with ``solve(r)``."""
        return _StageFactors(self)


class _StageFactors:
    def __init__(self, sm):
        b, h = sm.blocks, sm.h
        K, D, M = b.K, b.D, b.M
        m = sm.m
        self.m, self.S, self.Sinv = m, sm.S, sm.Sinv
        self.plan = []   # (j, factor or None, conjugate-of index)
        self._complex = {}
        done = {}
        for j, lam in enumerate(sm.lam):
            twin = next((k for k, l2 in done.items() if abs(np.conj(l2) - lam) <= 1e-14 * abs(lam)
                         and abs(lam.imag) > 0), None)
            if twin is not None:
                self.plan.append((j, None, twin))
                continue
            self._complex[j] = abs(lam.imag) > 0
            if self._complex[j]:
                data = M.data + (h * lam) * D.data + (h * h * lam * lam) * K.data
            else:
                lr = lam.real
                data = M.data + (h * lr) * D.data + (h * h * lr * lr) * K.data
            self.plan.append((j, _factorize_pattern(data, K.indptr, K.indices, K.shape[0]), None))
            done[j] = lam
        self.singular = any(getattr(f, "singular", False) for _, f, _ in self.plan if f is not None)
        lu = self.plan[0][1]
        # Lobatto IIIA-3 and the like: one conjugate pair on a narrow band -> one compiled call per solve
        self._pair = (m == 2 and self.plan[1][2] == 0 and isinstance(lu, _Banded) and lu._compiled)
        if self._pair:
            self._pair_args = (lu.lub, lu.kl, lu.ku, lu.piv, complex(self.S[0, 0]), complex(self.S[1, 0]),
                               complex(self.Sinv[0, 0]), complex(self.Sinv[0, 1]))

    def solve(self, rhs):
        m = self.m
        if self._pair:
            R = np.ascontiguousarray(rhs, dtype=float).reshape(-1, 2)
            out = np.empty(R.shape)
            lub, kl, ku, piv, s0, s1, w0, w1 = self._pair_args
            _pair_solve()(lub, kl, ku, piv, R, s0, s1, w0, w1, out)
            return out.ravel()
        R = np.asarray(rhs).reshape(-1, m)
        RS = R @ self.S                                       # (n, m) complex
        Y = np.empty(RS.shape, dtype=complex)
        for j, lu, twin in self.plan:
            if lu is None:
                continue
            rj = np.ascontiguousarray(RS[:, j])
            Y[:, j] = lu.solve(rj) if self._complex[j] else lu.solve(rj.real) + 1j * lu.solve(rj.imag)
        for j, lu, twin in self.plan:
            if lu is None:
                Y[:, j] = np.conj(Y[:, twin])
        return (Y @ self.Sinv).real.ravel()


def factorize(matrix):
    """LU-factorise a square dense array or sparse matrix; returns an object with ``solve(rhs)``.

    A :class:`StageMatrix` factorises in its eigenbasis. Sparse matrices go
    to LAPACK's banded LU, real or complex, when small
    (``n <= SMALL``) or when their pattern fills the band (``BAND_DENSITY``, :func:`use_banded`),
    otherwise to SuperLU; dense arrays to dense LAPACK. A singular banded or dense matrix gives
    ``inf``/``nan`` in the solution (the Newton solver reports that as a
    non-finite correction); SuperLU raises RuntimeError for an exactly
    singular matrix.
    """
    if isinstance(matrix, StageMatrix) or (not sp.issparse(matrix) and callable(getattr(matrix, "factorize", None))):
        return matrix.factorize()   # a matrix object that factorises itself (StageMatrix, GGL's ReducedMatrix)
    if not sp.issparse(matrix):
        arr = np.asarray(matrix)
        if not np.iscomplexobj(arr):
            arr = arr.astype(float, copy=False)
        if arr.ndim != 2 or arr.shape[0] != arr.shape[1]:
            raise ValueError(f"the Jacobian must be a square matrix, got shape {arr.shape}.")
        return _Dense(arr)
    n = matrix.shape[0]
    if matrix.shape[0] != matrix.shape[1]:
        raise ValueError(f"the Jacobian must be a square matrix, got shape {matrix.shape}.")
    csr = matrix if sp.isspmatrix_csr(matrix) else sp.csr_matrix(matrix)
    return _factorize_pattern(csr.data, csr.indptr, csr.indices, n)


def use_banded(n: int, band: tuple, nnz: int) -> bool:
    """True when banded LAPACK factorises an ``n x n`` matrix of ``nnz`` stored entries and the band
    ``band`` (of :func:`_band_map`): small, or the pattern fills enough of the band (``BAND_DENSITY``)."""
    kl, ku = band[0], band[1]
    return n <= SMALL or nnz >= BAND_DENSITY * n * (kl + ku + 1)


def _factorize_pattern(data, indptr, indices, n):
    """Factorise the CSR matrix ``(data, indices, indptr)``; the band map is cached by the identity of
    the pattern arrays, so callers should pass the same arrays every time (the beam's assembler does)."""
    band = _band_map(indptr, indices, n)
    if use_banded(n, band, indices.size):
        return _Banded(data, band, n)
    return _SuperLU(sp.csr_matrix((data, indices, indptr), shape=(n, n)))
