"""SUNDIALS IDA (variable-order, variable-step BDF) through scikit-sundae.

IDA sees the first-order form of the Model contract (design.md Sect. 3)::

    y = [q, v],   F(t, y, y') = [q' - v ; r(t, q, v, v')] = 0,
    dF/dy + cj dF/dy' = [[cj I, -I], [K, D + cj M]]

with the exact Jacobian filled into the CSC data array of the ``'sparse'``
linear solver (SuperLU_MT) through slots precomputed once: notes/ida.md
measured it as fast as the best banded variant with no N x N memory.

Measured facts this module follows (notes/ida.md): consistent initial
conditions ``y'0 = [v0, a0]`` with ``M a0 = f_ext - f_int`` are mandatory;
BDF orders above 2 are not A-stable, so undamped models default to
``max_order = 2``; ``atol`` is per component (positions and slopes vs
velocities); ``OMP_NUM_THREADS=1`` avoids a large slowdown of the bundled
OpenMP threads on a busy machine -- this module sets it when unset before it
first imports scikit-sundae (effective only if no OpenMP runtime is loaded
yet; set it in the shell to be sure).

The integrator advances one internal step at a time (``method='onestep'``)
so that it can count steps, call the model's ``accept_step`` hook after each
of them and feed the monitors; output times are interpolated between steps
with IDA's own interpolating polynomial.
"""
from __future__ import annotations

import os
import time

import numpy as np
import scipy.sparse as sp

from ancfdae import _validate as V
from ancfdae.integrators._base import GRID_TOL, Recorder, check_model, consistent_acceleration, output_times
from ancfdae.problem import accept_step

__all__ = ["IDA"]


def _sundae():
    """Import scikit-sundae lazily (it is only needed for this integrator)."""
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    try:
        import sksundae
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise ImportError("the 'ida' integrator needs scikit-sundae: pip install scikit-sundae") from exc
    return sksundae


class _JacobianFiller:
    """Scatter ``[[cj I, -I], [K, D + cj M]]`` into the CSC data array of a fixed pattern."""

    def __init__(self, blocks, n):
        self.n = n
        K, D, M = (sp.csr_matrix(b) for b in (blocks.K, blocks.D, blocks.M))
        self.same = bool(blocks.same_pattern)
        eye = np.arange(n)
        parts = [(eye, eye), (eye, eye + n)]  # cj I at (q, q'); -I at (q, v)
        if self.same:
            kr, kc = self._coords(K)
            parts += [(kr + n, kc), (kr + n, kc + n)]
        else:
            for X, off in ((K, 0), (D, n), (M, n)):
                r, c = self._coords(X)
                parts.append((r + n, c + off))
        rows = np.concatenate([p[0] for p in parts])
        cols = np.concatenate([p[1] for p in parts])
        N = 2 * n
        self.pattern = sp.csc_matrix((np.ones(rows.size), (rows, cols)), shape=(N, N))
        self.pattern.sum_duplicates()
        self.pattern.sort_indices()
        key = cols.astype(np.int64) * N + rows
        csc_key = (np.repeat(np.arange(N), np.diff(self.pattern.indptr)).astype(np.int64) * N
                   + self.pattern.indices)
        slot = np.searchsorted(csc_key, key)
        sizes = np.cumsum([p[0].size for p in parts])[:-1]
        self.slots = np.split(slot, sizes)
        self.nnz = self.pattern.nnz
        self._ref = K.indptr.copy(), K.indices.copy()

    @staticmethod
    def _coords(X):
        X = sp.csr_matrix(X)
        return np.repeat(np.arange(X.shape[0]), np.diff(X.indptr)), X.indices

    def fill(self, JJ, blocks, cj):
        K = blocks.K
        if self.same:
            if K.indices.size != self._ref[1].size or not np.array_equal(K.indices, self._ref[1]):
                raise ValueError("the model's Jacobian pattern changed during the run; IDA needs a fixed pattern.")
            JJ[:] = 0.0
            JJ[self.slots[0]] = cj
            JJ[self.slots[1]] = -1.0
            JJ[self.slots[2]] = K.data
            JJ[self.slots[3]] = blocks.D.data + cj * blocks.M.data
        else:
            vals = [np.full(self.n, cj), -np.ones(self.n)]
            slots = list(self.slots[:2])
            N = 2 * self.n
            csc_key = (np.repeat(np.arange(N), np.diff(self.pattern.indptr)).astype(np.int64) * N
                       + self.pattern.indices)
            for X, off, scale in ((K, 0, 1.0), (blocks.D, self.n, 1.0), (blocks.M, self.n, cj)):
                X = sp.csr_matrix(X)
                r, c = self._coords(X)
                key = (c + off).astype(np.int64) * N + r + self.n
                s = np.searchsorted(csc_key, key)
                if np.any(s >= csc_key.size) or np.any(csc_key[np.minimum(s, csc_key.size - 1)] != key):
                    raise ValueError("the model's Jacobian has entries outside the pattern seen at t0.")
                slots.append(s)
                vals.append(scale * X.data)
            JJ[:] = np.bincount(np.concatenate(slots), weights=np.concatenate(vals), minlength=self.nnz)


class IDA:
    """SUNDIALS IDA on the Model contract.

    Parameters
    ----------
    model : Model
    rtol : float
        Relative tolerance (> 0). The global error is typically 10-1000 x rtol.
    atol : float, (atol_q, atol_v) or array of length 2 n_dof, optional
        Absolute tolerance. Default ``(rtol * L, rtol * L / (tf - t0))`` with
        ``L = max(1, max|q0|)``: positions and slopes on the scale of the
        configuration, velocities on that scale per run time. The velocity
        tolerance decides the cost on stiff beams: on the 25-element BE2D
        pendulum (0.2 s, rtol 1e-6) the default resolved the axial
        vibrations (8,903 steps, tip error 8e-7) while ``atol=(1e-6, 1e-2)``
        took 217 steps (tip error 1.5e-4) -- measured.
    max_order : int in [1, 5], optional
        BDF order limit. Default 2 when the damping block ``D`` at t0 is zero
        (undamped: orders 3-5 are not A-stable and force tiny steps), else 5.
    max_step, first_step : float, optional
        0 = chosen by IDA.
    max_steps : int
        Total internal steps allowed before the run is ended as failed.
    linsolver : {"sparse", "dense"}
        "sparse" (default; SuperLU_MT with the exact Jacobian) or "dense"
        (LAPACK-free SUNDIALS dense, for tiny models).
    """

    name = "ida"
    order = None

    def __init__(self, model, rtol=1e-6, atol=None, *, max_order=None, max_step=0.0, first_step=0.0,
                 max_steps=1_000_000, linsolver="sparse"):
        self.n_dof = check_model(model)
        self.model = model
        self.rtol = V.positive("rtol", rtol)
        self.atol = atol
        if atol is not None:
            arr = np.atleast_1d(np.asarray(atol, dtype=float)) if not isinstance(atol, str) else None
            if arr is None or arr.ndim != 1 or arr.size not in (1, 2, 2 * self.n_dof) or not np.all(arr > 0) \
                    or not np.all(np.isfinite(arr)):
                raise ValueError(f"`atol` must be a positive number, a pair (atol_q, atol_v) or an array of "
                                 f"length 2 n_dof = {2 * self.n_dof}, got {atol!r}.")
        if max_order is not None and (isinstance(max_order, bool) or max_order not in (1, 2, 3, 4, 5)):
            raise ValueError(f"`max_order` must be an integer in [1, 5], got {max_order!r}.")
        self.max_order = max_order
        self.max_step = V.nonnegative("max_step", max_step)
        self.first_step = V.nonnegative("first_step", first_step)
        self.max_steps = V.positive_int("max_steps", max_steps)
        self.linsolver = V.choice("linsolver", linsolver, ("sparse", "dense"))

    def options(self) -> dict:
        atol = self.atol
        if atol is not None:
            atol = np.atleast_1d(np.asarray(atol, float)).tolist()
        return {"rtol": self.rtol, "atol": atol, "max_order": self.max_order, "max_step": self.max_step,
                "first_step": self.first_step, "linsolver": self.linsolver}

    def _atol(self, q0, span):
        n = self.n_dof
        if self.atol is None:
            L = max(1.0, float(np.max(np.abs(q0))))
            return np.r_[np.full(n, self.rtol * L), np.full(n, self.rtol * L / span)]
        arr = np.atleast_1d(np.asarray(self.atol, dtype=float))
        if arr.size == 1:
            return float(arr[0])
        if arr.size == 2:
            return np.r_[np.full(n, arr[0]), np.full(n, arr[1])]
        return arr

    @staticmethod
    def _interpolate(solver, t, n):
        """IDA's own BDF interpolant inside the last internal step (consistent to IDA's accuracy;
        a Hermite interpolant of (q, v, a) would amplify their O(rtol) inconsistency by 1/h^2)."""
        out = solver.step(t, method="normal")
        if not out.success:
            raise RuntimeError(f"IDA could not interpolate at t = {t}: {out.message}")
        y, yp = np.asarray(out.y).reshape(-1), np.asarray(out.yp).reshape(-1)
        return y[:n].copy(), y[n:].copy(), yp[n:].copy()

    def run(self, t_span, t_eval=None, monitors=(), hooks=(), q0=None, v0=None):
        """Integrate over ``t_span``; same contract as ``FixedStepIntegrator.run``."""
        t0, tf, t_out = output_times(t_span, t_eval)
        hooks = list(hooks or ())
        for k in hooks:
            if not callable(k):
                raise TypeError(f"`hooks` entries must be callables hook(t, q, v, a), got {k!r}.")
        model, n = self.model, self.n_dof
        q_i, v_i = model.initial_state() if (q0 is None or v0 is None) else (None, None)
        q0 = V.finite_vector("q0", q_i if q0 is None else q0, n).copy()
        v0 = V.finite_vector("v0", v_i if v0 is None else v0, n).copy()
        rec = Recorder(model, monitors)
        count = {"res": 1, "jac": 1}
        wall = time.perf_counter()
        a0, reason = consistent_acceleration(model, t0, q0, v0)
        base = {"method": self.name, "options": self.options()}
        if a0 is None:
            return rec.result(n, status="failed", message=f"initial acceleration at t = {t0:g} failed: {reason}",
                              stats={"steps": 0}, t_fail=t0, **base)
        blocks0 = model.jacobian(t0, q0, v0, a0)
        filler = _JacobianFiller(blocks0, n)
        max_order = self.max_order
        if max_order is None:
            D = blocks0.D
            max_order = 2 if (D.nnz == 0 or not np.any(sp.csr_matrix(D).data)) else 5

        def resfn(t, y, yp, res):
            count["res"] += 1
            res[:n] = yp[:n] - y[n:]
            res[n:] = model.residual(t, y[:n], y[n:], yp[n:])

        def jacfn(t, y, yp, res, cj, JJ):
            count["jac"] += 1
            blk = model.jacobian(t, y[:n], y[n:], yp[n:])
            if self.linsolver == "sparse":
                filler.fill(JJ, blk, cj)
            else:
                JJ[:, :] = sp.bmat([[cj * sp.eye(n), -sp.eye(n)], [blk.K, blk.D + cj * blk.M]]).toarray()

        sun = _sundae()
        opts = dict(rtol=self.rtol, atol=self._atol(q0, tf - t0), max_order=max_order, jacfn=jacfn,
                    max_step=self.max_step, first_step=self.first_step, linsolver=self.linsolver)
        if self.linsolver == "sparse":
            opts.update(sparsity=filler.pattern, nthreads=1)
        import warnings
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="Custom sparse Jacobian")
            solver = sun.ida.IDA(resfn, **opts)
        y, yp = np.r_[q0, v0], np.r_[v0, a0]
        solver.init_step(t0, y, yp)
        rec.start(t0, q0, v0, a0)
        j = 0
        if t_out is None or t_out[0] <= t0:
            rec.sample(t0, q0, v0, a0)
            j = 1
        t, state = t0, (q0, v0, a0)
        status, message, t_fail, steps, reinits = "success", "", None, 0, 0
        replay = False
        while t < tf:
            if steps >= self.max_steps:
                status, t_fail = "failed", t
                message = f"IDA: more than max_steps = {self.max_steps} internal steps before t = {tf:g}"
                break
            out = solver.step(tf, method="onestep", tstop=tf)
            if not out.success:
                status, t_fail = "failed", t
                message = f"IDA failed after t = {t:.9g} (status {out.status}): {out.message}"
                break
            t_new = float(np.atleast_1d(out.t)[-1])
            y, yp = np.asarray(out.y).reshape(-1), np.asarray(out.yp).reshape(-1)
            if not t_new > t and replay:
                replay = False  # after an interpolation IDA first re-reports its current step
                continue
            if not t_new > t:
                # IDA creeps towards a point where the residual cannot be evaluated (halving its
                # step while reporting success) until t + h == t: end the run there.
                status, t_fail = "failed", t
                message = (f"IDA failed after t = {t:.9g}: step size underflow (no progress; the residual "
                           "may be non-finite or the problem singular beyond this time)")
                break
            if not (np.isfinite(y).all() and np.isfinite(yp).all()):
                status, t_fail = "failed", t
                message = f"IDA failed after t = {t:.9g}: the solution became non-finite"
                break
            steps += 1
            q, v, a = y[:n].copy(), y[n:].copy(), yp[n:].copy()
            q2, v2 = accept_step(model, t_new, q, v)
            if q2 is not q or v2 is not v:
                q, v = np.asarray(q2, float), np.asarray(v2, float)
                solver.init_step(t_new, np.r_[q, v], np.r_[v, a])  # restart: BDF history is lost
                reinits += 1
            rec.advance(t_new, q, v, a)
            if t_out is None:
                rec.sample(t_new, q, v, a)
            else:
                h = t_new - t
                while j < t_out.size and t_out[j] <= t_new + GRID_TOL * h:
                    if abs(t_out[j] - t_new) <= GRID_TOL * h:
                        rec.sample(t_new, q, v, a)
                    else:
                        rec.sample(t_out[j], *self._interpolate(solver, t_out[j], n))
                        replay = True
                    j += 1
            t, state = t_new, (q, v, a)
            reason = rec.stop_reason()
            if reason:
                status, message, t_fail = "failed", reason, t
                break
            if any(k(t, q, v, a) is True for k in hooks):
                message = f"stopped by a hook at t = {t:.9g}"
                break
        if status == "success" and not message:
            message = f"reached tf = {tf:g} in {steps} steps"
        stats = {"steps": steps, "newton_iterations": int(count["res"] - 1), "residual_evals": count["res"],
                 "jacobian_evals": count["jac"], "factorizations": count["jac"] - 1, "reinits": reinits,
                 "max_order": max_order, "wall_time": time.perf_counter() - wall}
        return rec.result(n, status=status, message=message, stats=stats, t_fail=t_fail, **base)
