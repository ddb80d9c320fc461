"""BE2D: the planar Bernoulli-Euler ANCF beam element (chapter Sects. 3.1-3.3).

Two nodes with coordinates ``(x, y, x', y')`` -- position and axial slope --
and the cubic Hermite interpolation of chapter Eq. 60, 8 DOF per element.

Both formulations are written as an energy density in the two invariants of
the axis at a quadrature point, ``g = r'.r'`` and ``c = (r' x r'').e_z``:
``|r'| = sqrt(g)`` and the material curvature ``K = c / g`` (Eq. 70). Since
``g`` and ``c`` are quadratic forms in the element coordinates, their
Hessians are constant (the NumPy reference stores them at its first use,
:func:`reference_terms`; the compiled kernel forms them on the fly); the force is
``W_g dg + W_c dc`` and the tangent
``W_gg dg dg^T + W_gc (dg dc^T + dc dg^T) + W_cc dc dc^T + W_g d2g + W_c d2c``,
exact, for all elements and points in a few ``einsum`` calls.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..._quadrature import gauss
from ..._validate import choice, positive_int
from ...materials import CircularSection, Material, RectangularSection
from ..element import Element, Kernel
from ..shapes import hermite

__all__ = ["BE2D", "BE2DReference", "invariants", "densities"]

__all__ = ["BE2D"]

# (r' x r'').e_z = r'^T P r''
_P = np.array([[0.0, 1.0], [-1.0, 0.0]])


def _expand2(N: np.ndarray) -> np.ndarray:
    """Scalar shape functions (..., 4) -> interpolation matrices (..., 2, 8), dof order (x, y) per function."""
    out = np.zeros(N.shape[:-1] + (2, 8))
    out[..., 0, 0::2] = N
    out[..., 1, 1::2] = N
    return out



def reference_terms(geom: dict) -> tuple:
    """``(dN, ddN, d2)``: the NumPy reference's own arrays, made at its first use and kept in ``geom``.

    ``dN``, ``ddN`` (4, 1, n_el, n_pts): the shape-function derivatives points-last, and ``d2``
    (n_el, 2 n_pts, 64): the constant Hessians of ``g = r'.r'`` and ``c = (r' x r'').e_z``,
    ``d2g[k, a, l, b] = 2 N'_k N'_l delta_ab``, ``d2c[k, a, l, b] = N'_k N''_l P_ab + N''_k N'_l P_ba``
    (``P_01 = 1``, ``P_10 = -1``), written block by block (no temporaries of its size). The compiled
    kernel forms the Hessians on the fly, so a beam that never calls the reference does not store them
    (7.2 GB at 10^6 elements).
    """
    terms = geom.get("_reference")
    if terms is None:
        dN, ddN = geom["dN_e"], geom["ddN_e"]                       # (n_el, n_pts, 4)
        n_el, n_pts = dN.shape[:2]
        d2 = np.zeros((n_el, 2, n_pts, 4, 2, 4, 2))
        gg = 2.0 * (dN[:, :, :, None] * dN[:, :, None, :])
        x, y = dN[:, :, :, None] * ddN[:, :, None, :], ddN[:, :, :, None] * dN[:, :, None, :]
        for a in range(2):
            d2[:, 0, :, :, a, :, a] = gg
        d2[:, 1, :, :, 0, :, 1] = x - y
        d2[:, 1, :, :, 1, :, 0] = y - x
        terms = geom["_reference"] = (np.ascontiguousarray(dN.transpose(2, 0, 1))[:, None],
                                      np.ascontiguousarray(ddN.transpose(2, 0, 1))[:, None],
                                      d2.reshape(n_el, 2 * n_pts, 64))
    return terms


def invariants(geom: dict, q: np.ndarray, order: int = 1) -> tuple:
    """``g = r'.r'`` and ``c = (r' x r'').e_z`` at every point, shape (n_el, n_pts); for ``order`` 1 also
    their gradients ``dg``, ``dc`` in the element coordinates, shape (4, 2, n_el, n_pts)."""
    Q = q.reshape(q.shape[0], 4, 2)
    r1 = np.ascontiguousarray((geom["dN_e"] @ Q).transpose(2, 0, 1))      # (2, n_el, n_pts)
    r2 = np.ascontiguousarray((geom["ddN_e"] @ Q).transpose(2, 0, 1))
    g = r1[0] * r1[0] + r1[1] * r1[1]
    c = r1[0] * r2[1] - r1[1] * r2[0]
    if order == 0:
        return g, c
    dN, ddN = reference_terms(geom)[:2]
    dg = dN * (2.0 * r1)
    # dc = Sx^T P r'' + Sxx^T P^T r', with P r'' = (r''_y, -r''_x), P^T r' = (-r'_y, r'_x)
    r2[0] *= -1.0
    r1[1] *= -1.0
    dc = dN * r2[::-1] + ddN * r1[::-1]
    return g, c, dg, dc


def densities(element: BE2D, g: np.ndarray, c: np.ndarray, geom: dict, order: int = 2) -> list:
    """The energy density of Eqs. 82-88 and its derivatives in (g, c), each of shape (n_el, n_pts):
    ``(W, Wg, Wc)``, and for ``order`` 2 also ``(Wgg, Wgc, Wcc)``.

    Axial terms act at the axial rule's points (the first ``n_a``), bending
    terms at the bending rule's points; each is evaluated on its own slice.
    """
    E, sec = element.material.E, element.section
    EA, EI = E * sec.A, E * sec.I3
    na = geom["n_a"]
    ga, gb, cb = g[:, :na], g[:, na:], c[:, na:]
    out = [np.empty_like(g) for _ in range(6 if order >= 2 else 3)]
    if element.formulation == "structural":
        a = 1.0 + geom["eps_ref"][:, :na]
        rg = np.sqrt(ga)
        Kr = geom["K_ref"][:, na:]
        igb = 1.0 / gb
        K = cb * igb
        dK = K - Kr
        out[0][:, :na] = 0.5 * EA * (rg - a) ** 2
        out[0][:, na:] = 0.5 * EI * dK * dK
        out[1][:, :na] = EA * (0.5 - 0.5 * a / rg)
        out[1][:, na:] = -EI * dK * K * igb
        out[2][:, :na] = 0.0
        out[2][:, na:] = EI * dK * igb
        if order >= 2:
            igb2 = igb * igb
            out[3][:, :na] = 0.25 * EA * a / (ga * rg)
            out[3][:, na:] = EI * (3 * K - 2 * Kr) * K * igb2
            out[4][:, :na] = 0.0
            out[4][:, na:] = -EI * (2 * K - Kr) * igb2
            out[5][:, :na] = 0.0
            out[5][:, na:] = EI * igb2
        return out
    a = 0.5 * (ga - 1.0)
    I, I4 = sec.I3, sec.I4
    ig = 1.0 / gb
    phi = (1.5 - 0.5 * ig) * ig
    phi1 = (-1.5 + ig) * ig**2
    psi, psi1 = 0.25 * ig**4, -ig**5
    c2 = cb * cb
    out[0][:, :na] = 0.5 * EA * a**2
    out[0][:, na:] = 0.5 * E * (I * c2 * phi + I4 * c2 * c2 * psi)
    out[1][:, :na] = 0.5 * EA * a
    out[1][:, na:] = 0.5 * E * (I * c2 * phi1 + I4 * c2 * c2 * psi1)
    out[2][:, :na] = 0.0
    out[2][:, na:] = E * (I * cb * phi + 2 * I4 * c2 * cb * psi)
    if order >= 2:
        phi2 = (3.0 - 3.0 * ig) * ig**3
        psi2 = 5.0 * ig**6
        out[3][:, :na] = 0.25 * EA
        out[3][:, na:] = 0.5 * E * (I * c2 * phi2 + I4 * c2 * c2 * psi2)
        out[4][:, :na] = 0.0
        out[4][:, na:] = E * (I * cb * phi1 + 2 * I4 * c2 * cb * psi1)
        out[5][:, :na] = 0.0
        out[5][:, na:] = E * (I * phi + 6 * I4 * c2 * psi)
    return out


class BE2DReference(Kernel):
    """The NumPy reference of BE2D's internal forces and tangent, a few ``einsum`` calls over all elements x points.

    The force is ``W_g dg + W_c dc`` and the tangent
    ``W_gg dg dg^T + W_gc (dg dc^T + dc dg^T) + W_cc dc dc^T + W_g d2g + W_c d2c``
    (module docstring); the compiled twin is :class:`~.be2d_kernel.BE2DCompiled`.
    """

    name = "numpy"

    def strain_energy(self, geom: dict, q: np.ndarray) -> np.ndarray:
        """Strain energy of each element (n_el,): ``sum_p w_p W(g_p, c_p)`` (Eqs. 82-88)."""
        g, c = invariants(geom, q, order=0)
        return np.sum(geom["w"] * densities(self.element, g, c, geom, order=1)[0], axis=1)

    def internal_forces(self, geom: dict, q: np.ndarray,
                        tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """``f = dU/dq_e`` (n_el, 8) and, if ``tangent``, ``K = df/dq_e`` (n_el, 8, 8)."""
        w = geom["w"]
        g, c, dg, dc = invariants(geom, q)
        W = densities(self.element, g, c, geom, 2 if tangent else 1)
        n_el, n_pts = g.shape
        # f_i = sum_p w (Wg dg_i + Wc dc_i)
        wg, wc = w * W[1], w * W[2]
        f = (np.sum(dg * wg + dc * wc, axis=-1)).reshape(8, n_el).T
        if not tangent:
            return f, None
        Wgg, Wgc, Wcc = w * W[3], w * W[4], w * W[5]
        Bg = dg * Wgg + dc * Wgc                         # H A, row g
        Bc = dg * Wgc + dc * Wcc                         # H A, row c
        A = np.concatenate([dg, dc], axis=-1).reshape(8, n_el, 2 * n_pts).transpose(1, 0, 2)
        B = np.concatenate([Bg, Bc], axis=-1).reshape(8, n_el, 2 * n_pts).transpose(1, 2, 0)
        first = np.stack([wg, wc], axis=1).reshape(n_el, 1, 2 * n_pts)
        K = A @ B + (first @ reference_terms(geom)[2]).reshape(n_el, 8, 8)
        return f, K


def _compiled(element: BE2D) -> Kernel:
    """The compiled kernel object; its module, and numba's loops with it, is imported when selected."""
    from .be2d_kernel import BE2DCompiled
    return BE2DCompiled(element)



class BE2D(Element):
    """Planar Bernoulli-Euler ANCF beam element (chapter Sects. 3.1-3.3).

    Parameters
    ----------
    material : Material
    section : RectangularSection or CircularSection
        Uses ``A``, ``I3`` (in-plane bending) and, for the continuum
        formulation, ``I4``.
    formulation : {"structural", "continuum"}
        ``"structural"``: axial strain ``eps0 = |r'| - 1`` and curvature ``K``
        (Eq. 78) with ``U = int EA/2 (eps0 - eps0_ref)^2 + EI/2 (K - K_ref)^2
        dxi`` (Eqs. 82-83); the reference values make a pre-curved or
        pre-stretched undeformed beam stress-free.
        ``"continuum"``: St. Venant-Kirchhoff on the Green strain
        ``E11 = ((|r'| - eta K)^2 - 1)/2`` (Eq. 74) integrated exactly over
        the section, ``U = int E/2 [A a^2 + I (3g-1)/(2g^2) c^2 + I4 c^4/(4 g^4)]
        dxi`` with ``a = (g-1)/2`` -- the energy whose variation is Eqs. 84-88
        (with the factor EA of Eq. 84 restored); straight reference only.
    axial_points, bending_points : int
        Gauss points for the axial and the bending (curvature) terms. The
        defaults 5 and 3 (integration orders 9 and 5, as recommended at the
        end of Sect. 3.5) reproduce the chapter's Table 2.
    kernel : {"auto", "numba", "numpy"}
        Implementation of :meth:`internal_forces`. ``"numba"`` and ``"auto"``
        (the default): one compiled loop over elements x points
        (:class:`~.be2d_kernel.BE2DCompiled`, same results to rounding; the
        first call compiles, or loads the on-disk cache). ``"numpy"``:
        vectorised NumPy (:class:`BE2DReference`), the reference. Settable
        later through the ``kernel`` attribute.
    """

    name = "BE2D"
    dim = 2
    node_params = (-1.0, 1.0)
    node_coordinates = ("x", "y", "x'", "y'")
    formulations = ("structural", "continuum")
    kernel_twins = {"numpy": BE2DReference, "numba": _compiled}

    def __init__(self, material: Material, section: RectangularSection | CircularSection,
                 formulation: str = "structural", axial_points: int = 5, bending_points: int = 3,
                 kernel: str = "auto") -> None:
        if not isinstance(material, Material):
            raise TypeError(f"`material` must be a Material, got {material!r}.")
        for attr in ("A", "I3", "I4"):
            if not hasattr(section, attr):
                raise TypeError(f"`section` must provide {attr} (e.g. RectangularSection), got {section!r}.")
        self.material = material
        self.section = section
        self.formulation = choice("formulation", formulation, self.formulations)
        self.axial_points = positive_int("axial_points", axial_points)
        self.bending_points = positive_int("bending_points", bending_points)
        self.kernel = kernel

    def __repr__(self):
        return (f"BE2D(formulation={self.formulation!r}, axial_points={self.axial_points}, "
                f"bending_points={self.bending_points}, kernel={self._kernel!r})")

    # -- mesh -----------------------------------------------------------
    def reference_coordinates(self, points: np.ndarray, frames: np.ndarray) -> np.ndarray:
        return np.concatenate([points, frames[:, :, 0]], axis=1)

    def support_coordinates(self, kind: str, frame: np.ndarray) -> tuple[str, ...]:
        if kind == "pin":
            return ("x", "y")
        # Clamp: fix the transverse slope only, so the axial strain at the
        # clamp stays free (fixing it too over-constrains the axial strain there); possible when the axis is
        # aligned with e_x or e_y, otherwise both slope coordinates are fixed.
        t = frame[:, 0]
        if abs(t[1]) < 1e-12:
            return ("x", "y", "y'")
        if abs(t[0]) < 1e-12:
            return ("x", "y", "x'")
        return ("x", "y", "x'", "y'")

    def prepare(self, q_ref: np.ndarray, lengths: np.ndarray) -> dict:
        # One concatenated point set: the axial rule's points first, then the
        # bending rule's; masks select which density acts where. Arrays are
        # stored points-last ("structure of arrays", (..., n_el, n_pts)) so that
        # every elementwise operation runs over all elements x points at once.
        sa, wa = gauss(self.axial_points)
        sb, wb = gauss(self.bending_points)
        s = np.concatenate([sa, sb])
        w = np.concatenate([wa, wb])
        _, dN, ddN = hermite(s, lengths)                         # (n_el, n_pts, 4)
        n_el, n_pts = dN.shape[:2]
        geom = {"L": lengths, "w": w[None, :] * lengths[:, None] / 2.0,
                "dN_e": dN, "ddN_e": ddN,                                   # (n_el, n_pts, 4): for r', r''
                "n_a": sa.size}
        g, c = invariants(geom, q_ref, order=0)
        geom["eps_ref"] = np.sqrt(g) - 1.0
        geom["K_ref"] = c / g
        if self.formulation == "continuum":
            bent = max(np.abs(geom["eps_ref"]).max(), np.abs(geom["K_ref"]).max() * lengths.max())
            if bent > 1e-10:
                raise ValueError("formulation='continuum' needs a straight, unstretched reference configuration; "
                                 f"the given nodes have |eps_ref|, |K_ref| L up to {bent:.3g}.")
        sm, wm = gauss(4)   # cubic x cubic: exact with 4 points
        N, _, _ = hermite(sm, lengths)
        m = np.einsum("ep,epi,epj->eij", wm[None, :] * lengths[:, None] / 2, N, N)
        rhoA = self.material.rho * self.section.A
        M = np.zeros((n_el, 4, 2, 4, 2))                            # rhoA m_ij delta_kl
        for k in range(2):
            M[:, :, k, :, k] = rhoA * m
        geom["M"] = M.reshape(-1, 8, 8)
        return geom

    # -- kernels --------------------------------------------------------
    def mass_matrix(self, geom: dict) -> np.ndarray:
        return geom["M"]

    def shape_matrix(self, s: ArrayLike, lengths: ArrayLike) -> np.ndarray:
        N, _, _ = hermite(np.asarray(s, dtype=float), lengths)
        return _expand2(N)

    def moment_slope_operator(self, s: float, length: float) -> np.ndarray | None:
        """``S'`` (2, 8) at ``s``: :meth:`moment_load` is the turn of the tangent, applied compiled by the beam
        (None for a subclass with a moment of its own)."""
        if type(self).moment_load is not BE2D.moment_load:
            return None
        _, dN, _ = hermite(np.array([float(s)]), np.array([float(length)]))
        return _expand2(dN)[0, 0]

    def moment_load(self, geom: dict, q: np.ndarray, s: float, moment: np.ndarray, element: int,
                    tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Dead moment ``M_z`` at ``s``: ``delta phi = (r' x delta r').e_z / |r'|^2`` (the reference of
        :func:`ancfdae.models.beam.moments_numba.tangent_moments`)."""
        L = geom["L"][[element]]
        _, dN, _ = hermite(np.array([s]), L)
        Sx = _expand2(dN)[0, 0]                        # (2, 8)
        r1 = Sx @ q
        g = r1 @ r1
        h = Sx.T @ (_P.T @ r1)                         # d(r' x r'')/d... : Sx^T P^T r'
        Mz = float(moment[2])
        f = Mz * h / g
        if not tangent:
            return f, None
        dh = Sx.T @ _P.T @ Sx
        dg = 2.0 * Sx.T @ r1
        return f, Mz * (dh / g - np.outer(h, dg) / g**2)
