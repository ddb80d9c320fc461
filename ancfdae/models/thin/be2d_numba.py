"""Compiled BE2D kernel: the default of :class:`ancfdae.models.BE2D` (``kernel="auto"``).

The same force and exact tangent as the NumPy reference :class:`.be2d.BE2DReference`
(chapter Eqs. 70, 78, 82-88, written in the invariants ``g = r'.r'`` and
``c = (r' x r'').e_z``), computed in one compiled loop over elements x
quadrature points: on small meshes it removes the per-call overhead of some
fifty NumPy operations on arrays of a few hundred entries. The tests compare
the two on random deformed states. The kernel object that offers these calls to
the beam is :class:`.be2d_kernel.BE2DCompiled`.

Importing this module compiles (or loads) numba code.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ...integrators._affine import affine3
from ..beam.iteration_numba import alpha_finish, alpha_update, carry_on
from ...integrators._alpha_steps_numba import alpha_steps
from ..beam.static_numba import static_newton
from ...integrators._index3_steps_numba import index3_steps
from ...integrators._index3_kkt_numba import multiplier_work, system_multipliers
from .be2d_energy_numba import CONTINUUM, STRUCTURAL

__all__ = ["be2d_forces", "be2d_fused", "be2d_alpha_iterations", "be2d_alpha_steps",
           "be2d_static_newton", "be2d_index3_steps", "be2d_multipliers", "STRUCTURAL", "CONTINUUM"]


@njit(cache=True, inline="always", fastmath={"contract"})
def _densities_axial(form, g, eps_ref, EA):
    """(Wg, Wgg) at an axial point; W_c, W_gc, W_cc are zero there."""
    if form == STRUCTURAL:
        a = 1.0 + eps_ref
        rg = np.sqrt(g)
        return EA * (0.5 - 0.5 * a / rg), 0.25 * EA * a / (g * rg)
    return 0.5 * EA * (0.5 * (g - 1.0)), 0.25 * EA


@njit(cache=True, inline="always", fastmath={"contract"})
def _densities_bending(form, g, c, K_ref, E, I, I4):
    """(Wg, Wc, Wgg, Wgc, Wcc) at a bending point (same expressions as BE2D._densities)."""
    if form == STRUCTURAL:
        EI = E * I
        igb = 1.0 / g
        K = c * igb
        dK = K - K_ref
        igb2 = igb * igb
        return (-EI * dK * K * igb, EI * dK * igb, EI * (3 * K - 2 * K_ref) * K * igb2,
                -EI * (2 * K - K_ref) * igb2, EI * igb2)
    ig = 1.0 / g
    phi = (1.5 - 0.5 * ig) * ig
    phi1 = (-1.5 + ig) * ig**2
    phi2 = (3.0 - 3.0 * ig) * ig**3
    psi, psi1, psi2 = 0.25 * ig**4, -ig**5, 5.0 * ig**6
    c2 = c * c
    return (0.5 * E * (I * c2 * phi1 + I4 * c2 * c2 * psi1), E * (I * c * phi + 2 * I4 * c2 * c * psi),
            0.5 * E * (I * c2 * phi2 + I4 * c2 * c2 * psi2), E * (I * c * phi1 + 2 * I4 * c2 * c * psi1),
            E * (I * phi + 6 * I4 * c2 * psi))


@njit(cache=True, inline="always", fastmath={"contract"})
def _element(e, q0, q1, q2, q3, q4, q5, q6, q7, dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4, tangent,
             Ku, dg, dc):
    """Element ``e``'s forces ``dU/dq_e`` as eight scalars (x, y per Hermite function) and, if ``tangent``,
    the upper triangle of its stiffness in ``Ku`` (8, 8).

    The forces are accumulated in scalars, ``f_x,k = a_k u_x + b_k v_x`` with ``a_k, b_k`` the
    shape-function derivatives and ``u, v`` the point's coefficients (``dg = 2 a r'``,
    ``dc = (a r''_y - b r'_y, -a r''_x + b r'_x)``, the same sums regrouped): no per-point arrays are
    written or read back, which LLVM cannot keep in registers (numba gives it no aliasing facts).
    The tangent is ``W_gg dg dg^T + W_gc (dg dc^T + dc dg^T) + W_cc dc dc^T + W_g d2g + W_c d2c``
    with the constant Hessians d2g, d2c formed on the fly; it is symmetric, so its upper triangle
    is accumulated (mirrored by the caller).
    """
    f0 = f1 = f2 = f3 = f4 = f5 = f6 = f7 = 0.0
    if tangent:
        Ku[:] = 0.0
    for p in range(w.shape[1]):
        a0, a1, a2, a3 = dN[e, p, 0], dN[e, p, 1], dN[e, p, 2], dN[e, p, 3]
        r1x = a0 * q0 + a1 * q2 + a2 * q4 + a3 * q6
        r1y = a0 * q1 + a1 * q3 + a2 * q5 + a3 * q7
        g = r1x * r1x + r1y * r1y
        wp = w[e, p]
        axial = p < n_a
        if axial:   # W depends on g alone here: r'' and dc do not enter
            Wg, Wgg = _densities_axial(form, g, eps_ref[e, p], EA)
            Wc = Wgc = Wcc = 0.0
            wg = wp * Wg
            ux, uy = 2.0 * wg * r1x, 2.0 * wg * r1y
            f0 += a0 * ux
            f1 += a0 * uy
            f2 += a1 * ux
            f3 += a1 * uy
            f4 += a2 * ux
            f5 += a2 * uy
            f6 += a3 * ux
            f7 += a3 * uy
            r2x = r2y = 0.0
        else:
            b0, b1, b2, b3 = ddN[e, p, 0], ddN[e, p, 1], ddN[e, p, 2], ddN[e, p, 3]
            r2x = b0 * q0 + b1 * q2 + b2 * q4 + b3 * q6
            r2y = b0 * q1 + b1 * q3 + b2 * q5 + b3 * q7
            c = r1x * r2y - r1y * r2x
            Wg, Wc, Wgg, Wgc, Wcc = _densities_bending(form, g, c, K_ref[e, p], E, I, I4)
            wg, wc = wp * Wg, wp * Wc
            ux, uy = 2.0 * wg * r1x + wc * r2y, 2.0 * wg * r1y - wc * r2x
            vx, vy = -wc * r1y, wc * r1x
            f0 += a0 * ux + b0 * vx
            f1 += a0 * uy + b0 * vy
            f2 += a1 * ux + b1 * vx
            f3 += a1 * uy + b1 * vy
            f4 += a2 * ux + b2 * vx
            f5 += a2 * uy + b2 * vy
            f6 += a3 * ux + b3 * vx
            f7 += a3 * uy + b3 * vy
        if not tangent:
            continue
        for k in range(4):
            a = dN[e, p, k]
            dg[2 * k] = 2.0 * a * r1x
            dg[2 * k + 1] = 2.0 * a * r1y
            if not axial:   # dc = Sx^T P r'' + Sxx^T P^T r'
                b = ddN[e, p, k]
                dc[2 * k] = a * r2y - b * r1y
                dc[2 * k + 1] = -a * r2x + b * r1x
        wgg, wgc, wcc = wp * Wgg, wp * Wgc, wp * Wcc
        if axial:
            for i in range(8):
                bg = dg[i] * wgg
                for j in range(i, 8):
                    Ku[i, j] += bg * dg[j]
        else:
            for i in range(8):
                bg = dg[i] * wgg + dc[i] * wgc
                bc = dg[i] * wgc + dc[i] * wcc
                for j in range(i, 8):
                    Ku[i, j] += bg * dg[j] + bc * dc[j]
        # Constant Hessians: d2g = 2 dN_k dN_l delta_ab, d2c = dN_k ddN_l P_ab + ddN_k dN_l P_ba,
        # P = [[0, 1], [-1, 0]]; upper triangle only (rows 2k, 2k+1 <= columns 2m, 2m+1).
        for k in range(4):
            ak, bk = dN[e, p, k], ddN[e, p, k]
            for m in range(k, 4):
                am, bm = dN[e, p, m], ddN[e, p, m]
                hg = 2.0 * wg * ak * am
                Ku[2 * k, 2 * m] += hg
                Ku[2 * k + 1, 2 * m + 1] += hg
                if not axial:
                    hc = wc * (ak * bm - bk * am)
                    Ku[2 * k, 2 * m + 1] += hc
                    if m > k:
                        Ku[2 * k + 1, 2 * m] -= hc
    return f0, f1, f2, f3, f4, f5, f6, f7


@njit(cache=True, fastmath={"contract"})
def be2d_forces(q, dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4, tangent):
    """Element forces ``dU/dq_e`` (n_el, 8) and, if ``tangent``, stiffness (n_el, 8, 8).

    ``q`` (n_el, 8) element coordinates in the order (x, y) per Hermite
    function; ``dN``, ``ddN`` (n_el, n_pts, 4) shape-function derivatives at
    the axial points (the first ``n_a``) then the bending points; ``w``
    (n_el, n_pts) weights times the Jacobian ``L/2``. One element: :func:`_element`.
    """
    n_el = w.shape[0]
    f = np.empty((n_el, 8))
    K = np.empty((n_el, 8, 8) if tangent else (0, 8, 8))
    Ku, dg, dc = np.empty((8, 8)), np.empty(8), np.empty(8)
    for e in range(n_el):
        f[e, 0], f[e, 1], f[e, 2], f[e, 3], f[e, 4], f[e, 5], f[e, 6], f[e, 7] = _element(
            e, q[e, 0], q[e, 1], q[e, 2], q[e, 3], q[e, 4], q[e, 5], q[e, 6], q[e, 7],
            dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4, tangent, Ku, dg, dc)
        if tangent:
            for i in range(8):
                for j in range(i, 8):
                    K[e, i, j] = Ku[i, j]
                    K[e, j, i] = Ku[i, j]
    return f, K


@njit(cache=True, fastmath={"contract"})
def be2d_fused(q, q_fixed, gather, vec_slot, mat_slot, tangent, r, kdata,
               dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4):
    """Gather, kernel and scatter in one call (the fused assembly of :mod:`ancfdae.models.beam.assembly_numba`).

    ``r`` (length ``n_dof + 1``) receives the assembled ``dU/dq`` and, if
    ``tangent``, ``kdata`` (length ``nnz + 1``) the CSR data of its tangent;
    the last entry of each collects the fixed coordinates' share. Element by element, with no
    element arrays in between: each element's coordinates are read through ``gather`` and its
    forces (and tangent) added at their slots in element order, the additions of
    :func:`~ancfdae.models.beam.assembly_numba.scatter` in the same order (the same bits as
    :func:`be2d_forces` gathered and scattered).
    """
    nq = q.size
    r[:] = 0.0
    if tangent:
        kdata[:] = 0.0
    Ku, dg, dc = np.empty((8, 8)), np.empty(8), np.empty(8)
    qe = np.empty(8)
    for e in range(w.shape[0]):
        for k in range(8):
            g = gather[e, k]
            qe[k] = q[g] if g < nq else q_fixed[g - nq]
        fe = _element(e, qe[0], qe[1], qe[2], qe[3], qe[4], qe[5], qe[6], qe[7],
                      dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4, tangent, Ku, dg, dc)
        b = 8 * e
        r[vec_slot[b]] += fe[0]
        r[vec_slot[b + 1]] += fe[1]
        r[vec_slot[b + 2]] += fe[2]
        r[vec_slot[b + 3]] += fe[3]
        r[vec_slot[b + 4]] += fe[4]
        r[vec_slot[b + 5]] += fe[5]
        r[vec_slot[b + 6]] += fe[6]
        r[vec_slot[b + 7]] += fe[7]
        if tangent:
            b = 64 * e
            for i in range(8):
                for j in range(8):
                    kdata[mat_slot[b + 8 * i + j]] += Ku[i, j] if j >= i else Ku[j, i]


@njit(cache=True)
def be2d_alpha_iterations(x, r, err, max_k, contraction, threshold, lub, kl, ku, piv, qa0, va0, aa0, cqa, cva,
                          caa, lam, f_ext, q_fixed, gather, vec_slot, mat_slot, m_data, indptr, indices, rbuf,
                          kdata, dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4):
    """Newmark-family Newton iterations in one call (contract in :mod:`ancfdae.models.beam.iteration_numba`)."""
    if max_k == 0:   # the residual at x alone
        q, v, a = affine3(qa0, va0, aa0, cqa, cva, caa, x)
        be2d_fused(q, q_fixed, gather, vec_slot, mat_slot, False, rbuf, kdata,
                   dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4)
        return 0.0, alpha_finish(r, rbuf, m_data, indptr, indices, a, lam, f_ext), err, 0
    k = 0
    while True:
        q, v, a, dx_max = alpha_update(x, r, lub, kl, ku, piv, qa0, va0, aa0, cqa, cva, caa)
        k += 1
        if not np.isfinite(dx_max):
            return dx_max, err, err, k
        be2d_fused(q, q_fixed, gather, vec_slot, mat_slot, False, rbuf, kdata,
                   dN, ddN, w, eps_ref, K_ref, n_a, form, EA, E, I, I4)
        err_new = alpha_finish(r, rbuf, m_data, indptr, indices, a, lam, f_ext)
        if k >= max_k or not carry_on(err_new, err, threshold, contraction):
            return dx_max, err_new, err, k
        err = err_new


@njit(cache=True)
def be2d_alpha_steps(S, P, fpar, ipar, out, lub, piv, gravity, dead, scales, arrays, element_args):
    """Newmark-family steps in one call (contract in :mod:`ancfdae.integrators._alpha_steps_numba`)."""
    alpha_steps(be2d_alpha_iterations, S, P, fpar, ipar, out, lub, piv, gravity, dead, scales, arrays, element_args)


@njit(cache=True)
def be2d_static_newton(x, r, f_ext, fpar, ipar, flat, ab, piv, kdata, rbuf, arrays, element_args):
    """A load step's static full Newton in one call (contract in :mod:`ancfdae.models.beam.static_numba`)."""
    return static_newton(be2d_fused, x, r, f_ext, fpar, ipar, flat, ab, piv, kdata, rbuf, arrays, element_args)


@njit(cache=True)
def be2d_index3_steps(S, P, L, fpar, ipar, out, AB, piv, ABs, pivs, lub, bpiv, W, E, cons, rigid, beam, element_args,
                      kkt, T_rec, rec_q, rec_v, rec_a, rec_lam):
    """Index-3 steps of a System holding a BE2D beam in one call (contract in
    :mod:`ancfdae.integrators._index3_steps_numba`)."""
    index3_steps(be2d_fused, S, P, L, fpar, ipar, out, AB, piv, ABs, pivs, lub, bpiv, W, E, cons, rigid, beam,
                 element_args, kkt, T_rec, rec_q, rec_v, rec_a, rec_lam)


@njit(cache=True)
def be2d_multipliers(W, ext, q, v, a, lam, cons, rigid, beam, element_args, load_factor, kkt):
    """A System's ``(a, lam)`` at an output time in one call (:func:`ancfdae.integrators._index3_kkt_numba.system_multipliers`)."""
    work = multiplier_work(q.size, lam.size, beam[1], 2 * kkt[1] + kkt[2] + 1, cons[14].size)
    system_multipliers(be2d_fused, W, ext, q, v, a, lam, cons, rigid, beam, element_args, load_factor, kkt, work,
                       np.empty(0))
