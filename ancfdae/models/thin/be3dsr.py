"""BE3DSR: BE3D with interior frames transported from the nodal frames, whose energy no director update changes.

The chapter's BE3D (Sects. 3.5-3.6, :mod:`.be3d`) interpolates the director and the torsion angle inside an
element; its director update (Sect. 3.6) keeps the nodal frames but changes the interior ones, and with them
``T + U``: the energy jumps behind the blow-ups of Sect. 5.3. BE3DSR keeps BE3D's coordinates, nodal frames,
axial energy, loads and director update, and builds the interior frame from the nodal frames and the axis
alone (smallest rotation, :mod:`.be3dsr_kinematics`). The directors are then only a chart of the nodal angle:
updating them changes neither the strain nor the kinetic energy (to round-off), so the semi-discrete equations
conserve energy through every update. This module holds the element and its NumPy reference kernel
(:class:`BE3DSRReference`); the compiled twin is :mod:`.be3dsr_numba`.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ...materials import CircularSection, Material, RectangularSection
from ..element import Kernel
from .be3d import BE3D
from .be3d_kinematics import TorsionRule
from .be3d_moment import moment_load
from .be3dsr_kinematics import curvatures, point_data, spin_coefficients
from .rotary import mass_bilinear, rotary_inertia, rotary_kinetic_energy
from .spatial import axial_energy

__all__ = ["BE3DSR", "BE3DSRReference"]


def _curvature_energy(pd, q, k_ref, stiffness, order):
    """``sum_p w_p 1/2 sum_i C_i (k_i - k_ref_i)^2`` per element, with its gradient and Hessian by ``order``."""
    ks = curvatures(pd, q, order)
    k_ref = k_ref.reshape(-1, 3)
    n_el, n_pts = pd.n_el, pd.n_pts
    U = g = H = 0.0
    for i, k in enumerate(ks):
        wc = stiffness[i] * pd.w
        r = k.v - k_ref[:, i]
        U = U + 0.5 * wc * r * r
        if order >= 1:
            g = g + (wc * r)[:, None] * k.g
        if order >= 2:
            H = H + (wc * r)[:, None, None] * k.h + wc[:, None, None] * k.g[:, :, None] * k.g[:, None, :]
    out = [U.reshape(n_el, n_pts).sum(axis=1)]
    if order >= 1:
        out.append(g.reshape(n_el, n_pts, -1).sum(axis=1))
    if order >= 2:
        out.append(H.reshape((n_el, n_pts) + H.shape[1:]).sum(axis=1))
    return out


class BE3DSRReference(Kernel):
    """The NumPy reference of BE3DSR's kernels (jets over the 14 element coordinates)."""

    name = "numpy"

    def _points(self, geom, key):
        return point_data(geom[key], geom["directors"], geom["L"])

    def strain_energy(self, geom: dict, q: np.ndarray) -> np.ndarray:
        """Axial plus bending-torsion energy per element (:class:`BE3DSR`)."""
        el = self.element
        U, _, _ = axial_energy(geom["axial"], q, geom["slope_ref"], el.EA, False)
        return U + _curvature_energy(self._points(geom, "bend"), q, geom["k_ref"], el.curvature_stiffness, 0)[0]

    def internal_forces(self, geom: dict, q: np.ndarray,
                        tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """``f = dU/dq_e`` (n_el, 14) and, if ``tangent``, ``K = df/dq_e`` (n_el, 14, 14)."""
        el = self.element
        _, f, K = axial_energy(geom["axial"], q, geom["slope_ref"], el.EA, tangent)
        out = _curvature_energy(self._points(geom, "bend"), q, geom["k_ref"], el.curvature_stiffness,
                                2 if tangent else 1)
        return f + out[1], (K + out[2] if tangent else None)

    def moment_load(self, geom: dict, q: np.ndarray, s: float, moment: np.ndarray, element: int,
                    tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """The dead moment of :func:`.be3d_moment.moment_load` (at a node, where the frames are BE3D's)."""
        return moment_load(geom, q, s, moment, element, tangent)

    def _spin(self, geom, q, order):
        pd = self._points(geom, "inertia")
        c, C, Hc = spin_coefficients(pd, q, order)
        return self.element.rhoJ * pd.w, c, C, Hc, pd.n_pts

    def inertia(self, geom: dict, q: np.ndarray, v: np.ndarray, a: np.ndarray, tangent: bool = True) -> tuple:
        """The rotary inertia of :func:`.rotary.rotary_inertia` with BE3DSR's spin."""
        W, c, C, Hc, n_pts = self._spin(geom, q, 2 if tangent else 1)
        return rotary_inertia(W, c, C, Hc, v, a, n_pts, tangent)

    def kinetic_energy(self, geom: dict, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``1/2 int rho J omega1^2 dxi`` per element."""
        W, c, _, _, n_pts = self._spin(geom, q, 0)
        return rotary_kinetic_energy(W, c, v, n_pts)

    def mass_bilinear(self, geom: dict, q: np.ndarray, u: np.ndarray, w: np.ndarray, order: int = 2) -> tuple:
        """``1/2 u^T M_rot(q) w`` per element with its q-derivatives (:func:`.rotary.mass_bilinear`)."""
        W, c, C, Hc, n_pts = self._spin(geom, q, order)
        return mass_bilinear(W, c, C, Hc, u, w, n_pts, order)


def _compiled(element: BE3DSR) -> Kernel:
    """The compiled kernel object; its module, and numba's loops with it, is imported when selected."""
    from .be3dsr_numba import BE3DSRCompiled
    return BE3DSRCompiled(element)


class BE3DSR(BE3D):
    """BE3D whose interior cross-section frames are transported from the nodal frames (smallest rotation).

    Coordinates, nodal frames (chapter Eqs. 96-100), axial energy (Eq. 16), loads, supports and the director
    update are BE3D's (:class:`~.be3d.BE3D`, whose parameters this class takes). Inside an element the frame
    is the nodal frame of A carried onto the local tangent by the smallest rotation and turned by ``S6 phi``
    (Eq. 102), ``phi`` the relative twist of the two nodal frames (:mod:`.be3dsr_kinematics`)::

        U = int_L EA/2 (|r'| - |r'_ref|)^2 + G J k_t/2 (k1 - k1_ref)^2 + EI2/2 (k2 - k2_ref)^2
                + EI3/2 (k3 - k3_ref)^2 dxi,     k1 = phi/L + S5 tau_A + S6 tau_B,

    and the rotary kinetic energy ``1/2 int rho J omega1^2`` with the spin of the same frames. Strain and
    kinetic energy depend on the nodal frames, not on the directors, so the director update is a change of
    chart that keeps ``T + U`` to round-off: between and across updates the semi-discrete equations conserve
    energy. The update is still needed where a node's director comes close to its tangent (Eq. 99 singular
    there): the default ``update_below=0.5`` updates the directors when the sine of that angle falls below
    0.5 at some node, rarely; ``update_below=None`` updates after every step (energy-neutral as well). The
    frames are defined unless the tangent turns by 180 degrees within one element or two neighbouring nodal
    frames differ by a twist of 180 degrees (``phi`` is taken in (-pi, pi]).

    Parameters
    ----------
    material, section, director_update, director, axial_points, bending_points, inertia_points, kernel
        As for :class:`~.be3d.BE3D`.
    update_below : float in (0, 1] or None
        As for BE3D; default 0.5 here.
    """

    name = "BE3DSR"
    kernel_twins = {"numpy": BE3DSRReference, "numba": _compiled}

    def __init__(self, material: Material, section: RectangularSection | CircularSection,
                 director_update: str = "projected", director: ArrayLike | None = None,
                 axial_points: int = 5, bending_points: int = 3, inertia_points: int = 3,
                 update_below: float | None = 0.5, kernel: str = "auto") -> None:
        super().__init__(material, section, director_update=director_update, director=director,
                         axial_points=axial_points, bending_points=bending_points, inertia_points=inertia_points,
                         update_below=update_below, kernel=kernel)

    def __repr__(self) -> str:
        return super().__repr__().replace("BE3D(", "BE3DSR(", 1)

    def prepare(self, q_ref: np.ndarray, lengths: np.ndarray, directors: ArrayLike | None = None) -> dict:
        """BE3D's geometry with the reference twist and curvatures of BE3DSR's frames."""
        geom = super().prepare(q_ref, lengths, directors)
        pd = point_data(geom["bend"], geom["directors"], geom["L"])
        ks = curvatures(pd, np.asarray(q_ref, dtype=float), 0)
        geom["k_ref"] = np.stack([k.v for k in ks], axis=-1).reshape(pd.n_el, pd.n_pts, 3)
        return geom

    def curvature(self, geom: dict, q: np.ndarray, s: ArrayLike) -> np.ndarray:
        """Twist and curvatures ``(k1, k2, k3)`` per xi at normalised coordinates ``s``, shape (n_el, n_pts, 3)."""
        pd = point_data(TorsionRule(np.atleast_1d(np.asarray(s, dtype=float)), geom["L"]), geom["directors"],
                        geom["L"])
        return np.stack([k.v for k in curvatures(pd, q, 0)], axis=-1).reshape(pd.n_el, pd.n_pts, 3)

    def mass_bilinear(self, geom: dict, q: np.ndarray, u: np.ndarray, w: np.ndarray, order: int = 2) -> tuple:
        """``1/2 u^T M_rot(q) w`` per element, its q-gradient and Hessian (the energy-momentum method's)."""
        return self.kernels.mass_bilinear(geom, q, u, w, order)
