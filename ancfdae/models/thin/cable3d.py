"""Cable3D: the thin spatial ANCF element without torsion (chapter Sect. 3.4).

Two nodes with coordinates ``(x, y, z, x', y', z')`` -- position and axial
slope -- and the cubic Hermite interpolation of chapter Eq. 62: 12 DOF per
element. The planar BE2D element extended by a third component
(Gerstmayr and Shabana 2006, as corrected by Gerstmayr and Irschik 2008).
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import finite_vector, positive_int
from ...materials import CircularSection, Material, RectangularSection
from ..element import Element, Kernel
from ..shapes import hermite
from .spatial import (PointRule, assemble, axial_energy, check_material_section, clamp_coordinates,
                      hermite_operator, translational_mass)

__all__ = ["Cable3D", "Cable3DReference", "curvature_squared"]

# Hermite vector k, component i -> element coordinate: (r_A, r'_A, r_B, r'_B) back to back.
_DOF = np.arange(12).reshape(4, 3)

# Relative tolerance of the restriction I2 == I3 and of a straight reference.
_SYM_RTOL = 1e-10
_STRAIGHT_TOL = 1e-10


def curvature_squared(rule: PointRule, q: np.ndarray) -> np.ndarray:
    """``K^2 = |r' x r''|^2 / |r'|^4`` (Eq. 95) at the points of ``rule``, shape (n_el, n_pts)."""
    a = np.einsum("epin,en->epi", rule.Ba, q)
    b = np.einsum("epin,en->epi", rule.Bb, q)
    p = np.einsum("...i,...i", a, a)
    ab = np.einsum("...i,...i", a, b)
    bb = np.einsum("...i,...i", b, b)
    return (p * bb - ab**2) / p**2


class Cable3DReference(Kernel):
    """The NumPy reference of Cable3D's strain energy, internal forces and tangent (Eqs. 94-95).

    The compiled twin is :class:`~.cable3d_numba.Cable3DCompiled`.
    """

    name = "numpy"

    def strain_energy(self, geom: dict, q: np.ndarray) -> np.ndarray:
        """``EA/2 (|r'| - |r'_ref|)^2`` at the axial points plus ``EI/2 K^2`` at the bending points, per element."""
        el = self.element
        U, _, _ = axial_energy(geom["axial"], q, geom["slope_ref"], el.material.E * el.section.A, False)
        rule = geom["bend"]
        K2 = curvature_squared(rule, q)
        return U + 0.5 * el.material.E * el.section.I3 * np.sum(rule.wdx * K2, axis=1)

    def internal_forces(self, geom: dict, q: np.ndarray,
                        tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """``f = dU/dq_e`` (n_el, 12) and, if ``tangent``, ``K = df/dq_e`` (n_el, 12, 12)."""
        el = self.element
        _, f, K = axial_energy(geom["axial"], q, geom["slope_ref"], el.material.E * el.section.A, tangent)
        rule = geom["bend"]
        EI = el.material.E * el.section.I3
        a = np.einsum("epin,en->epi", rule.Ba, q)
        b = np.einsum("epin,en->epi", rule.Bb, q)
        p = np.einsum("...i,...i", a, a)[..., None]
        ab = np.einsum("...i,...i", a, b)[..., None]
        bb = np.einsum("...i,...i", b, b)[..., None]
        # K^2 = g / p^2 with g = |a x b|^2 = p |b|^2 - (a.b)^2
        g = p * bb - ab**2
        ga = 2.0 * (a * bb - ab * b)
        gb = 2.0 * (b * p - ab * a)
        Fa = ga / p**2 - 4.0 * g * a / p**3
        Fb = gb / p**2
        c = 0.5 * EI * rule.wdx[..., None]
        f = f + np.einsum("epin,epi->en", rule.Ba, c * Fa) + np.einsum("epin,epi->en", rule.Bb, c * Fb)
        if not tangent:
            return f, None
        I = np.eye(3)
        p2, p3, p4 = (p**2)[..., None], (p**3)[..., None], (p**4)[..., None]
        outer = lambda u, v: u[..., :, None] * v[..., None, :]   # noqa: E731
        gaa = 2.0 * (bb[..., None] * I - outer(b, b))
        gab = 4.0 * outer(a, b) - 2.0 * outer(b, a) - 2.0 * ab[..., None] * I
        gbb = 2.0 * (p[..., None] * I - outer(a, a))
        Faa = (gaa / p2 - 4.0 * (outer(ga, a) + outer(a, ga)) / p3
               + 24.0 * g[..., None] * outer(a, a) / p4 - 4.0 * g[..., None] * I / p3)
        Fab = gab / p2 - 4.0 * outer(a, gb) / p3
        Fbb = gbb / p2
        H = np.concatenate([np.concatenate([Faa, Fab], -1), np.concatenate([np.swapaxes(Fab, -1, -2), Fbb], -1)],
                           -2) * c[..., None]
        B = np.concatenate([rule.Ba, rule.Bb], axis=2)                     # (n_el, n_pts, 6, 12)
        return f, K + assemble(B, H)


def _compiled(element: Cable3D) -> Kernel:
    """The compiled kernel object; its module, and numba's loops with it, is imported when selected."""
    from .cable3d_numba import Cable3DCompiled
    return Cable3DCompiled(element)



class Cable3D(Element):
    """Spatial thin ANCF beam without torsional stiffness (chapter Sect. 3.4).

    Strain energy (structural formulation, chapter Eqs. 37 and 40 with the
    axial and the bending stiffness only)::

        U = int_L  EA/2 (|r'| - |r'_ref|)^2  +  EI/2 K^2  dxi,
        eps0 = |r'| - 1                        (Eq. 94)
        K    = |r' x r''| / |r'|^2             (Eq. 95)

    ``K^2 = (|r'|^2 |r''|^2 - (r'.r'')^2) / |r'|^4`` is smooth, so the
    straight beam (``K = 0``) has a well-defined tangent stiffness.

    Restrictions (chapter Sect. 3.4), enforced where they can be:

    (a) symmetric bending stiffness ``EI2 == EI3`` (round or square cables):
        a section with ``I2 != I3`` raises ValueError;
    (b) no torsional stiffness and no rotary inertia about the axis: the
        model must not be used for problems that twist the cable. A moment
        load acts through its bending part only: the component along the
        current tangent does no work on a cable and is dropped (a
        projection, not an error, because the tangent moves during a
        simulation); see :meth:`moment_load`.

    The reference configuration must be straight (zero curvature): the
    energy uses ``K^2``, which has no stress-free curved state.

    Parameters
    ----------
    material : Material
    section : RectangularSection or CircularSection
        Uses ``A`` and ``I2 == I3``.
    axial_points, bending_points : int
        Gauss points of the axial and the bending term; the defaults 5 and 3
        (orders 9 and 5, as for BE2D) reproduce the chapter's Table 2.
    kernel : {"auto", "numba", "numpy"}
        Implementation of :meth:`strain_energy` and :meth:`internal_forces`.
        ``"numba"`` and ``"auto"`` (the default): one compiled loop over
        elements x points (:class:`~.cable3d_numba.Cable3DCompiled`; the first
        call compiles or loads the on-disk cache). ``"numpy"``: vectorised
        NumPy (:class:`Cable3DReference`), the readable reference (same
        results to rounding). Settable later through the ``kernel`` attribute.
    """

    name = "Cable3D"
    dim = 3
    node_params = (-1.0, 1.0)
    node_coordinates = ("x", "y", "z", "x'", "y'", "z'")
    kernel_twins = {"numpy": Cable3DReference, "numba": _compiled}

    def __init__(self, material: Material, section: RectangularSection | CircularSection, axial_points: int = 5,
                 bending_points: int = 3, kernel: str = "auto") -> None:
        check_material_section(material, section, ("A", "I2", "I3"))
        if not np.isclose(section.I2, section.I3, rtol=_SYM_RTOL, atol=0.0):
            raise ValueError("`section` of a Cable3D must have a symmetric bending stiffness (I2 == I3, chapter "
                             f"Sect. 3.4 restriction (a)), got I2 = {section.I2!r}, I3 = {section.I3!r}; "
                             "use BE3D for unequal bending stiffnesses.")
        self.material = material
        self.section = section
        self.axial_points = positive_int("axial_points", axial_points)
        self.bending_points = positive_int("bending_points", bending_points)
        self.kernel = kernel

    def __repr__(self):
        return (f"Cable3D(axial_points={self.axial_points}, bending_points={self.bending_points}, "
                f"kernel={self._kernel!r})")

    # -- mesh -------------------------------------------------------------
    def reference_coordinates(self, points: np.ndarray, frames: np.ndarray) -> np.ndarray:
        return np.concatenate([points, frames[:, :, 0]], axis=1)

    def support_coordinates(self, kind: str, frame: np.ndarray) -> tuple[str, ...]:
        """``"pin"``: r; ``"clamp"``: r and the slope components transverse to the reference tangent.

        With a tangent along a global axis the axial slope component stays
        free (fixing it over-constrains the axial strain); otherwise all slope coordinates are fixed.
        """
        return clamp_coordinates(kind, frame)

    def prepare(self, q_ref: np.ndarray, lengths: np.ndarray) -> dict:
        q_ref = np.asarray(q_ref, dtype=float)
        lengths = np.asarray(lengths, dtype=float)
        geom = {"L": lengths,
                "axial": PointRule(self.axial_points, lengths, _DOF, 12),
                "bend": PointRule(self.bending_points, lengths, _DOF, 12),
                "M": translational_mass(lengths, _DOF, 12, self.material.rho * self.section.A)}
        a = np.einsum("epin,en->epi", geom["axial"].Ba, q_ref)
        geom["slope_ref"] = np.linalg.norm(a, axis=-1)
        K2 = curvature_squared(geom["bend"], q_ref)
        bent = float(np.sqrt(K2.max()) * lengths.max()) if K2.size else 0.0
        if bent > _STRAIGHT_TOL:
            raise ValueError("Cable3D needs a straight reference configuration (its energy EI/2 K^2 has no "
                             f"stress-free curved state); the given nodes have K L up to {bent:.3g}.")
        return geom

    # -- kernels ----------------------------------------------------------
    def mass_matrix(self, geom: dict) -> np.ndarray:
        return geom["M"]

    def shape_matrix(self, s: ArrayLike, lengths: ArrayLike) -> np.ndarray:
        N, _, _ = hermite(np.asarray(s, dtype=float), np.asarray(lengths, dtype=float))
        return hermite_operator(N, _DOF, 12)

    def moment_slope_operator(self, s: float, length: float) -> np.ndarray | None:
        """``S'`` (3, 12) at ``s``: :meth:`moment_load` is the turn of the tangent, applied compiled by the beam
        (None for a subclass with a moment of its own)."""
        if type(self).moment_load is not Cable3D.moment_load:
            return None
        _, dN, _ = hermite(np.array([float(s)]), np.array([float(length)]))
        return hermite_operator(dN, _DOF, 12)[0, 0]

    def moment_load(self, geom: dict, q: np.ndarray, s: float, moment: np.ndarray, element: int,
                    tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Dead moment at ``s``: virtual rotation ``delta phi = r' x delta r' / |r'|^2`` (bending only; the
        reference of :func:`ancfdae.models.beam.moments_numba.tangent_moments`).

        A cable has no torsional coordinate, so the virtual rotation of its
        cross-section is the turn of the tangent, ``e1 x delta e1``; the
        moment's component along the current tangent ``e1`` does no virtual
        work and is dropped (projection, documented in the class docstring).
        The generalised force is ``Sx^T (M x r') / |r'|^2``.
        """
        M = finite_vector("moment", moment, 3)
        L = geom["L"][[element]]
        _, dN, _ = hermite(np.array([float(s)]), L)
        Sx = hermite_operator(dN, _DOF, 12)[0, 0]                       # (3, 12)
        a = Sx @ q
        p = a @ a
        Mxa = np.cross(M, a)
        f = Sx.T @ (Mxa / p)
        if not tangent:
            return f, None
        Mx = np.cross(M[None, :], np.eye(3)).T                          # d(M x a)/da
        dfa = Mx / p - 2.0 * np.outer(Mxa, a) / p**2
        return f, Sx.T @ dfa @ Sx
