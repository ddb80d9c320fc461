"""The compiled band LU (``band_factor``) keeps LAPACK ``dgbtf2``'s elimination, and the trimmed solve on its own
layout (``band_solve_ab``) the substitution of ``band_solve``, on matrices that need row interchanges.

Catches: an update skipped that was not by an exact zero (a multiplier trim cut too short, a zero test on the
wrong entry: the factors differ from the reference's), pivots other than ``dgbtf2``'s (first largest), the row
interchange stopping before the last column an earlier interchange filled, a zero pivot handled otherwise than
LAPACK (``info``, no elimination), and a trim of ``L`` or ``U`` read by the solve that drops a nonzero (the solution
differs from the untrimmed substitution's bits).
"""
import numpy as np
import pytest

pytest.importorskip("numba")

from ancfdae.integrators._linsolve_numba import band_factor, band_solve, band_solve_ab  # noqa: E402


def _kkt_like(rng, n, kl, ku, density, zero_diagonals):
    """A random band matrix with some exact-zero diagonal entries (a KKT matrix's multiplier rows) and entries
    over six decades."""
    A = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - kl), min(n, i + ku + 1)):
            if rng.random() < density:
                A[i, j] = rng.standard_normal() * 10.0 ** rng.integers(-3, 4)
    z = rng.choice(n, size=zero_diagonals, replace=False)
    A[z, z] = 0.0
    return A


def _band(A, kl, ku):
    """``A`` in band_factor's storage: ``A[i, j]`` at ``ab[j, kl + ku + i - j]`` (the ``kl`` rows of fill above
    ``U``'s band included)."""
    n = A.shape[0]
    ab = np.zeros((n, 2 * kl + ku + 1))
    for j in range(n):
        for i in range(max(0, j - kl - ku), min(n, j + kl + 1)):
            ab[j, kl + ku + i - j] = A[i, j]
    return ab


def _dgbtf2(A, kl, ku):
    """Reference: LAPACK dgbtf2's elimination written on the dense matrix (idamax, dswap over columns j..ju,
    dscal by the reciprocal, dger), returning (LU in band storage, pivots, info)."""
    A = A.copy()
    n = A.shape[0]
    piv, info, ju = np.zeros(n, dtype=np.int64), 0, 0
    for j in range(n):
        km = min(kl, n - 1 - j)
        jp = int(np.argmax(np.abs(A[j:j + km + 1, j])))
        piv[j] = j + jp
        if A[j + jp, j] == 0.0:
            info = info or j + 1
            continue
        ju = max(ju, min(j + ku + jp, n - 1))
        A[[j, j + jp], j:ju + 1] = A[[j + jp, j], j:ju + 1]
        if km > 0:
            A[j + 1:j + km + 1, j] *= 1.0 / A[j, j]
            A[j + 1:j + km + 1, j + 1:ju + 1] -= np.outer(A[j + 1:j + km + 1, j], A[j, j + 1:ju + 1])
    return _band(A, kl, ku), piv, info


@pytest.mark.parametrize("seed", range(6))
def test_band_factor_is_dgbtf2_and_the_trimmed_solve_its_substitution(seed):
    rng = np.random.default_rng(seed)
    checked = 0
    for _ in range(40):
        n, kl, ku = int(rng.integers(2, 40)), int(rng.integers(0, 7)), int(rng.integers(0, 7))
        A = _kkt_like(rng, n, kl, ku, rng.uniform(0.4, 1.0), int(rng.integers(0, n // 4 + 1)))
        ref, piv_ref, info_ref = _dgbtf2(A, kl, ku)
        for size in (n, 3 * n):   # without and with the trims
            ab, piv = _band(A, kl, ku), np.zeros(size, dtype=np.int64)
            assert band_factor(ab, kl, ku, piv) == info_ref
            np.testing.assert_array_equal(piv[:n], piv_ref)
            np.testing.assert_array_equal(ab, ref)
        if info_ref:
            continue
        # the trims: the last nonzero multiplier of each column of L, the first nonzero above U's diagonal
        for j in range(n):
            lower = np.flatnonzero(ab[j, kl + ku + 1:kl + ku + 1 + min(kl, n - 1 - j)])
            upper = np.flatnonzero(ab[j, kl + ku - min(kl + ku, j):kl + ku])
            assert piv[n + j] == (lower[-1] + 1 if lower.size else 0)
            assert piv[2 * n + j] == (min(kl + ku, j) - upper[0] if upper.size else 0)
        b = rng.standard_normal(n)
        x_full, x_trim = b.copy(), b.copy()
        band_solve(ab.T, kl, ku, piv, x_full)
        band_solve_ab(ab, kl, ku, piv, x_trim)
        np.testing.assert_array_equal(x_trim, x_full)
        cond = np.linalg.cond(A)
        if cond < 1e8:   # a solution at all (some draws are singular to round-off)
            assert np.abs(A @ x_trim - b).max() <= 1e-12 * cond * np.abs(A).max() * np.abs(x_trim).max()
        checked += 1
    assert checked >= 10   # enough regular matrices among the draws


def test_zero_pivot_gives_non_finite_solution():
    # the trims of a singular factor still leave the zero pivot's division in the solve (a non-finite result)
    rng = np.random.default_rng(7)
    A = _kkt_like(rng, 20, 3, 3, 1.0, 0)
    A[:, 5] = 0.0
    ab, piv = _band(A, 3, 3), np.zeros(60, dtype=np.int64)
    assert band_factor(ab, 3, 3, piv) == 6
    x = np.ones(20)
    band_solve_ab(ab, 3, 3, piv, x)
    assert not np.all(np.isfinite(x))
