"""Whole steps of the Newmark family as one compiled call, between the driver's stops.

When nothing needs the state between two output times -- no monitor, no hook, no model event -- the
driver asks the stepper for all the steps up to the next output time at once
(:meth:`ancfdae.integrators.newmark._AlphaFamily.steps_until`). A beam that offers compiled steps
(:meth:`ancfdae.models.Beam.compiled_residual` with ``steps``: BE2D with constant mass and no point
moments) runs them in one compiled call (contract and decisions in
:mod:`ancfdae.integrators._alpha_steps_numba`): the predictor, the modified-Newton iterations with the
cached matrix, the update of ``q, v, a`` and the counters, as long as no step needs a decision of
Python (a new or refreshed matrix, a failure); that step is then taken by the ordinary Python step,
which redoes it from its start and counts it. States, decisions and counters are those of the
step-by-step path (the tests hold them equal).
"""
from __future__ import annotations

import numpy as np

from ancfdae.integrators.driver import GRID_TOL
from ancfdae.integrators.protocol import StepOutcome
from ancfdae.integrators import _alpha_steps_numba as sn

__all__ = ["AlphaSteps"]

#: at most this many steps per compiled call: compiled code cannot be interrupted, so Ctrl-C (and the progress
#: bar) is served at least this often (some 0.4 s of a 400-element beam; the return costs ~40 us)
STEPS_PER_CALL = 500
#: at most this many steps per call when dead loads need their time functions evaluated in advance
SCALE_CHUNK = 1024
_NO_SCALES = np.zeros((0, 0))


class AlphaSteps:
    """A beam's compiled steps for one Newmark-family stepper (the run's constant arguments packed once).

    Parameters
    ----------
    compiled : CompiledResidual
        The model's offer, with ``steps`` not None.
    stepper : _AlphaFamily
        The stepper whose state and counters the steps advance.
    """

    __slots__ = ("_fn", "_arrays", "_element", "_gravity", "_dead", "_times", "_fpar", "_stepper")

    def __init__(self, compiled, stepper):
        self._fn = compiled.steps
        self._arrays, self._element = compiled.arrays, compiled.element_args
        self._gravity, self._dead, self._times = compiled.gravity, compiled.dead, compiled.dead_times
        s, o = stepper, stepper.newton.options
        f = np.zeros(sn.N_FPAR)
        f[[sn.T0, sn.H, sn.T_BOUND, sn.BETA, sn.GAMMA, sn.ALPHA_M, sn.ALPHA_F, sn.LAM, sn.TOL, sn.CONTRACTION,
           sn.GRID_TOL]] = (s.t0, s.h, s.t_bound, s.beta, s.gamma, s.alpha_m, s.alpha_f, compiled.load_factor,
                            o.tol, o.contraction, GRID_TOL)
        self._fpar, self._stepper = f, stepper

    def _scales(self, t_stop, max_count):
        """The dead loads' time functions at the weighted times of the coming steps (as ``_step_impl``)."""
        s = self._stepper
        h = s.h
        k = int(max(0, min(max_count, SCALE_CHUNK, (t_stop - s.t) / h + 2)))
        t_new = s.t0 + (s.n_steps + 1 + np.arange(k)) * h
        t_new[t_new >= s.t_bound - GRID_TOL * h] = s.t_bound
        t_start = np.concatenate(([s.t], t_new[:-1]))
        ta = t_start + (1.0 - s.alpha_f) * (t_new - t_start)
        return np.array([[float(time(t)) for time in self._times] for t in ta]).reshape(k, len(self._times))

    def run(self, band, t_stop, max_count):
        """``(outcome, taken)`` as :meth:`_AlphaFamily.steps_until`, with the cached band factors ``band``."""
        s = self._stepper
        max_count = min(max_count, STEPS_PER_CALL)
        f = self._fpar.copy()
        f[[sn.T, sn.T_STOP, sn.H_MATRIX, sn.ATOL, sn.FLOOR]] = s.t, t_stop, s._h_matrix, s._atol, s._floor
        ipar = np.array([s.n_steps, max_count, s.newton.options.max_iter, band.kl, band.ku], dtype=np.int64)
        scales = self._scales(t_stop, max_count) if self._times else _NO_SCALES
        S = np.stack((s.q, s.v, s.a))
        P = np.empty_like(S)
        out = np.zeros(4, dtype=np.int64)
        self._fn(S, P, f, ipar, out, band.lub, band.piv, self._gravity, self._dead, scales, self._arrays,
                 self._element)
        done, status, iterations, evals = (int(x) for x in out)
        st = s.newton.stats
        st.iterations += iterations
        st.residual_evals += evals
        st.solves += done
        s.model.n_residual += evals
        if status == sn.STOPPED and done:   # the last step is the driver's to accept
            s.t, s.q, s.v, s.a = float(f[sn.T_PREV]), P[0], P[1], P[2]
            s.previous = None
            s.n_steps += done - 1
            return StepOutcome(ok=True, t=float(f[sn.T]), q=S[0], v=S[1], a=S[2]), done - 1
        if done:
            s.previous = (float(f[sn.T_PREV]), P[0], P[1], P[2])
            s.t, s.q, s.v, s.a = float(f[sn.T]), S[0], S[1], S[2]
            s.n_steps += done
        return s.step(), done
