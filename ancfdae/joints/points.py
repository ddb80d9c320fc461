"""Joints between points: :class:`Spherical` (points coincide: the planar pin), :class:`Distance` (a massless
rod) and :class:`Prismatic` (a point stays on a line).

Each builds its rows from the sides' affine points (:mod:`ancfdae.joints.rows`): Spherical is linear in
``q``, Distance quadratic, Prismatic linear on a ground line and quadratic on a body's line.
"""
from __future__ import annotations

import numpy as np

from ancfdae.joints.base import Frame, Joint, axis, constant, normals, vector
from ancfdae.joints.rows import Rows, dot, linear

__all__ = ["Spherical", "Distance", "Prismatic"]


class Spherical(Joint):
    """The points of two sides coincide: ``r_a - r_b = 0`` (dim rows, linear in ``q``).

    Planar: a pin (revolute about the normal of the plane). Spatial: a ball joint.

    Parameters
    ----------
    a, b : side
        ``"ground"`` or ``(body, where)``; the ground's point is the other side's initial point unless
        ``at`` is given.
    at : array_like, optional
        The ground point (only with a ground side).
    name : str, optional
        Labels the rows.
    """

    kind = "Spherical"

    def __init__(self, a, b, *, at=None, name: str | None = None) -> None:
        super().__init__((("a", a), ("b", b)), name)
        self.at = at

    def rows(self, frames: tuple[Frame, ...], q0: np.ndarray, n: int) -> Rows:
        dim = self.check_dim(frames)
        pa, pb = _points(self, frames, q0, n, dim)
        rows = Rows(n)
        linear(rows, self.label(frames), pa - pb)
        return rows


class Distance(Joint):
    """The points of two sides keep their distance: ``(|r_a - r_b|^2 - L^2) / 2 = 0`` (one quadratic row).

    Parameters
    ----------
    a, b : side
        ``"ground"`` or ``(body, where)``.
    length : float, optional
        ``L``; default the initial distance (must then be positive).
    at : array_like, optional
        The ground point, required with a ground side (its default, the other side's initial point, would
        make a zero distance, which is refused).
    name : str, optional
    """

    kind = "Distance"

    def __init__(self, a, b, *, length: float | None = None, at=None, name: str | None = None) -> None:
        super().__init__((("a", a), ("b", b)), name)
        if length is not None:
            if isinstance(length, bool) or not isinstance(length, (int, float, np.floating, np.integer)) \
                    or not np.isfinite(length) or length <= 0:
                raise ValueError(f"`length` must be a positive number, got {length!r}.")
        self.length, self.at = length, at

    def rows(self, frames: tuple[Frame, ...], q0: np.ndarray, n: int) -> Rows:
        dim = self.check_dim(frames)
        pa, pb = _points(self, frames, q0, n, dim)
        d = pa - pb
        L = self.length if self.length is not None else float(np.linalg.norm(d.value(q0)))
        if L <= 0:
            raise ValueError(f"{self.label(frames)}: the initial distance is zero; give `length` (or use "
                             "Spherical for coinciding points).")
        rows = Rows(n)
        # 1/2 (d.d - L^2): dot() gives d.d with A = 2 X^T X, so halve every part
        i = dot(rows, self.label(frames), d, d, -L * L)
        rows.b[i] = 0.5 * rows.b[i]
        rows.c[i] = 0.5 * rows.c[i]
        rows.A[i] = None if rows.A[i] is None else 0.5 * rows.A[i]
        return rows


class Prismatic(Joint):
    """A point stays on a line: ``(r_a - r_b) · n_k = 0`` for the normals ``n_k`` of the line (dim - 1 rows).

    Parameters
    ----------
    point : side
        The side whose point slides, ``(body, where)``.
    line : side
        ``"ground"`` (a fixed line through ``at``, default the point's initial position, along
        ``direction``) or ``(body, where)``: the line through that body point along its frame vector
        ``axis`` (planar: the normal is that vector turned by 90 degrees, linear in ``q``) or normal to the
        frame vectors ``normals`` (spatial: two indices; the rows are quadratic).
    direction : array_like, optional
        The ground line's direction (required with a ground line).
    axis : int, optional
        Planar body line: the frame vector along the line.
    normals : tuple of two int, optional
        Spatial body line: the frame vectors normal to the line.
    at : array_like, optional
    name : str, optional
    """

    kind = "Prismatic"

    def __init__(self, point, line, *, direction=None, axis: int | None = None, normals: tuple | None = None,
                 at=None, name: str | None = None) -> None:
        super().__init__((("point", point), ("line", line)), name)
        if point == "ground":
            raise ValueError("`point` must be a body side (body, where), got 'ground'.")
        self.direction, self.axis, self.normals, self.at = direction, axis, normals, at

    def rows(self, frames: tuple[Frame, ...], q0: np.ndarray, n: int) -> Rows:
        dim = self.check_dim(frames)
        fp, fl = frames
        rows, label = Rows(n), self.label(frames)
        if fl.ground:
            if self.direction is None:
                raise ValueError(f"{label}: a ground line needs `direction`, got None.")
            u = vector("direction", self.direction, dim, unit=True)
            p0 = vector("at", self.at, dim) if self.at is not None else fp.point.value(q0)
            d = fp.point - constant(p0, n)
            for k, nk in enumerate(normals(u)):
                dot(rows, f"{label}[{k}]", d, constant(nk, n))
            return rows
        if self.at is not None or self.direction is not None:
            raise ValueError(f"{label}: `at` and `direction` are for a ground line; a body's line is given by "
                             "`axis` (planar) or `normals` (spatial).")
        d = fp.point - fl.point
        if dim == 2:
            w = axis(fl, "axis", 0 if self.axis is None else self.axis).rotated()
            dot(rows, label, d, w)
            return rows
        if self.normals is None or len(self.normals) != 2:
            raise ValueError(f"{label}: a spatial body line needs `normals`, two indices of frame vectors of "
                             f"{fl.label} normal to the line, got {self.normals!r}.")
        for k, i in enumerate(self.normals):
            dot(rows, f"{label}[{k}]", d, axis(fl, "normals", i))
        return rows


def _points(joint: Joint, frames: tuple[Frame, ...], q0: np.ndarray, n: int, dim: int) -> tuple:
    """The two sides' points as affine maps of q; a ground side is the fixed point ``joint.at`` (default: the
    body's point in ``q0``, so the joint holds the initial configuration)."""
    fa, fb = frames
    if joint.at is not None and not (fa.ground or fb.ground):
        raise ValueError(f"`at` is the ground point: {joint.label(frames)} has no ground side.")
    body = fb if fa.ground else fa
    ground = vector("at", joint.at, dim) if joint.at is not None else body.point.value(q0)
    return (constant(ground, n) if fa.ground else fa.point), (constant(ground, n) if fb.ground else fb.point)
