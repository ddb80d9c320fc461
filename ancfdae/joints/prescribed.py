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
    """One evaluation of a time function per time, shared by the rows' terms; :meth:`table` evaluates it at
    many times at once (the compiled index-3 steps take the rows' weights of their coming steps as a table)."""

    def __init__(self, fn, raw, size):
        self.fn, self.raw, self.size, self.t, self.value = fn, raw, size, None, None
        self._times, self._table = None, None

    def __call__(self, t):
        if t != self.t:
            self.value, self.t = self.fn(t), t
        return self.value

    def table(self, times: np.ndarray) -> np.ndarray:
        """``(k, 3, size)``: value and two derivatives at each of ``times`` (kept for the same array object).

        One call of the user's function per time and one check of the whole table; a table that fails the
        check is evaluated again through the checked call, which names the time and the fault."""
        if times is not self._times:
            try:
                tab = np.array([self.raw(t) for t in times], dtype=float)
            except (TypeError, ValueError):
                tab = None
            if tab is not None and self.size == 1 and tab.shape == (times.size, 3):
                tab = tab[:, :, None]
            if tab is None or tab.shape != (times.size, 3, self.size) or not np.all(np.isfinite(tab)):
                tab = np.array([self.fn(t) for t in times], dtype=float).reshape(times.size, 3, self.size)
            self._times, self._table = times, tab
        return self._table


class _Component:
    """``phi(t)`` of the ``k``-th coordinate of a prescribed position (and its table of values)."""

    def __init__(self, p: _Cached, k: int) -> None:
        self.p, self.k = p, k

    def __call__(self, t):
        return tuple(x[self.k] for x in self.p(t))

    def table(self, times: np.ndarray) -> np.ndarray:
        """``phi`` and its two derivatives at each of ``times``, (k, 3)."""
        return self.p.table(times)[:, :, self.k]


class _AngleTerm:
    """``-sin th(t)`` (``cos=False``) or ``cos th(t)`` with two derivatives: the slope-direction row's factors."""

    def __init__(self, th: _Cached, cos: bool) -> None:
        self.th, self.cos = th, cos

    def __call__(self, t):
        a, w, al = (x[0] for x in self.th(t))
        if self.cos:
            return np.cos(a), -np.sin(a) * w, -np.cos(a) * w * w - np.sin(a) * al
        return -np.sin(a), -np.cos(a) * w, np.sin(a) * w * w - np.cos(a) * al

    def table(self, times: np.ndarray) -> np.ndarray:
        """``phi`` and its two derivatives at each of ``times``, (k, 3) (the expressions of ``__call__``)."""
        tab = self.th.table(times)[:, :, 0]
        a, w, al = tab[:, 0], tab[:, 1], tab[:, 2]
        if self.cos:
            return np.column_stack((np.cos(a), -np.sin(a) * w, -np.cos(a) * w * w - np.sin(a) * al))
        return np.column_stack((-np.sin(a), -np.cos(a) * w, np.sin(a) * w * w - np.cos(a) * al))


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
            p = _Cached(_checked("position", self.position, dim), self.position, dim)
            for k, i in enumerate(idx):
                rows.add_timed([i], TimedTerm(_Component(p, k), sp.csr_matrix((1, n)), np.array([-1.0])))
        if self.angle is not None:
            if dim != 2:
                raise ValueError(f"{label}: `angle` drives a planar slope; a {dim}D body needs `position` only.")
            d = axis(f, "axis", self.axis)
            th = _Cached(_checked("angle", self.angle, 1), self.angle, 1)
            i = rows.add(f"{label}.angle", sp.csr_matrix((1, n)), 0.0)
            X = sp.csr_matrix(d.X)
            rows.add_timed([i], TimedTerm(_AngleTerm(th, False), X[0], d.x0[:1]))
            rows.add_timed([i], TimedTerm(_AngleTerm(th, True), X[1], d.x0[1:]))
        return rows
