"""Count the floating-point operations a compiled kernel executes, by running its Python source on counting numbers.

Run in a process with ``NUMBA_DISABLE_JIT=1`` (then ``@njit`` functions are their plain Python
source): the kernel's inputs are arrays of :class:`Counted`, the NumPy allocations inside the kernel
module are redirected to such arrays, and every ``+ - * /`` and ``sqrt`` on a floating value adds one
to the count. Index arithmetic (Python ints) and comparisons are not counted; a fused multiply-add
counts 2. :func:`count` is that of the loop bodies as written, including multiplications by zero that
the code does not skip -- the operations the compiled kernel executes. :func:`useful` leaves out the
operations whose result needs no arithmetic: a product with a factor 0 or +-1, a sum or difference with
a term 0, a quotient with numerator 0 or denominator +-1 (structural zeros and ones: an identity block,
a shape function that vanishes at a node, a sign). A kernel's rate in useful flops is comparable across
layouts that do or do not skip such operations.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["Counted", "CountingArray", "counting", "count", "useful", "patch_numpy"]

_count = [0]
_useful = [0]
_TRIVIAL = {"+": (0.0,), "-": (0.0,), "*": (0.0, 1.0, -1.0)}


def count() -> int:
    """Operations counted so far."""
    return _count[0]


def useful() -> int:
    """Operations counted so far that needed arithmetic (see the module docstring)."""
    return _useful[0]


def _is_trivial(op, a, b):
    """Whether ``a op b`` (``a`` the left operand) needs no arithmetic."""
    if op == "/":
        return a == 0.0 or b in (1.0, -1.0)
    triv = _TRIVIAL[op]
    return a in triv or b in triv


def _val(x):
    return x.v if isinstance(x, Counted) else x


_OPS = {"+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b, "/": lambda a, b: a / b}


class Counted:
    """A float that counts the arithmetic done with it."""

    __slots__ = ("v",)

    def __init__(self, v):
        self.v = float(v)

    def _op(self, other, op, left=True):
        _count[0] += 1
        a, b = (self.v, float(_val(other))) if left else (float(_val(other)), self.v)
        if not _is_trivial(op, a, b):
            _useful[0] += 1
        return Counted(_OPS[op](a, b))

    def __add__(self, o): return self._op(o, "+")
    def __radd__(self, o): return self._op(o, "+", False)
    def __sub__(self, o): return self._op(o, "-")
    def __rsub__(self, o): return self._op(o, "-", False)
    def __mul__(self, o): return self._op(o, "*")
    def __rmul__(self, o): return self._op(o, "*", False)
    def __truediv__(self, o): return self._op(o, "/")
    def __rtruediv__(self, o): return self._op(o, "/", False)
    def __neg__(self): return Counted(-self.v)
    def __float__(self): return self.v
    def __eq__(self, o): return self.v == _val(o)
    def __ne__(self, o): return self.v != _val(o)
    def __lt__(self, o): return self.v < _val(o)
    def __gt__(self, o): return self.v > _val(o)
    def __hash__(self): return hash(self.v)

    def sqrt(self):
        _count[0] += 1
        _useful[0] += 1
        return Counted(math.sqrt(self.v))


class CountingArray(np.ndarray):
    """Object array whose stored floats become :class:`Counted` (so work arrays count too)."""

    def __setitem__(self, key, value):
        if isinstance(value, (float, int)) and not isinstance(value, bool):
            value = Counted(value)
        elif isinstance(value, np.ndarray) and value.dtype != object:
            value = counting(value)
        super().__setitem__(key, value)


def counting(a) -> CountingArray:
    """A float array as a :class:`CountingArray` of :class:`Counted` (integer arrays are returned as they are)."""
    a = np.asarray(a)
    if a.dtype.kind in "iub":
        return a
    out = np.empty(a.shape, dtype=object).view(CountingArray)
    flat = out.reshape(-1)
    for i, x in enumerate(a.reshape(-1)):
        np.ndarray.__setitem__(flat, i, Counted(x))
    return out


class _NumpyShim:
    """``np`` for a kernel module: float allocations are counting arrays, everything else is NumPy."""

    def __getattr__(self, name):
        return getattr(np, name)

    @staticmethod
    def zeros(shape, dtype=float):
        return counting(np.zeros(shape)) if dtype is float else np.zeros(shape, dtype)

    @staticmethod
    def empty(shape, dtype=float):
        return counting(np.zeros(shape)) if dtype is float else np.zeros(shape, dtype)

    @staticmethod
    def sqrt(x):
        return x.sqrt() if isinstance(x, Counted) else np.sqrt(x)


def patch_numpy(*modules):
    """Point the ``np`` of each kernel module at the counting shim."""
    for m in modules:
        m.np = _NumpyShim()
