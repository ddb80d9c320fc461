"""Second-order forward-mode automatic differentiation of scalar expressions ("jets"), with operators.

A :class:`Jet` carries a value and its exact gradient and Hessian with respect
to ``n`` local variables, for a whole batch of points at once: ``v`` has the
batch shape ``S`` (e.g. ``(n_el, n_pts)``), ``g`` the shape ``S + (n,)`` and
``h`` the shape ``S + (n, n)``; ``h`` is None in first-order mode (residuals
need gradients only, tangents need Hessians too).

The BE3D element writes its curvature, twist and cross-section angular
velocity as short expressions in a few polynomial invariants of the slope
``r'`` and its derivative ``r''``; propagating jets through those expressions
gives the exact first and second derivatives without hand-expanded formulae
(the model contract asks for exact Jacobians, never finite differences).
:mod:`._jet` holds the vector-valued, function-style jets of the SQ elements;
this module overloads the arithmetic operators of scalar jets instead, which
keeps the BE3D expressions readable as written in the chapter.
"""
from __future__ import annotations

import numpy as np

__all__ = ["Jet"]


def _outer(a, b):
    return a[..., :, None] * b[..., None, :]


class Jet:
    """Value, gradient and (optionally) Hessian of a scalar field over a batch of points."""

    __slots__ = ("v", "g", "h")
    # Make ``ndarray * Jet`` call Jet.__rmul__ instead of broadcasting over an object.
    __array_ufunc__ = None

    def __init__(self, v, g, h=None):
        self.v = v
        self.g = g
        self.h = h

    @property
    def second(self) -> bool:
        """True when Hessians are propagated."""
        return self.h is not None

    # -- arithmetic ---------------------------------------------------------
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
        if isinstance(o, Jet):
            a, b = self, o
            g = a.g * b.v[..., None] + b.g * a.v[..., None]
            h = None
            if a.h is not None:
                ab = _outer(a.g, b.g)
                h = a.h * b.v[..., None, None] + b.h * a.v[..., None, None] + ab + np.swapaxes(ab, -1, -2)
            return Jet(a.v * b.v, g, h)
        o = np.asarray(o)
        return Jet(self.v * o, self.g * o[..., None], None if self.h is None else self.h * o[..., None, None])

    __rmul__ = __mul__

    def __truediv__(self, o):
        if isinstance(o, Jet):
            return self * o.reciprocal()
        return self * (1.0 / np.asarray(o))

    def __rtruediv__(self, o):
        return self.reciprocal() * o

    def _chain(self, f0, f1, f2):
        """Compose with a scalar function given its value and first two derivatives."""
        g = self.g * f1[..., None]
        h = None
        if self.h is not None:
            h = self.h * f1[..., None, None] + _outer(self.g, self.g) * f2[..., None, None]
        return Jet(f0, g, h)

    def reciprocal(self):
        r = 1.0 / self.v
        return self._chain(r, -r * r, 2.0 * r * r * r)

    def sqrt(self):
        s = np.sqrt(self.v)
        return self._chain(s, 0.5 / s, -0.25 / (s * self.v))

    def square(self):
        return self._chain(self.v * self.v, 2.0 * self.v, np.full_like(self.v, 2.0))

    def cos(self):
        c, s = np.cos(self.v), np.sin(self.v)
        return self._chain(c, -s, -c)

    def sin(self):
        c, s = np.cos(self.v), np.sin(self.v)
        return self._chain(s, c, -s)

