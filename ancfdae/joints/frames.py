"""Joints that hold frames as well as points: :class:`Rigid` (a weld) and :class:`Revolute` (a spatial hinge).

Frame vectors are those of the bodies' attachments (a beam node: its slope vectors; see
:meth:`ancfdae.models.Beam.attachment`). A weld keeps the frame vectors of one side fixed combinations of the
other's, with the coefficients of the initial configuration: linear rows. A hinge keeps an axis of one side
normal to two vectors of the other: bilinear rows.
"""
from __future__ import annotations

import numpy as np

from ancfdae.joints.base import Frame, Joint, axis, constant, normals, vector
from ancfdae.joints.rows import Affine, Rows, dot, linear

__all__ = ["Rigid", "Revolute"]

#: a weld's frame vector must be a combination of the other side's to this relative accuracy
_FIT_TOL = 1e-9


class Rigid(Joint):
    """A weld: the points coincide and the frame vectors keep their initial relation (at any angle).

    To the ground the point keeps its initial position and every frame vector its initial *direction*
    (``d . n_k = 0`` for the normals ``n_k`` of that direction; its length, a beam's axial stretch, stays
    free): for the thin elements the same as a clamp by elimination (``supports={0: "clamp"}``, which
    leaves the axial slope free for the same reason), with the reaction forces as multipliers; with
    ``fix_lengths=True`` the lengths are kept too (``u . d = |d0|``), the clamp of SQ2D/SQ3D. Between
    two bodies ``d_b,k = sum_j C_kj e_j`` with ``e_j`` the frame vectors of side ``a`` (planar: also those
    turned by 90 degrees) and ``C`` fitted in the initial configuration: linear rows, rotation-invariant
    (beams welded at an angle stay welded at that angle as they turn; a slope that stretches carries the
    other along). Side ``b``'s frame vectors must be combinations of ``a``'s: a spatial weld to a body
    with a single frame vector (Cable3D) can only continue it along its axis.

    Parameters
    ----------
    a, b : side
        ``"ground"`` or ``(body, where)``.
    fix_lengths : bool
        To the ground only: keep the frame vectors' lengths as well as their directions.
    name : str, optional
    """

    kind = "Rigid"

    def __init__(self, a, b, *, fix_lengths: bool = False, name: str | None = None) -> None:
        super().__init__((("a", a), ("b", b)), name)
        if not isinstance(fix_lengths, bool):
            raise ValueError(f"`fix_lengths` must be True or False, got {fix_lengths!r}.")
        self.fix_lengths = fix_lengths

    def rows(self, frames: tuple[Frame, ...], q0: np.ndarray, n: int) -> Rows:
        dim = self.check_dim(frames)
        fa, fb = frames
        label = self.label(frames)
        rows = Rows(n)
        if fa.ground or fb.ground:
            body = fb if fa.ground else fa
            linear(rows, f"{label}.r", body.point - constant(body.point.value(q0), n))
            for k, d in enumerate(body.axes):
                u = vector(f"frame vector {k} of {body.label}", d.value(q0), dim, unit=True)
                for j, nj in enumerate(normals(u)):
                    dot(rows, f"{label}.d{k}[{j}]", d, constant(nj, n))
                if self.fix_lengths:
                    dot(rows, f"{label}.|d{k}|", d, constant(u, n), -float(u @ d.value(q0)))
            return rows
        if self.fix_lengths:
            raise ValueError(f"{label}: `fix_lengths` is for a weld to the ground; between bodies the frame "
                             "vectors are tied with their lengths.")
        linear(rows, f"{label}.r", fa.point - fb.point)
        basis = list(fa.axes) + ([d.rotated() for d in fa.axes] if dim == 2 else [])
        if not basis and fb.axes:
            raise ValueError(f"{label}: side `a` has no frame vectors to weld the frame of `b` to.")
        E = np.column_stack([e.value(q0) for e in basis]) if basis else np.zeros((dim, 0))
        for k, d in enumerate(fb.axes):
            target = d.value(q0)
            coef = np.linalg.lstsq(E, target, rcond=None)[0]
            miss = np.linalg.norm(E @ coef - target)
            if miss > _FIT_TOL * max(np.linalg.norm(target), 1e-300):
                raise ValueError(f"{label}: frame vector {k} of {fb.label} is not a combination of the frame "
                                 f"vectors of {fa.label} (misfit {miss:.3g}); a weld needs side `a` to span it "
                                 "(swap the sides, or weld to a body with a full frame).")
            linear(rows, f"{label}.d{k}", d - Affine.combination(coef, basis))
        return rows


class Revolute(Joint):
    """A spatial hinge: the points coincide and an axis of side ``a`` stays normal to two vectors of ``b``.

    Rows: ``r_a - r_b = 0`` (3) and ``d_a . n_b,k = 0`` (k = 1, 2): with bodies on both sides bilinear in
    ``q``; to the ground, whose normals are constant, linear. Planar hinges are :class:`Spherical` joints.

    Parameters
    ----------
    a : side
        ``(body, where)``: its frame vector ``axis`` is the hinge axis.
    b : side
        ``"ground"`` (the hinge axis stays along ``ground_axis``, default the initial axis of ``a``) or
        ``(body, where)``: its frame vectors ``normals`` stay normal to the axis.
    axis : int
        Index of the frame vector of ``a`` along the hinge (default 0: a beam's slope).
    normals : tuple of two int, optional
        Indices of frame vectors of ``b`` normal to the hinge (required for a body ``b``).
    ground_axis : array_like, optional
        The hinge axis of a ground ``b``.
    at : array_like, optional
        The ground point (default the initial point of ``a``).
    name : str, optional
    """

    kind = "Revolute"
    dims = (3,)

    def __init__(self, a, b, *, axis: int = 0, normals: tuple | None = None, ground_axis=None, at=None,
                 name: str | None = None) -> None:
        super().__init__((("a", a), ("b", b)), name)
        if a == "ground":
            raise ValueError("`a` must be a body side (body, where) holding the hinge axis; put 'ground' as `b`.")
        self.axis, self.normals, self.ground_axis, self.at = axis, normals, ground_axis, at

    def rows(self, frames: tuple[Frame, ...], q0: np.ndarray, n: int) -> Rows:
        dim = self.check_dim(frames)
        fa, fb = frames
        label = self.label(frames)
        rows = Rows(n)
        d_a = axis(fa, "axis", self.axis)
        if fb.ground:
            p0 = vector("at", self.at, dim) if self.at is not None else fa.point.value(q0)
            linear(rows, f"{label}.r", fa.point - constant(p0, n))
            u = (vector("ground_axis", self.ground_axis, dim, unit=True) if self.ground_axis is not None
                 else vector("axis of a", d_a.value(q0), dim, unit=True))
            for k, nk in enumerate(normals(u)):
                dot(rows, f"{label}.axis[{k}]", d_a, constant(nk, n))
            return rows
        if self.at is not None or self.ground_axis is not None:
            raise ValueError(f"{label}: `at` and `ground_axis` are for a ground side `b`.")
        if self.normals is None or len(self.normals) != 2:
            raise ValueError(f"{label}: `normals` must be two indices of frame vectors of {fb.label} normal to "
                             f"the hinge, got {self.normals!r}.")
        linear(rows, f"{label}.r", fa.point - fb.point)
        for k, i in enumerate(self.normals):
            dot(rows, f"{label}.axis[{k}]", d_a, axis(fb, "normals", i))
        return rows
