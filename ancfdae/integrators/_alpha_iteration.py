"""Newton iterations of the Newmark family as one compiled call, for a model that offers them.

An iteration of :class:`~ancfdae.integrators._newton.NewtonSolver` is ``dx = J^-1 r`` (substitution
with the cached banded factors), ``x <- x - dx``, the weighted state ``(qa0 + cqa x, va0 + cva x,
aa0 + caa x)`` and the residual there. A model that offers them compiled
(:meth:`ancfdae.models.Beam.compiled_residual`: BE2D beams without point moments) runs the iterations
of a step in one call instead of some twenty Python-level calls each (argument checks, the counting
proxy, the kernel's argument tuple, the load pass, two norms, the substitution wrapper), up to the
iteration that needs a decision -- converged, not contracting, non-finite -- which the solver then
takes in Python as before (contract in :mod:`ancfdae.models.beam.iteration_numba`).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["AlphaIteration"]

_NO_LU = np.zeros((2, 2), order="F")   # the band factors' types (Fortran order), for a residual-only call
_NO_PIV = np.zeros(1, dtype=np.int32)


class AlphaIteration:
    """The compiled iterations of one Newmark-family step, the step's constants bound.

    Parameters
    ----------
    compiled : CompiledResidual
        The model's offer (:class:`ancfdae.models.beam.compiled.CompiledResidual`).
    counter : CountingModel
        The run's counting proxy: each iteration that evaluates a residual counts one.
    ta : float
        The time of the weighted state.
    qa0, va0, aa0, cqa, cva, caa
        The weighted state's affine map of the unknown ``x``.
    """

    __slots__ = ("_fn", "_args", "_tail", "_counter")

    def __init__(self, compiled, counter, ta, qa0, va0, aa0, cqa, cva, caa):
        self._fn = compiled.iterations
        self._args = (qa0, va0, aa0, float(cqa), float(cva), float(caa), compiled.load_factor,
                      compiled.external(ta)) + compiled.arrays
        self._tail = (np.empty(qa0.size + 1), np.empty(1)) + compiled.element_args
        self._counter = counter

    def residual(self, x):
        """The residual at ``x`` (the solver's first evaluation), compiled, counted."""
        self._counter.n_residual += 1
        r = np.empty(x.size)
        self._fn(x, r, 0.0, 0, 0.0, 0.0, _NO_LU, 0, 0, _NO_PIV, *self._args, *self._tail)
        return r

    def __call__(self, x, r, lu, err, max_k, contraction, threshold):
        """``(max|dx|, err_new, err_prev, k)`` after ``k`` compiled iterations that update ``x`` and ``r`` in
        place, or None when ``lu`` has no compiled real substitution (see
        :meth:`ancfdae.integrators._newton.NewtonSolver.solve`)."""
        lub = getattr(lu, "lub", None)
        if lub is None or not lu._compiled or lu.dtype != np.float64:
            return None
        out = self._fn(x, r, float(err), int(max_k), float(contraction), float(threshold), lub, lu.kl, lu.ku,
                       lu.piv, *self._args, *self._tail)
        # the Python iteration evaluates no residual after a non-finite correction
        self._counter.n_residual += out[3] if math.isfinite(out[0]) else out[3] - 1
        return out
