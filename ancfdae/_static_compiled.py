"""A load step of :func:`ancfdae.solve_static` as one compiled call, where the beam offers it.

With full Newton, a :class:`ancfdae.models.Beam` whose element's compiled kernel offers a static entry point
(BE2D), constant mass, no point moments and no event state has the residual ``f(q) - lambda f_ext`` with
``f_ext`` fixed over the solve; :class:`CompiledStatic` runs a load step's Newton iterations in one compiled
call (:mod:`ancfdae.models.beam.static_numba`) and turns its status into the
:class:`~ancfdae.integrators._newton.NewtonSolver`'s outcome, message and counters, as the Python iteration
would give them (the tests hold both equal). Any other model, or ``jacobian="modified"``, takes the Python
iteration.
"""
from __future__ import annotations

import numpy as np

from .integrators._linsolve import COMPILED_SOLVE_MAX, _band_map, use_banded
from .integrators import _newton_messages as says
from .integrators._newton import DIVERGENCE_RATE
from .integrators._newton_records import NewtonOutcome
from .models.beam import static_numba as sn
from .models.beam.beam import Beam

__all__ = ["CompiledStatic"]


class CompiledStatic:
    """A beam's compiled load step at time ``t`` (see the module docstring); made by :meth:`offer`."""

    def __init__(self, beam: Beam, t: float, fn, element_args: tuple, band: tuple) -> None:
        kl, ku, ldab, flat, _ = band
        asm, n = beam._asm, beam.n_dof
        self._beam, self._fn, self._element = beam, fn, tuple(element_args)
        self._f_ext = np.ascontiguousarray(beam._load_set.external(t, None, beam.geom, False)[0], dtype=float)
        self._arrays = (beam._q_fixed, beam._gather, asm._vec_all, asm._slot_all)
        self._kl, self._ku, self._flat = kl, ku, flat
        self._ab, self._piv = np.zeros((n, ldab)), np.zeros(n, dtype=np.int64)
        self._kdata, self._rbuf = np.empty(asm.nnz + 1), np.empty(n + 1)

    @classmethod
    def offer(cls, model, t: float, jacobian: str, events: bool) -> CompiledStatic | None:
        """The compiled load step for ``model`` at ``t``, or None where the Python iteration must run."""
        if type(model) is not Beam or jacobian != "full" or events:
            return None
        el = model.element
        if not model.mass_is_constant or model._load_set.moments or not el.kernel_twins:
            return None
        offer = getattr(el.kernels, "static_newton", None)
        if offer is None or el.fused_kernel(model.geom) is None:
            return None
        asm = model._asm
        band = _band_map(asm.indptr, asm.indices, model.n_dof)
        if not use_banded(model.n_dof, band, asm.nnz) or band[0] + band[1] > COMPILED_SOLVE_MAX:
            return None    # the Python iteration factorises otherwise (SuperLU or LAPACK's substitution)
        fn, element_args = offer(model.geom)
        return cls(model, t, fn, element_args, band)

    def solve(self, solver, x0: np.ndarray, residual_atol: float) -> NewtonOutcome:
        """``solver.solve`` of the load step at the beam's ``load_factor`` from ``x0``: the same outcome,
        message and counters (``solver.stats``) as the Python iteration."""
        o = solver.options
        x = np.array(x0, dtype=float)
        r = np.empty(x.size)
        fpar = np.array([o.tol, residual_atol, o.xtol, o.contraction, DIVERGENCE_RATE,
                         float(self._beam.load_factor)])
        ipar = np.array([o.max_iter, self._kl, self._ku], dtype=np.int64)
        status, k, evals, err, rate, threshold = self._fn(x, r, self._f_ext, fpar, ipar, self._flat, self._ab,
                                                          self._piv, self._kdata, self._rbuf, self._arrays,
                                                          self._element)
        st = solver.stats
        st.solves += 1
        st.residual_evals += evals
        st.iterations += k
        st.jacobian_evals += k
        st.factorizations += k
        ok = status in (sn.CONVERGED_INITIAL, sn.CONVERGED, sn.STAGNANT)
        if not ok:
            st.failed_solves += 1
        return NewtonOutcome(x, ok, k, err, _message(status, k, err, rate, threshold, o.max_iter), 0.0)


def _message(status, k, err, rate, threshold, max_iter):
    """The :class:`~ancfdae.integrators._newton.NewtonSolver`'s message for the compiled solve's ending ``status``."""
    if status == sn.CONVERGED_INITIAL:
        return says.converged_initial()
    if status == sn.CONVERGED:
        return says.converged(k)
    if status == sn.STAGNANT:
        return says.stagnant(k, err)
    if status == sn.INITIAL_NOT_FINITE:
        return says.initial_not_finite()
    if status == sn.DX_NOT_FINITE:
        return says.dx_not_finite()
    if status == sn.R_NOT_FINITE:
        return says.r_not_finite(k)
    if status == sn.DIVERGING:
        return says.diverging(rate, k)
    return says.not_converged(max_iter, err, threshold)
