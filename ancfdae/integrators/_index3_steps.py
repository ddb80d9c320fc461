"""Whole index-3 steps of the Newmark family on a System as one compiled call, between the driver's stops.

When nothing needs the state between two output times the driver asks the stepper for every step up to the
next one at once (:meth:`ancfdae.integrators.newmark._AlphaFamily.steps_until`). On a constrained model that
is a :class:`ancfdae.System` of one beam whose element offers compiled index-3 steps (BE2D:
:func:`ancfdae.models.thin.be2d_numba.be2d_index3_steps`) and rigid bodies, with every constraint row in the
compiled set (its :attr:`~ancfdae.System.compiled_arrays`, :mod:`ancfdae.system_compiled`), :class:`Index3Steps`
runs the steps in one compiled call (contract and decisions in
:mod:`ancfdae.integrators._index3_steps_numba`): the predictor, the modified-Newton iterations, the refresh
of the KKT matrix and its LU (band storage, in the band order of :attr:`SystemArrays.kkt`), the update of ``q, v, a, ah, lam`` and the counters. The time functions
(the joints' drives, the rigid bodies' and the beam's loads) are evaluated here, before the call, at the ends
of the coming steps: one call of each user function per step (a table kept for :data:`TABLE_STEPS` steps),
not one per iteration.

A step that needs a decision of Python (a failure, the solver's retry) is taken by the ordinary Python step,
which redoes it from its start with the factors the compiled steps left (their band factors are handed
over as such). The Python path stays the reference: the tests hold states, multipliers and counters equal
to it on B5 and B6 (the LU in band order rounds differently from LAPACK's of the System's order, so states agree to
round-off).
"""
from __future__ import annotations

import numpy as np

from ancfdae.integrators import _index3_steps_numba as sn
from ancfdae.integrators._alpha_index3 import EXTRAPOLATE_TOL
from ancfdae.integrators._index3_kkt_numba import kkt_solve
from ancfdae.integrators._linsolve import _Banded
from ancfdae.integrators._newton import _Factor
from ancfdae.integrators.driver import GRID_TOL
from ancfdae.integrators.protocol import StepOutcome
from ancfdae.system_compiled import SystemArrays

__all__ = ["Index3Steps"]

#: at most this many steps per compiled call (Ctrl-C and the progress bar are served between calls)
STEPS_PER_CALL = 500
_NO_TIMES = np.zeros(0)

#: the time functions are tabulated this many steps ahead: one table serves the calls up to several output times
#: (the user's functions are called once per step either way; the Python around them is paid once per table)
TABLE_STEPS = 256


class _KKTFactors:
    """The compiled steps' band factors of the KKT matrix (band order), handed to the Python solver (``solve``
    as its factors')."""

    __slots__ = ("ab", "piv", "kkt")

    def __init__(self, ab, piv, kkt):
        self.ab, self.piv, self.kkt = ab, piv, kkt

    def solve(self, rhs):
        rhs = np.ascontiguousarray(rhs, dtype=float)
        return kkt_solve(self.ab, self.piv, self.kkt, rhs, np.empty(rhs.size), np.empty(rhs.size))


class Index3Steps:
    """A System's compiled index-3 steps for one Newmark-family stepper (see the module docstring).

    Use :meth:`offer`; the constructor takes what it found there.
    """

    def __init__(self, stepper, arrays: SystemArrays) -> None:
        s, o, model = stepper, stepper.newton.options, stepper.model.wrapped
        self._fn, self._stepper, self._arrays = arrays.compiled.index3_steps, stepper, arrays
        f = np.zeros(sn.N_FPAR)
        f[[sn.T0, sn.H, sn.T_BOUND, sn.BETA, sn.GAMMA, sn.ALPHA_M, sn.ALPHA_F, sn.TOL, sn.CONTRACTION,
           sn.GRID_TOL, sn.MSCALE, sn.XTOL, sn.LOAD_FACTOR, sn.FLOOR_FACTOR, sn.EXTRAPOLATE_TOL]] = (
            s.t0, s.h, s.t_bound, s.beta, s.gamma, s.alpha_m, s.alpha_f, o.tol, o.contraction, GRID_TOL,
            s._mscale, o.xtol, arrays.load_factor, s.FLOOR_ROUNDOFF, EXTRAPOLATE_TOL)
        self._fpar = f
        N, kl, ku = model.n_dof + model.n_constraints, arrays.kkt[1], arrays.kkt[2]
        # the pivots with band_factor's trims of the factors (3 N), read by kkt_solve
        self._AB, self._piv = np.zeros((N, 2 * kl + ku + 1)), np.zeros(3 * N, dtype=np.int64)
        self._ABs, self._pivs = np.zeros_like(self._AB), np.zeros(3 * N, dtype=np.int64)
        self._no_band = (np.zeros((1, 1), order="F"), np.zeros(1, dtype=np.int32))   # LAPACK's types
        self._table, self._grid = (0, np.zeros((0, 3, arrays.n_weights)), None), None   # (first step, W, E), grid

    @classmethod
    def offer(cls, stepper) -> "Index3Steps | None":
        """The compiled steps for ``stepper``'s constrained model, or None when it is not such a System
        (:attr:`ancfdae.System.compiled_arrays`) or Newton is not modified."""
        if stepper.newton.options.jacobian != "modified":
            return None
        arrays = getattr(stepper.model.wrapped, "compiled_arrays", None)
        return None if arrays is None else cls(stepper, arrays)

    def _tables(self, t_stop, max_count, t_next):
        """``(W, E)``: the time weights with their two derivatives and the beam's external force at the ends of the
        coming steps (up to ``t_stop``; where a time function fails before, up to ``t_next``, the next output time:
        the call stops there), or ``(None, None)`` when it fails before ``t_next`` (the Python steps reach it and
        fail at its step). Tabulated :data:`TABLE_STEPS` steps ahead and kept: one table serves several calls."""
        s = self._stepper
        h, first = s.h, s.n_steps + 1
        k, k_next = (int(max(1, min(max_count, (tt - s.t) / h + 2))) for tt in (t_stop, t_next))
        start, W, E = self._table
        if not (start <= first and first + k <= start + W.shape[0] and self._grid == (s.t0, h, s.t_bound)):
            W = E = None
            for size in (max(k, TABLE_STEPS), k, k_next):   # a bad time ahead: only the steps needed now
                t_new = s.t0 + (first + np.arange(size)) * h
                t_new[t_new >= s.t_bound - GRID_TOL * h] = s.t_bound
                t_new = t_new[:int(np.searchsorted(t_new, s.t_bound)) + 1]   # nothing past the end
                try:
                    W, E = self._arrays.weights(t_new, True), self._arrays.external(t_new)
                    break
                except ValueError:
                    continue
            if W is None:
                return None, None
            start, self._table, self._grid = first, (first, W, E), (s.t0, h, s.t_bound)
        i = first - start
        return W[i:], (E if E.shape[0] == 1 else E[i:])

    def run(self, t_stop: float, max_count: int, t_out=None) -> tuple[StepOutcome, int, tuple | None]:
        """``(outcome, taken, samples)`` as :meth:`ancfdae.integrators.newmark._AlphaFamily.steps_sampling`: with the
        coming output times ``t_out`` (``t_stop`` the last one this call may reach), ``samples = (t, q, v, a, lam)``
        at those that accepted steps reached (rows; None without ``t_out``)."""
        s = self._stepper
        newton = s.newton
        lu = newton._lu
        inner = getattr(lu, "_lu", None)
        kind, lub, bpiv, kl, ku = sn.NONE, *self._no_band, 0, 0
        if isinstance(inner, _KKTFactors) and inner.ab is self._AB:
            kind = sn.OWN
        elif isinstance(inner, _Banded) and inner.dtype == np.float64:
            kind, lub, bpiv, kl, ku = sn.BAND, inner.lub, inner.piv, inner.kl, inner.ku
        elif lu is not None:
            return s.step(), 0, None
        max_count = min(max_count, STEPS_PER_CALL)
        T_rec = _NO_TIMES
        if t_out is not None:   # at most max_count - 1 steps accepted here: the next output time stops the call
            T_rec = np.array(t_out[:max_count - 1], dtype=float)   # a copy: the steps' times are written into it
            if T_rec.size < len(t_out):
                t_stop = min(t_stop, float(t_out[T_rec.size]))
        W, E = self._tables(t_stop, max_count, t_stop if t_out is None or not len(t_out) else float(t_out[0]))
        if W is None:
            return s.step(), 0, None
        f = self._fpar.copy()
        f[sn.T], f[sn.T_STOP], f[sn.H_MATRIX], f[sn.ATOL], f[sn.FLOOR] = (s.t, t_stop, s._h_matrix or 0.0, s._atol,
                                                                          s._floor)
        last = s._last
        ipar = np.array((s.n_steps, max_count, newton.options.max_iter, kind, s._h_matrix is not None, kl, ku,
                         last is not None, s.predictor != "constant"), dtype=np.int64)
        n, m = s.q.size, s.lam.size
        S, P, L = np.empty((4, n)), np.empty((4, n)), np.empty((2, m))
        S[0], S[1], S[2], S[3], L[0], L[1] = s.q, s.v, s.a, s._ah, s.lam, s.lam
        if last is not None:   # the predictor's second point
            f[sn.H_LAST], P[3], L[1] = last
        out = np.zeros(sn.N_OUT, dtype=np.int64)
        a = self._arrays
        rec = (np.empty((T_rec.size, n)), np.empty((T_rec.size, n)), np.empty((T_rec.size, n)),
               np.empty((T_rec.size, m)))
        self._fn(S, P, L, f, ipar, out, self._AB, self._piv, self._ABs, self._pivs, lub, bpiv, W, E, a.cons, a.rigid,
                 a.beam, a.element_args, a.kkt, T_rec, *rec)
        done, status, iterations, evals, jacs, k = (int(x) for x in out)
        samples = None if t_out is None else (T_rec[:k], *(x[:k] for x in rec))
        st = newton.stats
        st.iterations += iterations
        st.residual_evals += evals
        st.solves += done
        st.jacobian_evals += jacs
        st.factorizations += jacs
        s.model.n_residual += evals
        s.model.n_jacobian += jacs
        s._floor = float(f[sn.FLOOR])
        s._h_matrix = float(f[sn.H_MATRIX]) if ipar[sn.HAVE_H] else None
        if ipar[sn.KIND] == sn.OWN and kind != sn.OWN or ipar[sn.KIND] == sn.NONE:
            newton._lu = None
            if ipar[sn.KIND] == sn.OWN:
                newton._lu = _Factor.__new__(_Factor)
                newton._lu._lu = _KKTFactors(self._AB, self._piv, a.kkt)
        if status == sn.STOPPED and done:   # the last step is the driver's to accept
            s.t, s.q, s.v, s.a, s._ah, s.lam = float(f[sn.T_PREV]), P[0], P[1], P[2], P[3], L[1]
            s.previous = None
            s.n_steps += done - 1
            s._ah_next = S[3]
            return StepOutcome(ok=True, t=float(f[sn.T]), q=S[0], v=S[1], a=S[2], lam=L[0]), done - 1, samples
        if done:
            s.previous = (float(f[sn.T_PREV]), P[0], P[1], P[2])
            s.t, s.q, s.v, s.a, s._ah, s.lam = float(f[sn.T]), S[0], S[1], S[2], S[3], L[0]
            s._last = (float(f[sn.H_LAST]), P[3], L[1])
            s.n_steps += done
        return s.step(), done, samples
