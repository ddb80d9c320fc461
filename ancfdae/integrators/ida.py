"""SUNDIALS IDA (variable-order, variable-step BDF) through scikit-sundae, as a stepper.

IDA sees the first-order form of the Model contract::

    y = [q, v],   F(t, y, y') = [q' - v ; r(t, q, v, v')] = 0,
    dF/dy + cj dF/dy' = [[cj I, -I], [K, D + cj M]]

with the exact Jacobian scattered into the solver's matrix through slots precomputed once.
Consistent initial conditions ``y'0 = [v0, a0]`` (``M a0 = f_ext - f_int``) are mandatory; the
driver computes them, and again after every model event (IDA then re-initialises: its BDF history
is lost). ``OMP_NUM_THREADS=1`` avoids a large slowdown of the bundled OpenMP threads on a busy
machine -- this module sets it when unset before it first imports scikit-sundae (effective only if
no OpenMP runtime is loaded yet; set it in the shell to be sure).

The stepper advances one internal IDA step per :meth:`IDA.step` (``method='onestep'``), so the
driver sees every step (monitors, model events); output times inside a step come from IDA's own
interpolating polynomial (``IDASolve`` in normal mode with ``tout`` inside the last step, which
interpolates and never integrates backwards).
"""
from __future__ import annotations

import math
import os
import warnings

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

from ancfdae import _validate as validate
from ancfdae.constrained import multipliers
from ancfdae.integrators._ida_jacobian import _JacobianFiller
from ancfdae._scale import max_abs
from ancfdae.integrators.ida_constrained import GGLResidual
from ancfdae.integrators.integrator import Integrator
from ancfdae.integrators.protocol import StepOutcome
from ancfdae.problem import Model, capabilities

__all__ = ["IDA"]


def _sundae():
    """Import scikit-sundae lazily (it is only needed for this integrator)."""
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    try:
        import sksundae
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise ImportError("the 'ida' integrator needs scikit-sundae: pip install scikit-sundae") from exc
    return sksundae


class IDA(Integrator):
    """SUNDIALS IDA on the Model contract.

    Parameters
    ----------
    model : Model
    rtol : float
        Relative tolerance (> 0), passed to SUNDIALS unchanged. The global error is typically
        10-1000 x rtol.
    atol : float, (atol_q, atol_v) or array of length 2 n_dof, optional
        Absolute tolerance per coordinate group: positions and slopes (``q``) and velocities
        (``v``). Default ``(rtol * L, rtol * L / (tf - t0))`` with ``L = max(1, max|q0|)``:
        positions and slopes on the scale of the configuration, velocities on that scale per
        run time. The velocity tolerance decides the cost on stiff beams: on the 25-element
        BE2D pendulum (0.2 s, rtol 1e-6) the default resolved the axial vibrations (8,903
        steps, tip error 8e-7) while ``atol=(1e-6, 1e-2)`` took 217 steps (tip error 1.5e-4).
        On B2 (8 BE2D elements, [0, 4] s) the cost stays near 3,500 steps from rtol 1e-4 to
        1e-6 because the default resolves the axial vibrations; a looser velocity tolerance
        did not reach a given eps_T any cheaper (rtol 1e-4, ``atol=(rtol, 10 rtol)``: 333 steps
        but eps_T 6.9e-4 against 4.3e-6; rtol 1e-6, ``(rtol, 100 rtol)``: 4.7e-6 against 4.2e-8
        at the same step count).
    max_order : int in [1, 5]
        BDF order limit (default 5, see Notes).
    max_step, first_step : float, optional
        0 = chosen by IDA.
    linsolver : {"auto", "band", "sparse", "dense"}
        "band": SUNDIALS band solver on the node-interleaved ordering ``[q_0, v_0, q_1, v_1,
        ...]`` that keeps the band of the model's matrices (scikit-sundae hands the Jacobian over
        as a full N x N array, N = 2 n_dof: 8 N^2 bytes). "sparse": SuperLU_MT on the exact
        Jacobian's pattern (no N x N array, but it leaks memory at every re-initialisation, see
        Notes). "dense": for tiny models. "auto" (default): "band" up to N = 2000 (32 MB), else
        "sparse".

    Notes
    -----
    Default ``max_order = 5``, chosen by measurement (process CPU seconds on a shared 2-core
    machine; eps_T of chapter Eq. 115 on the tip against a converged Lobatto IIIA-3 run of the
    same mesh; ``benchmarks/ida_vs_lobatto.py``). B2 (revision-2 loads, 8 BE2D elements,
    [0, 4] s), rtol 1e-4 / 1e-5 / 1e-6: order <= 5 gave eps_T 1.7e-6 / 1.9e-7 / 4.2e-8 in about
    3,500 steps and 0.8-1.2 s; order <= 4: 2.1e-5 / 2.0e-6 / 1.9e-7 (6,200 steps, 1.3-1.4 s);
    order <= 3: 1.2e-4 / 6.3e-6 / 4.6e-7 (9,500 steps, 1.6-2.0 s); order <= 2: 3.9e-4 /
    5.7e-5 / 5.4e-6 (0.5-1.3 s), and 2.8e-8 only at rtol 1e-9 after 77,559 steps and 10.5 s.
    CPU to reach eps_T = 1e-6: 0.9 s (order 5), 1.4 s (4), 2.0 s (3), 1.9 s (2); Lobatto IIIA-3
    0.7 s; measured again with medians of 3 interleaved runs: IDA default 0.65 s, Lobatto
    0.57 s (at eps_T 4e-8 IDA took 0.66 s, Lobatto 0.95 s for 6.8e-8). The integrator study's
    problems (4 elements, [0, 2] s): B2, order 5 was 30-75x more accurate at equal or lower
    CPU for rtol 1e-5..1e-7; B2 with E x 100, orders 3-5 are held by stability, not accuracy
    (about 8,000 steps whatever rtol, eps_T 6.5e-8 at rtol 1e-6), where
    order 2 reached 7e-7 in 1,865 steps (rtol 1e-7): for stiff undamped beams at moderate
    accuracy ``max_order=2`` can be cheaper. (The order-2 cap of earlier versions came from a
    linear chain, where BDF 3-5, not A-stable, forced tiny steps.)

    Linear solver, measured: on B2 above "band" on the node-interleaved ordering cost the same
    as "sparse" (0.80 vs 0.86 s to eps_T = 1e-6, within the noise of the shared machine). Each
    re-initialisation (a model event) leaks memory inside SuperLU_MT: B3 with 8 BE3D elements,
    3,000 restarts grew the resident set from 62 to 1,113 MB with "sparse" and by 0.8 MB with
    "band". Hence "band" by default while its N x N array is small.

    BE3D: an update of the directors is a model event and re-initialises IDA (order 1, small
    first step). Updating after every step is unusable with IDA: on B3 (2 elements, rtol 1e-6)
    20,000 steps and 20,000 restarts reached only t = 0.055 s in 100 s CPU, while with
    ``BE3D(update_below=0.5)`` 0.2 s took 41 steps, no restart, 0.09 s CPU. Use
    ``update_below`` with IDA. A run that starts at rest under a load that starts from zero
    has a stationary initial state: IDA's first step then scales with the span (a run over
    [0, 1e6] s stepped over a 3 s load); give ``max_step`` for long spans.

    Constrained models (capability ``"constraints"``): the GGL form ``y = [q, v, lam, mu]`` with the
    multipliers out of the error test (:mod:`ancfdae.integrators.ida_constrained`, which says why and
    what it costs: the constraints hold to about the position tolerance).

    Statistics: ``newton_iterations`` counts calls of the residual, which SUNDIALS' Newton
    solver evaluates exactly once per iteration (the Jacobian is ours, no difference
    quotients); ``jacobian_evals`` = ``factorizations`` counts calls of the Jacobian (each is
    followed by one factorisation); both from the counting proxy of the base class.
    ``reinits`` counts the re-initialisations after model events.
    """

    name = "ida"
    order = None
    fixed_step = False
    handles_constraints = True

    def __init__(self, model: Model, rtol: float = 1e-6, atol: float | ArrayLike | None = None, *,
                 max_order: int = 5, max_step: float = 0.0, first_step: float = 0.0,
                 linsolver: str = "auto") -> None:
        super().__init__(model, None)
        self.rtol = validate.positive("rtol", rtol)
        self.atol = atol
        if atol is not None:
            arr = np.atleast_1d(np.asarray(atol, dtype=float)) if not isinstance(atol, str) else None
            if arr is None or arr.ndim != 1 or arr.size not in (1, 2, 2 * self.n_dof) or not np.all(arr > 0) \
                    or not np.all(np.isfinite(arr)):
                raise ValueError(f"`atol` must be a positive number, a pair (atol_q, atol_v) or an array of "
                                 f"length 2 n_dof = {2 * self.n_dof}, got {atol!r}.")
        if isinstance(max_order, bool) or max_order not in (1, 2, 3, 4, 5):
            raise ValueError(f"`max_order` must be an integer in [1, 5], got {max_order!r}.")
        self.max_order = int(max_order)
        self.max_step = validate.nonnegative("max_step", max_step)
        self.first_step = validate.nonnegative("first_step", first_step)
        self.linsolver = validate.choice("linsolver", linsolver, ("auto", "band", "sparse", "dense"))
        self._ls = self.linsolver if self.linsolver != "auto" else ("band" if 2 * self.n_dof <= 2000 else "sparse")
        self._solver = None
        self._ggl = None           # the GGL form of a constrained model (set up by initialize)
        self._reinits = 0

    def options(self) -> dict:
        """The options as a JSON-able dict.

        Returns
        -------
        dict
            ``rtol``, ``atol``, ``max_order``, ``max_step``, ``first_step`` and the linear solver used.
        """
        atol = self.atol
        if atol is not None:
            atol = np.atleast_1d(np.asarray(atol, float)).tolist()
        return {"rtol": self.rtol, "atol": atol, "max_order": self.max_order, "max_step": self.max_step,
                "first_step": self.first_step, "linsolver": self._ls}

    def _atol(self, q0, span):
        n = self.n_dof
        if self.atol is None:
            L = max(1.0, float(np.max(np.abs(q0))))
            out = np.r_[np.full(n, self.rtol * L), np.full(n, self.rtol * L / span)]
        else:
            arr = np.atleast_1d(np.asarray(self.atol, dtype=float))
            if arr.size == 1:
                return float(arr[0])
            out = np.r_[np.full(n, arr[0]), np.full(n, arr[1])] if arr.size == 2 else arr
        return out[self._perm] if self._perm is not None else out

    # -- the first-order system in the solver's ordering -----------------------------------------
    def _resfn(self, t, y, yp, res):
        n = self.n_dof
        if self._perm is None:
            res[:n] = yp[:n] - y[n:]
            res[n:] = self.model.residual(t, y[:n], y[n:], yp[n:])
        else:   # interleaved: y[0::2] = q, y[1::2] = v
            res[0::2] = yp[0::2] - y[1::2]
            res[1::2] = self.model.residual(t, y[0::2], y[1::2], yp[1::2])

    def _jacfn(self, t, y, yp, res, cj, JJ):
        q, v, a = self._split(y, yp)
        blk = self.model.jacobian(t, q, v, a)
        if self._ls == "sparse":
            self._filler.fill(JJ, blk, cj)
        else:
            self._filler.fill(self._buf, blk, cj)
            JJ.flat[self._dense_index] = self._buf

    def _split(self, y, yp):
        n = self.n_dof
        if self._ggl is not None:
            return self._ggl.split(y, yp)[:3]
        if self._perm is None:
            return y[:n].copy(), y[n:].copy(), yp[n:].copy()
        return y[0::2].copy(), y[1::2].copy(), yp[1::2].copy()

    def _join(self, q, v, a):
        if self._ggl is not None:
            return self._ggl.join(q, v, a, self.lam)
        y, yp = np.r_[q, v], np.r_[v, a]
        return (y, yp) if self._perm is None else (y[self._perm], yp[self._perm])

    # -- protocol -----------------------------------------------------------------------------
    def _setup(self) -> None:
        """Set up the solver (pattern of the Jacobian at t0) at the initial state."""
        n, t0, q0, v0, a0 = self.n_dof, self.t, self.q, self.v, self.a
        self._reinits = 0
        self._replay = False
        self._ggl = None
        if "constraints" in capabilities(self.model):
            self._setup_constrained()
            return
        blocks0 = self.model.jacobian(t0, q0, v0, a0)
        self._filler = _JacobianFiller(blocks0, n)
        self._perm = None
        opts = dict(rtol=self.rtol, max_order=self.max_order, jacfn=self._jacfn, max_step=self.max_step,
                    first_step=self.first_step, linsolver=self._ls, max_num_steps=1_000_000)
        if self._ls == "sparse":
            opts.update(sparsity=self._filler.pattern, nthreads=1)
        else:
            if self._ls == "band":   # node-interleaved: entry (i, j) of [q; v] goes to (p[i], p[j])
                inv = np.empty(2 * n, dtype=np.int64)
                inv[:n], inv[n:] = 2 * np.arange(n), 2 * np.arange(n) + 1
                self._perm = np.argsort(inv)
            else:
                inv = np.arange(2 * n)
            P = self._filler.pattern.tocoo()
            csc = self._filler.pattern
            rows = inv[csc.indices]
            cols = inv[np.repeat(np.arange(2 * n), np.diff(csc.indptr))]
            self._dense_index = rows * (2 * n) + cols
            self._buf = np.zeros(csc.nnz)
            if self._ls == "band":
                bw = int(np.max(np.abs(inv[P.row] - inv[P.col])))
                opts.update(lband=bw, uband=bw)
        opts["atol"] = self._atol(q0, self.t_bound - t0)
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="Custom sparse Jacobian")
            self._solver = _sundae().ida.IDA(self._resfn, **opts)
        self._solver.init_step(t0, *self._join(q0, v0, a0))

    def _setup_constrained(self) -> None:
        """The GGL form (:mod:`ancfdae.integrators.ida_constrained`) with consistent ``(a0, lam0)``."""
        if self.lam is None:     # no multipliers given: (a0, lam0) from the KKT system
            self.a, self.lam = multipliers(self.model, self.t, self.q, self.v)
        ls = self._ls
        self._ggl = ggl = GGLResidual(self.model, self.t, self.q, self.v, self.a, self.lam, ls)
        self._perm = None
        opts = dict(rtol=self.rtol, max_order=self.max_order, jacfn=ggl.jacfn, max_step=self.max_step,
                    first_step=self.first_step, linsolver=ls, max_num_steps=1_000_000,
                    algebraic_idx=ggl.algebraic_idx)
        if ls == "sparse":
            opts.update(sparsity=ggl.pattern, nthreads=1)
        elif ls == "band":
            opts.update(lband=ggl.bandwidth, uband=ggl.bandwidth)
        n = self.n_dof
        if self.atol is None:
            L = max(1.0, float(np.max(np.abs(self.q))))
            atol_qv = np.r_[np.full(n, self.rtol * L), np.full(n, self.rtol * L / (self.t_bound - self.t))]
        else:
            arr = np.atleast_1d(np.asarray(self.atol, dtype=float))
            atol_qv = arr[0] if arr.size == 1 else (np.r_[np.full(n, arr[0]), np.full(n, arr[1])] if arr.size == 2
                                                    else arr)
        opts["atol"] = ggl.atol(atol_qv)
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="Custom sparse Jacobian")
            self._solver = _sundae().ida.IDA(ggl.resfn, **opts)
        self._solver.init_step(self.t, *self._join(self.q, self.v, self.a))

    def step(self) -> StepOutcome:
        """One internal IDA step towards the end of the run (IDA's state advances with it)."""
        while True:
            out = self._solver.step(self.t_bound, method="onestep", tstop=self.t_bound)
            if not out.success:
                return StepOutcome.failure(f"IDA status {out.status}: {out.message}")
            t_new = float(np.atleast_1d(out.t)[-1])
            if self._replay and not t_new > self.t:
                self._replay = False   # after an interpolation IDA first re-reports its current step
                continue
            self._replay = False
            break
        if not t_new > self.t:
            # IDA creeps towards a point where the residual cannot be evaluated (halving its step while
            # reporting success) until t + h == t.
            return StepOutcome.failure("step size underflow (no progress; the residual may be non-finite or "
                                       "the problem singular beyond this time)")
        y, yp = np.asarray(out.y).reshape(-1), np.asarray(out.yp).reshape(-1)
        if not (math.isfinite(max_abs(y)) and math.isfinite(max_abs(yp))):   # compiled: ~10x np.isfinite().all()
            return StepOutcome.failure("the solution became non-finite")
        if self._ggl is not None:
            q, v, a, lam = self._ggl.split(y, yp)
            return StepOutcome(ok=True, t=t_new, q=q, v=v, a=a, lam=lam)
        q, v, a = self._split(y, yp)
        return StepOutcome(ok=True, t=t_new, q=q, v=v, a=a)

    def interpolate(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """IDA's own BDF interpolant inside the last internal step (consistent to IDA's accuracy;
        a Hermite interpolant of (q, v, a) would amplify their O(rtol) inconsistency by 1/h^2)."""
        if not (self.previous is not None and self.previous[0] <= t <= self.t):
            raise ValueError(f"IDA interpolates only inside its last step, got t = {t!r}.")
        out = self._solver.step(t, method="normal")
        if not out.success:
            raise RuntimeError(f"IDA could not interpolate at t = {t}: {out.message}")
        self._replay = True
        return self._split(np.asarray(out.y).reshape(-1), np.asarray(out.yp).reshape(-1))

    def restart(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray, model: Model) -> None:
        """Re-initialise IDA at a state changed by a model event (BDF history lost).

        Parameters
        ----------
        t, q, v, a, model
            As for :meth:`~ancfdae.integrators.Integrator.restart`.
        """
        super().restart(t, q, v, a, model)
        if self._ggl is not None:    # multipliers consistent with the changed state (and a with them)
            self.a, self.lam = multipliers(self.model, self.t, q, v)
            a = self.a
        self._solver.init_step(float(t), *self._join(q, v, a))
        self._replay = False
        self._reinits += 1

    @property
    def stats(self) -> dict:
        """Work counters since :meth:`initialize` (see Notes)."""
        m = self.model
        return {"steps": self.n_steps, "newton_iterations": m.n_residual, **m.counts(),
                "factorizations": m.n_jacobian, "reinits": self._reinits, "max_order": self.max_order}
