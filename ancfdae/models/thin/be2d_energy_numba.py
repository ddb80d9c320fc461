"""Compiled BE2D strain energy: the energy of the compiled kernel :class:`.be2d_kernel.BE2DCompiled`.

``U = sum_e sum_p w_p W(g_p, c_p)`` with the densities of chapter Eqs. 82-83 (structural: ``EA/2 (|r'| -
1 - eps_ref)^2`` at the axial points, ``EI/2 (K - K_ref)^2`` with ``K = c / g`` (Eq. 78) at the bending
points) or the continuum density whose variation is Eqs. 84-88, in the invariants ``g = r'.r'`` and ``c =
(r' x r'').e_z`` (Eq. 70). The same expressions, in the same order of operations, as the NumPy reference
:func:`.be2d.densities` at ``order`` 0, computed in one loop over elements x points with no per-point
arrays: on small meshes the NumPy energy's array operations cost more than their arithmetic (both timed by
``python -m benchmarks.be2d_potential``).

Two entry points: :func:`be2d_energies` (one energy per element, the element contract's ``strain_energy``)
and :func:`be2d_energy_fused` (the sum over the elements, read through the beam's gather: the beam's
``potential``, called once per step by energy-collocation's energy balance). The tests hold both equal to
the NumPy reference on random deformed states and the compiled force equal to the energy's gradient.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["be2d_energies", "be2d_energy_fused", "STRUCTURAL", "CONTINUUM"]

#: The ``form`` argument of the compiled BE2D kernels (here, below :mod:`.be2d_numba`, which imports them).
STRUCTURAL, CONTINUUM = 0, 1


@njit(cache=True, inline="always", fastmath={"contract"})
def _density_axial(form, g, eps_ref, EA):
    """``W`` at an axial point (Eq. 82; continuum: ``EA/2 ((g - 1)/2)^2``)."""
    if form == STRUCTURAL:
        d = np.sqrt(g) - (1.0 + eps_ref)
        return 0.5 * EA * (d * d)
    a = 0.5 * (g - 1.0)
    return 0.5 * EA * (a * a)


@njit(cache=True, inline="always", fastmath={"contract"})
def _density_bending(form, g, c, K_ref, E, I, I4):
    """``W`` at a bending point (Eq. 83; continuum: ``E/2 (I c^2 phi(g) + I4 c^4 / (4 g^4))``, the section
    integral of the Green strain's square, :class:`.be2d.BE2D`)."""
    ig = 1.0 / g
    if form == STRUCTURAL:
        dK = c * ig - K_ref
        return 0.5 * (E * I) * dK * dK
    phi = (1.5 - 0.5 * ig) * ig
    psi = 0.25 * ig**4
    c2 = c * c
    return 0.5 * E * (I * c2 * phi + I4 * c2 * c2 * psi)


@njit(cache=True, inline="always", fastmath={"contract"})
def _element_energy(e, qe, dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4):
    """Strain energy of element ``e`` with coordinates ``qe`` (8,), order (x, y) per Hermite function."""
    U = 0.0
    for p in range(w.shape[1]):
        r1x = dN[e, p, 0] * qe[0] + dN[e, p, 1] * qe[2] + dN[e, p, 2] * qe[4] + dN[e, p, 3] * qe[6]
        r1y = dN[e, p, 0] * qe[1] + dN[e, p, 1] * qe[3] + dN[e, p, 2] * qe[5] + dN[e, p, 3] * qe[7]
        g = r1x * r1x + r1y * r1y
        if p < n_a:
            U += w[e, p] * _density_axial(form, g, eps_ref[e, p], EA)
        else:
            r2x = ddN[e, p, 0] * qe[0] + ddN[e, p, 1] * qe[2] + ddN[e, p, 2] * qe[4] + ddN[e, p, 3] * qe[6]
            r2y = ddN[e, p, 0] * qe[1] + ddN[e, p, 1] * qe[3] + ddN[e, p, 2] * qe[5] + ddN[e, p, 3] * qe[7]
            U += w[e, p] * _density_bending(form, g, r1x * r2y - r1y * r2x, K_ref[e, p], E, I, I4)
    return U


@njit(cache=True, fastmath={"contract"})
def be2d_energies(q, dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4):
    """Strain energy of each element, shape (n_el,); ``q`` (n_el, 8) element coordinates, the other arrays
    as :func:`.be2d_numba.be2d_forces`."""
    n_el = w.shape[0]
    U = np.empty(n_el)
    for e in range(n_el):
        U[e] = _element_energy(e, q[e], dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4)
    return U


@njit(cache=True, fastmath={"contract"})
def be2d_energy_fused(q, q_fixed, gather, dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4):
    """The beam's strain energy ``sum_e U_e`` (a float) at free coordinates ``q``: element ``e``'s coordinates
    are ``concat(q, q_fixed)[gather[e]]`` (the beam's ``_element_q``), read in place."""
    nq = q.size
    qe = np.empty(8)
    U = 0.0
    for e in range(w.shape[0]):
        for k in range(8):
            g = gather[e, k]
            qe[k] = q[g] if g < nq else q_fixed[g - nq]
        U += _element_energy(e, qe, dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4)
    return U
