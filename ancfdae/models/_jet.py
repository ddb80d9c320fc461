"""Second-order forward differentiation ("jets") of small vector expressions, vectorised over points.

The SQ elements need the frame of chapter Eq. 7 and its first *and second*
derivatives with respect to the cross-section slopes, for exact tangents. The
frame is a short chain of products, cross products, square roots and
reciprocals of at most six variables, so it is propagated here as a jet:
value ``v`` of shape ``(P, *shape)``, gradient ``g`` ``(P, *shape, K)`` and
Hessian ``h`` ``(P, *shape, K, K)`` over ``K`` variables, for ``P`` points at
once (no loop over points). Every rule is the plain product or chain rule, so
the derivatives are exact to rounding.
"""
from __future__ import annotations

import numpy as np

__all__ = ["Jet", "variables", "dot", "cross", "mul", "sqrt", "recip", "linear", "combine"]


class Jet:
    """Value, gradient and Hessian of a scalar (shape ``()``) or vector (shape ``(d,)``) quantity."""

    __slots__ = ("v", "g", "h")

    def __init__(self, v, g, h):
        self.v, self.g, self.h = v, g, h

    @property
    def is_vector(self) -> bool:
        return self.v.ndim == 2

    def __add__(self, other: "Jet") -> "Jet":
        return Jet(self.v + other.v, self.g + other.g, self.h + other.h)

    def __sub__(self, other: "Jet") -> "Jet":
        return Jet(self.v - other.v, self.g - other.g, self.h - other.h)

    def __neg__(self) -> "Jet":
        return Jet(-self.v, -self.g, -self.h)


def variables(*blocks: np.ndarray, derivatives: bool = True) -> list[Jet]:
    """Vector jets of independent variables, one per block of shape ``(P, d)``.

    With ``derivatives=False`` the jets carry no variables (K = 0): values only.
    """
    P = blocks[0].shape[0]
    K = sum(b.shape[1] for b in blocks) if derivatives else 0
    out, k = [], 0
    for b in blocks:
        d = b.shape[1]
        g = np.zeros((P, d, K))
        if derivatives:
            g[:, np.arange(d), k + np.arange(d)] = 1.0
            k += d
        out.append(Jet(b, g, np.zeros((P, d, K, K))))
    return out


def mul(a: Jet, b: Jet) -> Jet:
    """Scalar jet ``a`` times scalar or vector jet ``b``."""
    if b.is_vector:
        av, ag, ah = a.v[:, None], a.g[:, None, :], a.h[:, None, :, :]
    else:
        av, ag, ah = a.v, a.g, a.h
    o = ag[..., :, None] * b.g[..., None, :]
    return Jet(av * b.v, av[..., None] * b.g + ag * b.v[..., None],
               av[..., None, None] * b.h + ah * b.v[..., None, None] + o + np.swapaxes(o, -1, -2))


def dot(a: Jet, b: Jet) -> Jet:
    """Scalar product of two vector jets."""
    v = np.einsum("pc,pc->p", a.v, b.v)
    g = np.einsum("pck,pc->pk", a.g, b.v) + np.einsum("pc,pck->pk", a.v, b.g)
    o = np.einsum("pck,pcl->pkl", a.g, b.g)
    h = (np.einsum("pckl,pc->pkl", a.h, b.v) + np.einsum("pc,pckl->pkl", a.v, b.h)
         + o + np.swapaxes(o, -1, -2))
    return Jet(v, g, h)


def cross(a: Jet, b: Jet) -> Jet:
    """Cross product of two 3-vector jets."""
    def cx(x, y):
        return np.cross(x, y, axisa=1, axisb=1, axisc=1)
    v = cx(a.v, b.v)
    g = cx(a.g, b.v[:, :, None]) + cx(a.v[:, :, None], b.g)
    o = cx(a.g[:, :, :, None], b.g[:, :, None, :])          # (k, l) entry: a_k x b_l
    h = cx(a.h, b.v[:, :, None, None]) + cx(a.v[:, :, None, None], b.h) + o + np.swapaxes(o, -1, -2)
    return Jet(v, g, h)


def _unary(a: Jet, f, f1, f2) -> Jet:
    """Chain rule for a scalar function with value f, first and second derivatives f1, f2."""
    return Jet(f, f1[..., None] * a.g,
               f1[..., None, None] * a.h + f2[..., None, None] * a.g[..., :, None] * a.g[..., None, :])


def sqrt(a: Jet) -> Jet:
    r = np.sqrt(a.v)
    return _unary(a, r, 0.5 / r, -0.25 / (r * a.v))


def recip(a: Jet) -> Jet:
    inv = 1.0 / a.v
    return _unary(a, inv, -inv**2, 2.0 * inv**3)


def linear(M: np.ndarray, a: Jet) -> Jet:
    """Constant matrix ``M`` (d x d) applied to the components of a vector jet."""
    return Jet(np.einsum("ij,pj->pi", M, a.v), np.einsum("ij,pjk->pik", M, a.g),
               np.einsum("ij,pjkl->pikl", M, a.h))


def combine(weights, jets: list[Jet]) -> Jet:
    """``sum_k weights[k] * jets[k]`` with per-point constant weights (arrays of shape (P,))."""
    def w_(w, x):
        return w.reshape(w.shape + (1,) * (x.ndim - 1)) * x
    return Jet(sum(w_(w, j.v) for w, j in zip(weights, jets)), sum(w_(w, j.g) for w, j in zip(weights, jets)),
               sum(w_(w, j.h) for w, j in zip(weights, jets)))
