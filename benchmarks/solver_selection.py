"""Banded LAPACK against SuperLU on the Newton matrices' patterns, at every size: where the rule of
``ancfdae.integrators._linsolve.use_banded`` switches, and what each choice costs.

``python -m benchmarks.solver_selection [--repeats 7]``

Two families of sparse patterns, each factorised and solved once per timing (process time, interleaved
medians, microseconds), real (static and Newmark-family matrices) and complex (the conjugate-pair
stage matrix of Lobatto IIIA-3):

* *band*: beam matrices, half bandwidth ``kl`` independent of the mesh (7: BE2D, 26: SQ3D) at sizes
  ``n`` from 50 to 10^4, and wider bands (53: two coupled stages of SQ3D; 120) -- the B1 SQ3D meshes of 12-16 elements sit at n = 201-290, where the rule
  before issue 22 (banded only up to n = 200 or while ``2 kl + ku + 1 <= n / 4``) chose SuperLU;
* *beam*: the stiffness (static) and ``M + (h^2/4) K`` (Newmark, h = 1e-4) of clamped SQ3D and BE2D beams;
* *arrow*: a BE2D band plus ``k`` dense last rows and columns (a rigid body or a constraint coupled
  to every node): its bandwidth is ``n``, and SuperLU's fill stays small.

Printed per case: the band storage rows ``ldab``, both times, their ratio (banded / SuperLU) and the
choice of the package's rule (``banded`` / ``superlu``); a choice against a ratio far from 1 is a
rule to fix.
"""
from __future__ import annotations

import argparse
import time

import numpy as np
import scipy.sparse as sp

from ancfdae.integrators import _linsolve as ls


def band(n, kl, seed=0, cplx=False):
    """A random ``n x n`` CSR band matrix, half bandwidth ``kl``, diagonally dominant."""
    rng = np.random.default_rng(seed)
    diags = [rng.standard_normal(n - abs(d)) for d in range(-kl, kl + 1)]
    A = sp.diags(diags, list(range(-kl, kl + 1)), format="csr") + sp.identity(n, format="csr") * (2.0 * kl + 2)
    if cplx:
        A = A + 1j * sp.diags([rng.standard_normal(n - abs(d)) for d in range(-kl, kl + 1)],
                             list(range(-kl, kl + 1)), format="csr")
    return sp.csr_matrix(A)


def arrow(n, kl, k, seed=0):
    """A band of half width ``kl`` plus ``k`` dense last rows and columns."""
    A = band(n, kl, seed).tolil()
    rng = np.random.default_rng(seed + 1)
    A[n - k:, :] = rng.standard_normal((k, n)) * 0.01
    A[:, n - k:] = rng.standard_normal((n, k)) * 0.01
    A[range(n - k, n), range(n - k, n)] = 10.0 * kl
    return sp.csr_matrix(A)


def beam_matrix(element, n_el, dynamic):
    """A clamped beam's stiffness at the reference state (static) or ``M + (h^2 / 4) K`` with h = 1e-4."""
    from ancfdae import Material, RectangularSection
    from ancfdae.models import BE2D, SQ3D, Beam
    el = {"BE2D": BE2D, "SQ3D": SQ3D}[element](Material(2.07e11, 0.3, 7800.0), RectangularSection(0.1))
    beam = Beam(el, n_elements=n_el, length=2.0, supports={0: "clamp"})
    q, v = beam.initial_state()
    J = beam.jacobian(0.0, q, v, np.zeros_like(q))
    return sp.csr_matrix(J.combine(2.5e-9, 0.0, 1.0) if dynamic else J.K)


def case(A, repeats):
    """(banded us, SuperLU us, relative difference of the solutions) for fill + factor + one solve."""
    n = A.shape[0]
    A.sort_indices()
    data, indptr, indices = A.data, A.indptr, A.indices
    band_info = ls._band_map(indptr, indices, n)
    rhs = np.arange(1.0, n + 1.0)

    def banded():
        return ls._Banded(data, band_info, n).solve(rhs)

    def superlu():
        return ls._SuperLU(A).solve(rhs)

    x1, x2 = banded(), superlu()
    diff = float(np.abs(x1 - x2).max() / np.abs(x2).max())
    inner = max(1, int(2e4 // (n * (band_info[0] + 1))))
    times = [[], []]
    for _ in range(repeats):
        for i, fn in enumerate((banded, superlu)):
            t = time.process_time()
            for _ in range(inner):
                fn()
            times[i].append((time.process_time() - t) / inner)
    tb, ts = (1e6 * float(np.median(t)) for t in times)
    return band_info[2], tb, ts, diff


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    a = ap.parse_args(argv)
    cases = []
    for kl in (7, 26):
        for n in (50, 150, 201, 250, 290, 400, 1000, 3000, 10000):
            cases.append((f"band kl={kl}", n, lambda n=n, kl=kl: band(n, kl)))
            cases.append((f"band kl={kl} complex", n, lambda n=n, kl=kl: band(n, kl, cplx=True)))
    for kl in (53, 120):
        for n in (300, 1000, 3000):
            cases.append((f"band kl={kl}", n, lambda n=n, kl=kl: band(n, kl)))
    for element, sizes in (("SQ3D", (4, 12, 14, 16, 32, 128)), ("BE2D", (16, 64, 256, 1024))):
        for n_el in sizes:
            for dyn in (False, True):
                A = beam_matrix(element, n_el, dyn)
                cases.append((f"{element} {n_el} el {'M+cK' if dyn else 'K'}", A.shape[0], lambda A=A: A))
    for k in (1, 3):
        for n in (100, 201, 400, 1000, 3000):
            cases.append((f"arrow kl=7 k={k}", n, lambda n=n, k=k: arrow(n, 7, k)))
    print(f"{'pattern':24s} {'n':>6s} {'ldab':>6s} {'banded us':>10s} {'SuperLU us':>11s} {'ratio':>6s} "
          f"{'rule':>8s} {'|dx|':>8s}")
    for name, n, make in cases:
        A = make()
        ldab, tb, ts, diff = case(A, a.repeats)
        rule = "banded" if ls.use_banded(n, ls._band_map(A.indptr, A.indices, n), A.nnz) else "superlu"
        print(f"{name:24s} {n:6d} {ldab:6d} {tb:10.1f} {ts:11.1f} {tb / ts:6.2f} {rule:>8s} {diff:8.1e}",
              flush=True)


if __name__ == "__main__":
    main()
