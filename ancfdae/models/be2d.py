"""BE2D: the planar Bernoulli-Euler ANCF beam element (chapter Sects. 3.1-3.3).

Two nodes with coordinates ``(x, y, x', y')`` -- position and axial slope --
and the cubic Hermite interpolation of chapter Eq. 60, 8 DOF per element.

Both formulations are written as an energy density in the two invariants of
the axis at a quadrature point, ``g = r'.r'`` and ``c = (r' x r'').e_z``:
``|r'| = sqrt(g)`` and the material curvature ``K = c / g`` (Eq. 70). Since
``g`` and ``c`` are quadratic forms in the element coordinates, their
Hessians are constant and are precomputed; the force is
``W_g dg + W_c dc`` and the tangent
``W_gg dg dg^T + W_gc (dg dc^T + dc dg^T) + W_cc dc dc^T + W_g d2g + W_c d2c``,
exact, for all elements and points in a few ``einsum`` calls.
"""
from __future__ import annotations

import numpy as np

from .._validate import choice, positive_int
from ..materials import Material
from ._element import Element
from ._quadrature import gauss
from ._shapes import hermite

__all__ = ["BE2D"]

# (r' x r'').e_z = r'^T P r''
_P = np.array([[0.0, 1.0], [-1.0, 0.0]])


def _expand2(N: np.ndarray) -> np.ndarray:
    """Scalar shape functions (..., 4) -> interpolation matrices (..., 2, 8), dof order (x, y) per function."""
    out = np.zeros(N.shape[:-1] + (2, 8))
    out[..., 0, 0::2] = N
    out[..., 1, 1::2] = N
    return out


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
    """

    name = "BE2D"
    dim = 2
    node_params = (-1.0, 1.0)
    node_coordinates = ("x", "y", "x'", "y'")
    formulations = ("structural", "continuum")

    def __init__(self, material: Material, section, formulation: str = "structural",
                 axial_points: int = 5, bending_points: int = 3):
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

    def __repr__(self):
        return (f"BE2D(formulation={self.formulation!r}, axial_points={self.axial_points}, "
                f"bending_points={self.bending_points})")

    # -- mesh -----------------------------------------------------------
    def reference_coordinates(self, points, frames):
        return np.concatenate([points, frames[:, :, 0]], axis=1)

    def support_coordinates(self, kind, frame):
        if kind == "pin":
            return ("x", "y")
        # Clamp: fix the transverse slope only, so the axial strain at the
        # clamp stays free (benchmarks.md B1); possible when the axis is
        # aligned with e_x or e_y, otherwise both slope coordinates are fixed.
        t = frame[:, 0]
        if abs(t[1]) < 1e-12:
            return ("x", "y", "y'")
        if abs(t[0]) < 1e-12:
            return ("x", "y", "x'")
        return ("x", "y", "x'", "y'")

    def prepare(self, q_ref, lengths):
        geom = {"L": lengths}
        for part, n in (("a", self.axial_points), ("b", self.bending_points)):
            s, w = gauss(n)
            _, dN, ddN = hermite(s, lengths)
            Sx, Sxx = _expand2(dN), _expand2(ddN)                   # (n_el, n_pts, 2, 8)
            geom[part] = {
                "w": w[None, :] * lengths[:, None] / 2.0,
                "Sx": Sx, "Sxx": Sxx,
                "d2g": 2.0 * np.einsum("epdi,epdj->epij", Sx, Sx),
                "d2c": (np.einsum("epdi,dk,epkj->epij", Sx, _P, Sxx)
                        + np.einsum("epdi,kd,epkj->epij", Sxx, _P, Sx)),
            }
            g, c, *_ = self._invariants(geom[part], q_ref, derivatives=False)
            geom[part]["eps_ref"] = np.sqrt(g) - 1.0
            geom[part]["K_ref"] = c / g
        if self.formulation == "continuum":
            bent = max(np.abs(geom["a"]["eps_ref"]).max(), np.abs(geom["b"]["K_ref"]).max() * lengths.max())
            if bent > 1e-10:
                raise ValueError("formulation='continuum' needs a straight, unstretched reference configuration; "
                                 f"the given nodes have |eps_ref|, |K_ref| L up to {bent:.3g}.")
        s, w = gauss(4)   # cubic x cubic: exact with 4 points
        N, _, _ = hermite(s, lengths)
        m = np.einsum("ep,epi,epj->eij", w[None, :] * lengths[:, None] / 2, N, N)
        rhoA = self.material.rho * self.section.A
        geom["M"] = rhoA * np.einsum("eij,kl->eikjl", m, np.eye(2)).reshape(-1, 8, 8)
        return geom

    # -- kernels --------------------------------------------------------
    @staticmethod
    def _invariants(part, q, derivatives=True):
        r1 = np.einsum("epdi,ei->epd", part["Sx"], q)
        r2 = np.einsum("epdi,ei->epd", part["Sxx"], q)
        g = np.einsum("epd,epd->ep", r1, r1)
        c = r1[..., 0] * r2[..., 1] - r1[..., 1] * r2[..., 0]
        if not derivatives:
            return g, c
        dg = 2.0 * np.einsum("epdi,epd->epi", part["Sx"], r1)
        # dc = Sx^T P r'' + Sxx^T P^T r'
        dc = (np.einsum("epdi,dk,epk->epi", part["Sx"], _P, r2)
              + np.einsum("epdi,kd,epk->epi", part["Sxx"], _P, r1))
        return g, c, dg, dc

    def _densities(self, part_name, g, c, geom, order):
        """Energy density W and its derivatives in (g, c) at the points of one rule."""
        E, sec = self.material.E, self.section
        EA, EI = E * sec.A, E * sec.I3
        part = geom[part_name]
        zero = np.zeros_like(g)
        if self.formulation == "structural":
            if part_name == "a":
                a = 1.0 + part["eps_ref"]
                rg = np.sqrt(g)
                d = rg - a
                return (0.5 * EA * d**2, EA * (0.5 - a / (2 * rg)), zero, EA * a / (4 * g * rg), zero, zero)
            K = c / g
            dK = K - part["K_ref"]
            return (0.5 * EI * dK**2, -EI * dK * K / g, EI * dK / g,
                    EI * (3 * K**2 - 2 * part["K_ref"] * K) / g**2, -EI * (2 * K - part["K_ref"]) / g**2, EI / g**2)
        if part_name == "a":
            a = 0.5 * (g - 1.0)
            return (0.5 * EA * a**2, 0.5 * EA * a, zero, np.full_like(g, 0.25 * EA), zero, zero)
        I, I4 = sec.I3, sec.I4
        phi = 1.5 / g - 0.5 / g**2
        phi1 = -1.5 / g**2 + 1.0 / g**3
        phi2 = 3.0 / g**3 - 3.0 / g**4
        psi, psi1, psi2 = 0.25 / g**4, -1.0 / g**5, 5.0 / g**6
        W = 0.5 * E * (I * c**2 * phi + I4 * c**4 * psi)
        Wg = 0.5 * E * (I * c**2 * phi1 + I4 * c**4 * psi1)
        Wc = E * (I * c * phi + 2 * I4 * c**3 * psi)
        Wgg = 0.5 * E * (I * c**2 * phi2 + I4 * c**4 * psi2)
        Wgc = E * (I * c * phi1 + 2 * I4 * c**3 * psi1)
        Wcc = E * (I * phi + 6 * I4 * c**2 * psi)
        return W, Wg, Wc, Wgg, Wgc, Wcc

    def mass_matrix(self, geom):
        return geom["M"]

    def strain_energy(self, geom, q):
        U = 0.0
        for name in ("a", "b"):
            g, c = self._invariants(geom[name], q, derivatives=False)
            U = U + np.einsum("ep,ep->e", geom[name]["w"], self._densities(name, g, c, geom, 0)[0])
        return U

    def internal_forces(self, geom, q, tangent=True):
        f = np.zeros(q.shape)
        K = np.zeros(q.shape + (q.shape[-1],)) if tangent else None
        for name in ("a", "b"):
            part = geom[name]
            w = part["w"]
            g, c, dg, dc = self._invariants(part, q)
            _, Wg, Wc, Wgg, Wgc, Wcc = self._densities(name, g, c, geom, 2)
            f += np.einsum("ep,epi->ei", w * Wg, dg)
            if name == "b" or self.formulation == "continuum":
                f += np.einsum("ep,epi->ei", w * Wc, dc)
            if tangent:
                K += np.einsum("ep,epi,epj->eij", w * Wgg, dg, dg)
                K += np.einsum("ep,epij->eij", w * Wg, part["d2g"])
                if name == "b":
                    K += np.einsum("ep,epi,epj->eij", w * Wcc, dc, dc)
                    K += np.einsum("ep,epi,epj->eij", w * Wgc, dg, dc)
                    K += np.einsum("ep,epi,epj->eij", w * Wgc, dc, dg)
                    K += np.einsum("ep,epij->eij", w * Wc, part["d2c"])
        return f, K

    def shape_matrix(self, s, lengths):
        N, _, _ = hermite(np.asarray(s, dtype=float), lengths)
        return _expand2(N)

    def moment_load(self, geom, q, s, moment, element, tangent=True):
        """Dead moment ``M_z`` at ``s``: ``delta phi = (r' x delta r').e_z / |r'|^2``."""
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
