"""Linear solver choice and correctness: banded LAPACK for every small or narrow-banded matrix."""
import numpy as np
import pytest
import scipy.sparse as sp

from ancfdae.integrators import _linsolve as ls
from ancfdae._scale import max_abs


def _banded(n, kl, ku, seed=0, dtype=float):
    rng = np.random.default_rng(seed)
    A = np.zeros((n, n), dtype=dtype)
    for d in range(-kl, ku + 1):
        i = np.arange(max(0, -d), min(n, n - d))
        A[i, i + d] = rng.standard_normal(i.size) + (1j * rng.standard_normal(i.size) if dtype is complex else 0)
    return A


@pytest.mark.parametrize("n, kl, ku", [(68, 7, 7), (27, 26, 26), (150, 40, 3), (400, 7, 9)])
def test_band_patterns_use_banded_lu_and_solve_exactly(n, kl, ku):
    # Catches: the 65-88 DOF gap (SuperLU was chosen there) and a wrong band map (kl/ku swapped).
    A = _banded(n, kl, ku)
    lu = ls.factorize(sp.csr_matrix(A))
    assert isinstance(lu, ls._Banded)
    b = np.arange(1.0, n + 1)
    x = lu.solve(b)
    assert np.abs(A @ x - b).max() <= 1e-10 * np.abs(b).max() * np.linalg.cond(A)


def test_complex_banded_system():
    # Catches: complex data silently cast to real (the Lobatto eigenbasis system is complex).
    A = _banded(90, 7, 7, dtype=complex)
    lu = ls.factorize(sp.csr_matrix(A))
    b = np.linspace(1, 2, 90) + 1j
    assert np.abs(A @ lu.solve(b) - b).max() < 1e-9


def test_wide_large_pattern_goes_to_superlu():
    A = sp.random(400, 400, density=0.02, random_state=1, format="csr") + sp.eye(400) * 10
    assert isinstance(ls.factorize(sp.csr_matrix(A)), ls._SuperLU)


@pytest.mark.parametrize("n", [201, 250, 290, 316, 1000])
def test_sq3d_wide_bands_above_200_use_banded_lu(n):
    # Catches: the 201-315 coordinate gap of the old rule (band storage rows <= n/4), which sent B1 SQ3D
    # beams of 12-16 elements (half bandwidth 26) to SuperLU at 8-11 times the banded cost.
    A = _banded(n, 26, 26) + 60 * np.eye(n)
    lu = ls.factorize(sp.csr_matrix(A))
    assert isinstance(lu, ls._Banded)
    b = np.arange(1.0, n + 1)
    assert np.abs(A @ lu.solve(b) - b).max() <= 1e-12 * np.abs(b).max()


def _arrow(n, kl, k):
    """A band plus ``k`` dense last rows and columns: bandwidth n, little of the band filled."""
    A = _banded(n, kl, kl) + 4 * kl * np.eye(n)
    A[n - k:, :] = 0.01
    A[:, n - k:] = 0.01
    A[range(n - k, n), range(n - k, n)] = 10.0 * kl
    return A


def test_arrow_patterns_above_small_go_to_superlu_and_below_stay_banded():
    # Catches: a rule on the band width alone (an arrow's band is the whole matrix; banded LU was measured
    # 2x slower than SuperLU at n = 400, 13x at 1000) and one that drops the small-size exception.
    assert isinstance(ls.factorize(sp.csr_matrix(_arrow(400, 7, 1))), ls._SuperLU)
    assert isinstance(ls.factorize(sp.csr_matrix(_arrow(ls.SMALL, 7, 1))), ls._Banded)


def test_band_density_threshold_is_where_the_rule_switches():
    # Catches: the threshold applied to the wrong quantity (band rows 2 kl + ku + 1 instead of kl + ku + 1,
    # or nnz counted without the band): at exactly BAND_DENSITY of the band filled it stays banded.
    n, kl, ku = 500, 30, 30
    band = (kl, ku, 2 * kl + ku + 1, None, True)
    at = int(np.ceil(ls.BAND_DENSITY * n * (kl + ku + 1)))
    assert ls.use_banded(n, band, at) and not ls.use_banded(n, band, at - 1)
    assert ls.use_banded(ls.SMALL, band, 1)


def test_duplicate_entries_are_summed():
    # Catches: assignment instead of accumulation into band storage for a non-canonical CSR.
    data, indices, indptr = np.array([1.0, 2.0, 5.0]), np.array([0, 0, 1]), np.array([0, 2, 3])
    m = sp.csr_matrix((data, indices, indptr), shape=(2, 2))
    x = ls.factorize(m).solve(np.array([3.0, 5.0]))
    assert np.allclose(x, [1.0, 1.0])


def test_max_abs_matches_numpy_and_propagates_nan():
    x = np.array([1.0, -3.0, 2.0])
    assert max_abs(x) == 3.0 and max_abs(np.zeros(0)) == 0.0
    assert np.isnan(max_abs(np.array([1.0, np.nan, 5.0]))) and np.isnan(max_abs(np.array([np.nan, 1.0])))
    assert max_abs(np.array([1.0, -np.inf])) == np.inf


def test_compiled_substitution_equals_lapack_dgbtrs():
    # Catches: pivots read 1-based (scipy returns them 0-based), the wrong band row of L or U.
    import scipy.linalg.lapack as lapack
    A = _banded(120, 7, 7, seed=5)
    lu = ls.factorize(sp.csr_matrix(A))
    assert lu._compiled
    b = np.random.default_rng(2).standard_normal(120)
    x_ref, _ = lapack.dgbtrs(lu.lub, lu.kl, lu.ku, b, lu.piv)
    assert np.abs(lu.solve(b) - x_ref).max() <= 1e-13 * np.abs(x_ref).max()


def test_singular_banded_gives_non_finite_not_an_exception():
    A = _banded(80, 3, 3)
    A[:, 10] = 0.0
    x = ls.factorize(sp.csr_matrix(A)).solve(np.ones(80))
    assert not np.all(np.isfinite(x))


def test_band_map_is_reused_for_a_copied_pattern_and_redone_for_another():
    # Catches: the band map recomputed at every refresh of a Newton matrix whose CSR indices scipy copied
    # (JacobianBlocks.combine: 28 ms per refresh at n = 1602), and a cached map reused for a different
    # pattern that shares indptr (a wrong band layout: wrong solutions).
    A = sp.csr_matrix(_banded(60, 3, 2))
    first = ls._band_map(A.indptr, A.indices, 60)
    assert ls._band_map(A.indptr, A.indices.copy(), 60) is first
    other = A.indices.copy()
    other[[0, 1]] = other[[1, 0]]   # same row lengths (same indptr), other columns
    assert ls._band_map(A.indptr, other, 60) is not first
    assert ls._band_map(A.indptr, A.indices, 60)[:3] == first[:3]


def test_trimmed_factor_solves_to_the_same_bits_as_the_full_one():
    # Catches: a trim that drops a row with a nonzero entry, or ku not shrunk with the rows (the
    # substitution then reads the wrong band row): the solve would differ from LAPACK's factors.
    import scipy.linalg.lapack as lapack
    from ancfdae.integrators._linsolve_numba import band_solve
    n, kl, ku = 102, 7, 7
    rng = np.random.default_rng(3)
    A = _banded(n, kl, ku, seed=3) + 30.0 * np.eye(n)   # dominant diagonal: few interchanges, fill rows stay zero
    lu = ls.factorize(sp.csr_matrix(A))
    assert lu._compiled and lu.ku < ku and lu.lub.shape[0] == 2 * kl + ku + 1 - (ku - lu.ku)
    ab = np.zeros((2 * kl + ku + 1, n))
    for j in range(n):
        for i in range(max(0, j - ku), min(n, j + kl + 1)):
            ab[kl + ku + i - j, j] = A[i, j]
    full, piv, info = lapack.dgbtrf(ab, kl, ku)
    for _ in range(3):
        b = rng.standard_normal(n)
        x_full = b.copy()
        band_solve(np.asfortranarray(full), kl, ku, piv, x_full)
        assert np.array_equal(lu.solve(b), x_full)


def test_factor_with_a_full_fill_row_is_not_trimmed():
    # Catches: trimming rows that row interchanges filled (a pivot from below in the first column).
    A = _banded(40, 3, 3, seed=4)
    A[0, 0], A[3, 0] = 1e-6, 50.0
    lu = ls.factorize(sp.csr_matrix(A))
    assert lu.ku == 3 or lu.lub[0].any()
    b = np.linspace(1.0, 2.0, 40)
    assert np.abs(A @ lu.solve(b) - b).max() <= 1e-10 * np.linalg.cond(A)
