"""A driven point or slope: :class:`Prescribed` (rheonomic rows, e.g. a hub spinning a beam up).

The rows are linear in ``q`` with time-dependent coefficients (:class:`ancfdae.joints.rows.TimedTerm`): the
position ``r(q) - p(t) = 0`` and, planar, the slope direction ``r'(q) . (-sin th(t), cos th(t)) = 0``. The
time functions give their first two derivatives (the acceleration constraint and the work of the driving
forces need them exactly).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae.joints.base import Frame, Joint, axis
from ancfdae.joints.rows import Rows, TimedTerm, linear

__all__ = ["Prescribed"]


def _checked(arg, fn, size):
    """``fn(t) -> (value, first, second derivative)`` checked at every call (shape, finiteness)."""
    def call(t):
        try:
            out = fn(t)
            parts = [np.asarray(p, dtype=float).reshape(-1) for p in out]
        except (TypeError, ValueError) as exc:
            raise ValueError(f"`{arg}`(t) must return (value, d/dt, d2/dt2), got an error at t = {t:g}: {exc}") \
                from None
        if len(parts) != 3 or any(p.shape != (size,) or not np.all(np.isfinite(p)) for p in parts):
            raise ValueError(f"`{arg}`(t) must return three finite arrays of {size} numbers (value, d/dt, "
                             f"d2/dt2), got {out!r:.200} at t = {t:g}.")
        return parts
    return call


class _Cached:
    """One evaluation of a time function per time, shared by the rows' terms."""

    def __init__(self, fn):
        self.fn, self.t, self.value = fn, None, None

    def __call__(self, t):
        if t != self.t:
            self.value, self.t = self.fn(t), t
        return self.value


class Prescribed(Joint):
    """A body point (and, planar, its slope direction) follows given functions of time.

    Parameters
    ----------
    side : side
        ``(body, where)``.
    position : callable, optional
        ``position(t) -> (p, dp/dt, d2p/dt2)``, each of ``dim`` numbers: ``r(t) = p(t)``.
    angle : callable, optional
        Planar only: ``angle(t) -> (th, dth/dt, d2th/dt2)``: the frame vector ``axis`` (a beam's slope)
        points along ``(cos th, sin th)`` (its length is free).
    axis : int
        The frame vector the angle drives (default 0).
    name : str, optional

    Notes
    -----
    The work of the driving forces, ``int lam . dg/dt dt``, is what an energy monitor adds to the balance.
    """

    kind = "Prescribed"

    def __init__(self, side, *, position=None, angle=None, axis: int = 0, name: str | None = None) -> None:
        super().__init__((("side", side),), name)
        if side == "ground":
            raise ValueError("`side` must be a body side (body, where), got 'ground'.")
        if position is None and angle is None:
            raise ValueError("Prescribed needs `position` or `angle` (or both), got neither.")
        for arg, fn in (("position", position), ("angle", angle)):
            if fn is not None and not callable(fn):
                raise ValueError(f"`{arg}` must be a callable t -> (value, d/dt, d2/dt2), got {fn!r}.")
        self.position, self.angle, self.axis = position, angle, axis

    def rows(self, frames: tuple[Frame, ...], q0: np.ndarray, n: int) -> Rows:
        dim = self.check_dim(frames)
        (f,) = frames
        label = self.label(frames)
        rows = Rows(n)
        if self.position is not None:
            idx = linear(rows, f"{label}.r", f.point)
            p = _Cached(_checked("position", self.position, dim))
            for k, i in enumerate(idx):
                rows.add_timed([i], TimedTerm(lambda t, k=k: tuple(x[k] for x in p(t)),
                                              sp.csr_matrix((1, n)), np.array([-1.0])))
        if self.angle is not None:
            if dim != 2:
                raise ValueError(f"{label}: `angle` drives a planar slope; a {dim}D body needs `position` only.")
            d = axis(f, "axis", self.axis)
            th = _Cached(_checked("angle", self.angle, 1))
            i = rows.add(f"{label}.angle", sp.csr_matrix((1, n)), 0.0)
            X = sp.csr_matrix(d.X)

            def minus_sin(t):
                a, w, al = (x[0] for x in th(t))
                return -np.sin(a), -np.cos(a) * w, np.sin(a) * w * w - np.cos(a) * al

            def cos(t):
                a, w, al = (x[0] for x in th(t))
                return np.cos(a), -np.sin(a) * w, -np.cos(a) * w * w - np.sin(a) * al
            rows.add_timed([i], TimedTerm(minus_sin, X[0], d.x0[:1]))
            rows.add_timed([i], TimedTerm(cos, X[1], d.x0[1:]))
        return rows
