"""Kinematics of BE3D: its coordinate layout, point rules, cross-section frame, curvature and twist, spin.

Element coordinates (Eqs. 62, 101-103): per node ``(r, r', theta)``, the axis
by cubic Hermite functions and the torsion angle linearly; a
:class:`TorsionRule` evaluates both at the points of a Gauss rule.

Everything is written in the slope ``a = r'`` and its derivative ``b = r''``
(per the element coordinate xi), the torsion angle ``theta`` and its
derivative ``theta'``, and the interpolated director ``d`` with its
derivative ``d'`` (chapter Sect. 3.6, linear in xi, constant between director
updates). With ``p = a.a``, ``m = d x a``, ``m2 = |m|^2``:

* Frame (Eqs. 96-100): ``e1 = a/|a|``, ``e20 = m/|m|``,
  ``e30 = e1 x e20 = (p d - (a.d) a) / (|a| |m|)``, and ``e2, e3`` turned by
  ``theta`` about ``e1`` (Eqs. 97-98).
* Curvature vector components ``k_i`` along ``e_i`` (Eqs. 18-20, per xi)::

      k1 = e2'.e3 = theta' - tau0,   tau0 = (p d'.m - (a.d) b.m) / (|a| m2)
      k2 = e3'.e1 = s X - c Y,       k3 = e1'.e2 = c X + s Y,
      X  = b.e20 / |a| = b.m / (|a| |m|),
      Y  = b.e30 / |a| = (p b.d - (a.b)(a.d)) / (p |m|),   c, s = cos, sin theta.

  ``tau0`` is the twist of the director frame ``(e1, e20, e30)``; ``k1`` has
  no shear part because ``e1`` follows ``r'`` (zero shear, Sect. 3.5).
* Spin about the axis (``omega . e1``, the same formula with time instead of
  xi and ``d' -> d_dot = 0``)::

      omega1 = theta_dot + g(a) . a_dot,   g(a) = (a.d) m / (|a| m2).

All quantities are returned as :class:`~ancfdae.models.jets.scalar.Jet` objects with
exact derivatives with respect to the local variables.
"""
from __future__ import annotations

import numpy as np

from ..jets import scalar as jet
from ..jets.scalar import Jet
from ..shapes import linear
from .spatial import PointRule

__all__ = ["DOF", "THETA", "N_EDOF", "TorsionRule", "local_variables", "curvatures", "curvature_energy", "spin_coefficients",
           "spin_gradient", "frames", "director_field", "cross", "EPS"]

# Per element: r_A 0:3, r'_A 3:6, theta_A 6, r_B 7:10, r'_B 10:13, theta_B 13.
DOF = np.array([[0, 1, 2], [3, 4, 5], [7, 8, 9], [10, 11, 12]])   # Hermite vector k, component i
THETA = np.array([6, 13])                                          # the angle at A and B
N_EDOF = 14

# Levi-Civita symbol: (u x v)_i = EPS[i, j, k] u_j v_k
EPS = np.zeros((3, 3, 3))
EPS[0, 1, 2] = EPS[1, 2, 0] = EPS[2, 0, 1] = 1.0
EPS[0, 2, 1] = EPS[2, 1, 0] = EPS[1, 0, 2] = -1.0


class TorsionRule(PointRule):
    """A Gauss rule (or given points) of BE3D: the axis operators of :class:`.spatial.PointRule` plus the
    linear interpolation of the angle and the director (Eqs. 101-103, Sect. 3.6).

    Attributes
    ----------
    theta : (2,) the element coordinates of the angle; Nt, dNt : (n_el, n_pts, 14) rows giving ``theta``
    and ``theta'``; lin : (n_pts, 2) the linear functions ``(S5, S6)``; L : (n_el,) element lengths;
    Bx : (n_el, n_pts, 8, 14) the map to the local variables ``(r', r'', theta, theta')``.
    """

    def __init__(self, n_points, lengths: np.ndarray):
        super().__init__(n_points, lengths, DOF, N_EDOF)
        N, dN = linear(self.s, lengths)
        self.theta = THETA
        self.Nt = np.zeros(N.shape[:2] + (N_EDOF,))
        self.Nt[..., THETA] = N
        self.dNt = np.zeros(N.shape[:2] + (N_EDOF,))
        self.dNt[..., THETA] = dN
        self.lin = N[0]
        self.L = lengths
        self.Bx = np.concatenate([self.Ba, self.Bb, self.Nt[:, :, None, :], self.dNt[:, :, None, :]], axis=2)


def cross(u, v):
    """``u x v`` over the last axis (np.cross costs several times more on small batches)."""
    u0, u1, u2 = u[..., 0], u[..., 1], u[..., 2]
    v0, v1, v2 = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0], axis=-1)


def _dot(u, v):
    return u[..., 0] * v[..., 0] + u[..., 1] * v[..., 1] + u[..., 2] * v[..., 2]


def _jet(v, n, order, grads, hess=()):
    """Build a jet from its value and sparse gradient/Hessian blocks ``(slice, array)``."""
    g = np.zeros(v.shape + (n,))
    for sl, val in grads:
        g[..., sl] = val
    h = None
    if order >= 2:
        h = np.zeros(v.shape + (n, n))
        for (si, sj), val in hess:
            h[..., si, sj] = val
    return Jet(v, g, h)


def _invariants(a, b, d, dp, n, order, with_b=True):
    """Polynomial invariants as jets over ``(a[, b, theta, theta'])`` (variables a: 0:3, b: 3:6)."""
    A, B = slice(0, 3), slice(3, 6)
    I = np.eye(3)
    dot = _dot
    dd = dot(d, d)
    ad = dot(a, d)
    m = cross(d, a)
    out = {
        "p": _jet(dot(a, a), n, order, [(A, 2.0 * a)], [((A, A), 2.0 * I)]),
        "ad": _jet(ad, n, order, [(A, d)]),
        "m2": _jet(dot(m, m), n, order, [(A, 2.0 * (dd[..., None] * a - ad[..., None] * d))],
                   [((A, A), 2.0 * (dd[..., None, None] * I - d[..., :, None] * d[..., None, :]))]),
    }
    if with_b:
        # b.(d x a) = a.(b x d); d2/(da_i db_j) = (e_j x d)_i = EPS[i, j, k] d_k
        Hab = np.einsum("ijk,...k->...ij", EPS, d)
        out["ab"] = _jet(dot(a, b), n, order, [(A, b), (B, a)], [((A, B), I), ((B, A), I)])
        out["bd"] = _jet(dot(b, d), n, order, [(B, d)])
        out["t"] = _jet(dot(b, m), n, order, [(A, cross(b, d)), (B, m)],
                        [((A, B), Hab), ((B, A), np.swapaxes(Hab, -1, -2))])
        out["tp"] = _jet(dot(dp, m), n, order, [(A, cross(dp, d))])
    return out


def curvatures(a, b, theta, dtheta, d, dp, order=2):
    """Twist and curvatures ``(k1, k2, k3)`` per xi as jets over ``(a, b, theta, theta')`` (8 variables).

    Parameters
    ----------
    a, b : (..., 3) slope ``r'`` and ``r''``; theta, dtheta : (...,) angle and
    its xi-derivative; d, dp : (..., 3) director and its xi-derivative.
    """
    n = 8
    inv = _invariants(a, b, d, dp, n, order)
    p, ad, m2, ab, bd, t, tp = (inv[k] for k in ("p", "ad", "m2", "ab", "bd", "t", "tp"))
    th = _jet(theta, n, order, [(6, 1.0)])
    thp = _jet(dtheta, n, order, [(7, 1.0)])
    sp = jet.sqrt(p)
    sm = jet.sqrt(m2)
    X = t / (sm * sp)
    Y = (bd * p - ab * ad) / (p * sm)
    tau0 = (p * tp - ad * t) / (sp * m2)
    c, s = jet.cos(th), jet.sin(th)
    return thp - tau0, s * X - c * Y, c * X + s * Y


def curvature_energy(a, b, theta, dtheta, d, dp, k_ref, stiffness):
    """Bending-torsion energy density and its gradient, by the chain rule written out (residual path).

    ``W = 1/2 sum_i C_i (k_i - k_ref_i)^2`` (``C = stiffness``) with the ``k_i`` of
    :func:`curvatures`; the gradient is with respect to ``(a, b, theta,
    theta')``, shape (..., 8). Same values as the jets of :func:`curvatures`
    (the tests compare the two), a few times fewer array operations.
    """
    dot = _dot
    p, ad, ab, bd = dot(a, a), dot(a, d), dot(a, b), dot(b, d)
    m = cross(d, a)
    m2, t, tp = dot(m, m), dot(b, m), dot(dp, m)
    sp, sm = np.sqrt(p), np.sqrt(m2)
    X = t / (sm * sp)
    Yn = bd * p - ab * ad
    Y = Yn / (p * sm)
    tau0 = (p * tp - ad * t) / (sp * m2)
    c, s = np.cos(theta), np.sin(theta)
    k1, k2, k3 = dtheta - tau0, s * X - c * Y, c * X + s * Y
    r1, r2, r3 = (stiffness[0] * (k1 - k_ref[..., 0]), stiffness[1] * (k2 - k_ref[..., 1]),
                  stiffness[2] * (k3 - k_ref[..., 2]))
    W = 0.5 * (r1 * (k1 - k_ref[..., 0]) + r2 * (k2 - k_ref[..., 1]) + r3 * (k3 - k_ref[..., 2]))
    WX, WY, Wtau = r3 * c + r2 * s, r3 * s - r2 * c, -r1
    # partial derivatives of W through X, Y, tau0 with respect to the invariants
    W_t = WX / (sm * sp) - Wtau * ad / (sp * m2)
    W_p = -WX * X / (2 * p) + WY * (bd / (p * sm) - Y / p) + Wtau * (tp / (sp * m2) - tau0 / (2 * p))
    W_m2 = -(WX * X + WY * Y) / (2 * m2) - Wtau * tau0 / m2
    W_ad = -WY * ab / (p * sm) - Wtau * t / (sp * m2)
    W_ab = -WY * ad / (p * sm)
    W_bd = WY / sm
    W_tp = Wtau * sp / m2
    dd = dot(d, d)
    e = lambda x: x[..., None]   # noqa: E731
    ga = (e(2 * W_p + 2 * dd * W_m2) * a + e(W_ad - 2 * ad * W_m2) * d + e(W_ab) * b
          + e(W_t) * cross(b, d) + e(W_tp) * cross(dp, d))
    gb = e(W_ab) * a + e(W_bd) * d + e(W_t) * m
    grad = np.concatenate([ga, gb, e(r2 * k3 - r3 * k2), e(r1)], axis=-1)
    return W, grad


def spin_gradient(a, d):
    """``g(a)`` of :func:`spin_coefficients` and ``G = dg/da`` (shape (..., 3, 3)) without jets."""
    dot = _dot
    p, ad = dot(a, a), dot(a, d)
    m = cross(d, a)
    m2 = dot(m, m)
    sp = np.sqrt(p)
    coef = ad / (sp * m2)
    dcoef = (d / (sp * m2)[..., None] - (coef / p)[..., None] * a
             - (coef / m2)[..., None] * (2 * dot(d, d)[..., None] * a - 2 * ad[..., None] * d))
    dm = np.einsum("jlk,...l->...jk", EPS, d)
    g = coef[..., None] * m
    G = coef[..., None, None] * dm + m[..., :, None] * dcoef[..., None, :]
    return g, G


def spin_coefficients(a, d, order=2):
    """The vector ``g(a) = (a.d)(d x a) / (|a| |d x a|^2)`` of ``omega1 = theta_dot + g . a_dot``.

    Returns three jets over ``a`` (3 variables): ``G = dg/da`` are their
    gradients and ``H = d2g/da2`` their Hessians.
    """
    inv = _invariants(a, None, d, None, 3, order, with_b=False)
    p, ad, m2 = inv["p"], inv["ad"], inv["m2"]
    coef = ad / (jet.sqrt(p) * m2)
    m = cross(d, a)
    # d(d x a)_j / da_k = EPS[j, l, k] d_l
    dm = np.einsum("jlk,...l->...jk", EPS, d)
    zero = np.zeros(a.shape[:-1] + (3, 3)) if order >= 2 else None
    return [coef * Jet(m[..., j], dm[..., j, :], zero) for j in range(3)]


def frames(a, theta, d):
    """Cross-section frames (Eqs. 96-100), shape (..., 3, 3) with columns ``(e1, e2, e3)``.

    Also returns ``n = |d x e1| / |d|``, the sine of the angle between
    director and axis (the projection of Eq. 99 is singular at ``n = 0``).
    """
    e1 = a / np.linalg.norm(a, axis=-1, keepdims=True)
    u = cross(d, e1)
    nu = np.linalg.norm(u, axis=-1, keepdims=True)
    e20 = u / nu
    e30 = cross(e1, e20)
    c, s = np.cos(theta)[..., None], np.sin(theta)[..., None]
    e2 = c * e20 + s * e30
    e3 = c * e30 - s * e20
    return np.stack([e1, e2, e3], axis=-1), nu[..., 0] / np.linalg.norm(d, axis=-1)


def director_field(directors, rule):
    """Director ``d = S5 d_A + S6 d_B`` and ``d' = (d_B - d_A) / L`` at a rule's points (Sect. 3.6).

    ``directors`` has shape (n_el + 1, 3) (global nodes along the beam);
    ``rule.lin`` holds ``(S5, S6)`` at the points, shape (n_pts, 2), and
    ``rule.L`` the element lengths. Returns ``d`` (n_el, n_pts, 3) and
    ``d'`` (n_el, 1, 3).
    """
    dA, dB = directors[:-1], directors[1:]
    d = rule.lin[None, :, 0, None] * dA[:, None, :] + rule.lin[None, :, 1, None] * dB[:, None, :]
    dp = ((dB - dA) / rule.L[:, None])[:, None, :]
    return d, dp


def local_variables(directors, q, rule):
    """``(a, b, theta, theta', d, d')`` at the points of a :class:`TorsionRule`: slope ``r'``, its derivative
    ``r''``, the angle and its derivative, the director and its derivative (shapes (n_el, n_pts[, 3]))."""
    d, dp = director_field(directors, rule)
    a = np.einsum("epin,en->epi", rule.Ba, q)
    b = np.einsum("epin,en->epi", rule.Bb, q)
    th = np.einsum("epn,en->ep", rule.Nt, q)
    dth = np.einsum("epn,en->ep", rule.dNt, q)
    return a, b, th, dth, d, np.broadcast_to(dp, d.shape)
