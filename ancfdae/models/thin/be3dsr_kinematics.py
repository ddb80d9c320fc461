"""Kinematics of BE3DSR in NumPy: nodal frames, interior frames by smallest rotation, twist, curvatures, spin.

BE3DSR has BE3D's coordinates (per node ``r, r', theta``; chapter Eqs. 62, 101-103) and BE3D's nodal frames
(Eqs. 96-100 with the node's director ``d_X`` and angle ``theta_X``), but not its interior frames. Inside an
element BE3D turns the frame of the *interpolated director* by the *interpolated angle* (Sect. 3.6); a director
update therefore changes the interior frames, the strain and the kinetic energy (the energy jumps of the
chapter's Sect. 5.3). Here the interior frame is built from the two nodal frames and the axis alone:

* transport each nodal frame onto the local tangent ``t = r'/|r'|`` by the smallest rotation that takes the
  node's tangent ``u_X`` to ``t``: ``ebar2_X = e2_X - (t.e2_X)/(1 + u_X.t) (u_X + t)`` (and ``ebar3_X``
  likewise), defined unless the tangent turns by 180 degrees within the element;
* ``phi`` is the angle from ``ebar2_A`` to ``ebar2_B`` about ``t`` (the relative twist of the nodal frames);
  the frame at the point is ``ebar_A`` turned by ``S6 phi`` (``S5, S6`` of Eq. 102):
  ``e2 = cos(S6 phi) ebar2_A + sin(S6 phi) ebar3_A``, ``e3 = e1 x e2``; it equals the nodal frames at the
  nodes and is symmetric in A and B.

Twist and curvatures (Eq. 18, components along ``e_i``, per element coordinate xi)::

    k1 = phi / L + S5 tau_A + S6 tau_B,   tau_X = -u_X . (r' x r'') / (|r'|^2 (1 + u_X . t)),
    k2 = -r''. e3 / |r'|,                 k3 = r''. e2 / |r'|,

``tau_X`` being the twist of the transported frame. The spin of the cross-section about the axis::

    omega1 = S5 w_A + S6 w_B,   w_X = theta_dot_X + g_X . r'_dot_X + h_X . (r'_dot_X / |r'_X| + r'_dot / |r'|),
    g_X = (r'_X . d_X)(d_X x r'_X) / (|r'_X| |d_X x r'_X|^2),   h_X = (t x u_X) / (1 + u_X . t),

``theta_dot_X + g_X . r'_dot_X`` being the node's spin of BE3D. Every quantity depends on the nodal frames and
the axis only, so a change of a node's director that keeps its frame (the update of Sect. 3.6 with the angle
and its rate remapped) changes nothing: it is a change of chart, energy-neutral to round-off.

Each quantity is a jet over the 14 element coordinates (:mod:`ancfdae.models.jets.vector`), the operations in
the order of the compiled twin :mod:`.be3dsr_numba`.
"""
from __future__ import annotations

import numpy as np

from ..jets import vector as vj
from .be3d_kinematics import DOF, N_EDOF, TorsionRule

__all__ = ["PointData", "point_data", "nodal_frame", "transported", "curvatures", "spin_coefficients",
           "spin_vector"]

K = N_EDOF


class PointData:
    """The points of a :class:`~.be3d_kinematics.TorsionRule`, flattened over elements x points.

    Attributes
    ----------
    n_el, n_pts : int
    dN, ddN : (P, 4) the Hermite functions' derivatives (``r'``, ``r''`` at the point)
    S5, S6 : (P,) the linear functions of Eq. 102; L : (P,) the element length
    dA, dB : (P, 3) the element's nodal directors
    w : (P,) quadrature weights of ``dxi`` (zero for evaluation points)
    """

    def __init__(self, rule: TorsionRule, directors: np.ndarray, lengths: np.ndarray) -> None:
        n_el, n_pts = rule.wdx.shape
        self.n_el, self.n_pts = n_el, n_pts
        P = n_el * n_pts
        self.dN = rule.dN.reshape(P, 4)
        self.ddN = rule.ddN.reshape(P, 4)
        lin = np.broadcast_to(rule.lin[None], (n_el, n_pts, 2)).reshape(P, 2)
        self.S5, self.S6 = lin[:, 0].copy(), lin[:, 1].copy()
        self.L = np.repeat(lengths, n_pts)
        self.dA = np.repeat(directors[:-1], n_pts, axis=0)
        self.dB = np.repeat(directors[1:], n_pts, axis=0)
        self.w = rule.wdx.reshape(P)


def point_data(rule: TorsionRule, directors: np.ndarray, lengths: np.ndarray) -> PointData:
    """The :class:`PointData` of ``rule``."""
    return PointData(rule, directors, lengths)


def _hermite(q, N, order):
    """Jet of ``sum_k N_k q_(DOF[k])`` (``r'`` or ``r''``) over the element coordinates; ``q`` (P, 14)."""
    v = np.einsum("pk,pki->pi", N, q[:, DOF])
    g = h = None
    if order >= 1:
        g = np.zeros(v.shape + (K,))
        for k in range(4):
            g[:, np.arange(3), DOF[k]] = N[:, k, None]
    if order >= 2:
        h = np.zeros(v.shape + (K, K))
    return vj.Jet(v, g, h)


def _variable(q, first, d, order):
    return vj.variable(q, first, d, first, K, order) if d > 1 else _scalar_variable(q, first, order)


def _scalar_variable(q, i, order):
    P = q.shape[0]
    g = h = None
    if order >= 1:
        g = np.zeros((P, K))
        g[:, i] = 1.0
    if order >= 2:
        h = np.zeros((P, K, K))
    return vj.Jet(q[:, i].copy(), g, h)


def _unit(x, order):
    """``x / |x|`` and ``1/|x|``."""
    inv = vj.recip(vj.sqrt(vj.dot(x, x)))
    return vj.mul(inv, x, 1.0), inv


def nodal_frame(a: vj.Jet, theta: vj.Jet, d: np.ndarray, order: int) -> tuple:
    """``(u, e2, e3, 1/|a|, m, |m|^2)`` of a node (Eqs. 96-100); ``d`` the director (P, 3), ``m = d x a``."""
    u, inv = _unit(a, order)
    m = vj.cross(vj.constant(d, K, order), a)
    m2 = vj.dot(m, m)
    e20 = vj.mul(vj.recip(vj.sqrt(m2)), m, 1.0)
    e30 = vj.cross(u, e20)
    c = vj.chain(theta, np.cos(theta.v), -np.sin(theta.v), -np.cos(theta.v))
    s = vj.chain(theta, np.sin(theta.v), np.cos(theta.v), -np.sin(theta.v))
    e2 = vj.lin(1.0, vj.mul(c, e20, 1.0), 1.0, vj.mul(s, e30, 1.0))
    e3 = vj.lin(1.0, vj.mul(c, e30, 1.0), -1.0, vj.mul(s, e20, 1.0))
    return u, e2, e3, inv, m, m2


def transported(u: vj.Jet, e2: vj.Jet, e3: vj.Jet, t: vj.Jet, order: int) -> tuple:
    """``(ebar2, ebar3, 1/(1 + u.t))``: ``e2, e3`` turned by the smallest rotation taking ``u`` to ``t``."""
    one = vj.constant(np.ones(t.v.shape[0]), K, order)
    ic = vj.recip(vj.lin(1.0, vj.dot(u, t), 1.0, one))
    w = vj.lin(1.0, u, 1.0, t)
    eb2 = vj.lin(1.0, e2, -1.0, vj.mul(vj.mul(ic, vj.dot(t, e2), 1.0), w, 1.0))
    eb3 = vj.lin(1.0, e3, -1.0, vj.mul(vj.mul(ic, vj.dot(t, e3), 1.0), w, 1.0))
    return eb2, eb3, ic


def _common(pd: PointData, q: np.ndarray, order: int) -> dict:
    """The nodal frames, the tangent and the transports at the points (shared by strain and spin)."""
    qp = np.repeat(np.asarray(q, dtype=float), pd.n_pts, axis=0)
    a = _hermite(qp, pd.dN, order)
    out = {"a": a, "qp": qp}
    pa = vj.dot(a, a)
    ina = vj.recip(vj.sqrt(pa))
    out.update(pa=pa, ina=ina, t=vj.mul(ina, a, 1.0))
    for X, first, d in (("A", 3, pd.dA), ("B", 10, pd.dB)):
        aX = _variable(qp, first, 3, order)
        th = _scalar_variable(qp, first + 3, order)
        u, e2, e3, inv, m, m2 = nodal_frame(aX, th, d, order)
        eb2, eb3, ic = transported(u, e2, e3, out["t"], order)
        out[X] = dict(a=aX, u=u, inv=inv, m=m, m2=m2, d=d, eb2=eb2, eb3=eb3, ic=ic)
    return out


def curvatures(pd: PointData, q: np.ndarray, order: int = 2) -> tuple[vj.Jet, vj.Jet, vj.Jet]:
    """Jets of the twist ``k1`` and the curvatures ``k2, k3`` (module docstring) at the points, shape (P,)."""
    c = _common(pd, q, order)
    A, B = c["A"], c["B"]
    qp = c["qp"]
    b = _hermite(qp, pd.ddN, order)
    phi = vj.atan2(vj.dot(A["eb3"], B["eb2"]), vj.dot(A["eb2"], B["eb2"]))
    al = vj.lin(pd.S6, phi, 0.0, phi)
    ca = vj.chain(al, np.cos(al.v), -np.sin(al.v), -np.cos(al.v))
    sa = vj.chain(al, np.sin(al.v), np.cos(al.v), -np.sin(al.v))
    e2 = vj.lin(1.0, vj.mul(ca, A["eb2"], 1.0), 1.0, vj.mul(sa, A["eb3"], 1.0))
    e3 = vj.lin(1.0, vj.mul(ca, A["eb3"], 1.0), -1.0, vj.mul(sa, A["eb2"], 1.0))
    k3 = vj.mul(c["ina"], vj.dot(b, e2), 1.0)
    k2 = vj.mul(c["ina"], vj.dot(b, e3), -1.0)
    axb = vj.cross(c["a"], b)
    ipa = vj.recip(c["pa"])
    tau = [vj.mul(vj.mul(ipa, X["ic"], 1.0), vj.dot(X["u"], axb), -1.0) for X in (A, B)]
    k1 = vj.lin(1.0 / pd.L, phi, 1.0, vj.lin(pd.S5, tau[0], pd.S6, tau[1]))
    return k1, k2, k3


def spin_vector(pd: PointData, q: np.ndarray, order: int = 2) -> tuple:
    """Per node X the jets ``(c_X, ch_X)`` of the 3-vectors multiplying ``r'_dot_X`` and ``r'_dot`` in ``w_X``.

    ``c_X = g_X + h_X / |r'_X|``, ``ch_X = h_X / |r'|`` (module docstring); the angle rates enter with 1.
    """
    c = _common(pd, q, order)
    out = []
    for X in (c["A"], c["B"]):
        ad = vj.dot(X["a"], vj.constant(X["d"], K, order))
        coef = vj.mul(ad, vj.recip(vj.mul(vj.recip(X["inv"]), X["m2"], 1.0)), 1.0)
        g = vj.mul(coef, X["m"], 1.0)
        h = vj.mul(X["ic"], vj.cross(c["t"], X["u"]), 1.0)
        out.append((vj.lin(1.0, g, 1.0, vj.mul(X["inv"], h, 1.0)), vj.mul(c["ina"], h, 1.0)))
    return out


def spin_coefficients(pd: PointData, q: np.ndarray, order: int = 2) -> tuple:
    """``omega1 = c . v`` at the points: ``c`` (P, 14), ``C = dc/dq`` (P, 14, 14), ``Hc`` (P, 14, 14, 14) or None.

    ``order`` is the highest derivative of ``c`` returned (0, 1 or 2).
    """
    P = pd.w.size
    (cA, hA), (cB, hB) = spin_vector(pd, q, order)
    c = np.zeros((P, K))
    C = np.zeros((P, K, K)) if order >= 1 else None
    Hc = np.zeros((P, K, K, K)) if order >= 2 else None
    for S, cX, first, theta in ((pd.S5, cA, 3, 6), (pd.S6, cB, 10, 13)):
        c[:, theta] += S
        c[:, first:first + 3] += S[:, None] * cX.v
        if order >= 1:
            C[:, first:first + 3] += S[:, None, None] * cX.g
        if order >= 2:
            Hc[:, first:first + 3] += S[:, None, None, None] * cX.h
    ch = vj.lin(pd.S5, hA, pd.S6, hB)          # the coefficient of r'_dot = sum_k dN_k r_dot_(DOF[k])
    for k in range(4):
        for i in range(3):
            n = DOF[k, i]
            c[:, n] += pd.dN[:, k] * ch.v[:, i]
            if order >= 1:
                C[:, n] += pd.dN[:, k, None] * ch.g[:, i]
            if order >= 2:
                Hc[:, n] += pd.dN[:, k, None, None] * ch.h[:, i]
    return c, C, Hc
