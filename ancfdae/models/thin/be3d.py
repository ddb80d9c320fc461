"""BE3D: the thin spatial ANCF beam with torsion, angle and director (chapter Sects. 3.5-3.6).

Two nodes with coordinates ``(x, y, z, x', y', z', theta)`` -- position, axial
slope and torsion angle -- 14 DOF per element: the cubic Hermite axis of
Eq. 62 and the linear angle of Eqs. 101-103. Kinematics in
:mod:`._be3d_kinematics`, inertia and director update in
:mod:`._be3d_dynamics`.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import choice, finite_vector, positive_int
from ...materials import CircularSection, Material, RectangularSection
from .be3d_inertia import UPDATES, rotary_inertia, rotary_kinetic_energy
from .be3d_directors import BE3DEvents
from .be3d_kinematics import curvature_energy, curvatures, director_field, frames, spin_gradient
from ..element import Element
from .._kernel_option import KernelOption
from ..jets import scalar as jet
from ..jets.scalar import Jet
from ..shapes import hermite, linear
from .spatial import (PointRule, assemble, axial_energy, check_material_section, clamp_coordinates,
                    hermite_operator, translational_mass)

__all__ = ["BE3D"]

# Per element: r_A 0:3, r'_A 3:6, theta_A 6, r_B 7:10, r'_B 10:13, theta_B 13.
_DOF = np.array([[0, 1, 2], [3, 4, 5], [7, 8, 9], [10, 11, 12]])
_THETA = np.array([6, 13])
_NDOF = 14
# Smallest admissible sine of the angle between director and axis in the reference configuration.
_PARALLEL_TOL = 1e-6


class BE3D(KernelOption, BE3DEvents, Element):
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
    :mod:`._be3d_dynamics`.

    Parameters
    ----------
    material : Material
    section : RectangularSection or CircularSection
        Uses ``A``, ``I2``, ``I3``, ``J = I2 + I3`` and ``k_t``.
    director_update : {"projected", "post-rotated", "none"}
        Update of the nodal directors after an accepted step (Sect. 3.6): a
        model event (:meth:`step_event`); the directors are the beam's event
        state, carried by the driver and kept in ``Result.model_state``. With ``"post-rotated"`` the update is
        also applied to the reference configuration (director ``e3``,
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
    kernel : {"auto", "numpy", "numba"}
        Implementation of the strain energy, internal forces, rotary inertia
        and dead-moment load. ``"numba"``: compiled loops over elements x
        points (:mod:`._be3d_numba`, :mod:`._be3d_inertia_numba`,
        :mod:`._be3d_moment_numba`; the first call compiles or loads the
        on-disk cache). ``"numpy"``: vectorised NumPy,
        the readable reference (same results to rounding). ``"auto"``
        (default): numba when importable. Settable later through the
        ``kernel`` attribute.
    """

    name = "BE3D"
    dim = 3
    node_params = (-1.0, 1.0)
    node_coordinates = ("x", "y", "z", "x'", "y'", "z'", "theta")
    mass_is_constant = False

    def __init__(self, material: Material, section: RectangularSection | CircularSection,
                 director_update: str = "projected", director: ArrayLike | None = None,
                 axial_points: int = 5, bending_points: int = 3, inertia_points: int = 3,
                 update_below: float | None = None, kernel: str = "auto") -> None:
        check_material_section(material, section, ("A", "I2", "I3", "J", "k_t"))
        self.material = material
        self.section = section
        self.director_update = choice("director_update", director_update, UPDATES)
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
        self.D = np.array([G * section.J * section.k_t, E * section.I2, E * section.I3])
        self.rhoA = material.rho * section.A
        self.rhoJ = material.rho * section.J
        self._pending = None
        self.kernel = kernel

    def __repr__(self):
        return (f"BE3D(director_update={self.director_update!r}, axial_points={self.axial_points}, "
                f"bending_points={self.bending_points}, inertia_points={self.inertia_points}, "
                f"kernel={self._kernel!r})")

    # -- mesh -------------------------------------------------------------
    def reference_coordinates(self, points: np.ndarray, frames_: np.ndarray) -> np.ndarray:
        """``(r, e1, theta_ref)`` per node; keeps the initial nodal directors for :meth:`prepare`.

        The director is ``e3`` of each node's frame (``theta_ref = 0``), or the
        given ``director`` with ``theta_ref`` the angle that turns its
        projected frame ``(e20, e30)`` into the node's ``(e2, e3)``.
        """
        frames_ = np.asarray(frames_, dtype=float)
        e1, e2, e3 = frames_[:, :, 0], frames_[:, :, 1], frames_[:, :, 2]
        theta = np.zeros(len(points))
        if self.director is not None:
            D = np.repeat(self.director[None, :], len(points), axis=0)
            _check_director(D, e1)
        if self.director is None or self.director_update == "post-rotated":
            D = e3.copy()
        else:
            F, _ = frames(e1, theta, D)
            # e3 = cos(theta) e30 - sin(theta) e20 and e2 = cos(theta) e20 + sin(theta) e30
            theta = np.arctan2(np.einsum("ni,ni->n", e2, F[:, :, 2]), np.einsum("ni,ni->n", e3, F[:, :, 2]))
        self._pending = D
        return np.concatenate([points, e1, theta[:, None]], axis=1)

    def support_coordinates(self, kind: str, frame: np.ndarray) -> tuple[str, ...]:
        """``"pin"``: r; ``"clamp"``: r, the slope components transverse to the reference tangent, theta.

        With a tangent along a global axis the axial slope component stays
        free (fixing it over-constrains the axial strain); otherwise all slope coordinates are fixed.
        """
        return clamp_coordinates(kind, frame, ("theta",) if kind == "clamp" else ())

    def _rule(self, n_points, lengths):
        rule = PointRule(n_points, lengths, _DOF, _NDOF)
        N, dN = linear(rule.s, lengths)
        rule.Nt = np.zeros(N.shape[:2] + (_NDOF,))
        rule.Nt[..., _THETA] = N
        rule.dNt = np.zeros(N.shape[:2] + (_NDOF,))
        rule.dNt[..., _THETA] = dN
        rule.lin = N[0]
        rule.L = lengths
        rule.Bx = np.concatenate([rule.Ba, rule.Bb, rule.Nt[:, :, None, :], rule.dNt[:, :, None, :]], axis=2)
        return rule

    def prepare(self, q_ref: np.ndarray, lengths: np.ndarray) -> dict:
        q_ref = np.asarray(q_ref, dtype=float)
        lengths = np.asarray(lengths, dtype=float)
        n_el = lengths.size
        D = self._pending
        self._pending = None
        if D is None or D.shape[0] != n_el + 1:
            D = self._fallback_directors(q_ref)
        D = np.array(D, dtype=float)
        D.setflags(write=False)   # event state: replaced (Beam.bind), never changed in place
        geom = {"L": lengths, "directors": D,
                "axial": PointRule(self.axial_points, lengths, _DOF, _NDOF),
                "bend": self._rule(self.bending_points, lengths),
                "inertia": self._rule(self.inertia_points, lengths),
                "M": translational_mass(lengths, _DOF, _NDOF, self.rhoA)}
        a = np.einsum("epin,en->epi", geom["axial"].Ba, q_ref)
        geom["slope_ref"] = np.linalg.norm(a, axis=-1)
        for key in ("bend", "inertia"):
            rule = geom[key]
            d, _ = director_field(geom["directors"], rule)
            _check_director(d.reshape(-1, 3), np.einsum("epin,en->epi", rule.Ba, q_ref).reshape(-1, 3))
        geom["k_ref"] = np.stack([k.v for k in self._curvatures(geom, q_ref, 1)], axis=-1)
        return geom

    def _fallback_directors(self, q_ref):
        """Directors when :meth:`prepare` is called without :meth:`reference_coordinates` first.

        The given ``director`` if any, else per node the global axis least
        aligned with the reference slope.
        """
        slopes = np.concatenate([q_ref[:, 3:6], q_ref[-1:, 10:13]])
        if self.director is not None:
            return np.repeat(self.director[None, :], len(slopes), axis=0)
        return np.eye(3)[np.argmin(np.abs(slopes), axis=1)]

    # -- kernels ----------------------------------------------------------
    @staticmethod
    def _local(geom, q, rule):
        """Slope, its derivative, angle, its derivative, director and its derivative at a rule's points."""
        d, dp = director_field(geom["directors"], rule)
        a = np.einsum("epin,en->epi", rule.Ba, q)
        b = np.einsum("epin,en->epi", rule.Bb, q)
        th = np.einsum("epn,en->ep", rule.Nt, q)
        dth = np.einsum("epn,en->ep", rule.dNt, q)
        return a, b, th, dth, d, np.broadcast_to(dp, d.shape)

    def _curvatures(self, geom, q, order, rule=None):
        return curvatures(*self._local(geom, q, geom["bend"] if rule is None else rule), order=order)

    def curvature(self, geom: dict, q: np.ndarray, s: ArrayLike) -> np.ndarray:
        """Twist and curvatures ``(k1, k2, k3)`` per xi at normalised coordinates ``s``, shape (n_el, n_pts, 3)."""
        rule = self._rule(np.atleast_1d(np.asarray(s, dtype=float)), geom["L"])
        return np.stack([k.v for k in self._curvatures(geom, q, 1, rule)], axis=-1)

    def spin(self, geom: dict, q: np.ndarray, v: np.ndarray, s: ArrayLike) -> np.ndarray:
        """Angular velocity of the cross-section about the axis, ``omega . e1``, shape (n_el, n_pts)."""
        rule = self._rule(np.atleast_1d(np.asarray(s, dtype=float)), geom["L"])
        a = np.einsum("epin,en->epi", rule.Ba, q)
        d, _ = director_field(geom["directors"], rule)
        g, _ = spin_gradient(a, d)
        return np.einsum("epn,en->ep", rule.Nt, v) + np.einsum("epi,epin,en->ep", g, rule.Ba, v)

    def mass_matrix(self, geom: dict) -> np.ndarray:
        """Constant part ``rho A int S^T S dxi`` (zero rows and columns for theta)."""
        return geom["M"]

    @staticmethod
    def _directors(geom):
        """The nodal directors (n_nodes, 3) the compiled kernels take as input (C-contiguous floats)."""
        return np.ascontiguousarray(geom["directors"], dtype=float)

    def _compiled_forces(self, geom, q, tangent):
        """(U, f, K) from the compiled kernel, with the nodal directors of ``geom``."""
        from .be3d_numba import be3d_forces
        ax, bd = geom["axial"], geom["bend"]
        return be3d_forces(np.ascontiguousarray(q, dtype=float), _DOF, _THETA, ax.dN, ax.wdx, geom["slope_ref"],
                           bd.dN, bd.ddN, bd.wdx, bd.lin, geom["L"], self._directors(geom),
                           geom["k_ref"], self.D, self.EA, bool(tangent))

    def strain_energy(self, geom: dict, q: np.ndarray) -> np.ndarray:
        if self._impl == "numba":
            return self._compiled_forces(geom, q, False)[0]
        U, _, _ = axial_energy(geom["axial"], q, geom["slope_ref"], self.EA, False)
        W, _ = curvature_energy(*self._local(geom, q, geom["bend"]), geom["k_ref"], self.D)
        return U + np.sum(geom["bend"].wdx * W, axis=1)

    def internal_forces(self, geom: dict, q: np.ndarray,
                        tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        if self._impl == "numba":
            _, f, K = self._compiled_forces(geom, q, tangent)
            return f, (K if tangent else None)
        _, f, K = axial_energy(geom["axial"], q, geom["slope_ref"], self.EA, tangent)
        rule = geom["bend"]
        if not tangent:
            # residual path: the chain rule written out, no Hessians
            _, grad = curvature_energy(*self._local(geom, q, rule), geom["k_ref"], self.D)
            return f + np.einsum("epvn,epv->en", rule.Bx, grad * rule.wdx[..., None]), None
        grad = 0.0
        hess = 0.0
        for i, ki in enumerate(self._curvatures(geom, q, 2)):
            wi = self.D[i] * rule.wdx
            ri = (ki.v - geom["k_ref"][..., i]) * wi
            grad = grad + ri[..., None] * ki.g
            hess = hess + ri[..., None, None] * ki.h + wi[..., None, None] * (ki.g[..., :, None] * ki.g[..., None, :])
        f = f + np.einsum("epvn,epv->en", rule.Bx, grad)
        return f, K + assemble(rule.Bx, hess)

    def shape_matrix(self, s: ArrayLike, lengths: ArrayLike) -> np.ndarray:
        N, _, _ = hermite(np.asarray(s, dtype=float), np.asarray(lengths, dtype=float))
        return hermite_operator(N, _DOF, _NDOF)

    def frames(self, geom: dict, q: np.ndarray, s: ArrayLike) -> np.ndarray:
        """Cross-section frames at normalised coordinates ``s``, shape (n_el, n_pts, 3, 3), columns e1, e2, e3."""
        rule = self._rule(np.atleast_1d(np.asarray(s, dtype=float)), geom["L"])
        a, _, th, _, d, _ = self._local(geom, q, rule)
        F, _ = frames(a, th, d)
        return F

    def moment_load(self, geom: dict, q: np.ndarray, s: float, moment: np.ndarray, element: int,
                    tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Dead moment at ``s``: ``f = G^T M`` with the virtual rotation of the frame.

        ``delta phi = e1 x delta e1 + (delta theta + g . delta r') e1``
        (the bending part and the spin of Eqs. 96-100 under a variation, see
        :mod:`._be3d_dynamics` for ``g``), hence
        ``f_r' = (M x e1)/|r'| + g (M . e1)`` and ``f_theta = M . e1``.
        """
        M = finite_vector("moment", moment, 3)
        if self._impl == "numba":
            from .be3d_moment_numba import be3d_moment
            D = self._directors(geom)
            f, K = be3d_moment(np.ascontiguousarray(q, dtype=float), _DOF, _THETA, float(s), float(geom["L"][element]),
                               D[element], D[element + 1], M, bool(tangent))
            return f, (K if tangent else None)
        L = geom["L"][[element]]
        s_ = np.array([float(s)])
        _, dN, _ = hermite(s_, L)
        N, _ = linear(s_, L)
        Sx = hermite_operator(dN, _DOF, _NDOF)[0, 0]
        Nt = np.zeros(_NDOF)
        Nt[_THETA] = N[0, 0]
        D = geom["directors"]
        d = N[0, 0, 0] * D[element] + N[0, 0, 1] * D[element + 1]
        a = Sx @ q
        I = np.eye(3)
        aj = [Jet(a[i], I[i]) for i in range(3)]
        sp = jet.sqrt(aj[0] * aj[0] + aj[1] * aj[1] + aj[2] * aj[2])
        e1 = [x / sp for x in aj]
        Me1 = M[0] * e1[0] + M[1] * e1[1] + M[2] * e1[2]
        Mxe1 = [M[1] * e1[2] - M[2] * e1[1], M[2] * e1[0] - M[0] * e1[2], M[0] * e1[1] - M[1] * e1[0]]
        g, G = spin_gradient(a, d)
        gj = [Jet(g[i], G[i]) for i in range(3)]
        fa = [Mxe1[i] / sp + gj[i] * Me1 for i in range(3)]
        f = Sx.T @ np.array([x.v for x in fa]) + Nt * Me1.v
        if not tangent:
            return f, None
        dfa = np.array([x.g for x in fa])
        return f, Sx.T @ dfa @ Sx + np.outer(Nt, Me1.g @ Sx)

    def inertia(self, geom: dict, q: np.ndarray, v: np.ndarray, a: np.ndarray, jacobian: bool = True) -> tuple:
        """Rotary inertia about the axis: ``f``, and ``df/dq, df/dv, df/da`` (exact).

        From ``T_rot = 1/2 int rho J omega1^2 dxi`` with the spin
        ``omega1 = w(q) . v`` (``w = N_theta + Sx^T g(r')``), Lagrange's
        equations give ``f = int rho J [w Omega + omega1 Sx^T (G - G^T) r'_dot]``,
        ``Omega = w . a + r'_dot^T G r'_dot``, ``G = dg/dr'``: the mass term
        ``M_rot(q) a`` plus gyroscopic terms (derivation in
        :mod:`._be3d_dynamics`). Returns ``(f, None, None, None)`` when
        ``jacobian`` is False.
        """
        if self._impl == "numba":
            from .be3d_inertia_numba import be3d_inertia
            rule = geom["inertia"]
            f, Kq, Dv, Ma = be3d_inertia(*(np.ascontiguousarray(x, dtype=float) for x in (q, v, a)), _DOF, _THETA,
                                         rule.dN, rule.wdx, rule.lin, self._directors(geom), self.rhoJ,
                                         bool(jacobian))
            return (f, Kq, Dv, Ma) if jacobian else (f, None, None, None)
        return rotary_inertia(geom["inertia"], geom, q, v, a, self.rhoJ, jacobian)

    def kinetic_energy_extra(self, geom: dict, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``1/2 int rho J omega1^2 dxi`` per element."""
        if self._impl == "numba":
            from .be3d_inertia_numba import be3d_kinetic_energy
            rule = geom["inertia"]
            return be3d_kinetic_energy(np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(v, dtype=float),
                                       _DOF, _THETA, rule.dN, rule.wdx, rule.lin, self._directors(geom),
                                       self.rhoJ)
        return rotary_kinetic_energy(geom["inertia"], geom, q, v, self.rhoJ)


def _check_director(d, e1):
    """Raise ValueError where a director is (nearly) parallel to the axis."""
    sin = np.linalg.norm(np.cross(d, e1), axis=-1) / (np.linalg.norm(d, axis=-1) * np.linalg.norm(e1, axis=-1))
    bad = np.flatnonzero(~(sin > _PARALLEL_TOL))
    if bad.size:
        raise ValueError(f"`director` must not be parallel to the beam axis (chapter Eq. 99 would be singular); "
                         f"sine of the angle {sin[bad[0]]:.3g} at point/node {int(bad[0])}, director "
                         f"{d[bad[0]].tolist()}, axis {e1[bad[0]].tolist()}.")
