"""Whole index-3 steps of the Newmark family on a System as one compiled call, between the driver's stops.

When nothing needs the state between two output times the driver asks the stepper for every step up to the
next one at once (:meth:`ancfdae.integrators.newmark._AlphaFamily.steps_until`). On a constrained model that
is a :class:`ancfdae.System` of one beam whose element offers compiled index-3 steps (BE2D:
:func:`ancfdae.models.thin.be2d_numba.be2d_index3_steps`) and rigid bodies, with every constraint row in the
compiled set (:attr:`ancfdae.System.compiled_rows`), :class:`Index3Steps` packs the system's constant arrays
once and runs the steps in one compiled call (contract and decisions in
:mod:`ancfdae.integrators._index3_steps_numba`): the predictor, the modified-Newton iterations, the refresh
of the KKT matrix and its dense LU, the update of ``q, v, a, ah, lam`` and the counters. The time functions
(the joints' drives, the rigid bodies' and the beam's loads) are evaluated here, before the call, at the ends
of the coming steps: one call of each user function per step and time (a table), not one per iteration.

A step that needs a decision of Python (a failure, the solver's retry) is taken by the ordinary Python step,
which redoes it from its start with the factors the compiled steps left (a dense factorisation is handed
over as such). The Python path stays the reference: the tests hold states, multipliers and counters equal
to it on B5 and B6 (the dense LU rounds differently from LAPACK's banded one, so states agree to round-off).
"""
from __future__ import annotations

import numpy as np

from ancfdae.integrators import _index3_steps_numba as sn
from ancfdae.integrators._linsolve import _Banded
from ancfdae.integrators._newton import _Factor
from ancfdae.integrators.driver import GRID_TOL
from ancfdae.integrators.protocol import StepOutcome

__all__ = ["Index3Steps"]

#: at most this many steps per compiled call (Ctrl-C and the progress bar are served between calls)
STEPS_PER_CALL = 500
#: the compiled path factorises the KKT matrix densely: offered up to this many unknowns ``n + m``
#: (dense LU of 62 unknowns, B6: some 20 us; above a few hundred banded or sparse factors win)
DENSE_MAX = 200


class _DenseLU:
    """The compiled steps' dense factorisation, handed to the Python solver (``solve`` as its factors')."""

    __slots__ = ("lu", "piv")

    def __init__(self, lu, piv):
        self.lu, self.piv = lu, piv

    def solve(self, rhs):
        x = np.array(rhs, dtype=float)
        sn.dense_solve(self.lu, self.piv, x)
        return x


def _coo(block: np.ndarray, offset: int):
    i, j = np.nonzero(block)
    return i + offset, j + offset, block[i, j]


class Index3Steps:
    """A System's compiled index-3 steps for one Newmark-family stepper (see the module docstring).

    Use :meth:`offer`; the constructor takes what it found there.
    """

    def __init__(self, stepper, rows, beam_at, compiled, rigid_bodies):
        s, o, model = stepper, stepper.newton.options, stepper.model.wrapped
        n, m = model.n_dof, model.n_constraints
        self._fn, self._stepper, self._rows = compiled.index3_steps, stepper, rows
        cons = (rows.lin_term, rows.lin_row, rows.lin_col, rows.lin_val, rows.const_term, rows.const_row,
                rows.const_val, rows.qi, rows.qj, rows.qk, rows.qa, rows.lin_slot, rows._q_slot,
                rows.G_pattern.indptr.astype(np.int64), rows.G_pattern.indices.astype(np.int64))
        self._cons = tuple(np.ascontiguousarray(a) for a in cons)
        n_w = 1 + len(rows.timed)
        times, mi, mj, mv, ci, cj, cv, ccol, fvec, fcol = [], [], [], [], [], [], [], [], [], []
        grav, ridx = np.zeros(n), []
        for body, off in rigid_bodies:
            M, fg, forces, moments = body.residual_parts()
            nb = M.shape[0]
            ridx.extend(range(off, off + nb))
            for a, b in zip((mi, mj, mv), _coo(M, off)):
                a.append(b)
            grav[off:off + nb] = fg
            for time, f in forces:
                fv = np.zeros(n)
                fv[off:off + nb] = f
                fvec.append(fv)
                fcol.append(n_w + len(times))
                times.append(time)
            for time, C in moments:
                i, j, c = _coo(C, off)
                ci.append(i)
                cj.append(j)
                cv.append(c)
                ccol.append(np.full(i.size, n_w + len(times)))
                times.append(time)
        cat = (lambda x, dt: np.concatenate(x).astype(dt) if x else np.zeros(0, dt))
        self._rigid = (np.array(ridx, dtype=np.int64), cat(mi, np.int64), cat(mj, np.int64), cat(mv, float),
                       grav, np.array(fvec, dtype=float).reshape(len(fvec), n), np.array(fcol, dtype=np.int64),
                       cat(ci, np.int64), cat(cj, np.int64), cat(cv, float), cat(ccol, np.int64))
        self._times = times
        beam, off = beam_at
        q_fixed, gather, vec_slot, mat_slot, m_data, indptr, indices = compiled.arrays
        self._beam = (int(off), int(beam.n_dof), q_fixed, gather, vec_slot, mat_slot, m_data, indptr, indices)
        self._element = compiled.element_args
        # the beam's external force: gravity alone is constant; dead loads need their time functions
        self._external = compiled.external if compiled.dead_times else None
        self._E = np.ascontiguousarray(compiled.external(s.t0)[None, :], dtype=float)
        f = np.zeros(sn.N_FPAR)
        f[[sn.T0, sn.H, sn.T_BOUND, sn.BETA, sn.GAMMA, sn.ALPHA_M, sn.ALPHA_F, sn.TOL, sn.CONTRACTION,
           sn.GRID_TOL, sn.MSCALE, sn.XTOL, sn.LOAD_FACTOR, sn.FLOOR_FACTOR]] = (
            s.t0, s.h, s.t_bound, s.beta, s.gamma, s.alpha_m, s.alpha_f, o.tol, o.contraction, GRID_TOL,
            s._mscale, o.xtol, compiled.load_factor, s.FLOOR_ROUNDOFF)
        self._fpar = f
        N = n + m
        self._LU, self._piv = np.zeros((N, N)), np.zeros(N, dtype=np.int64)
        self._LUs, self._pivs = np.zeros((N, N)), np.zeros(N, dtype=np.int64)
        self._no_band = (np.zeros((1, 1), order="F"), np.zeros(1, dtype=np.int32))   # LAPACK's types

    @classmethod
    def offer(cls, stepper) -> "Index3Steps | None":
        """The compiled steps for ``stepper``'s constrained model, or None when it is not such a System (one beam
        offering ``index3_steps``, rigid bodies, every row compiled, at most :data:`DENSE_MAX` unknowns) or
        Newton is not modified."""
        model = stepper.model.wrapped
        rows = getattr(model, "compiled_rows", None)
        if rows is None or stepper.newton.options.jacobian != "modified" or not model.n_constraints:
            return None
        if model.n_dof + model.n_constraints > DENSE_MAX:
            return None
        beams, rigid = [], []
        for body, off in zip(model.bodies, model.offsets):
            offer = getattr(body, "compiled_residual", None)
            if offer is not None:
                compiled = offer()
                if compiled is None or compiled.index3_steps is None:
                    return None
                beams.append(((body, off), compiled))
            elif callable(getattr(body, "residual_parts", None)):
                rigid.append((body, int(off)))
            else:
                return None
        if len(beams) != 1:
            return None
        (beam_at, compiled), = beams
        return cls(stepper, rows, beam_at, compiled, rigid)

    def _tables(self, t_stop, max_count):
        """``(W, E)``: the time weights and the beam's external force at the ends of the coming steps."""
        s = self._stepper
        h = s.h
        k = int(max(1, min(max_count, (t_stop - s.t) / h + 2)))
        t_new = s.t0 + (s.n_steps + 1 + np.arange(k)) * h
        t_new[t_new >= s.t_bound - GRID_TOL * h] = s.t_bound
        try:
            W = self._rows.weight_table(t_new)
        except ValueError:   # a bad time function: the Python steps reach it and fail at its step, with its message
            return None, None
        if self._times:
            W = np.hstack((W, np.array([[float(time(t)) for time in self._times] for t in t_new])))
        E = (self._E if self._external is None else
             np.array([self._external(t) for t in t_new], dtype=float))
        return np.ascontiguousarray(W), np.ascontiguousarray(E)

    def run(self, t_stop: float, max_count: int) -> tuple[StepOutcome, int]:
        """``(outcome, taken)`` as :meth:`ancfdae.integrators.newmark._AlphaFamily.steps_until`."""
        s = self._stepper
        newton = s.newton
        lu = newton._lu
        inner = getattr(lu, "_lu", None)
        kind, lub, bpiv, kl, ku = sn.NONE, *self._no_band, 0, 0
        if isinstance(inner, _DenseLU) and inner.lu is self._LU:
            kind = sn.DENSE
        elif isinstance(inner, _Banded) and inner.dtype == np.float64:
            kind, lub, bpiv, kl, ku = sn.BAND, inner.lub, inner.piv, inner.kl, inner.ku
        elif lu is not None:
            return s.step(), 0
        max_count = min(max_count, STEPS_PER_CALL)
        W, E = self._tables(t_stop, max_count)
        if W is None:
            return s.step(), 0
        f = self._fpar.copy()
        f[[sn.T, sn.T_STOP, sn.H_MATRIX, sn.ATOL, sn.FLOOR]] = (s.t, t_stop, s._h_matrix or 0.0, s._atol, s._floor)
        ipar = np.array([s.n_steps, max_count, newton.options.max_iter, kind, s._h_matrix is not None, kl, ku],
                        dtype=np.int64)
        S = np.stack((s.q, s.v, s.a, s._ah))
        P = np.empty_like(S)
        L = np.stack((s.lam, s.lam))
        out = np.zeros(sn.N_OUT, dtype=np.int64)
        self._fn(S, P, L, f, ipar, out, self._LU, self._piv, self._LUs, self._pivs, lub, bpiv, W, E, self._cons,
                 self._rigid, self._beam, self._element)
        done, status, iterations, evals, jacs = (int(x) for x in out)
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
        if ipar[sn.KIND] == sn.DENSE and kind != sn.DENSE or ipar[sn.KIND] == sn.NONE:
            newton._lu = None
            if ipar[sn.KIND] == sn.DENSE:
                newton._lu = _Factor.__new__(_Factor)
                newton._lu._lu = _DenseLU(self._LU, self._piv)
        if status == sn.STOPPED and done:   # the last step is the driver's to accept
            s.t, s.q, s.v, s.a, s._ah, s.lam = float(f[sn.T_PREV]), P[0], P[1], P[2], P[3], L[1]
            s.previous = None
            s.n_steps += done - 1
            s._ah_next = S[3]
            return StepOutcome(ok=True, t=float(f[sn.T]), q=S[0], v=S[1], a=S[2], lam=L[0]), done - 1
        if done:
            s.previous = (float(f[sn.T_PREV]), P[0], P[1], P[2])
            s.t, s.q, s.v, s.a, s._ah, s.lam = float(f[sn.T]), S[0], S[1], S[2], S[3], L[0]
            s.n_steps += done
        return s.step(), done
