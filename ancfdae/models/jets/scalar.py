"""Scalar jets in NumPy: value, exact gradient and Hessian of scalar expressions over a batch of points.

A :class:`Jet` carries a value and its exact gradient and Hessian with respect
to ``n`` local variables, for a whole batch of points at once: ``v`` has the
batch shape ``S`` (e.g. ``(n_el, n_pts)``), ``g`` the shape ``S + (n,)`` and
``h`` the shape ``S + (n, n)``. ``order`` 1 propagates gradients only (``h``
is None: residuals need no Hessians), ``order`` 2 Hessians too.

The BE3D element writes its curvature, twist and cross-section angular
velocity as short expressions in a few polynomial invariants of the slope
``r'`` and its derivative ``r''``; propagating jets through those expressions
gives the exact first and second derivatives without hand-expanded formulae
(the model contract asks for exact Jacobians, never finite differences). The
arithmetic operators are overloaded, so the expressions read as the chapter
writes them; the functions below are the same operations by name.

The compiled twin :mod:`.scalar_numba` offers ``mul``, ``chain``, ``recip``
and ``sqrt`` under the same names with the operands in the same order; there a
jet is a slot of work arrays instead of an object (see
:mod:`ancfdae.models.jets`).
"""
from __future__ import annotations

import numpy as np

__all__ = ["Jet", "mul", "recip", "sqrt", "cos", "sin", "chain"]


def _outer(a, b):
    return a[..., :, None] * b[..., None, :]


class Jet:
    """Value ``v``, gradient ``g`` and (for order 2) Hessian ``h`` of a scalar field over a batch of points."""

    __slots__ = ("v", "g", "h")
    # Make ``ndarray * Jet`` call Jet.__rmul__ instead of broadcasting over an object.
    __array_ufunc__ = None

    def __init__(self, v, g, h=None):
        self.v = v
        self.g = g
        self.h = h

    @property
    def order(self) -> int:
        """2 when Hessians are propagated, else 1."""
        return 1 if self.h is None else 2

    # -- arithmetic: the operators are the functions below --------------------
    def __add__(self, o):
        if isinstance(o, Jet):
            return Jet(self.v + o.v, self.g + o.g, None if self.h is None else self.h + o.h)
        return Jet(self.v + o, self.g, self.h)

    __radd__ = __add__

    def __neg__(self):
        return Jet(-self.v, -self.g, None if self.h is None else -self.h)

    def __sub__(self, o):
        return self + (-o)

    def __rsub__(self, o):
        return (-self) + o

    def __mul__(self, o):
        return mul(self, o)

    __rmul__ = __mul__

    def __truediv__(self, o):
        if isinstance(o, Jet):
            return mul(self, recip(o))
        return mul(self, 1.0 / np.asarray(o))

    def __rtruediv__(self, o):
        return mul(recip(self), o)


def mul(a: Jet, b) -> Jet:
    """``a * b`` of two jets, or of a jet and a constant (array)."""
    if isinstance(b, Jet):
        g = a.g * b.v[..., None] + b.g * a.v[..., None]
        h = None
        if a.h is not None:
            ab = _outer(a.g, b.g)
            h = a.h * b.v[..., None, None] + b.h * a.v[..., None, None] + ab + np.swapaxes(ab, -1, -2)
        return Jet(a.v * b.v, g, h)
    b = np.asarray(b)
    return Jet(a.v * b, a.g * b[..., None], None if a.h is None else a.h * b[..., None, None])


def chain(a: Jet, f0, f1, f2) -> Jet:
    """``phi(a)`` for a scalar function with ``phi(a) = f0``, ``phi' = f1``, ``phi'' = f2`` (chain rule)."""
    g = a.g * f1[..., None]
    h = None
    if a.h is not None:
        h = a.h * f1[..., None, None] + _outer(a.g, a.g) * f2[..., None, None]
    return Jet(f0, g, h)


def recip(a: Jet) -> Jet:
    """``1 / a``."""
    r = 1.0 / a.v
    return chain(a, r, -r * r, 2.0 * r * r * r)


def sqrt(a: Jet) -> Jet:
    """``sqrt(a)``."""
    s = np.sqrt(a.v)
    return chain(a, s, 0.5 / s, -0.25 / (s * a.v))


def cos(a: Jet) -> Jet:
    """``cos(a)``."""
    c, s = np.cos(a.v), np.sin(a.v)
    return chain(a, c, -s, -c)


def sin(a: Jet) -> Jet:
    """``sin(a)``."""
    c, s = np.cos(a.v), np.sin(a.v)
    return chain(a, s, c, -s)
