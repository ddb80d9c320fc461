"""Vector jets in NumPy: value, exact gradient and Hessian of small vector expressions, over points at once.

The SQ elements need the frame of chapter Eq. 7 and its first *and second*
derivatives with respect to the cross-section slopes, for exact tangents. The
frame is a short chain of products, cross products, square roots and
reciprocals of at most six variables, so it is propagated here as a jet:
value ``v`` of shape ``(P, *shape)``, gradient ``g`` ``(P, *shape, K)`` and
Hessian ``h`` ``(P, *shape, K, K)`` over ``K`` variables, for ``P`` points at
once (no loop over points). Every rule is the plain product or chain rule, so
the derivatives are exact to rounding. ``order`` says how much is propagated:
a jet of order 1 carries no Hessian (``h is None``), one of order 0 no
gradient either: the residual pays only for what it uses.

The compiled twin :mod:`.vector_numba` has the same functions (``variable``,
``dot``, ``cross``, ``mul``, ``chain``, ``sqrt``, ``recip``, ``turn``) with the
operands in the same order; ``combine`` is NumPy's only (the compiled kernels
sum inline).
"""
from __future__ import annotations

import numpy as np

__all__ = ["Jet", "variable", "dot", "cross", "mul", "chain", "sqrt", "recip", "turn", "combine", "lin", "constant", "atan2"]

# (a_y, -a_x) = TURN a: a 2-vector turned by -90 degrees.
_TURN = np.array([[0.0, 1.0], [-1.0, 0.0]])


class Jet:
    """Value, gradient and Hessian of a scalar (shape ``()``) or vector (shape ``(d,)``) quantity."""

    __slots__ = ("v", "g", "h")

    def __init__(self, v, g=None, h=None):
        self.v, self.g, self.h = v, g, h

    @property
    def is_vector(self) -> bool:
        return self.v.ndim == 2

    def __neg__(self) -> "Jet":
        return Jet(-self.v, None if self.g is None else -self.g, None if self.h is None else -self.h)


def variable(x: np.ndarray, x0: int, d: int, first: int, n: int, order: int = 2) -> Jet:
    """The d-vector jet of the independent variables ``x[:, x0:x0 + d]``, numbered ``first .. first + d - 1`` of ``n``."""
    block = x[:, x0:x0 + d]
    P = block.shape[0]
    g = h = None
    if order >= 1:
        g = np.zeros((P, d, n))
        g[:, np.arange(d), first + np.arange(d)] = 1.0
    if order >= 2:
        h = np.zeros((P, d, n, n))
    return Jet(block, g, h)


def _sym(o):
    return o + np.swapaxes(o, -1, -2)


def mul(a: Jet, b: Jet, sign: float = 1.0) -> Jet:
    """``sign * a * b``: scalar jet ``a`` times scalar or vector jet ``b``."""
    e = (slice(None), None) if b.is_vector else (slice(None),)
    if sign != 1.0:   # exact: a sign flip rounds symmetrically, so this is -(a * b) to the bit
        a = Jet(sign * a.v, None if a.g is None else sign * a.g, None if a.h is None else sign * a.h)
    av = a.v[e]
    v = av * b.v
    if a.g is None:
        return Jet(v)
    ag = a.g[e]
    g = av[..., None] * b.g + ag * b.v[..., None]
    if a.h is None:
        return Jet(v, g)
    h = av[..., None, None] * b.h + a.h[e] * b.v[..., None, None] + _sym(ag[..., :, None] * b.g[..., None, :])
    return Jet(v, g, h)


def dot(a: Jet, b: Jet) -> Jet:
    """Scalar product of two vector jets."""
    v = np.einsum("pc,pc->p", a.v, b.v)
    if a.g is None:
        return Jet(v)
    g = np.einsum("pck,pc->pk", a.g, b.v) + np.einsum("pc,pck->pk", a.v, b.g)
    if a.h is None:
        return Jet(v, g)
    h = (np.einsum("pckl,pc->pkl", a.h, b.v) + np.einsum("pc,pckl->pkl", a.v, b.h)
         + _sym(np.einsum("pck,pcl->pkl", a.g, b.g)))
    return Jet(v, g, h)


def _cx(x, y):
    """Cross product over axis 1 (broadcasting over the trailing axes)."""
    return np.stack([x[:, 1] * y[:, 2] - x[:, 2] * y[:, 1],
                     x[:, 2] * y[:, 0] - x[:, 0] * y[:, 2],
                     x[:, 0] * y[:, 1] - x[:, 1] * y[:, 0]], axis=1)


def cross(a: Jet, b: Jet) -> Jet:
    """Cross product of two 3-vector jets."""
    v = _cx(a.v, b.v)
    if a.g is None:
        return Jet(v)
    g = _cx(a.g, b.v[:, :, None]) + _cx(a.v[:, :, None], b.g)
    if a.h is None:
        return Jet(v, g)
    h = (_cx(a.h, b.v[:, :, None, None]) + _cx(a.v[:, :, None, None], b.h)
         + _sym(_cx(a.g[:, :, :, None], b.g[:, :, None, :])))    # a_k x b_l + a_l x b_k
    return Jet(v, g, h)


def chain(a: Jet, f0, f1, f2) -> Jet:
    """``phi(a)`` of a scalar jet for a function with value ``f0`` and derivatives ``f1``, ``f2`` at ``a``."""
    if a.g is None:
        return Jet(f0)
    g = f1[..., None] * a.g
    if a.h is None:
        return Jet(f0, g)
    return Jet(f0, g, f1[..., None, None] * a.h + f2[..., None, None] * a.g[..., :, None] * a.g[..., None, :])


def sqrt(a: Jet) -> Jet:
    """``sqrt(a)`` of a scalar jet."""
    r = np.sqrt(a.v)
    return chain(a, r, 0.5 / r, -0.25 / (r * a.v))


def recip(a: Jet) -> Jet:
    """``1 / a`` of a scalar jet."""
    inv = 1.0 / a.v
    return chain(a, inv, -inv**2, 2.0 * inv**3)


def turn(a: Jet, sign: float) -> Jet:
    """``sign * (a_y, -a_x)`` of a 2-vector jet: ``a`` turned by -90 degrees (times sign)."""
    M = sign * _TURN
    return Jet(np.einsum("ij,pj->pi", M, a.v), None if a.g is None else np.einsum("ij,pjk->pik", M, a.g),
               None if a.h is None else np.einsum("ij,pjkl->pikl", M, a.h))


def combine(weights, jets: list[Jet]) -> Jet:
    """``sum_k weights[k] * jets[k]`` with per-point constant weights (arrays of shape (P,))."""
    def part(name):
        xs = [getattr(j, name) for j in jets]
        if xs[0] is None:
            return None
        return sum(w.reshape(w.shape + (1,) * (x.ndim - 1)) * x for w, x in zip(weights, xs))
    return Jet(part("v"), part("g"), part("h"))


def lin(ca, a: Jet, cb, b: Jet) -> Jet:
    """``ca a + cb b`` of two jets of the same shape; ``ca``, ``cb`` constants or per-point arrays (P,)."""
    def part(x, y):
        if x is None:
            return None
        shape = (-1,) + (1,) * (x.ndim - 1)
        return np.reshape(ca, shape) * x + np.reshape(cb, shape) * y if np.ndim(ca) or np.ndim(cb) else ca * x + cb * y
    return Jet(part(a.v, b.v), part(a.g, b.g), part(a.h, b.h))


def constant(value: np.ndarray, K: int, order: int = 2) -> Jet:
    """A jet of the constant ``value`` (P,) or (P, d) over ``K`` variables (zero derivatives)."""
    value = np.asarray(value, dtype=float)
    return Jet(value, np.zeros(value.shape + (K,)) if order >= 1 else None,
               np.zeros(value.shape + (K, K)) if order >= 2 else None)


def atan2(s: Jet, c: Jet) -> Jet:
    """The angle ``atan2(s, c)`` of two scalar jets (for ``s = sin, c = cos`` of an angle times a length)."""
    v = np.arctan2(s.v, c.v)
    if s.g is None:
        return Jet(v)
    r2 = c.v * c.v + s.v * s.v
    g = (c.v[:, None] * s.g - s.v[:, None] * c.g) / r2[:, None]
    if s.h is None:
        return Jet(v, g)
    # d/dx_l of (c s_k - s c_k) / r2, dr2/dx_l = 2 (c c_l + s s_l); the antisymmetric parts cancel exactly
    dr2 = 2.0 * (c.v[:, None] * c.g + s.v[:, None] * s.g)
    gd = g[:, :, None] * dr2[:, None, :]
    h = (c.v[:, None, None] * s.h - s.v[:, None, None] * c.h - 0.5 * (gd + np.swapaxes(gd, -1, -2))) / r2[:, None, None]
    return Jet(v, g, h)
