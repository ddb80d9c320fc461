"""The rotary inertia of a thin beam from its spin coefficients, in NumPy (chapter Sects. 2.2, 3.5).

A thin spatial beam with torsion (BE3D, BE3DSR) has the kinetic energy of its axis (constant mass matrix,
Eq. 27) plus that of the cross-section spinning about the axis, ``T_rot = 1/2 int rho J omega1^2 dxi``. The
spin is linear in the velocities, ``omega1 = c(q) . v``, with a coefficient vector ``c`` that depends on the
configuration; at the quadrature points ``p`` (weights ``W_p = rho J w_p``)::

    T_rot = 1/2 v^T M_rot(q) v,   M_rot(q) = sum_p W_p c_p c_p^T.

With ``C = dc/dq`` (``C[i, k] = dc_i/dq_k``) Lagrange's equations give the inertia force
``f = d/dt (dT/dv) - dT/dq``::

    f = sum_p W_p [ c Omega + omega1 (C - C^T) v ],   Omega = c . a + v^T C v    (= d omega1/dt),

and its exact derivatives need ``Hc = d2c/dq2``. This module works from ``(c, C, Hc)`` at the points, whatever
the element: BE3D (``c = N_theta + B_a^T g(r')``) and BE3DSR (:mod:`.be3dsr_kinematics`) supply them. Besides
the force it gives ``B = 1/2 u^T M_rot(q) w`` with its q-gradient and Hessian for fixed ``u, w``: the
energy-momentum integrator's discrete gradient of the kinetic energy (:mod:`ancfdae.integrators.energy_momentum`)
needs them. The compiled twin is :mod:`.rotary_numba`.
"""
from __future__ import annotations

import numpy as np

__all__ = ["rotary_inertia", "rotary_kinetic_energy", "mass_bilinear"]


def _sum(x, n_el, n_pts):
    """Per-point rows (P, ...) summed over the points of each element: (n_el, ...)."""
    return x.reshape((n_el, n_pts) + x.shape[1:]).sum(axis=1)


def _outer(x, y):
    return x[:, :, None] * y[:, None, :]


def rotary_kinetic_energy(W, c, v, n_pts):
    """``1/2 sum_p W_p (c_p . v)^2`` per element; ``W`` (P,), ``c`` (P, n), ``v`` (n_el, n)."""
    om = np.einsum("pn,pn->p", c, np.repeat(v, n_pts, axis=0))
    return _sum(0.5 * W * om * om, v.shape[0], n_pts)


def rotary_inertia(W, c, C, Hc, v, acc, n_pts, tangent=True):
    """Force ``f`` (n_el, n) and, if ``tangent``, ``df/dq``, ``df/dv``, ``df/da`` (n_el, n, n); module docstring.

    ``Hc`` is needed only with ``tangent``.
    """
    n_el = v.shape[0]
    vp, ap = np.repeat(v, n_pts, axis=0), np.repeat(acc, n_pts, axis=0)
    om = np.einsum("pn,pn->p", c, vp)
    Cv = np.einsum("pik,pk->pi", C, vp)
    CTv = np.einsum("pik,pi->pk", C, vp)                       # d omega1 / dq
    Om = np.einsum("pn,pn->p", c, ap) + np.einsum("pi,pi->p", vp, Cv)
    skew = Cv - CTv
    f = _sum(W[:, None] * (c * Om[:, None] + om[:, None] * skew), n_el, n_pts)
    if not tangent:
        return f, None, None, None
    Wm = W[:, None, None]
    dfda = _sum(Wm * _outer(c, c), n_el, n_pts)
    dfdv = _sum(Wm * (_outer(c, Cv + CTv) + _outer(skew, c) + om[:, None, None] * (C - np.swapaxes(C, 1, 2))),
                n_el, n_pts)
    HCv = np.einsum("pikl,pk->pil", Hc, vp)                    # d (C v)_i / dq_l
    HCTv = np.einsum("pikl,pi->pkl", Hc, vp)                   # d (C^T v)_k / dq_l
    dOm = np.einsum("pil,pi->pl", C, ap) + np.einsum("pi,pil->pl", vp, HCv)
    dfdq = _sum(Wm * (C * Om[:, None, None] + _outer(c, dOm) + _outer(skew, CTv)
                      + om[:, None, None] * (HCv - HCTv)), n_el, n_pts)
    return f, dfdq, dfdv, dfda


def mass_bilinear(W, c, C, Hc, u, w, n_pts, order=2):
    """``B = 1/2 u^T M_rot(q) w`` per element and, by ``order``, its q-gradient (n_el, n) and Hessian (n_el, n, n).

    ``u, w`` (n_el, n) are held fixed: ``dB/dq = 1/2 sum_p W_p [(c.w) C^T u + (c.u) C^T w]`` and
    ``d2B/dq2 = 1/2 sum_p W_p [C^T u (C^T w)^T + C^T w (C^T u)^T + (c.w) Hc.u + (c.u) Hc.w]``.
    """
    n_el = u.shape[0]
    up, wp = np.repeat(u, n_pts, axis=0), np.repeat(w, n_pts, axis=0)
    cu, cw = np.einsum("pn,pn->p", c, up), np.einsum("pn,pn->p", c, wp)
    out = [_sum(0.5 * W * cu * cw, n_el, n_pts)]
    if order >= 1:
        Ctu, Ctw = np.einsum("pik,pi->pk", C, up), np.einsum("pik,pi->pk", C, wp)
        out.append(_sum(0.5 * W[:, None] * (cw[:, None] * Ctu + cu[:, None] * Ctw), n_el, n_pts))
    if order >= 2:
        Hu, Hw = np.einsum("pikl,pi->pkl", Hc, up), np.einsum("pikl,pi->pkl", Hc, wp)
        out.append(_sum(0.5 * W[:, None, None] * (_outer(Ctu, Ctw) + _outer(Ctw, Ctu) + cw[:, None, None] * Hu
                                                 + cu[:, None, None] * Hw), n_el, n_pts))
    return tuple(out)
