"""Banded LU: LAPACK (dgbtrf/dgbtrs through scipy) against a compiled numba LU, at our band widths.

``python -m benchmarks.banded_lu`` prints, per size n and half bandwidth kl = ku, the median time
(process time, microseconds) of filling the band storage from CSR data and factorising, and of one
solve, for both implementations, interleaved in one process. Half bandwidths: 7 (BE2D), 26 (SQ3D),
15 and 53 (two interleaved Lobatto stages). The matrices are random band matrices with a shifted
diagonal (partial pivoting is exercised). The package uses the faster one (LAPACK; see
``ancfdae/integrators/_linsolve.py``).
"""
from __future__ import annotations

import argparse
import time

import numpy as np
import scipy.linalg.lapack as lapack

from ancfdae.integrators._linsolve_numba import band_solve

from ._banded_numba import band_factor, band_fill

CASES = [(68, 7), (257, 7), (1028, 7), (4100, 7), (153, 26), (585, 26), (2313, 26), (136, 15), (514, 15),
         (306, 53), (1170, 53)]


def _median_us(fns, repeats, inner):
    """Interleaved medians: each repeat times every function once (``inner`` calls each)."""
    out = [[] for _ in fns]
    for _ in range(repeats):
        for i, f in enumerate(fns):
            t = time.process_time()
            for _ in range(inner):
                f()
            out[i].append((time.process_time() - t) / inner)
    return [1e6 * float(np.median(o)) for o in out]


def case(n, kl, repeats=7, seed=0):
    """Times (us) of fill+factor and solve for numba and LAPACK, and the relative difference of the solutions."""
    ku, ldab = kl, 3 * kl + 1
    rng = np.random.default_rng(seed)
    A = np.zeros((n, n))
    for d in range(-kl, ku + 1):
        i = np.arange(max(0, -d), min(n, n - d))
        A[i, i + d] = rng.standard_normal(i.size)
    A += 0.5 * np.eye(n)
    rows, cols = np.nonzero(A)
    data = A[rows, cols]
    flat = (kl + ku + rows - cols) + cols.astype(np.int64) * ldab
    ab, piv = np.zeros((n, ldab)), np.zeros(n, dtype=np.int64)
    lub_nb = ab.T   # the same memory as LAPACK's Fortran (ldab, n) factor: the library's solve reads it
    b = rng.standard_normal(n)

    def nb_factor():
        band_fill(data, flat, ab.reshape(-1))
        band_factor(ab, kl, ku, piv)

    def nb_solve():
        x = b.copy()
        band_solve(lub_nb, kl, ku, piv, x)
        return x

    def la_factor():
        abf = np.zeros(ldab * n)
        abf[flat] = data
        return lapack.dgbtrf(abf.reshape((ldab, n), order="F"), kl, ku, overwrite_ab=1)

    lub, p, _ = la_factor()
    nb_factor()

    def la_solve():
        return lapack.dgbtrs(lub, kl, ku, b, p)[0]

    diff = float(np.abs(nb_solve() - la_solve()).max() / np.abs(la_solve()).max())
    inner = max(3, 20000 // n)
    tf = _median_us([nb_factor, la_factor], repeats, inner)
    ts = _median_us([nb_solve, la_solve], repeats, inner)
    return dict(factor_numba=tf[0], factor_lapack=tf[1], solve_numba=ts[0], solve_lapack=ts[1], diff=diff)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args(argv)
    print("banded LU, median process time in us (fill + factor | solve); ratio numba / LAPACK")
    print(f"{'n':>6}{'kl':>4} | {'numba':>9}{'LAPACK':>9}{'ratio':>7} | {'numba':>8}{'LAPACK':>8}{'ratio':>7} | rel diff")
    for n, kl in CASES:
        r = case(n, kl, args.repeats)
        print(f"{n:6d}{kl:4d} | {r['factor_numba']:9.1f}{r['factor_lapack']:9.1f}"
              f"{r['factor_numba'] / r['factor_lapack']:7.2f} | {r['solve_numba']:8.1f}{r['solve_lapack']:8.1f}"
              f"{r['solve_numba'] / r['solve_lapack']:7.2f} | {r['diff']:.1e}", flush=True)


if __name__ == "__main__":
    main()
