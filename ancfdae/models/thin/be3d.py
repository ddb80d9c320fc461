"""BE3D: the thin spatial ANCF beam with torsion, angle and director (chapter Sects. 3.5-3.6).

Two nodes with coordinates ``(x, y, z, x', y', z', theta)`` -- position, axial
slope and torsion angle -- 14 DOF per element: the cubic Hermite axis of
Eq. 62 and the linear angle of Eqs. 101-103. This module holds the element and
the NumPy reference of its strain energy (:class:`BE3DReference`); kinematics
in :mod:`.be3d_kinematics`, rotary inertia in :mod:`.be3d_inertia`, the dead
moment in :mod:`.be3d_moment`, the directors in :mod:`.be3d_directors`, and
the compiled twins beside them (``*_numba.py``).
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import choice, finite_vector, positive_int
from ...materials import CircularSection, Material, RectangularSection
from ..element import Element, Kernel
from ..shapes import hermite
from . import be3d_directors as directors_
from .be3d_inertia import rotary_bilinear, rotary_inertia, rotary_kinetic_energy
from .be3d_kinematics import (DOF, N_EDOF, TorsionRule, curvature_energy, curvatures, director_field, frames,
                              local_variables, spin_gradient)
from .be3d_moment import moment_load
from .spatial import (PointRule, assemble, axial_energy, check_material_section, clamp_coordinates,
                      hermite_operator, translational_mass)

__all__ = ["BE3D", "BE3DReference"]


class BE3DReference(Kernel):
    """The NumPy reference of BE3D's kernels: strain energy, forces and tangent, rotary inertia, dead moment.

    The residual path writes the chain rule out (:func:`.be3d_kinematics.curvature_energy`); the tangent
    propagates scalar jets (:func:`.be3d_kinematics.curvatures`). The compiled twin is
    :class:`~.be3d_numba.BE3DCompiled`.
    """

    name = "numpy"

    def strain_energy(self, geom: dict, q: np.ndarray) -> np.ndarray:
        """Axial plus bending-torsion energy per element (class docstring of :class:`BE3D`)."""
        el = self.element
        U, _, _ = axial_energy(geom["axial"], q, geom["slope_ref"], el.EA, False)
        W, _ = curvature_energy(*local_variables(geom["directors"], q, geom["bend"]), geom["k_ref"],
                                el.curvature_stiffness)
        return U + np.sum(geom["bend"].wdx * W, axis=1)

    def internal_forces(self, geom: dict, q: np.ndarray,
                        tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """``f = dU/dq_e`` (n_el, 14) and, if ``tangent``, ``K = df/dq_e`` (n_el, 14, 14)."""
        el = self.element
        _, f, K = axial_energy(geom["axial"], q, geom["slope_ref"], el.EA, tangent)
        rule = geom["bend"]
        local = local_variables(geom["directors"], q, rule)
        if not tangent:
            # residual path: the chain rule written out, no Hessians
            _, grad = curvature_energy(*local, geom["k_ref"], el.curvature_stiffness)
            return f + np.einsum("epvn,epv->en", rule.Bx, grad * rule.wdx[..., None]), None
        grad = 0.0
        hess = 0.0
        for i, ki in enumerate(curvatures(*local, order=2)):
            wi = el.curvature_stiffness[i] * rule.wdx
            ri = (ki.v - geom["k_ref"][..., i]) * wi
            grad = grad + ri[..., None] * ki.g
            hess = hess + ri[..., None, None] * ki.h + wi[..., None, None] * (ki.g[..., :, None] * ki.g[..., None, :])
        f = f + np.einsum("epvn,epv->en", rule.Bx, grad)
        return f, K + assemble(rule.Bx, hess)

    def moment_load(self, geom: dict, q: np.ndarray, s: float, moment: np.ndarray, element: int,
                    tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """The dead moment of :func:`.be3d_moment.moment_load`."""
        return moment_load(geom, q, s, moment, element, tangent)

    def inertia(self, geom: dict, q: np.ndarray, v: np.ndarray, a: np.ndarray, tangent: bool = True) -> tuple:
        """The rotary inertia of :func:`.be3d_inertia.rotary_inertia`."""
        return rotary_inertia(geom["inertia"], geom, q, v, a, self.element.rhoJ, tangent)

    def kinetic_energy(self, geom: dict, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The rotary kinetic energy of :func:`.be3d_inertia.rotary_kinetic_energy`."""
        return rotary_kinetic_energy(geom["inertia"], geom, q, v, self.element.rhoJ)

    def mass_bilinear(self, geom: dict, q: np.ndarray, u: np.ndarray, w: np.ndarray, order: int = 2) -> tuple:
        """``1/2 u^T M_rot(q) w`` per element with its q-derivatives (:func:`.be3d_inertia.rotary_bilinear`)."""
        return rotary_bilinear(geom["inertia"], geom, q, u, w, self.element.rhoJ, order)


def _compiled(element: BE3D) -> Kernel:
    """The compiled kernel object; its module, and numba's loops with it, is imported when selected."""
    from .be3d_numba import BE3DCompiled
    return BE3DCompiled(element)


class BE3D(Element):
    """Spatial thin ANCF beam with torsional stiffness (chapter Sects. 3.5-3.6).

    Frame (Eqs. 96-100): ``e1 = r'/|r'|``; ``e30`` the normalised projection
    of the director ``d`` on the normal plane of ``r'``, ``e20 = e30 x e1``;
    ``e2, e3`` turned from ``e20, e30`` by the torsion angle ``theta`` about
    ``e1``. The director is interpolated linearly between nodal directors
    (Sect. 3.6) and is constant between updates.

    Strain energy (structural formulation, Eq. 37 with the diagonal
    stiffness of Eqs. 42/111, zero shear since ``e1`` follows ``r'``)::

        U = int_L EA/2 (|r'| - |r'_ref|)^2
                + G J k_t/2 (k1 - k1_ref)^2 + EI2/2 (k2 - k2_ref)^2 + EI3/2 (k3 - k3_ref)^2 dxi

    with the axial strain of Eq. 16 and the twist ``k1`` and curvatures
    ``k2, k3`` of the frame (Eq. 18, components along ``e1, e2, e3``);
    ``I2 != I3`` is allowed (``EI3``: bending in the ``e1-e2`` plane). The
    reference values make the undeformed beam stress-free. Reduced
    integration as recommended at the end of Sect. 3.5: the axial term with
    ``axial_points`` (default 5, order 9), bending and torsion with
    ``bending_points`` (default 3, order 5).

    Inertia: the axis' translation (constant mass matrix) plus the spin of
    the cross-section about the axis, ``1/2 int rho J omega1^2``, which makes
    ``M`` depend on ``q`` and adds gyroscopic forces; derivation in
    :mod:`.be3d_inertia`.

    Parameters
    ----------
    material : Material
    section : RectangularSection or CircularSection
        Uses ``A``, ``I2``, ``I3``, ``J = I2 + I3`` and ``k_t``.
    director_update : {"projected", "post-rotated", "none"}
        Update of the nodal directors after an accepted step (Sect. 3.6,
        :mod:`.be3d_directors`): a model event (:meth:`step_event`); the
        directors are the beam's event state, carried by the driver and kept
        in ``Result.model_state``. With ``"post-rotated"`` the update is also
        applied to the reference configuration (director ``e3``,
        ``theta = 0``), so that the values fixed by supports stay valid.
    director : array_like (3,), optional
        Initial director of every node; default ``e3`` of each node's
        reference frame (``theta_ref = 0``). Must not be parallel to the axis.
    axial_points, bending_points, inertia_points : int
        Gauss points of the axial term, of the bending and torsion terms,
        and of the rotary kinetic energy.
    update_below : float in (0, 1], optional
        Update the directors only when at some node the sine of the angle
        between director and axis (the norm of the projection of Eq. 99 of
        the unit director) falls below this value; None (default) updates
        after every step, as the chapter does. The fixed-step integrators
        carry on through an update at no cost; IDA re-initialises (order 1,
        small first step) and needs the threshold. Measured on B3 (2
        elements, IDA rtol 1e-6): after every step, 20,000 steps and as many
        restarts reached t = 0.055 s in 100 s CPU; with 0.5, the run to 3 s
        took 1,031 steps, no restart, 1.45 s CPU; with 0.9, 1,246 steps and 3
        restarts, 1.87 s. 0.5 keeps the projection well conditioned (angle
        between director and axis >= 30 degrees). When the directors are
        updated changes the motion by a discretisation error that vanishes
        with the mesh (O(h^2) in the strain energy): on this 2-element mesh
        the tip of B after 3 s differed by 2e-2 m between the update after
        every step (Lobatto IIIA, h = 1e-3) and none.
    kernel : {"auto", "numba", "numpy"}
        Implementation of the strain energy, internal forces, rotary inertia
        and dead-moment load. ``"numba"`` and ``"auto"`` (the default):
        compiled loops over elements x points
        (:class:`~.be3d_numba.BE3DCompiled`; the first call compiles or loads
        the on-disk cache). ``"numpy"``: vectorised NumPy
        (:class:`BE3DReference`), the readable reference (same results to
        rounding). Settable later through the ``kernel`` attribute.

    Attributes
    ----------
    EA : float
        Axial stiffness.
    curvature_stiffness : ndarray (3,)
        ``(G J k_t, E I2, E I3)``: the stiffnesses of the twist ``k1`` and the
        curvatures ``k2, k3`` (the diagonal of Eqs. 42/111).
    """

    name = "BE3D"
    dim = 3
    node_params = (-1.0, 1.0)
    node_coordinates = ("x", "y", "z", "x'", "y'", "z'", "theta")
    mass_is_constant = False
    kernel_twins = {"numpy": BE3DReference, "numba": _compiled}

    def __init__(self, material: Material, section: RectangularSection | CircularSection,
                 director_update: str = "projected", director: ArrayLike | None = None,
                 axial_points: int = 5, bending_points: int = 3, inertia_points: int = 3,
                 update_below: float | None = None, kernel: str = "auto") -> None:
        check_material_section(material, section, ("A", "I2", "I3", "J", "k_t"))
        self.material = material
        self.section = section
        self.director_update = choice("director_update", director_update, directors_.UPDATES)
        if update_below is not None and (isinstance(update_below, bool) or not isinstance(update_below, (int, float))
                                         or not 0.0 < update_below <= 1.0):
            raise ValueError(f"`update_below` must be None or a number in (0, 1], got {update_below!r}.")
        self.update_below = None if update_below is None else float(update_below)
        if director is not None:
            director = finite_vector("director", director, 3)
            if not np.linalg.norm(director) > 0:
                raise ValueError(f"`director` must be a non-zero vector, got {director.tolist()}.")
        self.director = director
        self.axial_points = positive_int("axial_points", axial_points)
        self.bending_points = positive_int("bending_points", bending_points)
        self.inertia_points = positive_int("inertia_points", inertia_points)
        E, G = material.E, material.G
        self.EA = E * section.A
        self.curvature_stiffness = np.array([G * section.J * section.k_t, E * section.I2, E * section.I3])
        self.rhoA = material.rho * section.A
        self.rhoJ = material.rho * section.J
        self.kernel = kernel

    def __repr__(self):
        return (f"BE3D(director_update={self.director_update!r}, axial_points={self.axial_points}, "
                f"bending_points={self.bending_points}, inertia_points={self.inertia_points}, "
                f"kernel={self._kernel!r})")

    # -- mesh -------------------------------------------------------------
    def reference_coordinates(self, points: np.ndarray, frames_: np.ndarray) -> np.ndarray:
        """``(r, e1, theta_ref)`` per node, ``theta_ref`` from :func:`.be3d_directors.reference_directors`."""
        _, theta = directors_.reference_directors(self.director, self.director_update, frames_)
        return np.concatenate([points, np.asarray(frames_, dtype=float)[:, :, 0], theta[:, None]], axis=1)

    def reference_state(self, points: np.ndarray, frames_: np.ndarray) -> dict:
        """``{"directors": (n_nodes, 3)}``: the nodal directors of the undeformed beam, for :meth:`prepare`."""
        directors, _ = directors_.reference_directors(self.director, self.director_update, frames_)
        return {"directors": directors}

    def support_coordinates(self, kind: str, frame: np.ndarray) -> tuple[str, ...]:
        """``"pin"``: r; ``"clamp"``: r, the slope components transverse to the reference tangent, theta.

        With a tangent along a global axis the axial slope component stays
        free (fixing it over-constrains the axial strain); otherwise all slope coordinates are fixed.
        """
        return clamp_coordinates(kind, frame, ("theta",) if kind == "clamp" else ())

    def prepare(self, q_ref: np.ndarray, lengths: np.ndarray, directors: ArrayLike | None = None) -> dict:
        """The geometry, with the nodal ``directors`` (n_el + 1, 3) of :meth:`reference_state` (None: fallback
        directors of :func:`.be3d_directors.fallback_directors`, e.g. for stacked copies of a mesh)."""
        q_ref = np.asarray(q_ref, dtype=float)
        lengths = np.asarray(lengths, dtype=float)
        if directors is None:
            directors = directors_.fallback_directors(self.director, q_ref)
        directors = np.array(directors, dtype=float)
        if directors.shape != (lengths.size + 1, 3):
            raise ValueError(f"`directors` must have shape {(lengths.size + 1, 3)} (one per node), "
                             f"got {directors.shape}.")
        directors.setflags(write=False)   # event state: replaced (Beam.bind), never changed in place
        geom = {"L": lengths, "directors": directors,
                "axial": PointRule(self.axial_points, lengths, DOF, N_EDOF),
                "bend": TorsionRule(self.bending_points, lengths),
                "inertia": TorsionRule(self.inertia_points, lengths),
                "M": translational_mass(lengths, DOF, N_EDOF, self.rhoA)}
        a = np.einsum("epin,en->epi", geom["axial"].Ba, q_ref)
        geom["slope_ref"] = np.linalg.norm(a, axis=-1)
        for key in ("bend", "inertia"):
            rule = geom[key]
            d, _ = director_field(geom["directors"], rule)
            directors_.check_director(d.reshape(-1, 3), np.einsum("epin,en->epi", rule.Ba, q_ref).reshape(-1, 3))
        local = local_variables(geom["directors"], q_ref, geom["bend"])
        geom["k_ref"] = np.stack([k.v for k in curvatures(*local, order=1)], axis=-1)
        return geom

    # -- fields at given points (diagnostics: exports, plots, tests) -------
    def _points(self, geom, s):
        return TorsionRule(np.atleast_1d(np.asarray(s, dtype=float)), geom["L"])

    def curvature(self, geom: dict, q: np.ndarray, s: ArrayLike) -> np.ndarray:
        """Twist and curvatures ``(k1, k2, k3)`` per xi at normalised coordinates ``s``, shape (n_el, n_pts, 3)."""
        local = local_variables(geom["directors"], q, self._points(geom, s))
        return np.stack([k.v for k in curvatures(*local, order=1)], axis=-1)

    def spin(self, geom: dict, q: np.ndarray, v: np.ndarray, s: ArrayLike) -> np.ndarray:
        """Angular velocity of the cross-section about the axis, ``omega . e1``, shape (n_el, n_pts)."""
        rule = self._points(geom, s)
        a = np.einsum("epin,en->epi", rule.Ba, q)
        d, _ = director_field(geom["directors"], rule)
        g, _ = spin_gradient(a, d)
        return np.einsum("epn,en->ep", rule.Nt, v) + np.einsum("epi,epin,en->ep", g, rule.Ba, v)

    def frames(self, geom: dict, q: np.ndarray, s: ArrayLike) -> np.ndarray:
        """Cross-section frames at normalised coordinates ``s``, shape (n_el, n_pts, 3, 3), columns e1, e2, e3."""
        a, _, th, _, d, _ = local_variables(geom["directors"], q, self._points(geom, s))
        F, _ = frames(a, th, d)
        return F

    # -- kernels ----------------------------------------------------------
    def mass_matrix(self, geom: dict) -> np.ndarray:
        """Constant part ``rho A int S^T S dxi`` (zero rows and columns for theta)."""
        return geom["M"]

    def shape_matrix(self, s: ArrayLike, lengths: ArrayLike) -> np.ndarray:
        N, _, _ = hermite(np.asarray(s, dtype=float), np.asarray(lengths, dtype=float))
        return hermite_operator(N, DOF, N_EDOF)

    def moment_load(self, geom: dict, q: np.ndarray, s: float, moment: np.ndarray, element: int,
                    tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Dead moment at ``s``: ``f = G^T M`` with the virtual rotation of the frame (:mod:`.be3d_moment`)."""
        return self.kernels.moment_load(geom, q, s, finite_vector("moment", moment, 3), element, tangent)

    def inertia(self, geom: dict, q: np.ndarray, v: np.ndarray, a: np.ndarray, tangent: bool = True) -> tuple:
        """Rotary inertia about the axis: ``f``, and ``df/dq, df/dv, df/da`` (exact).

        From ``T_rot = 1/2 int rho J omega1^2 dxi`` with the spin
        ``omega1 = w(q) . v`` (``w = N_theta + Sx^T g(r')``), Lagrange's
        equations give ``f = int rho J [w Omega + omega1 Sx^T (G - G^T) r'_dot]``,
        ``Omega = w . a + r'_dot^T G r'_dot``, ``G = dg/dr'``: the mass term
        ``M_rot(q) a`` plus gyroscopic terms (derivation in
        :mod:`.be3d_inertia`). Returns ``(f, None, None, None)`` when
        ``tangent`` is False.
        """
        return self.kernels.inertia(geom, q, v, a, tangent)

    def kinetic_energy_extra(self, geom: dict, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``1/2 int rho J omega1^2 dxi`` per element."""
        return self.kernels.kinetic_energy(geom, q, v)

    def mass_bilinear(self, geom: dict, q: np.ndarray, u: np.ndarray, w: np.ndarray, order: int = 2) -> tuple:
        """``1/2 u^T M_rot(q) w`` per element, its q-gradient and Hessian (the energy-momentum method's; by
        ``order`` 0, 1, 2), from the selected kernel."""
        return self.kernels.mass_bilinear(geom, q, u, w, order)

    # -- the director event (Sect. 3.6) -------------------------------------
    def event_state(self, geom: dict) -> dict:
        """``{"directors": (n_nodes, 3)}``: the nodal directors, carried by the driver between steps."""
        return {"directors": geom["directors"]}

    def bind(self, geom: dict, state: dict) -> dict:
        """``geom`` with the nodal directors of ``state`` (read-only; ``geom`` itself is unchanged)."""
        return directors_.bind(geom, state)

    def step_event(self, geom: dict, Q: np.ndarray, V: np.ndarray) -> tuple | None:
        """Director update of Sect. 3.6 (``director_update``, ``update_below``); None when not done.

        See :func:`.be3d_directors.update_directors`.
        """
        return directors_.step(geom, Q, V, self.director_update, self.update_below)
