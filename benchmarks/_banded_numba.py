"""Compiled banded LU with partial pivoting (the algorithm of LAPACK's dgbtf2/dgbtrs).

Beam matrices with nodes numbered along the axis are banded with a half
bandwidth of two nodes' coordinates, whatever the mesh (BE2D: 7, SQ3D: 26,
twice that for two coupled Runge-Kutta stages). At these widths LAPACK's own
work is a few microseconds and the cost of calling it from Python (argument
checks, copies, the f2py wrappers) is of the same size; these loops run the
same elimination from one compiled call, reading the matrix straight from the
CSR data through a precomputed map into band storage.

Storage: ``ab`` of shape ``(n, 2 kl + ku + 1)`` in C order, i.e. LAPACK's
Fortran ``AB(ldab, n)`` with ``A[i, j]`` at ``ab[j, kl + ku + i - j]``; the
first ``kl`` rows of AB (the fill-in of U) start as zero. The pivots ``piv``
are 0-based row indices. The transpose ``ab.T`` is LAPACK's factor itself, so the solve is the
package's :func:`ancfdae.integrators._linsolve_numba.band_solve` applied to ``ab.T``.
"""
from __future__ import annotations


__all__ = ["band_fill", "band_factor"]

from ancfdae.integrators._linsolve_numba import band_factor, band_fill  # noqa: E402,F401  (moved to the package)
