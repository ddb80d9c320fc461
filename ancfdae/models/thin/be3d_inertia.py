"""BE3D's configuration-dependent inertia in NumPy: the rotary inertia about the axis (chapter Sects. 2.2, 3.5).

Kinetic energy and inertia forces
---------------------------------
The kinetic energy of the thin beam is that of its axis plus the spin of the
cross-section about the axis (the bending rotary inertia ``rho I2, rho I3`` is
neglected, as in every Bernoulli-Euler ANCF element)::

    T = 1/2 int rho A |r_dot|^2 dxi  +  1/2 int rho J omega1^2 dxi,
    omega1 = omega . e1 = theta_dot + g(r') . r'_dot,
    g(a)   = (a.d) (d x a) / (|a| |d x a|^2)               (d: director).

``omega1 = e2_dot . e3`` follows from Eqs. 96-100 exactly like the twist
``k1`` (see :mod:`.be3d_kinematics`), with the director constant in time
between updates. With the element coordinates ``q`` and, at a point,
``a = Ba q``, ``theta = Nt q``, the spin is linear in the velocities,
``omega1 = w(q) . v`` with ``w = Nt + Ba^T g(a)``, so

    T_rot = 1/2 v^T M_rot(q) v,    M_rot(q) = int rho J w w^T dxi.

Lagrange's equations ``d/dt dT/dv - dT/dq`` give the rotary inertia force
(``G = dg/da``, ``a_dot = Ba v``, ``a_ddot = Ba a``)::

    f_rot = int rho J [ w Omega + omega1 Ba^T (G - G^T) a_dot ] dxi,
    Omega = omega1_dot = w . a_acc + a_dot^T G a_dot,

i.e. ``M_rot(q) a`` plus velocity-quadratic (gyroscopic) terms. Because the
semi-discrete equations derive from the Lagrangian ``T - U`` (both evaluated
with the same quadrature rules), ``d/dt (T + U) = v . f_ext``: the model
conserves energy between director updates. The Jacobian blocks need ``H =
d2g/da2`` and are exact (jets).
"""
from __future__ import annotations

import numpy as np

from .be3d_kinematics import director_field, spin_coefficients, spin_gradient
from .rotary import mass_bilinear

__all__ = ["rotary_inertia", "rotary_kinetic_energy", "rotary_bilinear"]


def _spin_parts(rule, geom, q, order):
    a = np.einsum("epin,en->epi", rule.Ba, q)
    d, _ = director_field(geom["directors"], rule)
    if order >= 2:
        gj = spin_coefficients(a, d, 2)
        g = np.stack([j.v for j in gj], axis=-1)              # (n_el, n_pts, 3)
        G = np.stack([j.g for j in gj], axis=-2)              # (..., 3, 3): G[i, k] = dg_i/da_k
        H = np.stack([j.h for j in gj], axis=-3)              # (..., 3, 3, 3)
    else:
        (g, G), H = spin_gradient(a, d), None
    w = rule.Nt + np.einsum("epin,epi->epn", rule.Ba, g)      # omega1 = w . v
    return a, g, G, H, w


def rotary_kinetic_energy(rule, geom, q, v, rhoJ):
    """``1/2 int rho J omega1^2 dxi`` per element, shape (n_el,)."""
    *_, w = _spin_parts(rule, geom, q, 1)
    om = np.einsum("epn,en->ep", w, v)
    return 0.5 * rhoJ * np.sum(rule.wdx * om**2, axis=1)


def rotary_inertia(rule, geom, q, v, acc, rhoJ, tangent=True):
    """Rotary inertia force ``f_rot`` and, if asked, ``df/dq``, ``df/dv``, ``df/da`` (module docstring)."""
    a, g, G, H, w = _spin_parts(rule, geom, q, 2 if tangent else 1)
    Ba = rule.Ba
    ad = np.einsum("epin,en->epi", Ba, v)                     # a_dot
    om = np.einsum("epn,en->ep", w, v)                        # omega1
    Gad = np.einsum("...ik,...k->...i", G, ad)
    Om = np.einsum("epn,en->ep", w, acc) + np.einsum("...i,...i", ad, Gad)
    Aad = Gad - np.einsum("...ki,...k->...i", G, ad)          # (G - G^T) a_dot
    c = np.einsum("epin,epi->epn", Ba, Aad)
    W = rhoJ * rule.wdx
    f = np.einsum("ep,epn->en", W, w * Om[..., None] + om[..., None] * c)
    if not tangent:
        return f, None, None, None
    outer = lambda x, y: x[..., :, None] * y[..., None, :]   # noqa: E731
    Wm = W[..., None, None]
    dfda = np.sum(Wm * outer(w, w), axis=1)
    GGt = G + np.swapaxes(G, -1, -2)
    GmGt = G - np.swapaxes(G, -1, -2)
    BaT = np.swapaxes(Ba, -1, -2)
    sym = np.einsum("epin,epi->epn", Ba, np.einsum("...ik,...k->...i", GGt, ad))
    dfdv = np.sum(Wm * (outer(w, sym) + outer(c, w) + om[..., None, None] * (BaT @ GmGt @ Ba)), axis=1)
    add = np.einsum("epin,en->epi", Ba, acc)                  # a_ddot
    T1 = np.einsum("...i,...ijk,...j->...k", ad, H, ad)
    dOm = np.einsum("epin,epi->epn", Ba, np.einsum("...ik,...i->...k", G, add) + T1)
    dom = np.einsum("epin,epi->epn", Ba, np.einsum("...ik,...i->...k", G, ad))
    A2 = np.einsum("...ijk,...j->...ik", H, ad) - np.einsum("...jik,...j->...ik", H, ad)
    dfdq = np.sum(Wm * ((BaT @ G @ Ba) * Om[..., None, None] + outer(w, dOm) + outer(c, dom)
                        + om[..., None, None] * (BaT @ A2 @ Ba)), axis=1)
    return f, dfdq, dfdv, dfda


def rotary_bilinear(rule, geom, q, u, w, rhoJ, order=2):
    """``1/2 u^T M_rot(q) w`` per element and, by ``order``, its q-gradient and Hessian (``u, w`` fixed).

    ``omega1 = c(q) . v`` with ``c = N_theta + Sx^T g(r')``, so ``C = dc/dq = Sx^T G Sx`` and
    ``d2c/dq2 = Sx^T H Sx Sx`` (``G, H`` the first and second derivatives of ``g``); the forms of
    :func:`.rotary.mass_bilinear` (the energy-momentum integrator's discrete gradient of ``T``).
    """
    _, _, G, H, c = _spin_parts(rule, geom, q, 2 if order >= 2 else 1)
    Ba = rule.Ba
    n_el, n_pts = rule.wdx.shape
    P, n = n_el * n_pts, Ba.shape[-1]
    C = np.einsum("epin,epik,epkm->epnm", Ba, G, Ba).reshape(P, n, n)
    Hc = (np.einsum("epin,epikl,epkm,eplr->epnmr", Ba, H, Ba, Ba).reshape(P, n, n, n) if order >= 2 else None)
    return mass_bilinear((rhoJ * rule.wdx).reshape(P), c.reshape(P, n), C, Hc, u, w, n_pts, order)
