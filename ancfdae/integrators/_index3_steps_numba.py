"""Whole index-3 steps of the Newmark family on a System, as one compiled call (needs numba).

The compiled twin of :func:`ancfdae.integrators._alpha_index3.index3_step` with the modified Newton of
:class:`ancfdae.integrators._newton.NewtonSolver`, for a :class:`ancfdae.System` of one beam whose element
offers a fused kernel and any number of rigid bodies, every constraint row folded into the compiled set
(:mod:`ancfdae.joints.assembled_numba`). Per Newton iteration: the substitution with the cached factors, the
update of ``x = [y, mu]``, the step's states, the beam's fused residual and ``+ M a - lambda f_ext``, the rigid
bodies' ``M a - f(t, q) - f_g``, ``(g, G^T lam)`` in one pass, the norms and the solver's decisions. A refresh
assembles the KKT matrix ``[[K + s M + H(lam), sm G^T], [sm G, 0]]`` (the beam's tangent from its fused kernel,
``H`` and ``G`` on their fixed patterns; :func:`~ancfdae.integrators._index3_kkt_numba.kkt_fill`) in band storage,
its unknowns in the band order of
:attr:`ancfdae.system_compiled.SystemArrays.kkt` (reverse Cuthill-McKee of its pattern: B6's 62 unknowns have 8 sub-
and 8 super-diagonals, 57 in the System's order), and factorises it with partial pivoting inside the band
(:func:`~ancfdae.integrators._linsolve_numba.band_factor`, LAPACK's ``dgbtf2`` elimination); the round-off floor
is the Python path's. The entry point::

    steps(S, P, L, fpar, ipar, out, AB, piv, ABs, pivs, lub, bpiv, W, E, cons, rigid, beam, element_args, kkt,
          T_rec, rec_q, rec_v, rec_a, rec_lam)

* ``S`` (4, n): ``q, v, a, ah`` (``ah`` the algorithmic acceleration) at ``fpar[T]`` on entry, the state
  reached on return; ``P`` (4, n) the state before the last step taken; ``L`` (2, m): the multipliers
  reached and those before the last step. On entry ``P[3]`` and ``L[1]`` are those at the start of the
  stepper's last step (read only where ``ipar[HAVE_LAST]``: the extrapolating predictor).
* ``AB, piv``: the band factors of the KKT matrix in band order (``(n + m, 2 kl + ku + 1)``, the layout of
  :func:`~ancfdae.integrators._linsolve_numba.band_factor`, ``piv`` of ``3 (n + m)`` with its trims; written at each
  refresh, ``ipar[KIND] = OWN``),
  ``ABs, pivs`` their copy at the start of a step that refreshed; ``lub, bpiv``: LAPACK's banded factors of the
  matrix in the System's order that the Python path left (``ipar[KIND] = BAND``, its ``KL``, ``KU``).
* ``W`` (k, 3, nw): per coming step, the time weights at its end and their first two derivatives (the constraint
  terms' :meth:`~ancfdae.joints.assembled.ConstraintSet.weights`, then the rigid bodies' load factors); ``E``
  (k or 1, nb): the beam's external force at each step's end (one row: constant).
* ``cons``, ``rigid``, ``beam``, ``kkt``: the arrays of :class:`ancfdae.system_compiled.SystemArrays`
  (``kkt``: the band order and the band positions of the KKT matrix's entries, :mod:`._index3_kkt_numba`).

* ``T_rec``: the coming output times (ascending, those after ``t_stop`` ignored). A step accepted here whose end is one
  of them (to ``GRID_TOL``) is recorded: ``q, v, a`` into row ``out[RECORDED]`` of ``rec_q, rec_v, rec_a`` and the
  multipliers of :func:`~._index3_kkt_numba.system_multipliers` (the driver's,
  :func:`ancfdae.constrained.multipliers`) into ``rec_lam``;
  a step that passes one inside (the driver interpolates) or whose multipliers are not finite (the driver's solve
  raises) stops the call, handed to the driver like the last one.

Status ``STOPPED`` (the last step reached ``t_stop`` or the end, or ``max_count`` steps were taken) or
``NEEDS_PYTHON``: the next step needs a decision of Python (a non-finite value, a failed attempt that the
solver retries, ``max_iter``); ``S``, the factors (restored) and the floor are those before it, none of its
work is counted, and the Python step redoes it. As in :mod:`._alpha_steps_numba`, the loop is inlined into
the element's one-line entry point (numba caches a function on disk only when the kernel it calls is a
compile-time constant); after editing this module delete the element's cached ``*index3_steps*`` files.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ancfdae.integrators._index3_kkt_numba import kkt_fill, kkt_solve, multiplier_work, rigid_residual, \
    system_multipliers
from ancfdae.integrators._linsolve_numba import band_factor, band_solve
from ancfdae._scale import max_abs
from ancfdae.joints.assembled_numba import _g_force
from ancfdae._residual_numba import finish_residual

__all__ = ["index3_steps"]

# fpar
T0, H, T, T_BOUND, T_STOP, H_MATRIX, BETA, GAMMA, ALPHA_M, ALPHA_F, TOL, ATOL, FLOOR, CONTRACTION, GRID_TOL, \
    T_PREV, MSCALE, XTOL, LOAD_FACTOR, FLOOR_FACTOR, H_LAST, EXTRAPOLATE_TOL = range(22)
N_FPAR = 22
# ipar (HAVE_LAST: P[3] and L[1] hold ah and lam at the start of a last step of size fpar[H_LAST]; EXTRAPOLATE:
# the predictor of :func:`ancfdae.integrators._alpha_index3.predictor`)
N_STEPS, MAX_COUNT, MAX_ITER, KIND, HAVE_H, KL, KU, HAVE_LAST, EXTRAPOLATE = range(9)
N_IPAR = 9
# ipar[KIND]: no factors, the steps' own band factors (AB, piv), LAPACK's of the Python path (lub, bpiv)
NONE, OWN, BAND = 0, 1, 2
# out
DONE, STATUS, ITERATIONS, RESIDUALS, JACOBIANS, RECORDED = range(6)
N_OUT = 6
STOPPED, NEEDS_PYTHON = 0, 1


@njit(inline="always")
def _residual(fused, x, r, n, m, qp, ca, s, sm, w, ext, lf, cons, rigid, beam, eargs, rbuf, kbuf, work):
    """The step's residual ``[r(t1, q1, v1, a1) + G^T lam; sm g]`` at ``x`` into ``r``; returns ``(max|r|, q1)``
    (``q1`` in the work arrays ``work = (q, v, a, lam, g, f, f2, ma)``, overwritten by the next call; ``rbuf`` the
    beam's force at ``q1``). ``v1`` is not formed: neither the fused beam kernels nor the rigid bodies depend on it
    (no damping)."""
    ob, nb, q_fixed, gather, vec_slot, mat_slot = beam[:6]
    mr_data, mr_indptr, mr_indices = beam[9:12]   # the mass without its stored zeros, as the Python path's
    q, v, a, lam, g, f, f2, ma = work
    for i in range(n):
        y = x[i]
        q[i] = qp[i] + y
        a[i] = s * y + ca[i]
    for i in range(m):
        lam[i] = sm * x[n + i]
    fused(q[ob:ob + nb], q_fixed, gather, vec_slot, mat_slot, False, rbuf, kbuf, *eargs)
    for i in range(nb):   # rbuf keeps the beam's force: the reactions at an output time reuse it
        r[ob + i] = rbuf[i]
    finish_residual(r[ob:ob + nb], mr_data, mr_indptr, mr_indices, a[ob:ob + nb], lf, ext)
    rigid_residual(r, q, a, w, rigid, f2, ma)
    lt, lr, lc, lv, ct, cr, cv, qi, qj, qk, qa = cons[:11]
    _g_force(w, lt, lr, lc, lv, ct, cr, cv, qi, qj, qk, qa, q, lam, g, f)
    for i in range(n):
        r[i] = r[i] + f[i]
    for i in range(m):
        r[n + i] = sm * g[i]
    return max_abs(r), q


@njit(inline="always")
def index3_steps(fused, S, P, L, fpar, ipar, out, AB, piv, ABs, pivs, lub, bpiv, W, E, cons, rigid, beam, eargs,
                 kkt, T_rec, rec_q, rec_v, rec_a, rec_lam):
    """Index-3 steps until ``t_stop``, the end, ``max_count`` steps or a decision for Python (module docstring)."""
    n, m = S.shape[1], L.shape[1]
    N = n + m
    nb = beam[1]
    t0, h, t_bound, t_stop = fpar[T0], fpar[H], fpar[T_BOUND], fpar[T_STOP]
    beta, gamma, am, af = fpar[BETA], fpar[GAMMA], fpar[ALPHA_M], fpar[ALPHA_F]
    tol, atol, contraction, grid_tol = fpar[TOL], fpar[ATOL], fpar[CONTRACTION], fpar[GRID_TOL]
    mscale, xtol, lf, ffac = fpar[MSCALE], fpar[XTOL], fpar[LOAD_FACTOR], fpar[FLOOR_FACTOR]
    n_steps, max_count, max_iter = ipar[N_STEPS], min(ipar[MAX_COUNT], W.shape[0]), ipar[MAX_ITER]
    kind, kl, ku = ipar[KIND], ipar[KL], ipar[KU]
    have_h, h_matrix, floor = ipar[HAVE_H], fpar[H_MATRIX], fpar[FLOOR]
    have_last, h_last, extrapolate, etol = ipar[HAVE_LAST], fpar[H_LAST], ipar[EXTRAPOLATE], fpar[EXTRAPOLATE_TOL]
    x, r, dx, bx = np.empty(N), np.empty(N), np.empty(N), np.empty(N)
    rbuf, kbuf = np.empty(nb + 1), np.empty(beam[6].size + 1)
    qp, vp, ca = np.empty(n), np.empty(n), np.empty(n)
    work = (np.empty(n), np.empty(n), np.empty(n), np.empty(m), np.empty(m), np.empty(n), np.empty(n), np.empty(n))
    t = fpar[T]
    done, iters, evals, jacs, status, nrec = 0, 0, 0, 0, NEEDS_PYTHON, 0
    a_scratch, lam_w, gdata = np.empty(n), np.empty(m), np.empty(cons[14].size)
    mwork = multiplier_work(n, m, nb, AB.shape[1], cons[14].size)
    eps = np.finfo(np.float64).eps
    while done < max_count:
        t_new = t0 + (n_steps + done + 1) * h
        if t_new >= t_bound - grid_tol * h:
            t_new = t_bound
        hs = t_new - t
        # NewtonStepper.step: a new step size drops the matrix
        kind0, floor0, have_h0, h_matrix0 = kind, floor, have_h, h_matrix
        if have_h == 0 or abs(hs - h_matrix) > 1e-8 * h:
            kind, have_h, h_matrix = NONE, 1, hs
        # index3_equations
        w = W[done, 0]
        ext = E[done] if E.shape[0] > 1 else E[0]
        wi = done
        s = (1.0 - am) / ((1.0 - af) * beta * hs * hs)
        sm = s * mscale
        c_v = gamma / (beta * hs)
        cx = beta * hs * hs
        # the predictor (_alpha_index3.predictor): extrapolated from the last step when it had this size
        extra = extrapolate == 1 and have_last == 1 and abs(h_last - hs) <= etol * hs
        for i in range(n):
            ah0 = S[3, i]
            qp[i] = S[0, i] + hs * S[1, i] + (hs * hs * (0.5 - beta)) * ah0
            vp[i] = S[1, i] + (hs * (1.0 - gamma)) * ah0
            ca[i] = (am * ah0 - af * S[2, i]) / (1.0 - af)
            x[i] = cx * (2.0 * ah0 - P[3, i]) if extra else cx * ah0
        for i in range(m):
            x[n + i] = (2.0 * L[0, i] - L[1, i]) / sm if extra else L[0, i] / sm
        # NewtonSolver.solve and _attempt (modified Newton)
        err, q = _residual(fused, x, r, n, m, qp, ca, s, sm, w, ext, lf, cons, rigid, beam, eargs,
                           rbuf, kbuf, work)
        its, ev, jc, saved = 0, 1, 0, False
        ok = np.isfinite(err)
        if ok:
            rel = max(tol * err, atol)
            threshold = max(rel, floor)
            converged = err <= threshold
            fresh, diverging, k = False, 0, 0
            while not converged and k < max_iter:
                k += 1
                if kind == NONE:
                    if kind0 == OWN and not saved:   # kept to restore if Python must redo the step
                        ABs[:, :] = AB
                        pivs[:] = piv
                        saved = True
                    kmax, gmax = kkt_fill(fused, AB, x, q, n, m, s, sm, w, cons, rigid, beam, eargs, rbuf, kbuf, kkt,
                                          lam_w, gdata)
                    qm = max(1.0, max_abs(q))
                    floor = max(floor, max(ffac * eps * kmax * qm, ffac * eps * gmax * qm))
                    band_factor(AB, kkt[1], kkt[2], piv)
                    kind, fresh, jc = OWN, True, jc + 1
                    threshold = max(rel, floor)
                if kind == OWN:
                    kkt_solve(AB, piv, kkt, r, dx, bx)
                else:
                    dx[:] = r
                    band_solve(lub, kl, ku, bpiv, dx)
                its += 1
                dx_max = max_abs(dx)
                if not np.isfinite(dx_max):
                    ok = False
                    break
                for i in range(N):
                    x[i] = x[i] - dx[i]
                err_new, q = _residual(fused, x, r, n, m, qp, ca, s, sm, w, ext, lf, cons, rigid, beam,
                                       eargs, rbuf, kbuf, work)
                ev += 1
                if not np.isfinite(err_new):
                    ok = False
                    break
                stagnant = (err_new > threshold and fresh and err_new > 0.5 * err
                            and dx_max <= xtol * max(1.0, max_abs(x)))
                if err_new <= threshold or stagnant:
                    converged = True
                    break
                rate = err_new / err if err > 0 else np.inf
                err = err_new
                if rate > contraction:
                    if fresh and rate >= 1.0:
                        diverging += 1
                        if diverging >= 2:
                            ok = False
                            break
                    else:
                        diverging = 0
                    kind = NONE
                else:
                    diverging = 0
            ok = ok and converged
        if ok:
            for i in range(n):
                y = x[i]
                if not (np.isfinite(qp[i] + y) and np.isfinite(vp[i] + c_v * y)):
                    ok = False
        if not ok:   # Python redoes this step from its start: its state, factors and floor as they were
            if saved:
                AB[:, :] = ABs
                piv[:] = pivs
            kind, floor, have_h, h_matrix = kind0, floor0, have_h0, h_matrix0
            break
        P[:, :] = S
        L[1, :] = L[0, :]
        for i in range(n):
            y = x[i]
            S[0, i] = qp[i] + y
            S[1, i] = vp[i] + c_v * y
            S[2, i] = s * y + ca[i]
            S[3, i] = y / cx
        for i in range(m):
            L[0, i] = sm * x[n + i]
        iters += its
        evals += ev
        jacs += jc
        done += 1
        have_last, h_last = 1, hs
        t_prev, t = t, t_new
        fpar[T_PREV], fpar[T] = t_prev, t
        tol_t = grid_tol * (t - t_prev)
        if t >= t_bound or t_stop <= t + tol_t or done == max_count:
            status = STOPPED
            break
        if nrec < rec_q.shape[0] and T_rec[nrec] <= t + tol_t:   # an output time reached (the driver's test)
            if abs(T_rec[nrec] - t) > tol_t:   # inside the step: the driver interpolates
                status = STOPPED
                break
            # the last residual was at the accepted state: rbuf holds the beam's force at S[0]
            system_multipliers(fused, W[wi], ext, S[0], S[1], a_scratch, rec_lam[nrec], cons, rigid, beam, eargs, lf,
                               kkt, mwork, rbuf)
            if not np.isfinite(max_abs(rec_lam[nrec])):   # the driver's solve reports it
                status = STOPPED
                break
            T_rec[nrec] = t   # the step's time, as the driver records it
            rec_q[nrec, :] = S[0]
            rec_v[nrec, :] = S[1]
            rec_a[nrec, :] = S[2]
            nrec += 1
    fpar[FLOOR], fpar[H_MATRIX], fpar[H_LAST] = floor, h_matrix, h_last
    ipar[KIND], ipar[HAVE_H] = kind, have_h
    out[DONE], out[STATUS], out[ITERATIONS], out[RESIDUALS], out[JACOBIANS], out[RECORDED] = (done, status, iters,
                                                                                           evals, jacs, nrec)
