"""External loads on a beam: point forces and moments, gravity, distributed loads.

Every load except gravity carries a *time function* ``time(t) -> float`` that
scales it (constant 1 by default); :func:`ramp`, :func:`pulse` and :func:`hat`
build the common ones, any callable works. All loads are *dead*: their
direction is fixed in the global frame. A :class:`ancfdae.models.Beam` also
multiplies every load by its ``load_factor`` (the static solver steps it).

Where a load acts
-----------------
A point load acts at a node (``node=i``, negative indices count from the end)
or at any point of the beam axis (``s=`` arc length along the undeformed axis,
measured from node 0). A force ``F`` at axis point ``r(s) = S(s) q`` does the
virtual work ``F . S(s) dq``: its generalised force ``S(s)^T F`` is constant.

How a moment acts on slope coordinates
--------------------------------------
ANCF has no rotation coordinates, so a moment ``M`` works through the virtual
rotation ``delta phi`` of the cross-section frame at the load point, which the
element computes from its slopes (chapter Sect. 2.2): ``delta W = M . delta phi
= M . G(q) delta q``. In 2D, ``phi`` is the angle of the axis slope ``r'``:
``delta phi = (r' x delta r') . e_z / |r'|^2``; in 3D it is
``1/2 e_i x delta e_i`` of the element's frame (Eq. 7 for SQ3D, Eqs. 96-100 for
BE3D). The generalised force ``G(q)^T M`` depends on the configuration, so a
moment also contributes to the tangent stiffness. A planar dead moment is
conservative; a spatial one in general is not, which is why the energy monitor
integrates the power of every load except gravity.
"""
from __future__ import annotations

import numbers
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ._validate import finite_vector, positive

__all__ = ["PointForce", "PointMoment", "Gravity", "DistributedLoad", "constant", "ramp", "pulse", "hat"]

TimeFunction = Callable[[float], float]


def constant(value: float = 1.0) -> TimeFunction:
    """Time function equal to ``value`` for all t.

    Parameters
    ----------
    value : float

    Returns
    -------
    callable
        ``time(t) -> float``.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not np.isfinite(value):
        raise ValueError(f"`value` must be a finite real number, got {value!r}.")
    value = float(value)
    return lambda t: value


def ramp(t_end: float) -> TimeFunction:
    """Time function ``t / t_end`` up to ``t_end``, then 1.

    Parameters
    ----------
    t_end : float
        End of the ramp (> 0).

    Returns
    -------
    callable
        ``time(t) -> float``.
    """
    t_end = positive("t_end", t_end)
    return lambda t: min(max(t / t_end, 0.0), 1.0)


def pulse(T: float) -> TimeFunction:
    """Time function ``(1 - cos(2 pi t / T)) / 2`` for ``0 <= t <= T``, 0 after.

    The smooth load pulse that sets the flying beams of the chapter's
    Sect. 5.2 in motion.

    Parameters
    ----------
    T : float
        Duration of the pulse (> 0).

    Returns
    -------
    callable
        ``time(t) -> float``.
    """
    T = positive("T", T)
    return lambda t: 0.5 * (1.0 - np.cos(2.0 * np.pi * t / T)) if 0.0 <= t <= T else 0.0


def hat(t_peak: float) -> TimeFunction:
    """Time function ``t / t_peak`` up to ``t_peak``, down to 0 at ``2 t_peak``, 0 after.

    The hat-shaped load history of the spatial flying beam (chapter Sect. 5.3).

    Parameters
    ----------
    t_peak : float
        Time of the peak (> 0).

    Returns
    -------
    callable
        ``time(t) -> float``.
    """
    t_peak = positive("t_peak", t_peak)

    def f(t):
        if t <= 0.0 or t >= 2 * t_peak:
            return 0.0
        return t / t_peak if t <= t_peak else 2.0 - t / t_peak
    return f


def _check_time(time):
    if time is None:
        return constant(1.0)
    if not callable(time):
        raise ValueError(f"`time` must be a callable t -> float or None, got {time!r}.")
    return time


def _check_point(load) -> None:
    """Check where a point load acts (exactly one of ``node`` and ``s``) and fill in its time function.

    Shared by :class:`PointForce` and :class:`PointMoment` (frozen dataclasses: set through
    ``object.__setattr__``).
    """
    node, s = load.node, load.s
    if (node is None) == (s is None):
        raise ValueError(f"give exactly one of `node` and `s`, got node={node!r}, s={s!r}.")
    if node is not None and (isinstance(node, bool) or not isinstance(node, numbers.Integral)):
        raise ValueError(f"`node` must be an integer node index, got {node!r}.")
    if s is not None and (isinstance(s, bool) or not isinstance(s, numbers.Real) or not np.isfinite(s)):
        raise ValueError(f"`s` must be a finite arc length, got {s!r}.")
    object.__setattr__(load, "time", _check_time(load.time))


@dataclass(frozen=True)
class PointForce:
    """Dead force at a node or at axis point ``s``.

    Parameters
    ----------
    force : array_like, shape (dim,)
    node : int, optional
    s : float, optional
        Arc length along the undeformed axis.
    time : callable, optional
        Scale ``time(t)``; constant 1 if omitted.
    """

    force: np.ndarray
    node: int | None = None
    s: float | None = None
    time: TimeFunction | None = None

    def __post_init__(self):
        object.__setattr__(self, "force", finite_vector("force", self.force))
        _check_point(self)


@dataclass(frozen=True)
class PointMoment:
    """Dead moment at a node or at axis point ``s``.

    It acts through the virtual rotation of the cross-section frame, computed
    from the slopes (chapter Sect. 2.2); see the module docstring.

    Parameters
    ----------
    moment : float or array_like, shape (3,)
        A scalar (about e_z) for planar elements or a 3-vector for spatial ones.
    node : int, optional
    s : float, optional
        Arc length along the undeformed axis.
    time : callable, optional
        Scale ``time(t)``; constant 1 if omitted.
    """

    moment: np.ndarray
    node: int | None = None
    s: float | None = None
    time: TimeFunction | None = None

    def __post_init__(self):
        m = np.atleast_1d(np.asarray(self.moment, dtype=float)) if not isinstance(self.moment, str) else None
        if m is None or m.ndim != 1 or m.shape[0] not in (1, 3):
            raise ValueError(f"`moment` must be a scalar (2D) or a 3-vector, got {self.moment!r}.")
        finite_vector("moment", m)
        object.__setattr__(self, "moment", m)
        _check_point(self)

    def vector3(self) -> np.ndarray:
        """The moment as a 3-vector (a scalar is about e_z)."""
        return np.array([0.0, 0.0, self.moment[0]]) if self.moment.shape[0] == 1 else self.moment


@dataclass(frozen=True)
class Gravity:
    """Uniform gravity field; conservative, constant in time.

    Parameters
    ----------
    g : array_like, shape (dim,)
        Acceleration of gravity, e.g. ``(0, -9.81)``.
    """

    g: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "g", finite_vector("g", self.g))


@dataclass(frozen=True)
class DistributedLoad:
    """Dead line load on the whole beam.

    Parameters
    ----------
    w : array_like, shape (dim,)
        Force per unit undeformed length.
    time : callable, optional
        Scale ``time(t)``; constant 1 if omitted.
    """

    w: np.ndarray
    time: TimeFunction | None = None

    def __post_init__(self):
        object.__setattr__(self, "w", finite_vector("w", self.w))
        object.__setattr__(self, "time", _check_time(self.time))
